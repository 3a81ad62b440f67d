//! The TDK InvenSense ICM-42688-P (accel + gyro + temperature): register addresses of user banks
//! 0–4, bits, reset values, access masks, full scales and output rates (datasheet DS-000347
//! rev. 1.7, "DS" below: the register map and the register descriptions of user banks 0–4).
//! Sections are cited by title; the numbers we could check in rev. 1.7 are 4.11 Sensor Data
//! Registers, 4.12 Interrupts, 4.13 Digital-Output Temperature Sensor, 4.16 Standard Power
//! Modes, 5.3 Anti-Alias Filter and 5.5 UI Filter Block.
//!
//! Registers are named by `(bank, addr)`: REG_BANK_SEL (0x76, present in every bank) selects the
//! bank that addresses 0x00..=0x7F reach. Addresses that the datasheet does not list are
//! reserved: they read 0 and ignore writes. Listed registers keep their reserved bits at the
//! reset value ([`write_mask`]); read-only registers ignore writes ([`is_read_only`]); the
//! action bits of DEVICE_CONFIG and SIGNAL_PATH_RESET read back 0 ([`self_clearing_mask`]).
//!
//! Reset values are the datasheet's (DS register map); the factory-trimmed registers (gyro notch
//! coefficients GYRO_CONFIG_STATIC6..9 and the self-test data) hold the fixed values of this
//! emulated part ([`FACTORY_TRIM`]). Bank 3 is not tabulated in the datasheet; only CLKDIV
//! (0x2A, named by Zephyr's `icm42688_reg.h`) is kept, reset value 0x00 assumed.
//!
//! Write masks keep the bit fields the register descriptions name; where a description names
//! none (bank 4 APEX, thresholds and offsets) every bit is writable. The reset values were
//! cross-checked with register headers that transcribe the datasheet table (e.g. the
//! `ICM42688.h` headers quoting "Serial IF … Reset value" per register).
//!
//! Cross-checked against Zephyr `drivers/sensor/tdk/icm42688/icm42688_reg.h` (Apache-2.0) and
//! the register lists of PX4 `InvenSense_ICM42688P_registers.hpp`; no code was taken from them.
//!
//! ```
//! use margemu_protocol::regmap::icm42688p::{bank0, reset_value, write_mask, AccelFs, Odr};
//! assert_eq!(reset_value(0, bank0::WHO_AM_I), 0x47);
//! assert_eq!(reset_value(0, bank0::INTF_CONFIG1), 0x91);
//! assert_eq!(write_mask(0, bank0::FIFO_CONFIG), 0xC0);
//! assert_eq!(AccelFs::from_accel_config0(0x66), AccelFs::G2);
//! assert_eq!(Odr::from_config0(0x06).map(Odr::period_ns), Some(1_000_000));
//! ```

mod access;
pub mod convert;
pub mod image;
mod scale;

pub use access::{
    is_defined, is_read_only, next_address, reset_value, self_clearing_mask, write_mask,
    FACTORY_TRIM,
};
pub use scale::{AccelFs, GyroFs, Odr};

/// REG_BANK_SEL, at the same address in every bank (DS: REG_BANK_SEL).
pub const REG_BANK_SEL: u8 = 0x76;

/// Number of user banks (0..=4).
pub const BANKS: u8 = 5;

/// FIFO size in bytes (DS: FIFO, 2 KB).
pub const FIFO_SIZE: usize = 2048;

