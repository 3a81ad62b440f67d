//! What makes one part of the InvenSense 6xxx family differ from another: identity, reset
//! values, which registers exist, which are read-only or self-clearing, factory-trim addresses,
//! FIFO size and contents, temperature scale. Data only; the firmware serves it and the host
//! predicts with it.
//!
//! Sources, per part:
//! - MPU-9250 / MPU-9255 / 0x68-answering MPU-9250: RM-MPU-9250A-00 rev. 1.6 section 3 (the
//!   register map the rest of [`super`] follows); every address is a plain R/W byte unless the
//!   RM says otherwise.
//! - MPU-6500: RM-MPU-6500A-01 rev. 2.1 section 3: the MPU-9250's accel/gyro die, WHO_AM_I 0x70,
//!   no AK8963; same registers and reset values.
//! - MPU-6000: RM-MPU-6000A-00 rev. 4.2 section 3 and PS-MPU-6000A-00 rev. 3.4 section 7.17
//!   (1024-byte FIFO). Reset values 0x00 except PWR_MGMT_1 = 0x40 (asleep) and WHO_AM_I = 0x68
//!   (RM section 3). Register 4.4: the divider applies at 8 kHz too; GYRO_CONFIG has no FCHOICE_B
//!   and there is no ACCEL_CONFIG2 (the accelerometer always outputs at 1 kHz, RM section 4.2
//!   note). Temperature `TEMP_OUT / 340 + 36.53` °C (RM section 4.18). PRODUCT_ID at 0x0C is not
//!   in the RM; Betaflight's MPU-6000 driver accepts 0x14–0x18 (engineering samples) and
//!   0x54–0x5A (revisions C4 to D10), so a part answers one of them ([`MPU6000_PRODUCT_ID`]).
//!   The accel offset trim sits at 0x06–0x0B (InvenSense application note "MPU Hardware
//!   Offset Registers"; the `mpu6050-dmp` crate's calibration writes it there), the self-test
//!   registers at 0x0D–0x10.
//! - ICM-20602: DS-000176 rev. 1.0 sections 9–11: WHO_AM_I 0x12, reset values 0x00 except
//!   CONFIG = 0x80, PWR_MGMT_1 = 0x41, WHO_AM_I; no auxiliary I2C master and no EXT_SENS_DATA
//!   (0x24–0x35, 0x49–0x5F, 0x63–0x67 reserved), no DMP (0x6D–0x6F); its own registers
//!   ACCEL_WOM_X/Y/Z_THR 0x20–0x22, FSYNC_INT 0x36, FIFO_WM_INT_STATUS 0x39, SELF_TEST_X/Y/Z_GYRO
//!   0x50–0x52, FIFO_WM_TH1/2 0x60–0x61, I2C_IF 0x70 (bit 6 I2C_IF_DIS); ACCEL_CONFIG2 bits 5:4
//!   DEC2_CFG (low-power averaging) and 7:6 FIFO_SIZE are stored. FIFO 1008 bytes usable (PX4's
//!   `InvenSense_ICM20602_registers.hpp` reads it as 1008: 72 records of 14 bytes).
//!   Register 0x11 is undocumented but R/W (see [`extra_reg::ICM20602_UNDOC_0X11`]).
//!   FIFO_EN has only GYRO_FIFO_EN (bit 4) and ACCEL_FIFO_EN (bit 3); either one brings
//!   TEMP_OUT along (Linux's `iio/imu/inv_mpu6050` counts two temperature bytes per ICM-20602
//!   FIFO sample whatever is enabled), so a record with both is the 14 bytes of 0x3B..=0x48
//!   (PX4's layout). Temperature
//!   `TEMP_OUT / 326.8 + 25` °C.
//!
//! A register a part lacks reads 0x00 and ignores writes ("reserved" in its map).
//!
//! ```
//! use margemu_protocol::regmap::mpu6xxx::variant::Variant;
//! use margemu_protocol::regmap::mpu6xxx::reg;
//! assert_eq!(Variant::Mpu6000.reset_value(reg::PWR_MGMT_1), 0x40);
//! assert_eq!(Variant::Mpu6000.reset_value(0x0C), 0x58); // PRODUCT_ID, MPU-6000 rev. D8
//! assert!(!Variant::Mpu6000.has_register(reg::ACCEL_CONFIG2));
//! assert_eq!(Variant::Icm20602.who_am_i(), 0x12);
//! assert_eq!(Variant::Icm20602.fifo_size(), 1008);
//! assert_eq!(Variant::Icm20602.write_mask(reg::I2C_SLV0_CTRL), 0x00); // no aux master
//! ```

