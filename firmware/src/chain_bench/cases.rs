//! The cases' chips, paths and vibration.
//!
//! Each family runs at the output rate flight controllers use it at, with its declared chain
//! ([`ChipChain`]: internal rates, filters as [`ChainConfig::default_for`] that rate) at the
//! widest full scales (16 g, 24 g for the BMI088; 2000 °/s). The internal rates
//! ([`Family::internal_periods_ns`], checked against the declared chain by the tests): the
//! ICM-20602's ADC at 8 kHz (gyro) and 4 kHz (accelerometer, ACCEL_FCHOICE_B = 1); the
//! ICM-42688-P's both at 32 kHz; the BMI270's gyro at 3.2 kHz, accelerometer at 1.6 kHz; the
//! BMI088's gyro at 2 kHz, accelerometer at 1.6 kHz.

use core::fmt;

use margemu_model::chain::{DeviceChain, SensorPath};
use margemu_model::perturbation::Complex;
use margemu_model::sensor::MargConfig;
use margemu_model::vibration::{
    Harmonic, PsdPoint, RandomSource, RpmPoint, Sense, Shock, ToneSource, Vibration,
};
use margemu_model::Error;
use margemu_protocol::chip::{ChainConfig, ChipChain, ChipModel, ChipSettings, FullScale};
use margemu_protocol::chip::{ChainError, SensorChain};
use margemu_protocol::link::Rate;

use super::{BenchError, Case, DURATION_NS, SEED};

/// Complex values of random-vibration buffer the largest [`Path::InternalRandom`] case needs
/// (the ICM-42688-P's 32 kHz accelerometer: 5120-point blocks; 16 bytes each, 560 KiB).
pub const RANDOM_BUFFER_LEN: usize = 35_840;

/// A case's chain type: static rpm profile, the caller's random buffer.
pub(super) type BenchChain<'a> = DeviceChain<&'static [RpmPoint], &'a mut [Complex]>;
type BenchPath<'a> = SensorPath<&'static [RpmPoint], &'a mut [Complex]>;

/// The chip families benchmarked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// InvenSense 6xxx: the ICM-20602 at 8 kHz (accelerometer 4 kHz).
    Icm20602,
    /// ICM-42688-P at 8 kHz (both sensors 32 kHz inside).
    Icm42688p,
    /// BMI270 at 3.2 kHz (accelerometer 1.6 kHz).
    Bmi270,
    /// BMI088 at 2 kHz (accelerometer 1.6 kHz).
    Bmi088,
}

impl Family {
    /// Every family, in [`super::CASES`] order.
    pub const ALL: [Self; 4] = [Self::Icm20602, Self::Icm42688p, Self::Bmi270, Self::Bmi088];

    /// The chip model.
    pub fn model(self) -> ChipModel {
        match self {
            Self::Icm20602 => ChipModel::Icm20602,
            Self::Icm42688p => ChipModel::Icm42688p,
            Self::Bmi270 => ChipModel::Bmi270,
            Self::Bmi088 => ChipModel::Bmi088,
        }
    }

    /// The output (data-ready) period, ns.
    pub fn output_period_ns(self) -> u64 {
        match self {
            Self::Icm20602 | Self::Icm42688p => 125_000,
            Self::Bmi270 => 312_500,
            Self::Bmi088 => 500_000,
        }
    }

    /// The output rate, Hz.
    pub fn output_rate_hz(self) -> f64 {
        1e9 / self.output_period_ns() as f64
    }

    /// The internal sample periods (accelerometer, gyroscope), ns.
    pub fn internal_periods_ns(self) -> [u64; 2] {
        match self {
            Self::Icm20602 => [250_000, 125_000],
            Self::Icm42688p => [31_250, 31_250],
            Self::Bmi270 => [625_000, 312_500],
            Self::Bmi088 => [625_000, 500_000],
        }
    }

    /// The chip's declared chain at its output rate: the family's default filter settings at
    /// that rate, the widest full scales.
    pub fn declared(self) -> Result<ChipChain, BenchError> {
        let model = self.model();
        let hz = (1e9 / self.output_period_ns() as f64) as u32;
        let rate = Rate::hz(hz).ok_or(ChainError::NoChain { model })?;
        let config = ChainConfig::default_for(model, rate).ok_or(ChainError::NoChain { model })?;
        let accel_g = if self == Self::Bmi088 { 24.0 } else { 16.0 };
        let fs = FullScale {
            accel_g,
            gyro_dps: 2000.0,
        };
        let settings = ChipSettings::with_full_scale(model, fs).map_err(BenchError::Settings)?;
        Ok(ChipChain::new(&settings, &config, rate)?)
    }
}

impl fmt::Display for Family {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Icm20602 => "icm20602",
            Self::Icm42688p => "icm42688p",
            Self::Bmi270 => "bmi270",
            Self::Bmi088 => "bmi088",
        })
    }
}

/// The path through the chain and the vibration a case runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Path {
    /// The output path, nothing vibrating.
    Output,
    /// The output path with the motor tones.
    OutputTones,
    /// The internal path, nothing vibrating.
    Internal,
    /// The internal path with the motor tones and a shock.
    InternalTonesShock,
    /// The internal path with random vibration (the accelerometer's only).
    InternalRandom,
}

