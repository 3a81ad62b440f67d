//! Cost of the emulated chips' hot paths.
//!
//! MPU-9250 in the `mpu9250` crate's MARG setup ([`Mpu6xxx`] directly):
//! (1) a physical sample → register image (`latch`: conversion, AK8963, aux master, FIFO,
//!     interrupt, swap) and a register image (`latch_image`);
//! (2) a 22-byte SPI burst (address byte 0x80 | 0x3B + 21 data bytes, ACCEL_XOUT_H through
//!     EXT_SENS_DATA_06, as the `mpu9250` crate reads a MARG sample) through the SPI target
//!     state machine: select, 22 exchanges, deselect.
//!
//! Every chip model the firmware emulates (`EmulatedChip::models()`; the protocol's MPU-6000
//! and ICM-20602 have their images and conversions but no emulated chip yet), through the chip
//! boundary (`EmulatedChip::new(model, model.who_am_i(), 0x68)` and the `Chip` trait), sensors
//! on, otherwise at power-on:
//! (3) `chip image/<model>`: a physical sample → the model's register image on the host side
//!     (`ChipSettings::image`, what source mode (a) streams; every `ChipModel`);
//! (4) `chip latch_image_at/<model>`: latching that image into the emulated chip;
//! (5) `chip latch_at/<model>`: latching the physical sample (the chip converts; source mode (b));
//! (6) `chip spi burst/<model>`: select + the model's data burst + deselect: MPU family
//!     0x80 | 0x3B + 14 bytes (accel, temp, gyro), ICM-42688-P 0x80 | 0x1D + 14 bytes (temp,
//!     accel, gyro), and for the ICM a 20-byte FIFO packet (0x80 | 0x30 + 20 bytes, the FIFO in
//!     stream mode with 20-bit packets: FIFO_CONFIG1 HIRES + TEMP + GYRO + ACCEL), refilled
//!     between timed reads.
//!
//! The RM3100 on its own ([`Rm3100`]), in continuous mode on x, y, z
//! at 200 cycle counts (ArduPilot's and PX4's setup):
//! (7) `rm3100/latch_at`: one physical sample per measurement sequence (3 axes converted, the
//!     results published);
//! (8) `rm3100/spi burst` and `rm3100/i2c burst`: the 9 result bytes from 0x24 (SPI: select,
//!     0x80 | 0x24 + 9 bytes, deselect; I2C: register pointer, repeated START, 9 reads, STOP).
//! The BMI088's two dies, not yet behind the chip boundary, directly:
//! (9) `bmi088 latch_at/{accel,gyro}`: a physical sample into each die's registers and FIFO
//!     (accel ±24 g, 1.6 kHz, FIFO on; gyro ±2000 °/s, 2 kHz, FIFO mode), the FIFOs emptied
//!     outside the timing;
//! (10) `bmi088 spi burst`: the accel data (0x80 | 0x12, dummy + 6 bytes), the gyro data
//!     (0x80 | 0x02 + 6 bytes), and one FIFO frame each (accel 0x80 | 0x26 + dummy + 7 bytes,
//!     gyro 0x80 | 0x3F + 6 bytes), refilled between timed reads.
//!
//! The requirement: well under one byte time of a 20 MHz SPI clock (400 ns) per byte.
//!
//! `cargo bench -p margemu-firmware --bench chip -- --warm-up-time 1 --measurement-time 3`

// criterion_group! generates an undocumented public function.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use margemu_firmware::chip::bmi088::{Bmi088Accel, Bmi088Gyro};
use margemu_firmware::chip::{
    Chip, EmulatedChip, I2cTarget, Mpu6xxx, PhysicalSample, Rm3100, SpiTarget,
};
use margemu_protocol::chip::{ChipModel, ChipSettings, Family};
use margemu_protocol::regmap::mpu6xxx::image::{ImageConfig, ImageRepr};
use std::hint::black_box;
use std::time::{Duration, Instant};

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

/// One SPI transaction: select, `bytes`, deselect.
fn spi_write(chip: &mut EmulatedChip, bytes: &[u8]) {
    chip.select();
    for &b in bytes {
        chip.exchange(b);
    }
    chip.deselect();
}

