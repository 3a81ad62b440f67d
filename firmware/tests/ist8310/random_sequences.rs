//! Any sequence of bus operations and clock steps: the chip never panics, WAI stays 0x10, SRST
//! never reads back set, CNTL1 holds only a mode, and the data stay inside the range.

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
    let byte = prop_oneof![0x00u8..=0x0D, 0x40u8..=0x42, any::<u8>()];
    let field = prop_oneof![-3000.0f32..3000.0, Just(f32::NAN), Just(f32::INFINITY)];
    prop_oneof![
        2 => (address, any::<bool>()).prop_map(|(a, r)| Op::Start(a, r)),
        4 => byte.prop_map(Op::Write),
        4 => Just(Op::Read),
        2 => Just(Op::Stop),
        2 => (0u32..20_000_000, [field.clone(), field.clone(), field])
            .prop_map(|(dt, f)| Op::Advance(dt, f)),
    ]
}

proptest! {
    #[test]
    fn invariants_hold(ops in proptest::collection::vec(op(), 0..200)) {
        let mut mag = Ist8310::new();
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
            prop_assert_eq!(mag.peek(0x00), 0x10);
            prop_assert_eq!(mag.peek(0x0B) & 0x01, 0);
            prop_assert!(mag.peek(0x0A) <= 0x0F);
            let d: [u8; 6] = core::array::from_fn(|i| mag.peek(0x03 + i as u8));
            for (i, max) in [5333u16, 5333, 8333].into_iter().enumerate() {
                let raw = i16::from_le_bytes([d[2 * i], d[2 * i + 1]]);
                prop_assert!(raw.unsigned_abs() <= max);
            }
        }
    }
}
