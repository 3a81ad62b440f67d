//! The register image of a standalone magnetometer whose data registers are three
//! little-endian 16-bit values, x then y then z (the IST8310's DATAXL..=DATAZH, the
//! QMC5883L's XOUT_L..=ZOUT_H): what the link carries for one sample of such a chip, and
//! what its data registers hold after a measurement of that sample.
//!
//! The raw values are at the chip's current sensitivity and already clipped (each chip module
//! says how: [`super::ist8310::measurement`], [`super::qmc5883l::measurement`]), so a
//! measurement copies the image as it is.
//!
//! ```
//! use margemu_protocol::regmap::mag_image::{emit, parse};
//! let image = emit([100, -1, 8333]);
//! assert_eq!(image, [100, 0, 0xFF, 0xFF, 0x8D, 0x20]);
//! assert_eq!(parse(&image), [100, -1, 8333]);
//! ```

/// Bytes of one image.
pub const IMAGE_LEN: usize = 6;

/// The image (the data registers' bytes) of raw x, y, z values.
pub fn emit(raw: [i16; 3]) -> [u8; IMAGE_LEN] {
    let [x, y, z] = raw.map(i16::to_le_bytes);
    [x[0], x[1], y[0], y[1], z[0], z[1]]
}

/// The raw x, y, z values of an image.
pub fn parse(image: &[u8; IMAGE_LEN]) -> [i16; 3] {
    let [x0, x1, y0, y1, z0, z1] = *image;
    [
        i16::from_le_bytes([x0, x1]),
        i16::from_le_bytes([y0, y1]),
        i16::from_le_bytes([z0, z1]),
    ]
}