/// `model` at power-on with its sensors on (MPU family: PWR_MGMT_1 = 0x01, awake on the PLL;
/// ICM-42688-P: PWR_MGMT0 = 0x0F, gyro and accel low noise; BMI270: the dummy read, a
/// 328-byte configuration upload, PWR_CTRL = 0x0E; BMI088: the accelerometer's dummy read,
/// ACC_PWR_CONF = 0x00, ACC_PWR_CTRL = 0x04 (the gyro runs from power-on); QMC5883L: CONF1 = 0x0D, continuous at
/// 200 Hz; IST8310: single measurements, triggered by its reader; RM3100: continuous).
fn powered(model: ChipModel) -> EmulatedChip {
    let address = model.i2c_addresses()[0];
    let mut chip =
        EmulatedChip::new(model, model.who_am_i(), address).expect("the model's identity");
    match model.family() {
        Family::Mpu6xxx => spi_write(&mut chip, &[0x6B, 0x01]),
        Family::Icm42688p => spi_write(&mut chip, &[0x4E, 0x0F]),
        Family::Bmi270 => {
            spi_write(&mut chip, &[0x80, 0x00]);
            spi_write(&mut chip, &[0x59, 0x00]);
            let mut upload = [0xC8u8; 1 + 328];
            upload[0] = 0x5E;
            spi_write(&mut chip, &upload);
            spi_write(&mut chip, &[0x59, 0x01]);
            spi_write(&mut chip, &[0x7D, 0x0E]);
        }
        Family::Bmi088 => {
            spi_write(&mut chip, &[0x80, 0x00]);
            spi_write(&mut chip, &[0x7C, 0x00]);
            spi_write(&mut chip, &[0x7D, 0x04]);
        }
        Family::Qmc5883l => assert!(chip.write_register(0, 0x09, 0x0D)),
        Family::Ist8310 => {}
        // Continuous measurement of x, y, z at TMRC's reset rate.
        Family::Rm3100 => assert!(chip.write_register(0, 0x01, 0x71)),
    }
    chip
}

/// Times `iters` I2C reads of `n` bytes from register `start` (a pointer write, then a read).
fn timed_i2c_bursts(chip: &mut EmulatedChip, start: u8, n: usize, iters: u64) -> Duration {
    let address = chip.i2c_address();
    let t = Instant::now();
    for _ in 0..iters {
        chip.start(address, false);
        chip.write(black_box(start));
        chip.start(address, true);
        let mut acc = 0u8;
        for _ in 0..n {
            acc ^= chip.read();
        }
        chip.stop();
        black_box(acc);
    }
    t.elapsed()
}

/// Times `iters` reads of `mosi` (one transaction each).
fn timed_bursts(chip: &mut EmulatedChip, mosi: &[u8], iters: u64) -> Duration {
    let t = Instant::now();
    for _ in 0..iters {
        let mut acc = chip.select();
        for &byte in black_box(mosi) {
            acc ^= chip.exchange(byte);
        }
        chip.deselect();
        black_box(acc);
    }
    t.elapsed()
}

