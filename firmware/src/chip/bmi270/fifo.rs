//! The 2 KB FIFO (DS: 4.7 FIFO): frames pushed at each latch, read byte by byte through
//! FIFO_DATA, fill level in FIFO_LENGTH_0/1.
//!
//! At each latch one frame holds the sensors FIFO_CONFIG_1 enables (fifo_gyr_en, fifo_acc_en)
//! that have a new sample for the FIFO: a sensor that took the latch, thinned by FIFO_DOWNS
//! (gyr_fifo_downs, acc_fifo_downs: one sample in 2^n, counted on the chip's clock as the
//! sensors' own rates are). With headers (fifo_header_en) `0x80 | gyr << 3 | acc << 2`, then
//! gyro X/Y/Z and accel X/Y/Z, little-endian: 0x8C + 12 bytes with both, 0x88 or 0x84 + 6
//! with one, as ArduPilot's parser expects at accel and gyro rates that differ. Without headers
//! a frame holds every enabled sensor that runs, the one without a new sample repeating its
//! last value. ArduPilot's configuration (gyro 3.2 kHz, accel 1.6 kHz, FIFO_DOWNS 0x89: the
//! gyro halved) gives one 0x8C frame every 625 µs. A frame that does not fit is dropped; in
//! stream mode (FIFO_CONFIG_0 fifo_stop_on_full = 0) that also sets ERR_REG.fifo_err, which a
//! FIFO flush (CMD 0xB0) or a soft reset clears. A read of an empty FIFO returns 0x80.
//!
//! Not emulated: the sensor time frame after the last frame (FIFO_CONFIG_0 bit 1), skip,
//! configuration-change and drop frames, pre-filtered data (FIFO_DOWNS bits 3 and 7 are stored;
//! the frames hold the filtered data of the data registers), the auxiliary sensor, the
//! watermark and its interrupt, and stream mode discarding the oldest frames. A frame leaves
//! the FIFO only when all its bytes were clocked out in one burst; a burst that ends inside a
//! frame leaves it to be read again whole.

use margemu_protocol::regmap::bmi270::image::field;
use margemu_protocol::regmap::bmi270::{bits, reg, FIFO_SIZE};

use super::{Bmi270, LATCH_LEN};

/// Most frames the FIFO can hold (the shortest frame is 6 bytes).
const MAX_FRAMES: usize = FIFO_SIZE / 6 + 1;

/// A ring buffer of FIFO bytes, kept as whole frames: a frame leaves only once every byte of it
/// was clocked out within one burst (DS: 4.7 FIFO; Betaflight's driver relies on a partially
/// read frame staying in the queue).
#[derive(Clone, Debug)]
pub(super) struct Fifo {
    buf: [u8; FIFO_SIZE],
    head: usize,
    len: usize,
    /// Lengths of the queued frames, oldest at `frame_head`.
    frames: [u8; MAX_FRAMES],
    frame_head: usize,
    frame_count: usize,
    /// Bytes of the oldest frame clocked out in the current burst.
    read_in_front: usize,
}

impl Default for Fifo {
    fn default() -> Self {
        Self {
            buf: [0; FIFO_SIZE],
            head: 0,
            len: 0,
            frames: [0; MAX_FRAMES],
            frame_head: 0,
            frame_count: 0,
            read_in_front: 0,
        }
    }
}

impl Fifo {
    pub(super) fn flush(&mut self) {
        *self = Self {
            buf: self.buf,
            ..Self::default()
        };
    }

    /// Bytes queued, the partially read front frame included.
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// The next byte out, without removing it.
    pub(super) fn peek(&self) -> Option<u8> {
        if self.read_in_front >= self.len {
            return None;
        }
        self.buf
            .get((self.head + self.read_in_front) % FIFO_SIZE)
            .copied()
    }

    /// One byte was clocked out; the front frame leaves when its last byte has.
    pub(super) fn pop(&mut self) {
        if self.peek().is_none() {
            return;
        }
        self.read_in_front += 1;
        let front = usize::from(self.frames.get(self.frame_head).copied().unwrap_or(0));
        if self.read_in_front >= front {
            let n = front.min(self.len);
            self.head = (self.head + n) % FIFO_SIZE;
            self.len -= n;
            self.frame_head = (self.frame_head + 1) % MAX_FRAMES;
            self.frame_count = self.frame_count.saturating_sub(1);
            self.read_in_front = 0;
        }
    }

