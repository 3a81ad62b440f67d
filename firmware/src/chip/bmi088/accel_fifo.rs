//! The accelerometer's 1 KB FIFO (AN 3): 7-byte frames (header 0x84, then ACC_X..Z
//! little-endian) pushed at the ODR divided by 2^FIFO_DOWNS, read through FIFO_DATA.
//!
//! - FIFO_LENGTH counts whole frames' bytes; a frame leaves only once all its bytes were clocked
//!   out in one burst: a burst that ends inside a frame leaves it to be read again whole
//!   (AN 3.2.6, 3.5.3);
//! - overflow (AN 2.1, 3.2.2): in FIFO mode (FIFO_CONFIG_0 bit 0) a frame that does not fit is
//!   dropped, in stream mode the oldest frames make room; either way the next burst begins with
//!   a skip frame `0x40, n` (n frames lost, at most 0xFF), which takes no FIFO space;
//! - when the last frame leaves during a burst, a sensortime frame `0x44` + SENSORTIME (3 bytes,
//!   taken at that moment) follows (AN 3.2.3; FIFO_CONFIG_0 bit 1, which enables it on the
//!   BMI270, "must always be 1" here); after it, and on a burst into an empty FIFO, an over-read
//!   returns 0x80, 0x00, 0x80, … ("0x8000", AN 3.2.6);
//! - FIFO reset: ACC_SOFTRESET = 0xB0 (AN 3.4), and a soft reset.
//!
//! Not emulated: the INT1/INT2 tags of the header (the pins are never inputs here), the FIFO
//! input config and sample drop frames of a configuration change.

use margemu_protocol::regmap::bmi088::accel::{bits, FIFO_SIZE};
use margemu_protocol::regmap::bmi088::convert::sensortime_bytes;

/// Bytes of an acceleration frame.
pub(super) const FRAME_LEN: usize = 7;

/// What the current burst clocks out of FIFO_DATA next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Out {
    /// Nothing read yet in this burst.
    Start,
    /// The skip frame; `sent` of its 2 bytes went out.
    Skip { count: u8, sent: u8 },
    /// Data frames.
    Frames,
    /// The sensortime frame; `sent` of its 4 bytes went out.
    Time { ticks: u32, sent: u8 },
    /// Over-read bytes; `sent` went out.
    Over { sent: usize },
}

/// The FIFO and the state of the burst reading it.
#[derive(Clone, Debug)]
pub(super) struct AccelFifo {
    buf: [u8; FIFO_SIZE],
    head: usize,
    len: usize,
    /// Bytes of the front frame clocked out in this burst.
    front_read: usize,
    /// Frames lost to overflow since the last skip frame.
    skipped: u16,
    /// Samples since the last reset, for down-sampling.
    samples: u32,
    out: Out,
}

impl Default for AccelFifo {
    fn default() -> Self {
        Self {
            buf: [0; FIFO_SIZE],
            head: 0,
            len: 0,
            front_read: 0,
            skipped: 0,
            samples: 0,
            out: Out::Start,
        }
    }
}

impl AccelFifo {
    /// FIFO reset: empty, nothing skipped.
    pub(super) fn reset(&mut self) {
        *self = Self {
            buf: self.buf,
            ..Self::default()
        };
    }

    /// Bytes of whole frames queued.
    pub(super) fn len(&self) -> usize {
        self.len
    }

    /// Whether another frame would not fit.
    pub(super) fn is_full(&self) -> bool {
        self.len + FRAME_LEN > FIFO_SIZE
    }

    /// A sample's data: stored as a frame when the down-sampling factor 2^`downs` lets it in;
    /// `stop_on_full` is FIFO mode.
    pub(super) fn push_sample(&mut self, data: &[u8; 6], downs: u8, stop_on_full: bool) {
        let due = self.samples & ((1u32 << (downs & 0x07)) - 1) == 0;
        self.samples = self.samples.wrapping_add(1);
        if !due {
            return;
        }
        self.push_frame(data, stop_on_full);
    }

    /// The overflow fault: frames of `data` until the FIFO is full, then one more, which is
    /// lost (or makes room, in stream mode) and counts in the next skip frame.
    pub(super) fn overflow_with(&mut self, data: &[u8; 6], stop_on_full: bool) {
        while !self.is_full() {
            self.push_frame(data, stop_on_full);
        }
        self.push_frame(data, stop_on_full);
    }

    /// Appends one frame of `data`, making room or dropping it when full.
    fn push_frame(&mut self, data: &[u8; 6], stop_on_full: bool) {
        if self.is_full() {
            self.skipped = self.skipped.saturating_add(1);
            if stop_on_full {
                return;
            }
            self.drop_front();
        }
        let frame = [
            bits::FIFO_HEADER_ACC,
            data[0],
            data[1],
            data[2],
            data[3],
            data[4],
            data[5],
        ];
        for byte in frame {
            if let Some(slot) = self.buf.get_mut((self.head + self.len) % FIFO_SIZE) {
                *slot = byte;
            }
            self.len += 1;
        }
    }

