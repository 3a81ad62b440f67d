//! Each device's sampling chain on the host: which path runs ([`SamplingPath`]) and what it is
//! built from (the chip's declared chain, the vibration reaching the device, its seed).
//!
//! - An IMU device always has a front end. On the **output path** (the default when nothing
//!   reaching the device vibrates above the output Nyquist frequency) it adds the vibration at
//!   the output instants and clips and counts at the chip's full scale; without vibration that
//!   is the [`Clipper`] alone, a few comparisons per sample (what the device runs in source
//!   mode (b)).
//! - On the **internal path** it runs the chip's internal rate, front-end clipping, filters and
//!   decimation ([`margemu_protocol::chip::chain`]): the cost grows with the internal rate.
//! - A magnetometer-only device has none (vibration does not reach a magnetometer's reading).
//!
//! In source mode (b) the device runs the same chain, built by the firmware's
//! `margemu_firmware::link::setup::model_chain` (same periods, seed and order of sources) from
//! the AddVibration messages; the host predicts with that constructor, so both give the same
//! bits.

use crate::scene::chip::ChipSetup;
use crate::scene::vibration::{DeviceVibration, SamplingPath};
use crate::scene::Scene;
use margemu_model::chain::{output_period_ns, Clipper, DeviceChain, Front, SensorPath};
use margemu_model::perturbation::Complex;
use margemu_model::vibration::{RpmPoint, Sense, Vibration};
use margemu_model::Error;
use margemu_protocol::chip::chain::{ChipChain, SensorChain};

/// A device's chain with host-owned buffers.
pub type HostChain = DeviceChain<Vec<RpmPoint>, Vec<Complex>>;
/// A device's front end with host-owned buffers.
pub type HostFront = Front<Vec<RpmPoint>, Vec<Complex>>;
/// One sensor's path with host-owned buffers.
pub type HostPath = SensorPath<Vec<RpmPoint>, Vec<Complex>>;
/// One sensor's vibration with host-owned buffers.
pub type HostVibration = Vibration<Vec<RpmPoint>, Vec<Complex>>;

/// Whether `vibration` on a device of `scene` takes the internal path.
pub fn uses_internal_path(scene: &Scene, vibration: &DeviceVibration) -> bool {
    match scene.sampling {
        SamplingPath::Internal => true,
        SamplingPath::Output => false,
        SamplingPath::Auto => vibration.max_frequency_hz() > 0.5 * scene.clock.hz(),
    }
}

/// Whether the scene asks for the internal path whatever vibrates (`path = "internal"`).
pub fn forces_internal_path(scene: &Scene) -> bool {
    scene.sampling == SamplingPath::Internal
}

/// The chip's declared chain at the scene's output rate (`None` for a magnetometer).
pub fn chip_chain(scene: &Scene, chip: &ChipSetup) -> Option<Result<ChipChain, Error>> {
    let config = chip.chain.as_ref()?;
    let Some(rate) = crate::scene::chip::link_rate(scene.clock.hz()) else {
        return Some(Err(Error::ChainRefused));
    };
    Some(ChipChain::new(&chip.settings, config, rate).map_err(|_| Error::ChainRefused))
}

/// The front end of a device mounted as `chip`, with `vibration` reaching it (chip axes) and
/// the device's seed: the [`Clipper`] when nothing vibrates on the output path, else the
/// chain; `None` for a magnetometer-only device.
pub fn build(
    scene: &Scene,
    chip: &ChipSetup,
    vibration: &DeviceVibration,
    seed: u64,
) -> Option<Result<HostFront, Error>> {
    let [accel_range, gyro_range] = chip.settings.front_end_ranges()?;
    let internal = uses_internal_path(scene, vibration);
    if vibration.is_empty() && !internal {
        return Some(Clipper::new(accel_range, gyro_range).map(Front::Clip));
    }
    let ranges = [accel_range, gyro_range];
    Some(chain(scene, chip, vibration, seed, internal, ranges).map(Front::Chain))
}

fn chain(
    scene: &Scene,
    chip: &ChipSetup,
    vibration: &DeviceVibration,
    seed: u64,
    internal: bool,
    [accel_range, gyro_range]: [f32; 2],
) -> Result<HostChain, Error> {
    if !internal {
        let period = output_period_ns(scene.clock.hz());
        let path = |sense, range| -> Result<HostPath, Error> {
            SensorPath::at_output(range, sensor_vibration(sense, period, seed, vibration)?)
        };
        return Ok(DeviceChain {
            accel: path(Sense::Linear, accel_range)?,
            gyro: path(Sense::Angular, gyro_range)?,
        });
    }
    let declared = chip_chain(scene, chip).ok_or(Error::ChainRefused)??;
    let path = |sense, spec: &SensorChain| -> Result<HostPath, Error> {
        let vib = sensor_vibration(sense, spec.period_ns, seed, vibration)?;
        SensorPath::new(spec.period_ns, spec.filter, spec.range, vib)
    };
    Ok(DeviceChain {
        accel: path(Sense::Linear, &declared.accel)?,
        gyro: path(Sense::Angular, &declared.gyro)?,
    })
}

/// The vibration one sensor sees, sampled every `period_ns`.
pub fn sensor_vibration(
    sense: Sense,
    period_ns: u64,
    seed: u64,
    vibration: &DeviceVibration,
) -> Result<HostVibration, Error> {
    let mut vib =
        Vibration::with_sources(sense, period_ns, seed, &vibration.tones, &vibration.shocks)?;
    if let (Sense::Linear, Some(random)) = (sense, &vibration.random) {
        let len = random.buffer_len(1e9 / period_ns as f64)?;
        vib.add_random(random, vec![Complex::ZERO; len])?;
    }
    Ok(vib)
}

/// `vibration` (in the axes of a chip mounted as `chip`) back in plate axes: what a model that
/// works in plate axes (`margemu simulate`) adds.
pub fn in_plate_axes(vibration: &DeviceVibration, chip: &ChipSetup) -> DeviceVibration {
    let Some(r) = chip.rotation else {
        return vibration.clone();
    };
    let back = |v: [f64; 3]| -> [f64; 3] {
        core::array::from_fn(|i| r[0][i] * v[0] + r[1][i] * v[1] + r[2][i] * v[2])
    };
    let mut out = vibration.clone();
    for tones in &mut out.tones {
        tones.map_harmonics(|h| {
            h.linear = back(h.linear);
            h.angular = back(h.angular);
        });
    }
    for shock in &mut out.shocks {
        shock.linear = back(shock.linear);
        shock.angular = back(shock.angular);
    }
    if let Some(random) = &mut out.random {
        random.axes = None;
    }
    out
}
