//! Semantic checks of a parsed scene: every value finite and in range, the run a whole number of
//! integrator steps, and each joint's source allowed in the scene's motion mode.

use super::error::Violation;
use super::ranges::{self, Plausible};
use super::schema::*;
use margemu_model::time::{nanos_from_seconds, Nanos, SampleClock};

/// What validation derives on the way.
pub(crate) struct Checked {
    pub clock: SampleClock,
    pub duration_ns: Nanos,
    pub step_ns: Nanos,
    pub primary: super::rig::Device,
    pub others: Vec<super::rig::Device>,
    /// Legal but likely wrong inputs.
    pub warnings: Vec<Violation>,
    /// The fault schedule (`[[fault]]`), device indices into the rig.
    pub faults: Vec<margemu_model::fault::Fault>,
}

type Check = Result<(), Violation>;

pub(crate) fn check(spec: &SceneSpec) -> Result<Checked, Violation> {
    let duration_ns = positive_nanos(spec.duration, &["duration"], ranges::TIME)?;
    finite_positive(spec.rate, &["rate"], ranges::RATE)?;
    let clock = SampleClock::from_hz(spec.rate)
        .ok_or_else(|| Violation::at(&["rate"], "must be between 0.001 Hz and 1 GHz"))?;
    let step_ns = positive_nanos(spec.integrator.step, &["integrator", "step"], ranges::STEP)?;
    if duration_ns % step_ns != 0 {
        return Err(Violation::at(
            &["duration"],
            format!(
                "{} s is not a whole number of integrator steps of {} s",
                spec.duration, spec.integrator.step
            ),
        ));
    }
    if clock.count_before(duration_ns) == 0 {
        return Err(Violation::at(
            &["duration"],
            "shorter than one output sample",
        ));
    }
    all_finite(
        &spec.field.reference,
        &["field", "reference"],
        ranges::FIELD,
    )?;
    check_bench(&spec.bench)?;
    check_control(&spec.control)?;
    for (name, source) in &spec.joints {
        check_joint(name, source, spec.motion)?;
    }
    check_sensors(spec)?;
    let (primary, others) = super::rig::resolve(spec.chip.as_ref(), &spec.device, spec.rate)?;
    let devices: Vec<_> = std::iter::once(primary.clone())
        .chain(others.iter().cloned())
        .collect();
    let faults = super::fault::resolve(&spec.fault, &devices, duration_ns)?;
    Ok(Checked {
        faults,
        clock,
        duration_ns,
        step_ns,
        primary,
        others,
        warnings: super::warnings::collect(spec),
    })
}

/// The sensor and perturbation sections: keys on the right sensor, and everything the model
/// itself refuses (it validates its configuration once, at construction).
fn check_sensors(spec: &SceneSpec) -> Check {
    use margemu_model::perturbation::PerturbationPlan;
    use margemu_model::sensor::Marg;
    let sensors = &spec.sensors;
    for (name, sensor) in [
        ("gyro", &sensors.gyro),
        ("accel", &sensors.accel),
        ("mag", &sensors.mag),
    ] {
        if let Some(key) = sensor.foreign_term(name) {
            return Err(Violation::at(
                &["sensors", name, key],
                format!("does not apply to `{name}`"),
            ));
        }
    }
    if let Some(t) = &sensors.temperature {
        let at = ["sensors", "temperature"];
        finite(t[0], &at, ranges::TEMPERATURE).map_err(|v| v.index(0))?;
        finite(t[1], &at, ranges::TEMPERATURE_SLOPE).map_err(|v| v.index(1))?;
    }
    super::sensors::check_ranges(spec)?;
    Marg::new(&sensors.config(), spec.rate, spec.seed).map_err(model_violation)?;
    if let Some(p) = &spec.perturbation {
        use super::sensors::PlacementSpec;
        if p.placement == PlacementSpec::Direction && p.direction.is_none() {
            return Err(Violation::at(
                &["perturbation", "placement"],
                "`direction` placement needs `direction = [x, y, z]`",
            ));
        }
        PerturbationPlan::new(&p.config(), spec.rate).map_err(model_violation)?;
    }
    Ok(())
}

