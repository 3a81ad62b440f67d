//! Register-level tests of the emulated RM3100 over I2C and SPI: registers, bus transactions,
//! measurement timing and data, and the register sequences of two flight-controller drivers,
//! ArduPilot `libraries/AP_Compass/AP_Compass_RM3100.cpp` (`fc_ardupilot.rs`) and PX4
//! `src/drivers/magnetometer/rm3100/` (`fc_px4.rs`). The sequences are re-described here from
//! reading those drivers, not copied.

#![allow(missing_docs)]

mod bus;
mod fc_ardupilot;
mod fc_px4;
mod measurements;
mod random_sequences;
mod registers;

#[path = "../common/transactions.rs"]
mod transactions;

pub use transactions::*;

use margemu_firmware::chip::{PhysicalSample, Rm3100};
use margemu_protocol::regmap::rm3100::from_data_bytes;

pub const MS: u64 = 1_000_000;
pub const US: u64 = 1_000;
pub const ADDRESS: u8 = 0x20;

/// Three axes at 200 cycle counts: 3 × (60 µs + 2 × 200 / 180 kHz).
pub const MEAS_3X200: u64 = 6_846_666;

/// How a driver reaches the chip.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Link {
    /// I2C at this address; register reads with a repeated START.
    I2c(u8),
    /// SPI, bit 7 of the address byte reads.
    Spi,
}

/// Writes `values` from `reg` on; returns whether every byte was acknowledged (SPI: always).
pub fn write(mag: &mut Rm3100, link: Link, reg: u8, values: &[u8]) -> bool {
    match link {
        Link::I2c(address) => {
            let mut bytes = vec![reg];
            bytes.extend_from_slice(values);
            i2c_write(mag, address, &bytes).into_iter().all(|ack| ack)
        }
        Link::Spi => {
            let mut mosi = vec![reg];
            mosi.extend_from_slice(values);
            let miso = spi(mag, &mosi);
            assert!(miso[1..].iter().all(|&b| b == 0), "MISO 0x00 during writes");
            true
        }
    }
}

/// Reads `n` registers from `reg` on.
pub fn read(mag: &mut Rm3100, link: Link, reg: u8, n: usize) -> Vec<u8> {
    match link {
        Link::I2c(address) => i2c_read(mag, address, reg, n).expect("address acknowledged"),
        Link::Spi => spi_read(mag, reg, n),
    }
}

/// One register write that must be acknowledged.
pub fn write_reg(mag: &mut Rm3100, link: Link, reg: u8, value: u8) {
    assert!(write(mag, link, reg, &[value]), "write {reg:#04x}");
}

/// A sample with this field (µT, chip axes).
pub fn field(mag: [f32; 3]) -> PhysicalSample {
    PhysicalSample {
        mag,
        ..Default::default()
    }
}

/// The x, y, z results of 9 bytes from MX2 on.
pub fn decode(bytes: &[u8]) -> [i32; 3] {
    core::array::from_fn(|i| from_data_bytes([bytes[3 * i], bytes[3 * i + 1], bytes[3 * i + 2]]))
}

/// Whether `raw` is within one LSB of `want` µT at 0.375 LSB/µT per cycle count, every axis.
pub fn within_one_lsb(raw: [i32; 3], want: [f32; 3], cycle_counts: [u16; 3]) -> bool {
    (0..3).all(|i| {
        let exact = f64::from(want[i]) * 0.375 * f64::from(cycle_counts[i]);
        (f64::from(raw[i]) - exact).abs() <= 1.0
    })
}

/// Asserts that `raw` is sample `k` of `fields` within one LSB at 200 cycle counts.
#[track_caller]
pub fn assert_sample(
    raw: [i32; 3],
    fields: &[[f32; 3]],
    k: usize,
    context: impl core::fmt::Display,
) {
    assert!(
        within_one_lsb(raw, fields[k], [200; 3]),
        "{context}: {raw:?} vs sample {k} {:?}",
        fields[k]
    );
}

/// The device side of a continuous-mode run: latches `fields[k]` 1 µs after the chip's k-th
/// measurement sequence starts, at `start + k · period` (the z axis of the sequence before
/// completes at the start), and moves the chip's clock.
pub struct Bench {
    pub start: u64,
    pub period: u64,
    pub fields: Vec<[f32; 3]>,
    latched: usize,
}

impl Bench {
    /// Enough [`samples`] for a run until `end`.
    pub fn new(start: u64, period: u64, end: u64) -> Self {
        let fields = samples(2 + ((end - start) / period) as usize);
        Self {
            start,
            period,
            fields,
            latched: 0,
        }
    }

    /// Latches the samples due by `now`, then advances the chip to `now`.
    pub fn run_to(&mut self, mag: &mut Rm3100, now: u64) {
        loop {
            let at = self.start + self.latched as u64 * self.period + US;
            if at > now {
                break;
            }
            mag.latch_at(&field(self.fields[self.latched]), at);
            self.latched += 1;
        }
        mag.advance(now);
    }
}

/// A field sequence (µT, chip axes) sweeping every axis through both signs, inside ±800 µT.
pub fn samples(n: usize) -> Vec<[f32; 3]> {
    (0..n)
        .map(|i| {
            let a = i as f32 * 0.37;
            [
                500.0 * a.sin(),
                -450.0 * a.cos(),
                300.0 * (0.5 * a).sin() + 0.1,
            ]
        })
        .collect()
}