/// User bank 0 (DS: user bank 0 register descriptions): configuration, data, FIFO and interrupts.
pub mod bank0 {
    /// SPI_MODE (bit 4), SOFT_RESET_CONFIG (bit 0).
    pub const DEVICE_CONFIG: u8 = 0x11;
    /// I2C and SPI slew rates.
    pub const DRIVE_CONFIG: u8 = 0x13;
    /// INT1/INT2 mode, drive circuit and polarity.
    pub const INT_CONFIG: u8 = 0x14;
    /// FIFO_MODE (bits 7:6).
    pub const FIFO_CONFIG: u8 = 0x16;
    /// Temperature, high byte (big-endian order; INTF_CONFIG0 can swap).
    pub const TEMP_DATA1: u8 = 0x1D;
    /// Temperature, low byte.
    pub const TEMP_DATA0: u8 = 0x1E;
    /// Accel X high byte; Y and Z follow at 0x21 and 0x23.
    pub const ACCEL_DATA_X1: u8 = 0x1F;
    /// Gyro X high byte; Y and Z follow at 0x27 and 0x29.
    pub const GYRO_DATA_X1: u8 = 0x25;
    /// Gyro Z low byte: the last data register.
    pub const GYRO_DATA_Z0: u8 = 0x2A;
    /// FSYNC timestamp, high byte.
    pub const TMST_FSYNCH: u8 = 0x2B;
    /// FSYNC timestamp, low byte.
    pub const TMST_FSYNCL: u8 = 0x2C;
    /// Interrupt status, cleared on read.
    pub const INT_STATUS: u8 = 0x2D;
    /// FIFO count, first byte (high byte in big-endian order).
    pub const FIFO_COUNTH: u8 = 0x2E;
    /// FIFO count, second byte.
    pub const FIFO_COUNTL: u8 = 0x2F;
    /// FIFO read port: bursts stay on it.
    pub const FIFO_DATA: u8 = 0x30;
    /// APEX data 0 (first of six).
    pub const APEX_DATA0: u8 = 0x31;
    /// APEX data 3.
    pub const APEX_DATA3: u8 = 0x34;
    /// APEX data 5.
    pub const APEX_DATA5: u8 = 0x36;
    /// Wake-on-motion / SMD status, cleared on read.
    pub const INT_STATUS2: u8 = 0x37;
    /// APEX status, cleared on read.
    pub const INT_STATUS3: u8 = 0x38;
    /// FIFO flush, timestamp strobe, abort and reset (write 1 to act).
    pub const SIGNAL_PATH_RESET: u8 = 0x4B;
    /// Endianness, FIFO count format, interface selection.
    pub const INTF_CONFIG0: u8 = 0x4C;
    /// AFSR (bits 7:6), accel LP clock, RTC mode, clock selection.
    pub const INTF_CONFIG1: u8 = 0x4D;
    /// TEMP_DIS, IDLE, GYRO_MODE, ACCEL_MODE.
    pub const PWR_MGMT0: u8 = 0x4E;
    /// GYRO_FS_SEL (7:5), GYRO_ODR (3:0).
    pub const GYRO_CONFIG0: u8 = 0x4F;
    /// ACCEL_FS_SEL (7:5), ACCEL_ODR (3:0).
    pub const ACCEL_CONFIG0: u8 = 0x50;
    /// Temperature filter, gyro UI filter order.
    pub const GYRO_CONFIG1: u8 = 0x51;
    /// Accel and gyro UI filter bandwidths.
    pub const GYRO_ACCEL_CONFIG0: u8 = 0x52;
    /// Accel UI filter order.
    pub const ACCEL_CONFIG1: u8 = 0x53;
    /// Timestamp configuration.
    pub const TMST_CONFIG: u8 = 0x54;
    /// APEX configuration.
    pub const APEX_CONFIG0: u8 = 0x56;
    /// Wake-on-motion / significant motion configuration.
    pub const SMD_CONFIG: u8 = 0x57;
    /// FIFO packet contents.
    pub const FIFO_CONFIG1: u8 = 0x5F;
    /// FIFO watermark, bits 7:0.
    pub const FIFO_CONFIG2: u8 = 0x60;
    /// FIFO watermark, bits 11:8.
    pub const FIFO_CONFIG3: u8 = 0x61;
    /// FSYNC configuration.
    pub const FSYNC_CONFIG: u8 = 0x62;
    /// How the interrupt status bits clear.
    pub const INT_CONFIG0: u8 = 0x63;
    /// Pulse duration, de-assert duration, async reset.
    pub const INT_CONFIG1: u8 = 0x64;
    /// Interrupt sources routed to INT1.
    pub const INT_SOURCE0: u8 = 0x65;
    /// More INT1 sources (wake on motion, SMD).
    pub const INT_SOURCE1: u8 = 0x66;
    /// Interrupt sources routed to INT2.
    pub const INT_SOURCE3: u8 = 0x68;
    /// More INT2 sources.
    pub const INT_SOURCE4: u8 = 0x69;
    /// Packets lost, low byte.
    pub const FIFO_LOST_PKT0: u8 = 0x6C;
    /// Packets lost, high byte.
    pub const FIFO_LOST_PKT1: u8 = 0x6D;
    /// Self-test enables.
    pub const SELF_TEST_CONFIG: u8 = 0x70;
    /// Identity (0x47).
    pub const WHO_AM_I: u8 = 0x75;
}