use super::{bits, reg};
use crate::chip::ChipModel;
use crate::regmap::mpu6xxx::convert::round_saturate;

/// PRODUCT_ID (0x0C) the emulated MPU-6000 answers: 0x58, "MPU6000 rev. D8" in Betaflight's list.
pub const MPU6000_PRODUCT_ID: u8 = 0x58;

/// Extra register addresses some parts have.
pub mod extra_reg {
    /// MPU-6000: accel offset trim X, high byte (Y at 0x08, Z at 0x0A).
    pub const MPU6000_XA_OFFS_H: u8 = 0x06;
    /// MPU-6000: PRODUCT_ID (revision), read only.
    pub const MPU6000_PRODUCT_ID: u8 = 0x0C;
    /// ICM-20602: an undocumented R/W register; ArduPilot (and PX4's older driver) write 0xC9
    /// to it as a checked register ("set incorrectly results in a 2.7 m/s² offset on Y"), so
    /// it must read back what was written. Reset value 0x00 here (the part's own is unknown).
    pub const ICM20602_UNDOC_0X11: u8 = 0x11;
    /// ICM-20602: FSYNC_INT status (read only).
    pub const ICM20602_FSYNC_INT: u8 = 0x36;
    /// ICM-20602: FIFO watermark interrupt status (read only).
    pub const ICM20602_FIFO_WM_INT_STATUS: u8 = 0x39;
    /// ICM-20602: SELF_TEST_X_GYRO (Y, Z follow).
    pub const ICM20602_SELF_TEST_X_GYRO: u8 = 0x50;
    /// ICM-20602: FIFO watermark threshold, high bits.
    pub const ICM20602_FIFO_WM_TH1: u8 = 0x60;
    /// ICM-20602: FIFO watermark threshold, low byte.
    pub const ICM20602_FIFO_WM_TH2: u8 = 0x61;
    /// ICM-20602: I2C_IF (bit 6: I2C_IF_DIS).
    pub const ICM20602_I2C_IF: u8 = 0x70;
    /// ICM-20602 I2C_IF: primary I2C interface disabled.
    pub const I2C_IF_DIS: u8 = 1 << 6;
}

/// Which part of the family the chip claims to be.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Variant {
    /// MPU-9250, WHO_AM_I 0x71, with AK8963.
    #[default]
    Mpu9250,
    /// MPU-9255, WHO_AM_I 0x73, with AK8963.
    Mpu9255,
    /// MPU-6500 (also sold as "MPU-9250" without magnetometer), WHO_AM_I 0x70, no AK8963.
    Mpu6500,
    /// An MPU-9250 answering WHO_AM_I 0x68 (the reset value RM rev. 1.4 prints), with AK8963.
    WhoAmI68,
    /// MPU-6000, WHO_AM_I 0x68, PRODUCT_ID 0x58, no AK8963, 1024-byte FIFO.
    Mpu6000,
    /// ICM-20602, WHO_AM_I 0x12, no auxiliary I2C master, 1008-byte FIFO.
    Icm20602,
}

/// Which data one sample writes into the FIFO, in this order: accel (6 bytes), temperature (2),
/// gyro x, y, z (2 each), then the EXT_SENS_DATA of slaves 0..=3.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct FifoSources {
    /// ACCEL_XOUT_H..=ACCEL_ZOUT_L.
    pub accel: bool,
    /// TEMP_OUT_H..=TEMP_OUT_L.
    pub temp: bool,
    /// GYRO_XOUT, GYRO_YOUT, GYRO_ZOUT.
    pub gyro: [bool; 3],
    /// The external sensor data of auxiliary slaves 0..=3.
    pub slaves: [bool; 4],
}

impl Variant {
    /// Every part, in declaration order.
    pub const ALL: [Self; 6] = [
        Self::Mpu9250,
        Self::Mpu9255,
        Self::Mpu6500,
        Self::WhoAmI68,
        Self::Mpu6000,
        Self::Icm20602,
    ];

    /// The WHO_AM_I value.
    pub const fn who_am_i(self) -> u8 {
        match self {
            Self::Mpu9250 => 0x71,
            Self::Mpu9255 => 0x73,
            Self::Mpu6500 => 0x70,
            Self::WhoAmI68 | Self::Mpu6000 => 0x68,
            Self::Icm20602 => 0x12,
        }
    }

    /// Whether the package holds an AK8963.
    pub const fn has_magnetometer(self) -> bool {
        matches!(self, Self::Mpu9250 | Self::Mpu9255 | Self::WhoAmI68)
    }

    /// Whether the part has the auxiliary I2C master and EXT_SENS_DATA.
    pub const fn has_aux_master(self) -> bool {
        !matches!(self, Self::Icm20602)
    }

