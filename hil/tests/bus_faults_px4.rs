//! A PX4-style FIFO reader of the ICM-42688-P on the host's virtual SPI bus with a `corrupt`
//! window: it rejects exactly the packets the window damaged, as counted from the fault's own
//! stream, and accepts every packet outside the window, byte for byte.
//!
//! The reader follows PX4's `src/drivers/imu/invensense/icm42688p/ICM42688P.cpp` (read for its
//! checks, no code taken): the bank-0 configuration of 20-byte high-resolution packets at
//! 8 kHz, big-endian, the count in bytes; then one transfer from INT_STATUS (0x2D) returning
//! INT_STATUS, FIFO_COUNTH, FIFO_COUNTL and the packets. A set FIFO_FULL_INT or a count of
//! 2048 bytes or more is implausible: the whole transfer is dropped (PX4 flushes the FIFO).
//! Otherwise `count / 20` packets (at most those read) are checked in order: a header with
//! HEADER_MSG set, ACCEL, GYRO or 20-bit clear, TIMESTAMP_FSYNC other than `10`, or an ODR-change
//! bit set ends the transfer there (PX4's `break`: the packets before it are used, it and the
//! rest are not). PX4 has no check on the data bytes: a flipped data bit passes, and the test
//! counts those too.
//!
//! A twin chip, driven identically through a fault-free bus, gives the clean bytes.

use embedded_hal::spi::{Operation, SpiDevice as _};
use margemu_firmware::bus_fault::BusFaults;
use margemu_firmware::chip::{Chip, Icm42688p, PhysicalSample};
use margemu_firmware::fault::FaultSchedule;
use margemu_hil::bus::{self, Shared, SpiDevice};
use margemu_model::fault::{Fault, FaultKind, Window};
use margemu_model::rng::{unit_f64, StreamRng};

const US: u64 = 1_000;
const MS: u64 = 1_000_000;
const PACKET: usize = 20;
/// Packets per transfer: one transfer per 1 ms at 8 kHz.
const SAMPLES: usize = 8;
/// INT_STATUS, FIFO_COUNTH, FIFO_COUNTL, then the packets.
const TRANSFER: usize = 3 + SAMPLES * PACKET;
const PROBABILITY: f32 = 0.02;
const TRANSFERS: u64 = 150;
/// Transfers 20..120 fall in the window.
const FIRST_IN: u64 = 20;
const FIRST_AFTER: u64 = 120;

/// Bank-0 registers as PX4 configures them: (register, bits set, bits cleared).
const CONFIG: [(u8, u8, u8); 10] = [
    (0x16, 0xC0, 0x00),                     // FIFO_CONFIG: stop on full
    (0x4C, 0x30, 0x40), // INTF_CONFIG0: big-endian data and count, count in bytes
    (0x4D, 0x40, 0x80), // INTF_CONFIG1: AFSR off
    (0x4E, 0x0F, 0x00), // PWR_MGMT0: gyro and accel low noise
    (0x4F, 0x03, 0xEC), // GYRO_CONFIG0: ±2000 °/s, 8 kHz
    (0x50, 0x03, 0xEC), // ACCEL_CONFIG0: ±16 g, 8 kHz
    (0x54, 0x05, 0x08), // TMST_CONFIG: timestamp deltas, 1 µs
    (0x5F, 0x7F, 0x00), // FIFO_CONFIG1: hires, tmst, temp, gyro, accel, partial reads
    (0x60, (SAMPLES * PACKET) as u8, 0x00), // FIFO_CONFIG2: watermark
    (0x61, 0x00, 0x0F), // FIFO_CONFIG3
];

fn write(spi: &mut SpiDevice<Icm42688p>, reg: u8, value: u8) {
    spi.write(&[reg, value]).unwrap();
}

fn read(spi: &mut SpiDevice<Icm42688p>, reg: u8) -> u8 {
    let mut buf = [reg | 0x80, 0];
    spi.transfer_in_place(&mut buf).unwrap();
    buf[1]
}

/// PX4's reset and configuration, then a FIFO flush.
fn configure(spi: &mut SpiDevice<Icm42688p>) {
    write(spi, 0x11, 0x01); // DEVICE_CONFIG: soft reset
    assert_eq!(read(spi, 0x75), 0x47);
    for (reg, set, clear) in CONFIG {
        let value = read(spi, reg);
        write(spi, reg, (value & !clear) | set);
    }
    let flush = read(spi, 0x4B) | 0x02; // SIGNAL_PATH_RESET: FIFO flush
    write(spi, 0x4B, flush);
}

/// One transfer from INT_STATUS.
fn fifo_transfer(spi: &mut SpiDevice<Icm42688p>) -> [u8; TRANSFER] {
    let mut buf = [0u8; TRANSFER];
    spi.transaction(&mut [Operation::Write(&[0x2D | 0x80]), Operation::Read(&mut buf)])
        .unwrap();
    buf
}

/// What the reader made of one transfer.
#[derive(Debug, PartialEq)]
enum Outcome {
    /// FIFO_FULL_INT or an implausible count: all dropped.
    Dropped,
    /// The first `accepted` of the packets; a bad header ended the transfer if fewer than
    /// `counted`.
    Packets { accepted: usize, counted: usize },
}

