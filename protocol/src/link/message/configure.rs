//! [`Configure`]: which chip to emulate (model, identity, image length, I2C address), its output rate, initial register values, and where the
//! samples come from (register images from the host, or the on-device model with its terms).
//!
//! ```
//! use margemu_model::sensor::MargConfig;
//! use margemu_protocol::chip::ChipModel;
//! use margemu_protocol::link::{Configure, Message, ModelParams, Rate, Source};
//! // 1 kHz / (1 + SMPLRT_DIV = 2): not an integer rate, exact as a ratio.
//! let rate = Rate::new(1000, 3).unwrap();
//! assert_eq!(rate.sample_time_ns(1), 3_000_000);
//! assert_eq!(rate.sample_time_ns(2), 6_000_000);
//! let mut marg = MargConfig::default();
//! marg.gyro.errors.noise_density = Some([0.0224; 3]);
//! let cfg = Configure {
//!     source: Source::Model(ModelParams::new(42, Rate::hz(200).unwrap(), marg)),
//!     ..Configure::new(ChipModel::Mpu9250, rate)
//! };
//! let msg = Message::Configure(cfg.clone());
//! let mut buf = [0u8; 256];
//! let n = msg.emit(&mut buf)?;
//! assert_eq!(Message::parse(0x02, &buf[..n])?, Message::Configure(cfg));
//! # Ok::<(), margemu_protocol::link::Error>(())
//! ```

use margemu_model::perturbation::PerturbationConfig;
use margemu_model::sensor::MargConfig;

use super::model_terms::{
    marg_len, perturbation_len, read_marg, read_perturbation, write_marg, write_perturbation,
    MAX_MARG_CONFIG_LEN, MAX_PERTURBATION_LEN,
};
use crate::chip::ChipModel;
use crate::link::wire::{Reader, Writer};
use crate::link::{Error, MAX_PAYLOAD_LEN};

/// Most register overrides in one [`Configure`].
pub const MAX_OVERRIDES: usize = 32;

const FIXED_LEN: usize = 4 + 1 + 8 + 8 + 1;
const MODEL_FIXED_LEN: usize = 8 + 8 + 8 + 1;
/// Largest [`Configure`] payload (every model term and the perturbation present).
pub const MAX_CONFIGURE_LEN: usize =
    FIXED_LEN + 3 * MAX_OVERRIDES + MODEL_FIXED_LEN + MAX_MARG_CONFIG_LEN + MAX_PERTURBATION_LEN;
const _: () = assert!(MAX_CONFIGURE_LEN <= MAX_PAYLOAD_LEN);

/// A rate as an exact ratio `num / den` Hz (both non-zero), so that rates such as
/// 1 kHz / (1 + SMPLRT_DIV) need no rounding.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Rate {
    num: u32,
    den: u32,
}

impl Rate {
    /// `num / den` Hz; `None` if either is zero.
    pub const fn new(num: u32, den: u32) -> Option<Self> {
        if num == 0 || den == 0 {
            None
        } else {
            Some(Self { num, den })
        }
    }

    /// An integer rate in Hz; `None` if zero.
    pub const fn hz(hz: u32) -> Option<Self> {
        Self::new(hz, 1)
    }

    /// Numerator, Hz.
    pub fn num(&self) -> u32 {
        self.num
    }

    /// Denominator.
    pub fn den(&self) -> u32 {
        self.den
    }

    /// The rate in Hz, for the model's constructors.
    pub fn as_hz_f64(&self) -> f64 {
        f64::from(self.num) / f64::from(self.den)
    }

    /// Scene time of sample `index`: `floor(index · den · 10⁹ / num)` ns (saturating).
    pub fn sample_time_ns(&self, index: u64) -> u64 {
        let t = u128::from(index) * u128::from(self.den) * 1_000_000_000 / u128::from(self.num);
        u64::try_from(t).unwrap_or(u64::MAX)
    }

    fn read(r: &mut Reader<'_>) -> Result<Self, Error> {
        Self::new(r.u32()?, r.u32()?).ok_or(Error::InvalidValue)
    }

    fn write(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.u32(self.num)?;
        w.u32(self.den)
    }
}

/// An initial register value, applied after the chip's reset values through the chip's own bus
/// (e.g. a full-scale register, or a trimmed self-test or fuse ROM value).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RegisterOverride {
    /// Register file, numbered by the chip model (see
    /// [`ChipModel::register_files`](crate::chip::ChipModel::register_files)): the MPU-9250's
    /// die 0 and AK8963 1, the ICM-42688-P's banks 0–4.
    pub file: u8,
    /// Register address.
    pub register: u8,
    /// Value.
    pub value: u8,
}

/// Source mode (b): what the device needs to run the shared model itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelParams {
    /// The scene seed (every random stream of the model derives from it).
    pub seed: u64,
    /// Rate of the [`KinematicsBatch`](super::KinematicsBatch) samples the host sends.
    pub truth_rate: Rate,
    /// µT per unit of the scene's magnetic field (1 when the scene is in µT).
    pub mag_ut_per_unit: f64,
    /// The sensor model's terms.
    pub marg: MargConfig,
    /// The magnetic perturbation, if the scene has one.
    pub perturbation: Option<PerturbationConfig>,
}

