//! Raw MARG samples: the shared `model` crate driven by ground truth, exactly as the firmware
//! will drive it, so the host predicts every sample the device emits bit for bit.
//!
//! Per output sample the body-frame truth is rounded to `f32`, the magnetic disturbance of the
//! perturbation generator (if the scene has one) is added to the true field, the specific force
//! and the body rate go through the device's sampling chain (vibration, front-end clipping,
//! the chip's filters: [`crate::sampling`]), and the sensor model of eq. 18 turns that into
//! accelerometer, gyroscope and magnetometer readings.
//!
//! The scene's sensor faults of the device (`[[fault]]`, [`margemu_model::fault::SensorFaults`]
//! on the device's seed at the scene's output rate) act on each sample last, after the model and
//! before anything else uses it (the chip's conversion, the files, the filters); a scene without
//! sensor faults skips them. A dropout keeps the model's value in [`MargSample::sample`] and
//! names the sensor in [`MargSample::dropout`]: the chip's conversion marks those registers
//! invalid, and `marg.csv` writes `NaN` for them.
//!
//! `marg.csv`: `t_ns,acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z,mag_x,mag_y,mag_z` in m/s², rad/s and
//! the scene's field unit (`NaN` for a sensor in a dropout window). `perturbation.csv`: `t_ns,mag_x,mag_y,mag_z`, the disturbance added
//! to the true field per axis (written only when the scene has a `[perturbation]`).

use crate::csv_row::{self, RowBuf};
use crate::sampling::HostFront;
use crate::scene::chip::ChipSetup;
use crate::scene::vibration::DeviceVibration;
use crate::scene::Scene;
use crate::truth::Truth;
use margemu_model::fault::{Sensor, SensorFaults};
use margemu_model::perturbation::{Complex, Perturbation, PerturbationPlan};
use margemu_model::sensor::{self, Marg, Sample};
use std::io::{self, Write};

/// Header of `marg.csv`.
pub const MARG_COLUMNS: [&str; 10] = [
    "t_ns", "acc_x", "acc_y", "acc_z", "gyr_x", "gyr_y", "gyr_z", "mag_x", "mag_y", "mag_z",
];

/// Header of `perturbation.csv`.
pub const PERTURBATION_COLUMNS: [&str; 4] = ["t_ns", "mag_x", "mag_y", "mag_z"];

/// The seed of device `index` of a rig whose scene seed is `seed`: the scene's own for the
/// first device, then steps of the 64-bit golden ratio, so each device draws its own noise.
///
/// ```
/// use margemu_sim::marg::device_seed;
/// assert_eq!(device_seed(7, 0), 7);
/// assert_ne!(device_seed(7, 1), device_seed(7, 2));
/// ```
pub fn device_seed(seed: u64, index: usize) -> u64 {
    seed.wrapping_add((index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15))
}

/// The perturbation generator with host-owned buffers.
type HostPerturbation = Perturbation<Vec<Complex>, Vec<f32>>;

/// The sensor model of one scene, sample by sample.
pub struct MargSim {
    marg: Marg,
    /// Samples produced so far (the index of the next one).
    produced: u64,
    perturbation: Option<HostPerturbation>,
    temperature: Option<[f64; 2]>,
    chain: Option<HostFront>,
    /// The device's sensor faults; `None` when it has none (nothing to pay).
    faults: Option<SensorFaults>,
}

/// Front-end clipping so far: internal samples (or output samples, on the output path) that
/// clipped, per axis.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ClipCounts {
    /// Accelerometer x, y, z.
    pub accel: [u64; 3],
    /// Gyroscope x, y, z.
    pub gyro: [u64; 3],
}

/// One output sample of the sensor model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MargSample {
    /// Latch instant.
    pub t_ns: u64,
    /// What the sensors read.
    pub sample: Sample,
    /// Disturbance added to the true field.
    pub disturbance: [f32; 3],
    /// Sensors in a dropout window ([`Sensor::bit`]s): their registers hold the chip's invalid
    /// value ([`margemu_protocol::chip::ChipSettings::mark_invalid`]), `marg.csv` writes `NaN`.
    pub dropout: u8,
}

