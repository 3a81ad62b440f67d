//! Scores per fault window: the attitude error inside each window of the scene's fault schedule
//! and the time the estimator takes to recover after it.
//!
//! The windows come from the `fault` rows of the directory's `events.csv`
//! ([`margemu_sim::fault_log`]: a session's, or a `simulate` run's); a directory without one
//! has none. Per window, over the scored instants (aligned, after the warm-up, as every other
//! figure):
//!
//! - **before**: the geodesic RMS of every scored instant before the window's start;
//! - **inside**: the geodesic RMS and maximum over `[start, end)`;
//! - **recovery**: the threshold is [`FaultOptions::threshold_rad`] when given, else
//!   `max(factor × before, floor)` ([`FaultOptions::factor`], default 2; [`FaultOptions::floor_rad`],
//!   default 1°; the floor alone when nothing was scored before). The estimator has recovered
//!   at the first scored instant `t ≥ end` from which the error stays below the threshold for
//!   [`FaultOptions::hold_ns`] (default 0.5 s) of scored instants; the time to recover is
//!   `t − end`. `None` when that never happens before the scores end (or the window lasts
//!   until the end).
//!
//! `faults.csv` (one row per window):
//! `device,kind,sensor,start_s,end_s,n_inside,rms_before,rms_inside,max_inside,threshold,recovery_s`,
//! angles in rad, empty cells where a figure has no instant (`end_s` empty: until the end).

use super::run::EvalError;
use margemu_sim::fault_log::{read_rows, FaultRow, EVENTS_FILE};
use std::fmt::Write as _;
use std::path::Path;

/// `faults.csv`.
pub const FAULTS_FILE: &str = "faults.csv";

/// The columns of `faults.csv`.
pub const FAULTS_HEADER: &str =
    "device,kind,sensor,start_s,end_s,n_inside,rms_before,rms_inside,max_inside,threshold,recovery_s";

/// How recovery is judged (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaultOptions {
    /// Threshold = this × the RMS before the window.
    pub factor: f64,
    /// Smallest threshold (rad).
    pub floor_rad: f64,
    /// A fixed threshold (rad) instead.
    pub threshold_rad: Option<f64>,
    /// How long the error must stay below the threshold (ns).
    pub hold_ns: u64,
}

impl Default for FaultOptions {
    fn default() -> Self {
        Self {
            factor: 2.0,
            floor_rad: 1f64.to_radians(),
            threshold_rad: None,
            hold_ns: 500_000_000,
        }
    }
}

/// What one window's scores are.
#[derive(Clone, Debug, PartialEq)]
pub struct FaultScore {
    /// The window, as `events.csv` lists it.
    pub window: FaultRow,
    /// Scored instants inside.
    pub n_inside: usize,
    /// Geodesic RMS before the window (rad).
    pub rms_before: Option<f64>,
    /// Geodesic RMS inside (rad).
    pub rms_inside: Option<f64>,
    /// Geodesic maximum inside (rad).
    pub max_inside: Option<f64>,
    /// The recovery threshold (rad), once the window has ended.
    pub threshold: Option<f64>,
    /// Time to recover after the end (s).
    pub recovery_s: Option<f64>,
}

/// One window being scored.
#[derive(Clone, Debug)]
struct State {
    row: FaultRow,
    before: (f64, usize),
    inside: (f64, usize, f64),
    threshold: Option<f64>,
    /// Since when the error has stayed below the threshold.
    below_since: Option<u64>,
    recovered_at: Option<u64>,
}

/// Scores every window from the scored instants, in time order.
#[derive(Clone, Debug, Default)]
pub struct FaultScorer {
    options: FaultOptions,
    windows: Vec<State>,
}

fn rms((sum, n): (f64, usize)) -> Option<f64> {
    (n > 0).then(|| (sum / n as f64).sqrt())
}

impl FaultScorer {
    /// The windows of `rows`.
    pub fn new(rows: Vec<FaultRow>, options: FaultOptions) -> Self {
        let windows = rows
            .into_iter()
            .map(|row| State {
                row,
                before: (0.0, 0),
                inside: (0.0, 0, 0.0),
                threshold: None,
                below_since: None,
                recovered_at: None,
            })
            .collect();
        Self { options, windows }
    }

    /// The windows of the `events.csv` in `dir` (none without one).
    pub fn from_dir(dir: &Path, options: FaultOptions) -> Result<Self, EvalError> {
        let path = dir.join(EVENTS_FILE);
        let rows = match std::fs::read_to_string(&path) {
            Ok(text) => read_rows(&text).map_err(|reason| EvalError::Input {
                path: path.clone(),
                reason,
            })?,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
            Err(e) => {
                return Err(EvalError::Input {
                    path,
                    reason: e.to_string(),
                })
            }
        };
        Ok(Self::new(rows, options))
    }

    /// Whether there is any window.
    pub fn is_empty(&self) -> bool {
        self.windows.is_empty()
    }

