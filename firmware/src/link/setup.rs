//! Applying a [`Configure`]: the chip (model, identity, image length, I2C address), its register
//! overrides, and the model of source mode (b).

#[cfg(feature = "model-vibration")]
use margemu_model::chain::Front;
use margemu_model::chain::{Clipper, DeviceChain};
use margemu_model::fault::{Fault, ScheduleFull, SensorFaults};
use margemu_model::perturbation::Complex;
use margemu_model::sensor::{Marg, Truth};
use margemu_model::vibration::{Sense, Shock, ToneSource, MAX_SHOCKS, MAX_TONE_SOURCES};
use margemu_protocol::chip::chain::ChainConfig;
use margemu_protocol::chip::{ChipSettings, PhysicalSample};
use margemu_protocol::link::{
    AddVibration, Chips, Configure, ErrorCode, Image, ModelParams, Rate, RpmProfile, Source,
};

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

/// What the AddVibration messages of source mode (b) built up (`docs/spec/link.md` §5.15):
/// the chain's path and the vibration reaching the device, in the chip's axes, in the order
/// received (tones, then shocks, as the host's model adds them).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ChainSetup {
    /// The chip's filter settings for its internal path (`None`: the output path).
    pub internal: Option<ChainConfig>,
    /// The motor tone sources.
    pub tones: heapless::Vec<ToneSource<RpmProfile>, TONES_HELD>,
    /// The shocks.
    pub shocks: heapless::Vec<Shock, SHOCKS_HELD>,
}

impl ChainSetup {
    /// The vibration sources that move `sense`: each tone source's motors × harmonics, and
    /// each shock with a non-zero part on that sense (the unit both cost models count in).
    pub fn sources_moving(&self, sense: Sense) -> usize {
        let tones: usize = self
            .tones
            .iter()
            .filter(|t| t.moves(sense))
            .map(|t| usize::from(t.motors) * t.harmonics().len())
            .sum();
        let shocks = self
            .shocks
            .iter()
            .filter(|s| match sense {
                Sense::Linear => s.linear != [0.0; 3],
                Sense::Angular => s.angular != [0.0; 3],
            })
            .count();
        tones + shocks
    }

    /// Adds one piece; `false` (nothing changed) if it does not fit.
    pub fn add(&mut self, piece: &AddVibration) -> bool {
        match piece {
            AddVibration::Path(p) if p.is_none() || cfg!(feature = "model-vibration") => {
                self.internal = *p;
                true
            }
            AddVibration::Path(_) => false,
            AddVibration::Tones(t) => self.tones.push(t.clone()).is_ok(),
            AddVibration::Shock(s) => self.shocks.push(*s).is_ok(),
        }
    }

    /// The messages that build this setup: the path, each tone source, each shock.
    pub fn messages(&self) -> impl Iterator<Item = AddVibration> + '_ {
        let path = core::iter::once(AddVibration::Path(self.internal));
        let tones = self.tones.iter().cloned().map(AddVibration::Tones);
        path.chain(tones)
            .chain(self.shocks.iter().copied().map(AddVibration::Shock))
    }
}

/// A device's chain in source mode (b): rpm profiles of at most
/// [`MAX_RPM_POINTS`](margemu_protocol::link::MAX_RPM_POINTS) points, no random vibration (its
/// FFT buffers do not fit: the host refuses it).
pub type ModelChain = DeviceChain<RpmProfile, [Complex; 0]>;
/// Tone sources a device holds: the model's limit with the `model-vibration` feature, none
/// without.
pub const TONES_HELD: usize = if cfg!(feature = "model-vibration") {
    MAX_TONE_SOURCES
} else {
    0
};
/// Shocks a device holds, likewise.
pub const SHOCKS_HELD: usize = if cfg!(feature = "model-vibration") {
    MAX_SHOCKS
} else {
    0
};

/// A device's front end in source mode (b): the [`Clipper`] when nothing vibrates on the output
/// path, else a [`ModelChain`].
#[cfg(feature = "model-vibration")]
pub type ModelFront = Front<RpmProfile, [Complex; 0]>;

/// A device's front end in source mode (b) without the `model-vibration` feature: the
/// [`Clipper`] alone (the chain's vibration is refused).
#[cfg(not(feature = "model-vibration"))]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelFront(Clipper);

#[cfg(not(feature = "model-vibration"))]
impl ModelFront {
    /// One output sample of `marg` behind the clipper.
    #[inline]
    pub fn sample(
        &mut self,
        marg: &mut Marg,
        _t_ns: u64,
        truth: &Truth,
    ) -> margemu_model::sensor::Sample {
        self.0.sample(marg, truth)
    }

    /// Samples clipped so far, `[accel, gyro]` per axis.
    pub fn clips(&self) -> [[u64; 3]; 2] {
        self.0.clips()
    }
}

