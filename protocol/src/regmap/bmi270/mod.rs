//! The Bosch BMI270 (accel + gyro + temperature): register addresses, bits, reset values, access
//! masks, ranges, output rates and conversions (datasheet BST-BMI270-DS000, "DS" below: section 5
//! register description and the register map; section 4 for the configuration upload, the
//! primary interface and the sensor time).
//!
//! One flat page of 128 registers (no banks). Addresses the datasheet does not list read 0 and
//! ignore writes ([`is_defined`]); read-only registers ignore writes ([`is_read_only`]); listed
//! registers keep the bits outside their fields at 0 ([`write_mask`]). CMD (0x7E) is write-only
//! and reads 0. INIT_DATA (0x5E) and FIFO_DATA (0x26) are ports: a burst stays on them
//! ([`next_address`]).
//!
//! The driver sequences these values serve were read in ArduPilot
//! `libraries/AP_InertialSensor/AP_InertialSensor_BMI270.cpp`, Betaflight
//! `src/main/drivers/accgyro/accgyro_spi_bmi270.c` and the Rust `bmi2` crate; no code was taken
//! from them.
//!
//! ```
//! use margemu_protocol::regmap::bmi270::{reg, reset_value, write_mask, AccRange, GyrRange, Odr};
//! assert_eq!(reset_value(reg::CHIP_ID), 0x24);
//! assert_eq!(reset_value(reg::PWR_CONF), 0x03);
//! assert_eq!(write_mask(reg::ACC_RANGE), 0x03);
//! assert_eq!(AccRange::from_reg(0x03), AccRange::G16);
//! assert_eq!(GyrRange::from_reg(0x04), GyrRange::Dps125);
//! assert_eq!(Odr::from_conf(0xAD).map(Odr::period_ns), Some(312_500)); // 3.2 kHz
//! ```

mod access;
pub mod convert;
pub mod image;
mod scale;

pub use access::{is_defined, is_read_only, next_address, reset_value, write_mask};
pub use scale::{AccRange, GyrRange, Odr};

/// The CHIP_ID value (DS: CHIP_ID).
pub const CHIP_ID: u8 = 0x24;

/// The 7-bit I2C address with SDO low (0x69 with SDO high).
pub const I2C_ADDRESS: u8 = 0x68;

/// Both 7-bit I2C addresses, SDO low first (DS: 6.3 I2C interface).
pub const I2C_ADDRESSES: [u8; 2] = [0x68, 0x69];

/// Size of the configuration RAM reached through INIT_DATA, in bytes (DS: 4.2 initialization:
/// Bosch's full configuration file is 8 KB).
pub const CONFIG_RAM_LEN: usize = 8192;

/// Lengths of the configuration files the emulated chip accepts: Bosch's 328-byte
/// maximum-FIFO file the flight firmwares upload and the 8 KB full file.
pub const CONFIG_FILE_LENS: [usize; 2] = [328, CONFIG_RAM_LEN];

/// FIFO size in bytes (DS: 4.7 FIFO, 2 KB). Bosch's maximum-FIFO configuration file is described
/// by the Bosch sensor API as giving a 6 KB FIFO; that is not modelled (and not yet checked).
pub const FIFO_SIZE: usize = 2048;

/// The data registers ACC_X_LSB..=GYR_Z_MSB: 12 bytes.
pub const DATA_LEN: usize = 12;