/// User bank 1 (DS: user bank 1): gyro notch and anti-alias filter, timestamp, interface.
pub mod bank1 {
    /// Per-axis sensor disables.
    pub const SENSOR_CONFIG0: u8 = 0x03;
    /// GYRO_AAF_DIS (bit 1), GYRO_NF_DIS (bit 0).
    pub const GYRO_CONFIG_STATIC2: u8 = 0x0B;
    /// GYRO_AAF_DELT.
    pub const GYRO_CONFIG_STATIC3: u8 = 0x0C;
    /// GYRO_AAF_DELTSQR bits 7:0.
    pub const GYRO_CONFIG_STATIC4: u8 = 0x0D;
    /// GYRO_AAF_BITSHIFT, GYRO_AAF_DELTSQR bits 11:8.
    pub const GYRO_CONFIG_STATIC5: u8 = 0x0E;
    /// Notch X coefficient (factory trim).
    pub const GYRO_CONFIG_STATIC6: u8 = 0x0F;
    /// Notch Y coefficient (factory trim).
    pub const GYRO_CONFIG_STATIC7: u8 = 0x10;
    /// Notch Z coefficient (factory trim).
    pub const GYRO_CONFIG_STATIC8: u8 = 0x11;
    /// Notch coefficient high bits and selects (factory trim).
    pub const GYRO_CONFIG_STATIC9: u8 = 0x12;
    /// Notch bandwidth.
    pub const GYRO_CONFIG_STATIC10: u8 = 0x13;
    /// Gyro X self-test data (factory).
    pub const XG_ST_DATA: u8 = 0x5F;
    /// Gyro Z self-test data (factory).
    pub const ZG_ST_DATA: u8 = 0x61;
    /// Timestamp value bits 7:0 (read only).
    pub const TMSTVAL0: u8 = 0x62;
    /// Timestamp value bits 19:16 (read only).
    pub const TMSTVAL2: u8 = 0x64;
    /// I3C bus mode, SPI 3/4 wire.
    pub const INTF_CONFIG4: u8 = 0x7A;
    /// PIN9_FUNCTION (INT2 / FSYNC / CLKIN).
    pub const INTF_CONFIG5: u8 = 0x7B;
    /// I3C enables.
    pub const INTF_CONFIG6: u8 = 0x7C;
}

/// User bank 2 (DS: user bank 2): accel anti-alias filter and self-test data.
pub mod bank2 {
    /// ACCEL_AAF_DELT (6:1), ACCEL_AAF_DIS (0).
    pub const ACCEL_CONFIG_STATIC2: u8 = 0x03;
    /// ACCEL_AAF_DELTSQR bits 7:0.
    pub const ACCEL_CONFIG_STATIC3: u8 = 0x04;
    /// ACCEL_AAF_BITSHIFT, ACCEL_AAF_DELTSQR bits 11:8.
    pub const ACCEL_CONFIG_STATIC4: u8 = 0x05;
    /// Accel X self-test data (factory).
    pub const XA_ST_DATA: u8 = 0x3B;
    /// Accel Z self-test data (factory).
    pub const ZA_ST_DATA: u8 = 0x3D;
}

