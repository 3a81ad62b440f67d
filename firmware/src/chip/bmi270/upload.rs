//! The configuration upload through INIT_DATA (DS: 4.2 initialization), tracked by coverage: the
//! emulated chip does not store the file, it records how far the bytes written reach from
//! offset 0 without a gap.

use margemu_protocol::regmap::bmi270::{CONFIG_FILE_LENS, CONFIG_RAM_LEN};

/// Progress of one configuration load (reset by INIT_CTRL = 0 and by a soft reset).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Upload {
    /// Byte offset of the next INIT_DATA byte in the current burst; `None` between bursts.
    cursor: Option<usize>,
    /// Bytes 0..loaded have been written.
    loaded: usize,
    /// A byte was written past the configuration RAM.
    overflow: bool,
}

impl Upload {
    /// A byte written to INIT_DATA; `word` is INIT_ADDR's word offset, read when a burst begins.
    /// Bytes written while INIT_CTRL is not 0 are ignored.
    pub(super) fn store(&mut self, word: u16, init_ctrl: u8) {
        if init_ctrl != 0 {
            return;
        }
        let offset = self.cursor.unwrap_or(usize::from(word) * 2);
        if offset >= CONFIG_RAM_LEN {
            self.overflow = true;
        } else if offset <= self.loaded {
            self.loaded = self.loaded.max(offset + 1);
        }
        self.cursor = Some(offset.saturating_add(1));
    }

    /// The transaction ended: the next INIT_DATA byte starts a burst at INIT_ADDR.
    pub(super) fn end_burst(&mut self) {
        self.cursor = None;
    }

    /// Whether a whole configuration file was written.
    pub(super) fn is_complete(&self) -> bool {
        !self.overflow && CONFIG_FILE_LENS.contains(&self.loaded)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn burst(upload: &mut Upload, word: u16, len: usize) {
        for _ in 0..len {
            upload.store(word, 0);
        }
        upload.end_burst();
    }

    #[test]
    fn one_burst_of_328_bytes() {
        let mut u = Upload::default();
        burst(&mut u, 0, 327);
        assert!(!u.is_complete());
        let mut u = Upload::default();
        burst(&mut u, 0, 328);
        assert!(u.is_complete());
    }

    #[test]
    fn chunks_addressed_by_word_offset() {
        let mut u = Upload::default();
        for chunk in 0..(CONFIG_RAM_LEN / 256) {
            burst(&mut u, (chunk * 128) as u16, 256);
        }
        assert!(u.is_complete());
    }

    #[test]
    fn gaps_overflow_and_locked_writes_fail() {
        let mut u = Upload::default();
        burst(&mut u, 0, 100);
        burst(&mut u, 60, 228); // resumes at byte 120: a gap of 20 bytes
        assert!(!u.is_complete());
        let mut u = Upload::default();
        burst(&mut u, 0, CONFIG_RAM_LEN + 1);
        assert!(!u.is_complete());
        let mut u = Upload::default();
        for _ in 0..328 {
            u.store(0, 1);
        }
        assert!(!u.is_complete());
    }
}
