//! margemu evaluation: a device's or a filter's attitude scored against the truth (eq. 27,
//! geodesic), noise analysis, the reference filters run offline, and their tuning. Built on
//! `margemu-sim` (run directories, truth, scenes); independent of the hardware-in-the-loop
//! library, so scoring a recording needs no serial port or MAVLink.
//!
//! - [`analysis`]: Allan deviation, PSD and their plots behind `margemu analyze`;
//! - [`evaluate`](mod@evaluate): scores of an attitude against the truth, aligned and split by
//!   phase, with a report and figures;
//! - [`offline`]: the reference filters (`margemu-filters`) run over recorded samples;
//! - [`tune`](mod@tune): a filter's parameters tuned on a scene over several seeds
//!   (Nelder–Mead, eq. 27).
#![warn(missing_docs)]

pub mod analysis;
pub mod evaluate;
pub mod frame;
pub mod offline;
pub mod tune;