/// The front end of a chip with `settings` at the output `rate`, seeded with `seed`, as `setup`
/// says (`None` for a magnetometer-only chip: vibration does not reach it): the [`Clipper`]
/// when nothing vibrates on the output path, else the chain. Built exactly as the host's
/// `margemu_sim::sampling::build`: the output path at the output period rounded to ns, or the
/// chip's declared chain ([`ChipChain::new`](margemu_protocol::chip::chain::ChipChain::new)) at
/// its internal periods; each sensor's vibration adds the tone sources then the shocks, in
/// order.
pub fn model_chain(
    settings: &ChipSettings,
    rate: Rate,
    seed: u64,
    setup: &ChainSetup,
) -> Option<Result<ModelFront, margemu_model::Error>> {
    let [accel, gyro] = settings.front_end_ranges()?;
    if setup.internal.is_none() && setup.tones.is_empty() && setup.shocks.is_empty() {
        #[cfg(feature = "model-vibration")]
        return Some(Clipper::new(accel, gyro).map(Front::Clip));
        #[cfg(not(feature = "model-vibration"))]
        return Some(Clipper::new(accel, gyro).map(ModelFront));
    }
    Some(vibration_chain(settings, rate, seed, setup, [accel, gyro]))
}

/// Without the `model-vibration` feature the device holds no chain: refused.
#[cfg(not(feature = "model-vibration"))]
fn vibration_chain(
    _: &ChipSettings,
    _: Rate,
    _: u64,
    _: &ChainSetup,
    _: [f32; 2],
) -> Result<ModelFront, margemu_model::Error> {
    Err(margemu_model::Error::ChainRefused)
}

/// The chain with vibration or on the internal path (see [`model_chain`]).
#[cfg(feature = "model-vibration")]
fn vibration_chain(
    settings: &ChipSettings,
    rate: Rate,
    seed: u64,
    setup: &ChainSetup,
    [accel, gyro]: [f32; 2],
) -> Result<ModelFront, margemu_model::Error> {
    use margemu_model::chain::SensorPath;
    use margemu_model::vibration::{Sense, Vibration};
    use margemu_protocol::chip::chain::{ChipChain, SensorChain};
    let vibration = |sense, period_ns| {
        Vibration::with_sources(sense, period_ns, seed, &setup.tones, &setup.shocks)
    };
    match &setup.internal {
        None => {
            let period = margemu_model::chain::output_period_ns(rate.as_hz_f64());
            let path = |sense, range| SensorPath::at_output(range, vibration(sense, period)?);
            Ok(Front::Chain(DeviceChain {
                accel: path(Sense::Linear, accel)?,
                gyro: path(Sense::Angular, gyro)?,
            }))
        }
        Some(config) => {
            let declared = ChipChain::new(settings, config, rate)
                .map_err(|_| margemu_model::Error::ChainRefused)?;
            let path = |sense, spec: &SensorChain| {
                let vib = vibration(sense, spec.period_ns)?;
                SensorPath::new(spec.period_ns, spec.filter, spec.range, vib)
            };
            Ok(Front::Chain(DeviceChain {
                accel: path(Sense::Linear, &declared.accel)?,
                gyro: path(Sense::Angular, &declared.gyro)?,
            }))
        }
    }
}

/// The sensor model of source mode (b) at the output rate: the chain of [`model_chain`]
/// (clipping at the chip's full scale, counted; the vibration and path of a [`ChainSetup`])
/// and the error terms. The host predicts with the same ([`DeviceModel::new`] on both sides).
///
/// **Sensor faults.** A model may carry its device's [`SensorFaults`] ([`DeviceModel::push_fault`]
/// or [`DeviceModel::set_faults`]): [`model_image`] applies them to each output sample before the
/// conversion and writes the chip's invalid value for a dropout
/// ([`ChipSettings::mark_invalid`]), on the device and in the host's prediction alike.
pub struct DeviceModel {
    marg: Marg,
    front: Option<ModelFront>,
    rate_hz: f64,
    /// The device's faults (every class, so each keeps its index).
    faults: Option<SensorFaults>,
    /// Whether one of them is a sensor fault (else [`model_image`] skips them).
    sensor_faults: bool,
}

impl DeviceModel {
    /// The model of `cfg` at the output `rate` with `seed`, behind the chain `setup` gives
    /// `chip` (none for a magnetometer-only chip).
    pub fn new(
        cfg: &margemu_model::sensor::MargConfig,
        rate: Rate,
        seed: u64,
        chip: &impl Chip,
        setup: &ChainSetup,
    ) -> Result<Self, margemu_model::Error> {
        let marg = Marg::new(cfg, rate.as_hz_f64(), seed)?;
        let front = model_chain(&chip.settings(), rate, seed, setup).transpose()?;
        Ok(Self {
            marg,
            front,
            rate_hz: rate.as_hz_f64(),
            faults: None,
            sensor_faults: false,
        })
    }

