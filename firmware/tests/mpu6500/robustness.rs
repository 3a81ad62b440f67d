//! Every part survives arbitrary bus traffic and latches (no panic), and its FIFO never holds
//! more than its size: a seeded xorshift drives SPI bytes, I2C transactions, sample and image
//! latches and clock steps.

use super::*;
use margemu_firmware::chip::{I2cTarget, SpiTarget};
use margemu_protocol::regmap::mpu6xxx::variant::Variant as V;

struct XorShift(u64);

impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    fn byte(&mut self) -> u8 {
        self.next() as u8
    }
}

#[test]
fn random_traffic_on_every_part() {
    for (seed, variant) in (1u64..).zip(V::ALL) {
        let mut rng = XorShift(0x9E37_79B9_7F4A_7C15 ^ seed);
        let mut c: Mpu6xxx = chip(variant);
        let mut now = 0u64;
        for _ in 0..20_000 {
            match rng.next() % 8 {
                0 => {
                    c.select();
                }
                1 | 2 => {
                    c.exchange(rng.byte());
                }
                3 => c.deselect(),
                4 => {
                    let address = 0x68 | (rng.byte() & 1);
                    if c.start(address, rng.byte() & 1 == 1) {
                        c.write(rng.byte());
                        c.read();
                    }
                    c.stop();
                }
                5 => {
                    now += rng.next() % 300_000;
                    let s = numbered(rng.next() % 16_000);
                    c.latch_at(&s, now);
                }
                6 => {
                    now += rng.next() % 300_000;
                    let image = [rng.byte(); 22];
                    c.latch_image_at(&image, now);
                }
                _ => {
                    now += rng.next() % 100_000;
                    c.advance(now);
                }
            }
            assert!(c.accel_period_ns() >= 250_000);
            assert!(c.sample_period_ns() >= 31_250);
        }
        c.deselect();
        c.stop();
        let count = spi_read(&mut c, 0x72, 2);
        let count = usize::from(u16::from_be_bytes([count[0], count[1]]));
        assert!(count <= variant.fifo_size(), "{variant:?}: {count}");
        assert_eq!(c.peek(0x75), variant.who_am_i());
    }
}