/// Register addresses (DS: register map).
pub mod reg {
    /// Chip identification, 0x24.
    pub const CHIP_ID: u8 = 0x00;
    /// Error flags (bit 0 fatal, 4:1 internal error code, bit 6 FIFO error, bit 7 aux error).
    pub const ERR_REG: u8 = 0x02;
    /// Status: bit 7 drdy_acc, bit 6 drdy_gyr, bit 5 drdy_aux, bit 4 cmd_rdy, bit 2 aux_busy.
    pub const STATUS: u8 = 0x03;
    /// Auxiliary data, 0x04..=0x0B.
    pub const DATA_0: u8 = 0x04;
    /// Accel X LSB; X MSB, Y and Z follow up to 0x11 (little-endian).
    pub const ACC_X_LSB: u8 = 0x0C;
    /// Gyro X LSB; X MSB, Y and Z follow up to 0x17 (little-endian).
    pub const GYR_X_LSB: u8 = 0x12;
    /// Gyro Z MSB: the last data register.
    pub const GYR_Z_MSB: u8 = 0x17;
    /// Sensor time bits 7:0; 15:8 and 23:16 follow at 0x19 and 0x1A.
    pub const SENSORTIME_0: u8 = 0x18;
    /// Sensor time bits 23:16.
    pub const SENSORTIME_2: u8 = 0x1A;
    /// Event flags (bit 0 por_detected).
    pub const EVENT: u8 = 0x1B;
    /// Feature interrupt status.
    pub const INT_STATUS_0: u8 = 0x1C;
    /// Data interrupt status.
    pub const INT_STATUS_1: u8 = 0x1D;
    /// Internal status: bits 3:0 message (0 not_init, 1 init_ok, 2 init_err, …).
    pub const INTERNAL_STATUS: u8 = 0x21;
    /// Temperature LSB (0x22/0x23, little-endian; 0x8000 = invalid).
    pub const TEMPERATURE_0: u8 = 0x22;
    /// Temperature MSB.
    pub const TEMPERATURE_1: u8 = 0x23;
    /// FIFO fill level, bits 7:0.
    pub const FIFO_LENGTH_0: u8 = 0x24;
    /// FIFO fill level, bits 13:8.
    pub const FIFO_LENGTH_1: u8 = 0x25;
    /// FIFO read port.
    pub const FIFO_DATA: u8 = 0x26;
    /// Feature page selection.
    pub const FEAT_PAGE: u8 = 0x2F;
    /// Accel configuration: bits 3:0 ODR, 6:4 bandwidth, bit 7 filter performance.
    pub const ACC_CONF: u8 = 0x40;
    /// Accel range: bits 1:0.
    pub const ACC_RANGE: u8 = 0x41;
    /// Gyro configuration: bits 3:0 ODR, 5:4 bandwidth, bit 6 noise, bit 7 filter performance.
    pub const GYR_CONF: u8 = 0x42;
    /// Gyro range: bits 2:0 range, bit 3 OIS range.
    pub const GYR_RANGE: u8 = 0x43;
    /// FIFO downsampling: bits 2:0 gyro, bit 3 gyro filtered data, 6:4 accel, bit 7 accel
    /// filtered data.
    pub const FIFO_DOWNS: u8 = 0x45;
    /// FIFO configuration 0 (bit 0 stop on full, bit 1 sensortime frame).
    pub const FIFO_CONFIG_0: u8 = 0x48;
    /// FIFO configuration 1 (bit 4 header, bits 7:5 aux/acc/gyr enables).
    pub const FIFO_CONFIG_1: u8 = 0x49;
    /// INT1 pin electrical behaviour.
    pub const INT1_IO_CTRL: u8 = 0x53;
    /// INT2 pin electrical behaviour.
    pub const INT2_IO_CTRL: u8 = 0x54;
    /// Interrupt latch mode (bit 0).
    pub const INT_LATCH: u8 = 0x55;
    /// Data interrupt mapping to INT1/INT2.
    pub const INT_MAP_DATA: u8 = 0x58;
    /// Configuration load: 0 prepares an upload, 1 starts the initialization.
    pub const INIT_CTRL: u8 = 0x59;
    /// Upload word offset, bits 3:0.
    pub const INIT_ADDR_0: u8 = 0x5B;
    /// Upload word offset, bits 11:4.
    pub const INIT_ADDR_1: u8 = 0x5C;
    /// Configuration upload port.
    pub const INIT_DATA: u8 = 0x5E;
    /// Internal error flags.
    pub const INTERNAL_ERROR: u8 = 0x5F;
    /// Interface configuration (SPI 3/4 wire, aux).
    pub const IF_CONF: u8 = 0x6B;
    /// Power configuration: bit 0 adv_power_save, bit 1 fifo_self_wake_up, bit 2 fup_en.
    pub const PWR_CONF: u8 = 0x7C;
    /// Power control: bit 0 aux_en, bit 1 gyr_en, bit 2 acc_en, bit 3 temp_en.
    pub const PWR_CTRL: u8 = 0x7D;
    /// Command register (write-only).
    pub const CMD: u8 = 0x7E;
}

