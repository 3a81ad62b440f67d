//! The log of register writes the device under test makes, for telemetry.
//!
//! Every write that reaches an emulated register — over SPI, over I2C (the MPU-9250 itself or the
//! AK8963 in bypass mode) or through the MPU-9250's auxiliary I2C master on the DUT's behalf —
//! is appended as a [`RegisterWrite`]. The link handler drains it with
//! [`WriteLog::pop`]; when it does not keep up, the *oldest* entries are overwritten (the most
//! recent configuration is what the host needs) and [`WriteLog::dropped`] counts them.
//!
//! ```
//! use margemu_firmware::chip::{Bus, RegisterWrite, WriteLog};
//! let mut log = WriteLog::<2>::new();
//! for value in 1..=3 {
//!     log.push(RegisterWrite { bus: Bus::Spi, device: 0x68, register: 0x6B, value });
//! }
//! assert_eq!(log.dropped(), 1);
//! assert_eq!(log.pop().map(|w| w.value), Some(2));
//! assert_eq!(log.pop().map(|w| w.value), Some(3));
//! assert_eq!(log.pop(), None);
//! ```

/// The bus a register write arrived on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bus {
    /// The SPI target interface.
    Spi,
    /// The primary I2C target interface (including the AK8963 in bypass mode).
    I2c,
    /// The MPU-9250's auxiliary I2C master, writing to a slave on the DUT's behalf.
    Aux,
}

/// One register write made by the device under test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RegisterWrite {
    /// Where it arrived.
    pub bus: Bus,
    /// The 7-bit I2C address of the die written to (the MPU-9250's 0x68/0x69 also for SPI;
    /// 0x0C for the AK8963).
    pub device: u8,
    /// Register address.
    pub register: u8,
    /// The byte written (before any write mask).
    pub value: u8,
}

impl RegisterWrite {
    const EMPTY: Self = Self {
        bus: Bus::Spi,
        device: 0,
        register: 0,
        value: 0,
    };
}

/// A ring buffer of the last `N` register writes.
#[derive(Clone, Debug)]
pub struct WriteLog<const N: usize> {
    entries: [RegisterWrite; N],
    head: usize,
    len: usize,
    dropped: u32,
}

impl<const N: usize> Default for WriteLog<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> WriteLog<N> {
    /// An empty log.
    pub const fn new() -> Self {
        Self {
            entries: [RegisterWrite::EMPTY; N],
            head: 0,
            len: 0,
            dropped: 0,
        }
    }

    /// Appends `write`, overwriting the oldest entry when full.
    pub fn push(&mut self, write: RegisterWrite) {
        if N == 0 {
            self.dropped = self.dropped.saturating_add(1);
            return;
        }
        if self.len == N {
            self.head = (self.head + 1) % N;
            self.len -= 1;
            self.dropped = self.dropped.saturating_add(1);
        }
        let tail = (self.head + self.len) % N;
        self.entries[tail] = write;
        self.len += 1;
    }

    /// Removes and returns the oldest entry.
    pub fn pop(&mut self) -> Option<RegisterWrite> {
        if self.len == 0 {
            return None;
        }
        let write = self.entries[self.head];
        self.head = (self.head + 1) % N;
        self.len -= 1;
        Some(write)
    }

    /// Number of entries waiting.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no entry is waiting.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Entries overwritten before they were popped, since creation (saturating).
    pub fn dropped(&self) -> u32 {
        self.dropped
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(value: u8) -> RegisterWrite {
        RegisterWrite {
            bus: Bus::I2c,
            device: 0x0C,
            register: 0x0A,
            value,
        }
    }

    #[test]
    fn fifo_order_and_wraparound() {
        let mut log = WriteLog::<3>::new();
        assert!(log.is_empty());
        for round in 0..5u8 {
            log.push(write(2 * round));
            log.push(write(2 * round + 1));
            assert_eq!(log.pop(), Some(write(2 * round)));
            assert_eq!(log.pop(), Some(write(2 * round + 1)));
        }
        assert_eq!(log.pop(), None);
        assert_eq!(log.dropped(), 0);
    }

    #[test]
    fn overflow_keeps_the_newest() {
        let mut log = WriteLog::<3>::new();
        for v in 0..10 {
            log.push(write(v));
        }
        assert_eq!(log.len(), 3);
        assert_eq!(log.dropped(), 7);
        assert_eq!(
            [log.pop(), log.pop(), log.pop()],
            [Some(write(7)), Some(write(8)), Some(write(9))]
        );
    }

    #[test]
    fn zero_capacity_never_panics() {
        let mut log = WriteLog::<0>::new();
        log.push(write(1));
        assert_eq!(log.pop(), None);
        assert_eq!(log.dropped(), 1);
    }
}
