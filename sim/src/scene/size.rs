//! How big a scene's run is, and the limit commands hold it to.
//!
//! [`estimate`] counts the output samples and estimates the bytes of the per-sample files from
//! their row widths: each row is the time stamp (the digits of the last instant), then per
//! value a comma and [`F64_CHARS`] characters for an `f64` (`truth.csv`) or [`F32_CHARS`] for an
//! `f32` (`marg.csv`, `perturbation.csv`), then a newline. Values are written in shortest
//! round-trip form, which at full precision takes about that width; zeros (a plate at rest)
//! take less, so the estimate is an upper one (measured: 3–10 % above the files of the
//! fixture scenes in motion). `meta.toml` is the scene text plus [`META_BYTES`]. A streaming
//! session logs the same samples in files of the same order.
//!
//! [`check`] refuses a run of more than [`MAX_SAMPLES`] samples or [`MAX_OUTPUT_BYTES`] of
//! estimated output, unless the caller allows large runs (`--allow-large` on `simulate`,
//! `loopback` and `stream`).

use super::Scene;
use crate::marg::{MARG_COLUMNS, PERTURBATION_COLUMNS};
use crate::output::TRUTH_COLUMNS;
use std::fmt;

/// Most output samples a run may have without `--allow-large` (10 M: 2.8 h at 1 kHz).
pub const MAX_SAMPLES: u64 = 10_000_000;
/// Most estimated output a run may write without `--allow-large` (2 GiB).
pub const MAX_OUTPUT_BYTES: u64 = 2 << 30;
/// Characters an `f64` takes in shortest round-trip form at full precision, with its sign.
pub const F64_CHARS: u64 = 20;
/// Characters an `f32` takes in shortest round-trip form at full precision, with its sign.
pub const F32_CHARS: u64 = 11;
/// `meta.toml` beyond the scene text it embeds.
pub const META_BYTES: u64 = 4096;

/// The estimated size of one output file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FileSize {
    /// File name in the run directory.
    pub name: &'static str,
    /// Rows (header included).
    pub rows: u64,
    /// Estimated bytes.
    pub bytes: u64,
}

/// A run's size: samples and estimated output.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RunSize {
    /// Output samples.
    pub samples: u64,
    /// Estimated size per file.
    pub files: Vec<FileSize>,
}

impl RunSize {
    /// Estimated bytes of all files.
    pub fn total_bytes(&self) -> u64 {
        self.files
            .iter()
            .fold(0u64, |sum, f| sum.saturating_add(f.bytes))
    }

    /// Whether the run is beyond [`MAX_SAMPLES`] or [`MAX_OUTPUT_BYTES`].
    pub fn is_large(&self) -> bool {
        self.samples > MAX_SAMPLES || self.total_bytes() > MAX_OUTPUT_BYTES
    }
}

impl fmt::Display for RunSize {
    /// `N samples, about B of output (truth.csv B, marg.csv B, ...)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} samples, about {} of output (",
            self.samples,
            bytes(self.total_bytes())
        )?;
        for (i, file) in self.files.iter().enumerate() {
            let sep = if i == 0 { "" } else { ", " };
            write!(f, "{sep}{} {}", file.name, bytes(file.bytes))?;
        }
        write!(f, ")")
    }
}

// A run refused for its size (the doc comment is the message).
#[derive(Debug, thiserror::Error, docsplay::Display)]
/// the run is too large: {size}; the limit is {max_samples} samples and {max_output} of output without --allow-large (pass --allow-large to run it anyway)
pub struct TooLarge {
    /// The run's size.
    pub size: RunSize,
    /// [`MAX_SAMPLES`].
    pub max_samples: u64,
    /// [`MAX_OUTPUT_BYTES`], as text.
    pub max_output: String,
}

