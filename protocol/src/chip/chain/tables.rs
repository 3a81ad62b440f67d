//! The datasheet tables the chains are built from, one row per configuration code. Sources and
//! what each row means are in the [parent module's docs](super).

/// One row of a filter table: the configuration code, the rate the table gives for it (the
/// register rate; the InvenSense DLPF runs on the faster ADC samples before it, see
/// `super::build`), its −3 dB bandwidth and, where the datasheet gives one, its delay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Row {
    /// The register code the row is selected by (see each table).
    pub code: u8,
    /// The table's sample period, ns.
    pub period_ns: u64,
    /// The −3 dB bandwidth, Hz.
    pub bandwidth_hz: f64,
    /// The datasheet's delay, ms (`None`: not given).
    pub delay_ms: Option<f64>,
}

const fn row(code: u8, khz: u32, bandwidth_hz: f64, delay_ms: f64) -> Row {
    Row {
        code,
        period_ns: 1_000_000 / khz as u64,
        bandwidth_hz,
        delay_ms: Some(delay_ms),
    }
}

/// MPU-6500 / MPU-9250 gyro (RM-MPU-6500A rev. 2.1 and RM-MPU-9250A rev. 1.6 section 4.6,
/// table "FCHOICE_B / DLPF_CFG"). Code: DLPF_CFG 0–7 with FCHOICE_B = 00; 8 = FCHOICE_B x1
/// (8800 Hz, 32 kHz), 9 = FCHOICE_B 10 (3600 Hz, 32 kHz).
pub const MPU6500_GYRO: [Row; 10] = [
    row(0, 8, 250.0, 0.97),
    row(1, 1, 184.0, 2.9),
    row(2, 1, 92.0, 3.9),
    row(3, 1, 41.0, 5.9),
    row(4, 1, 20.0, 9.9),
    row(5, 1, 10.0, 17.85),
    row(6, 1, 5.0, 33.48),
    row(7, 8, 3600.0, 0.17),
    row(8, 32, 8800.0, 0.064),
    row(9, 32, 3600.0, 0.11),
];

/// MPU-6500 / MPU-9250 accelerometer (same documents, section 4.8, table "Accelerometer Data
/// Rates and Bandwidths (Normal Mode)"). Code: A_DLPF_CFG 0–7 with ACCEL_FCHOICE_B = 0; 8 =
/// ACCEL_FCHOICE_B = 1 (1130 Hz, 4 kHz).
pub const MPU6500_ACCEL: [Row; 9] = [
    row(0, 1, 460.0, 1.94),
    row(1, 1, 184.0, 5.80),
    row(2, 1, 92.0, 7.80),
    row(3, 1, 41.0, 11.80),
    row(4, 1, 20.0, 19.80),
    row(5, 1, 10.0, 35.70),
    row(6, 1, 5.0, 66.96),
    row(7, 1, 460.0, 1.94),
    row(8, 4, 1130.0, 0.75),
];

/// ICM-20602 gyro (DS-000176 rev. 1.0 section 10.2 table 2), codes as [`MPU6500_GYRO`].
pub const ICM20602_GYRO: [Row; 10] = [
    row(0, 8, 250.0, 0.97),
    row(1, 1, 176.0, 2.9),
    row(2, 1, 92.0, 3.9),
    row(3, 1, 41.0, 5.9),
    row(4, 1, 20.0, 9.9),
    row(5, 1, 10.0, 17.85),
    row(6, 1, 5.0, 33.48),
    row(7, 8, 3281.0, 0.17),
    row(8, 32, 8173.0, 0.064),
    row(9, 32, 3281.0, 0.11),
];

/// ICM-20602 accelerometer (DS-000176 section 10.3 table 3), codes as [`MPU6500_ACCEL`].
pub const ICM20602_ACCEL: [Row; 9] = [
    row(0, 1, 218.1, 1.88),
    row(1, 1, 218.1, 1.88),
    row(2, 1, 99.0, 2.88),
    row(3, 1, 44.8, 4.88),
    row(4, 1, 21.2, 8.87),
    row(5, 1, 10.2, 16.83),
    row(6, 1, 5.1, 32.48),
    row(7, 1, 420.0, 1.38),
    row(8, 4, 1046.0, 0.503),
];

/// MPU-6000 gyro (RM-MPU-6000A rev. 4.2 section 4.3, register 26 CONFIG): DLPF_CFG 0–6 (7 is
/// reserved).
pub const MPU6000_GYRO: [Row; 7] = [
    row(0, 8, 256.0, 0.98),
    row(1, 1, 188.0, 1.9),
    row(2, 1, 98.0, 2.8),
    row(3, 1, 42.0, 4.8),
    row(4, 1, 20.0, 8.3),
    row(5, 1, 10.0, 13.4),
    row(6, 1, 5.0, 18.6),
];