/// A model error at the scene key it concerns.
fn model_violation(e: margemu_model::Error) -> Violation {
    use margemu_model::Error as E;
    let keys: &[&str] = match e {
        E::NonFiniteParameter { what }
        | E::ParameterTooLarge { what }
        | E::NegativeParameter { what }
        | E::NonPositiveParameter { what } => {
            return Violation::at_keys(super::sensors::key_path(what), e.to_string());
        }
        E::InvalidRate => &["rate"],
        E::PerturbationWindowTooShort { .. } | E::PerturbationWindowTooLong => {
            &["perturbation", "window"]
        }
        E::CutoffAboveNyquist => &["perturbation", "cutoff"],
        E::ZeroAmplitudeRange | E::InvertedAmplitudeRange => &["perturbation", "amplitude"],
        E::InvertedGapRange => &["perturbation", "gap"],
        E::ZeroDirection => &["perturbation", "direction"],
        _ => &["perturbation"],
    };
    Violation::at(keys, e.to_string())
}

fn check_bench(b: &BenchSpec) -> Check {
    let at = |key| ["bench", key];
    all_positive(&b.link_mass, &at("link_mass"), "a mass", ranges::MASS)?;
    finite_positive(b.plate_mass, &at("plate_mass"), ranges::MASS)?;
    let inertia = ranges::INERTIA;
    all_positive(
        &b.plate_inertia,
        &at("plate_inertia"),
        "an inertia",
        inertia,
    )?;
    let viscous = ranges::VISCOUS_FRICTION;
    all_non_negative(&b.viscous_friction, &at("viscous_friction"), viscous)?;
    let stiction = ranges::STATIC_FRICTION;
    all_non_negative(&b.static_friction, &at("static_friction"), stiction)?;
    if let Some(limit) = &b.effort_limit {
        all_positive(
            limit,
            &at("effort_limit"),
            "an effort limit",
            ranges::EFFORT,
        )?;
    }
    all_finite(&b.initial, &at("initial"), ranges::JOINT_VALUE)?;
    non_negative(b.gravity, &at("gravity"), ranges::GRAVITY)
}

fn check_control(c: &ControlSpec) -> Check {
    for (i, &o) in c.overshoot.iter().enumerate() {
        if !(o.is_finite() && o > 0.0 && o < 1.0) {
            return Err(Violation::at(
                &["control", "overshoot"],
                format!("must be in (0, 1), not {o}"),
            )
            .index(i));
        }
    }
    all_positive(
        &c.settling_time,
        &["control", "settling_time"],
        "a settling time",
        ranges::SETTLING_TIME,
    )?;
    if !(c.pole_ratio.is_finite() && c.pole_ratio >= 1.0) {
        return Err(Violation::at(
            &["control", "pole_ratio"],
            format!("must be finite and ≥ 1, not {}", c.pole_ratio),
        ));
    }
    ranges::POLE_RATIO.check(c.pole_ratio, &["control", "pole_ratio"])?;
    if !(c.retune_margin.is_finite() && c.retune_margin > 0.0 && c.retune_margin <= 1.0) {
        return Err(Violation::at(
            &["control", "retune_margin"],
            format!("must be in (0, 1], not {}", c.retune_margin),
        ));
    }
    if let Some(gains) = &c.gains {
        for (i, g) in gains.iter().enumerate() {
            all_finite(g, &["control", "gains"], ranges::GAIN).map_err(|v| v.index(i))?;
        }
    }
    finite_positive(
        c.external_acceleration,
        &["control", "external_acceleration"],
        ranges::EXTERNAL_ACCELERATION,
    )?;
    finite_positive(
        c.oscillation_rate,
        &["control", "oscillation_rate"],
        ranges::OSCILLATION_RATE,
    )?;
    Ok(())
}

