//! The operations of the random-sequence property tests and the loop that applies them to a
//! chip, shared by the chips' test crates (included with `#[path]`, beside `transactions.rs`);
//! each crate keeps its own strategies, biased towards its chip's registers.

use margemu_firmware::chip::{Chip, PhysicalSample};

use super::transactions::spi;

/// One bus operation, sample or pause; `N` is the length of the model's register image.
#[derive(Clone, Debug)]
pub enum Op<const N: usize> {
    Select,
    Exchange(u8),
    Deselect,
    /// A whole SPI transaction of random bytes.
    Spi(Vec<u8>),
    Start(u8, bool),
    Write(u8),
    Read,
    Stop,
    Latch(PhysicalSample, u32),
    LatchImage([u8; N], u32),
    Advance(u32),
}

/// Applies `ops` to `c` in order (time moving on by each operation's delay), calling `probe`
/// with the chip and the time after each one; returns the time reached.
pub fn run<C: Chip, const N: usize>(c: &mut C, ops: &[Op<N>], probe: impl Fn(&C, u64)) -> u64 {
    let mut now = 0u64;
    for op in ops {
        match op {
            Op::Select => {
                c.select();
            }
            Op::Exchange(b) => {
                c.exchange(*b);
            }
            Op::Deselect => c.deselect(),
            Op::Spi(bytes) => {
                spi(c, bytes);
            }
            Op::Start(a, r) => {
                c.start(*a, *r);
            }
            Op::Write(b) => {
                c.write(*b);
            }
            Op::Read => {
                c.read();
            }
            Op::Stop => c.stop(),
            Op::Latch(s, dt) => {
                now += u64::from(*dt);
                c.latch_at(s, now);
            }
            Op::LatchImage(i, dt) => {
                now += u64::from(*dt);
                c.latch_image_at(i, now);
            }
            Op::Advance(dt) => {
                now += u64::from(*dt);
                c.advance(now);
            }
        }
        probe(c, now);
    }
    now
}
