//! Attitude series that an evaluation reads from the start as often as it needs (once to count,
//! once per alignment and scoring pass), one row in memory at a time: a `truth.csv`, an
//! estimates file or an external recording's reference on disk (the last two in a named world
//! frame, converted as read; a recording's rows without a reference passed over), or samples
//! already in memory (sessions, recordings with estimate columns). Files
//! are checked as they are read (order, quaternions), each fault at its line, as
//! [`input`](super::input) does.

use super::input::{check_seconds_order, reference_of, seconds_to_ns, unit};
use super::quat::normalize;
use super::run::EvalError;
use super::score::{validated, Sample, ScoreError, Span, Stamped};
use crate::frame::Frame;
use margemu_sim::csv_table::Table;
use std::path::PathBuf;

/// One attitude series.
#[derive(Clone, Debug)]
pub(super) enum Series {
    /// `truth.csv` (`t_ns`, `qw..qz`).
    Truth(PathBuf),
    /// An estimates file (`t_s`, `qw..qz`; seconds from the scene start).
    Estimates(PathBuf),
    /// An estimates file in a named world frame, converted as read.
    FramedEstimates(PathBuf, Frame),
    /// An external recording's reference (`t_s`, `qw..qz`) in a named world frame, converted
    /// as read; rows without one (empty or `NaN`) are passed over.
    Recording(PathBuf, Frame),
    /// Validated samples.
    Memory(Vec<Sample>),
}

/// What a counting pass found: the series is not empty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Extent {
    /// Samples.
    pub(super) count: usize,
    /// First instant (ns).
    pub(super) first_ns: u64,
    /// Last instant (ns).
    pub(super) last_ns: u64,
}

impl Extent {
    /// Counts one more sample at `t_ns` (in time order) into `extent`, starting it if empty.
    pub(super) fn add(extent: &mut Option<Extent>, t_ns: u64) {
        let e = extent.get_or_insert(Extent {
            count: 0,
            first_ns: t_ns,
            last_ns: t_ns,
        });
        e.count += 1;
        e.last_ns = t_ns;
    }

    /// The span, shifted back by `shift_ns`.
    pub(super) fn span(&self, shift_ns: i64) -> Span {
        Span {
            start_ns: self.first_ns as i64 - shift_ns,
            end_ns: self.last_ns as i64 - shift_ns,
        }
    }
}

impl Series {
    /// In-memory samples, checked as the scoring functions check them (`what`: `truth` or
    /// `estimate`).
    pub(super) fn memory(samples: &[Stamped], what: &'static str) -> Result<Self, ScoreError> {
        validated(samples, what).map(Self::Memory)
    }

    /// A reader from the first sample.
    pub(super) fn read(&self) -> Result<Reader<'_>, EvalError> {
        Ok(Reader(match self {
            Self::Memory(samples) => Inner::Memory(samples.iter()),
            Self::Truth(path)
            | Self::Estimates(path)
            | Self::FramedEstimates(path, _)
            | Self::Recording(path, _) => {
                let table = Table::open(path)?;
                let seconds = !matches!(self, Self::Truth(_));
                let (frame, recording) = match self {
                    Self::FramedEstimates(_, f) => (*f, false),
                    Self::Recording(_, f) => (*f, true),
                    _ => (Frame::Nwu, false),
                };
                let t = table.column(if seconds { "t_s" } else { "t_ns" })?;
                let q = table.columns(["qw", "qx", "qy", "qz"])?;
                Inner::Csv {
                    table: Box::new(table),
                    t,
                    q,
                    seconds,
                    last: None,
                    frame,
                    recording,
                }
            }
        }))
    }

    /// Reads the series through once; `None` when it is empty.
    pub(super) fn extent(&self) -> Result<Option<Extent>, EvalError> {
        let mut extent: Option<Extent> = None;
        for sample in self.read()? {
            Extent::add(&mut extent, sample?.0);
        }
        Ok(extent)
    }
}

/// Samples of a [`Series`] in order.
pub(super) struct Reader<'a>(Inner<'a>);

enum Inner<'a> {
    Memory(std::slice::Iter<'a, Sample>),
    Csv {
        table: Box<Table>,
        t: usize,
        q: [usize; 4],
        seconds: bool,
        last: Option<u64>,
        frame: Frame,
        recording: bool,
    },
}

impl Iterator for Reader<'_> {
    type Item = Result<Sample, EvalError>;

    fn next(&mut self) -> Option<Self::Item> {
        match &mut self.0 {
            Inner::Memory(samples) => samples.next().copied().map(Ok),
            Inner::Csv {
                table,
                t,
                q,
                seconds,
                last,
                frame,
                recording,
            } => loop {
                let row = match table.next_row() {
                    Ok(Some(row)) => row,
                    Ok(None) => return None,
                    Err(e) => return Some(Err(e.into())),
                };
                let sample = (|| {
                    let t_ns = if *seconds {
                        let t_ns = seconds_to_ns(&row, *t)?;
                        check_seconds_order(&row, *t, *last, t_ns)?;
                        t_ns
                    } else {
                        let t_ns: u64 = row.int(*t)?;
                        row.check_order(*t, *last, t_ns, true)?;
                        t_ns
                    };
                    // Normalised as the file readers do, then as the scoring functions do.
                    let q = if *recording {
                        match reference_of(&row, *q)? {
                            Some(q) => q,
                            None => return Ok(None),
                        }
                    } else {
                        unit(&row, row.f64s(*q)?)?
                    };
                    let q = frame.quat_in(q);
                    let q = normalize(q)
                        .ok_or_else(|| row.error(format!("quaternion {q:?} has no direction")))?;
                    Ok(Some((t_ns, q)))
                })();
                match sample {
                    Ok(Some(s)) => {
                        *last = Some(s.0);
                        return Some(Ok(s));
                    }
                    // A recording's row without a reference still orders the time column.
                    Ok(None) => {
                        if let Ok(t_ns) = seconds_to_ns(&row, *t) {
                            *last = Some(t_ns);
                        }
                    }
                    Err(e) => return Some(Err(EvalError::Column(e))),
                }
            },
        }
    }
}