    /// Whether the part has ACCEL_CONFIG2 (accelerometer DLPF and ACCEL_FCHOICE_B).
    pub const fn has_accel_config2(self) -> bool {
        !matches!(self, Self::Mpu6000)
    }

    /// Whether GYRO_CONFIG bits 1:0 are FCHOICE_B (the 32 kHz DLPF bypass).
    pub const fn has_gyro_fchoice(self) -> bool {
        !matches!(self, Self::Mpu6000)
    }

    /// FIFO capacity in bytes.
    pub const fn fifo_size(self) -> usize {
        match self {
            Self::Mpu6000 => 1024,
            Self::Icm20602 => 1008,
            _ => 512,
        }
    }

    /// Whether register `addr` (7 bits) exists on this part; one that does not reads 0x00 and
    /// ignores writes.
    pub const fn has_register(self, addr: u8) -> bool {
        let addr = addr & 0x7F;
        match self {
            Self::Mpu9250 | Self::Mpu9255 | Self::Mpu6500 | Self::WhoAmI68 => true,
            // ACCEL_CONFIG2 and LP_ACCEL_ODR came with the MPU-6500; the accel offsets moved to
            // 0x77.. then (0x06..=0x0B here); nothing above WHO_AM_I.
            Self::Mpu6000 => !matches!(addr, 0x1D | 0x1E | 0x70 | 0x71 | 0x76..=0x7F),
            Self::Icm20602 => matches!(
                addr,
                0x04 | 0x05
                    | 0x07
                    | 0x08
                    | 0x0A
                    | 0x0B
                    | 0x0D..=0x0F
                    | extra_reg::ICM20602_UNDOC_0X11
                    | 0x13..=0x1E
                    | 0x20..=0x23
                    | 0x36..=0x48
                    | 0x50..=0x52
                    | 0x60
                    | 0x61
                    | 0x68..=0x6C
                    | 0x70
                    | 0x72..=0x75
                    | 0x77
                    | 0x78
                    | 0x7A
                    | 0x7B
                    | 0x7D
                    | 0x7E
            ),
        }
    }

    /// Reset value of `addr` (power-on and PWR_MGMT_1.DEVICE_RESET). Factory-trim registers are
    /// set from the part's configuration on top of this.
    pub const fn reset_value(self, addr: u8) -> u8 {
        let addr = addr & 0x7F;
        if !self.has_register(addr) {
            return 0x00;
        }
        match (self, addr) {
            (_, reg::WHO_AM_I) => self.who_am_i(),
            (Self::Mpu6000, reg::PWR_MGMT_1) => 0x40,
            (Self::Mpu6000, extra_reg::MPU6000_PRODUCT_ID) => MPU6000_PRODUCT_ID,
            (Self::Icm20602, reg::PWR_MGMT_1) => 0x41,
            (Self::Icm20602, reg::CONFIG) => 0x80,
            (_, _) => super::reset_value(addr),
        }
    }

    /// Whether the serial interface can write `addr` at all (absent registers included).
    pub const fn is_read_only(self, addr: u8) -> bool {
        let addr = addr & 0x7F;
        if !self.has_register(addr) {
            return true;
        }
        match self {
            Self::Icm20602 => matches!(
                addr,
                extra_reg::ICM20602_FSYNC_INT
                    | extra_reg::ICM20602_FIFO_WM_INT_STATUS
                    | reg::INT_STATUS
                    | reg::ACCEL_XOUT_H
                    ..=0x48 | reg::FIFO_COUNTH | reg::FIFO_COUNTL | reg::WHO_AM_I
            ),
            Self::Mpu6000 => addr == extra_reg::MPU6000_PRODUCT_ID || super::is_read_only(addr),
            _ => super::is_read_only(addr),
        }
    }

    /// Bits of `addr` that act when written as 1 and always read back 0.
    pub const fn self_clearing_mask(self, addr: u8) -> u8 {
        match (self, addr & 0x7F) {
            // ICM-20602: SIGNAL_PATH_RESET has ACCEL_RST and TEMP_RST only; USER_CTRL has no
            // I2C_MST_RST.
            (Self::Icm20602, reg::SIGNAL_PATH_RESET) => 0x03,
            (Self::Icm20602, reg::USER_CTRL) => bits::USER_FIFO_RST | bits::USER_SIG_COND_RST,
            (_, addr) => super::self_clearing_mask(addr),
        }
    }

    /// Bits a serial-interface write stores in `addr`.
    pub const fn write_mask(self, addr: u8) -> u8 {
        if self.is_read_only(addr) {
            0x00
        } else {
            !self.self_clearing_mask(addr)
        }
    }

