//! Applying a [`Configure`]: the chip (model, identity, image length, I2C address), its register
//! overrides, and the model of source mode (b).

use margemu_model::chain::Clipper;
use margemu_model::sensor::{Marg, Truth};
use margemu_protocol::chip::PhysicalSample;
use margemu_protocol::link::{Chips, Configure, ErrorCode, Image, ModelParams, Rate, Source};

use crate::chip::{Chip, EmulatedChip};

/// The chip models this device emulates.
pub fn chips() -> Chips {
    EmulatedChip::models().fold(Chips::EMPTY, |set, m| set | Chips::of(m))
}

/// A fresh chip of `cfg`'s model, identity and address with its overrides applied (through the
/// chip's own buses) and its write log emptied. [`ErrorCode::UnsupportedChip`] for a model this
/// device does not emulate, an identity or address the model lacks, or an image length other
/// than the model's; [`ErrorCode::InvalidConfig`] for an override of a register file the model
/// does not have.
pub fn build_chip(cfg: &Configure) -> Result<EmulatedChip, ErrorCode> {
    if usize::from(cfg.image_len) != cfg.chip.image_len() {
        return Err(ErrorCode::UnsupportedChip);
    }
    let mut chip = EmulatedChip::new(cfg.chip, cfg.who_am_i, cfg.i2c_address)
        .ok_or(ErrorCode::UnsupportedChip)?;
    for o in &cfg.overrides {
        if !chip.write_register(o.file, o.register, o.value) {
            return Err(ErrorCode::InvalidConfig);
        }
    }
    while chip.pop_write().is_some() {}
    Ok(chip)
}

/// The sensor model of source mode (b) at the output rate: the front end of the output path
/// without vibration (a [`Clipper`]: clipping at the chip's full scale, counted) and the error
/// terms. The host's model of a device without vibration is the same.
pub struct DeviceModel {
    marg: Marg,
    front: Option<Clipper>,
}

impl DeviceModel {
    /// The model of `cfg` at `rate_hz` with `seed`, clipping at `chip`'s full scale (none for a
    /// magnetometer-only chip).
    pub fn new(
        cfg: &margemu_model::sensor::MargConfig,
        rate_hz: f64,
        seed: u64,
        chip: &impl Chip,
    ) -> Result<Self, margemu_model::Error> {
        let marg = Marg::new(cfg, rate_hz, seed)?;
        let front = match chip.settings().front_end_ranges() {
            None => None,
            Some([accel, gyro]) => Some(Clipper::new(accel, gyro)?),
        };
        Ok(Self { marg, front })
    }

    /// One output sample at `t_ns` from `truth`.
    #[inline]
    pub fn sample(&mut self, t_ns: u64, truth: &Truth) -> margemu_model::sensor::Sample {
        let _ = t_ns;
        match self.front.as_mut() {
            Some(front) => front.sample(&mut self.marg, truth),
            None => self.marg.sample(truth),
        }
    }

    /// Front-end clipping so far, `[accel, gyro]` per axis (zeros without a front end).
    pub fn clips(&self) -> [[u64; 3]; 2] {
        self.front.as_ref().map_or([[0; 3]; 2], Clipper::clips)
    }
}

/// Source mode (b): the shared sensor model at the output rate, fed by the latest kinematics.
pub struct Model {
    model: DeviceModel,
    truth_rate: Rate,
    mag_ut_per_unit: f64,
    held: Option<Truth>,
}

impl Model {
    /// The model of `params` at the output `rate`; `None` if the model refuses the terms.
    /// A perturbation is refused by the caller (it needs buffers this device does not have).
    pub fn new(params: &ModelParams, rate: Rate, chip: &impl Chip) -> Option<Self> {
        let model = DeviceModel::new(&params.marg, rate.as_hz_f64(), params.seed, chip).ok()?;
        Some(Self {
            model,
            truth_rate: params.truth_rate,
            mag_ut_per_unit: params.mag_ut_per_unit,
            held: None,
        })
    }

    /// The kinematics index in effect at scene time `t_ns`: the latest `j` with
    /// `truth_rate.sample_time_ns(j) ≤ t_ns`.
    pub fn truth_index_at(&self, t_ns: u64) -> u64 {
        truth_index_at(self.truth_rate, t_ns)
    }

    /// Holds `truth` as the latest kinematics sample.
    pub fn hold(&mut self, truth: Truth) {
        self.held = Some(truth);
    }

    /// Whether a kinematics sample has been held yet.
    pub fn has_truth(&self) -> bool {
        self.held.is_some()
    }

    /// One output sample from the held kinematics, as the register image the chip serves
    /// (`None` before the first kinematics sample: the model does not step).
    pub fn image(&mut self, t_ns: u64, chip: &impl Chip) -> Option<Image> {
        let truth = self.held?;
        Some(model_image(
            &mut self.model,
            t_ns,
            &truth,
            self.mag_ut_per_unit,
            chip,
        ))
    }
}

/// The kinematics index in effect at scene time `t_ns` for kinematics at `rate`: the largest `j`
/// with `floor(j·den·10⁹/num) ≤ t_ns`, i.e. `floor(((t_ns+1)·num − 1) / (den·10⁹))`.
pub fn truth_index_at(rate: Rate, t_ns: u64) -> u64 {
    let num = u128::from(rate.num());
    let den = u128::from(rate.den()) * 1_000_000_000;
    let j = ((u128::from(t_ns) + 1) * num - 1) / den;
    u64::try_from(j).unwrap_or(u64::MAX)
}

/// Die temperature assumed when the kinematics carry none, °C (the MPU-9250's TEMP_OUT 0).
pub const DEFAULT_TEMP_C: f32 = 21.0;

/// The image of one model step at `t_ns`, exactly as the device computes it in source mode (b),
/// so a host can predict it: the model's sample, the field scaled to µT as
/// `(f64::from(mag) * mag_ut_per_unit) as f32`, the temperature of the kinematics
/// ([`DEFAULT_TEMP_C`] when absent), converted with the chip's current [`Chip::settings`].
pub fn model_image(
    model: &mut DeviceModel,
    t_ns: u64,
    truth: &Truth,
    mag_ut_per_unit: f64,
    chip: &impl Chip,
) -> Image {
    let s = model.sample(t_ns, truth);
    let sample = PhysicalSample {
        acc: s.acc,
        gyr: s.gyr,
        mag: s.mag.map(|m| (f64::from(m) * mag_ut_per_unit) as f32),
        temp_c: truth.temperature_c.unwrap_or(DEFAULT_TEMP_C),
    };
    chip.settings().image(&sample)
}

/// Whether the device can serve `source` (no perturbation in mode (b) yet).
pub fn source_supported(source: &Source) -> bool {
    match source {
        Source::Images => true,
        Source::Model(p) => p.perturbation.is_none(),
    }
}
