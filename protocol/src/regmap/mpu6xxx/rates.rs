//! Internal sensor rates and the output rate of each part, and the rule that decides when the
//! accelerometer registers take a new value.
//!
//! **Gyro** (and the output clock it drives): RM-MPU-6500A rev. 2.1 / RM-MPU-9250A rev. 1.6
//! section 4.6 table "FCHOICE_B / DLPF_CFG", DS-000176 (ICM-20602) section 10.2 table 2:
//! FCHOICE_B ≠ 00 → 32 kHz; DLPF_CFG 0 or 7 → 8 kHz; otherwise 1 kHz. The MPU-6000 has no
//! FCHOICE_B (RM-MPU-6000A rev. 4.2 section 4.6): 8 kHz at DLPF_CFG 0/7, else 1 kHz.
//!
//! **Output rate** (data ready, FIFO, data registers): the gyro rate, divided by
//! `1 + SMPLRT_DIV` only at 1 kHz on the MPU-6500/9250/ICM-20602 (their section 4.4: "only
//! effective when FCHOICE_B = 00 and 0 < DLPF_CFG < 7"), always on the MPU-6000 (its
//! section 4.2: "Sample Rate = Gyroscope Output Rate / (1 + SMPLRT_DIV)").
//!
//! **Accelerometer**: RM-MPU-6500A / RM-MPU-9250A section 4.8 table "Accelerometer Data Rates
//! and Bandwidths (Normal Mode)" and DS-000176 section 10.3 table 3: ACCEL_FCHOICE_B = 1
//! (bypassing the accel DLPF) → 4 kHz; otherwise 1 kHz. The MPU-6000 accelerometer outputs at
//! 1 kHz whatever the settings (RM-MPU-6000A section 4.2 note: "for a Sample Rate greater than
//! 1kHz, the same accelerometer sample may be output to the FIFO, DMP, and sensor registers more
//! than once").
//!
//! **The hold rule** ([`SensorClock`]): the accelerometer samples at the instants
//! `k · accel_period` of the chip's clock (ns since the chip's time origin). A latch at `t`
//! takes a new accelerometer value iff an accelerometer instant fell since the latch that last
//! took one, i.e. `t / accel_period` (integer division) differs from that latch's, or the
//! accel period changed, or nothing was taken since a reset; otherwise the accel registers and
//! the FIFO repeat the last value. With the gyro at 8 kHz and the accel at 4 kHz, latches at
//! `n · 125 µs` give each accel value twice (after the first); at 8 kHz with a 1 kHz accel,
//! eight times. The gyro follows the same rule with its own period; latched at the output
//! rate (never faster than the gyro's) it takes every latch, and only a board latching faster
//! than the gyro samples sees gyro values repeat. Deterministic: it depends only on the latch
//! instants and the registers.
//!
//! ```
//! use margemu_protocol::regmap::mpu6xxx::rates::{accel_period_ns, sample_period_ns, SensorClock};
//! use margemu_protocol::regmap::mpu6xxx::variant::Variant;
//! let v = Variant::Icm20602;
//! assert_eq!(sample_period_ns(v, 0x07, 0x00, 0), 125_000); // DLPF_CFG 7: 8 kHz
//! let period = accel_period_ns(v, 0x08); // ACCEL_FCHOICE_B: 4 kHz
//! let mut clock = SensorClock::default();
//! let taken: Vec<bool> = (1..=6).map(|n| clock.take(period, n * 125_000)).collect();
//! assert_eq!(taken, [true, true, false, true, false, true]);
//! ```

use super::bits;
use super::variant::Variant;

/// ACCEL_CONFIG2: ACCEL_FCHOICE_B (bypass the accel DLPF, 4 kHz).
pub const ACCEL_FCHOICE_B: u8 = 1 << 3;

/// Nanoseconds between the gyro's internal samples for CONFIG and GYRO_CONFIG.
pub const fn gyro_period_ns(variant: Variant, config: u8, gyro_config: u8) -> u64 {
    if variant.has_gyro_fchoice() && gyro_config & bits::GYRO_FCHOICE_B != 0 {
        31_250
    } else {
        match config & bits::CONFIG_DLPF_CFG {
            0 | 7 => 125_000,
            _ => 1_000_000,
        }
    }
}