fn check_joint(name: &str, source: &SourceSpec, motion: MotionMode) -> Check {
    let at = ["joints", name];
    if !JOINT_NAMES.contains(&name) {
        return Err(Violation::at(
            &at,
            format!("unknown joint; the joints are {}", JOINT_NAMES.join(", ")),
        ));
    }
    match motion {
        MotionMode::Static => {
            return Err(Violation::at(&at, "a static scene takes no joint sources"));
        }
        MotionMode::Kinematic if !source.is_kinematic() || source.smoothing().is_some() => {
            return Err(Violation::at(
                &["joints", name, "type"],
                format!(
                    "`{}`{} cannot prescribe motion directly (kinematic mode needs twice \
                     differentiable sources: constant, sine, polynomial, random-sine, csv)",
                    source.type_name(),
                    if source.smoothing().is_some() {
                        " with smoothing"
                    } else {
                        ""
                    }
                ),
            ));
        }
        _ => {}
    }
    if let Some(s) = source.smoothing() {
        let at = ["joints", name, "smoothing"];
        finite_positive(
            s.natural_frequency,
            &[at[0], at[1], at[2], "natural_frequency"],
            ranges::SMOOTHING_FREQUENCY,
        )?;
        finite_positive(
            s.damping,
            &[at[0], at[1], at[2], "damping"],
            ranges::DAMPING,
        )?;
    }
    let key = |k: &'static str| [at[0], at[1], k];
    match source {
        SourceSpec::Constant { value } => finite(*value, &key("value"), ranges::JOINT_VALUE),
        SourceSpec::Steps { points, .. } => {
            non_empty(points, &key("points"))?;
            let mut last = f64::NEG_INFINITY;
            for (i, &[t, v]) in points.iter().enumerate() {
                let entry = |k, why| Violation::at(&key("points"), why).index(i).index(k);
                if !(t.is_finite() && t >= 0.0 && t > last) {
                    return Err(entry(
                        0,
                        format!("times must be finite, ≥ 0 and increasing, not {t}"),
                    ));
                }
                if !ranges::TIME.contains(t) {
                    return Err(entry(0, ranges::TIME.refusal(t)));
                }
                if !v.is_finite() {
                    return Err(entry(1, format!("must be finite, not {v}")));
                }
                if !ranges::JOINT_VALUE.contains(v) {
                    return Err(entry(1, ranges::JOINT_VALUE.refusal(v)));
                }
                last = t;
            }
            Ok(())
        }
        SourceSpec::Waypoints { points, .. } => {
            non_empty(points, &key("points"))?;
            for (i, &[v, hold]) in points.iter().enumerate() {
                let entry = |k, why| Violation::at(&key("points"), why).index(i).index(k);
                if !v.is_finite() {
                    return Err(entry(0, format!("must be finite, not {v}")));
                }
                if !ranges::JOINT_VALUE.contains(v) {
                    return Err(entry(0, ranges::JOINT_VALUE.refusal(v)));
                }
                if !(hold.is_finite() && hold > 0.0) {
                    return Err(entry(1, format!("hold must be finite and > 0, not {hold}")));
                }
                if !ranges::TIME.contains(hold) {
                    return Err(entry(1, ranges::TIME.refusal(hold)));
                }
            }
            Ok(())
        }
        SourceSpec::Sine {
            amplitude,
            frequency,
            phase,
            offset,
        } => {
            finite(*amplitude, &key("amplitude"), ranges::JOINT_VALUE)?;
            non_negative(*frequency, &key("frequency"), ranges::FREQUENCY)?;
            finite(*phase, &key("phase"), ranges::JOINT_VALUE)?;
            finite(*offset, &key("offset"), ranges::JOINT_VALUE)
        }
        SourceSpec::Polynomial { coefficients } => {
            non_empty(coefficients, &key("coefficients"))?;
            all_finite(coefficients, &key("coefficients"), ranges::COEFFICIENT)
        }
        SourceSpec::RandomSetpoints { range, hold, .. } => {
            interval(range, &key("range"), false, ranges::JOINT_VALUE)?;
            interval(hold, &key("hold"), true, ranges::TIME)
        }
        SourceSpec::RandomSine {
            amplitude,
            frequency,
            segment,
            offset,
        } => {
            interval(amplitude, &key("amplitude"), false, ranges::JOINT_VALUE)?;
            interval(frequency, &key("frequency"), true, ranges::FREQUENCY)?;
            interval(segment, &key("segment"), true, ranges::TIME)?;
            finite(*offset, &key("offset"), ranges::JOINT_VALUE)
        }
        SourceSpec::Csv { column, .. } => {
            if column.is_empty() {
                return Err(Violation::at(&key("column"), "must name a column"));
            }
            Ok(())
        }
    }
}