/// The size of `scene`'s run (see the module documentation for the estimate).
pub fn estimate(scene: &Scene) -> RunSize {
    let samples = scene.samples();
    let last = scene.clock.instant(samples.saturating_sub(1));
    let stamp = last.checked_ilog10().map_or(1, |d| d as u64 + 1);
    let csv = |name: &'static str, columns: &[&str], chars: u64| {
        let header = columns.join(",").len() as u64 + 1;
        let row = stamp + (columns.len() as u64 - 1) * (chars + 1) + 1;
        FileSize {
            name,
            rows: samples.saturating_add(1),
            bytes: row.saturating_mul(samples).saturating_add(header),
        }
    };
    let mut files = vec![
        FileSize {
            name: "meta.toml",
            rows: 0,
            bytes: scene.text.len() as u64 + META_BYTES,
        },
        csv("truth.csv", &TRUTH_COLUMNS, F64_CHARS),
        csv("marg.csv", &MARG_COLUMNS, F32_CHARS),
    ];
    if scene.spec.perturbation.is_some() {
        files.push(csv("perturbation.csv", &PERTURBATION_COLUMNS, F32_CHARS));
    }
    RunSize { samples, files }
}

/// The size of `scene`'s run, refused beyond [`MAX_SAMPLES`] or [`MAX_OUTPUT_BYTES`] unless
/// `allow_large`. Every command that runs a scene calls this before it allocates or writes.
pub fn check(scene: &Scene, allow_large: bool) -> Result<RunSize, Box<TooLarge>> {
    let size = estimate(scene);
    if size.is_large() && !allow_large {
        return Err(Box::new(TooLarge {
            size,
            max_samples: MAX_SAMPLES,
            max_output: bytes(MAX_OUTPUT_BYTES),
        }));
    }
    Ok(size)
}

/// Bytes in binary units: `512 B`, `1.5 KiB`, `2.0 GiB`.
pub fn bytes(n: u64) -> String {
    const UNITS: [&str; 6] = ["KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    if n < 1024 {
        return format!("{n} B");
    }
    let mut value = n as f64 / 1024.0;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < UNITS.len() {
        value /= 1024.0;
        unit += 1;
    }
    format!("{value:.1} {}", UNITS[unit])
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn scene(text: &str) -> Scene {
        Scene::parse_str(text, Path::new("size.toml")).unwrap()
    }

    #[test]
    fn rows_are_estimated_from_their_widths() {
        let s = scene("duration = 1.0\nrate = 100.0\nseed = 1\n");
        let size = estimate(&s);
        assert_eq!(size.samples, 100);
        // Last instant 990 000 000 ns: 9 digits; 31 f64 of 21 characters; newline.
        let truth = &size.files[1];
        assert_eq!(truth.name, "truth.csv");
        let header = TRUTH_COLUMNS.join(",").len() as u64 + 1;
        assert_eq!(truth.bytes, 100 * (9 + 31 * 21 + 1) + header);
        let marg = &size.files[2];
        let header = MARG_COLUMNS.join(",").len() as u64 + 1;
        assert_eq!(marg.bytes, 100 * (9 + 9 * 12 + 1) + header);
        assert_eq!(
            size.files.len(),
            3,
            "no perturbation.csv without [perturbation]"
        );
        assert!(!size.is_large());
    }

    #[test]
    fn large_runs_are_refused_unless_allowed() {
        // 10⁵ s at 1 kHz: 10⁸ samples, far beyond both limits.
        let s = scene("duration = 1e5\nrate = 1000.0\nseed = 1\nmotion = \"static\"\n");
        let e = check(&s, false).unwrap_err().to_string();
        assert!(
            e.starts_with("the run is too large: 100000000 samples, about 7"),
            "{e}"
        );
        assert!(
            e.ends_with(
                "; the limit is 10000000 samples and 2.0 GiB of output without --allow-large \
                 (pass --allow-large to run it anyway)"
            ),
            "{e}"
        );
        assert_eq!(check(&s, true).unwrap().samples, 100_000_000);
        assert_eq!(bytes(1536), "1.5 KiB");
        assert_eq!(bytes(2 << 30), "2.0 GiB");
    }
}
