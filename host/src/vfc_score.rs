//! A virtual flight controller's session ([`margemu_hil::vfc`]) scored against the truth, as
//! `margemu loopback --vfc` and `margemu demo` report it.

use margemu_hil::vfc::session_has_magnetometer;

/// `margemu evaluate` on a session the flight controller wrote: its ATTITUDE_QUATERNION rows
/// (ATTITUDE carries the same estimates as Euler angles), aligned and scored with the defaults,
/// except when the flight controller had no magnetometer (neither its chip's nor a rig's
/// compass, [`session_has_magnetometer`]): there the latency is fixed at 0 instead of
/// estimated. The estimate matches the attitude against the truth by the geodesic angle, which
/// the heading offset of a run without a magnetometer (the truth's initial heading, 26° in the
/// tests' gentle scene) dominates: it drags the estimate to a latency that trades roll and
/// pitch error for yaw error (−114 ms seen, with 5° of roll error instead of 0.3°). The flight
/// controller stamps each output with its sample's instant on the device clock, so its latency
/// on that clock is 0 by construction. Writes `dir/errors.csv`.
pub fn evaluate_session(
    dir: &std::path::Path,
) -> Result<margemu_eval::evaluate::Evaluation, margemu_eval::evaluate::EvalError> {
    use margemu_eval::evaluate::{evaluate_writing, EvalOptions, LatencyMode, Source};
    let options = EvalOptions {
        message: Some("ATTITUDE_QUATERNION".into()),
        latency: (!session_has_magnetometer(dir)).then_some(LatencyMode::Fixed(0)),
        ..EvalOptions::default()
    };
    let errors = dir.join("errors.csv");
    evaluate_writing(&Source::Session(dir.to_path_buf()), &options, Some(&errors))
}
