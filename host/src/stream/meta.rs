//! `meta.toml` of a session: what produced it (versions, scene, seed, port, rates, the chip and
//! the register settings of the images) and, appended after the handshake, the device's
//! `[device]` table.

use super::images::ImageSettings;
use super::session::StreamConfig;
use crate::scene::chip::{ChipSetup, Rotation};
use crate::scene::Scene;
use margemu_protocol::chip::Conversion;
use margemu_protocol::link::{HelloAck, Rate};
use margemu_protocol::PROTOCOL_VERSION;
use serde::Serialize;

#[derive(Serialize)]
struct Meta<'a> {
    margemu_version: &'a str,
    protocol_version: u16,
    scene_file: String,
    scene_sha256: String,
    seed: u64,
    samples: u64,
    duration_s: f64,
    rate_hz: f64,
    rate_num: u32,
    rate_den: u32,
    port: &'a str,
    baud: u32,
    source: &'a str,
    kinematics_hold: Option<u32>,
    kinematics_rate_hz: Option<f64>,
    lead_ns: u64,
    batch: usize,
    telemetry_period_ns: u64,
    session_id: u32,
    field_unit: &'a str,
    mag_ut_per_unit: f64,
    default_temp_c: f32,
    chip: ChipMeta,
    image: Option<ImageMeta>,
    scene_text: &'a str,
}

/// `[chip]`: the emulated chip and the full scales of the images.
#[derive(Serialize)]
struct ChipMeta {
    model: &'static str,
    who_am_i: u8,
    bus: &'static str,
    i2c_address: u8,
    image_len: usize,
    accel_range_g: f64,
    gyro_range_dps: f64,
    rotation: Option<Rotation>,
}

/// `[image]`: the InvenSense 6xxx family's further conversion settings (offsets, AK8963).
#[derive(Serialize)]
struct ImageMeta {
    accel_fs: String,
    gyro_fs: String,
    mag_bits: String,
    asa: [u8; 3],
    gyro_offset: [i16; 3],
    accel_offset: [i16; 3],
}

/// `meta.toml`; `hold` is the kinematics hold of source mode model (`None`: images).
pub(super) fn metadata(
    scene: &Scene,
    c: &StreamConfig,
    s: &ImageSettings,
    rate: Rate,
    hold: Option<u32>,
) -> String {
    let meta = Meta {
        margemu_version: env!("CARGO_PKG_VERSION"),
        protocol_version: PROTOCOL_VERSION,
        scene_file: scene.path.display().to_string(),
        scene_sha256: scene.hash(),
        seed: scene.spec.seed,
        samples: scene.samples(),
        duration_s: scene.spec.duration,
        rate_hz: scene.clock.hz(),
        rate_num: rate.num(),
        rate_den: rate.den(),
        port: &c.port,
        baud: c.baud,
        source: if hold.is_some() { "model" } else { "images" },
        kinematics_hold: hold,
        kinematics_rate_hz: hold.map(|h| rate.as_hz_f64() / f64::from(h)),
        lead_ns: c.lead.as_nanos() as u64,
        batch: c.batch,
        telemetry_period_ns: c.telemetry_period.as_nanos() as u64,
        session_id: c.session_id,
        field_unit: scene.spec.field.unit.symbol(),
        mag_ut_per_unit: s.mag_ut_per_unit,
        default_temp_c: s.default_temp_c,
        chip: chip_meta(&scene.chip, s),
        image: match &s.chip.conversion {
            Conversion::Mpu6xxx(i) => Some(ImageMeta {
                accel_fs: format!("{:?}", i.accel_fs),
                gyro_fs: format!("{:?}", i.gyro_fs),
                mag_bits: format!("{:?}", i.mag_bits),
                asa: i.asa,
                gyro_offset: i.gyro_offset,
                accel_offset: i.accel_offset,
            }),
            // The ICM-42688-P's settings are its full scales, in `[chip]` already.
            Conversion::Icm42688p(_) => None,
        },
        scene_text: &scene.text,
    };
    toml::to_string(&meta).expect("metadata serializes")
}

fn chip_meta(chip: &ChipSetup, s: &ImageSettings) -> ChipMeta {
    let fs = s.chip.full_scale();
    ChipMeta {
        model: s.chip.model.name(),
        who_am_i: chip.who_am_i,
        bus: chip.bus.name(),
        i2c_address: chip.i2c_address,
        image_len: s.chip.model.image_len(),
        accel_range_g: fs.accel_g,
        gyro_range_dps: fs.gyro_dps,
        rotation: chip.rotation,
    }
}

/// The `[device]` table appended to `meta.toml` after HelloAck.
pub(super) fn device_meta(a: &HelloAck) -> String {
    let c = a.capabilities;
    let id: String = a.device_id.iter().map(|b| format!("{b:02x}")).collect();
    format!(
        "\n[device]\nprotocol_version = {}\nfirmware = \"{}.{}.{}\"\ndevice_id = \"{id}\"\nchips = {}\nmodes = {}\nbuses = {}\nmax_batch = {}\nbuffer_capacity = {}\n",
        a.protocol_version,
        a.firmware.major,
        a.firmware.minor,
        a.firmware.patch,
        c.chips.0,
        c.modes.0,
        c.buses.0,
        c.max_batch,
        c.buffer_capacity
    )
}