    /// Stream mode makes room: the oldest frame goes (a partly read one too).
    fn drop_front(&mut self) {
        let n = FRAME_LEN.min(self.len);
        self.head = (self.head + n) % FIFO_SIZE;
        self.len -= n;
        self.front_read = 0;
    }

    /// The next FIFO_DATA byte of this burst; `ticks` is the sensor time now.
    pub(super) fn peek(&mut self, ticks: u32) -> u8 {
        if self.out == Out::Start {
            self.out = if self.skipped > 0 {
                let count = u8::try_from(self.skipped).unwrap_or(u8::MAX);
                Out::Skip { count, sent: 0 }
            } else if self.len > 0 {
                Out::Frames
            } else {
                Out::Over { sent: 0 }
            };
        }
        match self.out {
            Out::Start | Out::Over { .. } => {
                let sent = match self.out {
                    Out::Over { sent } => sent,
                    _ => 0,
                };
                bits::FIFO_OVERREAD[sent % 2]
            }
            Out::Skip { count, sent } => [bits::FIFO_HEADER_SKIP, count]
                .get(usize::from(sent))
                .copied()
                .unwrap_or(0),
            Out::Frames => self
                .buf
                .get((self.head + self.front_read) % FIFO_SIZE)
                .copied()
                .unwrap_or(0),
            Out::Time { sent, .. } => {
                let t = sensortime_bytes(ticks);
                [0x44, t[0], t[1], t[2]]
                    .get(usize::from(sent))
                    .copied()
                    .unwrap_or(0)
            }
        }
    }

    /// The byte [`AccelFifo::peek`] returned went out; `ticks` is the sensor time now.
    pub(super) fn pop(&mut self, ticks: u32) {
        self.out = match self.out {
            Out::Start => Out::Start,
            Out::Skip { count, sent: 0 } => {
                self.skipped = 0;
                Out::Skip { count, sent: 1 }
            }
            Out::Skip { .. } if self.len > 0 => Out::Frames,
            Out::Skip { .. } => Out::Over { sent: 0 },
            Out::Frames => self.pop_frame_byte(ticks),
            Out::Time { ticks, sent } if sent < 3 => Out::Time {
                ticks,
                sent: sent + 1,
            },
            Out::Time { .. } => Out::Over { sent: 0 },
            Out::Over { sent } => Out::Over {
                sent: sent.wrapping_add(1),
            },
        };
    }

    fn pop_frame_byte(&mut self, ticks: u32) -> Out {
        if self.len == 0 {
            return Out::Over { sent: 0 };
        }
        self.front_read += 1;
        if self.front_read < FRAME_LEN {
            return Out::Frames;
        }
        self.drop_front();
        if self.len == 0 {
            Out::Time { ticks, sent: 0 }
        } else {
            Out::Frames
        }
    }

    /// The burst ended: a partly read frame will be read again whole.
    pub(super) fn end_burst(&mut self) {
        self.front_read = 0;
        self.out = Out::Start;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A burst of `N` bytes.
    fn read<const N: usize>(f: &mut AccelFifo) -> [u8; N] {
        let mut bytes = [0; N];
        for b in &mut bytes {
            *b = f.peek(0x0A0B0C);
            f.pop(0x0A0B0C);
        }
        f.end_burst();
        bytes
    }

    #[test]
    fn frames_then_sensortime_then_overread() {
        let mut f = AccelFifo::default();
        f.push_sample(&[1, 2, 3, 4, 5, 6], 0, true);
        assert_eq!(f.len(), 7);
        assert_eq!(
            read::<13>(&mut f),
            [0x84, 1, 2, 3, 4, 5, 6, 0x44, 0x0C, 0x0B, 0x0A, 0x80, 0x00]
        );
        assert_eq!(read::<3>(&mut f), [0x80, 0x00, 0x80]);
    }

    #[test]
    fn overflow_skips_and_downsampling() {
        let mut f = AccelFifo::default();
        for k in 0..150u8 {
            f.push_sample(&[k; 6], 0, true);
        }
        assert_eq!(f.len(), 146 * 7);
        assert_eq!(read::<3>(&mut f), [0x40, 4, 0x84]);
        let mut f = AccelFifo::default();
        for k in 0..150u8 {
            f.push_sample(&[k; 6], 0, false);
        }
        assert_eq!(read::<4>(&mut f), [0x40, 4, 0x84, 4]); // the oldest four went
        let mut f = AccelFifo::default();
        for k in 0..8u8 {
            f.push_sample(&[k; 6], 2, true);
        }
        assert_eq!(
            read::<16>(&mut f),
            [0x84, 0, 0, 0, 0, 0, 0, 0x84, 4, 4, 4, 4, 4, 4, 0x44, 0x0C]
        );
    }
}
