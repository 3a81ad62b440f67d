//! [`Image`]: one sample's register image, of its chip model's length.

use core::fmt;
use core::ops::Deref;

/// The longest image of any one model (the ICM-42688-P's 32 bytes).
pub const MAX_CHIP_IMAGE_LEN: usize = 32;

/// The longest image the link carries: a rig's, every device's image back to back (two of the
/// longest, or an IMU, a second IMU and a compass). It sizes every sample slot of a device's
/// buffer, so it stays small: a rig whose images add up to more is refused.
pub const MAX_IMAGE_LEN: usize = 2 * MAX_CHIP_IMAGE_LEN;

/// One sample's register image: `len` bytes laid out by the chip module of its model (see
/// [`ChipModel::image_len`](super::ChipModel::image_len)), or a rig's images back to back: the
/// unit the link carries in source mode (a). Dereferences to its bytes; the bytes beyond `len` are always zero, so equality and
/// hashing see only the image.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Image {
    len: u8,
    bytes: [u8; MAX_IMAGE_LEN],
}

impl Image {
    /// An image of `bytes`; `None` if longer than [`MAX_IMAGE_LEN`].
    pub fn new(bytes: &[u8]) -> Option<Self> {
        let mut image = Self::zeroed(bytes.len())?;
        image.bytes.get_mut(..bytes.len())?.copy_from_slice(bytes);
        Some(image)
    }

    /// An image of `len` zero bytes; `None` if longer than [`MAX_IMAGE_LEN`].
    pub fn zeroed(len: usize) -> Option<Self> {
        (len <= MAX_IMAGE_LEN).then_some(Self {
            len: len as u8,
            bytes: [0; MAX_IMAGE_LEN],
        })
    }

    /// The image's bytes.
    pub fn as_bytes(&self) -> &[u8] {
        &self.bytes[..usize::from(self.len).min(MAX_IMAGE_LEN)]
    }

    /// The image's bytes, to fill.
    pub fn as_mut_bytes(&mut self) -> &mut [u8] {
        let len = usize::from(self.len).min(MAX_IMAGE_LEN);
        &mut self.bytes[..len]
    }

    /// Parses the image's text form, two hex digits per byte (the [`fmt::LowerHex`] output,
    /// as `sent.csv` holds it; either case); `None` unless `hex` is exactly `2 · len` hex digits
    /// and `len` at most [`MAX_IMAGE_LEN`].
    ///
    /// ```
    /// use margemu_protocol::chip::Image;
    /// let image = Image::new(&[0xab, 0x00, 0x01]).unwrap();
    /// assert_eq!(format!("{image:x}"), "ab0001");
    /// assert_eq!(Image::parse_hex("ab0001", 3), Some(image));
    /// assert_eq!(Image::parse_hex("ab0001", 2), None);
    /// ```
    pub fn parse_hex(hex: &str, len: usize) -> Option<Self> {
        let digits = hex.as_bytes();
        if digits.len() != 2 * len {
            return None;
        }
        let mut image = Self::zeroed(len)?;
        let digit = |c: &u8| char::from(*c).to_digit(16);
        for (slot, pair) in image.as_mut_bytes().iter_mut().zip(digits.chunks_exact(2)) {
            let [hi, lo] = pair else { return None };
            *slot = (digit(hi)? << 4 | digit(lo)?) as u8;
        }
        Some(image)
    }
}

impl Default for Image {
    /// The empty image.
    fn default() -> Self {
        Self {
            len: 0,
            bytes: [0; MAX_IMAGE_LEN],
        }
    }
}

impl Deref for Image {
    type Target = [u8];
    fn deref(&self) -> &[u8] {
        self.as_bytes()
    }
}

impl AsRef<[u8]> for Image {
    fn as_ref(&self) -> &[u8] {
        self.as_bytes()
    }
}

impl<const N: usize> From<[u8; N]> for Image {
    /// An image of an array; arrays longer than [`MAX_IMAGE_LEN`] keep their first bytes.
    fn from(bytes: [u8; N]) -> Self {
        let n = N.min(MAX_IMAGE_LEN);
        Self::new(&bytes[..n]).unwrap_or_default()
    }
}

impl fmt::LowerHex for Image {
    /// The image's text form: two lowercase hex digits per byte, no separator (what `sent.csv`
    /// holds; [`Image::parse_hex`] reads it back).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.as_bytes()
            .iter()
            .try_for_each(|b| write!(f, "{b:02x}"))
    }
}

impl fmt::Debug for Image {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Image({self:x})")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn length_and_bytes() {
        let image = Image::new(&[1, 2, 3]).unwrap();
        assert_eq!((image.len(), &image[..]), (3, &[1u8, 2, 3][..]));
        assert_eq!(Image::from([1u8, 2, 3]), image);
        assert_ne!(Image::new(&[1, 2, 3, 0]).unwrap(), image);
        assert!(Image::new(&[0; MAX_IMAGE_LEN + 1]).is_none());
    }

    #[test]
    fn hex_round_trips() {
        let mut bytes = [0u8; 22];
        bytes[0] = 0xAB;
        bytes[21] = 0x01;
        let image = Image::from(bytes);
        let mut text = heapless::String::<64>::new();
        core::fmt::write(&mut text, format_args!("{image:x}")).unwrap();
        assert_eq!((&text[..4], text.len()), ("ab00", 44));
        assert_eq!(Image::parse_hex(&text, 22), Some(image));
        assert_eq!(Image::parse_hex("AB", 1), Image::new(&[0xab]));
        assert_eq!(Image::parse_hex(&text, 14), None);
        for bad in ["zz", "+a", "a", "\u{e9}"] {
            assert_eq!(Image::parse_hex(bad, 1), None, "{bad}");
        }
        assert_eq!(Image::parse_hex("", 0), Image::new(&[]));
    }
}