/// Bits and values (DS: register description).
pub mod bits {
    /// STATUS.drdy_acc.
    pub const DRDY_ACC: u8 = 1 << 7;
    /// STATUS.drdy_gyr.
    pub const DRDY_GYR: u8 = 1 << 6;
    /// STATUS.cmd_rdy.
    pub const CMD_RDY: u8 = 1 << 4;
    /// EVENT.por_detected.
    pub const POR_DETECTED: u8 = 1 << 0;
    /// INTERNAL_STATUS message: not initialized.
    pub const MSG_NOT_INIT: u8 = 0x00;
    /// INTERNAL_STATUS message: initialization ok.
    pub const MSG_INIT_OK: u8 = 0x01;
    /// INTERNAL_STATUS message: initialization error.
    pub const MSG_INIT_ERR: u8 = 0x02;
    /// INTERNAL_STATUS message field.
    pub const MSG_MASK: u8 = 0x0F;
    /// PWR_CONF.adv_power_save.
    pub const ADV_POWER_SAVE: u8 = 1 << 0;
    /// PWR_CTRL.gyr_en.
    pub const GYR_EN: u8 = 1 << 1;
    /// PWR_CTRL.acc_en.
    pub const ACC_EN: u8 = 1 << 2;
    /// PWR_CTRL.temp_en.
    pub const TEMP_EN: u8 = 1 << 3;
    /// CMD: soft reset.
    pub const CMD_SOFT_RESET: u8 = 0xB6;
    /// ERR_REG.fifo_err.
    pub const FIFO_ERR: u8 = 1 << 6;
    /// CMD: FIFO flush.
    pub const CMD_FIFO_FLUSH: u8 = 0xB0;
    /// FIFO_CONFIG_0.fifo_stop_on_full.
    pub const FIFO_STOP_ON_FULL: u8 = 1 << 0;
    /// FIFO_CONFIG_1.fifo_header_en.
    pub const FIFO_HEADER_EN: u8 = 1 << 4;
    /// FIFO_CONFIG_1.fifo_acc_en.
    pub const FIFO_ACC_EN: u8 = 1 << 6;
    /// FIFO_CONFIG_1.fifo_gyr_en.
    pub const FIFO_GYR_EN: u8 = 1 << 7;
    /// Header of a regular frame; bit 3 gyro, bit 2 accel (bit 4 aux) tell what follows.
    pub const FIFO_HEADER_REGULAR: u8 = 0x80;
    /// Header bit: gyro data in the frame.
    pub const FIFO_HEADER_GYR: u8 = 1 << 3;
    /// Header bit: accel data in the frame.
    pub const FIFO_HEADER_ACC: u8 = 1 << 2;
    /// What a read of an empty FIFO returns (DS: 4.7 FIFO, over-read).
    pub const FIFO_EMPTY: u8 = 0x80;
    /// FIFO_DOWNS: gyro downsampling exponent (2^n), bits 2:0.
    pub const GYR_FIFO_DOWNS: u8 = 0x07;
    /// FIFO_DOWNS: accel downsampling exponent, bits 6:4.
    pub const ACC_FIFO_DOWNS: u8 = 0x70;
    /// INT_STATUS_1.acc_drdy_int.
    pub const ACC_DRDY_INT: u8 = 1 << 7;
    /// INT_STATUS_1.gyr_drdy_int.
    pub const GYR_DRDY_INT: u8 = 1 << 6;
    /// INTx_IO_CTRL.lvl: active high.
    pub const INT_LVL: u8 = 1 << 1;
    /// INTx_IO_CTRL.od: open drain (0: push-pull).
    pub const INT_OD: u8 = 1 << 2;
    /// INTx_IO_CTRL.output_en.
    pub const INT_OUTPUT_EN: u8 = 1 << 3;
    /// INT_MAP_DATA.drdy_int1: data ready on INT1.
    pub const DRDY_INT1: u8 = 1 << 2;
    /// INT_MAP_DATA.drdy_int2: data ready on INT2.
    pub const DRDY_INT2: u8 = 1 << 6;
    /// INT_LATCH.int_latch: latched (0: non-latched).
    pub const INT_LATCHED: u8 = 1 << 0;
}
