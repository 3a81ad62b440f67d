//! Any sequence of I2C and SPI operations and clock steps: the chip never panics, REVID stays
//! 0x22, the reserved bits of POLL, CMM, STATUS and HSHAKE read as the DS has them, the BIST OK
//! bits show only with STE, and continuous mode runs only with CMM.START set.

use margemu_firmware::chip::{I2cTarget, SpiTarget};
use proptest::prelude::*;

use super::*;

#[derive(Clone, Debug)]
enum Op {
    Start(u8, bool),
    Write(u8),
    Read,
    Stop,
    Select,
    Exchange(u8),
    Deselect,
    Latch(u32, [f32; 3]),
    Advance(u32),
    Strict(bool),
}

fn op() -> impl Strategy<Value = Op> {
    let address = prop_oneof![Just(ADDRESS), 0x20u8..=0x23, any::<u8>()];
    let byte = prop_oneof![
        0x00u8..=0x0B,
        0x24u8..=0x2C,
        0x33u8..=0x36,
        Just(0x70u8),
        Just(0x71u8),
        Just(0x8F),
        any::<u8>(),
    ];
    let field = prop_oneof![
        -1000.0f32..1000.0,
        Just(f32::NAN),
        Just(f32::INFINITY),
        Just(-1e30)
    ];
    prop_oneof![
        2 => (address, any::<bool>()).prop_map(|(a, r)| Op::Start(a, r)),
        4 => byte.clone().prop_map(Op::Write),
        3 => Just(Op::Read),
        2 => Just(Op::Stop),
        1 => Just(Op::Select),
        4 => byte.prop_map(Op::Exchange),
        1 => Just(Op::Deselect),
        2 => (0u32..20_000_000, [field.clone(), field.clone(), field])
            .prop_map(|(dt, f)| Op::Latch(dt, f)),
        1 => any::<u32>().prop_map(Op::Advance),
        1 => any::<bool>().prop_map(Op::Strict),
    ]
}

proptest! {
    #[test]
    fn invariants_hold(ops in proptest::collection::vec(op(), 0..300)) {
        let mut mag = Rm3100::new();
        let mut now = 0u64;
        for op in ops {
            match op {
                Op::Start(a, r) => { mag.start(a, r); }
                Op::Write(b) => { mag.write(b); }
                Op::Read => { mag.read(); }
                Op::Stop => mag.stop(),
                Op::Select => { mag.select(); }
                Op::Exchange(b) => { mag.exchange(b); }
                Op::Deselect => mag.deselect(),
                Op::Latch(dt, f) => {
                    now += u64::from(dt);
                    mag.latch_at(&field(f), now);
                }
                Op::Advance(dt) => {
                    now += u64::from(dt) * 1_000;
                    mag.advance(now);
                }
                Op::Strict(on) => mag.set_strict_cmm(on),
            }
            prop_assert_eq!(mag.peek(0x36), 0x22);
            prop_assert_eq!(mag.peek(0x34) & 0x7F, 0);
            prop_assert_eq!(mag.peek(0x35) & 0x88, 0x08);
            prop_assert_eq!(mag.peek(0x01) & 0x82, 0);
            prop_assert_eq!(mag.peek(0x00) & 0x8F, 0);
            let bist = mag.peek(0x33);
            prop_assert!(bist & 0x80 != 0 || bist & 0x70 == 0);
            prop_assert!(!mag.is_continuous() || mag.peek(0x01) & 0x01 != 0);
        }
    }
}