impl Path {
    /// Every path, in [`super::CASES`] order within a family.
    pub const ALL: [Self; 5] = [
        Self::Output,
        Self::OutputTones,
        Self::Internal,
        Self::InternalTonesShock,
        Self::InternalRandom,
    ];

    /// Whether the path runs the internal rate.
    pub fn is_internal(self) -> bool {
        matches!(
            self,
            Self::Internal | Self::InternalTonesShock | Self::InternalRandom
        )
    }

    /// Whether anything vibrates.
    pub fn vibrates(self) -> bool {
        !matches!(self, Self::Output | Self::Internal)
    }
}

impl fmt::Display for Path {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Output => "output",
            Self::OutputTones => "output+tones",
            Self::Internal => "internal",
            Self::InternalTonesShock => "internal+tones+shock",
            Self::InternalRandom => "internal+random",
        })
    }
}

/// The motors' rpm: a ramp from 6000 to 24 000 rpm over the case (100 to 400 Hz).
static PROFILE: [RpmPoint; 2] = [
    RpmPoint {
        t_ns: 0,
        rpm: 6000.0,
    },
    RpmPoint {
        t_ns: DURATION_NS,
        rpm: 24_000.0,
    },
];

/// Four motors within ±3 % of the ramp, the rotation and the blade pass (2 blades), per motor.
fn tones() -> Result<ToneSource<&'static [RpmPoint]>, Error> {
    let mut tones = ToneSource::new(4, &PROFILE[..]);
    tones.spread = 0.03;
    tones.push(Harmonic {
        order: 1.0,
        linear: [6.0, 4.0, 10.0],
        angular: [0.4, 0.4, 0.2],
    })?;
    tones.push(Harmonic {
        order: 2.0,
        linear: [3.0, 3.0, 6.0],
        angular: [0.2, 0.2, 0.1],
    })?;
    Ok(tones)
}

/// A 2 ms half-sine at a quarter of the case, beyond both front ends' ranges on one axis.
const SHOCK: Shock = Shock {
    t_ns: DURATION_NS / 4,
    duration_ns: 2_000_000,
    linear: [20.0, 0.0, 300.0],
    angular: [40.0, 0.0, 5.0],
};

/// Broadband vibration, 100 Hz to 2 kHz (about 1.5 g rms where the internal rate passes it).
fn random() -> Result<RandomSource, Error> {
    RandomSource::new(&[
        PsdPoint {
            f_hz: 100.0,
            g2_per_hz: 0.002,
        },
        PsdPoint {
            f_hz: 1000.0,
            g2_per_hz: 0.002,
        },
        PsdPoint {
            f_hz: 2000.0,
            g2_per_hz: 0.0005,
        },
    ])
}

/// The sensor model's terms: white noise only (ICM-42688-P-like densities).
pub(super) fn noise() -> MargConfig {
    let mut cfg = MargConfig::default();
    cfg.gyro.errors.noise_density = Some([4.9e-5; 3]);
    cfg.accel.errors.noise_density = Some([6.9e-4; 3]);
    cfg
}

/// The chain of `case`, `buffer` lent to the accelerometer's random synthesis if it has one.
pub(super) fn chain<'a>(
    case: &Case,
    buffer: &'a mut [Complex],
) -> Result<BenchChain<'a>, BenchError> {
    let declared = case.family.declared()?;
    let accel = path(case, Sense::Linear, &declared.accel, Some(buffer))?;
    let gyro = path(case, Sense::Angular, &declared.gyro, None)?;
    Ok(DeviceChain { accel, gyro })
}

fn path<'a>(
    case: &Case,
    sense: Sense,
    declared: &SensorChain,
    buffer: Option<&'a mut [Complex]>,
) -> Result<BenchPath<'a>, Error> {
    let period = match case.path.is_internal() {
        true => declared.period_ns,
        false => case.family.output_period_ns(),
    };
    let mut vibration = Vibration::new(sense, period, SEED);
    match case.path {
        Path::Output | Path::Internal => {}
        Path::OutputTones => vibration.add_tones(tones()?)?,
        Path::InternalTonesShock => {
            vibration.add_tones(tones()?)?;
            vibration.add_shock(&SHOCK)?;
        }
        Path::InternalRandom => {
            if let (Sense::Linear, Some(buffer)) = (sense, buffer) {
                vibration.add_random(&random()?, buffer)?;
            }
        }
    }
    if case.path.is_internal() {
        SensorPath::new(period, declared.filter, declared.range, vibration)
    } else {
        SensorPath::at_output(declared.range, vibration)
    }
}

/// The random-vibration buffer `case` needs, complex values (0 without random vibration).
pub fn random_buffer_len(case: &Case) -> Result<usize, Error> {
    match case.path {
        Path::InternalRandom => {
            let [accel_ns, _] = case.family.internal_periods_ns();
            random()?.buffer_len(1e9 / accel_ns as f64)
        }
        _ => Ok(0),
    }
}