    /// The burst ended: a partially read frame will be read again from its start.
    pub(super) fn end_burst(&mut self) {
        self.read_in_front = 0;
    }

    /// Appends `frame` whole; false (and nothing written) when it does not fit.
    pub(super) fn push(&mut self, frame: &[u8]) -> bool {
        let Ok(frame_len) = u8::try_from(frame.len()) else {
            return false;
        };
        if frame.is_empty() || frame.len() > FIFO_SIZE - self.len || self.frame_count >= MAX_FRAMES
        {
            return false;
        }
        for &byte in frame {
            let tail = (self.head + self.len) % FIFO_SIZE;
            if let Some(slot) = self.buf.get_mut(tail) {
                *slot = byte;
            }
            self.len += 1;
        }
        let slot = (self.frame_head + self.frame_count) % MAX_FRAMES;
        if let Some(entry) = self.frames.get_mut(slot) {
            *entry = frame_len;
        }
        self.frame_count += 1;
        true
    }
}

impl Bmi270 {
    /// Pushes the frame of one latched sample (`drdy`: the sensors that took the latch).
    pub(super) fn fifo_push_sample(&mut self, latch: &[u8; LATCH_LEN], drdy: u8) {
        let config = self.stored(reg::FIFO_CONFIG_1);
        let downs = self.stored(reg::FIFO_DOWNS);
        let now = self.now_ns;
        let gyr_downs = u32::from(downs & bits::GYR_FIFO_DOWNS);
        let acc_downs = u32::from((downs & bits::ACC_FIFO_DOWNS) >> 4);
        let gyr_period = self.gyro_period_ns().saturating_mul(1 << gyr_downs);
        let acc_period = self.accel_period_ns().saturating_mul(1 << acc_downs);
        let gyr_new = config & bits::FIFO_GYR_EN != 0
            && drdy & bits::DRDY_GYR != 0
            && (gyr_downs == 0 || self.ticks.fifo_gyro.take(now, gyr_period));
        let acc_new = config & bits::FIFO_ACC_EN != 0
            && drdy & bits::DRDY_ACC != 0
            && (acc_downs == 0 || self.ticks.fifo_accel.take(now, acc_period));
        if !gyr_new && !acc_new {
            return;
        }
        let headers = config & bits::FIFO_HEADER_EN != 0;
        // Headerless frames hold every enabled sensor that runs, the slower one repeated.
        let pwr = self.pwr_ctrl();
        let gyr = gyr_new || !headers && config & bits::FIFO_GYR_EN != 0 && pwr & bits::GYR_EN != 0;
        let acc = acc_new || !headers && config & bits::FIFO_ACC_EN != 0 && pwr & bits::ACC_EN != 0;
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
        if headers {
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
            append(latch.get(field::GYRO).unwrap_or(&[]));
        }
        if acc {
            append(latch.get(field::ACCEL).unwrap_or(&[]));
        }
        let frame = frame.get(..n).unwrap_or(&[]);
        let stop_on_full = self.stored(reg::FIFO_CONFIG_0) & bits::FIFO_STOP_ON_FULL != 0;
        let mut fits = self.fifo.push(frame);
        // The overflow fault: copies of the frame until one does not fit (`faults.rs`).
        let mut copies = if self.fault.fifo_overflow {
            MAX_FRAMES + 1
        } else {
            0
        };
        while fits && copies > 0 {
            fits = self.fifo.push(frame);
            copies -= 1;
        }
        if !fits && !stop_on_full {
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
        f.flush();
        assert_eq!(f.peek(), None);
        assert!(!f.push(&[]));
    }

    #[test]
    fn a_partially_read_frame_stays() {
        let mut f = Fifo::default();
        assert!(f.push(&[1, 2, 3, 4, 5, 6, 7]));
        assert!(f.push(&[8; 7]));
        f.pop();
        f.pop();
        assert_eq!((f.peek(), f.len()), (Some(3), 14));
        f.end_burst();
        assert_eq!(f.peek(), Some(1));
        for _ in 0..7 {
            f.pop();
        }
        assert_eq!((f.peek(), f.len()), (Some(8), 7));
        f.end_burst();
        assert_eq!(f.peek(), Some(8));
    }
}
