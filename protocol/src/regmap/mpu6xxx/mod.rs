//! The InvenSense 6xxx family (MPU-9250, MPU-9255, MPU-6500, MPU-6000, ICM-20602), accel/gyro
//! die: register addresses, bits, reset values, access masks, full scales and the output-rate
//! rule. The items at this level are the MPU-9250's (InvenSense RM-MPU-9250A-00 rev. 1.6, "RM"
//! below); [`variant`] says where each other part differs (identity, reset values, registers it
//! lacks or adds, FIFO size and contents, temperature scale) and [`rates`] gives every part's
//! internal gyro/accel rates, output rate and the accel hold rule.
//!
//! Everything here is data about the silicon; the behaviour that uses it lives in
//! `margemu_firmware::chip`. The host uses the same tables to predict what a driver reads.
//!
//! ```
//! use margemu_protocol::regmap::mpu6xxx::{reg, sample_period_ns, reset_value, GyroFs};
//! assert_eq!(reset_value(reg::PWR_MGMT_1), 0x01);
//! assert_eq!(reset_value(reg::WHO_AM_I), 0x71);
//! // DLPF on (DLPF_CFG = 1), SMPLRT_DIV = 4: 1 kHz / 5 = 200 Hz.
//! assert_eq!(sample_period_ns(0x01, 0x00, 4), 5_000_000);
//! assert_eq!(GyroFs::from_gyro_config(0x18), GyroFs::Dps2000);
//! ```

pub mod convert;
pub mod fifo;
pub mod image;
pub mod rates;
pub mod variant;

