//! Cost of the bus-fault application ([`margemu_firmware::bus_fault`]) on the chip's hot path:
//! a 22-byte SPI burst of the MPU-9250 (0x80 | 0x3B + 21 bytes: select, 22 exchanges,
//! deselect), as in `benches/chip.rs`,
//! (1) `bus_fault/plain`: on the chip itself;
//! (2) `bus_fault/no window`: through the device's [`BusFaults`] holding all three bus kinds,
//!     none of whose windows holds the instant (the cost of a schedule outside its windows);
//! (3) `bus_fault/corrupt`: inside a `corrupt { probability: 0.02 }` window (one draw per
//!     byte, two on a hit);
//! (4) `bus_fault/nak`: inside a `nak` window (the chip sees nothing).
//!
//! `cargo bench -p margemu-firmware --bench bus_fault -- --warm-up-time 1 --measurement-time 3`

// criterion_group! generates an undocumented public function.
#![allow(missing_docs)]

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use margemu_firmware::bus_fault::BusFaults;
use margemu_firmware::chip::{Chip, EmulatedChip, SpiTarget};
use margemu_firmware::fault::FaultSchedule;
use margemu_model::fault::{Fault, FaultKind, Window};
use std::hint::black_box;

const BURST: usize = 22;
/// The instant of the bursts.
const NOW_NS: u64 = 1_000_000;

fn burst(target: &mut impl SpiTarget) -> u8 {
    let mut acc = target.select();
    acc ^= target.exchange(0x80 | 0x3B);
    for _ in 1..BURST {
        acc ^= target.exchange(0x00);
    }
    target.deselect();
    acc
}

/// Device 0's bus faults: every bus kind, with windows around (not holding) `NOW_NS` unless
/// `active` names the one whose window holds it.
fn faults(active: Option<FaultKind>) -> BusFaults {
    let mut s = FaultSchedule::new();
    let kinds = [
        FaultKind::Nak,
        FaultKind::Corrupt { probability: 0.02 },
        FaultKind::ClockStretch { stretch_ns: 1_000 },
    ];
    for (i, kind) in (0u64..).zip(kinds) {
        let window = if Some(kind) == active {
            Window::new(0, 2 * NOW_NS)
        } else {
            Window::new(2 * NOW_NS + i * 10, 2 * NOW_NS + i * 10 + 5)
        };
        s.push(Fault::new(0, window, kind), 7).unwrap();
    }
    BusFaults::for_device(&s, 0)
}

fn bench(c: &mut Criterion) {
    let mut chip = EmulatedChip::default();
    chip.advance(NOW_NS);
    let mut group = c.benchmark_group("bus_fault");
    group.throughput(Throughput::Elements(BURST as u64));
    group.bench_function("plain", |b| b.iter(|| black_box(burst(&mut chip))));
    let cases = [
        ("no window", None),
        ("corrupt", Some(FaultKind::Corrupt { probability: 0.02 })),
        ("nak", Some(FaultKind::Nak)),
    ];
    for (name, active) in cases {
        let mut f = faults(active);
        group.bench_function(name, |b| {
            b.iter(|| black_box(burst(&mut f.on(&mut chip, NOW_NS))))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
