//! The FIFO (PS-MPU-9250A-01 section 4.17; RM registers 35, 114–116): 512 bytes on the
//! MPU-9250/6500, 1024 on the MPU-6000, 1008 on the ICM-20602 (`Variant::fifo_size`).
//!
//! At each sample the enabled data go in, in register order: ACCEL (6 bytes) if FIFO_EN.ACCEL,
//! TEMP_OUT (2) if FIFO_EN.TEMP, GYRO_X/Y/Z (2 each) by their bits, then the EXT_SENS_DATA bytes
//! of slaves 0, 1, 2 (FIFO_EN bits 0–2) and 3 (I2C_MST_CTRL.SLV_3_FIFO_EN). With everything but
//! the slaves on, a record is the 14 bytes of registers 0x3B..=0x48. The ICM-20602's FIFO_EN has
//! two bits, each bringing TEMP_OUT along (`Variant::fifo_sources`).
//!
//! Overflow is per byte, as the silicon writes bytes: with CONFIG.FIFO_MODE = 0 the oldest byte
//! is dropped, with FIFO_MODE = 1 the new byte is; either sets INT_STATUS.FIFO_OFLOW_INT (a
//! record can therefore be cut, which is why drivers reset the FIFO after an overflow). Reading
//! FIFO_R_W when empty returns the last byte read (RM section 4.37).

use margemu_protocol::regmap::mpu6xxx::{bits, reg, SENSOR_LEN};

/// Storage for the largest FIFO of the family (the MPU-6000's).
const FIFO_STORAGE: usize = 1024;

use super::Mpu6xxx;

/// The FIFO storage: a byte ring.
#[derive(Clone, Debug)]
pub(super) struct Fifo {
    buf: [u8; FIFO_STORAGE],
    /// The part's FIFO size (≤ `FIFO_STORAGE`).
    capacity: usize,
    head: usize,
    len: usize,
    last_read: u8,
}

impl Fifo {
    /// An empty FIFO of `capacity` bytes (clamped to 1..=1024).
    pub(super) fn new(capacity: usize) -> Self {
        Self {
            buf: [0; FIFO_STORAGE],
            capacity: capacity.clamp(1, FIFO_STORAGE),
            head: 0,
            len: 0,
            last_read: 0,
        }
    }

    pub(super) fn len(&self) -> u16 {
        self.len as u16
    }

    /// The part's FIFO size in bytes.
    pub(super) fn capacity(&self) -> u16 {
        self.capacity as u16
    }

    pub(super) fn clear(&mut self) {
        self.head = 0;
        self.len = 0;
    }

    pub(super) fn forget_last_read(&mut self) {
        self.last_read = 0;
    }

    /// The byte a read returns: the oldest, or the last one read when empty.
    pub(super) fn peek(&self) -> u8 {
        if self.len == 0 {
            self.last_read
        } else {
            self.buf[self.head]
        }
    }

    /// Removes the oldest byte (a read of it completed).
    pub(super) fn pop(&mut self) {
        if self.len > 0 {
            self.last_read = self.buf[self.head];
            self.head = (self.head + 1) % self.capacity;
            self.len -= 1;
        }
    }

    /// Appends `byte`; returns `false` if the FIFO was full (the oldest byte was dropped, or
    /// with `keep_old` the new one).
    fn push(&mut self, byte: u8, keep_old: bool) -> bool {
        if self.len == self.capacity {
            if keep_old {
                return false;
            }
            self.head = (self.head + 1) % self.capacity;
            self.len -= 1;
            self.buf[(self.head + self.len) % self.capacity] = byte;
            self.len += 1;
            return false;
        }
        self.buf[(self.head + self.len) % self.capacity] = byte;
        self.len += 1;
        true
    }
}

impl Mpu6xxx {
    /// Pushes `bytes` under the current CONFIG.FIFO_MODE; raises FIFO_OFLOW_INT on overflow.
    pub(super) fn fifo_push(&mut self, bytes: &[u8]) {
        let keep_old = self.regs[usize::from(reg::CONFIG)] & bits::CONFIG_FIFO_MODE != 0;
        let mut overflow = false;
        for &byte in bytes {
            overflow |= !self.fifo.push(byte, keep_old);
        }
        if overflow {
            self.raise_interrupt(bits::INT_FIFO_OFLOW);
        }
    }

    /// Pushes one sample's record, taken from the new data registers `data` (0x3B..=0x60).
    pub(super) fn fifo_push_record(&mut self, data: &[u8]) {
        if self.regs[usize::from(reg::USER_CTRL)] & bits::USER_FIFO_EN == 0 {
            return;
        }
        let sources = self.config.variant.fifo_sources(
            self.regs[usize::from(reg::FIFO_EN)],
            self.regs[usize::from(reg::I2C_MST_CTRL)],
        );
        // (enable, byte range within `data`), in register order.
        let sensors = [
            (sources.accel, 0..6),
            (sources.temp, 6..8),
            (sources.gyro[0], 8..10),
            (sources.gyro[1], 10..12),
            (sources.gyro[2], 12..14),
        ];
        for (enabled, range) in sensors {
            if enabled {
                self.fifo_push(data.get(range).unwrap_or_default());
            }
        }
        for (slave, enabled) in sources.slaves.into_iter().enumerate() {
            if enabled {
                let range = self.aux.ext_range(slave);
                let start = SENSOR_LEN + range.start;
                let end = SENSOR_LEN + range.end;
                self.fifo_push(data.get(start..end).unwrap_or_default());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ring_order_and_empty_reads() {
        let mut fifo = Fifo::new(512);
        assert_eq!((fifo.len(), fifo.peek()), (0, 0));
        for round in 0..300u16 {
            let byte = round as u8;
            assert!(fifo.push(byte, false));
            assert!(fifo.push(byte.wrapping_add(1), false));
            assert_eq!(fifo.peek(), byte);
            fifo.pop();
            fifo.pop();
        }
        assert_eq!(fifo.len(), 0);
        assert_eq!(fifo.peek(), 44, "last byte read: 299 + 1 = 300 mod 256");
        fifo.pop();
        assert_eq!(fifo.peek(), 44);
    }

    #[test]
    fn overflow_drops_oldest_or_newest() {
        let mut fifo = Fifo::new(512);
        for i in 0..512 {
            assert!(fifo.push(i as u8, false));
        }
        assert!(!fifo.push(0xAA, false));
        assert_eq!((fifo.len(), fifo.peek()), (512, 1), "byte 0 dropped");
        assert!(!fifo.push(0xBB, true));
        assert_eq!((fifo.len(), fifo.peek()), (512, 1), "0xBB not stored");
        for _ in 0..511 {
            fifo.pop();
        }
        assert_eq!(fifo.peek(), 0xAA);
    }
}