impl MargSample {
    /// The nine readings in `marg.csv`'s column order: accelerometer, gyroscope, magnetometer
    /// (x, y, z each).
    pub fn values(&self) -> impl Iterator<Item = &f32> {
        let s = &self.sample;
        s.acc.iter().chain(&s.gyr).chain(&s.mag)
    }

    /// [`Self::values`] with `NaN` for the sensors in [`Self::dropout`]: `marg.csv`'s row.
    pub fn written_values(&self) -> [f32; 9] {
        let mut out = [0.0f32; 9];
        for (o, v) in out.iter_mut().zip(self.values()) {
            *o = *v;
        }
        for sensor in Sensor::ALL {
            if self.dropout & sensor.bit() != 0 {
                let at = 3 * sensor as usize;
                out[at..at + 3].fill(f32::NAN);
            }
        }
        out
    }
}

impl MargSim {
    /// The model of `scene` (already validated, so this fails only on a model it refused), in
    /// plate axes: what `simulate` writes and the offline filters read. Without vibration it
    /// is eq. 18 alone (no chip front end: the scene's `[sensors.*] range` clips, if given);
    /// with vibration or `path = "internal"`, device 0's chain runs in front of it.
    pub fn new(scene: &Scene) -> Result<Self, margemu_model::Error> {
        let vibration = scene.vibration.first().cloned().unwrap_or_default();
        let vibration = crate::sampling::in_plate_axes(&vibration, &scene.chip);
        let chip = (!vibration.is_empty() || crate::sampling::forces_internal_path(scene))
            .then_some((&scene.chip, &vibration));
        Self::build(scene, &scene.spec.sensors.config(), 0, chip)
    }

    /// The model of device `index` of `scene`'s rig ([`Scene::devices`]): the scene's sensor
    /// terms on the device's own seed ([`device_seed`]), its lever arm
    /// ([`ChipSetup::offset`](crate::scene::chip::ChipSetup::offset), turned into the chip's
    /// axes) added to `[sensors.accel] lever_arm`, behind the chip's front end (clipping at its
    /// full scale, counted; its sampling chain with vibration: [`crate::sampling`]), as the
    /// chip serves it. `None` if the scene has no such device.
    pub fn for_device(scene: &Scene, index: usize) -> Option<Result<Self, margemu_model::Error>> {
        let device = scene.devices().into_iter().nth(index)?;
        let mut config = scene.spec.sensors.config();
        if let Some(offset) = device.chip.offset {
            let r = device.chip.to_chip(offset);
            let base = config.accel.lever_arm_m.unwrap_or([0.0; 3]);
            config.accel.lever_arm_m = Some([0, 1, 2].map(|i| base[i] + r[i]));
        }
        let vibration = scene.vibration.get(index).cloned().unwrap_or_default();
        Some(Self::build(
            scene,
            &config,
            index,
            Some((&device.chip, &vibration)),
        ))
    }

    /// The model of device `index` ([`device_seed`], its sensor faults).
    fn build(
        scene: &Scene,
        config: &sensor::MargConfig,
        index: usize,
        front: Option<(&ChipSetup, &DeviceVibration)>,
    ) -> Result<Self, margemu_model::Error> {
        let seed = device_seed(scene.spec.seed, index);
        let chain = front
            .and_then(|(chip, vibration)| crate::sampling::build(scene, chip, vibration, seed))
            .transpose()?;
        let spec = &scene.spec;
        let rate = scene.clock.hz();
        let marg = Marg::new(config, rate, seed)?;
        let perturbation = match &spec.perturbation {
            None => None,
            Some(p) => {
                let plan = PerturbationPlan::new(&p.config(), rate)?;
                let scratch = vec![Complex::default(); plan.scratch_len()];
                let signal = vec![0.0f32; plan.signal_len()];
                Some(Perturbation::new(&plan, seed, scratch, signal)?)
            }
        };
        Ok(Self {
            marg,
            produced: 0,
            perturbation,
            temperature: spec.sensors.temperature,
            chain,
            faults: sensor_faults(scene, index, seed, rate),
        })
    }

    /// Front-end clipping so far (`None` for a device without accelerometer and gyroscope).
    pub fn clips(&self) -> Option<ClipCounts> {
        self.chain.as_ref().map(|c| {
            let [accel, gyro] = c.clips();
            ClipCounts { accel, gyro }
        })
    }