/// MPU-6000 accelerometer, same table (one DLPF_CFG for both; the accelerometer at 1 kHz).
pub const MPU6000_ACCEL: [Row; 7] = [
    row(0, 1, 260.0, 0.0),
    row(1, 1, 184.0, 2.0),
    row(2, 1, 94.0, 3.0),
    row(3, 1, 44.0, 4.9),
    row(4, 1, 21.0, 8.5),
    row(5, 1, 10.0, 13.8),
    row(6, 1, 5.0, 19.0),
];

/// ICM-42688-P anti-alias filter (DS-000347 rev. 1.7 section 5.3, table "AAF bandwidth
/// programming"): the −3 dB bandwidth of AAF_DELT 1–63, index `delt − 1` (DELTSQR = DELT² and
/// BITSHIFT follow from the same row; drivers write them together).
pub const ICM42688P_AAF_HZ: [u16; 63] = [
    42, 84, 126, 170, 213, 258, 303, 348, 394, 441, 488, 536, 585, 634, 684, 734, 785, 837, 890,
    943, 997, 1051, 1107, 1163, 1220, 1277, 1336, 1395, 1454, 1515, 1577, 1639, 1702, 1766, 1830,
    1896, 1962, 2029, 2097, 2166, 2235, 2306, 2377, 2449, 2522, 2596, 2671, 2746, 2823, 2900, 2978,
    3057, 3137, 3217, 3299, 3381, 3464, 3548, 3633, 3718, 3805, 3892, 3979,
];

/// ICM-42688-P UI filter bandwidth divisors (DS-000347 section 14, GYRO_ACCEL_CONFIG0): index
/// 0 is ODR/2, 1–7 are max(400 Hz, ODR) divided by these.
pub const ICM42688P_UI_DIVISORS: [f64; 8] = [2.0, 4.0, 5.0, 8.0, 10.0, 16.0, 20.0, 40.0];

/// BMI088 gyroscope (BST-BMI088-DS001 rev. 1.3 section 5.5.5, GYRO_BANDWIDTH): code 0–7, the
/// filter runs at the ODR the code selects. No delays are given.
pub const BMI088_GYRO: [Row; 8] = [
    Row {
        code: 0,
        period_ns: 500_000,
        bandwidth_hz: 532.0,
        delay_ms: None,
    },
    Row {
        code: 1,
        period_ns: 500_000,
        bandwidth_hz: 230.0,
        delay_ms: None,
    },
    Row {
        code: 2,
        period_ns: 1_000_000,
        bandwidth_hz: 116.0,
        delay_ms: None,
    },
    Row {
        code: 3,
        period_ns: 2_500_000,
        bandwidth_hz: 47.0,
        delay_ms: None,
    },
    Row {
        code: 4,
        period_ns: 5_000_000,
        bandwidth_hz: 23.0,
        delay_ms: None,
    },
    Row {
        code: 5,
        period_ns: 10_000_000,
        bandwidth_hz: 12.0,
        delay_ms: None,
    },
    Row {
        code: 6,
        period_ns: 5_000_000,
        bandwidth_hz: 64.0,
        delay_ms: None,
    },
    Row {
        code: 7,
        period_ns: 10_000_000,
        bandwidth_hz: 32.0,
        delay_ms: None,
    },
];

/// BMI088 accelerometer −3 dB in normal filter mode (acc_bwp 0xA) per ACC_CONF ODR code 5
/// (12.5 Hz) to 12 (1.6 kHz) (BST-BMI088-DS001 section 4.4.1). OSR2 (0x9) and OSR4 (0x8)
/// have the normal bandwidth of half and a quarter the ODR (ArduPilot's driver: "OSR2 gives
/// 234 Hz LPF @ 1.6 kHz ODR", the normal figure at 800 Hz); below the table, half again.
pub const BMI088_ACCEL_NORMAL_HZ: [f64; 8] = [5.0, 10.5, 20.8, 40.8, 80.0, 145.0, 234.0, 280.0];

/// BMI270 −3 dB per ODR as a fraction of the ODR in normal filter mode, accelerometer and
/// gyroscope. APPROXIMATION: from the datasheet's key features (BST-BMI270-DS000 rev. 1.3:
/// "bandwidth 5.5 | 11 … 740 | 751 Hz", i.e. 740 Hz at the accelerometer's 1.6 kHz and 751 Hz
/// at the gyroscope's 3.2 kHz, both in normal mode); OSR2 halves and OSR4 quarters it.
pub const BMI270_NORMAL_FRACTION: (f64, f64) = (740.0 / 1600.0, 751.0 / 3200.0);
