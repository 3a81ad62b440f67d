//! Each chip family's sampling chain, declared from its datasheet: the internal rate each sensor
//! samples at, its range, its digital filters as one [`FilterDesign`] at that rate, and the
//! output period. The runner (`margemu_model::chain`) samples at the internal rate, clips at
//! the range, filters and decimates to the output rate; this module only declares.
//!
//! **Modelling rule.** Each row of a datasheet table (a configuration code) becomes a low-pass
//! whose −3 dB point is the table's bandwidth: a 2nd-order Butterworth, or a first-order one
//! where the 2nd-order's own low-frequency delay already exceeds the table's delay by more than
//! half an internal sample; then a pure delay of whole internal samples,
//! `round((table delay − filter delay) · rate)`, makes the total match the table's delay within
//! half a sample. Where even the first-order filter's delay exceeds the table's (rows listed
//! below), the row keeps the first-order filter and no added delay: no causal low-pass with that
//! −3 dB point is as fast as the table says.
//!
//! **InvenSense 6xxx** ([`tables`]): gyro rows from RM-MPU-6500A rev. 2.1 / RM-MPU-9250A rev.
//! 1.6 section 4.6 (FCHOICE_B / DLPF_CFG), DS-000176 (ICM-20602) section 10.2 table 2, and
//! RM-MPU-6000A rev. 4.2 section 4.3 (CONFIG); accel rows from section 4.8 (A_DLPF_CFG /
//! ACCEL_FCHOICE_B), DS-000176 table 3, and the MPU-6000's one table (its accelerometer at
//! 1 kHz). Exact: −3 dB points and delays (except the rows below), register rates (taken from
//! [`crate::regmap::mpu6xxx::rates`], not repeated here), the SMPLRT_DIV rule for the output
//! rate. The DLPF filters the ADC's samples before the register rate drops to 1 kHz, so the
//! gyro's filter runs at 8 kHz and the accelerometer's at 4 kHz (the rate ACCEL_FCHOICE_B
//! exposes); the MPU-6000's accelerometer ADC rate is not documented and stays at 1 kHz. Approximated: the filter's shape (the datasheets give only −3 dB and delay). Delays
//! not met: MPU-6000 DLPF_CFG 5 and 6, gyro and accel.
//!
//! **ICM-42688-P** (DS-000347 rev. 1.7): both sensors sample at 32 kHz; the anti-alias filter
//! (section 5.3, 2nd order, −3 dB per AAF_DELT from its table, exact) runs there; the UI
//! filter (section 5.5, order 1–3, bandwidth index of GYRO_ACCEL_CONFIG0: ODR/2 or
//! max(400 Hz, ODR)/4 … /40) is modelled as a Butterworth of that order at that −3 dB, run at
//! 32 kHz instead of after the decimation to the ODR (approximation), and left out where its
//! bandwidth reaches 0.45 × 32 kHz. The low-latency indices 14 and 15 (the Dec2 decimation
//! filter, whose response the datasheet does not give) are modelled as no filter. No delays
//! are given; the chain's delay is the design's.
//!
//! **BMI088** (BST-BMI088-DS001 rev. 1.3): gyro GYRO_BANDWIDTH (section 5.5.5: ODR and filter
//! together, exact −3 dB) at its ODR; accel ACC_CONF acc_bwp at the accel ODR at or below the
//! output rate, normal-mode −3 dB per ODR from section 4.4.1 (exact), OSR2 and OSR4 as the
//! normal figure at half and a quarter the ODR (derived). No delays are given.
//!
//! **BMI270** (BST-BMI270-DS000 rev. 1.3): APPROXIMATION throughout: the per-ODR table was not
//! at hand, so the −3 dB is a fixed fraction of the ODR from the datasheet's key features
//! (accel 740 Hz at 1.6 kHz, gyro 751 Hz at 3.2 kHz, normal mode), halved for OSR2 and
//! quartered for OSR4; filter_perf is stored but changes nothing here.
//!
//! ```
//! use margemu_protocol::chip::{ChainConfig, ChipChain, ChipModel, ChipSettings};
//! use margemu_protocol::link::Rate;
//! let model = ChipModel::Mpu6500;
//! let rate = Rate::hz(1000).unwrap();
//! let config = ChainConfig::default_for(model, rate).unwrap(); // DLPF_CFG 1: 184 Hz
//! let chain = ChipChain::new(&ChipSettings::power_on(model), &config, rate)?;
//! // The DLPF runs on the 8 kHz ADC samples; the registers update at 1 kHz.
//! assert_eq!((chain.gyro.period_ns, chain.output_period_ns), (125_000, 1_000_000));
//! assert_eq!(chain.gyro.bandwidth_hz, 184.0);
//! assert!((chain.gyro.filter.gain_at(184.0) - 0.7071).abs() < 1e-3);
//! assert!((chain.gyro.filter.delay_s() - 2.9e-3).abs() <= 0.5e-3);
//! # Ok::<(), margemu_protocol::chip::ChainError>(())
//! ```

mod build;
pub use build::row_design;
mod config;
pub mod tables;

pub use config::{ChainConfig, MAX_ENCODED_LEN};
pub use margemu_model::chain::filter::FilterDesign;

