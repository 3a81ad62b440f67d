//! [`Ending`]: how a session's device is stopped, after the last sample or when the session is
//! interrupted (SIGINT, SIGTERM, SIGHUP, the stop flag). The run (`flow.rs`) sequences it with
//! these answers.
//!
//! After the last sample, Stop is written half an output period after the last sample's instant,
//! on the session's clock ([`Plan::stop_at`]); go-backs are still written until then. The device
//! stops by itself at the scene's end (Start's `end_index`), so it never serves an instant after
//! the last sample, however late Stop arrives; Stop confirms that. In source images a Stop that
//! arrives early is graceful (the device serves what it still holds). In source model it stops
//! at once, and the device's clock lags the host's by the Start's delivery time, so the host
//! first waits, up to the drain timeout, until the device reports serving the last sample
//! ([`Ending::awaited`]).
//!
//! After an interruption, Stop is written at once (the device then holds its last sample
//! instead of counting underruns).
//!
//! Either way, once Stop is written the device's reports no longer lead to go-backs
//! ([`Ending::stopping`]), the host waits up to the drain timeout for Telemetry in the stopped
//! state, and `events.csv` says whether the device confirmed it (`stopped`) or not
//! (`stop_unconfirmed`, [`Ending::outcome`]).

use super::plan::Plan;
use super::reports::Reports;
use margemu_protocol::link::DeviceState;

/// Whether a run has written Stop (see the module docs).
#[derive(Default)]
pub(super) struct Ending {
    stop_written: bool,
}

impl Ending {
    /// Host time at which Stop is due after the last sample, for a Start written at `start`
    /// (`None`: never started, or an empty scene: Stop at once).
    pub(super) fn stop_at(plan: &Plan, start: Option<u64>) -> Option<u64> {
        start.and_then(|start| plan.stop_at(start))
    }

    /// The sample the device must report serving before Stop is written: the last one when it
    /// stops at once (source model).
    pub(super) fn awaited(plan: &Plan) -> Option<u64> {
        plan.samples()
            .checked_sub(1)
            .filter(|_| plan.stops_at_once())
    }

    /// Stop is about to be written.
    pub(super) fn stop(&mut self) {
        self.stop_written = true;
    }

    /// Whether Stop was written: the device's reports no longer lead to go-backs.
    pub(super) fn stopping(&self) -> bool {
        self.stop_written
    }

    /// The `events.csv` row that says whether the device confirmed Stop: `stopped` (with what
    /// it served) or `stop_unconfirmed`.
    pub(super) fn outcome(reports: &Reports) -> (&'static str, String) {
        match reports.telemetry() {
            Some(t) if t.state == DeviceState::Stopped => {
                let detail = format!(
                    "served {} samples, last index {}, underruns {}",
                    t.samples_served, t.last_served_index, t.underruns
                );
                ("stopped", detail)
            }
            _ => (
                "stop_unconfirmed",
                "no Telemetry in the stopped state".into(),
            ),
        }
    }

    /// The `events.csv` row when Stop could not be written after an interruption.
    pub(super) fn unwritten() -> (&'static str, String) {
        ("stop_unconfirmed", "Stop could not be written".into())
    }
}
