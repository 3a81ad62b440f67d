//! Any sequence of bus operations and samples never panics, and the resets recover the chip:
//! H_RESET restores every MPU-9250 register, CNTL2.SRST every AK8963 register, a power cycle
//! both, and the recovered chip serves samples exactly like a fresh one.

use super::*;
use margemu_firmware::chip::Variant;
use proptest::prelude::*;

type Op = random_ops::Op<22>;

/// Addresses around the interesting ones, so random I2C traffic actually reaches the chips.
fn i2c_address() -> impl Strategy<Value = u8> {
    prop_oneof![Just(0x68u8), Just(0x69), Just(0x0C), any::<u8>()]
}

/// Register bytes biased towards the registers with behaviour.
fn mosi() -> impl Strategy<Value = u8> {
    prop_oneof![
        any::<u8>(),
        prop::sample::select(vec![
            0x1A, 0x1B, 0x23, 0x25, 0x27, 0x34, 0x37, 0x38, 0x3A, 0x6A, 0x6B, 0x72, 0x74, 0xBA,
            0xF4, 0xB6, 0xCA, 0xBB, 0x0A, 0x02, 0x03, 0x09, 0x16, 0x8C, 0x87, 0x80, 0x20, 0x40,
            0x60,
        ]),
    ]
}

fn float() -> impl Strategy<Value = f32> {
    prop_oneof![
        -200.0f32..200.0,
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(f32::NEG_INFINITY),
        Just(1e30f32),
        any::<f32>(),
    ]
}

fn sample() -> impl Strategy<Value = PhysicalSample> {
    (
        prop::array::uniform3(float()),
        prop::array::uniform3(float()),
        prop::array::uniform3(float()),
        float(),
    )
        .prop_map(|(acc, gyr, mag, temp_c)| PhysicalSample {
            acc,
            gyr,
            mag,
            temp_c,
        })
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        2 => Just(Op::Select),
        6 => mosi().prop_map(Op::Exchange),
        2 => Just(Op::Deselect),
        4 => prop::collection::vec(mosi(), 1..24).prop_map(Op::Spi),
        2 => (i2c_address(), any::<bool>()).prop_map(|(a, r)| Op::Start(a, r)),
        4 => mosi().prop_map(Op::Write),
        3 => Just(Op::Read),
        2 => Just(Op::Stop),
        3 => (sample(), 0u32..20_000_000).prop_map(|(s, dt)| Op::Latch(s, dt)),
        1 => (any::<[u8; 22]>(), 0u32..20_000_000).prop_map(|(i, dt)| Op::LatchImage(i, dt)),
        1 => (0u32..200_000_000).prop_map(Op::Advance),
    ]
}

fn variant() -> impl Strategy<Value = Variant> {
    prop::sample::select(vec![
        Variant::Mpu9250,
        Variant::Mpu9255,
        Variant::Mpu6500,
        Variant::WhoAmI68,
    ])
}

fn run(c: &mut Mpu6xxx, ops: &[Op]) -> u64 {
    random_ops::run(c, ops, |c, _| {
        let _ = (
            c.int_pin(),
            c.peek(0x3A),
            c.output_rate_hz(),
            c.int_pulse_end_ns(),
        );
    })
}

fn ak_registers(c: &Mpu6xxx) -> Vec<u8> {
    c.ak8963()
        .map(|ak| (0..0x20).map(|a| ak.peek(a)).collect())
        .unwrap_or_default()
}

/// After the sequence: end any transaction, then H_RESET over SPI and SRST in bypass mode.
fn recover(c: &mut Mpu6xxx) {
    c.deselect();
    c.stop();
    spi_write(c, 0x6B, &[0x80]);
    spi_write(c, 0x37, &[0x02]);
    i2c_write(c, 0x0C, &[0x0B, 0x01]);
    spi_write(c, 0x6B, &[0x80]);
}

/// The recovered chip must behave like a fresh one: same sample, same bytes.
fn serves_like_new(c: &mut Mpu6xxx, fresh: &mut Mpu6xxx, now: u64) {
    for chip in [&mut *c, &mut *fresh] {
        spi_write(chip, 0x1C, &[0x08]);
        spi_write(chip, 0x6A, &[0x40]);
        spi_write(chip, 0x23, &[0xF8]);
        chip.latch_at(&at_rest(), now + 1_000_000);
    }
    assert_eq!(spi_read(c, 0x3A, 15), spi_read(fresh, 0x3A, 15));
    assert_eq!(spi_read(c, 0x72, 16), spi_read(fresh, 0x72, 16));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn random_sequences_never_panic_and_resets_recover(
        variant in variant(),
        ad0 in any::<bool>(),
        ops in prop::collection::vec(op(), 0..200),
    ) {
        let config = Config { variant, ad0, ..Config::default() };
        let mut c = Mpu6xxx::with_config(config);
        let now = run(&mut c, &ops);
        recover(&mut c);
        let mut fresh = Mpu6xxx::with_config(config);
        prop_assert_eq!(registers(&c), registers(&fresh));
        prop_assert_eq!(ak_registers(&c), ak_registers(&fresh));
        serves_like_new(&mut c, &mut fresh, now);
    }

    #[test]
    fn power_cycle_recovers_everything(ops in prop::collection::vec(op(), 0..200)) {
        let mut c = Mpu6xxx::new();
        let now = run(&mut c, &ops);
        c.deselect();
        c.stop();
        c.power_cycle();
        let mut fresh = Mpu6xxx::new();
        prop_assert_eq!(registers(&c), registers(&fresh));
        prop_assert_eq!(ak_registers(&c), ak_registers(&fresh));
        serves_like_new(&mut c, &mut fresh, now);
    }
}
