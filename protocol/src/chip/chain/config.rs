//! [`ChainConfig`]: a chip family's filter settings as register codes, their defaults per
//! output rate, their names for scenes, and their few bytes for the link.

use super::ChainError;
use crate::chip::{ChipModel, Family};
use crate::link::Rate;

/// A chip family's filter settings, as the codes of its registers (not Hz).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChainConfig {
    /// InvenSense 6xxx: CONFIG DLPF_CFG (0–7), GYRO_CONFIG FCHOICE_B (0–3; 0 on the MPU-6000),
    /// ACCEL_CONFIG2 A_DLPF_CFG (0–7) and ACCEL_FCHOICE_B (not on the MPU-6000, whose
    /// DLPF_CFG sets both sensors: keep them 0 / false there).
    Mpu6xxx {
        /// CONFIG bits 2:0.
        dlpf_cfg: u8,
        /// GYRO_CONFIG bits 1:0 (x1: 8800 Hz at 32 kHz, 10: 3600 Hz at 32 kHz).
        fchoice_b: u8,
        /// ACCEL_CONFIG2 bits 2:0.
        a_dlpf_cfg: u8,
        /// ACCEL_CONFIG2 bit 3 (bypass the accel DLPF: 4 kHz).
        accel_fchoice_b: bool,
    },
    /// ICM-42688-P: AAF_DELT of each sensor (1–63; 0 = AAF disabled, GYRO_AAF_DIS /
    /// ACCEL_AAF_DIS), UI filter order (GYRO_UI_FILT_ORD / ACCEL_UI_FILT_ORD: 0 first, 1 second,
    /// 2 third) and bandwidth index (GYRO_ACCEL_CONFIG0 nibbles: 0–7, 14, 15).
    Icm42688p {
        /// GYRO_CONFIG_STATIC3 GYRO_AAF_DELT.
        gyro_aaf_delt: u8,
        /// ACCEL_CONFIG_STATIC2 ACCEL_AAF_DELT.
        accel_aaf_delt: u8,
        /// GYRO_CONFIG1 bits 3:2.
        gyro_ui_order: u8,
        /// GYRO_ACCEL_CONFIG0 bits 3:0.
        gyro_ui_bw: u8,
        /// ACCEL_CONFIG1 bits 4:3.
        accel_ui_order: u8,
        /// GYRO_ACCEL_CONFIG0 bits 7:4.
        accel_ui_bw: u8,
    },
    /// BMI270: GYR_CONF gyr_filter_perf (bit 7) and gyr_bwp (bits 5:4: 0 OSR4, 1 OSR2, 2
    /// normal), ACC_CONF acc_filter_perf (bit 7) and acc_bwp (bits 6:4: 0 OSR4, 1 OSR2, 2
    /// normal; 3–7 low-power averaging, not modelled).
    Bmi270 {
        /// GYR_CONF bit 7.
        gyro_filter_perf: bool,
        /// GYR_CONF bits 5:4.
        gyro_bwp: u8,
        /// ACC_CONF bit 7.
        acc_filter_perf: bool,
        /// ACC_CONF bits 6:4.
        acc_bwp: u8,
    },
    /// BMI088: GYRO_BANDWIDTH code (0–7: ODR and filter together) and ACC_CONF acc_bwp (0x8
    /// OSR4, 0x9 OSR2, 0xA normal).
    Bmi088 {
        /// GYRO_BANDWIDTH bits 3:0.
        gyro_bandwidth: u8,
        /// ACC_CONF bits 7:4.
        acc_bwp: u8,
    },
}

/// Bytes of the longest [`ChainConfig::encode`].
pub const MAX_ENCODED_LEN: usize = 7;

/// The keys (field names) of each family's settings, in encoding order.
const MPU_KEYS: [&str; 4] = ["dlpf_cfg", "fchoice_b", "a_dlpf_cfg", "accel_fchoice_b"];
const ICM_KEYS: [&str; 6] = [
    "gyro_aaf_delt",
    "accel_aaf_delt",
    "gyro_ui_order",
    "gyro_ui_bw",
    "accel_ui_order",
    "accel_ui_bw",
];
const BMI270_KEYS: [&str; 4] = ["gyro_filter_perf", "gyro_bwp", "acc_filter_perf", "acc_bwp"];
const BMI088_KEYS: [&str; 2] = ["gyro_bandwidth", "acc_bwp"];