/// User bank 3 (not tabulated in DS rev. 1.7).
pub mod bank3 {
    /// Clock divider (named by Zephyr's register header).
    pub const CLKDIV: u8 = 0x2A;
}

/// User bank 4 (DS: user bank 4): APEX, wake-on-motion thresholds, user offsets.
pub mod bank4 {
    /// APEX configuration 1 (first of nine).
    pub const APEX_CONFIG1: u8 = 0x40;
    /// APEX configuration 9.
    pub const APEX_CONFIG9: u8 = 0x48;
    /// Wake-on-motion threshold X.
    pub const ACCEL_WOM_X_THR: u8 = 0x4A;
    /// Interrupt sources 6 (first of five).
    pub const INT_SOURCE6: u8 = 0x4D;
    /// Interrupt sources 10.
    pub const INT_SOURCE10: u8 = 0x51;
    /// User offset 0 (first of nine).
    pub const OFFSET_USER0: u8 = 0x77;
    /// User offset 8.
    pub const OFFSET_USER8: u8 = 0x7F;
}

/// Bits of the registers whose bits have behaviour.
pub mod bits {
    /// DEVICE_CONFIG: soft reset.
    pub const SOFT_RESET_CONFIG: u8 = 1 << 0;
    /// INT_CONFIG: INT1 active high.
    pub const INT1_POLARITY: u8 = 1 << 0;
    /// INT_CONFIG: INT1 push-pull (0 = open drain).
    pub const INT1_DRIVE_CIRCUIT: u8 = 1 << 1;
    /// INT_CONFIG: INT1 latched (0 = pulsed).
    pub const INT1_MODE: u8 = 1 << 2;
    /// INT_CONFIG: INT2 active high.
    pub const INT2_POLARITY: u8 = 1 << 3;
    /// INT_CONFIG: INT2 push-pull.
    pub const INT2_DRIVE_CIRCUIT: u8 = 1 << 4;
    /// INT_CONFIG: INT2 latched.
    pub const INT2_MODE: u8 = 1 << 5;
    /// FIFO_CONFIG: FIFO_MODE field.
    pub const FIFO_MODE: u8 = 0xC0;
    /// FIFO_MODE = 01: stream to FIFO.
    pub const FIFO_MODE_STREAM: u8 = 0x40;
    /// FIFO_MODE = 1x: stop on full.
    pub const FIFO_MODE_STOP_ON_FULL: u8 = 0x80;
    /// INT_STATUS: FIFO full.
    pub const FIFO_FULL_INT: u8 = 1 << 1;
    /// INT_STATUS: FIFO threshold.
    pub const FIFO_THS_INT: u8 = 1 << 2;
    /// INT_STATUS: UI data ready.
    pub const DATA_RDY_INT: u8 = 1 << 3;
    /// INT_STATUS: reset done.
    pub const RESET_DONE_INT: u8 = 1 << 4;
    /// SIGNAL_PATH_RESET: FIFO flush.
    pub const FIFO_FLUSH: u8 = 1 << 1;
    /// INTF_CONFIG0: data registers and FIFO data big-endian (1) or little-endian (0).
    pub const SENSOR_DATA_ENDIAN: u8 = 1 << 4;
    /// INTF_CONFIG0: FIFO count big-endian (1) or little-endian (0).
    pub const FIFO_COUNT_ENDIAN: u8 = 1 << 5;
    /// INTF_CONFIG0: FIFO count in records (1) or bytes (0).
    pub const FIFO_COUNT_REC: u8 = 1 << 6;
    /// INTF_CONFIG1: the AFSR control field (01 disables AFSR; every flight firmware writes it).
    pub const AFSR: u8 = 0xC0;
    /// PWR_MGMT0: accel mode field (00/01 off, 10 low power, 11 low noise).
    pub const ACCEL_MODE: u8 = 0x03;
    /// PWR_MGMT0: gyro mode field (00 off, 01 standby, 11 low noise).
    pub const GYRO_MODE: u8 = 0x0C;
    /// PWR_MGMT0: temperature sensor disabled.
    pub const TEMP_DIS: u8 = 1 << 5;
    /// TMST_CONFIG: timestamp enabled.
    pub const TMST_EN: u8 = 1 << 0;
    /// TMST_CONFIG: FIFO timestamps are deltas from the previous packet.
    pub const TMST_DELTA_EN: u8 = 1 << 2;
    /// TMST_CONFIG: 16 µs resolution (0 = 1 µs).
    pub const TMST_RES: u8 = 1 << 3;
    /// FIFO_CONFIG1: accel in packets.
    pub const FIFO_ACCEL_EN: u8 = 1 << 0;
    /// FIFO_CONFIG1: gyro in packets.
    pub const FIFO_GYRO_EN: u8 = 1 << 1;
    /// FIFO_CONFIG1: temperature in packets.
    pub const FIFO_TEMP_EN: u8 = 1 << 2;
    /// FIFO_CONFIG1: timestamp / FSYNC in packets.
    pub const FIFO_TMST_FSYNC_EN: u8 = 1 << 3;
    /// FIFO_CONFIG1: 20-bit packets (packet 4).
    pub const FIFO_HIRES_EN: u8 = 1 << 4;
    /// FIFO_CONFIG1: threshold interrupt at every packet while count ≥ watermark.
    pub const FIFO_WM_GT_TH: u8 = 1 << 5;
    /// FIFO_CONFIG1: a partly read packet resumes where the read stopped.
    pub const FIFO_RESUME_PARTIAL_RD: u8 = 1 << 6;
    /// INT_CONFIG1: 8 µs pulses (0 = 100 µs).
    pub const INT_TPULSE_DURATION: u8 = 1 << 6;
    /// INT_CONFIG1: no minimum de-assertion time between pulses.
    pub const INT_TDEASSERT_DISABLE: u8 = 1 << 5;
    /// FIFO header: FIFO empty.
    pub const HEADER_MSG: u8 = 1 << 7;
    /// FIFO header: packet holds accel data.
    pub const HEADER_ACCEL: u8 = 1 << 6;
    /// FIFO header: packet holds gyro data.
    pub const HEADER_GYRO: u8 = 1 << 5;
    /// FIFO header: 20-bit data.
    pub const HEADER_20: u8 = 1 << 4;
    /// FIFO header: TIMESTAMP_FSYNC = 10, the packet holds an ODR timestamp.
    pub const HEADER_TIMESTAMP_ODR: u8 = 1 << 3;
    /// FIFO header: the accel ODR differs from the previous packet's.
    pub const HEADER_ODR_ACCEL: u8 = 1 << 1;
    /// FIFO header: the gyro ODR differs from the previous packet's.
    pub const HEADER_ODR_GYRO: u8 = 1 << 0;
}

/// Bytes of the data registers TEMP_DATA1..=GYRO_DATA_Z0 (0x1D..=0x2A).
pub const DATA_LEN: usize = 14;

/// Packet sizes in bytes (DS: FIFO packet structure): packets 1 and 2 (accel or gyro only), 3 (both,
/// 16-bit) and 4 (both, 20-bit).
pub mod packet {
    /// Header, 6 data bytes, 8-bit temperature.
    pub const SINGLE_LEN: usize = 8;
    /// Header, accel, gyro, 8-bit temperature, 16-bit timestamp.
    pub const BOTH_LEN: usize = 16;
    /// Header, accel and gyro bits 19:4, 16-bit temperature, timestamp, 3 extension bytes.
    pub const HIRES_LEN: usize = 20;
}