/// The PX4-style checks (module docs).
fn px4_read(buf: &[u8; TRANSFER]) -> Outcome {
    let count = usize::from(u16::from_be_bytes([buf[1], buf[2]]));
    if buf[0] & 0x02 != 0 || count >= 2048 {
        return Outcome::Dropped;
    }
    let counted = (count / PACKET).min(SAMPLES);
    let valid = |h: u8| {
        h & 0x80 == 0 // HEADER_MSG: an empty FIFO
            && h & 0x70 == 0x70 // ACCEL, GYRO, 20-bit
            && h & 0x0C == 0x08 // TIMESTAMP_FSYNC = 10
            && h & 0x03 == 0 // no ODR change
    };
    let accepted = buf[3..]
        .chunks_exact(PACKET)
        .take(counted)
        .take_while(|p| valid(p[0]))
        .count();
    Outcome::Packets { accepted, counted }
}

/// The bit flips the fault's stream gives the `prepared` MISO bytes of one selection, by the
/// rule of `margemu_firmware::bus_fault` (one draw per byte; on a hit, one for the bit).
fn flips(rng: &mut StreamRng, prepared: usize) -> Vec<u8> {
    (0..prepared)
        .map(|_| {
            if unit_f64(rng) < f64::from(PROBABILITY) {
                1 << (unit_f64(rng) * 8.0) as u32
            } else {
                0
            }
        })
        .collect()
}

fn sample(k: u64) -> PhysicalSample {
    let x = k as f32;
    PhysicalSample {
        acc: [0.01 * x % 3.0, -1.0, 9.8],
        gyr: [0.2, (0.003 * x) % 1.0, -0.4],
        mag: [0.0; 3],
        temp_c: 25.0,
    }
}

fn latch(chips: [&Shared<Icm42688p>; 2], k: u64, t_ns: u64) {
    for chip in chips {
        Chip::latch_at(&mut *chip.borrow_mut(), &sample(k), t_ns);
    }
}

#[test]
fn px4_rejects_exactly_the_packets_a_corrupt_window_damaged() {
    let t0 = 40 * MS;
    // Transfer j reads at t0 + (j + 1) ms.
    let window = Window::new(t0 + (FIRST_IN + 1) * MS, t0 + (FIRST_AFTER + 1) * MS);
    let mut schedule = FaultSchedule::new();
    let kind = FaultKind::Corrupt {
        probability: PROBABILITY,
    };
    schedule.push(Fault::new(0, window, kind), 7).unwrap();
    let mut rng = schedule.iter().next().unwrap().rng();

    let (chip, twin) = (bus::shared(Icm42688p::new()), bus::shared(Icm42688p::new()));
    let faults = BusFaults::for_device(&schedule, 0);
    let mut spi = SpiDevice::new(chip.clone()).with_faults(faults);
    let mut clean = SpiDevice::new(twin.clone());
    configure(&mut spi);
    configure(&mut clean);

    let (mut damaged_headers, mut dropped, mut undetected, mut rejected) = (0, 0, 0, 0);
    for j in 0..TRANSFERS {
        // Eight samples at 8 kHz, then the read at the last one's instant.
        for i in 0..SAMPLES as u64 {
            let k = j * SAMPLES as u64 + i;
            latch([&chip, &twin], k, t0 + j * MS + (i + 1) * 125 * US);
        }
        let (got, want) = (fifo_transfer(&mut spi), fifo_transfer(&mut clean));
        assert_eq!(
            px4_read(&want),
            Outcome::Packets {
                accepted: SAMPLES,
                counted: SAMPLES
            },
            "clean transfer {j}"
        );
        if !(FIRST_IN..FIRST_AFTER).contains(&j) {
            assert_eq!(got, want, "transfer {j}, outside the window: exact");
            continue;
        }
        // Prepared: under the command byte, the 163 bytes read, and the one after the last.
        let f = flips(&mut rng, 1 + TRANSFER + 1);
        let f = &f[1..=TRANSFER];
        let expected_bytes: Vec<u8> = want.iter().zip(f).map(|(w, f)| w ^ f).collect();
        assert_eq!(
            got[..],
            expected_bytes[..],
            "transfer {j}: the stream's flips"
        );

        let status = want[0] ^ f[0];
        let count = usize::from(u16::from_be_bytes([want[1] ^ f[1], want[2] ^ f[2]]));
        let outcome = px4_read(&got);
        if status & 0x02 != 0 || count >= 2048 {
            assert_eq!(outcome, Outcome::Dropped, "transfer {j}");
            dropped += 1;
            continue;
        }
        let counted = (count / PACKET).min(SAMPLES);
        let header = |i: usize| f[3 + i * PACKET];
        let first_damaged = (0..counted).find(|&i| header(i) != 0);
        let accepted = first_damaged.unwrap_or(counted);
        assert_eq!(
            outcome,
            Outcome::Packets { accepted, counted },
            "transfer {j}"
        );
        damaged_headers += usize::from(first_damaged.is_some());
        rejected += counted - accepted;
        // Accepted packets: the header exact; a flipped data bit passes unseen, as in PX4.
        for i in 0..accepted {
            let packet = &f[3 + i * PACKET..3 + (i + 1) * PACKET];
            undetected += usize::from(packet.iter().any(|&b| b != 0));
        }
    }
    // The window did damage headers and counts (the test is not vacuous).
    assert!(
        damaged_headers > 3 && rejected > 3,
        "{damaged_headers} {rejected}"
    );
    println!(
        "in {} transfers: {damaged_headers} with a damaged header ({rejected} packets \
         rejected), {dropped} dropped for their count or status, {undetected} packets with \
         flipped data accepted",
        FIRST_AFTER - FIRST_IN
    );
}
