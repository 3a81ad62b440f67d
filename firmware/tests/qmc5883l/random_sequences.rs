//! Any sequence of bus operations and clock steps: the chip never panics, the identity
//! registers never change, SOFT_RST never reads back set, and the data stay inside full scale.

use proptest::prelude::*;

use super::*;

#[derive(Clone, Debug)]
enum Op {
    Start(u8, bool),
    Write(u8),
    Read,
    Stop,
    Advance(u32, [f32; 3]),
}

fn op() -> impl Strategy<Value = Op> {
    let address = prop_oneof![Just(ADDRESS), any::<u8>()];
    let byte = prop_oneof![0x00u8..=0x0D, 0x20u8..=0x21, any::<u8>()];
    let field = prop_oneof![-1000.0f32..1000.0, Just(f32::NAN), Just(f32::NEG_INFINITY)];
    prop_oneof![
        2 => (address, any::<bool>()).prop_map(|(a, r)| Op::Start(a, r)),
        4 => byte.prop_map(Op::Write),
        4 => Just(Op::Read),
        2 => Just(Op::Stop),
        2 => (0u32..250_000_000, [field.clone(), field.clone(), field])
            .prop_map(|(dt, f)| Op::Advance(dt, f)),
    ]
}

proptest! {
    #[test]
    fn invariants_hold(ops in proptest::collection::vec(op(), 0..200)) {
        let mut mag = Qmc5883l::new();
        let mut now = 0u64;
        for op in ops {
            match op {
                Op::Start(a, r) => { mag.start(a, r); }
                Op::Write(b) => { mag.write(b); }
                Op::Read => { mag.read(); }
                Op::Stop => mag.stop(),
                Op::Advance(dt, f) => {
                    now += u64::from(dt);
                    mag.advance(now, f);
                }
            }
            prop_assert_eq!([mag.peek(0x0C), mag.peek(0x0D)], [0x01, 0xFF]);
            prop_assert_eq!(mag.peek(0x0A) & 0x80, 0);
            prop_assert_eq!(mag.peek(0x06) & 0xF8, 0);
            let d: [u8; 6] = core::array::from_fn(|i| mag.peek(i as u8));
            for i in 0..3 {
                let raw = i16::from_le_bytes([d[2 * i], d[2 * i + 1]]);
                prop_assert!(raw.unsigned_abs() <= 24_000);
            }
        }
    }
}
