//! Cost of the emulated MPU-9250's two hot paths:
//! (1) a physical sample → register image (`latch`: conversion, AK8963, aux master, FIFO,
//!     interrupt, swap) and a register image (`latch_image`);
//! (2) a 22-byte SPI burst (address byte 0x80 | 0x3B + 21 data bytes, ACCEL_XOUT_H through
//!     EXT_SENS_DATA_06, as the `mpu9250` crate reads a MARG sample) through the SPI target
//!     state machine: select, 22 exchanges, deselect.
//!
//! The requirement: well under one byte time of a 20 MHz SPI clock (400 ns) per byte.
//!
//! `cargo bench -p margemu-firmware -- --warm-up-time 1 --measurement-time 3`

// criterion_group! generates an undocumented public function.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use margemu_firmware::chip::{Mpu6xxx, PhysicalSample, SpiTarget};
use margemu_protocol::regmap::mpu6xxx::image::{ImageConfig, ImageRepr};
use std::hint::black_box;

const BURST: usize = 22;

fn sample() -> PhysicalSample {
    PhysicalSample {
        acc: [0.31, -0.72, 9.79],
        gyr: [0.012, -0.2, 1.3],
        mag: [21.5, -3.2, -41.0],
        temp_c: 27.3,
    }
}

/// A chip set up like the `mpu9250` crate's MARG mode over SPI: AK8963 at 100 Hz 16-bit,
/// slave 0 reading its 7 data bytes each sample, FIFO on with accel + temp + gyro, data ready
/// interrupt latched.
fn marg_chip() -> Mpu6xxx {
    let mut chip = Mpu6xxx::new();
    let write = |chip: &mut Mpu6xxx, bytes: &[u8]| {
        chip.select();
        for &b in bytes {
            chip.exchange(b);
        }
        chip.deselect();
    };
    write(&mut chip, &[0x1A, 0x01]); // DLPF on, 1 kHz
    write(&mut chip, &[0x6A, 0x70]); // FIFO_EN, I2C_MST_EN, I2C_IF_DIS
    write(&mut chip, &[0x31, 0x0C, 0x0A, 0x16, 0x80]); // slave 4: CNTL1 = 0x16
    write(&mut chip, &[0x25, 0x8C, 0x03, 0x87]); // slave 0: 7 bytes from HXL
    write(&mut chip, &[0x23, 0xF8]);
    write(&mut chip, &[0x37, 0x30]);
    write(&mut chip, &[0x38, 0x01]);
    chip
}

fn latch(c: &mut Criterion) {
    let mut group = c.benchmark_group("latch");
    let s = sample();
    let mut chip = marg_chip();
    let mut now = 0u64;
    group.bench_function("physical sample", |b| {
        b.iter(|| {
            now += 1_000_000;
            chip.latch_at(black_box(&s), now);
            // Keep the FIFO from saturating into its overflow path.
            chip.select();
            chip.exchange(0x6A);
            chip.exchange(0x74);
            chip.deselect();
        })
    });
    let image =
        ImageRepr::from_physical(s.acc, s.gyr, s.temp_c, s.mag, &ImageConfig::NOMINAL).emit();
    let mut chip = marg_chip();
    group.bench_function("register image", |b| {
        b.iter(|| {
            now += 1_000_000;
            chip.latch_image_at(black_box(&image), now);
            chip.select();
            chip.exchange(0x6A);
            chip.exchange(0x74);
            chip.deselect();
        })
    });
    group.bench_function("conversion only (regmap)", |b| {
        b.iter(|| {
            let s = black_box(&s);
            ImageRepr::from_physical(
                s.acc,
                s.gyr,
                s.temp_c,
                s.mag,
                black_box(&ImageConfig::NOMINAL),
            )
        })
    });
    group.finish();
}

fn burst(c: &mut Criterion) {
    let mut group = c.benchmark_group("spi burst");
    let mut chip = marg_chip();
    chip.latch_at(&sample(), 10_000_000);
    let mut mosi = [0u8; BURST];
    mosi[0] = 0x80 | 0x3B;
    group.throughput(Throughput::Bytes(BURST as u64));
    group.bench_function("0x3B + 21 bytes", |b| {
        b.iter(|| {
            let mut acc = chip.select();
            for &byte in black_box(&mosi) {
                acc ^= chip.exchange(byte);
            }
            chip.deselect();
            acc
        })
    });
    group.finish();
}

criterion_group!(benches, latch, burst);
criterion_main!(benches);