pub(crate) fn positive_nanos(s: f64, at: &[&str], range: Plausible) -> Result<Nanos, Violation> {
    finite_positive(s, at, range)?;
    match nanos_from_seconds(s) {
        Some(ns) if ns > 0 => Ok(ns),
        _ => Err(Violation::at(
            at,
            format!("must be at least 1 ns, not {s} s"),
        )),
    }
}

/// `x` finite and in `range`.
pub(crate) fn finite(x: f64, at: &[&str], range: Plausible) -> Check {
    if x.is_finite() {
        range.check(x, at)
    } else {
        Err(Violation::at(at, format!("must be finite, not {x}")))
    }
}

pub(crate) fn finite_positive(x: f64, at: &[&str], range: Plausible) -> Check {
    if x.is_finite() && x > 0.0 {
        range.check(x, at)
    } else {
        Err(Violation::at(
            at,
            format!("must be finite and > 0, not {x}"),
        ))
    }
}

pub(crate) fn non_negative(x: f64, at: &[&str], range: Plausible) -> Check {
    if x.is_finite() && x >= 0.0 {
        range.check(x, at)
    } else {
        Err(Violation::at(
            at,
            format!("must be finite and ≥ 0, not {x}"),
        ))
    }
}

pub(crate) fn all_finite(xs: &[f64], at: &[&str], range: Plausible) -> Check {
    for (i, x) in xs.iter().enumerate() {
        finite(*x, at, range).map_err(|v| v.index(i))?;
    }
    Ok(())
}

fn all_positive(xs: &[f64], at: &[&str], what: &str, range: Plausible) -> Check {
    for (i, &x) in xs.iter().enumerate() {
        if !(x.is_finite() && x > 0.0) {
            return Err(
                Violation::at(at, format!("{what} must be finite and > 0, not {x}")).index(i),
            );
        }
        range.check(x, at).map_err(|v| v.index(i))?;
    }
    Ok(())
}

pub(crate) fn all_non_negative(xs: &[f64], at: &[&str], range: Plausible) -> Check {
    for (i, x) in xs.iter().enumerate() {
        non_negative(*x, at, range).map_err(|v| v.index(i))?;
    }
    Ok(())
}

fn non_empty<T>(xs: &[T], at: &[&str]) -> Check {
    if xs.is_empty() {
        Err(Violation::at(at, "must not be empty"))
    } else {
        Ok(())
    }
}

/// `[lo, hi]` finite, in `range`, with `lo ≤ hi`; `positive` also asks `lo > 0`.
fn interval(r: &[f64; 2], at: &[&str], positive: bool, range: Plausible) -> Check {
    all_finite(r, at, range)?;
    if r[0] > r[1] {
        return Err(Violation::at(
            at,
            format!("[lo, hi] must have lo ≤ hi, not {r:?}"),
        ));
    }
    if positive && r[0] <= 0.0 {
        return Err(Violation::at(at, format!("must be > 0, not {}", r[0])).index(0));
    }
    Ok(())
}