    /// Factory self-test registers, in the order of `Config::self_test` (gyro x, y, z, then accel
    /// x, y, z; the MPU-6000's four registers X, Y, Z, A take the first four values).
    pub const fn self_test_registers(self) -> &'static [u8] {
        match self {
            Self::Mpu6000 => &[0x0D, 0x0E, 0x0F, 0x10],
            Self::Icm20602 => &[0x50, 0x51, 0x52, 0x0D, 0x0E, 0x0F],
            _ => &[0x00, 0x01, 0x02, 0x0D, 0x0E, 0x0F],
        }
    }

    /// The high-byte addresses of the X, Y, Z accel offset trim pairs.
    pub const fn accel_offset_registers(self) -> [u8; 3] {
        match self {
            Self::Mpu6000 => [0x06, 0x08, 0x0A],
            _ => [reg::XA_OFFSET_H, reg::YA_OFFSET_H, reg::ZA_OFFSET_H],
        }
    }

    /// Whether the primary I2C interface is disabled: USER_CTRL.I2C_IF_DIS, or on the ICM-20602
    /// also I2C_IF.I2C_IF_DIS.
    pub const fn i2c_disabled(self, user_ctrl: u8, i2c_if: u8) -> bool {
        let by_i2c_if = matches!(self, Self::Icm20602) && i2c_if & extra_reg::I2C_IF_DIS != 0;
        user_ctrl & bits::USER_I2C_IF_DIS != 0 || by_i2c_if
    }

    /// What one sample writes into the FIFO for FIFO_EN = `fifo_en` and I2C_MST_CTRL =
    /// `mst_ctrl` (see the module docs for the ICM-20602's two-bit FIFO_EN).
    pub const fn fifo_sources(self, fifo_en: u8, mst_ctrl: u8) -> FifoSources {
        if let Self::Icm20602 = self {
            let gyro = fifo_en & bits::FIFO_GYRO_Z != 0; // GYRO_FIFO_EN is bit 4
            let accel = fifo_en & bits::FIFO_ACCEL != 0;
            return FifoSources {
                accel,
                temp: accel || gyro,
                gyro: [gyro; 3],
                slaves: [false; 4],
            };
        }
        FifoSources {
            accel: fifo_en & bits::FIFO_ACCEL != 0,
            temp: fifo_en & bits::FIFO_TEMP != 0,
            gyro: [
                fifo_en & bits::FIFO_GYRO_X != 0,
                fifo_en & bits::FIFO_GYRO_Y != 0,
                fifo_en & bits::FIFO_GYRO_Z != 0,
            ],
            slaves: [
                fifo_en & 1 != 0,
                fifo_en & 2 != 0,
                fifo_en & 4 != 0,
                mst_ctrl & bits::MST_SLV3_FIFO_EN != 0,
            ],
        }
    }

    /// The variant of `model` answering `who_am_i` (`None` for another family or identity).
    pub fn for_model(model: ChipModel, who_am_i: u8) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|v| v.model() == model && v.who_am_i() == who_am_i)
    }

    /// The chip model the variant is one identity of.
    pub const fn model(self) -> ChipModel {
        match self {
            Self::Mpu9250 | Self::Mpu9255 | Self::WhoAmI68 => ChipModel::Mpu9250,
            Self::Mpu6500 => ChipModel::Mpu6500,
            Self::Mpu6000 => ChipModel::Mpu6000,
            Self::Icm20602 => ChipModel::Icm20602,
        }
    }

    /// The part's temperature sensor scale.
    pub const fn temperature(self) -> TempScale {
        match self {
            Self::Mpu6000 => TempScale::Mpu6000,
            Self::Icm20602 => TempScale::Icm20602,
            _ => TempScale::Mpu6500,
        }
    }

    /// Temperature sensitivity (LSB/°C) and the temperature at which TEMP_OUT reads 0 (°C).
    pub const fn temp_scale(self) -> (f32, f32) {
        self.temperature().scale()
    }

    /// TEMP_OUT of a die temperature `t` in °C on this part (rounded, saturated, NaN → 0).
    pub fn temp_to_raw(self, t: f32) -> i16 {
        self.temperature().to_raw(t)
    }
}

/// The temperature sensor scales of the family (a field of the conversion settings, so the host
/// converts as the part does).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TempScale {
    /// MPU-6500, MPU-9250: 333.87 LSB/°C, 0 at 21 °C (RM-MPU-9250A section 4.23).
    #[default]
    Mpu6500,
    /// MPU-6000: 340 LSB/°C, 0 at 36.53 °C (RM-MPU-6000A section 4.18).
    Mpu6000,
    /// ICM-20602: 326.8 LSB/°C, 0 at 25 °C (DS-000176 section 3.4).
    Icm20602,
}

