//! The run stops at the first truth or sample value that is not finite (or, for the truth, beyond
//! the `f32` range its samples are rounded to), naming the sample, the value and the part of the
//! scene that drives it, so no run ever writes NaN or ±∞.
//!
//! Validated inputs lie in plausible ranges ([`crate::scene::ranges`]), so a non-finite value
//! comes from what the ranges cannot see: an explicit PID gain set that makes the bench unstable,
//! a CSV source whose rows are too close in time for its slope, a polynomial that outgrows `f64`
//! over a long run. [`check_truth`] runs on every output sample in [`crate::run::run`];
//! [`check_sample`] on every sensor sample ([`crate::marg::MargSim::try_sample`]).

use crate::bench::JointSample;
use crate::marg::{MargSample, MARG_COLUMNS};
use crate::motion::Motion;
use crate::output::TRUTH_COLUMNS;
use crate::scene::{MotionMode, Scene, JOINT_NAMES};
use crate::truth::Truth;

// The doc comment is the message.
#[derive(Debug, thiserror::Error, docsplay::Display)]
/// sample {index} (t = {t_ns} ns): {quantity} is {value:e}, {why}; it comes from {driver}
pub struct NonFinite {
    /// Output sample index (0-based).
    pub index: u64,
    /// Its latch instant.
    pub t_ns: u64,
    /// The first non-finite quantity (a `truth.csv` or `marg.csv` column, or a joint value).
    pub quantity: String,
    /// Its value.
    pub value: f64,
    /// "not finite", or "beyond the f32 range of the samples" for a finite truth value the
    /// samples cannot hold.
    pub why: &'static str,
    /// The scene part that drives it, with its `file:line:col`.
    pub driver: String,
}

/// Checks the truth of output sample `index`, computed from the joint sample `joints` of
/// `motion`.
#[inline]
pub fn check_truth(
    scene: &Scene,
    motion: &Motion,
    index: u64,
    joints: &JointSample,
    truth: &Truth,
) -> Result<(), Box<NonFinite>> {
    let values = truth.columns();
    // Branch-free over all values: the common case costs a few vector compares.
    if values.iter().fold(true, |ok, v| ok & fits(*v)) {
        return Ok(());
    }
    locate_truth(scene, motion, index, joints, truth)
}

/// Why [`check_truth`] refused `truth`: the first value, and what drives it.
#[cold]
fn locate_truth(
    scene: &Scene,
    motion: &Motion,
    index: u64,
    joints: &JointSample,
    truth: &Truth,
) -> Result<(), Box<NonFinite>> {
    let values = truth.columns();
    let Some(k) = values.iter().position(|v| !fits(*v)) else {
        return Ok(());
    };
    let non_finite = |quantity: String, value: f64, driver: String| {
        Box::new(NonFinite {
            index,
            t_ns: truth.t_ns,
            quantity,
            value,
            why: why(value),
            driver,
        })
    };
    for (i, name) in JOINT_NAMES.iter().enumerate() {
        let triple = [joints.q[i], joints.qd[i], joints.qdd[i]];
        let Some(d) = triple.iter().position(|v| !fits(*v)) else {
            continue;
        };
        let quantity = format!(
            "joint {name} {}",
            ["position", "velocity", "acceleration"][d]
        );
        let driver = joint_driver(scene, motion, i, truth.t_ns);
        return Err(non_finite(quantity, triple[d], driver));
    }
    let column = TRUTH_COLUMNS[k + 1];
    let driver =
        if column.starts_with('m') && !scene.spec.field.reference.iter().all(|x| x.is_finite()) {
            format!(
                "[field] reference ({})",
                scene.location(&["field", "reference"])
            )
        } else {
            format!(
                "the joint motion with [bench] gravity ({})",
                scene.location(&["bench", "gravity"])
            )
        };
    Err(non_finite(column.to_owned(), values[k], driver))
}

/// Whether a truth value is finite and within the range of the `f32` samples made from it.
#[inline]
fn fits(x: f64) -> bool {
    x.abs() <= f64::from(f32::MAX)
}

fn why(x: f64) -> &'static str {
    if x.is_finite() {
        "beyond the f32 range of the samples (±3.4e38)"
    } else {
        "not finite"
    }
}

/// What drives joint `i` at `t_ns`: its CSV rows, its source, or the bench dynamics.
fn joint_driver(scene: &Scene, motion: &Motion, i: usize, t_ns: u64) -> String {
    let name = JOINT_NAMES[i];
    let source = scene.spec.joints.get(name).map(|s| {
        let rows = motion
            .reference(i)
            .and_then(|r| r.rows_at(t_ns as f64))
            .map_or(String::new(), |rows| format!(", {rows}"));
        format!(
            "the {} source of joint {name} ({}{rows})",
            s.type_name(),
            scene.location(&["joints", name])
        )
    });
    match (scene.spec.motion, source) {
        (MotionMode::Bench, source) => {
            let gains = match scene.spec.control.gains {
                Some(_) => scene.location(&["control", "gains"]),
                None => scene.location(&["control"]),
            };
            format!(
                "the [bench] dynamics of joint {name} (masses and friction at {}, [control] \
                 gains at {gains}){}",
                scene.location(&["bench"]),
                source.map_or(String::new(), |s| format!(" tracking {s}"))
            )
        }
        (_, Some(source)) => source,
        (_, None) => format!(
            "[bench] initial of joint {name} ({})",
            scene.location(&["bench", "initial"])
        ),
    }
}

/// Checks sensor sample `index`.
pub fn check_sample(scene: &Scene, index: u64, s: &MargSample) -> Result<(), Box<NonFinite>> {
    let Some((k, &value)) = s.values().enumerate().find(|(_, v)| !v.is_finite()) else {
        return Ok(());
    };
    let sensor = ["accel", "gyro", "mag"][k / 3];
    let mut driver = format!(
        "[sensors.{sensor}] ({})",
        scene.location(&["sensors", sensor])
    );
    if sensor == "mag" && scene.spec.perturbation.is_some() {
        driver.push_str(&format!(
            " and [perturbation] ({})",
            scene.location(&["perturbation"])
        ));
    }
    Err(Box::new(NonFinite {
        index,
        t_ns: s.t_ns,
        quantity: MARG_COLUMNS[k + 1].to_owned(),
        value: f64::from(value),
        why: why(f64::from(value)),
        driver,
    }))
}
