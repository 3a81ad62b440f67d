//! [`ChipSettings`]: the register settings a model's conversion depends on, and the conversions
//! physical sample ↔ register image, dispatched to the chip's module.

use super::{ChipModel, Family, Image, PhysicalSample};
use crate::regmap::bmi088::image::{ImageConfig as Bmi088Config, ImageRepr as Bmi088Repr};
use crate::regmap::bmi088::{
    accel as bmi088_accel, convert as bmi088_convert, gyro as bmi088_gyro,
};
use crate::regmap::bmi270::image::{ImageConfig as BmiConfig, ImageRepr as BmiRepr};
use crate::regmap::bmi270::{self as bmi, convert as bmi_convert};
use crate::regmap::icm42688p::image::{ImageConfig as IcmConfig, ImageRepr as IcmRepr};
use crate::regmap::icm42688p::{self as icm, convert as icm_convert};
use crate::regmap::mpu6xxx::image::{ImageConfig as Mpu6xxxConfig, ImageRepr as Mpu6xxxRepr};
use crate::regmap::mpu6xxx::{self as mpu, AccelFs, GyroFs};
use crate::regmap::{ist8310, mag_image, qmc5883l, rm3100};

/// The conversion settings of one chip family (full scales, offsets, magnetometer settings).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Conversion {
    /// InvenSense 6xxx (and the AK8963 of the MPU-9250).
    Mpu6xxx(Mpu6xxxConfig),
    /// ICM-42688-P (full scales; the 20-bit FIFO values have fixed ones).
    Icm42688p(IcmConfig),
    /// IST8310 (one fixed sensitivity).
    Ist8310,
    /// QMC5883L at a range.
    Qmc5883l(qmc5883l::Range),
    /// RM3100 at cycle counts x, y, z (its gain).
    Rm3100([u16; 3]),
    /// BMI270 (ranges).
    Bmi270(BmiConfig),
    /// BMI088 (the accelerometer die's range, the gyroscope die's range).
    Bmi088(Bmi088Config),
}

/// A full-scale choice: accelerometer range in g, gyroscope range in °/s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FullScale {
    /// ± g.
    pub accel_g: f64,
    /// ± °/s.
    pub gyro_dps: f64,
}

/// A full scale the model does not have.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SettingsError {
    /// No accelerometer range of ± this many g; the model's are [`ChipSettings::accel_ranges_g`].
    AccelRange(f64),
    /// No gyroscope range of ± this many °/s; see [`ChipSettings::gyro_ranges_dps`].
    GyroRange(f64),
}

/// One physical sample decoded from an image (what the device under test was given).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reading {
    /// Specific force (m/s²), chip axes.
    pub acc: [f64; 3],
    /// Angular rate (rad/s), chip axes.
    pub gyr: [f64; 3],
    /// Die temperature (°C).
    pub temp_c: f64,
    /// Magnetic field (µT), chip accel/gyro axes, if the model has a magnetometer.
    pub mag_ut: Option<[f64; 3]>,
}

/// A magnetometer range the model does not have.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MagRangeError {
    /// The range asked for, ± gauss.
    pub gauss: f64,
}

/// A chip model with the register settings its images are computed with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChipSettings {
    /// The model.
    pub model: ChipModel,
    /// Its conversion settings.
    pub conversion: Conversion,
}

