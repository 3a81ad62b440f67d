//! A tone source's rpm profile from its one rpm key: `rpm` (constant), `rpm_ramp`, `rpm_steps`
//! (each value held until the next step's time: a step is two points at one instant) or
//! `rpm_csv` (rows `t_s,rpm`, linear between rows).

use super::at::At;
use super::spec::{RampSpec, ToneSpec};
use crate::csv_column::ColumnError;
use crate::scene::error::Violation;
use crate::scene::ranges::{self, RPM};
use margemu_model::time::nanos_from_seconds;
use margemu_model::vibration::RpmPoint;
use std::path::Path;

/// The rpm keys, in the order they are reported.
const KEYS: [&str; 4] = ["rpm", "rpm_ramp", "rpm_steps", "rpm_csv"];

/// The profile `tone` (at `at`) gives; `base` is the folder `rpm_csv` resolves against.
pub(super) fn profile(tone: &ToneSpec, at: &At, base: &Path) -> Result<Vec<RpmPoint>, Violation> {
    let given = [
        tone.rpm.is_some(),
        tone.rpm_ramp.is_some(),
        tone.rpm_steps.is_some(),
        tone.rpm_csv.is_some(),
    ];
    let mut keys = KEYS.iter().zip(given).filter(|(_, g)| *g).map(|(k, _)| *k);
    let (Some(first), second) = (keys.next(), keys.next()) else {
        return Err(at.error(format!(
            "a tone source needs its rpm: one of {}",
            KEYS.map(|k| format!("`{k}`")).join(", ")
        )));
    };
    if let Some(second) = second {
        return Err(at.key(second).error(format!(
            "`{first}` gives the rpm already: give one of {}",
            KEYS.map(|k| format!("`{k}`")).join(", ")
        )));
    }
    if let Some(rpm) = tone.rpm {
        return Ok(vec![point(0, rpm, &at.key("rpm"))?]);
    }
    if let Some(ramp) = &tone.rpm_ramp {
        return ramp_points(ramp, &at.key("rpm_ramp"));
    }
    if let Some(steps) = &tone.rpm_steps {
        return step_points(steps, &at.key("rpm_steps"));
    }
    match &tone.rpm_csv {
        Some(file) => csv_points(&base.join(file), &at.key("rpm_csv")),
        None => Ok(Vec::new()),
    }
}

/// `rpm` at `t_ns`, the rpm checked at `at`.
fn point(t_ns: u64, rpm: f64, at: &At) -> Result<RpmPoint, Violation> {
    at.check(crate::scene::validate::non_negative(rpm, &[], RPM))?;
    Ok(RpmPoint { t_ns, rpm })
}

/// `s` seconds as nanoseconds, checked at `at`.
pub(super) fn instant(s: f64, at: &At) -> Result<u64, Violation> {
    at.check(crate::scene::validate::non_negative(s, &[], ranges::TIME))?;
    nanos_from_seconds(s).ok_or_else(|| at.error(format!("{s} s is not a time")))
}

fn ramp_points(ramp: &RampSpec, at: &At) -> Result<Vec<RpmPoint>, Violation> {
    let start = instant(ramp.start, &at.key("start"))?;
    let end = instant(ramp.end, &at.key("end"))?;
    if ramp.end <= ramp.start {
        return Err(at.key("end").error(format!(
            "the ramp must end after it starts ({} s), not at {} s",
            ramp.start, ramp.end
        )));
    }
    Ok(vec![
        point(start, ramp.from, &at.key("from"))?,
        point(end, ramp.to, &at.key("to"))?,
    ])
}

fn step_points(steps: &[[f64; 2]], at: &At) -> Result<Vec<RpmPoint>, Violation> {
    if steps.is_empty() {
        return Err(at.error("needs at least one `[time s, rpm]` step"));
    }
    let mut points: Vec<RpmPoint> = Vec::with_capacity(2 * steps.len());
    let mut last: Option<f64> = None;
    for (i, &[t, rpm]) in steps.iter().enumerate() {
        let t_ns = instant(t, &at.index(i).index(0))?;
        if let Some(last) = last.filter(|&last| t <= last) {
            return Err(at.index(i).index(0).error(format!(
                "steps go in time order: {t} s does not come after the previous step's {last} s"
            )));
        }
        let step = point(t_ns, rpm, &at.index(i).index(1))?;
        // The previous value holds until this instant.
        if let Some(held) = points.last().map(|p| p.rpm) {
            points.push(RpmPoint { t_ns, rpm: held });
        }
        points.push(step);
        last = Some(t);
    }
    Ok(points)
}

fn csv_points(path: &Path, at: &At) -> Result<Vec<RpmPoint>, Violation> {
    let rows = crate::input_file::check(path)
        .map_err(ColumnError::Input)
        .and_then(|_| {
            crate::csv_column::read_checked::<f64>(path, "t_s", "rpm", 1, |t, rpm| {
                if !ranges::TIME.contains(t) {
                    return Err(format!("`t_s` = {}", ranges::TIME.refusal(t)));
                }
                if !RPM.contains(rpm) {
                    return Err(format!("`rpm` = {}", RPM.refusal(rpm)));
                }
                Ok(())
            })
        })
        .map_err(|e| at.error(e.to_string()))?;
    let ns = rows
        .times
        .iter()
        .map(|&t| nanos_from_seconds(t).unwrap_or(0));
    let points = ns
        .zip(rows.values)
        .map(|(t_ns, rpm)| RpmPoint { t_ns, rpm });
    Ok(points.collect())
}