fn per_chip(c: &mut Criterion) {
    let s = sample();
    for model in ChipModel::ALL {
        if !EmulatedChip::models().any(|m| m == model) {
            eprintln!(
                "{}: not emulated by this firmware; only its image conversion is measured",
                model.name()
            );
        }
    }
    let mut group = c.benchmark_group("chip image");
    for model in ChipModel::ALL {
        let settings = ChipSettings::power_on(model);
        group.bench_function(BenchmarkId::from_parameter(model.name()), |b| {
            b.iter(|| black_box(&settings).image(black_box(&s)))
        });
    }
    group.finish();

    let mut group = c.benchmark_group("chip latch_image_at");
    for model in EmulatedChip::models() {
        let mut chip = powered(model);
        let image = chip.settings().image(&s);
        let period = chip.sample_period_ns();
        let mut now = 0u64;
        group.bench_function(BenchmarkId::from_parameter(model.name()), |b| {
            b.iter(|| {
                now += period;
                Chip::latch_image_at(&mut chip, black_box(&image), now);
            })
        });
    }
    group.finish();

    let mut group = c.benchmark_group("chip latch_at");
    for model in EmulatedChip::models() {
        let mut chip = powered(model);
        let period = chip.sample_period_ns();
        let mut now = 0u64;
        group.bench_function(BenchmarkId::from_parameter(model.name()), |b| {
            b.iter(|| {
                now += period;
                Chip::latch_at(&mut chip, black_box(&s), now);
            })
        });
    }
    group.finish();

    let mut group = c.benchmark_group("chip i2c burst");
    for model in EmulatedChip::models().filter(|m| m.is_magnetometer_only()) {
        let mut chip = powered(model);
        let period = chip.sample_period_ns();
        Chip::latch_at(&mut chip, &s, period);
        let start = chip.burst_start();
        // IST8310: STAT1 and the data; QMC5883L: the data and STATUS; RM3100: the 9 results.
        let n = if model == ChipModel::Rm3100 { 9 } else { 7 };
        group.throughput(Throughput::Bytes(n as u64));
        group.bench_function(
            BenchmarkId::new(format!("0x{start:02X} + {n} bytes"), model.name()),
            |b| b.iter_custom(|iters| timed_i2c_bursts(&mut chip, start, n, iters)),
        );
    }
    group.finish();

    let mut group = c.benchmark_group("chip spi burst");
    for model in EmulatedChip::models().filter(|m| !m.is_magnetometer_only()) {
        let mut chip = powered(model);
        let period = chip.sample_period_ns();
        Chip::latch_at(&mut chip, &s, period);
        let start = chip.burst_start();
        let mut mosi = [0u8; 15];
        mosi[0] = 0x80 | start;
        group.throughput(Throughput::Bytes(mosi.len() as u64));
        group.bench_function(
            BenchmarkId::new(format!("0x{start:02X} + 14 bytes"), model.name()),
            |b| b.iter_custom(|iters| timed_bursts(&mut chip, &mosi, iters)),
        );
    }

    // The ICM-42688-P's FIFO: stream mode, 20-byte packets (header, accel, gyro, temp 16-bit,
    // timestamp, 20-bit extension). Each timed chunk reads packets latched before it.
    let model = ChipModel::Icm42688p;
    let mut chip = powered(model);
    spi_write(&mut chip, &[0x16, 0x40]); // FIFO_CONFIG: stream to FIFO
    spi_write(&mut chip, &[0x5F, 0x17]); // FIFO_CONFIG1: HIRES, TEMP, GYRO, ACCEL
    let period = chip.sample_period_ns();
    let mut now = 0u64;
    // Fewer packets than the 2 KB FIFO holds (102 of 20 bytes): none dropped.
    const CHUNK: u64 = 64;
    let mut mosi = [0u8; 21];
    mosi[0] = 0x80 | 0x30; // FIFO_DATA
    {
        // Check once that reads return whole 20-bit packets (header 0x78), back to back. Under
        // the one-byte-ahead contract of `SpiTarget`, `exchange(mosi[i])` returns the MISO byte
        // clocked during byte i + 1: the address exchange returns the first data byte.
        for _ in 0..2 {
            now += period;
            Chip::latch_at(&mut chip, &s, now);
        }
        for _ in 0..2 {
            chip.select();
            let miso: Vec<u8> = mosi.iter().map(|&b| chip.exchange(b)).collect();
            chip.deselect();
            assert_eq!(miso[0] & 0xFC, 0x78, "FIFO packet {miso:02x?}");
        }
    }
    group.throughput(Throughput::Bytes(mosi.len() as u64));
    group.bench_function(
        BenchmarkId::new("FIFO 0x30 + 20-byte packet", model.name()),
        |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                let mut left = iters;
                while left > 0 {
                    let n = left.min(CHUNK);
                    for _ in 0..n {
                        now += period;
                        Chip::latch_at(&mut chip, &s, now);
                    }
                    total += timed_bursts(&mut chip, &mosi, n);
                    left -= n;
                }
                total
            })
        },
    );
    group.finish();
}

/// An RM3100 measuring x, y, z continuously at 200 cycle counts (CMM = 0x71, TMRC = 0x94): one
/// sequence every 6.85 ms.
fn rm3100_continuous() -> (Rm3100, u64) {
    let mut mag = Rm3100::new();
    for (reg, value) in [(0x0B, 0x94), (0x01, 0x71)] {
        mag.start(0x20, false);
        mag.write(reg);
        mag.write(value);
        mag.stop();
    }
    let period = margemu_protocol::regmap::rm3100::continuous_period_ns(0x94, 0b111, [200; 3]);
    (mag, period)
}

fn rm3100(c: &mut Criterion) {
    let s = sample();
    let mut group = c.benchmark_group("rm3100");
    let (mut mag, period) = rm3100_continuous();
    let mut now = 0u64;
    group.bench_function("latch_at", |b| {
        b.iter(|| {
            now += period;
            mag.latch_at(black_box(&s), now);
        })
    });

    let (mut mag, period) = rm3100_continuous();
    mag.latch_at(&s, 0);
    mag.advance(period);
    let mut mosi = [0u8; 10];
    mosi[0] = 0x80 | 0x24;
    group.throughput(Throughput::Bytes(mosi.len() as u64));
    group.bench_function("spi burst 0xA4 + 9 bytes", |b| {
        b.iter(|| {
            let mut acc = mag.select();
            for &byte in black_box(&mosi) {
                acc ^= mag.exchange(byte);
            }
            mag.deselect();
            acc
        })
    });
    group.bench_function("i2c burst 0x24 + 9 bytes", |b| {
        b.iter(|| {
            mag.start(0x20, false);
            mag.write(black_box(0x24));
            mag.start(0x20, true);
            let mut acc = 0u8;
            for _ in 0..9 {
                acc ^= mag.read();
            }
            mag.stop();
            acc
        })
    });
    group.finish();
}