/// Register addresses (RM section 3, table 1).
pub mod reg {
    /// Gyro self-test value X (factory, R/W).
    pub const SELF_TEST_X_GYRO: u8 = 0x00;
    /// Gyro self-test value Y.
    pub const SELF_TEST_Y_GYRO: u8 = 0x01;
    /// Gyro self-test value Z.
    pub const SELF_TEST_Z_GYRO: u8 = 0x02;
    /// Accel self-test value X (factory, R/W).
    pub const SELF_TEST_X_ACCEL: u8 = 0x0D;
    /// Accel self-test value Y.
    pub const SELF_TEST_Y_ACCEL: u8 = 0x0E;
    /// Accel self-test value Z.
    pub const SELF_TEST_Z_ACCEL: u8 = 0x0F;
    /// Gyro X user offset, high byte.
    pub const XG_OFFSET_H: u8 = 0x13;
    /// Gyro X user offset, low byte.
    pub const XG_OFFSET_L: u8 = 0x14;
    /// Gyro Y user offset, high byte.
    pub const YG_OFFSET_H: u8 = 0x15;
    /// Gyro Y user offset, low byte.
    pub const YG_OFFSET_L: u8 = 0x16;
    /// Gyro Z user offset, high byte.
    pub const ZG_OFFSET_H: u8 = 0x17;
    /// Gyro Z user offset, low byte.
    pub const ZG_OFFSET_L: u8 = 0x18;
    /// Sample rate divider.
    pub const SMPLRT_DIV: u8 = 0x19;
    /// FIFO_MODE, EXT_SYNC_SET, DLPF_CFG.
    pub const CONFIG: u8 = 0x1A;
    /// Gyro self-test, GYRO_FS_SEL, FCHOICE_B.
    pub const GYRO_CONFIG: u8 = 0x1B;
    /// Accel self-test, ACCEL_FS_SEL.
    pub const ACCEL_CONFIG: u8 = 0x1C;
    /// ACCEL_FCHOICE_B, A_DLPF_CFG.
    pub const ACCEL_CONFIG2: u8 = 0x1D;
    /// Low-power accel output rate.
    pub const LP_ACCEL_ODR: u8 = 0x1E;
    /// Wake-on-motion threshold.
    pub const WOM_THR: u8 = 0x1F;
    /// Which sensor data go into the FIFO.
    pub const FIFO_EN: u8 = 0x23;
    /// Auxiliary I2C master control.
    pub const I2C_MST_CTRL: u8 = 0x24;
    /// Slave 0 address and read flag; slaves 1..3 follow at steps of 3.
    pub const I2C_SLV0_ADDR: u8 = 0x25;
    /// Slave 0 register.
    pub const I2C_SLV0_REG: u8 = 0x26;
    /// Slave 0 control (EN, BYTE_SW, REG_DIS, GRP, LENG).
    pub const I2C_SLV0_CTRL: u8 = 0x27;
    /// Slave 4 address and read flag.
    pub const I2C_SLV4_ADDR: u8 = 0x31;
    /// Slave 4 register.
    pub const I2C_SLV4_REG: u8 = 0x32;
    /// Slave 4 data out.
    pub const I2C_SLV4_DO: u8 = 0x33;
    /// Slave 4 control (EN, DONE_INT_EN, REG_DIS, I2C_MST_DLY).
    pub const I2C_SLV4_CTRL: u8 = 0x34;
    /// Slave 4 data in (read only).
    pub const I2C_SLV4_DI: u8 = 0x35;
    /// I2C master status (read only, clears on read).
    pub const I2C_MST_STATUS: u8 = 0x36;
    /// INT pin configuration and bypass enable.
    pub const INT_PIN_CFG: u8 = 0x37;
    /// Interrupt enables.
    pub const INT_ENABLE: u8 = 0x38;
    /// Interrupt status (read only, clears on read).
    pub const INT_STATUS: u8 = 0x3A;
    /// First data register: accel X high byte.
    pub const ACCEL_XOUT_H: u8 = 0x3B;
    /// Temperature high byte.
    pub const TEMP_OUT_H: u8 = 0x41;
    /// Gyro X high byte.
    pub const GYRO_XOUT_H: u8 = 0x43;
    /// First external sensor data register.
    pub const EXT_SENS_DATA_00: u8 = 0x49;
    /// Last external sensor data register.
    pub const EXT_SENS_DATA_23: u8 = 0x60;
    /// Slave 0 data out; slaves 1..3 follow.
    pub const I2C_SLV0_DO: u8 = 0x63;
    /// Slave delay enables and external-sensor shadowing.
    pub const I2C_MST_DELAY_CTRL: u8 = 0x67;
    /// Signal path resets (self-clearing).
    pub const SIGNAL_PATH_RESET: u8 = 0x68;
    /// Accel intelligence (wake on motion) control.
    pub const MOT_DETECT_CTRL: u8 = 0x69;
    /// FIFO/I2C master enables and self-clearing resets.
    pub const USER_CTRL: u8 = 0x6A;
    /// Reset, sleep, cycle, clock select.
    pub const PWR_MGMT_1: u8 = 0x6B;
    /// Per-axis standby.
    pub const PWR_MGMT_2: u8 = 0x6C;
    /// DMP memory bank (not in the RM; present on the die).
    pub const BANK_SEL: u8 = 0x6D;
    /// DMP memory start address.
    pub const MEM_START_ADDR: u8 = 0x6E;
    /// DMP memory read/write port (bursts do not increment the register address).
    pub const MEM_R_W: u8 = 0x6F;
    /// FIFO count, high bits (reading it latches both count registers).
    pub const FIFO_COUNTH: u8 = 0x72;
    /// FIFO count, low byte.
    pub const FIFO_COUNTL: u8 = 0x73;
    /// FIFO read/write port (bursts do not increment the register address).
    pub const FIFO_R_W: u8 = 0x74;
    /// Device identity.
    pub const WHO_AM_I: u8 = 0x75;
    /// Accel X offset trim, high byte (factory value).
    pub const XA_OFFSET_H: u8 = 0x77;
    /// Accel X offset trim, low byte.
    pub const XA_OFFSET_L: u8 = 0x78;
    /// Accel Y offset trim, high byte.
    pub const YA_OFFSET_H: u8 = 0x7A;
    /// Accel Y offset trim, low byte.
    pub const YA_OFFSET_L: u8 = 0x7B;
    /// Accel Z offset trim, high byte.
    pub const ZA_OFFSET_H: u8 = 0x7D;
    /// Accel Z offset trim, low byte.
    pub const ZA_OFFSET_L: u8 = 0x7E;
}

