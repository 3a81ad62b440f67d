//! [`ChipModel`]: the emulated chip models and what the rest of margemu may know about each
//! without naming a register.

use crate::link::Buses;

/// The register-map family a model belongs to: one chip module each.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Family {
    /// InvenSense 6xxx: MPU-9250 (with the AK8963), MPU-6500, MPU-6000, ICM-20602
    /// ([`crate::regmap::mpu6xxx`]).
    Mpu6xxx,
    /// TDK InvenSense ICM-42688-P ([`crate::regmap::icm42688p`]).
    Icm42688p,
    /// iSentek IST8310 magnetometer ([`crate::regmap::ist8310`]).
    Ist8310,
    /// QST QMC5883L magnetometer ([`crate::regmap::qmc5883l`]).
    Qmc5883l,
    /// PNI RM3100 magnetometer ([`crate::regmap::rm3100`]).
    Rm3100,
    /// Bosch BMI270 ([`crate::regmap::bmi270`]).
    Bmi270,
    /// Bosch BMI088, two dies ([`crate::regmap::bmi088`]).
    Bmi088,
}

/// An emulated chip model. Its wire code ([`ChipModel::code`]) is the bit of
/// [`Chips`](crate::link::Chips) and the chip byte of [`Configure`](crate::link::Configure).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum ChipModel {
    /// InvenSense MPU-9250 with the AK8963 magnetometer (identities 0x71, MPU-9255 0x73, 0x68).
    Mpu9250 = 0,
    /// InvenSense MPU-6500, WHO_AM_I 0x70.
    Mpu6500 = 1,
    /// InvenSense MPU-6000, WHO_AM_I 0x68 (and PRODUCT_ID).
    Mpu6000 = 2,
    /// TDK InvenSense ICM-20602, WHO_AM_I 0x12.
    Icm20602 = 3,
    /// TDK InvenSense ICM-42688-P, WHO_AM_I 0x47.
    Icm42688p = 4,
    /// Bosch BMI270, CHIP_ID 0x24.
    Bmi270 = 5,
    /// iSentek IST8310 magnetometer (I2C only), WAI 0x10.
    Ist8310 = 6,
    /// QST QMC5883L magnetometer (I2C only), chip id 0xFF.
    Qmc5883l = 7,
    /// PNI RM3100 magnetometer (SPI and I2C), REVID 0x22.
    Rm3100 = 8,
    /// Bosch BMI088 (accelerometer and gyroscope dies, one chip select or I2C address each),
    /// ACC_CHIP_ID 0x1E.
    Bmi088 = 9,
}

impl ChipModel {
    /// Every model, in code order.
    pub const ALL: [Self; 10] = [
        Self::Mpu9250,
        Self::Mpu6500,
        Self::Mpu6000,
        Self::Icm20602,
        Self::Icm42688p,
        Self::Bmi270,
        Self::Ist8310,
        Self::Qmc5883l,
        Self::Rm3100,
        Self::Bmi088,
    ];