    /// Appends the next fault of the device's schedule (every class: each keeps its index, so
    /// its random stream is the host's); the device's seed `seed` keys the streams (the first
    /// push fixes it). Sensor faults act from then on in [`model_image`].
    pub fn push_fault(&mut self, fault: &Fault, seed: u64) -> Result<(), ScheduleFull> {
        let rate_hz = self.rate_hz;
        let faults = self
            .faults
            .get_or_insert_with(|| SensorFaults::new(seed, rate_hz));
        faults.push(fault)?;
        self.sensor_faults = !faults.is_empty();
        Ok(())
    }

    /// Takes the device's faults as a whole (built by the caller with the output rate).
    pub fn set_faults(&mut self, faults: SensorFaults) {
        self.sensor_faults = !faults.is_empty();
        self.faults = Some(faults);
    }

    /// The faults, to carry over into a rebuilt model (before Start).
    fn take_faults(&mut self) -> (Option<SensorFaults>, bool) {
        (self.faults.take(), self.sensor_faults)
    }

    /// One output sample at `t_ns` from `truth`.
    #[inline]
    pub fn sample(&mut self, t_ns: u64, truth: &Truth) -> margemu_model::sensor::Sample {
        match self.front.as_mut() {
            Some(front) => front.sample(&mut self.marg, t_ns, truth),
            None => self.marg.sample(truth),
        }
    }

    /// Front-end clipping so far, `[accel, gyro]` per axis (zeros without a front end).
    pub fn clips(&self) -> [[u64; 3]; 2] {
        self.front.as_ref().map_or([[0; 3]; 2], ModelFront::clips)
    }
}

/// Source mode (b): the shared sensor model at the output rate, fed by the latest kinematics.
pub struct Model {
    model: DeviceModel,
    params: ModelParams,
    rate: Rate,
    chain: ChainSetup,
    truth_rate: Rate,
    mag_ut_per_unit: f64,
    held: Option<Truth>,
}

impl Model {
    /// The model of `params` at the output `rate`; `None` if the model refuses the terms.
    /// A perturbation is refused by the caller (it needs buffers this device does not have).
    pub fn new(params: &ModelParams, rate: Rate, chip: &impl Chip) -> Option<Self> {
        let chain = ChainSetup::default();
        let model = DeviceModel::new(&params.marg, rate, params.seed, chip, &chain).ok()?;
        Some(Self {
            model,
            params: *params,
            rate,
            chain,
            truth_rate: params.truth_rate,
            mag_ut_per_unit: params.mag_ut_per_unit,
            held: None,
        })
    }

    /// Adds one piece of the chain (an AddVibration) and rebuilds the model behind it, fresh
    /// (before Start); `false`, with nothing changed, if the piece does not fit
    /// ([`MAX_TONE_SOURCES`] tone sources, [`MAX_SHOCKS`] shocks) or the model refuses the chain
    /// with it (an invalid source, a chain the chip's settings do not have at this rate).
    pub fn add_vibration(&mut self, piece: &AddVibration, chip: &impl Chip) -> bool {
        let mut chain = self.chain.clone();
        if !chain.add(piece) {
            return false;
        }
        let p = &self.params;
        match DeviceModel::new(&p.marg, self.rate, p.seed, chip, &chain) {
            Ok(mut model) => {
                (model.faults, model.sensor_faults) = self.model.take_faults();
                self.model = model;
                self.chain = chain;
                true
            }
            Err(_) => false,
        }
    }

    /// Appends the next fault of device 0 (see [`DeviceModel::push_fault`]).
    pub fn push_fault(&mut self, fault: &Fault, seed: u64) -> Result<(), ScheduleFull> {
        self.model.push_fault(fault, seed)
    }

    /// The chain's setup so far.
    pub fn chain(&self) -> &ChainSetup {
        &self.chain
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
/// ([`DEFAULT_TEMP_C`] when absent), converted with the chip's current [`Chip::settings`]; the
/// model's sensor faults act on the sample before the scaling and conversion (units: m/s²,
/// rad/s, the scene's field unit), and a dropout's sensors get the chip's invalid value.
pub fn model_image(
    model: &mut DeviceModel,
    t_ns: u64,
    truth: &Truth,
    mag_ut_per_unit: f64,
    chip: &impl Chip,
) -> Image {
    let mut s = model.sample(t_ns, truth);
    let dropout = match model.faults.as_mut() {
        Some(f) if model.sensor_faults => f.apply(t_ns, &mut s),
        _ => 0,
    };
    let sample = PhysicalSample {
        acc: s.acc,
        gyr: s.gyr,
        mag: s.mag.map(|m| (f64::from(m) * mag_ut_per_unit) as f32),
        temp_c: truth.temperature_c.unwrap_or(DEFAULT_TEMP_C),
    };
    let settings = chip.settings();
    let mut image = settings.image(&sample);
    if dropout != 0 {
        settings.mark_invalid(&mut image, dropout);
    }
    image
}

/// Whether the device can serve `source` (no perturbation in mode (b) yet).
pub fn source_supported(source: &Source) -> bool {
    match source {
        Source::Images => true,
        Source::Model(p) => p.perturbation.is_none(),
    }
}