impl ChipSettings {
    /// The settings of `model` right after power-on (the MPU-9250's AK8963 with its emulated
    /// fuse-ROM sensitivity adjustment, so a driver that applies it reads the true field).
    pub fn power_on(model: ChipModel) -> Self {
        let conversion = match model.family() {
            Family::Mpu6xxx => Conversion::Mpu6xxx(Mpu6xxxConfig {
                asa: crate::regmap::ak8963::EMULATED_ASA,
                temp: mpu::variant::Variant::for_model(model, model.who_am_i())
                    .map_or(Default::default(), |v| v.temperature()),
                ..Mpu6xxxConfig::NOMINAL
            }),
            Family::Icm42688p => Conversion::Icm42688p(IcmConfig::NOMINAL),
            Family::Ist8310 => Conversion::Ist8310,
            Family::Qmc5883l => Conversion::Qmc5883l(qmc5883l::Range::default()),
            Family::Rm3100 => Conversion::Rm3100([rm3100::reset::CYCLE_COUNT; 3]),
            Family::Bmi270 => Conversion::Bmi270(BmiConfig::NOMINAL),
            Family::Bmi088 => Conversion::Bmi088(Bmi088Config::NOMINAL),
        };
        Self { model, conversion }
    }

    /// The magnetometer ranges (± gauss) a driver can choose, smallest first: the QMC5883L's
    /// two; none for the others (a fixed range, or the AK8963's output-width bit).
    pub fn mag_ranges_gauss(model: ChipModel) -> &'static [f64] {
        match model.family() {
            Family::Qmc5883l => &[2.0, 8.0],
            _ => &[],
        }
    }

    /// These settings with the magnetometer at ± `gauss` (one of
    /// [`ChipSettings::mag_ranges_gauss`]).
    pub fn with_mag_range(mut self, gauss: f64) -> Result<Self, MagRangeError> {
        match &mut self.conversion {
            Conversion::Qmc5883l(range) if gauss == 2.0 => *range = qmc5883l::Range::Gauss2,
            Conversion::Qmc5883l(range) if gauss == 8.0 => *range = qmc5883l::Range::Gauss8,
            _ => return Err(MagRangeError { gauss }),
        }
        Ok(self)
    }

    /// The power-on settings with the given full scales; an error names a range the model
    /// does not have.
    pub fn with_full_scale(model: ChipModel, fs: FullScale) -> Result<Self, SettingsError> {
        let mut settings = Self::power_on(model);
        match &mut settings.conversion {
            Conversion::Mpu6xxx(cfg) => {
                cfg.accel_fs = AccelFs::ALL
                    .into_iter()
                    .find(|a| f64::from(a.range_g()) == fs.accel_g)
                    .ok_or(SettingsError::AccelRange(fs.accel_g))?;
                cfg.gyro_fs = GyroFs::ALL
                    .into_iter()
                    .find(|g| f64::from(g.range_dps()) == fs.gyro_dps)
                    .ok_or(SettingsError::GyroRange(fs.gyro_dps))?;
            }
            Conversion::Icm42688p(cfg) => {
                cfg.accel_fs = icm::AccelFs::ALL
                    .into_iter()
                    .find(|a| a.range_g() == fs.accel_g)
                    .ok_or(SettingsError::AccelRange(fs.accel_g))?;
                cfg.gyro_fs = icm::GyroFs::ALL
                    .into_iter()
                    .find(|g| g.range_dps() == fs.gyro_dps)
                    .ok_or(SettingsError::GyroRange(fs.gyro_dps))?;
            }
            Conversion::Bmi270(cfg) => {
                cfg.acc_range = bmi::AccRange::ALL
                    .into_iter()
                    .find(|a| a.range_g() == fs.accel_g)
                    .ok_or(SettingsError::AccelRange(fs.accel_g))?;
                cfg.gyr_range = bmi::GyrRange::ALL
                    .into_iter()
                    .find(|g| g.range_dps() == fs.gyro_dps)
                    .ok_or(SettingsError::GyroRange(fs.gyro_dps))?;
            }
            Conversion::Bmi088(cfg) => {
                cfg.acc_range = bmi088_accel::AccRange::ALL
                    .into_iter()
                    .find(|a| f64::from(a.full_scale_g()) == fs.accel_g)
                    .ok_or(SettingsError::AccelRange(fs.accel_g))?;
                cfg.gyr_range = bmi088_gyro::GyroRange::ALL
                    .into_iter()
                    .find(|g| f64::from(g.full_scale_dps()) == fs.gyro_dps)
                    .ok_or(SettingsError::GyroRange(fs.gyro_dps))?;
            }
            Conversion::Ist8310 | Conversion::Qmc5883l(_) | Conversion::Rm3100(_) => {
                return Err(SettingsError::AccelRange(fs.accel_g))
            }
        }
        Ok(settings)
    }

    /// The accelerometer ranges (± g) of the model, smallest first.
    pub fn accel_ranges_g(model: ChipModel) -> impl Iterator<Item = f64> {
        let mut ranges: heapless::Vec<f64, 8> = match model.family() {
            Family::Mpu6xxx => AccelFs::ALL
                .iter()
                .map(|a| f64::from(a.range_g()))
                .collect(),
            Family::Icm42688p => icm::AccelFs::ALL.iter().map(|a| a.range_g()).collect(),
            Family::Ist8310 | Family::Qmc5883l | Family::Rm3100 => heapless::Vec::new(),
            Family::Bmi270 => bmi::AccRange::ALL.iter().map(|a| a.range_g()).collect(),
            Family::Bmi088 => bmi088_accel::AccRange::ALL
                .iter()
                .map(|a| f64::from(a.full_scale_g()))
                .collect(),
        };
        ranges.sort_unstable_by(f64::total_cmp);
        ranges.into_iter()
    }

    /// The gyroscope ranges (± °/s) of the model, smallest first.
    pub fn gyro_ranges_dps(model: ChipModel) -> impl Iterator<Item = f64> {
        let mut ranges: heapless::Vec<f64, 8> = match model.family() {
            Family::Mpu6xxx => GyroFs::ALL
                .iter()
                .map(|g| f64::from(g.range_dps()))
                .collect(),
            Family::Icm42688p => icm::GyroFs::ALL.iter().map(|g| g.range_dps()).collect(),
            Family::Ist8310 | Family::Qmc5883l | Family::Rm3100 => heapless::Vec::new(),
            Family::Bmi270 => bmi::GyrRange::ALL.iter().map(|g| g.range_dps()).collect(),
            Family::Bmi088 => bmi088_gyro::GyroRange::ALL
                .iter()
                .map(|g| f64::from(g.full_scale_dps()))
                .collect(),
        };
        ranges.sort_unstable_by(f64::total_cmp);
        ranges.into_iter()
    }

    /// The front end's ranges in SI units, `[accel m/s², gyro rad/s]`: the full scale, where a
    /// sampling chain clips (`None` for a magnetometer).
    pub fn front_end_ranges(&self) -> Option<[f32; 2]> {
        self.full_scale().map(|fs| {
            let g = f64::from(crate::regmap::mpu6xxx::convert::STANDARD_GRAVITY);
            [
                (fs.accel_g * g) as f32,
                (fs.gyro_dps * core::f64::consts::PI / 180.0) as f32,
            ]
        })
    }

    /// The accelerometer and gyroscope full scale in force; `None` for a magnetometer.
    pub fn full_scale(&self) -> Option<FullScale> {
        match &self.conversion {
            Conversion::Mpu6xxx(cfg) => Some(FullScale {
                accel_g: f64::from(cfg.accel_fs.range_g()),
                gyro_dps: f64::from(cfg.gyro_fs.range_dps()),
            }),
            Conversion::Icm42688p(cfg) => Some(FullScale {
                accel_g: cfg.accel_fs.range_g(),
                gyro_dps: cfg.gyro_fs.range_dps(),
            }),
            Conversion::Bmi270(cfg) => Some(FullScale {
                accel_g: cfg.acc_range.range_g(),
                gyro_dps: cfg.gyr_range.range_dps(),
            }),
            Conversion::Bmi088(cfg) => Some(FullScale {
                accel_g: f64::from(cfg.acc_range.full_scale_g()),
                gyro_dps: f64::from(cfg.gyr_range.full_scale_dps()),
            }),
            Conversion::Ist8310 | Conversion::Qmc5883l(_) | Conversion::Rm3100(_) => None,
        }
    }

    /// The magnetometer range in force, ± gauss, where a driver can choose it
    /// ([`ChipSettings::mag_ranges_gauss`]).
    pub fn mag_range_gauss(&self) -> Option<f64> {
        match &self.conversion {
            Conversion::Qmc5883l(qmc5883l::Range::Gauss2) => Some(2.0),
            Conversion::Qmc5883l(qmc5883l::Range::Gauss8) => Some(8.0),
            _ => None,
        }
    }

    /// The register writes, as `(register file, register, value)`, that take a power-on chip to
    /// these full scales and, where one register holds both, to the output rate `rate_hz` (the
    /// ICM-42688-P's GYRO_CONFIG0/ACCEL_CONFIG0; the 6xxx parts keep their power-on rate
    /// registers; the QMC5883L's range in CONF1, in stand-by: its driver starts it). The BMI270 gets its ranges and, in GYR_CONF and ACC_CONF (their other bits
    /// at the power-on values), the gyro ODR of `rate_hz` and the accel ODR nearest below or at
    /// it (1.6 kHz for a 3.2 kHz gyro: the chip then takes every second image's accel). The
    /// BMI088 likewise, die by die (file 0 the accelerometer, file 1 the gyroscope): ACC_RANGE
    /// and, in ACC_CONF (normal filter, as at power-on), the accel ODR at or below `rate_hz`
    /// (1.6 kHz for a 2 kHz gyro, 800 Hz for 1 kHz); GYRO_RANGE and, in GYRO_BANDWIDTH, the
    /// gyro ODR of `rate_hz` with its widest filter. Neither die is switched on: that is the
    /// driver's (ACC_PWR_CTRL, GYRO_LPM1). Writes that would store the power-on value are left
    /// out.
    pub fn config_writes(&self, rate_hz: f64) -> impl Iterator<Item = (u8, u8, u8)> {
        let writes: Writes = match &self.conversion {
            Conversion::Mpu6xxx(cfg) => writes(&[
                (0, mpu::reg::GYRO_CONFIG, cfg.gyro_fs.bits() << 3),
                (0, mpu::reg::ACCEL_CONFIG, cfg.accel_fs.bits() << 3),
            ]),
            // The RM3100's cycle counts are its driver's to set (200, their reset value, in
            // ArduPilot and PX4).
            Conversion::Ist8310 | Conversion::Rm3100(_) => writes(&[]),
            Conversion::Qmc5883l(range) => writes(&[(0, qmc5883l::reg::CONF1, range.conf1_bits())]),
            Conversion::Icm42688p(cfg) => {
                let reset = |reg| icm::reset_value(0, reg);
                let odr = icm::Odr::gyro_of_hz(rate_hz)
                    .map_or(reset(icm::bank0::GYRO_CONFIG0) & 0x0F, icm::Odr::bits);
                writes(&[
                    (0, icm::bank0::GYRO_CONFIG0, cfg.gyro_fs.bits() << 5 | odr),
                    (0, icm::bank0::ACCEL_CONFIG0, cfg.accel_fs.bits() << 5 | odr),
                ])
            }
            Conversion::Bmi270(cfg) => bmi270_writes(cfg, rate_hz),
            Conversion::Bmi088(cfg) => bmi088_writes(cfg, rate_hz),
        };
        let model = self.model;
        writes
            .into_iter()
            .filter(move |&(file, reg, value)| value != power_on_value(model, file, reg))
    }

    /// Writes the chip's own invalid value into the data of the sensors in `sensors` (bits of
    /// `margemu_model::fault::Sensor::bit`) of an image this chip's [`ChipSettings::image`]
    /// made: the dropout fault. Sensors the chip does not have are left alone. Each family's
    /// value and its source: [`super::invalid`].
    pub fn mark_invalid(&self, image: &mut Image, sensors: u8) {
        super::invalid::mark(&self.conversion, self.model, image, sensors);
    }

    /// [`ChipSettings::image`] with the dropout mask `dropout` (what
    /// `margemu_model::fault::SensorFaults::apply` returned for the sample) applied by
    /// [`ChipSettings::mark_invalid`]: the served image of a faulted sample, on the host
    /// (source (a)) and on the device (source (b)) alike.
    pub fn faulted_image(&self, sample: &PhysicalSample, dropout: u8) -> Image {
        let mut image = self.image(sample);
        if dropout != 0 {
            self.mark_invalid(&mut image, dropout);
        }
        image
    }

    /// The register image of `sample` (chip axes) under these settings, of the model's length
    /// (the first bytes of the family's image; zero-padded should a model and a conversion of
    /// different families ever be paired).
    pub fn image(&self, sample: &PhysicalSample) -> Image {
        let mut image = Image::zeroed(self.model.image_len()).unwrap_or_default();
        let (acc, gyr, temp) = (sample.acc, sample.gyr, sample.temp_c);
        let copy = |out: &mut Image, bytes: &[u8]| {
            for (slot, b) in out.as_mut_bytes().iter_mut().zip(bytes) {
                *slot = *b;
            }
        };
        match &self.conversion {
            Conversion::Mpu6xxx(cfg) => copy(
                &mut image,
                &Mpu6xxxRepr::from_physical(acc, gyr, temp, sample.mag, cfg).emit(),
            ),
            Conversion::Icm42688p(cfg) => copy(
                &mut image,
                &IcmRepr::from_physical(acc, gyr, temp, cfg).emit(),
            ),
            Conversion::Ist8310 => copy(
                &mut image,
                &mag_image::emit(ist8310::measurement(sample.mag).0),
            ),
            Conversion::Qmc5883l(range) => copy(
                &mut image,
                &mag_image::emit(qmc5883l::measurement(sample.mag, *range).0),
            ),
            Conversion::Rm3100(cycle_counts) => copy(
                &mut image,
                &rm3100::image(rm3100::measurement(sample.mag, *cycle_counts)),
            ),
            Conversion::Bmi270(cfg) => copy(
                &mut image,
                &BmiRepr::from_physical(acc, gyr, temp, cfg).emit(),
            ),
            Conversion::Bmi088(cfg) => copy(
                &mut image,
                &Bmi088Repr::from_physical(acc, gyr, temp, cfg).emit(),
            ),
        }
        image
    }

    /// The physical values an image of this model stands for under these settings; `None` if
    /// the image is not of the model's length. A BMI270 temperature of 0x8000 (invalid) reads
    /// as NaN, and so does a BMI088 temperature of TEMP_MSB 0x80 (−1024).
    pub fn decode(&self, image: &[u8]) -> Option<Reading> {
        if image.len() != self.model.image_len() {
            return None;
        }
        Some(match &self.conversion {
            Conversion::Mpu6xxx(cfg) => {
                let p = Mpu6xxxRepr::parse_slice(image).to_physical(cfg);
                Reading {
                    acc: p.acc,
                    gyr: p.gyr,
                    temp_c: p.temp_c,
                    mag_ut: self.model.has_magnetometer().then_some(p.mag_ut),
                }
            }
            Conversion::Icm42688p(cfg) => {
                let bytes: &[u8; icm::image::IMAGE_LEN] = image.try_into().ok()?;
                let r = IcmRepr::parse(bytes);
                Reading {
                    acc: r
                        .accel
                        .map(|v| f64::from(icm_convert::accel_from_raw(v, cfg.accel_fs))),
                    gyr: r
                        .gyro
                        .map(|v| f64::from(icm_convert::gyro_from_raw(v, cfg.gyro_fs))),
                    temp_c: f64::from(icm_convert::temp_from_raw(r.temp)),
                    mag_ut: None,
                }
            }
            Conversion::Bmi270(cfg) => {
                let bytes: &[u8; bmi::image::IMAGE_LEN] = image.try_into().ok()?;
                let r = BmiRepr::parse(bytes);
                Reading {
                    acc: r
                        .accel
                        .map(|v| f64::from(bmi_convert::accel_from_raw(v, cfg.acc_range))),
                    gyr: r
                        .gyro
                        .map(|v| f64::from(bmi_convert::gyro_from_raw(v, cfg.gyr_range))),
                    temp_c: bmi_convert::temp_from_raw(r.temp).map_or(f64::NAN, f64::from),
                    mag_ut: None,
                }
            }
            Conversion::Bmi088(cfg) => {
                let bytes: &[u8; crate::regmap::bmi088::image::IMAGE_LEN] =
                    image.try_into().ok()?;
                let r = Bmi088Repr::parse(bytes);
                let temp = bmi088_convert::temp_bytes(r.temp);
                Reading {
                    acc: r
                        .accel
                        .map(|v| f64::from(bmi088_convert::accel_from_raw(v, cfg.acc_range))),
                    gyr: r
                        .gyro
                        .map(|v| f64::from(bmi088_convert::gyro_from_raw(v, cfg.gyr_range))),
                    temp_c: bmi088_convert::temp_from_bytes(temp).map_or(f64::NAN, f64::from),
                    mag_ut: None,
                }
            }
            Conversion::Ist8310 | Conversion::Qmc5883l(_) | Conversion::Rm3100(_) => {
                let mag = match self.conversion {
                    Conversion::Qmc5883l(range) => {
                        qmc5883l::field_ut(mag_image::parse(image.try_into().ok()?), range)
                    }
                    Conversion::Rm3100(cycle_counts) => {
                        rm3100::field_ut(rm3100::parse_image(image.try_into().ok()?), cycle_counts)
                    }
                    _ => ist8310::field_ut(mag_image::parse(image.try_into().ok()?)),
                };
                Reading {
                    acc: [0.0; 3],
                    gyr: [0.0; 3],
                    temp_c: 0.0,
                    mag_ut: Some(mag),
                }
            }
        })
    }
}

