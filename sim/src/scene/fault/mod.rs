//! `[[fault]]`: the scene's fault schedule, resolved to [`margemu_model::fault::Fault`]s
//! ([`super::Scene::faults`]).
//!
//! ```toml
//! [[fault]]
//! device = "imu"        # a device's name, or its index in the rig; default device 0
//! kind = "stuck"        # FaultKind::name
//! sensor = "gyro"       # accel | gyro | mag, for the sensor kinds
//! start = 2.0           # s from the scene start
//! duration = 0.5        # s; or `until_end = true`
//! ```
//!
//! Each kind takes its own parameters and refuses every other one (the user guide,
//! `docs/faults.md`, lists them): `value` (stuck_at), `rate` (Hz) `amplitude` `axes` (spikes,
//! `axes` a string of `x`, `y`, `z`, default `"xyz"`), `bias` (bias_step), `factor` (scale),
//! `std` (noise), `field` (mag_saturation), `identity` (wrong_identity), `probability`
//! (corrupt, missing_drdy), `stretch` (clock_stretch), `ppm` and `drift` (ppm/s, default 0)
//! (clock_offset), `max_jitter` (drdy_jitter), `delay` (late). `stretch`, `max_jitter` and
//! `delay` are in **µs**; `bias`, `factor`, `std` take one number for all three axes or
//! `[x, y, z]`; sensor values are in the model's units (m/s², rad/s, the scene's field unit) and
//! the device's axes.
//!
//! Refused, each at its key: an unknown device or kind, a missing or foreign parameter, a
//! sensor the device's chip does not have, a start outside `[0, duration)` of the run, a
//! duration that is not > 0, both or neither of `duration` and `until_end`, a probability
//! outside `[0, 1]`, a number that is not finite, a FIFO overflow on a chip without FIFO,
//! clock stretching on an SPI device, more than [`MAX_FAULTS`] faults, and two faults that
//! [`overlaps_exclusively`] says may not overlap (the error names both).

use super::chip::BusKind;
mod params;

use super::error::{PathPart, Violation};
use super::rig::Device;
use margemu_model::fault::{
    overlaps_exclusively, Fault, FaultKind, Sensor, Window, MAX_FAULTS, UNTIL_END,
};
use margemu_model::time::{nanos_from_seconds, Nanos};
use serde::Deserialize;

/// Which device a fault acts on: its name or its index.
#[derive(Clone, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum DeviceRef {
    /// Index in [`super::Scene::devices`].
    Index(i64),
    /// Name ([`Device::name`]).
    Name(String),
}

/// One number for all three axes, or one per axis.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(untagged)]
pub enum Triple {
    /// The same for x, y and z.
    One(f64),
    /// x, y, z.
    Three([f64; 3]),
}

/// One `[[fault]]` table as written.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)] // the keys are documented in the module docs and the user guide
pub struct FaultSpec {
    pub device: Option<DeviceRef>,
    pub kind: String,
    pub sensor: Option<String>,
    pub start: f64,
    pub duration: Option<f64>,
    pub until_end: Option<bool>,
    pub value: Option<[f64; 3]>,
    pub rate: Option<f64>,
    pub amplitude: Option<f64>,
    pub axes: Option<String>,
    pub bias: Option<Triple>,
    pub factor: Option<Triple>,
    pub std: Option<Triple>,
    pub field: Option<[f64; 3]>,
    pub identity: Option<i64>,
    pub probability: Option<f64>,
    pub stretch: Option<f64>,
    pub ppm: Option<f64>,
    pub drift: Option<f64>,
    pub max_jitter: Option<f64>,
    pub delay: Option<f64>,
}

use margemu_model::fault::KIND_NAMES;

/// The parameters kind `kind` takes (required first, then `optional` ones).
fn params_of(kind: &str) -> (&'static [&'static str], &'static [&'static str]) {
    match kind {
        "stuck_at" => (&["sensor", "value"], &[]),
        "stuck" | "dropout" => (&["sensor"], &[]),
        "spikes" => (&["sensor", "rate", "amplitude"], &["axes"]),
        "bias_step" => (&["sensor", "bias"], &[]),
        "scale" => (&["sensor", "factor"], &[]),
        "noise" => (&["sensor", "std"], &[]),
        "mag_saturation" => (&["field"], &["sensor"]),
        "wrong_identity" => (&["identity"], &[]),
        "corrupt" | "missing_drdy" => (&["probability"], &[]),
        "clock_stretch" => (&["stretch"], &[]),
        "clock_offset" => (&["ppm"], &["drift"]),
        "drdy_jitter" => (&["max_jitter"], &[]),
        "late" => (&["delay"], &[]),
        _ => (&[], &[]),
    }
}