impl ChainConfig {
    /// The settings a flight controller's driver writes for `model` at `output_rate`; `None` for
    /// a magnetometer.
    ///
    /// - 6xxx: 32 kHz: FCHOICE_B = 01 (8800 Hz; Betaflight 3.x `gyro_use_32khz`,
    ///   src/main/drivers/accgyro/accgyro_mpu.c); 8 kHz and rates only the 8 kHz gyro divides
    ///   to: DLPF_CFG 0 (Betaflight's `GYRO_HARDWARE_LPF_NORMAL`, ArduPilot's fast sampling);
    ///   1 kHz and below: DLPF_CFG 1 (ArduPilot libraries/AP_InertialSensor/
    ///   AP_InertialSensor_Invensense.cpp, `BITS_DLPF_CFG_188HZ`). Accelerometer (not the
    ///   MPU-6000): above 1 kHz ACCEL_FCHOICE_B = 1, 4 kHz (PX4 src/drivers/imu/invensense/
    ///   {mpu9250,icm20602}), else A_DLPF_CFG at its reset value 0.
    /// - ICM-42688-P: Betaflight src/main/drivers/accgyro/accgyro_spi_icm426xx.c: both AAFs
    ///   258 Hz (DELT 6), UI filters "low latency" (bandwidth 15), orders at their reset
    ///   value (1, second order), at every rate.
    /// - BMI270: Betaflight src/main/drivers/accgyro/accgyro_spi_bmi270.c: normal filter
    ///   (bwp 2) with filter_perf for both sensors.
    /// - BMI088: ArduPilot libraries/AP_InertialSensor/AP_InertialSensor_BMI088.cpp: accel
    ///   OSR2 (ACC_CONF 0x9C); gyro GYRO_BANDWIDTH 0x80 (2 kHz, 532 Hz) at 2 kHz, otherwise
    ///   the widest filter at the rate.
    pub fn default_for(model: ChipModel, output_rate: Rate) -> Option<Self> {
        let hz = output_rate.as_hz_f64();
        Some(match model.family() {
            Family::Mpu6xxx => {
                let is_6000 = model == ChipModel::Mpu6000;
                let on_1k = (1..=256u32).any(|n| (1000.0 / f64::from(n) - hz).abs() <= 1e-9 * hz);
                let fchoice_b = u8::from(!is_6000 && (hz - 32_000.0).abs() < 1e-6);
                Self::Mpu6xxx {
                    dlpf_cfg: if on_1k { 1 } else { 0 },
                    fchoice_b,
                    a_dlpf_cfg: 0,
                    accel_fchoice_b: !is_6000 && hz > 1000.0,
                }
            }
            Family::Icm42688p => Self::Icm42688p {
                gyro_aaf_delt: 6,
                accel_aaf_delt: 6,
                gyro_ui_order: 1,
                gyro_ui_bw: 15,
                accel_ui_order: 1,
                accel_ui_bw: 15,
            },
            Family::Bmi270 => Self::Bmi270 {
                gyro_filter_perf: true,
                gyro_bwp: 2,
                acc_filter_perf: true,
                acc_bwp: 2,
            },
            Family::Bmi088 => Self::Bmi088 {
                gyro_bandwidth: if (hz - 2000.0).abs() < 1e-6 {
                    0
                } else {
                    crate::regmap::bmi088::gyro::Bandwidth::widest_at_hz(hz).map_or(0, |b| b.code())
                },
                acc_bwp: 0x9,
            },
            Family::Ist8310 | Family::Qmc5883l | Family::Rm3100 => return None,
        })
    }

    /// The family these settings belong to.
    pub fn family(&self) -> Family {
        match self {
            Self::Mpu6xxx { .. } => Family::Mpu6xxx,
            Self::Icm42688p { .. } => Family::Icm42688p,
            Self::Bmi270 { .. } => Family::Bmi270,
            Self::Bmi088 { .. } => Family::Bmi088,
        }
    }

