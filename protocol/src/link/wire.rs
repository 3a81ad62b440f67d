//! Little-endian cursors over byte slices that never panic: the one place where message fields
//! become bytes and back.
//!
//! [`Reader`] fails with [`Error::PayloadTooShort`] when a field runs past the end and
//! [`Reader::finish`] with [`Error::PayloadTooLong`] when bytes are left over. [`Writer`] fails
//! with [`Error::BufferTooSmall`] instead of writing past its buffer.
//!
//! ```
//! use margemu_protocol::link::wire::{Reader, Writer};
//! let mut buf = [0u8; 10];
//! let mut w = Writer::new(&mut buf);
//! w.u16(0x0102)?;
//! w.f64(-0.5)?;
//! assert_eq!(w.position(), 10);
//! assert_eq!(buf[..2], [0x02, 0x01]);
//! let mut r = Reader::new(&buf);
//! assert_eq!((r.u16()?, r.f64()?), (0x0102, -0.5));
//! r.finish()?;
//! # Ok::<(), margemu_protocol::link::Error>(())
//! ```

use super::Error;

/// Reads little-endian fields from the front of a byte slice.
#[derive(Clone, Copy, Debug)]
pub struct Reader<'a> {
    rest: &'a [u8],
}

impl<'a> Reader<'a> {
    /// A reader over `bytes`.
    pub fn new(bytes: &'a [u8]) -> Self {
        Self { rest: bytes }
    }

    /// The next `n` bytes.
    pub fn bytes(&mut self, n: usize) -> Result<&'a [u8], Error> {
        if n > self.rest.len() {
            return Err(Error::PayloadTooShort);
        }
        let (head, tail) = self.rest.split_at(n);
        self.rest = tail;
        Ok(head)
    }

    /// The next `N` bytes as an array.
    pub fn array<const N: usize>(&mut self) -> Result<[u8; N], Error> {
        let mut out = [0u8; N];
        out.copy_from_slice(self.bytes(N)?);
        Ok(out)
    }

    /// A `u8`.
    pub fn u8(&mut self) -> Result<u8, Error> {
        Ok(self.array::<1>()?[0])
    }

    /// A little-endian `u16`.
    pub fn u16(&mut self) -> Result<u16, Error> {
        self.array().map(u16::from_le_bytes)
    }

    /// A little-endian `u32`.
    pub fn u32(&mut self) -> Result<u32, Error> {
        self.array().map(u32::from_le_bytes)
    }

    /// A little-endian `u64`.
    pub fn u64(&mut self) -> Result<u64, Error> {
        self.array().map(u64::from_le_bytes)
    }

    /// An IEEE 754 binary32, little-endian, bit for bit (NaN payloads included).
    pub fn f32(&mut self) -> Result<f32, Error> {
        self.u32().map(f32::from_bits)
    }

    /// An IEEE 754 binary64, little-endian, bit for bit.
    pub fn f64(&mut self) -> Result<f64, Error> {
        self.u64().map(f64::from_bits)
    }

    /// `N` consecutive binary64 values.
    pub fn f64s<const N: usize>(&mut self) -> Result<[f64; N], Error> {
        let mut out = [0.0; N];
        for x in &mut out {
            *x = self.f64()?;
        }
        Ok(out)
    }

    /// `N` consecutive binary32 values.
    pub fn f32s<const N: usize>(&mut self) -> Result<[f32; N], Error> {
        let mut out = [0.0; N];
        for x in &mut out {
            *x = self.f32()?;
        }
        Ok(out)
    }

    /// The bytes not read yet.
    pub fn remaining(&self) -> &'a [u8] {
        self.rest
    }

    /// Succeeds if every byte was read.
    pub fn finish(self) -> Result<(), Error> {
        if self.rest.is_empty() {
            Ok(())
        } else {
            Err(Error::PayloadTooLong)
        }
    }
}

/// Writes little-endian fields into a byte slice, front to back.
#[derive(Debug)]
pub struct Writer<'a> {
    buf: &'a mut [u8],
    pos: usize,
}

impl<'a> Writer<'a> {
    /// A writer at the start of `buf`.
    pub fn new(buf: &'a mut [u8]) -> Self {
        Self { buf, pos: 0 }
    }

    /// The number of bytes written so far.
    pub fn position(&self) -> usize {
        self.pos
    }

    /// Appends `bytes`.
    pub fn bytes(&mut self, bytes: &[u8]) -> Result<(), Error> {
        let end = self
            .pos
            .checked_add(bytes.len())
            .ok_or(Error::BufferTooSmall)?;
        let dst = self
            .buf
            .get_mut(self.pos..end)
            .ok_or(Error::BufferTooSmall)?;
        dst.copy_from_slice(bytes);
        self.pos = end;
        Ok(())
    }

    /// A `u8`.
    pub fn u8(&mut self, v: u8) -> Result<(), Error> {
        self.bytes(&[v])
    }

    /// A little-endian `u16`.
    pub fn u16(&mut self, v: u16) -> Result<(), Error> {
        self.bytes(&v.to_le_bytes())
    }

    /// A little-endian `u32`.
    pub fn u32(&mut self, v: u32) -> Result<(), Error> {
        self.bytes(&v.to_le_bytes())
    }

    /// A little-endian `u64`.
    pub fn u64(&mut self, v: u64) -> Result<(), Error> {
        self.bytes(&v.to_le_bytes())
    }

    /// An IEEE 754 binary32, bit for bit.
    pub fn f32(&mut self, v: f32) -> Result<(), Error> {
        self.u32(v.to_bits())
    }

    /// An IEEE 754 binary64, bit for bit.
    pub fn f64(&mut self, v: f64) -> Result<(), Error> {
        self.u64(v.to_bits())
    }

    /// Consecutive binary64 values.
    pub fn f64s(&mut self, v: &[f64]) -> Result<(), Error> {
        v.iter().try_for_each(|&x| self.f64(x))
    }

    /// Consecutive binary32 values.
    pub fn f32s(&mut self, v: &[f32]) -> Result<(), Error> {
        v.iter().try_for_each(|&x| self.f32(x))
    }
}