use crate::chip::{ChipModel, ChipSettings};
use crate::link::Rate;
use core::fmt;

/// One sensor's chain: internal sampling, range, filters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorChain {
    /// The internal sample period, ns.
    pub period_ns: u64,
    /// Every digital filter up to the output, at `1e9 / period_ns` Hz.
    pub filter: FilterDesign,
    /// The front end's range, ± m/s² or ± rad/s (the configured full scale).
    pub range: f32,
    /// The −3 dB bandwidth of this configuration, Hz (the datasheet's where it gives one for
    /// the whole path, else the design's).
    pub bandwidth_hz: f64,
    /// The delay of this configuration, s (the datasheet's where it gives one, else the
    /// design's low-frequency delay).
    pub delay_s: f64,
}

/// A chip's two chains and its output period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChipChain {
    /// The accelerometer.
    pub accel: SensorChain,
    /// The gyroscope.
    pub gyro: SensorChain,
    /// The output (data ready) period, ns: a whole number of gyro periods.
    pub output_period_ns: u64,
}

/// Why a chain cannot be built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ChainError {
    /// A code is outside its register field.
    CodeOutOfRange {
        /// The setting's key.
        field: &'static str,
        /// The code given.
        value: u8,
        /// The codes allowed.
        allowed: &'static str,
    },
    /// A code the register has, but this model does not (or reserves).
    NotForModel {
        /// The setting's key.
        field: &'static str,
        /// The code given.
        value: u8,
        /// The model.
        model: ChipModel,
        /// The codes allowed on it, and why.
        allowed: &'static str,
    },
    /// The configuration cannot produce the output rate.
    OutputRate {
        /// The output rate asked for, Hz.
        rate_hz: f64,
        /// The setting that decides the rate.
        field: &'static str,
        /// Its code.
        value: u8,
        /// The rates it can give.
        allowed: &'static str,
    },
    /// The settings are another family's.
    WrongFamily {
        /// The model.
        model: ChipModel,
        /// The keys its family takes.
        keys: &'static [&'static str],
    },
    /// A magnetometer has no sampling chain.
    NoChain {
        /// The model.
        model: ChipModel,
    },
    /// A filter design failed (a table row outside the design's limits).
    Design(margemu_model::Error),
    /// Bytes that [`ChainConfig::encode`] did not write.
    Malformed,
}

impl fmt::Display for ChainError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::CodeOutOfRange {
                field,
                value,
                allowed,
            } => {
                write!(
                    f,
                    "filters: {field} = {value} is out of range (allowed: {allowed})"
                )
            }
            Self::NotForModel {
                field,
                value,
                model,
                allowed,
            } => write!(
                f,
                "filters: {field} = {value} does not fit the {} (allowed: {allowed})",
                model.part_name()
            ),
            Self::OutputRate {
                rate_hz,
                field,
                value,
                allowed,
            } => write!(
                f,
                "filters: output rate {rate_hz} Hz cannot be produced with {field} = {value} \
                 ({allowed})"
            ),
            Self::WrongFamily { model, keys } => {
                write!(f, "filters: the {} takes the keys ", model.part_name())?;
                for (i, key) in keys.iter().enumerate() {
                    let sep = if i == 0 { "" } else { ", " };
                    write!(f, "{sep}{key}")?;
                }
                Ok(())
            }
            Self::NoChain { model } => {
                write!(
                    f,
                    "filters: the {} has no sampling chain",
                    model.part_name()
                )
            }
            Self::Design(e) => write!(f, "filters: {e}"),
            Self::Malformed => f.write_str("filters: malformed settings bytes"),
        }
    }
}

impl core::error::Error for ChainError {}

impl From<margemu_model::Error> for ChainError {
    fn from(e: margemu_model::Error) -> Self {
        Self::Design(e)
    }
}

impl ChipChain {
    /// The chains of `settings.model` under `config` at `output_rate` (see the module docs).
    pub fn new(
        settings: &ChipSettings,
        config: &ChainConfig,
        output_rate: Rate,
    ) -> Result<Self, ChainError> {
        let model = settings.model;
        let fs = settings.full_scale().ok_or(ChainError::NoChain { model })?;
        if config.family() != model.family() {
            return Err(ChainError::WrongFamily {
                model,
                keys: ChainConfig::keys(model.family()),
            });
        }
        let accel_range =
            (fs.accel_g * f64::from(crate::regmap::mpu6xxx::convert::STANDARD_GRAVITY)) as f32;
        let gyro_range = fs.gyro_dps.to_radians() as f32;
        let out_ns = period_of(output_rate);
        let mut chain = build::chains(model, config, output_rate.as_hz_f64(), out_ns)?;
        chain.accel.range = accel_range;
        chain.gyro.range = gyro_range;
        Ok(chain)
    }
}

/// The period of `rate` in ns, rounded to the nearest ns (a scene's 1000/3 Hz given in mHz
/// still finds the chip's 3 ms); 0 for a rate above 2 GHz.
fn period_of(rate: Rate) -> u64 {
    let num = u128::from(rate.num());
    let ns = u128::from(rate.den()) * 1_000_000_000;
    u64::try_from((ns + num / 2) / num.max(1)).unwrap_or(0)
}
