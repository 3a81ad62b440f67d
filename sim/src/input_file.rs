//! Input files are opened only when they are regular files, and read with a bound:
//! - files read whole (a scene, its CSV joint sources, parameter files, `meta.toml`): [`read`],
//!   no larger than [`MAX_INPUT_BYTES`];
//! - files streamed row by row, which may be far larger (recordings, run and session CSVs read by
//!   `evaluate`, `filter`, `analyze`): [`open_stream`], whose lines may not exceed
//!   [`MAX_LINE_BYTES`], so memory stays bounded whatever the file holds.
//!
//! The file type is checked from its metadata before anything opens it, so a FIFO, a device such
//! as `/dev/zero` or a directory is refused at once instead of blocking or growing without end.
//! Reads stop after the bound even if the file grows between the check and the read.

use std::io::Read;
use std::path::{Path, PathBuf};

/// The largest input file read (256 MiB): far beyond any scene or joint-source CSV, small enough
/// that reading one never exhausts memory.
pub const MAX_INPUT_BYTES: u64 = 256 << 20;

/// The longest line a streamed input may hold (1 MiB): a CSV row of margemu's widest file is
/// under 1 KiB.
pub const MAX_LINE_BYTES: usize = 1 << 20;

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

/// Checks that `path` is a regular file, without opening it; returns its size.
fn check_regular(path: &Path) -> Result<u64, InputFileError> {
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
    Ok(meta.len())
}

/// Opens `path` to be read as a stream of lines: a regular file, of any size, whose lines are at
/// most [`MAX_LINE_BYTES`] long (a longer one fails the read with
/// [`std::io::ErrorKind::InvalidData`], saying so).
pub fn open_stream(path: &Path) -> Result<LineBounded<std::fs::File>, InputFileError> {
    check_regular(path)?;
    let file = std::fs::File::open(path).map_err(|cause| InputFileError::Io {
        path: path.to_path_buf(),
        cause,
    })?;
    Ok(LineBounded {
        inner: file,
        run: 0,
    })
}

/// A reader that fails once more than [`MAX_LINE_BYTES`] bytes pass without a line break.
pub struct LineBounded<R> {
    inner: R,
    /// Bytes since the last `\n`.
    run: usize,
}

impl<R: Read> Read for LineBounded<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        let read = &buf[..n];
        self.run = match read.iter().rposition(|&b| b == b'\n') {
            Some(last) => read.len() - last - 1,
            None => self.run + read.len(),
        };
        if self.run > MAX_LINE_BYTES {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "a line is longer than {MAX_LINE_BYTES} bytes: not a CSV file margemu reads"
                ),
            ));
        }
        Ok(n)
    }
}

/// Checks that `path` is a regular file within the size bound, without opening it; returns its
/// size.
pub fn check(path: &Path) -> Result<u64, InputFileError> {
    let len = check_regular(path)?;
    if len > MAX_INPUT_BYTES {
        return Err(InputFileError::TooLarge {
            path: path.to_path_buf(),
            size: len,
            limit: MAX_INPUT_BYTES,
        });
    }
    Ok(len)
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

/// [`read`] as text: the whole of `path`, bounded, which must be UTF-8.
pub fn read_to_string(path: &Path) -> Result<String, InputFileError> {
    String::from_utf8(read(path)?).map_err(|e| InputFileError::Io {
        path: path.to_path_buf(),
        cause: std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("not UTF-8 from byte {}", e.utf8_error().valid_up_to()),
        ),
    })
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
        let e = open_stream(Path::new("/dev/zero"))
            .err()
            .unwrap()
            .to_string();
        assert_eq!(e, "/dev/zero: is a character device, not a regular file");
    }

    #[test]
    fn a_stream_fails_at_a_line_longer_than_the_bound() {
        let read_all = |bytes: Vec<u8>| {
            let mut r = LineBounded {
                inner: &bytes[..],
                run: 0,
            };
            let mut out = Vec::new();
            r.read_to_end(&mut out).map(|_| out.len())
        };
        let mut ok = vec![b'x'; MAX_LINE_BYTES];
        ok.push(b'\n');
        ok.extend(vec![b'y'; MAX_LINE_BYTES]);
        assert_eq!(read_all(ok).unwrap(), 2 * MAX_LINE_BYTES + 1);
        let e = read_all(vec![0; MAX_LINE_BYTES + 1]).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidData);
        assert!(
            e.to_string()
                .contains("a line is longer than 1048576 bytes"),
            "{e}"
        );
    }
}
