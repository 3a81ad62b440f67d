//! The chip boundary: which chips margemu emulates, and the one face every chip module shows to
//! the link, the host's prediction, the logs and the evaluation.
//!
//! - [`ChipModel`]: the emulated models, each with its wire code, name, identities (WHO_AM_I
//!   variants), buses, I2C addresses, register files and image length;
//! - [`Image`]: one sample's register image as the link carries it, of the model's length (at
//!   most [`MAX_IMAGE_LEN`] bytes), opaque outside the chip's module;
//! - [`PhysicalSample`]: what the chip's sensors see, in the chip's axes;
//! - [`ChipSettings`]: the register settings a conversion depends on (full scales, offsets), with
//!   physical → image ([`ChipSettings::image`]) and image → physical
//!   ([`ChipSettings::decode`]); the host predicts with it, the firmware converts with it, the
//!   evaluation decodes with it.
//!
//! Only the chip modules ([`crate::regmap::mpu6xxx`], [`crate::regmap::ak8963`],
//! [`crate::regmap::icm42688p`], [`crate::regmap::bmi270`], [`crate::regmap::bmi088`], the
//! magnetometers') name registers; this module dispatches to them.
//!
//! ```
//! use margemu_protocol::chip::{ChipModel, ChipSettings, PhysicalSample};
//! let model = ChipModel::from_name("mpu9250").unwrap();
//! assert_eq!((model.who_am_i(), model.image_len()), (0x71, 22));
//! let settings = ChipSettings::power_on(model);
//! let at_rest = PhysicalSample { acc: [0.0, 0.0, 9.80665], temp_c: 21.0, ..Default::default() };
//! let image = settings.image(&at_rest);
//! assert_eq!(&image[4..6], &[0x40, 0x00]); // +1 g on z at ±2 g, big-endian
//! let reading = settings.decode(&image).unwrap();
//! assert!((reading.acc[2] - 9.80665).abs() < 1e-3);
//! ```

pub mod chain;
mod image;
pub mod invalid;
mod model;
mod settings;

pub use chain::{ChainConfig, ChainError, ChipChain, SensorChain};
pub use image::{Image, MAX_CHIP_IMAGE_LEN, MAX_IMAGE_LEN};
pub use model::{ChipModel, Family};
pub use settings::{ChipSettings, Conversion, FullScale, MagRangeError, Reading, SettingsError};

/// One physical sample as the chip's sensors would see it, in the chip's accel/gyro axes (each
/// chip applies its own internal axis quirks, such as the AK8963's, itself).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhysicalSample {
    /// Specific force (m/s²).
    pub acc: [f32; 3],
    /// Angular rate (rad/s).
    pub gyr: [f32; 3],
    /// Magnetic field (µT); ignored by chips without a magnetometer.
    pub mag: [f32; 3],
    /// Die temperature (°C).
    pub temp_c: f32,
}
