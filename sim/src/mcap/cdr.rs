//! Little-endian CDR (XCDR1, the encoding ROS 2's default middleware and rosbag2 use), written by
//! hand for the few message types of [`super::schema`].
//!
//! A message is the 4-byte encapsulation header `00 01 00 00` (CDR, little-endian) followed by
//! its fields in declaration order. Each primitive is aligned to its own size, counted from the
//! end of the header; a string is its `u32` length including the terminating NUL, its bytes and
//! the NUL; a sequence is its `u32` element count then its elements; a fixed array is its
//! elements alone. Reference: the OMG CDR specification (DDS-XTypes 1.3, §7.4.3.4, "XCDR
//! version 1"), as `rosbags.serde` and `mcap_ros2` read it.

/// A CDR message under construction, in a buffer the caller reuses.
pub(crate) struct Cdr<'a> {
    buf: &'a mut Vec<u8>,
}

/// The encapsulation header: plain CDR, little-endian.
const HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

impl<'a> Cdr<'a> {
    /// Clears `buf` and starts a message in it.
    pub(crate) fn new(buf: &'a mut Vec<u8>) -> Self {
        buf.clear();
        buf.extend_from_slice(&HEADER);
        Self { buf }
    }

    fn align(&mut self, n: usize) {
        let pos = self.buf.len() - HEADER.len();
        let pad = (n - pos % n) % n;
        self.buf.resize(self.buf.len() + pad, 0);
    }

    /// A `uint32`.
    pub(crate) fn u32(&mut self, v: u32) -> &mut Self {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// An `int32`.
    pub(crate) fn i32(&mut self, v: i32) -> &mut Self {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// A `float64`.
    pub(crate) fn f64(&mut self, v: f64) -> &mut Self {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }

    /// Several `float64` (a `Vector3`, a `float64[9]`).
    pub(crate) fn f64s(&mut self, vs: &[f64]) -> &mut Self {
        vs.iter().for_each(|v| {
            self.f64(*v);
        });
        self
    }

    /// A `string`.
    pub(crate) fn string(&mut self, s: &str) -> &mut Self {
        self.u32(s.len() as u32 + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
        self
    }

    /// A `std_msgs/Header`: `builtin_interfaces/Time` from `t_ns`, then the frame.
    pub(crate) fn header(&mut self, t_ns: u64, frame_id: &str) -> &mut Self {
        let (sec, nanosec) = stamp(t_ns);
        self.i32(sec).u32(nanosec).string(frame_id)
    }
}

/// `builtin_interfaces/Time` of `t_ns`: whole seconds (saturating at `i32::MAX`, 68 years) and
/// the nanoseconds left.
pub(crate) fn stamp(t_ns: u64) -> (i32, u32) {
    let sec = (t_ns / 1_000_000_000).min(i32::MAX as u64) as i32;
    (sec, (t_ns % 1_000_000_000) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_aligned_from_the_end_of_the_header() {
        let mut buf = Vec::new();
        Cdr::new(&mut buf).string("ab").f64(1.0);
        // header, length 3, "ab\0", one pad byte to 8, then the double
        let mut want = vec![0, 1, 0, 0, 3, 0, 0, 0, b'a', b'b', 0, 0];
        want.extend_from_slice(&1.0f64.to_le_bytes());
        assert_eq!(buf, want);
    }

    #[test]
    fn header_splits_the_time() {
        let mut buf = Vec::new();
        Cdr::new(&mut buf).header(2_000_000_005, "w");
        assert_eq!(
            buf,
            [0, 1, 0, 0, 2, 0, 0, 0, 5, 0, 0, 0, 2, 0, 0, 0, b'w', 0]
        );
    }
}
