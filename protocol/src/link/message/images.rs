//! [`ImageBatch`]: register images of the configured chip's length, host → device (source mode
//! (a)). Unlike the other batches, its items have no fixed size: the batch carries their length.
//!
//! ```
//! use margemu_protocol::link::{Image, ImageBatch, Message};
//! let images = [Image::from([1u8; 22]), Image::from([2u8; 22])];
//! let mut payload = [0u8; 9 + 2 * 22];
//! Message::Images(ImageBatch::new(40, &images)).emit(&mut payload)?;
//! let Message::Images(batch) = Message::parse(0x10, &payload)? else { unreachable!() };
//! assert_eq!((batch.first_index, batch.images.image_len()), (40, 22));
//! assert_eq!(batch.images.get(1), Some(Image::from([2u8; 22])));
//! # Ok::<(), margemu_protocol::link::Error>(())
//! ```

use core::fmt;

use crate::link::wire::{Reader, Writer};
use crate::link::{Error, MAX_PAYLOAD_LEN};

/// One finished register image, laid out by its chip's module (the link carries it as opaque
/// bytes of the configured model's [`image_len`](crate::chip::ChipModel::image_len)).
pub use crate::chip::{Image, MAX_IMAGE_LEN};

/// Most images of `image_len` bytes (at least 1) in one [`ImageBatch`].
pub const fn max_images_per_batch(image_len: usize) -> usize {
    (MAX_PAYLOAD_LEN - IMAGE_BATCH_HEADER_LEN) / if image_len == 0 { 1 } else { image_len }
}

/// Bytes of an [`ImageBatch`] before its images: the first index and the image length.
pub const IMAGE_BATCH_HEADER_LEN: usize = 9;

/// Host → device: finished register images for consecutive samples, all of one length.
///
/// Payload: `first_index` (u64), the image length (u8; 0 only when there is no image), then the
/// images back to back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageBatch<'a> {
    /// Index of the first image; image `k` is sample `first_index + k`.
    pub first_index: u64,
    /// The images, at most [`max_images_per_batch`] of their length.
    pub images: ImageItems<'a>,
}

/// The images of an [`ImageBatch`]: the caller's slice, or a validated payload region.
#[derive(Clone, Copy)]
pub struct ImageItems<'a> {
    repr: ImagesRepr<'a>,
}

#[derive(Clone, Copy)]
enum ImagesRepr<'a> {
    Values(&'a [Image]),
    Wire { image_len: usize, bytes: &'a [u8] },
}

impl<'a> ImageItems<'a> {
    /// Images to emit.
    pub const fn from_slice(images: &'a [Image]) -> Self {
        Self {
            repr: ImagesRepr::Values(images),
        }
    }

    /// Bytes per image (0 when there is none).
    pub fn image_len(&self) -> usize {
        match self.repr {
            ImagesRepr::Values(v) => v.first().map_or(0, |i| i.len()),
            ImagesRepr::Wire { image_len, .. } => image_len,
        }
    }

    /// The number of images.
    pub fn len(&self) -> usize {
        match self.repr {
            ImagesRepr::Values(v) => v.len(),
            ImagesRepr::Wire { image_len, bytes } => {
                bytes.len().checked_div(image_len).unwrap_or(0)
            }
        }
    }

    /// Whether there is no image.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Image `i`.
    pub fn get(&self, i: usize) -> Option<Image> {
        match self.repr {
            ImagesRepr::Values(v) => v.get(i).copied(),
            ImagesRepr::Wire { image_len, bytes } => {
                let at = i.checked_mul(image_len)?;
                Image::new(bytes.get(at..at.checked_add(image_len)?)?)
            }
        }
    }

    /// The images, in order.
    pub fn iter(&self) -> impl Iterator<Item = Image> + 'a {
        let items = *self;
        (0..self.len()).filter_map(move |i| items.get(i))
    }

    fn buffer_len(&self) -> usize {
        1 + self.len() * self.image_len()
    }

    fn parse(r: &mut Reader<'a>) -> Result<Self, Error> {
        let image_len = usize::from(r.u8()?);
        let bytes = r.bytes(r.remaining().len())?;
        if image_len > MAX_IMAGE_LEN || (image_len == 0 && !bytes.is_empty()) {
            return Err(Error::InvalidValue);
        }
        if image_len != 0 && bytes.len() % image_len != 0 {
            return Err(Error::PayloadTooLong);
        }
        Ok(Self {
            repr: ImagesRepr::Wire { image_len, bytes },
        })
    }

    fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        let image_len = self.image_len();
        // Length 0 means "no image": images of no bytes would be read back as none.
        if image_len == 0 && !self.is_empty() {
            return Err(Error::InvalidValue);
        }
        // image_len ≤ MAX_IMAGE_LEN (64) by construction of `Image`.
        w.u8(image_len as u8)?;
        match self.repr {
            ImagesRepr::Values(v) => v.iter().try_for_each(|image| {
                if image.len() == image_len {
                    w.bytes(image)
                } else {
                    Err(Error::InvalidValue)
                }
            }),
            ImagesRepr::Wire { bytes, .. } => w.bytes(bytes),
        }
    }
}

impl PartialEq for ImageItems<'_> {
    fn eq(&self, other: &Self) -> bool {
        self.len() == other.len() && self.iter().eq(other.iter())
    }
}

impl fmt::Debug for ImageItems<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

impl<'a> ImageBatch<'a> {
    /// A batch of `images` (all of one length) starting at sample `first_index`.
    pub const fn new(first_index: u64, images: &'a [Image]) -> Self {
        Self {
            first_index,
            images: ImageItems::from_slice(images),
        }
    }
    pub(crate) fn parse(r: &mut Reader<'a>) -> Result<Self, Error> {
        let first_index = r.u64()?;
        let images = ImageItems::parse(r)?;
        Ok(Self {
            first_index,
            images,
        })
    }
    pub(crate) fn emit(&self, w: &mut Writer<'_>) -> Result<(), Error> {
        w.u64(self.first_index)?;
        self.images.emit(w)
    }
    pub(crate) fn buffer_len(&self) -> usize {
        8 + self.images.buffer_len()
    }
}