    /// One scored instant: its aligned time and geodesic error (rad).
    pub fn add(&mut self, t_ns: u64, geodesic: f64) {
        let o = self.options;
        for w in &mut self.windows {
            let (start, end) = (w.row.start_ns, w.row.end_ns.unwrap_or(u64::MAX));
            if t_ns < start {
                w.before.0 += geodesic * geodesic;
                w.before.1 += 1;
            } else if t_ns < end {
                w.inside.0 += geodesic * geodesic;
                w.inside.1 += 1;
                w.inside.2 = w.inside.2.max(geodesic);
            } else if w.recovered_at.is_none() {
                let threshold = *w.threshold.get_or_insert_with(|| {
                    o.threshold_rad.unwrap_or_else(|| {
                        rms(w.before).map_or(o.floor_rad, |r| (o.factor * r).max(o.floor_rad))
                    })
                });
                if geodesic < threshold {
                    let since = *w.below_since.get_or_insert(t_ns);
                    if t_ns - since >= o.hold_ns {
                        w.recovered_at = Some(since);
                    }
                } else {
                    w.below_since = None;
                }
            }
        }
    }

    /// The scores of every window, in schedule order.
    pub fn finish(self) -> Vec<FaultScore> {
        self.windows
            .into_iter()
            .map(|w| FaultScore {
                n_inside: w.inside.1,
                rms_before: rms(w.before),
                rms_inside: rms((w.inside.0, w.inside.1)),
                max_inside: (w.inside.1 > 0).then_some(w.inside.2),
                threshold: w.threshold,
                recovery_s: match (w.recovered_at, w.row.end_ns) {
                    (Some(t), Some(end)) => Some(secs(t.saturating_sub(end))),
                    _ => None,
                },
                window: w.row,
            })
            .collect()
    }
}

fn secs(ns: u64) -> f64 {
    ns as f64 / 1e9
}

fn opt(v: Option<f64>) -> String {
    v.map_or(String::new(), |x| x.to_string())
}

/// `faults.csv`'s text.
pub fn csv(scores: &[FaultScore]) -> String {
    let mut out = format!("{FAULTS_HEADER}\n");
    for s in scores {
        let w = &s.window;
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{}",
            w.device,
            w.kind,
            w.sensor.map_or("-", |x| x.name()),
            secs(w.start_ns),
            w.end_ns.map_or(String::new(), |e| secs(e).to_string()),
            s.n_inside,
            opt(s.rms_before),
            opt(s.rms_inside),
            opt(s.max_inside),
            opt(s.threshold),
            opt(s.recovery_s),
        );
    }
    out
}

/// One line per window for the summary and `report.md` (angles in degrees).
pub fn lines(scores: &[FaultScore]) -> Vec<String> {
    let deg = |v: Option<f64>| v.map_or("–".to_owned(), |x| format!("{:.3}°", x.to_degrees()));
    scores
        .iter()
        .map(|s| {
            let w = &s.window;
            let sensor = w.sensor.map_or(String::new(), |x| format!(" {}", x.name()));
            let end = w.end_ns.map_or("end".to_owned(), |e| format!("{:.3} s", secs(e)));
            let recovery = match (s.recovery_s, w.end_ns) {
                (Some(r), _) => format!("recovered {r:.3} s after the end"),
                (None, None) => "lasts to the end".to_owned(),
                (None, Some(_)) => "not recovered".to_owned(),
            };
            format!(
                "fault {}{sensor} on {} ({:.3} s to {end}): geodesic before RMS {}, inside RMS {} max {} (N {}); threshold {}; {recovery}",
                w.kind,
                w.device,
                secs(w.start_ns),
                deg(s.rms_before),
                deg(s.rms_inside),
                deg(s.max_inside),
                s.n_inside,
                deg(s.threshold),
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(start_ns: u64, end_ns: Option<u64>) -> FaultRow {
        FaultRow {
            device: "imu".into(),
            kind: "stuck".into(),
            sensor: None,
            start_ns,
            end_ns,
        }
    }

    #[test]
    fn inside_before_and_recovery() {
        let options = FaultOptions {
            hold_ns: 3,
            ..FaultOptions::default()
        };
        let mut s = FaultScorer::new(vec![row(10, Some(20)), row(15, None)], options);
        // Before: 0.1 rad; inside 1 rad; after: high until 25, then low.
        for t in 0..40u64 {
            let e = match t {
                0..10 => 0.1,
                10..20 => 1.0,
                20..25 => 0.5,
                _ => 0.15,
            };
            s.add(t, e);
        }
        let got = s.finish();
        let a = &got[0];
        assert_eq!(a.n_inside, 10);
        assert!((a.rms_before.unwrap() - 0.1).abs() < 1e-12);
        assert_eq!((a.rms_inside, a.max_inside), (Some(1.0), Some(1.0)));
        assert!((a.threshold.unwrap() - 0.2).abs() < 1e-12);
        assert!((a.recovery_s.unwrap() - 5e-9).abs() < 1e-18);
        // Until the end: no recovery.
        assert_eq!(got[1].recovery_s, None);
        assert!(csv(&got)
            .lines()
            .nth(1)
            .unwrap()
            .starts_with("imu,stuck,-,0.00000001,0.00000002,10,"));
    }
}
