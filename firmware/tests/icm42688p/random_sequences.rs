//! Any sequence of bus operations and samples never panics, and the resets recover the chip:
//! DEVICE_CONFIG.SOFT_RESET_CONFIG restores every register of banks 0–4, a power cycle too, and
//! the recovered chip serves samples exactly like a fresh one.

use super::*;
use margemu_firmware::chip::icm42688p::Config;
use proptest::prelude::*;

type Op = random_ops::Op<32>;

/// Register bytes biased towards the registers and values with behaviour.
fn mosi() -> impl Strategy<Value = u8> {
    prop_oneof![
        any::<u8>(),
        prop::sample::select(vec![
            0x11, 0x14, 0x16, 0x2D, 0x2E, 0x30, 0x4B, 0x4C, 0x4E, 0x4F, 0x50, 0x54, 0x5F, 0x60,
            0x63, 0x64, 0x65, 0x68, 0x76, 0xAD, 0xAE, 0xB0, 0x9D, 0x0F, 0x03, 0x13, 0x40, 0x80,
            0x7F, 0x02, 0x01, 0x07, 0x05,
        ]),
    ]
}

fn float() -> impl Strategy<Value = f32> {
    prop_oneof![
        -400.0f32..400.0,
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(f32::NEG_INFINITY),
        any::<f32>(),
    ]
}

fn physical() -> impl Strategy<Value = PhysicalSample> {
    (
        prop::array::uniform3(float()),
        prop::array::uniform3(float()),
        float(),
    )
        .prop_map(|(acc, gyr, temp_c)| PhysicalSample {
            acc,
            gyr,
            mag: [0.0; 3],
            temp_c,
        })
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        2 => Just(Op::Select),
        6 => mosi().prop_map(Op::Exchange),
        2 => Just(Op::Deselect),
        4 => prop::collection::vec(mosi(), 1..40).prop_map(Op::Spi),
        2 => (prop_oneof![Just(0x68u8), Just(0x69), any::<u8>()], any::<bool>())
            .prop_map(|(a, r)| Op::Start(a, r)),
        4 => mosi().prop_map(Op::Write),
        3 => Just(Op::Read),
        2 => Just(Op::Stop),
        4 => (physical(), 0u32..2_000_000).prop_map(|(s, dt)| Op::Latch(s, dt)),
        1 => (any::<[u8; 32]>(), 0u32..2_000_000).prop_map(|(i, dt)| Op::LatchImage(i, dt)),
        1 => (0u32..200_000_000).prop_map(Op::Advance),
    ]
}

fn run(c: &mut Icm42688p, ops: &[Op]) -> u64 {
    random_ops::run(c, ops, |c, now| {
        let _ = (
            c.int_pin(),
            c.int2_pin_at(now),
            c.output_rate_hz(),
            c.int_pulse_end_ns(),
        );
    })
}

/// Every register of banks 0–4 as the bus would read it.
fn registers(c: &Icm42688p) -> Vec<u8> {
    (0..5)
        .flat_map(|b| (0..0x80).map(move |a| c.peek(b, a)))
        .collect()
}

/// The recovered chip must behave like a fresh one: same sample, same bytes.
fn serves_like_new(c: &mut Icm42688p, fresh: &mut Icm42688p, now: u64) {
    for chip in [&mut *c, &mut *fresh] {
        spi_write(chip, 0x4E, &[0x0F]);
        spi_write(chip, 0x5F, &[0x13]);
        spi_write(chip, 0x16, &[0x40]);
        chip.latch_at(&sample(3), now + MS);
    }
    assert_eq!(spi_read(c, 0x1D, 14), spi_read(fresh, 0x1D, 14));
    assert_eq!(spi_read(c, 0x2D, 23), spi_read(fresh, 0x2D, 23));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn random_sequences_never_panic_and_soft_reset_recovers(
        ad0 in any::<bool>(),
        ops in prop::collection::vec(op(), 0..200),
    ) {
        let config = Config { ad0, ..Config::default() };
        let mut c = Icm42688p::with_config(config);
        let now = run(&mut c, &ops);
        c.deselect();
        c.stop();
        spi_write(&mut c, 0x76, &[0x00]);
        spi_write(&mut c, 0x11, &[0x01]);
        let mut fresh = Icm42688p::with_config(config);
        prop_assert_eq!(registers(&c), registers(&fresh));
        serves_like_new(&mut c, &mut fresh, now);
    }

    #[test]
    fn power_cycle_recovers_everything(ops in prop::collection::vec(op(), 0..200)) {
        let mut c = Icm42688p::new();
        let now = run(&mut c, &ops);
        c.deselect();
        c.stop();
        c.power_cycle();
        let mut fresh = Icm42688p::new();
        prop_assert_eq!(registers(&c), registers(&fresh));
        serves_like_new(&mut c, &mut fresh, now);
    }
}
