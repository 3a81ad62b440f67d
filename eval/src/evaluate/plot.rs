//! The figures of an evaluation, as the paper's Figures 8–10 draw them, in PNG and SVG:
//!
//! - `attitude.{png,svg}`: five rows sharing the time axis: roll, pitch and yaw of the truth
//!   (blue) and of the estimate (red), in degrees; the accelerometer norm; the magnetometer norm.
//!   Static phases are shaded grey and magnetic perturbations pink on every row.
//! - `alignment.{png,svg}`: the mean squared geodesic error against the lag tried, with the lag
//!   found.
//!
//! Long series come thinned ([`super::thin`]): the lowest and highest point of each of about
//! 2000 time buckets, so spikes survive; angle curves are broken where they wrap at ±180°.

use super::phase::Phase;
use super::run::Evaluation;
use crate::analysis::plot::{render, DrawResult, Figure, PlotError};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

const TRUTH: RGBColor = RGBColor(31, 90, 200);
const ESTIMATE: RGBColor = RGBColor(215, 40, 40);
const STATIC_SHADE: RGBColor = RGBColor(225, 225, 225);
const MAGNETIC_SHADE: RGBColor = RGBColor(255, 215, 225);

/// Writes the figures into `dir`; returns the files written.
pub fn write(eval: &Evaluation, dir: &Path) -> Result<Vec<PathBuf>, PlotError> {
    let mut written = Vec::new();
    for ext in ["png", "svg"] {
        let path = dir.join(format!("attitude.{ext}"));
        render(&path, (1200, 1400), &Attitude(eval))?;
        written.push(path);
        if eval.latency.is_some() {
            let path = dir.join(format!("alignment.{ext}"));
            render(&path, (900, 450), &Alignment(eval))?;
            written.push(path);
        }
    }
    Ok(written)
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
        (l.min(v), h.max(v))
    });
    if !lo.is_finite() {
        return (-1.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-3);
    (lo - pad, hi + pad)
}

/// A curve in pieces, its colour and its legend label (empty: none).
type Curve<'a> = (&'a [Vec<(f64, f64)>], RGBColor, &'a str);

struct Attitude<'a>(&'a Evaluation);

impl Attitude<'_> {
    fn panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        label: &str,
        x: (f64, f64),
        series: &[Curve<'_>],
    ) -> DrawResult<DB> {
        let (y_lo, y_hi) = range(
            series
                .iter()
                .flat_map(|s| s.0.iter().flatten().map(|p| p.1)),
        );
        let mut chart = ChartBuilder::on(area)
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(70)
            .build_cartesian_2d(x.0..x.1, y_lo..y_hi)?;
        chart
            .configure_mesh()
            .y_desc(label)
            .x_desc("t (s)")
            .draw()?;
        for &(phase, a, b) in &self.0.traces.phases {
            let shade = match phase {
                Phase::Static => STATIC_SHADE,
                Phase::Magnetic => MAGNETIC_SHADE,
                Phase::Dynamic => continue,
            };
            chart.draw_series(std::iter::once(Rectangle::new(
                [(a, y_lo), (b, y_hi)],
                shade.filled(),
            )))?;
        }
        for (pieces, color, name) in series {
            for (i, piece) in pieces.iter().enumerate() {
                let drawn = chart.draw_series(LineSeries::new(piece.iter().copied(), color))?;
                if i == 0 && !name.is_empty() {
                    let c = *color;
                    drawn
                        .label(*name)
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
                }
            }
        }
        if series.len() > 1 {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()?;
        }
        Ok(())
    }
}

impl Figure for Attitude<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let eval = self.0;
        root.fill(&WHITE)?;
        let traces = &eval.traces;
        let x = range([traces.span_s.0, traces.span_s.1].into_iter());
        let rows = root.split_evenly((5, 1));
        let names = ["roll (°)", "pitch (°)", "yaw (°)"];
        for (i, name) in names.iter().enumerate() {
            self.panel(
                &rows[i],
                name,
                x,
                &[
                    (&traces.truth[i], TRUTH, "truth"),
                    (&traces.estimate[i], ESTIMATE, "estimate"),
                ],
            )?;
        }
        let n = &eval.norms;
        self.panel(
            &rows[3],
            "|accelerometer| (m/s²)",
            x,
            &[(&n.acc.pieces(), BLACK, "")],
        )?;
        self.panel(
            &rows[4],
            "|magnetometer|",
            x,
            &[(&n.mag.pieces(), BLACK, "")],
        )
    }
}

struct Alignment<'a>(&'a Evaluation);

impl Figure for Alignment<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        root.fill(&WHITE)?;
        let Some(latency) = &self.0.latency else {
            return Ok(());
        };
        let points: Vec<(f64, f64)> = latency
            .curve
            .iter()
            .map(|&(lag, c)| (lag as f64 * 1e-6, c.max(1e-30)))
            .collect();
        let x = range(points.iter().map(|p| p.0));
        let (lo, hi) = points.iter().fold((f64::INFINITY, 0.0f64), |(l, h), p| {
            (l.min(p.1), h.max(p.1))
        });
        let mut chart = ChartBuilder::on(root)
            .caption(
                format!("alignment: lag {:.3} ms", latency.lag_ns as f64 * 1e-6),
                ("sans-serif", 20),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(80)
            .build_cartesian_2d(x.0..x.1, (lo / 2.0..hi * 2.0).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("lag (ms)")
            .y_desc("mean geodesic² (rad²)")
            .draw()?;
        chart.draw_series(LineSeries::new(points, &TRUTH))?;
        let lag = latency.lag_ns as f64 * 1e-6;
        chart.draw_series(LineSeries::new(
            [(lag, lo / 2.0), (lag, hi * 2.0)],
            &ESTIMATE,
        ))?;
        Ok(())
    }
}