impl FaultSpec {
    /// The parameter keys present, by name.
    fn present(&self) -> Vec<&'static str> {
        let keys = [
            ("sensor", self.sensor.is_some()),
            ("value", self.value.is_some()),
            ("rate", self.rate.is_some()),
            ("amplitude", self.amplitude.is_some()),
            ("axes", self.axes.is_some()),
            ("bias", self.bias.is_some()),
            ("factor", self.factor.is_some()),
            ("std", self.std.is_some()),
            ("field", self.field.is_some()),
            ("identity", self.identity.is_some()),
            ("probability", self.probability.is_some()),
            ("stretch", self.stretch.is_some()),
            ("ppm", self.ppm.is_some()),
            ("drift", self.drift.is_some()),
            ("max_jitter", self.max_jitter.is_some()),
            ("delay", self.delay.is_some()),
        ];
        keys.iter().filter(|(_, on)| *on).map(|(k, _)| *k).collect()
    }
}

/// The key path of key `key` of fault `i` (`""`: the table itself).
fn path(i: usize, key: &str) -> Vec<PathPart> {
    let mut p = vec![PathPart::Key("fault".to_owned()), PathPart::Index(i)];
    if !key.is_empty() {
        p.push(PathPart::Key(key.to_owned()));
    }
    p
}

/// Resolves and checks the scene's `[[fault]]` tables against its devices and its run length.
pub(crate) fn resolve(
    specs: &[FaultSpec],
    devices: &[Device],
    duration_ns: Nanos,
) -> Result<Vec<Fault>, Violation> {
    if specs.len() > MAX_FAULTS {
        return Err(Violation::at_path(
            path(MAX_FAULTS, ""),
            format!("a scene has at most {MAX_FAULTS} faults"),
        ));
    }
    let mut faults: Vec<Fault> = Vec::with_capacity(specs.len());
    for (i, spec) in specs.iter().enumerate() {
        let fault = resolve_one(i, spec, devices, duration_ns)?;
        if let Some(j) = faults.iter().position(|f| overlaps_exclusively(f, &fault)) {
            return Err(Violation::at_path(
                path(i, "start"),
                format!(
                    "{} overlaps {}; two faults of this kind on one {}may not overlap",
                    describe(&fault, i, devices),
                    describe(&faults[j], j, devices),
                    if fault.kind.replaces_value() {
                        "sensor "
                    } else {
                        "device "
                    },
                ),
            ));
        }
        faults.push(fault);
    }
    Ok(faults)
}

/// `fault[i] (stuck gyro on `imu`, 1 s to 2 s)`.
fn describe(f: &Fault, i: usize, devices: &[Device]) -> String {
    let device = devices
        .get(usize::from(f.device))
        .map_or("?", |d| d.name.as_str());
    let sensor = f
        .kind
        .sensor()
        .map_or(String::new(), |s| format!(" {}", s.name()));
    let secs = |ns: u64| ns as f64 / 1e9;
    let end = if f.window.end_ns == UNTIL_END {
        "the end".to_owned()
    } else {
        format!("{} s", secs(f.window.end_ns))
    };
    format!(
        "fault[{i}] ({}{sensor} on `{device}`, {} s to {end})",
        f.kind.name(),
        secs(f.window.start_ns)
    )
}

