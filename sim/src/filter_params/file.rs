//! The parameters file: one table per filter (`[ecf]`, `[gda]`, `[ekf]`), each key optional,
//! values finite numbers ≥ 0 (the GDA's `normalization` a name); unknown tables and keys are
//! errors at their line and column (see [`super`]). Settings are written only when they differ
//! from the defaults, so a tuner's file stays as it was.

use super::{FilterKind, FilterParams, ParamError};
use crate::scene::SceneError;
use serde::{Deserialize, Deserializer};
use std::path::Path;

impl FilterParams {
    /// This filter's table of a parameters file (`[ecf]`, `[gda]` or `[ekf]`).
    pub fn to_toml(&self) -> String {
        let mut out = format!("[{}]\n", self.kind());
        for (p, v) in self.iter() {
            out.push_str(&format!("{} = {v:?}\n", p.name));
        }
        let (set, default) = (self.settings(), super::Settings::default());
        match self.kind() {
            FilterKind::Gda if set.normalization != default.normalization => {
                let name = super::normalization_name(set.normalization);
                out.push_str(&format!("normalization = \"{name}\"\n"));
            }
            FilterKind::Ekf => {
                if set.initial_attitude_std != default.initial_attitude_std {
                    let v = set.initial_attitude_std;
                    out.push_str(&format!("initial_attitude_std = {v:?}\n"));
                }
                if set.initial_bias_std != default.initial_bias_std {
                    let v = set.initial_bias_std;
                    out.push_str(&format!("initial_bias_std = {v:?}\n"));
                }
            }
            _ => {}
        }
        out
    }

    /// The values of `kind`'s table in a parameters file (`path` names it in errors); absent
    /// keys, or an absent table, keep the defaults. Unknown tables and keys, and values that
    /// are not finite numbers ≥ 0, are errors at their line and column.
    pub fn from_toml(text: &str, path: &Path, kind: FilterKind) -> Result<Self, ParamError> {
        let file: ParamsFile = toml::from_str(text)
            .map_err(|e| ParamError::File(SceneError::from_toml(path, text, &e)))?;
        let table = match kind {
            FilterKind::Ecf => file.ecf.as_ref().map(|t| vec![("kp", t.kp), ("ki", t.ki)]),
            FilterKind::Gda => file.gda.as_ref().map(|t| vec![("beta", t.beta)]),
            FilterKind::Ekf => file.ekf.as_ref().map(|t| {
                vec![
                    ("gyro_noise", t.gyro_noise),
                    ("gyro_bias_walk", t.gyro_bias_walk),
                    ("accel_noise", t.accel_noise),
                    ("mag_noise", t.mag_noise),
                ]
            }),
        };
        let mut params = Self::defaults(kind);
        for (name, value) in table.unwrap_or_default() {
            if let Some(Gain(v)) = value {
                params.set(name, v)?;
            }
        }
        let settings: Vec<(&str, Option<String>)> = match (kind, &file.gda, &file.ekf) {
            (FilterKind::Gda, Some(t), _) => vec![("normalization", t.normalization.clone())],
            (FilterKind::Ekf, _, Some(t)) => vec![
                (
                    "initial_attitude_std",
                    t.initial_attitude_std.map(|g| g.0.to_string()),
                ),
                (
                    "initial_bias_std",
                    t.initial_bias_std.map(|g| g.0.to_string()),
                ),
            ],
            _ => Vec::new(),
        };
        for (name, value) in settings {
            if let Some(text) = value {
                params.set_setting(name, &text).map_err(|e| match e {
                    ParamError::Setting { name, reason } => ParamError::Setting {
                        name,
                        reason: format!("{reason} (in {})", path.display()),
                    },
                    other => other,
                })?;
            }
        }
        Ok(params)
    }
}

/// A parameter value in a file: a finite number ≥ 0 (integers allowed).
#[derive(Clone, Copy, Debug)]
struct Gain(f64);

impl<'de> Deserialize<'de> for Gain {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = f64::deserialize(d)?;
        if v.is_finite() && v >= 0.0 {
            Ok(Gain(v))
        } else {
            Err(serde::de::Error::custom(format!(
                "{v} is not a finite number ≥ 0"
            )))
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ParamsFile {
    ecf: Option<EcfTable>,
    gda: Option<GdaTable>,
    ekf: Option<EkfTable>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EcfTable {
    kp: Option<Gain>,
    ki: Option<Gain>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GdaTable {
    beta: Option<Gain>,
    normalization: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EkfTable {
    gyro_noise: Option<Gain>,
    gyro_bias_walk: Option<Gain>,
    accel_noise: Option<Gain>,
    mag_noise: Option<Gain>,
    initial_attitude_std: Option<Gain>,
    initial_bias_std: Option<Gain>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use margemu_filters::Initial;

    #[test]
    fn file_tables_name_every_tunable_parameter() {
        for kind in FilterKind::ALL {
            let mut p = FilterParams::defaults(kind);
            for (i, spec) in kind.params().iter().enumerate() {
                p.set(spec.name, 1.0 + i as f64).unwrap();
            }
            let back = FilterParams::from_toml(&p.to_toml(), Path::new("x.toml"), kind).unwrap();
            assert_eq!(back, p, "{kind}");
            for name in super::super::setting_names(kind) {
                let value = if *name == "normalization" {
                    "xio"
                } else {
                    "0.25"
                };
                p.set_setting(name, value).unwrap();
            }
            let text = p.to_toml();
            let back = FilterParams::from_toml(&text, Path::new("x.toml"), kind).unwrap();
            assert_eq!(back, p, "{kind}: {text}");
            assert!(p.build([0.5, 0.0, -0.83], Initial::FirstSample).is_ok());
        }
    }

    #[test]
    fn bad_files_point_at_line_and_column() {
        let path = Path::new("p.toml");
        let err = |text: &str, kind| {
            FilterParams::from_toml(text, path, kind)
                .unwrap_err()
                .to_string()
        };
        let e = err("[ecf]\nkp = -1.0\n", FilterKind::Ecf);
        assert!(e.starts_with("p.toml:2:6: "), "{e}");
        assert!(e.contains("-1 is not a finite number ≥ 0"), "{e}");
        let e = err("[ekf]\ngyro_noise = 0.1\nbeta = 0.2\n", FilterKind::Ekf);
        assert!(e.starts_with("p.toml:3:1: "), "{e}");
        assert!(e.contains("unknown field `beta`"), "{e}");
        let e = err("[gda]\nbeta = \"fast\"\n", FilterKind::Gda);
        assert!(e.starts_with("p.toml:2:8: "), "{e}");
    }
}