impl TempScale {
    /// Sensitivity (LSB/°C) and the temperature at which TEMP_OUT reads 0 (°C).
    pub const fn scale(self) -> (f32, f32) {
        match self {
            Self::Mpu6000 => (340.0, 36.53),
            Self::Icm20602 => (326.8, 25.0),
            Self::Mpu6500 => (
                super::convert::TEMP_LSB_PER_C,
                super::convert::TEMP_OFFSET_C,
            ),
        }
    }

    /// TEMP_OUT of a die temperature `t` in °C (rounded, saturated, NaN → 0).
    pub fn to_raw(self, t: f32) -> i16 {
        let (lsb_per_c, offset_c) = self.scale();
        round_saturate((t - offset_c) * lsb_per_c, i16::MIN, i16::MAX)
    }

    /// The die temperature (°C) of a TEMP_OUT value.
    pub fn from_raw(self, raw: i16) -> f64 {
        let (lsb_per_c, offset_c) = self.scale();
        f64::from(raw) / f64::from(lsb_per_c) + f64::from(offset_c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mpu9250_family_keeps_the_mpu9250_map() {
        for v in [Variant::Mpu9250, Variant::Mpu9255, Variant::Mpu6500] {
            for addr in 0..0x80u8 {
                assert!(v.has_register(addr));
                assert_eq!(v.write_mask(addr), super::super::write_mask(addr));
                if addr != reg::WHO_AM_I {
                    assert_eq!(v.reset_value(addr), super::super::reset_value(addr));
                }
            }
            assert_eq!(v.temp_to_raw(22.0), 334);
        }
    }

    #[test]
    fn mpu6000_reset_values_and_missing_registers() {
        let v = Variant::Mpu6000;
        for addr in 0..0x80u8 {
            let expected = match addr {
                0x0C => 0x58,
                0x6B => 0x40,
                0x75 => 0x68,
                _ => 0x00,
            };
            assert_eq!(v.reset_value(addr), expected, "register {addr:#04x}");
        }
        assert_eq!(v.write_mask(0x1D), 0x00);
        assert_eq!(v.write_mask(0x0C), 0x00);
        assert_eq!(v.write_mask(0x06), 0xFF);
        assert_eq!(v.write_mask(reg::SIGNAL_PATH_RESET), 0xF8);
        assert_eq!(v.fifo_size(), 1024);
        assert_eq!(v.temp_to_raw(36.53), 0);
        assert_eq!(v.temp_to_raw(37.53), 340);
    }

    #[test]
    fn icm20602_reset_values_and_registers() {
        let v = Variant::Icm20602;
        for addr in 0..0x80u8 {
            let expected = match addr {
                0x1A => 0x80,
                0x6B => 0x41,
                0x75 => 0x12,
                _ => 0x00,
            };
            assert_eq!(v.reset_value(addr), expected, "register {addr:#04x}");
        }
        for absent in [
            0x00, 0x0C, 0x24, 0x34, 0x49, 0x5F, 0x63, 0x67, 0x6D, 0x6F, 0x76,
        ] {
            assert!(!v.has_register(absent), "{absent:#04x}");
            assert_eq!(v.write_mask(absent), 0x00);
        }
        assert_eq!(v.write_mask(0x70), 0xFF);
        assert_eq!(v.write_mask(0x60), 0xFF);
        assert_eq!(v.write_mask(0x11), 0xFF);
        assert_eq!(v.write_mask(0x36), 0x00);
        assert_eq!(v.write_mask(reg::SIGNAL_PATH_RESET), 0xFC);
        assert_eq!(v.write_mask(reg::USER_CTRL), 0xFA);
        assert_eq!(v.temp_to_raw(26.0), 327);
        assert!(v.i2c_disabled(0x00, 0x40));
        assert!(!Variant::Mpu6000.i2c_disabled(0x00, 0x40));
    }

    #[test]
    fn fifo_sources() {
        let both = Variant::Icm20602.fifo_sources(0x18, 0x00);
        assert_eq!((both.accel, both.temp, both.gyro), (true, true, [true; 3]));
        let accel = Variant::Icm20602.fifo_sources(0xE7, 0x20); // reserved bits ignored
        assert_eq!(accel, FifoSources::default());
        let m = Variant::Mpu6000.fifo_sources(0x81, 0x20);
        assert_eq!(
            (m.temp, m.accel, m.slaves),
            (true, false, [true, false, false, true])
        );
    }
}
