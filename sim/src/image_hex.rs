//! Register images as text: two lowercase hex digits per byte, as `sent.csv` and the session
//! logs write them, and the one parser that reads them back.

use margemu_protocol::link::Image;

/// Lowercase hex of an image (two digits per byte), as in `sent.csv`.
pub fn image_hex(image: &[u8]) -> String {
    image.iter().map(|b| format!("{b:02x}")).collect()
}

/// Parses [`image_hex`] back; `None` unless it is `2 · len` hex digits.
pub fn parse_image_hex(hex: &str, len: usize) -> Option<Image> {
    let bytes = hex.as_bytes();
    if bytes.len() != 2 * len {
        return None;
    }
    let mut out = Image::zeroed(len)?;
    for (slot, pair) in out.as_mut_bytes().iter_mut().zip(bytes.chunks(2)) {
        *slot = u8::from_str_radix(std::str::from_utf8(pair).ok()?, 16).ok()?;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hex_round_trips() {
        let mut bytes = [0u8; 22];
        bytes[0] = 0xAB;
        bytes[21] = 0x01;
        let image = Image::from(bytes);
        let hex = image_hex(&image);
        assert_eq!(&hex[..4], "ab00");
        assert_eq!(parse_image_hex(&hex, 22), Some(image));
        assert_eq!(parse_image_hex(&hex, 14), None);
        assert_eq!(parse_image_hex("zz", 1), None);
    }
}