/// Bits of the registers whose bits have behaviour.
pub mod bits {
    /// CONFIG: when the FIFO is full, drop new data instead of the oldest.
    pub const CONFIG_FIFO_MODE: u8 = 1 << 6;
    /// CONFIG: DLPF_CFG field.
    pub const CONFIG_DLPF_CFG: u8 = 0x07;
    /// GYRO_CONFIG: FCHOICE_B field (non-zero bypasses the DLPF, 32 kHz).
    pub const GYRO_FCHOICE_B: u8 = 0x03;
    /// FIFO_EN: temperature.
    pub const FIFO_TEMP: u8 = 1 << 7;
    /// FIFO_EN: gyro X.
    pub const FIFO_GYRO_X: u8 = 1 << 6;
    /// FIFO_EN: gyro Y.
    pub const FIFO_GYRO_Y: u8 = 1 << 5;
    /// FIFO_EN: gyro Z.
    pub const FIFO_GYRO_Z: u8 = 1 << 4;
    /// FIFO_EN: accel X, Y, Z.
    pub const FIFO_ACCEL: u8 = 1 << 3;
    /// FIFO_EN: external sensor data of slave 2 (slave 1: `<< 1`, slave 0: `<< 0`).
    pub const FIFO_SLV2: u8 = 1 << 2;
    /// I2C_MST_CTRL: external sensor data of slave 3 into the FIFO.
    pub const MST_SLV3_FIFO_EN: u8 = 1 << 5;
    /// I2C_SLVx_ADDR: read (1) or write (0).
    pub const SLV_RNW: u8 = 1 << 7;
    /// I2C_SLVx_CTRL: slave enabled (for slave 4: start one transfer).
    pub const SLV_EN: u8 = 1 << 7;
    /// I2C_SLVx_CTRL: swap the bytes of each word.
    pub const SLV_BYTE_SW: u8 = 1 << 6;
    /// I2C_SLVx_CTRL: do not send the register address.
    pub const SLV_REG_DIS: u8 = 1 << 5;
    /// I2C_SLVx_CTRL: words end at even slave register addresses.
    pub const SLV_GRP: u8 = 1 << 4;
    /// I2C_SLVx_CTRL: number of bytes.
    pub const SLV_LENG: u8 = 0x0F;
    /// I2C_SLV4_CTRL: slaves with DLY_EN are accessed every `1 + I2C_MST_DLY` samples.
    pub const SLV4_MST_DLY: u8 = 0x1F;
    /// I2C_MST_STATUS: slave 4 transfer complete.
    pub const MST_SLV4_DONE: u8 = 1 << 6;
    /// I2C_MST_STATUS: slave 4 was not acknowledged.
    pub const MST_SLV4_NACK: u8 = 1 << 4;
    /// INT_PIN_CFG: INT active low.
    pub const INT_ACTL: u8 = 1 << 7;
    /// INT_PIN_CFG: INT open drain.
    pub const INT_OPEN: u8 = 1 << 6;
    /// INT_PIN_CFG: INT held until the status is cleared (else a 50 µs pulse).
    pub const INT_LATCH_EN: u8 = 1 << 5;
    /// INT_PIN_CFG: any read clears the interrupt status.
    pub const INT_ANYRD_2CLEAR: u8 = 1 << 4;
    /// INT_PIN_CFG: auxiliary bus bypass to the primary I2C pins.
    pub const INT_BYPASS_EN: u8 = 1 << 1;
    /// INT_ENABLE / INT_STATUS: wake on motion.
    pub const INT_WOM: u8 = 1 << 6;
    /// INT_ENABLE / INT_STATUS: FIFO overflow.
    pub const INT_FIFO_OFLOW: u8 = 1 << 4;
    /// INT_ENABLE / INT_STATUS: FSYNC.
    pub const INT_FSYNC: u8 = 1 << 3;
    /// INT_ENABLE / INT_STATUS: raw sensor data ready.
    pub const INT_RAW_RDY: u8 = 1 << 0;
    /// USER_CTRL: FIFO enabled.
    pub const USER_FIFO_EN: u8 = 1 << 6;
    /// USER_CTRL: auxiliary I2C master enabled.
    pub const USER_I2C_MST_EN: u8 = 1 << 5;
    /// USER_CTRL: primary I2C interface disabled (SPI only).
    pub const USER_I2C_IF_DIS: u8 = 1 << 4;
    /// USER_CTRL: reset the FIFO (self-clearing).
    pub const USER_FIFO_RST: u8 = 1 << 2;
    /// USER_CTRL: reset the I2C master (self-clearing).
    pub const USER_I2C_MST_RST: u8 = 1 << 1;
    /// USER_CTRL: reset the signal paths and clear the sensor registers (self-clearing).
    pub const USER_SIG_COND_RST: u8 = 1 << 0;
    /// PWR_MGMT_1: device reset (self-clearing).
    pub const PWR1_H_RESET: u8 = 1 << 7;
    /// PWR_MGMT_1: sleep.
    pub const PWR1_SLEEP: u8 = 1 << 6;
    /// PWR_MGMT_1: clock select field; 7 stops the clock.
    pub const PWR1_CLKSEL: u8 = 0x07;
    /// I2C_MST_DELAY_CTRL: slave `i` (0..=4) delay enable is bit `i`.
    pub const DELAY_SLV0_EN: u8 = 1 << 0;
}