/// The register's value right after power-on (file 0 only; others count as 0).
fn power_on_value(model: ChipModel, file: u8, reg: u8) -> u8 {
    match (model.family(), file) {
        (Family::Mpu6xxx, 0) => mpu::reset_value(reg),
        (Family::Icm42688p, bank) => icm::reset_value(bank, reg),
        (Family::Bmi270, 0) => bmi::reset_value(reg),
        (Family::Bmi088, 0) => crate::regmap::bmi088::Die::Accel.reset_value(reg),
        (Family::Bmi088, 1) => crate::regmap::bmi088::Die::Gyro.reset_value(reg),
        _ => 0,
    }
}

/// The configuration writes of one model, `(file, register, value)`.
type Writes = heapless::Vec<(u8, u8, u8), 4>;

/// `list` as [`Writes`] (every list here has at most 4 writes).
fn writes(list: &[(u8, u8, u8)]) -> Writes {
    Writes::from_slice(list).unwrap_or_default()
}

/// The BMI270's writes (see [`ChipSettings::config_writes`]).
fn bmi270_writes(cfg: &BmiConfig, rate_hz: f64) -> Writes {
    let conf = |reg: u8, odr: Option<bmi::Odr>| {
        let reset = bmi::reset_value(reg);
        (0, reg, odr.map_or(reset, |o| (reset & 0xF0) | o.code()))
    };
    let accel_hz = if rate_hz > bmi::Odr::HZ1600.hz() {
        bmi::Odr::HZ1600.hz()
    } else {
        rate_hz
    };
    writes(&[
        (0, bmi::reg::ACC_RANGE, cfg.acc_range.bits()),
        (0, bmi::reg::GYR_RANGE, cfg.gyr_range.bits()),
        conf(bmi::reg::GYR_CONF, bmi::Odr::gyro_of_hz(rate_hz)),
        conf(bmi::reg::ACC_CONF, bmi::Odr::accel_of_hz(accel_hz)),
    ])
}