/// Both BMI088 dies configured as PX4 runs them (accel ±24 g at 1.6 kHz with FIFO frames, gyro
/// ±2000 °/s at 2 kHz in FIFO mode).
fn bmi088_dies() -> (Bmi088Accel, Bmi088Gyro) {
    let write = |chip: &mut dyn SpiTarget, bytes: &[u8]| {
        chip.select();
        for &b in bytes {
            chip.exchange(b);
        }
        chip.deselect();
    };
    let mut accel = Bmi088Accel::new();
    write(&mut accel, &[0x80, 0x00]); // dummy read: SPI mode
    for bytes in [
        [0x7C, 0x00],
        [0x7D, 0x04],
        [0x40, 0xAC],
        [0x41, 0x03],
        [0x49, 0x50],
    ] {
        write(&mut accel, &bytes);
    }
    let mut gyro = Bmi088Gyro::new();
    write(&mut gyro, &[0x3E, 0x40]);
    (accel, gyro)
}

fn bmi088(c: &mut Criterion) {
    let s = sample();
    let (mut accel, mut gyro) = bmi088_dies();
    let mut group = c.benchmark_group("bmi088 latch_at");
    let mut now = 0u64;
    group.bench_function("accel", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                now += 625_000;
                let t = Instant::now();
                accel.latch_at(black_box(&s), now);
                total += t.elapsed();
                accel.select();
                accel.exchange(0x7E);
                accel.exchange(0xB0); // FIFO reset, untimed
                accel.deselect();
            }
            total
        })
    });
    group.bench_function("gyro", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                now += 500_000;
                let t = Instant::now();
                gyro.latch_at(black_box(&s), now);
                total += t.elapsed();
                gyro.select();
                gyro.exchange(0x3E);
                gyro.exchange(0x40); // FIFO cleared, untimed
                gyro.deselect();
            }
            total
        })
    });
    group.finish();

    let mut group = c.benchmark_group("bmi088 spi burst");
    let (mut accel, mut gyro) = bmi088_dies();
    accel.latch_at(&s, 625_000);
    gyro.latch_at(&s, 500_000);
    let time_reads = |chip: &mut dyn SpiTarget, mosi: &[u8], iters: u64| {
        let t = Instant::now();
        for _ in 0..iters {
            let mut acc = chip.select();
            for &byte in black_box(mosi) {
                acc ^= chip.exchange(byte);
            }
            chip.deselect();
            black_box(acc);
        }
        t.elapsed()
    };
    let mut mosi = [0u8; 8];
    mosi[0] = 0x80 | 0x12;
    group.throughput(Throughput::Bytes(8));
    group.bench_function("accel 0x12 + dummy + 6 bytes", |b| {
        b.iter_custom(|iters| time_reads(&mut accel, &mosi, iters))
    });
    let mut mosi = [0u8; 7];
    mosi[0] = 0x80 | 0x02;
    group.throughput(Throughput::Bytes(7));
    group.bench_function("gyro 0x02 + 6 bytes", |b| {
        b.iter_custom(|iters| time_reads(&mut gyro, &mosi, iters))
    });
    // One FIFO frame per timed read, latched before each chunk (fewer than either FIFO holds).
    const CHUNK: u64 = 64;
    let (mut accel, mut gyro) = bmi088_dies();
    let mut mosi = [0u8; 9];
    mosi[0] = 0x80 | 0x26;
    group.throughput(Throughput::Bytes(9));
    group.bench_function("accel FIFO 0x26 + dummy + 7-byte frame", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut left = iters;
            while left > 0 {
                let n = left.min(CHUNK);
                for _ in 0..n {
                    let t = accel.now_ns() + 625_000;
                    accel.latch_at(&s, t);
                }
                total += time_reads(&mut accel, &mosi, n);
                left -= n;
            }
            total
        })
    });
    let mut mosi = [0u8; 7];
    mosi[0] = 0x80 | 0x3F;
    group.throughput(Throughput::Bytes(7));
    group.bench_function("gyro FIFO 0x3F + 6-byte frame", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut left = iters;
            while left > 0 {
                let n = left.min(CHUNK);
                for _ in 0..n {
                    let t = gyro.now_ns() + 500_000;
                    gyro.latch_at(&s, t);
                }
                total += time_reads(&mut gyro, &mosi, n);
                left -= n;
            }
            total
        })
    });
    group.finish();
}

criterion_group!(benches, latch, burst, per_chip, rm3100, bmi088);
criterion_main!(benches);