/// Reset value of `addr` (RM section 3: 0x00 for all but PWR_MGMT_1 = 0x01 and WHO_AM_I = 0x71).
/// The factory-trim registers (self-test and accel offsets) hold the part's own trim after a
/// reset; `margemu_firmware` takes those from its configuration.
pub const fn reset_value(addr: u8) -> u8 {
    match addr {
        reg::PWR_MGMT_1 => 0x01,
        reg::WHO_AM_I => 0x71,
        _ => 0x00,
    }
}

/// Whether the serial interface can write `addr` at all (RM: "Serial IF: RO" registers).
pub const fn is_read_only(addr: u8) -> bool {
    matches!(
        addr,
        reg::I2C_SLV4_DI | reg::I2C_MST_STATUS | reg::INT_STATUS | reg::ACCEL_XOUT_H
            ..=reg::EXT_SENS_DATA_23 | reg::FIFO_COUNTH | reg::FIFO_COUNTL | reg::WHO_AM_I
    )
}

/// Bits of `addr` that act when written as 1 and always read back 0 (self-clearing).
pub const fn self_clearing_mask(addr: u8) -> u8 {
    match addr {
        reg::PWR_MGMT_1 => bits::PWR1_H_RESET,
        reg::SIGNAL_PATH_RESET => 0x07,
        reg::USER_CTRL => bits::USER_FIFO_RST | bits::USER_I2C_MST_RST | bits::USER_SIG_COND_RST,
        _ => 0x00,
    }
}

/// Bits a serial-interface write stores in `addr`: everything of a R/W register (reserved bits
/// included, so they read back what was written) except the self-clearing bits.
pub const fn write_mask(addr: u8) -> u8 {
    if is_read_only(addr) {
        0x00
    } else {
        !self_clearing_mask(addr)
    }
}

/// Whether a burst access stays on `addr` instead of moving to the next register.
pub const fn is_port(addr: u8) -> bool {
    matches!(addr, reg::FIFO_R_W | reg::MEM_R_W)
}

/// The register a burst access reaches after `addr` (7-bit address space, wrapping).
pub const fn next_address(addr: u8) -> u8 {
    if is_port(addr) {
        addr
    } else {
        addr.wrapping_add(1) & 0x7F
    }
}

/// Size of the FIFO in bytes (product specification PS-MPU-9250A-01 section 4.17: 512 bytes).
pub const FIFO_SIZE: usize = 512;

/// Bytes of the data registers a burst can read at once: accel, temperature, gyro (14) and
/// EXT_SENS_DATA_00..23 (24), i.e. `0x3B..=0x60`.
pub const DATA_LEN: usize = 38;

/// Bytes of accel, temperature and gyro data, `0x3B..=0x48`.
pub const SENSOR_LEN: usize = 14;

/// Bytes of external sensor data, `0x49..=0x60`.
pub const EXT_SENS_LEN: usize = 24;

/// Accelerometer full scale (ACCEL_CONFIG.ACCEL_FS_SEL, RM section 4.7).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum AccelFs {
    /// ±2 g, 16384 LSB/g.
    #[default]
    G2,
    /// ±4 g, 8192 LSB/g.
    G4,
    /// ±8 g, 4096 LSB/g.
    G8,
    /// ±16 g, 2048 LSB/g.
    G16,
}

impl AccelFs {
    /// All settings, in register order.
    pub const ALL: [Self; 4] = [Self::G2, Self::G4, Self::G8, Self::G16];

    /// The full scale selected by an ACCEL_CONFIG value.
    pub const fn from_accel_config(value: u8) -> Self {
        Self::ALL[((value >> 3) & 0x03) as usize]
    }

    /// The ACCEL_FS_SEL field value (0..=3).
    pub const fn bits(self) -> u8 {
        self as u8
    }

    /// The range, ± g.
    pub const fn range_g(self) -> u16 {
        2 << self.bits()
    }

    /// Sensitivity in LSB per g (PS section 3).
    pub const fn lsb_per_g(self) -> f32 {
        match self {
            Self::G2 => 16384.0,
            Self::G4 => 8192.0,
            Self::G8 => 4096.0,
            Self::G16 => 2048.0,
        }
    }
}

/// Gyroscope full scale (GYRO_CONFIG.GYRO_FS_SEL, RM section 4.6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum GyroFs {
    /// ±250 °/s, 131 LSB/(°/s).
    #[default]
    Dps250,
    /// ±500 °/s, 65.5 LSB/(°/s).
    Dps500,
    /// ±1000 °/s, 32.8 LSB/(°/s).
    Dps1000,
    /// ±2000 °/s, 16.4 LSB/(°/s).
    Dps2000,
}