/// Nanoseconds between samples (data ready, FIFO records) for CONFIG, GYRO_CONFIG and
/// SMPLRT_DIV.
pub const fn sample_period_ns(variant: Variant, config: u8, gyro_config: u8, div: u8) -> u64 {
    let gyro = gyro_period_ns(variant, config, gyro_config);
    let divided = gyro == 1_000_000 || matches!(variant, Variant::Mpu6000);
    if divided {
        gyro * (1 + div as u64)
    } else {
        gyro
    }
}

/// Nanoseconds between the accelerometer's internal samples for ACCEL_CONFIG2.
pub const fn accel_period_ns(variant: Variant, accel_config2: u8) -> u64 {
    if variant.has_accel_config2() && accel_config2 & ACCEL_FCHOICE_B != 0 {
        250_000
    } else {
        1_000_000
    }
}

/// A sensor's sample clock as the latches see it (see the module docs): one for the
/// accelerometer, one for the gyro.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SensorClock {
    /// Period and `t / period` of the latch that last took a new accel value.
    last: Option<(u64, u64)>,
}

impl SensorClock {
    /// Whether a latch at `t_ns` takes a new value of the sensor; records it if so.
    /// `period_ns` 0 is taken as "every latch".
    pub fn take(&mut self, period_ns: u64, t_ns: u64) -> bool {
        let index = t_ns.checked_div(period_ns).unwrap_or(t_ns);
        let new = self.last != Some((period_ns, index));
        if new {
            self.last = Some((period_ns, index));
        }
        new
    }

    /// Restarts the sensor's path (a reset): the next latch takes a new value.
    pub fn restart(&mut self) {
        self.last = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn output_rates_per_variant() {
        for v in [Variant::Mpu9250, Variant::Mpu6500, Variant::Icm20602] {
            assert_eq!(sample_period_ns(v, 0x00, 0x00, 9), 125_000);
            assert_eq!(sample_period_ns(v, 0x03, 0x00, 9), 10_000_000);
            assert_eq!(sample_period_ns(v, 0x03, 0x02, 9), 31_250);
            assert_eq!(
                sample_period_ns(v, 0x03, 0x00, 9),
                super::super::sample_period_ns(0x03, 0x00, 9)
            );
        }
        let m = Variant::Mpu6000;
        assert_eq!(sample_period_ns(m, 0x00, 0x00, 0), 125_000);
        assert_eq!(sample_period_ns(m, 0x00, 0x00, 7), 1_000_000); // 8 kHz / 8
        assert_eq!(sample_period_ns(m, 0x07, 0x03, 1), 250_000); // no FCHOICE_B
        assert_eq!(sample_period_ns(m, 0x01, 0x00, 4), 5_000_000);
        assert_eq!(sample_period_ns(m, 0x01, 0x00, 255), 256_000_000);
    }

    #[test]
    fn accel_rates_per_variant() {
        assert_eq!(accel_period_ns(Variant::Mpu6500, 0x08), 250_000);
        assert_eq!(accel_period_ns(Variant::Mpu6500, 0x07), 1_000_000);
        assert_eq!(accel_period_ns(Variant::Icm20602, 0x38), 250_000);
        assert_eq!(accel_period_ns(Variant::Mpu6000, 0x08), 1_000_000);
    }

    #[test]
    fn accel_clock_repeats_until_the_next_accel_instant() {
        let mut c = SensorClock::default();
        // 8 kHz latches, 1 kHz accel: new at 125 µs (first), 1 ms, 2 ms.
        let taken = (1..=16u64).map(|n| c.take(1_000_000, n * 125_000));
        let first_new = [1, 8, 16];
        for (n, new) in (1..=16u64).zip(taken) {
            assert_eq!(new, first_new.contains(&n), "latch {n}");
        }
        // A period change takes a new value at once; a restart too.
        assert!(c.take(250_000, 2_000_000));
        assert!(!c.take(250_000, 2_100_000));
        c.restart();
        assert!(c.take(250_000, 2_100_000));
        assert!(c.take(0, 5) && c.take(0, 6));
    }
}
