//! The FIFO record a flight controller reads a MARG sample from (RM-MPU-9250A-00 registers 35
//! FIFO_EN, 114–116 FIFO_COUNT and FIFO_R_W; PS-MPU-9250A-01 section 4.17).
//!
//! With FIFO_EN = [`FIFO_EN_MARG`] (temperature, gyro X/Y/Z, accel, slave 0) and slave 0 reading
//! the AK8963's seven bytes HXL..=HZH, ST2 (I2C_SLV0_REG = HXL, length 7), each sample appends
//! one record of [`MARG_RECORD_LEN`] bytes: the 14 bytes of registers 0x3B..=0x48 (accel,
//! temperature, gyro, big-endian), then the seven AK8963 bytes as slave 0 read them at that
//! sample. A FIFO of `n` bytes holds `n / 21` whole records (24 in the MPU-9250's 512);
//! [`ImageRepr::parse_marg_record`](super::image::ImageRepr::parse_marg_record) decodes one.
//!
//! ```
//! use margemu_protocol::regmap::mpu6xxx::fifo::{whole_records, FIFO_EN_MARG, MARG_RECORD_LEN};
//! use margemu_protocol::regmap::mpu6xxx::image::{ImageConfig, ImageRepr};
//! assert_eq!(FIFO_EN_MARG, 0xF9);
//! assert_eq!(whole_records(3 * MARG_RECORD_LEN as u16), Some(3));
//! assert_eq!(whole_records(22), None); // a record cut by an overflow
//! let cfg = ImageConfig::default();
//! let repr = ImageRepr::from_physical([0.0, 0.0, 9.80665], [0.0; 3], 21.0, [0.6, 0.0, 0.0], &cfg);
//! let image = repr.emit();
//! let mut record = [0u8; MARG_RECORD_LEN];
//! record[..14].copy_from_slice(&image[..14]);
//! record[14..].copy_from_slice(&image[15..]); // slave 0 starts at HXL: no ST1
//! assert_eq!(ImageRepr::parse_marg_record(&record), repr);
//! ```

use super::bits;

/// Bytes slave 0 reads from the AK8963 per sample: HXL..=HZH and ST2 (reading ST2 ends the
/// measurement's read, as the AK8963 requires).
pub const SLV0_LEN: usize = 7;

/// One MARG record: registers 0x3B..=0x48, then [`SLV0_LEN`] AK8963 bytes.
pub const MARG_RECORD_LEN: usize = 14 + SLV0_LEN;

/// FIFO_EN for a MARG record: temperature, gyro X, Y, Z, accel and slave 0.
pub const FIFO_EN_MARG: u8 = bits::FIFO_TEMP
    | bits::FIFO_GYRO_X
    | bits::FIFO_GYRO_Y
    | bits::FIFO_GYRO_Z
    | bits::FIFO_ACCEL
    | (bits::FIFO_SLV2 >> 2);

/// The whole MARG records in a FIFO holding `count` bytes (FIFO_COUNT); `None` when `count` is
/// not a whole number of records (a record was cut: the FIFO overflowed, or its content is not
/// this layout).
pub const fn whole_records(count: u16) -> Option<usize> {
    let count = count as usize;
    match count % MARG_RECORD_LEN {
        0 => Some(count / MARG_RECORD_LEN),
        _ => None,
    }
}
