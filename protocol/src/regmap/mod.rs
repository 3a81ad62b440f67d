//! Register maps of the emulated chips and the one place where physical values become register
//! values (see `docs/spec/mpu9250.md`).
//!
//! - [`mpu6xxx`]: the InvenSense 6xxx family (MPU-9250 and its variants, MPU-6000, MPU-6500,
//!   ICM-20602): addresses, bits, reset values, write masks, per-part differences
//!   ([`mpu6xxx::variant`]), full scales, the output and accel rates ([`mpu6xxx::rates`]), the physical → register
//!   conversions ([`mpu6xxx::convert`]) and the register image of one sample
//!   ([`mpu6xxx::image`]);
//! - [`ak8963`]: the same for the AK8963 magnetometer die behind the MPU-9250's auxiliary bus;
//! - [`icm42688p`]: the TDK InvenSense ICM-42688-P: banks 0–4, full scales, output rates, FIFO
//!   packet sizes, conversions (16- and 20-bit) and its 32-byte register image;
//! - [`bmi270`]: the Bosch BMI270: register map, access masks, ranges, output rates, the
//!   configuration upload's registers and the conversions (little-endian data, temperature,
//!   sensor time);
//! - [`bmi088`]: the Bosch BMI088's two dies (accelerometer, gyroscope), each with its own
//!   register map, access rules, ranges, output rates and FIFO registers, and their conversions
//!   (little-endian data, 11-bit temperature, sensor time);
//! - [`ist8310`]: the iSentek IST8310 standalone I2C magnetometer;
//! - [`qmc5883l`]: the QST QMC5883L standalone I2C magnetometer;
//! - [`rm3100`]: the PNI RM3100 magneto-inductive magnetometer (I2C or SPI, 24-bit results);
//! - [`mag_image`]: the 6-byte register image the IST8310 and QMC5883L share.
//!
//! Both the firmware (which serves these values) and the host (which predicts what a driver
//! reads) call the same functions, so they agree bit for bit.
//!
//! ```
//! use margemu_protocol::regmap::mpu6xxx::image::{ImageConfig, ImageRepr};
//! let repr = ImageRepr::from_physical([0.0, 0.0, 9.80665], [0.0; 3], 21.0, [0.0; 3], &ImageConfig::NOMINAL);
//! assert_eq!(repr.accel, [0, 0, 16384]);
//! ```

pub mod ak8963;
pub mod bmi088;
pub mod bmi270;
pub mod icm42688p;
pub mod ist8310;
pub mod mag_image;
pub mod mpu6xxx;
pub mod qmc5883l;
pub mod rm3100;

pub use mpu6xxx::image::IMAGE_LEN;