impl GyroFs {
    /// All settings, in register order.
    pub const ALL: [Self; 4] = [Self::Dps250, Self::Dps500, Self::Dps1000, Self::Dps2000];

    /// The full scale selected by a GYRO_CONFIG value.
    pub const fn from_gyro_config(value: u8) -> Self {
        Self::ALL[((value >> 3) & 0x03) as usize]
    }

    /// The GYRO_FS_SEL field value (0..=3).
    pub const fn bits(self) -> u8 {
        self as u8
    }

    /// The range, ± °/s.
    pub const fn range_dps(self) -> u16 {
        250 << self.bits()
    }

    /// Sensitivity in LSB per °/s as the product specification states it (section 3.1:
    /// 131, 65.5, 32.8, 16.4), not `32768 / range`.
    pub const fn lsb_per_dps(self) -> f32 {
        match self {
            Self::Dps250 => 131.0,
            Self::Dps500 => 65.5,
            Self::Dps1000 => 32.8,
            Self::Dps2000 => 16.4,
        }
    }
}

/// Nanoseconds between samples (the data-ready, FIFO and I2C-master rate) for the given CONFIG,
/// GYRO_CONFIG and SMPLRT_DIV values (RM sections 4.4–4.6):
/// - FCHOICE_B ≠ 0: the DLPF is bypassed and the gyro runs at 32 kHz (31 250 ns);
/// - DLPF_CFG = 0 or 7: 8 kHz (125 000 ns);
/// - otherwise 1 kHz / (1 + SMPLRT_DIV), which the RM applies only in this case.
pub const fn sample_period_ns(config: u8, gyro_config: u8, smplrt_div: u8) -> u64 {
    if gyro_config & bits::GYRO_FCHOICE_B != 0 {
        31_250
    } else {
        match config & bits::CONFIG_DLPF_CFG {
            0 | 7 => 125_000,
            _ => 1_000_000 * (1 + smplrt_div as u64),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reset_values_match_the_register_map() {
        for addr in 0..0x80u8 {
            let expected = match addr {
                0x6B => 0x01,
                0x75 => 0x71,
                _ => 0x00,
            };
            assert_eq!(reset_value(addr), expected, "register {addr:#04x}");
        }
    }

    #[test]
    fn write_masks() {
        assert_eq!(write_mask(reg::PWR_MGMT_1), 0x7F);
        assert_eq!(write_mask(reg::USER_CTRL), 0xF8);
        assert_eq!(write_mask(reg::SIGNAL_PATH_RESET), 0xF8);
        assert_eq!(write_mask(reg::CONFIG), 0xFF);
        for ro in [0x35, 0x36, 0x3A, 0x3B, 0x48, 0x49, 0x60, 0x72, 0x73, 0x75] {
            assert_eq!(write_mask(ro), 0x00, "register {ro:#04x}");
        }
        assert_eq!(write_mask(0x61), 0xFF); // reserved: reads back what was written
    }

    #[test]
    fn burst_addresses() {
        assert_eq!(next_address(0x3B), 0x3C);
        assert_eq!(next_address(0x7F), 0x00);
        assert_eq!(next_address(0x74), 0x74);
        assert_eq!(next_address(0x6F), 0x6F);
    }

    #[test]
    fn full_scale_fields() {
        assert_eq!(AccelFs::from_accel_config(0x00), AccelFs::G2);
        assert_eq!(AccelFs::from_accel_config(0x08), AccelFs::G4);
        assert_eq!(AccelFs::from_accel_config(0x10), AccelFs::G8);
        assert_eq!(AccelFs::from_accel_config(0xFF), AccelFs::G16);
        assert_eq!(GyroFs::from_gyro_config(0x08), GyroFs::Dps500);
        assert_eq!(GyroFs::from_gyro_config(0x10), GyroFs::Dps1000);
        assert_eq!(GyroFs::Dps1000.bits(), 2);
    }

    #[test]
    fn output_rates() {
        assert_eq!(sample_period_ns(0x00, 0x00, 9), 125_000); // DLPF_CFG 0: 8 kHz, no divider
        assert_eq!(sample_period_ns(0x07, 0x00, 9), 125_000);
        assert_eq!(sample_period_ns(0x03, 0x00, 0), 1_000_000);
        assert_eq!(sample_period_ns(0x03, 0x00, 9), 10_000_000);
        assert_eq!(sample_period_ns(0x03, 0x00, 255), 256_000_000);
        assert_eq!(sample_period_ns(0x03, 0x01, 9), 31_250); // FCHOICE_B = 01
        assert_eq!(sample_period_ns(0x03, 0x02, 9), 31_250);
    }
}
