//! Each `[[fault]]` kind's parameters, checked and turned into the model's units
//! ([`kind`]): finite numbers that fit an `f32`, probabilities in `[0, 1]`, µs as whole ns,
//! axes as bits.

use super::{path, FaultSpec, Triple};
use crate::scene::error::Violation;
use margemu_model::fault::{FaultKind, Sensor};

/// A finite `f64` that fits an `f32`.
fn real(i: usize, key: &str, x: f64) -> Result<f32, Violation> {
    let y = x as f32;
    if x.is_finite() && y.is_finite() {
        Ok(y)
    } else {
        Err(Violation::at_path(
            path(i, key),
            format!("must be finite (and within ±3.4e38), not {x}"),
        ))
    }
}

/// An `[x, y, z]` array, each refusal located at its element.
fn reals(i: usize, key: &str, v: [f64; 3]) -> Result<[f32; 3], Violation> {
    let mut out = [0.0f32; 3];
    for (k, (o, x)) in out.iter_mut().zip(v).enumerate() {
        *o = real(i, key, x).map_err(|e| e.index(k))?;
    }
    Ok(out)
}

/// A number or an `[x, y, z]` array.
fn triple(i: usize, key: &str, t: Option<Triple>) -> Result<[f32; 3], Violation> {
    match t {
        Some(Triple::One(x)) => real(i, key, x).map(|y| [y; 3]),
        Some(Triple::Three(v)) => reals(i, key, v),
        None => Ok([0.0; 3]),
    }
}

/// µs as whole ns in `1 ..= u32::MAX`.
fn micros(i: usize, key: &str, x: f64) -> Result<u32, Violation> {
    let ns = x * 1e3;
    if x.is_finite() && x > 0.0 && ns >= 1.0 && ns <= f64::from(u32::MAX) {
        Ok(ns.round() as u32)
    } else {
        Err(Violation::at_path(
            path(i, key),
            format!("µs, must be finite, at least 0.001 and at most 4294967.295, not {x}"),
        ))
    }
}

fn probability(i: usize, x: f64) -> Result<f32, Violation> {
    if (0.0..=1.0).contains(&x) {
        Ok(x as f32)
    } else {
        Err(Violation::at_path(
            path(i, "probability"),
            format!("must be in [0, 1], not {x}"),
        ))
    }
}

fn sensor(i: usize, spec: &FaultSpec) -> Result<Sensor, Violation> {
    let name = spec.sensor.as_deref().unwrap_or("mag");
    Sensor::ALL
        .into_iter()
        .find(|s| s.name() == name)
        .ok_or_else(|| {
            Violation::at_path(
                path(i, "sensor"),
                format!("unknown sensor `{name}`; the sensors are accel, gyro, mag"),
            )
        })
}

/// The kind of fault `i` with its parameters (the keys present were checked against the kind).
pub(super) fn kind(i: usize, s: &FaultSpec) -> Result<FaultKind, Violation> {
    let need = |x: Option<f64>| x.unwrap_or_default();
    let triple = |key, t: Option<Triple>| triple(i, key, t);
    Ok(match s.kind.as_str() {
        "stuck" => FaultKind::Stuck {
            sensor: sensor(i, s)?,
        },
        "stuck_at" => FaultKind::StuckAt {
            sensor: sensor(i, s)?,
            value: reals(i, "value", s.value.unwrap_or_default())?,
        },
        "dropout" => FaultKind::Dropout {
            sensor: sensor(i, s)?,
        },
        "spikes" => {
            let rate = need(s.rate);
            if !(rate.is_finite() && rate > 0.0) {
                return Err(Violation::at_path(
                    path(i, "rate"),
                    format!("spikes per second, must be finite and > 0, not {rate}"),
                ));
            }
            FaultKind::Spikes {
                sensor: sensor(i, s)?,
                rate_hz: real(i, "rate", rate)?,
                amplitude: real(i, "amplitude", need(s.amplitude))?,
                axes: axes(i, s.axes.as_deref().unwrap_or("xyz"))?,
            }
        }
        "bias_step" => FaultKind::BiasStep {
            sensor: sensor(i, s)?,
            bias: triple("bias", s.bias)?,
        },
        "scale" => FaultKind::Scale {
            sensor: sensor(i, s)?,
            factor: triple("factor", s.factor)?,
        },
        "noise" => {
            let std = triple("std", s.std)?;
            if std.iter().any(|x| *x < 0.0) {
                return Err(Violation::at_path(
                    path(i, "std"),
                    format!("a standard deviation must be ≥ 0, not {std:?}"),
                ));
            }
            FaultKind::Noise {
                sensor: sensor(i, s)?,
                std,
            }
        }
        "mag_saturation" => {
            if sensor(i, s)? != Sensor::Mag {
                return Err(Violation::at_path(
                    path(i, "sensor"),
                    "a `mag_saturation` fault acts on the magnetometer (`sensor = \"mag\"` or none)",
                ));
            }
            FaultKind::MagSaturation {
                field: reals(i, "field", s.field.unwrap_or_default())?,
            }
        }
        "reset" => FaultKind::Reset,
        "wrong_identity" => {
            let v = s.identity.unwrap_or_default();
            let value = u8::try_from(v).map_err(|_| {
                Violation::at_path(
                    path(i, "identity"),
                    format!("a register value, must be 0 to 255 (0x00 to 0xFF), not {v}"),
                )
            })?;
            FaultKind::WrongIdentity { value }
        }
        "fifo_overflow" => FaultKind::FifoOverflow,
        "nak" => FaultKind::Nak,
        "corrupt" => FaultKind::Corrupt {
            probability: probability(i, need(s.probability))?,
        },
        "clock_stretch" => FaultKind::ClockStretch {
            stretch_ns: micros(i, "stretch", need(s.stretch))?,
        },
        "clock_offset" => {
            let ppm = need(s.ppm);
            if !(ppm.is_finite() && ppm.abs() < 1e6) {
                return Err(Violation::at_path(
                    path(i, "ppm"),
                    format!("must be finite and within ±1e6 ppm, not {ppm}"),
                ));
            }
            FaultKind::ClockOffset {
                ppm: ppm as f32,
                drift_ppm_per_s: real(i, "drift", need(s.drift))?,
            }
        }
        "drdy_jitter" => FaultKind::DrdyJitter {
            max_ns: micros(i, "max_jitter", need(s.max_jitter))?,
        },
        "missing_drdy" => FaultKind::MissingDrdy {
            probability: probability(i, need(s.probability))?,
        },
        _ => FaultKind::Late {
            delay_ns: micros(i, "delay", need(s.delay))?,
        },
    })
}

/// `"xz"` → bits 0 and 2.
fn axes(i: usize, text: &str) -> Result<u8, Violation> {
    let mut bits = 0u8;
    for c in text.chars() {
        let bit = match c {
            'x' => 1,
            'y' => 2,
            'z' => 4,
            _ => 0,
        };
        if bit == 0 || bits & bit != 0 {
            return Err(Violation::at_path(
                path(i, "axes"),
                format!("a string of distinct axes `x`, `y`, `z` (like \"xz\"), not {text:?}"),
            ));
        }
        bits |= bit;
    }
    if bits == 0 {
        return Err(Violation::at_path(
            path(i, "axes"),
            "must name at least one axis (like \"xz\")",
        ));
    }
    Ok(bits)
}
