//! Files a scene reads (the scene itself and its CSV joint sources) are opened only when they are
//! regular files no larger than [`MAX_INPUT_BYTES`].
//!
//! The file type is checked from its metadata before anything opens it, so a FIFO, a device such
//! as `/dev/zero` or a directory is refused at once instead of blocking or growing without end.
//! Reads stop after the bound even if the file grows between the check and the read.

use std::io::Read;
use std::path::{Path, PathBuf};

/// The largest input file read (256 MiB): far beyond any scene or joint-source CSV, small enough
/// that reading one never exhausts memory.
pub const MAX_INPUT_BYTES: u64 = 256 << 20;

/// An input file that was not read.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum InputFileError {
    /// {path}: cannot read: {cause}
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error (its text is part of the message).
        cause: std::io::Error,
    },
    /// {path}: is {kind}, not a regular file
    NotRegular {
        /// The file.
        path: PathBuf,
        /// What it is instead: "a directory", "a FIFO", "a character device", ...
        kind: &'static str,
    },
    /// {path}: is {size} bytes, more than the {limit}-byte limit on input files
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Its size (or the bytes read before the limit stopped the read).
        size: u64,
        /// [`MAX_INPUT_BYTES`].
        limit: u64,
    },
}

impl InputFileError {
    /// The message without the leading path (for errors that name the file themselves).
    pub fn reason(&self) -> String {
        let path = match self {
            Self::Io { path, .. } | Self::NotRegular { path, .. } | Self::TooLarge { path, .. } => {
                path
            }
        };
        let message = self.to_string();
        let prefix = format!("{}: ", path.display());
        message
            .strip_prefix(&prefix)
            .map_or_else(|| message.clone(), str::to_owned)
    }
}

/// Checks that `path` is a regular file within the size bound, without opening it; returns its
/// size.
pub fn check(path: &Path) -> Result<u64, InputFileError> {
    let meta = std::fs::metadata(path).map_err(|cause| InputFileError::Io {
        path: path.to_path_buf(),
        cause,
    })?;
    if !meta.is_file() {
        return Err(InputFileError::NotRegular {
            path: path.to_path_buf(),
            kind: kind_of(&meta.file_type()),
        });
    }
    if meta.len() > MAX_INPUT_BYTES {
        return Err(InputFileError::TooLarge {
            path: path.to_path_buf(),
            size: meta.len(),
            limit: MAX_INPUT_BYTES,
        });
    }
    Ok(meta.len())
}

/// Reads the whole of `path` after [`check`], never more than [`MAX_INPUT_BYTES`].
pub fn read(path: &Path) -> Result<Vec<u8>, InputFileError> {
    let size = check(path)?;
    let io = |cause| InputFileError::Io {
        path: path.to_path_buf(),
        cause,
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let mut bytes = Vec::with_capacity(size as usize);
    file.take(MAX_INPUT_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_INPUT_BYTES {
        return Err(InputFileError::TooLarge {
            path: path.to_path_buf(),
            size: bytes.len() as u64,
            limit: MAX_INPUT_BYTES,
        });
    }
    Ok(bytes)
}

fn kind_of(t: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    if t.is_dir() {
        "a directory"
    } else if t.is_fifo() {
        "a FIFO"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "a special file"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn devices_and_directories_are_refused_by_type() {
        let e = check(Path::new("/dev/zero")).unwrap_err().to_string();
        assert_eq!(e, "/dev/zero: is a character device, not a regular file");
        let e = read(Path::new("/")).unwrap_err().to_string();
        assert_eq!(e, "/: is a directory, not a regular file");
        let e = check(Path::new("/nonexistent/x.csv"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("/nonexistent/x.csv: cannot read: "), "{e}");
    }
}
