//! `meta.toml` of a session ([`SessionMeta`]): what produced it (versions, scene, seed, port,
//! rates, the chip and the register settings of the images) and, appended after the handshake,
//! the device's `[device]` table ([`DeviceMeta`]).

use super::images::ImageSettings;
use super::session::StreamConfig;
use margemu_protocol::chip::chain::ChainConfig;
use margemu_protocol::chip::{ChipSettings, Conversion};
use margemu_protocol::link::{HelloAck, Rate};
use margemu_protocol::PROTOCOL_VERSION;
use margemu_sim::meta::{ChipMeta, DeviceMeta, ImageMeta, SessionMeta};
use margemu_sim::scene::chip::{BusKind, ChipSetup};
use margemu_sim::scene::Scene;

/// `meta.toml`; `hold` is the kinematics hold of source mode model (`None`: images).
pub(crate) fn metadata(
    scene: &Scene,
    c: &StreamConfig,
    s: &ImageSettings,
    rate: Rate,
    hold: Option<u32>,
) -> SessionMeta {
    SessionMeta {
        margemu_version: env!("CARGO_PKG_VERSION").to_string(),
        protocol_version: PROTOCOL_VERSION,
        scene_file: scene.path.display().to_string(),
        scene_sha256: scene.hash(),
        seed: scene.spec.seed,
        samples: scene.samples(),
        duration_s: scene.spec.duration,
        rate_hz: scene.clock.hz(),
        rate_num: rate.num(),
        rate_den: rate.den(),
        port: c.port.clone(),
        baud: c.baud,
        source: if hold.is_some() { "model" } else { "images" }.to_string(),
        kinematics_hold: hold,
        kinematics_rate_hz: hold.map(|h| rate.as_hz_f64() / f64::from(h)),
        lead_ns: c.lead.as_nanos() as u64,
        batch: c.batch,
        telemetry_period_ns: c.telemetry_period.as_nanos() as u64,
        session_id: c.session_id,
        field_unit: scene.spec.field.unit.symbol().to_string(),
        mag_ut_per_unit: s.mag_ut_per_unit,
        default_temp_c: s.default_temp_c,
        chip: ChipMeta {
            name: Some(scene.chip_name.clone()),
            ..chip_meta(&scene.chip, &s.chip, internal_path(scene, 0))
        },
        other_devices: scene
            .other_devices
            .iter()
            .enumerate()
            .map(|(i, d)| ChipMeta {
                name: Some(d.name.clone()),
                ..chip_meta(&d.chip, &d.chip.settings, internal_path(scene, i + 1))
            })
            .collect(),
        image: match &s.chip.conversion {
            Conversion::Mpu6xxx(i) => Some(ImageMeta {
                accel_fs: format!("{:?}", i.accel_fs),
                gyro_fs: format!("{:?}", i.gyro_fs),
                mag_bits: format!("{:?}", i.mag_bits),
                asa: i.asa,
                gyro_offset: i.gyro_offset,
                accel_offset: i.accel_offset,
            }),
            // The others' conversions are their ranges, already in `[chip]`.
            Conversion::Icm42688p(_)
            | Conversion::Bmi270(_)
            | Conversion::Bmi088(_)
            | Conversion::Ist8310
            | Conversion::Qmc5883l(_)
            | Conversion::Rm3100(_) => None,
        },
        scene_text: scene.text.clone(),
        device: None,
        dut: None,
        completion: None,
    }
}

/// Whether device `index`'s sampling chain runs at its internal rate.
fn internal_path(scene: &Scene, index: usize) -> bool {
    let vibration = scene.vibration.get(index).cloned().unwrap_or_default();
    margemu_sim::sampling::uses_internal_path(scene, &vibration)
}

/// `chip`'s table, its images computed with `settings`, its chain on the internal path or not.
fn chip_meta(chip: &ChipSetup, settings: &ChipSettings, internal: bool) -> ChipMeta {
    let fs = settings.full_scale();
    let filters = chip.chain.map(|c| {
        let keys = ChainConfig::keys(c.family());
        keys.iter().map(|k| k.to_string()).zip(c.values()).collect()
    });
    ChipMeta {
        model: settings.model.name().to_string(),
        who_am_i: chip.who_am_i,
        bus: chip.bus.name().to_string(),
        i2c_address: chip.i2c_address,
        image_len: settings.model.image_len(),
        accel_range_g: fs.map(|fs| fs.accel_g),
        gyro_range_dps: fs.map(|fs| fs.gyro_dps),
        mag_range_gauss: settings.mag_range_gauss(),
        rotation: chip.rotation,
        name: None,
        chip_select: (chip.bus == BusKind::Spi).then_some(chip.chip_select),
        offset: chip.offset,
        sampling_path: filters
            .as_ref()
            .map(|_| if internal { "internal" } else { "output" }.to_string()),
        filters,
    }
}

/// The `[device]` table appended to `meta.toml` after HelloAck.
pub(super) fn device_meta(a: &HelloAck) -> DeviceMeta {
    let c = a.capabilities;
    let f = a.firmware;
    DeviceMeta {
        protocol_version: a.protocol_version,
        firmware: format!("{}.{}.{}", f.major, f.minor, f.patch),
        device_id: a.device_id.iter().map(|b| format!("{b:02x}")).collect(),
        chips: c.chips.0,
        modes: c.modes.0,
        buses: c.buses.0,
        max_batch: c.max_batch,
        buffer_capacity: c.buffer_capacity,
    }
}