/// The BMI088's writes (see [`ChipSettings::config_writes`]): file 0 the accelerometer die,
/// file 1 the gyroscope die.
fn bmi088_writes(cfg: &Bmi088Config, rate_hz: f64) -> Writes {
    use crate::regmap::bmi088::Die;
    let acc_conf = Die::Accel.reset_value(bmi088_accel::reg::ACC_CONF);
    let acc_conf = bmi088_accel::Odr::at_most_hz(rate_hz.min(bmi088_accel::Odr::HZ1600.hz()))
        .map_or(acc_conf, |odr| (acc_conf & 0xF0) | odr.code());
    let bandwidth = Die::Gyro.reset_value(bmi088_gyro::reg::BANDWIDTH);
    let bandwidth = bmi088_gyro::Bandwidth::widest_at_hz(rate_hz).map_or(bandwidth, |bw| {
        bmi088_gyro::bits::BANDWIDTH_FIXED | bw.code()
    });
    writes(&[
        (0, bmi088_accel::reg::ACC_RANGE, cfg.acc_range.bits()),
        (0, bmi088_accel::reg::ACC_CONF, acc_conf),
        (1, bmi088_gyro::reg::RANGE, cfg.gyr_range.bits()),
        (1, bmi088_gyro::reg::BANDWIDTH, bandwidth),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bmi(accel_g: f64, gyro_dps: f64) -> ChipSettings {
        let fs = FullScale { accel_g, gyro_dps };
        ChipSettings::with_full_scale(ChipModel::Bmi270, fs).unwrap()
    }

    #[test]
    fn bmi270_config_writes_set_ranges_and_both_rates() {
        let writes: Writes = bmi(16.0, 500.0).config_writes(3200.0).collect();
        // ACC_RANGE ±16 g, GYR_RANGE ±500 °/s, GYR_CONF 3.2 kHz, ACC_CONF 1.6 kHz; the other
        // bits of the CONF registers keep their power-on values (0xA9, 0xA8).
        assert_eq!(
            writes,
            [
                (0, 0x41, 0x03),
                (0, 0x43, 0x02),
                (0, 0x42, 0xAD),
                (0, 0x40, 0xAC)
            ]
        );
        // At the power-on ranges and the power-on rates (gyro 200 Hz, accel 100 Hz) only the
        // accel ODR moves up to the gyro's.
        let writes: Writes = bmi(8.0, 2000.0).config_writes(200.0).collect();
        assert_eq!(writes, [(0, 0x40, 0xA9)]);
        // A rate that is no ODR leaves the CONF registers alone.
        let writes: Writes = bmi(8.0, 2000.0).config_writes(1000.0).collect();
        assert!(writes.is_empty());
        assert_eq!(
            ChipSettings::with_full_scale(
                ChipModel::Bmi270,
                FullScale {
                    accel_g: 8.0,
                    gyro_dps: 4000.0
                }
            ),
            Err(SettingsError::GyroRange(4000.0))
        );
    }

    #[test]
    fn bmi270_images_decode_to_what_was_converted() {
        let s = bmi(4.0, 125.0);
        let sample = PhysicalSample {
            acc: [1.0, -2.0, 9.80665],
            gyr: [0.5, -1.0, 0.25],
            temp_c: 31.5,
            ..Default::default()
        };
        let image = s.image(&sample);
        assert_eq!(image.len(), 14);
        let r = s.decode(&image).unwrap();
        for (got, want) in r.acc.iter().zip(sample.acc) {
            assert!((got - f64::from(want)).abs() <= 9.80665 / 8192.0);
        }
        for (got, want) in r.gyr.iter().zip(sample.gyr) {
            assert!((got - f64::from(want)).abs() <= (1.0f64 / 262.4).to_radians());
        }
        assert_eq!(r.temp_c, 31.5);
        assert_eq!(r.mag_ut, None);
        let mut invalid = [0u8; 14];
        invalid[13] = 0x80;
        assert!(s.decode(&invalid).unwrap().temp_c.is_nan());
        assert_eq!(s.decode(&[0; 13]), None);
        assert_eq!(
            ChipSettings::power_on(ChipModel::Bmi270)
                .full_scale()
                .map(|fs| fs.accel_g),
            Some(8.0)
        );
    }

    #[test]
    fn bmi088_config_writes_set_both_dies() {
        let fs = |accel_g, gyro_dps| FullScale { accel_g, gyro_dps };
        let s = ChipSettings::with_full_scale(ChipModel::Bmi088, fs(24.0, 1000.0)).unwrap();
        let writes: Writes = s.config_writes(2000.0).collect();
        // ACC_RANGE ±24 g, ACC_CONF 1.6 kHz (normal filter); GYRO_RANGE ±1000 °/s; GYRO_BANDWIDTH
        // stays 2 kHz / 532 Hz (its power-on value).
        assert_eq!(writes, [(0, 0x41, 0x03), (0, 0x40, 0xAC), (1, 0x0F, 0x01)]);
        let s = ChipSettings::power_on(ChipModel::Bmi088);
        let writes: Writes = s.config_writes(1000.0).collect();
        assert_eq!(writes, [(0, 0x40, 0xAB), (1, 0x10, 0x82)]); // 800 Hz; 1 kHz / 116 Hz
        let writes: Writes = s.config_writes(100.0).collect();
        assert_eq!(writes, [(1, 0x10, 0x87)]); // accel 100 Hz at power-on; gyro 100 Hz / 32 Hz
        assert_eq!(
            ChipSettings::with_full_scale(ChipModel::Bmi088, fs(16.0, 2000.0)),
            Err(SettingsError::AccelRange(16.0))
        );
        assert_eq!(
            ChipSettings::accel_ranges_g(ChipModel::Bmi088).collect::<heapless::Vec<f64, 8>>(),
            [3.0, 6.0, 12.0, 24.0]
        );
        assert_eq!(
            ChipSettings::gyro_ranges_dps(ChipModel::Bmi088).collect::<heapless::Vec<f64, 8>>(),
            [125.0, 250.0, 500.0, 1000.0, 2000.0]
        );
    }

    #[test]
    fn bmi088_images_decode_to_what_was_converted() {
        let fs = FullScale {
            accel_g: 3.0,
            gyro_dps: 250.0,
        };
        let s = ChipSettings::with_full_scale(ChipModel::Bmi088, fs).unwrap();
        let sample = PhysicalSample {
            acc: [1.0, -2.0, 9.80665],
            gyr: [0.5, -1.0, 0.25],
            temp_c: 31.625,
            ..Default::default()
        };
        let image = s.image(&sample);
        assert_eq!(image.len(), 14);
        let r = s.decode(&image).unwrap();
        for (got, want) in r.acc.iter().zip(sample.acc) {
            assert!((got - f64::from(want)).abs() <= 9.80665 / 10922.0);
        }
        for (got, want) in r.gyr.iter().zip(sample.gyr) {
            assert!((got - f64::from(want)).abs() <= (1.0f64 / 131.0).to_radians());
        }
        assert_eq!((r.temp_c, r.mag_ut), (31.625, None));
        let mut invalid = [0u8; 14];
        invalid[12] = 0x80;
        assert!(s.decode(&invalid).unwrap().temp_c.is_nan());
        assert_eq!(s.decode(&[0; 15]), None);
        assert_eq!(
            ChipSettings::power_on(ChipModel::Bmi088).full_scale(),
            Some(FullScale {
                accel_g: 6.0,
                gyro_dps: 2000.0
            })
        );
    }
}