    /// The model's code on the link.
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// The model of a wire code.
    pub fn from_code(code: u8) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.code() == code)
    }

    /// The name scenes, files and the command line use (`"icm42688p"`).
    pub const fn name(self) -> &'static str {
        match self {
            Self::Mpu9250 => "mpu9250",
            Self::Mpu6500 => "mpu6500",
            Self::Mpu6000 => "mpu6000",
            Self::Icm20602 => "icm20602",
            Self::Icm42688p => "icm42688p",
            Self::Ist8310 => "ist8310",
            Self::Qmc5883l => "qmc5883l",
            Self::Rm3100 => "rm3100",
            Self::Bmi270 => "bmi270",
            Self::Bmi088 => "bmi088",
        }
    }

    /// The datasheet's part name (`"ICM-42688-P"`).
    pub const fn part_name(self) -> &'static str {
        match self {
            Self::Mpu9250 => "MPU-9250",
            Self::Mpu6500 => "MPU-6500",
            Self::Mpu6000 => "MPU-6000",
            Self::Icm20602 => "ICM-20602",
            Self::Icm42688p => "ICM-42688-P",
            Self::Ist8310 => "IST8310",
            Self::Qmc5883l => "QMC5883L",
            Self::Rm3100 => "RM3100",
            Self::Bmi270 => "BMI270",
            Self::Bmi088 => "BMI088",
        }
    }

    /// The model called `name` ([`ChipModel::name`], ASCII case and `-`/`_` ignored).
    pub fn from_name(name: &str) -> Option<Self> {
        let mut key = [0u8; 16];
        let mut n = 0;
        for b in name.bytes().filter(|b| !matches!(b, b'-' | b'_')) {
            *key.get_mut(n)? = b.to_ascii_lowercase();
            n += 1;
        }
        let key = key.get(..n)?;
        Self::ALL.into_iter().find(|m| m.name().as_bytes() == key)
    }

    /// The register-map family.
    pub const fn family(self) -> Family {
        match self {
            Self::Icm42688p => Family::Icm42688p,
            Self::Ist8310 => Family::Ist8310,
            Self::Qmc5883l => Family::Qmc5883l,
            Self::Rm3100 => Family::Rm3100,
            Self::Bmi270 => Family::Bmi270,
            Self::Bmi088 => Family::Bmi088,
            _ => Family::Mpu6xxx,
        }
    }

    /// What the part measures: an IMU (accelerometer and gyroscope, perhaps a magnetometer too)
    /// or a magnetometer alone.
    pub const fn is_magnetometer_only(self) -> bool {
        matches!(self, Self::Ist8310 | Self::Qmc5883l | Self::Rm3100)
    }

    /// The WHO_AM_I value of the part itself (the first of [`ChipModel::identities`]; for the
    /// magnetometers, the identity register drivers check: the IST8310's WAI, the
    /// QMC5883L's chip id register 0x0D, the RM3100's REVID; the BMI270's CHIP_ID; the BMI088's
    /// accelerometer die's ACC_CHIP_ID).
    pub const fn who_am_i(self) -> u8 {
        self.identities()[0]
    }

    /// The name of the identity register the datasheet gives ([`ChipModel::identities`] are
    /// its values): `"WHO_AM_I"`, the BMI270's `"CHIP_ID"`, the BMI088's `"ACC_CHIP_ID"`.
    pub const fn identity_register(self) -> &'static str {
        match self {
            Self::Bmi270 => "CHIP_ID",
            Self::Bmi088 => "ACC_CHIP_ID",
            Self::Ist8310 => "WAI",
            Self::Qmc5883l => "CHIP_ID 0x0D",
            Self::Rm3100 => "REVID",
            _ => "WHO_AM_I",
        }
    }

    /// Every WHO_AM_I value the model can be told to answer (identity variants of one register
    /// map: the MPU-9255 and the 0x68 parts behave as the MPU-9250).
    pub const fn identities(self) -> &'static [u8] {
        match self {
            Self::Mpu9250 => &[0x71, 0x73, 0x68],
            Self::Mpu6500 => &[0x70],
            Self::Mpu6000 => &[0x68],
            Self::Icm20602 => &[0x12],
            Self::Icm42688p => &[0x47],
            Self::Ist8310 => &[crate::regmap::ist8310::WAI_VALUE],
            Self::Qmc5883l => &[crate::regmap::qmc5883l::CHIP_ID_VALUE],
            Self::Rm3100 => &[crate::regmap::rm3100::REVID_VALUE],
            Self::Bmi270 => &[crate::regmap::bmi270::CHIP_ID],
            Self::Bmi088 => &[crate::regmap::bmi088::accel::CHIP_ID],
        }
    }

    /// The buses the part has: SPI and I2C, except the IST8310 and QMC5883L (I2C only).
    pub const fn buses(self) -> Buses {
        if matches!(self, Self::Ist8310 | Self::Qmc5883l) {
            Buses::I2C
        } else {
            Buses(Buses::SPI.0 | Buses::I2C.0)
        }
    }

    /// The 7-bit I2C addresses the part can be strapped to (the default first: AD0 low for the
    /// InvenSense IMUs, SDO low for the BMI270; the IST8310's CAD pins give 0x0C–0x0F, 0x0E with
    /// both low; the QMC5883L has one; the RM3100's SA0/SA1 pins give 0x20–0x23; the BMI088's
    /// accelerometer die, SDO1 low or high: its gyroscope die answers
    /// [`ChipModel::second_die_i2c_address`] too).
    pub const fn i2c_addresses(self) -> &'static [u8] {
        match self {
            Self::Bmi270 => &crate::regmap::bmi270::I2C_ADDRESSES,
            Self::Bmi088 => &[
                crate::regmap::bmi088::accel::I2C_ADDRESS,
                crate::regmap::bmi088::accel::I2C_ADDRESS | 1,
            ],
            Self::Ist8310 => &crate::regmap::ist8310::I2C_ADDRESSES,
            Self::Qmc5883l => &[crate::regmap::qmc5883l::I2C_ADDRESS],
            Self::Rm3100 => &[0x20, 0x21, 0x22, 0x23],
            _ => &[0x68, 0x69],
        }
    }

    /// The 7-bit I2C address of the part's second die when the part is strapped to `address`
    /// (one of [`ChipModel::i2c_addresses`]): the BMI088's gyroscope die, 0x68 with SDO1 low
    /// and 0x69 with it high (margemu straps SDO2 as SDO1: one `address` names both dies).
    /// `None` for the one-die parts.
    pub const fn second_die_i2c_address(self, address: u8) -> Option<u8> {
        match self {
            Self::Bmi088 => Some(crate::regmap::bmi088::gyro::I2C_ADDRESS | (address & 1)),
            _ => None,
        }
    }

    /// SPI chip selects the part takes: 2 for the BMI088 (CSB1 its accelerometer die, CSB2 its
    /// gyroscope die), 1 otherwise. A device on chip select `c` takes `c .. c + spi_selects()`.
    pub const fn spi_selects(self) -> u8 {
        match self {
            Self::Bmi088 => 2,
            _ => 1,
        }
    }

    /// Register files of the model, as [`RegisterOverride::file`](crate::link::RegisterOverride)
    /// numbers them: the MPU-9250's die (0) and its AK8963 (1); the ICM-42688-P's banks 0–4;
    /// the BMI088's accelerometer die (0) and gyroscope die (1); one file otherwise (the
    /// BMI270's one page of 128 registers).
    pub const fn register_files(self) -> u8 {
        match self {
            Self::Mpu9250 | Self::Bmi088 => 2,
            Self::Icm42688p => 5,
            _ => 1,
        }
    }

    /// Whether the package holds a magnetometer.
    pub const fn has_magnetometer(self) -> bool {
        matches!(
            self,
            Self::Mpu9250 | Self::Ist8310 | Self::Qmc5883l | Self::Rm3100
        )
    }

    /// What the emulation covers, for `margemu chips` (one line per item; the chip module's
    /// docs give the datasheet sections).
    pub const fn emulated(self) -> &'static [&'static str] {
        match self.family() {
            Family::Mpu6xxx => &[
                "every register with its reset value, write mask and read-back",
                "SPI (read flag 0x80) and I2C targets, burst auto-increment, FIFO and DMP ports",
                "accel, gyro and temperature data at the configured full scales, user offsets",
                "sample rate from SMPLRT_DIV, DLPF_CFG and FCHOICE; the accelerometer's own rate",
                "FIFO with its count latch, overflow and the FIFO_EN sources",
                "INT pin: data ready, FIFO overflow, pulse or latched, polarity, open drain",
                "device reset, SIGNAL_PATH_RESET, USER_CTRL resets, sleep and clock select",
            ],
            Family::Icm42688p => &[
                "register banks 0-4 with reset values, write masks and read-back",
                "SPI (read flag 0x80) and I2C targets; FIFO_DATA does not auto-increment",
                "soft reset with RESET_DONE; PWR_MGMT0 modes (a sensor that is off reads -32768)",
                "16-bit data at the configured full scales, either endianness (INTF_CONFIG0)",
                "FIFO: 8-, 16- and 20-byte packets with headers, 20-bit data, timestamps,                  count in bytes or records, lost packets, overflow, watermark",
                "INT1/INT2: data ready, FIFO threshold and full, reset done; pulse or latched",
            ],
            Family::Bmi270 => &[
                "every register with its reset value, write mask and read-back (one page)",
                "SPI with its dummy byte and the switch from I2C on a chip-select rising edge; I2C",
                "configuration upload (328-byte and 8 KB files, INIT_ADDR chunks), INTERNAL_STATUS; \
                 no data before init_ok",
                "16-bit little-endian data at the configured ranges; accel at its own ODR; \
                 temperature every 10 ms; SENSORTIME",
                "FIFO: headered and headerless frames, FIFO_DOWNS, stop-on-full or fifo_err, flush",
                "INT1/INT2: data ready, pulsed (156.25 µs) or latched, level, open drain, output enable",
            ],
            Family::Bmi088 => &[
                "both dies, each with its registers, reset values, write masks and read-back",
                "two chip selects (accel, gyro) or two I2C addresses; the accel's dummy byte and \
                 switch from I2C on a chip-select rising edge",
                "16-bit little-endian data at the configured ranges; the gyro at the served rate, \
                 the accel at its own ODR; temperature every 1.28 s; SENSORTIME",
                "power modes (ACC_PWR_CTRL, GYRO_LPM1); ERR_REG on an invalid ACC_CONF",
                "both FIFOs: accel 0x84 frames with skip and sensortime frames, down-sampling; \
                 gyro 6-byte frames, FIFO and stream modes, frame count and overrun",
                "INT1/INT2 (accel) and INT3/INT4 (gyro) mapping, level, open drain",
            ],
            Family::Ist8310 => &[
                "I2C target at its four strap addresses, registers with reset values and masks",
                "single measurements (CNTL1 = 1) taking the time the averaging (AVGCNTL) needs",
                "STAT1 DRDY and DOR, self-clearing soft reset, 0.3 uT/LSB with per-axis clipping",
            ],
            Family::Qmc5883l => &[
                "I2C target, registers with reset values, masks and the chip id registers",
                "continuous mode at 10/50/100/200 Hz, ranges 2 G and 8 G",
                "STATUS DRDY, OVL and DOR (data skipped), soft reset, pointer roll-over",
            ],
            Family::Rm3100 => &[
                "SPI (STATUS during the address byte) and I2C at 0x20-0x23, read-back, HSHAKE",
                "single (POLL) and continuous (CMM, TMRC) measurements, axis by axis in time",
                "cycle counts setting gain and measurement time, 24-bit results, STATUS DRDY",
                "the built-in self test (BIST)",
            ],
        }
    }

    /// What it does not emulate (yet), for `margemu chips`.
    pub const fn not_emulated(self) -> &'static [&'static str] {
        match self.family() {
            Family::Mpu6xxx => &[
                "filter registers a driver writes at run time (the data follows the scene's [chip.filters], with [vibration] in source images only)",
                "self-test responses, wake-on-motion, the DMP, FSYNC",
            ],
            Family::Icm42688p => &[
                "filter registers a driver writes at run time (the data follows the scene's [chip.filters], with [vibration] in source images only)",
                "APEX motion features, self-test, external clock (CLKIN), FSYNC",
            ],
            Family::Ist8310 => {
                &["temperature output, self-test field, 16-bit output mode, the DRDY pin"]
            }
            Family::Qmc5883l => &["temperature output, over-sampling noise, the DRDY pin"],
            Family::Rm3100 => &["the DRDY pin, noise, the output's bend beyond +-800 uT"],
            Family::Bmi088 => &[
                "filter registers a driver writes at run time (the data follows the scene's [chip.filters], with [vibration] in source images only)",
                "boot, reset and power-mode settling times, write spacing in suspend",
                "self-test responses, FIFO tags and input pins, external FIFO sync",
                "a board's second chip select (the Black Pill serves device 0's accel die)",
            ],
            Family::Bmi270 => &[
                "filter registers a driver writes at run time (the data follows the scene's [chip.filters], with [vibration] in source images only)",
                "pre-filtered FIFO data",
                "the configuration file's features (FEATURES pages are storage), the time init takes",
                "FIFO sensor time, skip and configuration frames, watermark and full interrupts",
                "low-power timing (adv_power_save is stored), the auxiliary interface, self-test, offsets",
            ],
        }
    }

    /// Bytes of one register image of this model (see each chip module's `image`).
    pub const fn image_len(self) -> usize {
        match self {
            Self::Mpu9250 => crate::regmap::mpu6xxx::image::IMAGE_LEN,
            Self::Mpu6500 | Self::Mpu6000 | Self::Icm20602 => {
                crate::regmap::mpu6xxx::image::SENSORS_LEN
            }
            Self::Icm42688p => crate::regmap::icm42688p::image::IMAGE_LEN,
            Self::Ist8310 => crate::regmap::ist8310::IMAGE_LEN,
            Self::Qmc5883l => crate::regmap::qmc5883l::IMAGE_LEN,
            Self::Rm3100 => crate::regmap::rm3100::IMAGE_LEN,
            Self::Bmi270 => crate::regmap::bmi270::image::IMAGE_LEN,
            Self::Bmi088 => crate::regmap::bmi088::image::IMAGE_LEN,
        }
    }

    /// Whether the part can output samples at `rate_hz` (within 1e-9 relative): the rates its
    /// rate registers give. MPU-6000: the gyro output rate (8 kHz with the DLPF off, 1 kHz on)
    /// divided by 1 + SMPLRT_DIV (RM-MPU-6000A section 4.2). MPU-6500, MPU-9250, ICM-20602:
    /// 32 kHz (FCHOICE_B), 8 kHz (DLPF_CFG 0 or 7), or 1 kHz / (1 + SMPLRT_DIV) (the divider
    /// applies only with the DLPF on; RM-MPU-9250A section 4.4). ICM-42688-P: its ODR codes.
    /// BMI270: its gyro ODR codes, 25 Hz to 3.2 kHz (the served rate is the gyro's; the
    /// accelerometer runs at its own ODR, at most 1.6 kHz). BMI088: its gyro ODRs, 100 Hz to
    /// 2 kHz, likewise (the accelerometer at its own ODR, at most 1.6 kHz).
    pub fn has_output_rate(self, rate_hz: f64) -> bool {
        let close = |r: f64| (r - rate_hz).abs() <= 1e-9 * r;
        let divided = |base: f64| (1..=256u32).any(|n| close(base / f64::from(n)));
        match self {
            Self::Mpu6000 => divided(8_000.0) || divided(1_000.0),
            Self::Mpu9250 | Self::Mpu6500 | Self::Icm20602 => {
                close(32_000.0) || close(8_000.0) || divided(1_000.0)
            }
            Self::Icm42688p => crate::regmap::icm42688p::Odr::gyro_of_hz(rate_hz).is_some(),
            // A magnetometer measures on its own schedule; any rate of the rig's IMU serves it.
            Self::Ist8310 | Self::Qmc5883l | Self::Rm3100 => rate_hz > 0.0,
            Self::Bmi270 => crate::regmap::bmi270::Odr::gyro_of_hz(rate_hz).is_some(),
            Self::Bmi088 => crate::regmap::bmi088::gyro::Bandwidth::widest_at_hz(rate_hz).is_some(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_and_names_round_trip() {
        for m in ChipModel::ALL {
            assert_eq!(ChipModel::from_code(m.code()), Some(m));
            assert_eq!(ChipModel::from_name(m.name()), Some(m));
            assert!(m.image_len() <= super::super::MAX_CHIP_IMAGE_LEN);
        }
        assert_eq!(
            ChipModel::from_name("ICM-42688-P"),
            Some(ChipModel::Icm42688p)
        );
        assert_eq!(ChipModel::from_name("MPU_6000"), Some(ChipModel::Mpu6000));
        assert_eq!(ChipModel::from_name("BMI-270"), Some(ChipModel::Bmi270));
        assert_eq!(ChipModel::from_name("bmi999"), None);
        assert_eq!(ChipModel::from_name("an-overlong-name-of-no-chip"), None);
        assert_eq!(ChipModel::from_code(200), None);
    }

    #[test]
    fn output_rates() {
        assert!(ChipModel::Mpu9250.has_output_rate(200.0));
        assert!(ChipModel::Mpu9250.has_output_rate(8000.0));
        assert!(!ChipModel::Mpu9250.has_output_rate(64_000.0));
        assert!(ChipModel::Icm42688p.has_output_rate(8000.0));
        assert!(ChipModel::Icm42688p.has_output_rate(12.5));
        assert!(!ChipModel::Icm42688p.has_output_rate(300.0));
        assert!(ChipModel::Bmi270.has_output_rate(3200.0));
        assert!(ChipModel::Bmi270.has_output_rate(25.0));
        assert!(!ChipModel::Bmi270.has_output_rate(1000.0));
        assert!(!ChipModel::Bmi270.has_output_rate(12.5));
        assert!(ChipModel::Bmi088.has_output_rate(2000.0));
        assert!(ChipModel::Bmi088.has_output_rate(100.0));
        assert!(!ChipModel::Bmi088.has_output_rate(1600.0));
        assert!(!ChipModel::Bmi088.has_output_rate(3200.0));
    }

    #[test]
    fn the_bmi270() {
        let m = ChipModel::Bmi270;
        assert_eq!((m.code(), m.who_am_i(), m.image_len()), (5, 0x24, 14));
        assert_eq!((m.family(), m.register_files()), (Family::Bmi270, 1));
        assert_eq!(m.identity_register(), "CHIP_ID");
        assert_eq!(m.i2c_addresses(), &[0x68, 0x69]);
        assert!(!m.has_magnetometer());
        assert_eq!((m.spi_selects(), m.second_die_i2c_address(0x68)), (1, None));
    }

    #[test]
    fn the_bmi088() {
        let m = ChipModel::Bmi088;
        assert_eq!((m.code(), m.who_am_i(), m.image_len()), (9, 0x1E, 14));
        assert_eq!((m.family(), m.register_files()), (Family::Bmi088, 2));
        assert_eq!(m.identity_register(), "ACC_CHIP_ID");
        assert_eq!(m.i2c_addresses(), &[0x18, 0x19]);
        assert_eq!(m.second_die_i2c_address(0x18), Some(0x68));
        assert_eq!(m.second_die_i2c_address(0x19), Some(0x69));
        assert_eq!(m.spi_selects(), 2);
        assert_eq!(ChipModel::from_name("BMI-088"), Some(m));
        assert!(!m.has_magnetometer() && !m.is_magnetometer_only());
    }
}