fn resolve_one(
    i: usize,
    spec: &FaultSpec,
    devices: &[Device],
    duration_ns: Nanos,
) -> Result<Fault, Violation> {
    let at = |key: &str, why: String| Violation::at_path(path(i, key), why);
    let index =
        match &spec.device {
            None => 0,
            Some(DeviceRef::Index(n)) => usize::try_from(*n)
                .ok()
                .filter(|&n| n < devices.len())
                .ok_or_else(|| {
                    at(
                        "device",
                        format!(
                            "no device {n}: the rig has devices 0 to {}",
                            devices.len() - 1
                        ),
                    )
                })?,
            Some(DeviceRef::Name(name)) => devices
                .iter()
                .position(|d| &d.name == name)
                .ok_or_else(|| {
                    let names: Vec<_> = devices.iter().map(|d| d.name.as_str()).collect();
                    at(
                        "device",
                        format!("no device `{name}`; the devices are {}", names.join(", ")),
                    )
                })?,
        };
    let device = &devices[index];
    if !KIND_NAMES.contains(&spec.kind.as_str()) {
        return Err(at(
            "kind",
            format!(
                "unknown fault kind `{}`; the kinds are {}",
                spec.kind,
                KIND_NAMES.join(", ")
            ),
        ));
    }
    let (required, optional) = params_of(&spec.kind);
    for key in spec.present() {
        if !required.contains(&key) && !optional.contains(&key) {
            return Err(at(
                key,
                format!("does not apply to a `{}` fault", spec.kind),
            ));
        }
    }
    let present = spec.present();
    if let Some(missing) = required.iter().find(|k| !present.contains(k)) {
        return Err(at("", format!("a `{}` fault needs `{missing}`", spec.kind)));
    }
    let window = window(i, spec, duration_ns)?;
    let kind = params::kind(i, spec)?;
    check_device(i, &kind, device)?;
    if index != 0 && kind.moves_latch() {
        return Err(at(
            "kind",
            format!(
                "a `{}` fault moves the instant samples are latched, and a rig's devices share \
                 one serving clock: only the first device (`{}`) can have it",
                spec.kind, devices[0].name
            ),
        ));
    }
    Ok(Fault::new(index as u8, window, kind))
}

fn window(i: usize, spec: &FaultSpec, duration_ns: Nanos) -> Result<Window, Violation> {
    let at = |key: &str, why: String| Violation::at_path(path(i, key), why);
    let run_s = duration_ns as f64 / 1e9;
    let start_ns = match nanos_from_seconds(spec.start) {
        Some(ns) if spec.start.is_finite() && ns < duration_ns => ns,
        _ => {
            return Err(at(
                "start",
                format!(
                    "must be finite, ≥ 0 and before the run's end ({run_s} s), not {}",
                    spec.start
                ),
            ))
        }
    };
    let end_ns = match (spec.duration, spec.until_end) {
        (Some(_), Some(true)) => {
            return Err(at(
                "until_end",
                "a fault has `duration` or `until_end = true`, not both".to_owned(),
            ))
        }
        (None, Some(true)) => UNTIL_END,
        (None, _) => {
            return Err(at(
                "",
                "a fault needs `duration` (s) or `until_end = true`".to_owned(),
            ))
        }
        (Some(d), _) => match nanos_from_seconds(d) {
            Some(ns) if d.is_finite() && d > 0.0 && ns > 0 => start_ns.saturating_add(ns),
            _ => {
                return Err(at(
                    "duration",
                    format!("must be finite and > 0 (at least 1 ns), not {d} s"),
                ))
            }
        },
    };
    Ok(Window::new(start_ns, end_ns))
}

/// What the device's chip can have.
fn check_device(i: usize, kind: &FaultKind, device: &Device) -> Result<(), Violation> {
    let model = device.chip.model;
    if let Some(sensor) = kind.sensor() {
        let has = match sensor {
            Sensor::Mag => model.has_magnetometer(),
            Sensor::Acc | Sensor::Gyr => !model.is_magnetometer_only(),
        };
        if !has {
            let key = if kind.name() == "mag_saturation" && sensor == Sensor::Mag {
                "kind"
            } else {
                "sensor"
            };
            return Err(Violation::at_path(
                path(i, key),
                format!(
                    "device `{}` ({}) has no {}",
                    device.name,
                    model.part_name(),
                    match sensor {
                        Sensor::Acc => "accelerometer",
                        Sensor::Gyr => "gyroscope",
                        Sensor::Mag => "magnetometer",
                    }
                ),
            ));
        }
    }
    if *kind == FaultKind::FifoOverflow && model.is_magnetometer_only() {
        return Err(Violation::at_path(
            path(i, "kind"),
            format!(
                "device `{}` ({}) has no FIFO",
                device.name,
                model.part_name()
            ),
        ));
    }
    if matches!(kind, FaultKind::ClockStretch { .. }) && device.chip.bus != BusKind::I2c {
        return Err(Violation::at_path(
            path(i, "kind"),
            format!(
                "device `{}` is on SPI; clock stretching is an I2C fault",
                device.name
            ),
        ));
    }
    Ok(())
}