impl ModelParams {
    /// `marg` with `seed` at `truth_rate`, field in µT, no perturbation.
    pub fn new(seed: u64, truth_rate: Rate, marg: MargConfig) -> Self {
        Self {
            seed,
            truth_rate,
            mag_ut_per_unit: 1.0,
            marg,
            perturbation: None,
        }
    }
}

/// Where the samples come from.
#[derive(Clone, Copy, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)] // no alloc; held once per session
pub enum Source {
    /// (a) [`ImageBatch`](super::ImageBatch)es from the host, one image per output sample.
    Images,
    /// (b) [`KinematicsBatch`](super::KinematicsBatch)es from the host and the model on the device.
    Model(ModelParams),
}

/// Host → device: configures the emulated chip and the sample source. Valid in the idle,
/// configured and stopped states; it drops buffered samples and resets the chip.
#[derive(Clone, Debug, PartialEq)]
pub struct Configure {
    /// The chip model.
    pub chip: ChipModel,
    /// The identity it answers: one of [`ChipModel::identities`].
    pub who_am_i: u8,
    /// Bytes per register image, [`ChipModel::image_len`]: the device refuses any other, so a
    /// host and a firmware that disagree on the image layout never stream.
    pub image_len: u8,
    /// Its 7-bit I2C address, one of [`ChipModel::i2c_addresses`].
    pub i2c_address: u8,
    /// Output rate: sample `i` is served at scene time [`Rate::sample_time_ns`]`(i)` (the
    /// clock set by [`Start`](super::Start)).
    pub rate: Rate,
    /// Period of unsolicited [`Telemetry`](super::Telemetry), ns (0: the device's default).
    pub telemetry_period_ns: u64,
    /// Initial register values, applied in order after reset.
    pub overrides: heapless::Vec<RegisterOverride, MAX_OVERRIDES>,
    /// Sample source.
    pub source: Source,
}

impl Configure {
    /// `chip` with its own identity at its first I2C address, at `rate`, images from the host,
    /// no overrides, default telemetry.
    pub fn new(chip: ChipModel, rate: Rate) -> Self {
        Self {
            chip,
            who_am_i: chip.who_am_i(),
            image_len: chip.image_len() as u8,
            i2c_address: chip.i2c_addresses().first().copied().unwrap_or(0),
            rate,
            telemetry_period_ns: 0,
            overrides: heapless::Vec::new(),
            source: Source::Images,
        }
    }

    pub(crate) fn buffer_len(&self) -> usize {
        let model = match &self.source {
            Source::Images => 0,
            Source::Model(m) => {
                MODEL_FIXED_LEN
                    + marg_len(&m.marg)
                    + m.perturbation.as_ref().map_or(0, perturbation_len)
            }
        };
        FIXED_LEN + 3 * self.overrides.len() + model
    }

    pub(crate) fn parse(r: &mut Reader<'_>) -> Result<Self, Error> {
        let chip = ChipModel::from_code(r.u8()?).ok_or(Error::UnknownChip)?;
        let who_am_i = r.u8()?;
        let image_len = r.u8()?;
        let i2c_address = r.u8()?;
        let source_tag = r.u8()?;
        let rate = Rate::read(r)?;
        let telemetry_period_ns = r.u64()?;
        let count = usize::from(r.u8()?);
        let mut overrides = heapless::Vec::new();
        for _ in 0..count {
            let o = RegisterOverride {
                file: r.u8()?,
                register: r.u8()?,
                value: r.u8()?,
            };
            overrides.push(o).map_err(|_| Error::InvalidValue)?;
        }
        let source = match source_tag {
            0 => Source::Images,
            1 => Source::Model(ModelParams {
                seed: r.u64()?,
                truth_rate: Rate::read(r)?,
                mag_ut_per_unit: r.f64()?,
                marg: read_marg(r)?,
                perturbation: match r.u8()? {
                    0 => None,
                    1 => Some(read_perturbation(r)?),
                    _ => return Err(Error::InvalidValue),
                },
            }),
            _ => return Err(Error::InvalidValue),
        };
        Ok(Self {
            chip,
            who_am_i,
            image_len,
            i2c_address,
            rate,
            telemetry_period_ns,
            overrides,
            source,
        })
    }

    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.bytes(&[
            self.chip.code(),
            self.who_am_i,
            self.image_len,
            self.i2c_address,
        ])?;
        w.u8(match self.source {
            Source::Images => 0,
            Source::Model(_) => 1,
        })?;
        self.rate.write(w)?;
        w.u64(self.telemetry_period_ns)?;
        // `overrides` holds at most MAX_OVERRIDES (32) entries.
        w.u8(self.overrides.len() as u8)?;
        for o in &self.overrides {
            w.bytes(&[o.file, o.register, o.value])?;
        }
        if let Source::Model(m) = &self.source {
            w.u64(m.seed)?;
            m.truth_rate.write(w)?;
            w.f64(m.mag_ut_per_unit)?;
            write_marg(w, &m.marg)?;
            match &m.perturbation {
                None => w.u8(0)?,
                Some(p) => {
                    w.u8(1)?;
                    write_perturbation(w, p)?;
                }
            }
        }
        Ok(())
    }
}
