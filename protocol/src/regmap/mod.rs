//! Register maps of the emulated chips and the one place where physical values become register
//! values (see `docs/spec/mpu9250.md`).
//!
//! - [`mpu9250`]: addresses, bits, reset values, write masks, full scales and the output-rate
//!   rule of the MPU-9250 accel/gyro die;
//! - [`ak8963`]: the same for its AK8963 magnetometer die;
//! - [`convert`]: physical (SI, µT) → register values, rounding to nearest and saturating;
//! - [`image`]: the 22-byte register image of one sample ([`image::IMAGE_LEN`]), the unit the
//!   link carries in source mode (a) and the firmware computes from a physical sample.
//!
//! Both the firmware (which serves these values) and the host (which predicts what a driver
//! reads) call the same functions, so they agree bit for bit.
//!
//! ```
//! use margemu_protocol::regmap::image::{ImageConfig, ImageRepr};
//! let repr = ImageRepr::from_physical([0.0, 0.0, 9.80665], [0.0; 3], 21.0, [0.0; 3], &ImageConfig::NOMINAL);
//! assert_eq!(repr.accel, [0, 0, 16384]);
//! ```

pub mod ak8963;
pub mod convert;
pub mod image;
pub mod mpu9250;

pub use image::IMAGE_LEN;