    /// The keys (field names) of `family`'s settings; empty for a magnetometer.
    pub fn keys(family: Family) -> &'static [&'static str] {
        match family {
            Family::Mpu6xxx => &MPU_KEYS,
            Family::Icm42688p => &ICM_KEYS,
            Family::Bmi270 => &BMI270_KEYS,
            Family::Bmi088 => &BMI088_KEYS,
            Family::Ist8310 | Family::Qmc5883l | Family::Rm3100 => &[],
        }
    }

    /// The settings' values in [`ChainConfig::keys`] order (a flag as 0 or 1).
    pub fn values(&self) -> heapless::Vec<u8, 6> {
        let v: &[u8] = match *self {
            Self::Mpu6xxx {
                dlpf_cfg,
                fchoice_b,
                a_dlpf_cfg,
                accel_fchoice_b,
            } => &[dlpf_cfg, fchoice_b, a_dlpf_cfg, u8::from(accel_fchoice_b)],
            Self::Icm42688p {
                gyro_aaf_delt,
                accel_aaf_delt,
                gyro_ui_order,
                gyro_ui_bw,
                accel_ui_order,
                accel_ui_bw,
            } => &[
                gyro_aaf_delt,
                accel_aaf_delt,
                gyro_ui_order,
                gyro_ui_bw,
                accel_ui_order,
                accel_ui_bw,
            ],
            Self::Bmi270 {
                gyro_filter_perf,
                gyro_bwp,
                acc_filter_perf,
                acc_bwp,
            } => &[
                u8::from(gyro_filter_perf),
                gyro_bwp,
                u8::from(acc_filter_perf),
                acc_bwp,
            ],
            Self::Bmi088 {
                gyro_bandwidth,
                acc_bwp,
            } => &[gyro_bandwidth, acc_bwp],
        };
        heapless::Vec::from_slice(v).unwrap_or_default()
    }

    /// The settings of `family` with `values` in [`ChainConfig::keys`] order (a flag is any
    /// non-zero value); `None` for a magnetometer or a wrong count. Codes are checked by
    /// [`crate::chip::ChipChain::new`], not here.
    pub fn from_values(family: Family, values: &[u8]) -> Option<Self> {
        let flag = |b: u8| b != 0;
        Some(match (family, values) {
            (Family::Mpu6xxx, &[a, b, c, d]) => Self::Mpu6xxx {
                dlpf_cfg: a,
                fchoice_b: b,
                a_dlpf_cfg: c,
                accel_fchoice_b: flag(d),
            },
            (Family::Icm42688p, &[a, b, c, d, e, f]) => Self::Icm42688p {
                gyro_aaf_delt: a,
                accel_aaf_delt: b,
                gyro_ui_order: c,
                gyro_ui_bw: d,
                accel_ui_order: e,
                accel_ui_bw: f,
            },
            (Family::Bmi270, &[a, b, c, d]) => Self::Bmi270 {
                gyro_filter_perf: flag(a),
                gyro_bwp: b,
                acc_filter_perf: flag(c),
                acc_bwp: d,
            },
            (Family::Bmi088, &[a, b]) => Self::Bmi088 {
                gyro_bandwidth: a,
                acc_bwp: b,
            },
            _ => return None,
        })
    }

    fn tag(&self) -> u8 {
        match self {
            Self::Mpu6xxx { .. } => 0,
            Self::Icm42688p { .. } => 1,
            Self::Bmi270 { .. } => 2,
            Self::Bmi088 { .. } => 3,
        }
    }

    /// Writes the settings to `out` as a family tag and the values in key order; returns the
    /// bytes written, 0 if `out` is shorter than that (at most [`MAX_ENCODED_LEN`]).
    pub fn encode(&self, out: &mut [u8]) -> usize {
        let values = self.values();
        let len = 1 + values.len();
        match out.get_mut(..len) {
            Some(slot) => {
                if let Some((tag, rest)) = slot.split_first_mut() {
                    *tag = self.tag();
                    rest.copy_from_slice(&values);
                }
                len
            }
            None => 0,
        }
    }

    /// The settings [`ChainConfig::encode`] wrote to `bytes` (exactly its length).
    pub fn decode(bytes: &[u8]) -> Result<Self, ChainError> {
        let (&tag, values) = bytes.split_first().ok_or(ChainError::Malformed)?;
        let family = match tag {
            0 => Family::Mpu6xxx,
            1 => Family::Icm42688p,
            2 => Family::Bmi270,
            3 => Family::Bmi088,
            _ => return Err(ChainError::Malformed),
        };
        let config = Self::from_values(family, values).ok_or(ChainError::Malformed)?;
        // The link carries a flag as 0 or 1 only: one encoding per setting, so what decodes
        // encodes back to the same bytes.
        if config.values().as_slice() != values {
            return Err(ChainError::Malformed);
        }
        Ok(config)
    }
}
