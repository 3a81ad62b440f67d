//! Allan deviation and PSD drawn one above the other, to PNG or SVG (chosen by extension).
//!
//! Text is rendered with `plotters`' `ab_glyph` backend from a TrueType font found on the
//! system (DejaVu Sans from Debian's `fonts-dejavu-core`, or `$MARGEMU_FONT`), so nothing links
//! against fontconfig.

use super::allan::AllanPoint;
use super::psd::Psd;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// A plot that could not be drawn.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum PlotError {
    /// no TrueType font found (looked at $MARGEMU_FONT and {tried}); install fonts-dejavu-core
    NoFont {
        /// Paths looked at.
        tried: String,
    },
    /// {path}: the plot format is chosen by the extension: .png or .svg
    UnknownFormat {
        /// The requested path.
        path: PathBuf,
    },
    /// {path}: {reason}
    Draw {
        /// The output.
        path: PathBuf,
        /// What failed.
        reason: String,
    },
}

const FONT_PATHS: [&str; 4] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
];

/// Registers a system font as `sans-serif` once per process.
pub(crate) fn ensure_font() -> Result<(), PlotError> {
    use std::sync::OnceLock;
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        let candidates = std::env::var("MARGEMU_FONT")
            .into_iter()
            .chain(FONT_PATHS.iter().map(|s| s.to_string()));
        for path in candidates {
            if let Ok(bytes) = std::fs::read(&path) {
                let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
                if plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_ok() {
                    return true;
                }
            }
        }
        false
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError::NoFont {
            tried: FONT_PATHS.join(", "),
        })
    }
}

/// Draws the Allan deviation and the PSD of `name` to `path` (.png or .svg).
pub fn noise(path: &Path, name: &str, allan: &[AllanPoint], psd: &Psd) -> Result<(), PlotError> {
    render(path, (900, 900), &Noise { name, allan, psd })
}

/// A figure that draws itself onto any `plotters` backend.
pub(crate) trait Figure {
    /// Draws onto `root`.
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB>;
}

/// Draws `figure` to `path`, PNG or SVG by the extension, `size` pixels.
pub(crate) fn render(path: &Path, size: (u32, u32), figure: &impl Figure) -> Result<(), PlotError> {
    ensure_font()?;
    let fail = |e: String| PlotError::Draw {
        path: path.to_path_buf(),
        reason: e,
    };
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("png") => {
            let root = BitMapBackend::new(path, size).into_drawing_area();
            figure.draw(&root).map_err(|e| fail(e.to_string()))?;
            root.present().map_err(|e| fail(e.to_string()))
        }
        Some("svg") => {
            let root = SVGBackend::new(path, size).into_drawing_area();
            figure.draw(&root).map_err(|e| fail(e.to_string()))?;
            root.present().map_err(|e| fail(e.to_string()))
        }
        _ => Err(PlotError::UnknownFormat {
            path: path.to_path_buf(),
        }),
    }
}

/// The result of drawing on a backend.
pub(crate) type DrawResult<DB> =
    Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

struct Noise<'a> {
    name: &'a str,
    allan: &'a [AllanPoint],
    psd: &'a Psd,
}

impl Figure for Noise<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        draw(root, self.name, self.allan, self.psd)
    }
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    name: &str,
    allan: &[AllanPoint],
    psd: &Psd,
) -> DrawResult<DB> {
    root.fill(&WHITE)?;
    let (top, bottom) = root.split_vertically(450);
    let range = |vals: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = vals
            .filter(|v| *v > 0.0 && v.is_finite())
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        if lo.is_finite() {
            (lo / 1.5, hi * 1.5)
        } else {
            (1e-12, 1.0)
        }
    };
    let (t_lo, t_hi) = range(&mut allan.iter().map(|p| p.tau));
    let (a_lo, a_hi) = range(&mut allan.iter().map(|p| p.adev));
    let mut chart = ChartBuilder::on(&top)
        .caption(
            format!("{name}: overlapping Allan deviation"),
            ("sans-serif", 22),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d((t_lo..t_hi).log_scale(), (a_lo..a_hi).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("τ (s)")
        .y_desc("σ(τ)")
        .draw()?;
    chart.draw_series(LineSeries::new(
        allan.iter().map(|p| (p.tau, p.adev)),
        &BLUE,
    ))?;
    let points: Vec<(f64, f64)> = psd
        .frequency
        .iter()
        .zip(&psd.density)
        .skip(1)
        .map(|(f, d)| (*f, *d))
        .filter(|(_, d)| *d > 0.0)
        .collect();
    let (f_lo, f_hi) = range(&mut points.iter().map(|p| p.0));
    let (d_lo, d_hi) = range(&mut points.iter().map(|p| p.1));
    let mut chart = ChartBuilder::on(&bottom)
        .caption(format!("{name}: one-sided PSD (Welch)"), ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d((f_lo..f_hi).log_scale(), (d_lo..d_hi).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("f (Hz)")
        .y_desc("unit²/Hz")
        .draw()?;
    chart.draw_series(LineSeries::new(points, &RED))?;
    Ok(())
}