    /// Whether the device's chain runs at the chip's internal rate.
    pub fn runs_internal_path(&self) -> bool {
        self.chain.as_ref().is_some_and(|c| c.runs_internal_path())
    }

    /// Whether the scene has a perturbation generator.
    pub fn has_perturbation(&self) -> bool {
        self.perturbation.is_some()
    }

    /// [`Self::sample`], stopped at a value that is not finite ([`crate::guard::check_sample`],
    /// naming `scene`'s sensor tables).
    pub fn try_sample(
        &mut self,
        scene: &Scene,
        t: &Truth,
    ) -> Result<MargSample, Box<crate::guard::NonFinite>> {
        let index = self.produced;
        let s = self.sample(t);
        crate::guard::check_sample(scene, index, &s)?;
        Ok(s)
    }

    /// The reading for the next output sample, whose truth is `t`.
    ///
    /// The model saturates its inputs, so finite truth gives finite samples; callers that
    /// write or serve samples use [`Self::try_sample`], which checks.
    pub fn sample(&mut self, t: &Truth) -> MargSample {
        self.produced += 1;
        let disturbance = self.perturbation.as_mut().map_or([0.0; 3], |p| p.sample());
        let f = |v: [f64; 3]| v.map(|x| x as f32);
        let field = f(t.field_body);
        let truth = sensor::Truth {
            angular_rate: f(t.body_rate),
            specific_force: f(t.specific_force),
            magnetic_field: [0, 1, 2].map(|i| field[i] + disturbance[i]),
            angular_acceleration: f(t.angular_accel),
            temperature_c: self
                .temperature
                .map(|[start, slope]| (start + slope * t.t_ns as f64 * 1e-9) as f32),
        };
        let sample = match self.chain.as_mut() {
            Some(chain) => chain.sample(&mut self.marg, t.t_ns, &truth),
            None => self.marg.sample(&truth),
        };
        let mut sample = sample;
        let dropout = match self.faults.as_mut() {
            Some(faults) => faults.apply(t.t_ns, &mut sample),
            None => 0,
        };
        MargSample {
            t_ns: t.t_ns,
            sample,
            disturbance,
            dropout,
        }
    }
}

/// The sensor faults of device `index` of `scene` (seed `seed`, output rate `rate_hz`), each
/// at its index among the device's faults; `None` when it has no sensor fault.
pub fn sensor_faults(scene: &Scene, index: usize, seed: u64, rate_hz: f64) -> Option<SensorFaults> {
    let mut faults = SensorFaults::new(seed, rate_hz);
    for fault in scene
        .faults
        .iter()
        .filter(|f| usize::from(f.device) == index)
    {
        // The scene check keeps a schedule within MAX_FAULTS.
        faults.push(fault).ok()?;
    }
    (!faults.is_empty()).then_some(faults)
}

/// Writes `marg.csv` rows (and optionally `perturbation.csv` rows), one `write_all` per row
/// ([`crate::csv_row`]).
pub struct MargWriter<W: Write> {
    marg: W,
    perturbation: Option<W>,
    row: RowBuf,
}

impl<W: Write> MargWriter<W> {
    /// Writes the headers.
    pub fn new(mut marg: W, mut perturbation: Option<W>) -> io::Result<Self> {
        marg.write_all(csv_row::header(&MARG_COLUMNS).as_bytes())?;
        if let Some(p) = perturbation.as_mut() {
            p.write_all(csv_row::header(&PERTURBATION_COLUMNS).as_bytes())?;
        }
        Ok(Self {
            marg,
            perturbation,
            row: RowBuf::default(),
        })
    }

    /// Writes one sample.
    pub fn write(&mut self, s: &MargSample) -> io::Result<()> {
        if s.dropout == 0 {
            self.row
                .write(&mut self.marg, s.t_ns, s.values().copied())?;
        } else {
            self.row.write(&mut self.marg, s.t_ns, s.written_values())?;
        }
        if let Some(p) = self.perturbation.as_mut() {
            self.row.write(p, s.t_ns, s.disturbance)?;
        }
        Ok(())
    }

    /// Flushes both files.
    pub fn finish(mut self) -> io::Result<()> {
        self.marg.flush()?;
        if let Some(p) = self.perturbation.as_mut() {
            p.flush()?;
        }
        Ok(())
    }
}
