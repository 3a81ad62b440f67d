//! [`ChipSettings`]: the register settings a model's conversion depends on, and the conversions
//! physical sample ↔ register image, dispatched to the chip's module.

use super::{ChipModel, Family, Image, PhysicalSample};
use crate::regmap::mpu6xxx::image::{ImageConfig as Mpu6xxxConfig, ImageRepr as Mpu6xxxRepr};
use crate::regmap::mpu6xxx::{AccelFs, GyroFs};

/// The conversion settings of one chip family (full scales, offsets, magnetometer settings).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Conversion {
    /// InvenSense 6xxx (and the AK8963 of the MPU-9250).
    Mpu6xxx(Mpu6xxxConfig),
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
            Family::Mpu6xxx | Family::Icm42688p => Conversion::Mpu6xxx(Mpu6xxxConfig {
                asa: crate::regmap::ak8963::EMULATED_ASA,
                ..Mpu6xxxConfig::NOMINAL
            }),
        };
        Self { model, conversion }
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
        }
        Ok(settings)
    }

    /// The accelerometer ranges (± g) of the model, smallest first.
    pub fn accel_ranges_g(model: ChipModel) -> impl Iterator<Item = f64> {
        let _ = model;
        AccelFs::ALL.into_iter().map(|a| f64::from(a.range_g()))
    }

    /// The gyroscope ranges (± °/s) of the model, smallest first.
    pub fn gyro_ranges_dps(model: ChipModel) -> impl Iterator<Item = f64> {
        let _ = model;
        GyroFs::ALL.into_iter().map(|g| f64::from(g.range_dps()))
    }

    /// The full scale in force.
    pub fn full_scale(&self) -> FullScale {
        match &self.conversion {
            Conversion::Mpu6xxx(cfg) => FullScale {
                accel_g: f64::from(cfg.accel_fs.range_g()),
                gyro_dps: f64::from(cfg.gyro_fs.range_dps()),
            },
        }
    }

    /// The register writes, as `(register file, register, value)`, that take a power-on chip to
    /// these full scales (the rest of the settings are the power-on ones or the chip's own).
    pub fn full_scale_writes(&self) -> impl Iterator<Item = (u8, u8, u8)> {
        use crate::regmap::mpu6xxx::reg;
        let writes = match &self.conversion {
            Conversion::Mpu6xxx(cfg) => [
                (0, reg::GYRO_CONFIG, cfg.gyro_fs.bits() << 3),
                (0, reg::ACCEL_CONFIG, cfg.accel_fs.bits() << 3),
            ],
        };
        writes.into_iter().filter(|&(_, _, value)| value != 0)
    }

    /// The register image of `sample` (chip axes) under these settings, of the model's length.
    pub fn image(&self, sample: &PhysicalSample) -> Image {
        let mut image = Image::zeroed(self.model.image_len()).unwrap_or_default();
        match &self.conversion {
            Conversion::Mpu6xxx(cfg) => {
                let repr = Mpu6xxxRepr::from_physical(
                    sample.acc,
                    sample.gyr,
                    sample.temp_c,
                    sample.mag,
                    cfg,
                )
                .emit();
                let n = image.len();
                image.as_mut_bytes().copy_from_slice(&repr[..n]);
            }
        }
        image
    }

    /// The physical values an image of this model stands for under these settings; `None` if
    /// the image is not of the model's length.
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
        })
    }
}
