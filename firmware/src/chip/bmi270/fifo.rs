//! The 2 KB FIFO (DS: 4.7 FIFO): frames pushed at each latch, read byte by byte through
//! FIFO_DATA, fill level in FIFO_LENGTH_0/1.
//!
//! At each latch one frame holds the sensors both FIFO_CONFIG_1 (fifo_gyr_en, fifo_acc_en)
//! and PWR_CTRL enable: with headers (fifo_header_en) `0x80 | gyr << 3 | acc << 2`, then gyro
//! X/Y/Z and accel X/Y/Z, little-endian (0x8C + 12 bytes with both); without headers the data
//! alone. A frame that does not fit is dropped; in stream mode (FIFO_CONFIG_0
//! fifo_stop_on_full = 0) that also sets ERR_REG.fifo_err, which a FIFO flush (CMD 0xB0) or a
//! soft reset clears. A read of an empty FIFO returns 0x80.
//!
//! Not emulated: the sensor time frame after the last frame (FIFO_CONFIG_0 bit 1), skip,
//! configuration-change and drop frames, FIFO_DOWNS and different accel and gyro rates (each
//! latch is one frame), the auxiliary sensor, the watermark and its interrupt, re-reading a
//! partially read frame (bytes leave the FIFO as they are clocked out), and stream mode
//! discarding the oldest frames.

use margemu_protocol::regmap::bmi270::{bits, reg, FIFO_SIZE};

use super::{Bmi270, LATCH_LEN};

/// A ring buffer of FIFO bytes.
#[derive(Clone, Debug)]
pub(super) struct Fifo {
    buf: [u8; FIFO_SIZE],
    head: usize,
    len: usize,
}

impl Default for Fifo {
    fn default() -> Self {
        Self {
            buf: [0; FIFO_SIZE],
            head: 0,
            len: 0,
        }
    }
}

impl Fifo {
    pub(super) fn flush(&mut self) {
        self.head = 0;
        self.len = 0;
    }

    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// The next byte out, without removing it.
    pub(super) fn peek(&self) -> Option<u8> {
        if self.len == 0 {
            return None;
        }
        self.buf.get(self.head).copied()
    }

    pub(super) fn pop(&mut self) {
        if self.len > 0 {
            self.head = (self.head + 1) % FIFO_SIZE;
            self.len -= 1;
        }
    }

    /// Appends `frame` whole; false (and nothing written) when it does not fit.
    pub(super) fn push(&mut self, frame: &[u8]) -> bool {
        if frame.len() > FIFO_SIZE - self.len {
            return false;
        }
        for &byte in frame {
            let tail = (self.head + self.len) % FIFO_SIZE;
            if let Some(slot) = self.buf.get_mut(tail) {
                *slot = byte;
            }
            self.len += 1;
        }
        true
    }
}

impl Bmi270 {
    /// Pushes the frame of one latched sample (`drdy`: the sensors that produced data).
    pub(super) fn fifo_push_sample(&mut self, latch: &[u8; LATCH_LEN], drdy: u8) {
        let config = self.stored(reg::FIFO_CONFIG_1);
        let gyr = config & bits::FIFO_GYR_EN != 0 && drdy & bits::DRDY_GYR != 0;
        let acc = config & bits::FIFO_ACC_EN != 0 && drdy & bits::DRDY_ACC != 0;
        if !gyr && !acc {
            return;
        }
        let mut frame = [0u8; 13];
        let mut n = 0;
        let mut append = |bytes: &[u8]| {
            for &b in bytes {
                if let Some(slot) = frame.get_mut(n) {
                    *slot = b;
                    n += 1;
                }
            }
        };
        if config & bits::FIFO_HEADER_EN != 0 {
            let mut header = bits::FIFO_HEADER_REGULAR;
            if gyr {
                header |= bits::FIFO_HEADER_GYR;
            }
            if acc {
                header |= bits::FIFO_HEADER_ACC;
            }
            append(&[header]);
        }
        if gyr {
            append(latch.get(6..12).unwrap_or(&[]));
        }
        if acc {
            append(latch.get(0..6).unwrap_or(&[]));
        }
        let frame = frame.get(..n).unwrap_or(&[]);
        let stop_on_full = self.stored(reg::FIFO_CONFIG_0) & bits::FIFO_STOP_ON_FULL != 0;
        if !self.fifo.push(frame) && !stop_on_full {
            let err = self.stored(reg::ERR_REG) | bits::FIFO_ERR;
            self.set(reg::ERR_REG, err);
        }
    }

    /// CMD 0xB0: the FIFO emptied, ERR_REG.fifo_err cleared.
    pub(super) fn fifo_flush(&mut self) {
        self.fifo.flush();
        let err = self.stored(reg::ERR_REG) & !bits::FIFO_ERR;
        self.set(reg::ERR_REG, err);
    }

    /// FIFO_LENGTH_0/1: the fill level in bytes (14 bits).
    pub(super) fn fifo_length_byte(&self, addr: u8) -> u8 {
        let len = self.fifo.len() as u16 & 0x3FFF;
        let [lo, hi] = len.to_le_bytes();
        if addr == reg::FIFO_LENGTH_0 {
            lo
        } else {
            hi
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn push_whole_frames_only() {
        let mut f = Fifo::default();
        for _ in 0..(FIFO_SIZE / 13) {
            assert!(f.push(&[0x8C; 13]));
        }
        assert_eq!(f.len(), FIFO_SIZE / 13 * 13);
        assert!(!f.push(&[0x8C; 13]));
        assert!(f.push(&[1; FIFO_SIZE % 13]));
        assert_eq!(f.len(), FIFO_SIZE);
        f.pop();
        assert_eq!(f.peek(), Some(0x8C));
        f.flush();
        assert_eq!(f.peek(), None);
    }
}
