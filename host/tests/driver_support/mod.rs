//! Shared by the driver tests (`driver_*.rs`): known physical samples for the emulated chips
//! and the worst deviation, in LSB, of what a driver read from them.
#![allow(dead_code)] // each test file uses its own part

use margemu::bus::{self, Shared};
use margemu_firmware::chip::{Config, Mpu6xxx, PhysicalSample, Variant};

/// Standard gravity, m/s².
pub const G: f64 = 9.80665;

/// Fractions of full scale the samples take: zero, small, negative, just inside, at and beyond
/// both ends (the register saturates at −32768 and 32767).
pub const FRACTIONS: [f64; 11] = [
    0.0, 7.7e-3, 0.3, -0.3, 0.999, -0.999, 1.0, -1.0, 1.7, -2.5, -0.61,
];

/// An emulated MPU-6000 at its power-on state.
pub fn new_mpu6000() -> Shared<Mpu6xxx> {
    bus::shared(Mpu6xxx::with_config(Config {
        variant: Variant::Mpu6000,
        ..Config::default()
    }))
}

/// Which [`FRACTIONS`] a sample's axes take (offsets from the sample's index) and its
/// temperature (`temp_c[0] + i · temp_c[1]`).
pub struct Spread {
    pub acc: [usize; 3],
    pub gyr: [usize; 3],
    pub temp_c: [f32; 2],
}

impl Spread {
    /// Sample `i` at the given full scales: each axis a different fraction of full scale.
    pub fn sample(&self, i: usize, accel_g: f64, gyro_dps: f64) -> PhysicalSample {
        let f = |j: usize| FRACTIONS[(i + j) % FRACTIONS.len()];
        PhysicalSample {
            acc: self.acc.map(|j| (f(j) * accel_g * G) as f32),
            gyr: self.gyr.map(|j| (f(j) * gyro_dps).to_radians() as f32),
            mag: [0.0; 3],
            temp_c: self.temp_c[0] + i as f32 * self.temp_c[1],
        }
    }
}

/// `value` (in LSB) clipped like a 16-bit register.
pub fn clip(value: f64) -> f64 {
    value.clamp(-32768.0, 32767.0)
}

/// Worst deviations (accel, gyro, temperature) in LSB of the current 16-bit full scale, and how
/// many sample axes were at or beyond full scale.
#[derive(Default)]
pub struct Worst {
    pub lsb: [f64; 3],
    pub saturated: usize,
}

impl Worst {
    /// One sample's accelerometer (`accel` in g) and gyroscope (`gyro` in °/s) as the driver
    /// returned them, against `s` at `accel_lsb` and `gyro_lsb` per unit.
    pub fn add(
        &mut self,
        s: &PhysicalSample,
        accel: [f32; 3],
        gyro: [f32; 3],
        accel_lsb: f64,
        gyro_lsb: f64,
    ) {
        for axis in 0..3 {
            let ideal = clip(f64::from(s.acc[axis]) / G * accel_lsb);
            self.lsb[0] = self.lsb[0].max((f64::from(accel[axis]) * accel_lsb - ideal).abs());
            let ideal_g = clip(f64::from(s.gyr[axis]).to_degrees() * gyro_lsb);
            self.lsb[1] = self.lsb[1].max((f64::from(gyro[axis]) * gyro_lsb - ideal_g).abs());
            self.saturated += usize::from(ideal.abs() >= 32767.0 || ideal_g.abs() >= 32767.0);
        }
    }

    /// One temperature's deviation, in LSB.
    pub fn add_temperature(&mut self, deviation_lsb: f64) {
        self.lsb[2] = self.lsb[2].max(deviation_lsb);
    }

    /// Prints the worst deviations; checks that all are within one LSB and that some samples
    /// were beyond full scale.
    pub fn check(&self) {
        let worst = self.lsb;
        println!(
            "worst deviation (LSB): accel {:.3}, gyro {:.3}, temperature {:.3}",
            worst[0], worst[1], worst[2]
        );
        assert!(worst.iter().all(|&w| w <= 1.0), "{worst:?}");
        assert!(self.saturated > 0, "some samples beyond full scale");
    }
}

/// Pseudo-random samples (xorshift64 from `state`, which must not be 0): every axis and the
/// temperature's offset from 22.5 °C uniform in ±1.3 × `accel_fs` (m/s²), `gyro_fs` (rad/s)
/// and 48 °C.
pub fn random_samples(
    mut state: u64,
    accel_fs: f64,
    gyro_fs: f64,
) -> impl Iterator<Item = PhysicalSample> {
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.6 - 1.3
    };
    std::iter::repeat_with(move || PhysicalSample {
        acc: [0; 3].map(|_| (next() * accel_fs) as f32),
        gyr: [0; 3].map(|_| (next() * gyro_fs) as f32),
        mag: [0.0; 3],
        temp_c: (22.5 + next() * 48.0) as f32,
    })
}
