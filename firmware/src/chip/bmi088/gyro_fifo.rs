//! The gyroscope's FIFO (AN 4): up to 100 frames in FIFO mode, 99 in stream mode (the oldest
//! discarded), each the rate data at one sample: X, Y, Z little-endian, or one axis (2 bytes)
//! with FIFO_CONFIG_1's data select. FIFO_STATUS counts frames and flags an overrun (a frame
//! arriving at a full FIFO, in either mode) until FIFO_CONFIG_0/1 is written. A burst that ends
//! inside a frame loses the rest of it (AN 4.2); reading an empty FIFO returns 0x00 (not
//! specified).

use margemu_protocol::regmap::bmi088::gyro::FIFO_FRAMES;

/// The FIFO and the read position in its front frame.
#[derive(Clone, Debug)]
pub(super) struct GyroFifo {
    frames: [[u8; 6]; FIFO_FRAMES],
    head: usize,
    count: usize,
    /// Bytes per frame (6, or 2 with a single axis selected).
    frame_len: usize,
    /// Bytes of the front frame clocked out in this burst.
    front_read: usize,
    overrun: bool,
}

impl Default for GyroFifo {
    fn default() -> Self {
        Self {
            frames: [[0; 6]; FIFO_FRAMES],
            head: 0,
            count: 0,
            frame_len: 6,
            front_read: 0,
            overrun: false,
        }
    }
}

impl GyroFifo {
    /// Empty, overrun cleared.
    pub(super) fn reset(&mut self) {
        *self = Self::default();
    }

    /// Frames queued.
    pub(super) fn count(&self) -> usize {
        self.count
    }

    /// Whether a frame arrived at a full FIFO since the last reset.
    pub(super) fn overrun(&self) -> bool {
        self.overrun
    }

    /// The frames the FIFO holds in a mode (stream mode keeps one fewer).
    pub(super) const fn capacity(stream: bool) -> usize {
        if stream {
            FIFO_FRAMES - 1
        } else {
            FIFO_FRAMES
        }
    }

    /// Appends the first `len` bytes of `frame`.
    pub(super) fn push(&mut self, frame: [u8; 6], len: usize, stream: bool) {
        if self.count >= Self::capacity(stream) {
            self.overrun = true;
            if !stream {
                return;
            }
            self.drop_front();
        }
        if let Some(slot) = self.frames.get_mut((self.head + self.count) % FIFO_FRAMES) {
            *slot = frame;
        }
        self.count += 1;
        self.frame_len = len.clamp(1, 6);
    }

    /// The overflow fault: copies of `frame` until the FIFO is full, then one more, which
    /// overruns.
    pub(super) fn overflow_with(&mut self, frame: [u8; 6], len: usize, stream: bool) {
        while self.count < Self::capacity(stream) {
            self.push(frame, len, stream);
        }
        self.push(frame, len, stream);
    }

    fn drop_front(&mut self) {
        if self.count > 0 {
            self.head = (self.head + 1) % FIFO_FRAMES;
            self.count -= 1;
        }
        self.front_read = 0;
    }

    /// The next FIFO_DATA byte.
    pub(super) fn peek(&self) -> u8 {
        if self.count == 0 {
            return 0x00;
        }
        self.frames
            .get(self.head)
            .and_then(|f| f.get(self.front_read))
            .copied()
            .unwrap_or(0)
    }

    /// The byte [`GyroFifo::peek`] returned went out.
    pub(super) fn pop(&mut self) {
        if self.count == 0 {
            return;
        }
        self.front_read += 1;
        if self.front_read >= self.frame_len {
            self.drop_front();
        }
    }

    /// The burst ended: a partly read frame is lost.
    pub(super) fn end_burst(&mut self) {
        if self.front_read > 0 {
            self.drop_front();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fifo_mode_stops_stream_mode_discards() {
        let mut f = GyroFifo::default();
        for k in 0..101u8 {
            f.push([k; 6], 6, false);
        }
        assert_eq!((f.count(), f.overrun(), f.peek()), (100, true, 0));
        let mut f = GyroFifo::default();
        for k in 0..101u8 {
            f.push([k; 6], 6, true);
        }
        assert_eq!((f.count(), f.overrun(), f.peek()), (99, true, 2));
    }

    #[test]
    fn a_partial_frame_is_lost() {
        let mut f = GyroFifo::default();
        f.push([1, 2, 3, 4, 5, 6], 6, false);
        f.push([7; 6], 6, false);
        f.pop();
        f.pop();
        f.end_burst();
        assert_eq!((f.count(), f.peek()), (1, 7));
        for _ in 0..6 {
            f.pop();
        }
        assert_eq!((f.count(), f.peek()), (0, 0));
        f.push([9, 8, 0, 0, 0, 0], 2, false);
        f.pop();
        f.pop();
        assert_eq!(f.count(), 0);
    }
}
