//! Which reference filter the virtual flight controller runs, and with which parameters: the
//! `margemu-filters` defaults, or a parameters file.
//!
//! The file has one table per filter; every key is optional (absent keys keep the filter's
//! default), so one file can carry the tuned values of all three. Unknown tables or keys, and
//! values that are not finite numbers ≥ 0, are errors at their line and column:
//!
//! ```toml
//! [ecf]
//! kp = 1.8
//! ki = 0.01
//!
//! [gda]
//! beta = 0.3
//!
//! [ekf]
//! gyro_noise = 0.05
//! gyro_bias_walk = 1e-4
//! accel_noise = 0.8
//! mag_noise = 0.6
//! ```
//!
//! Only the parameters the paper tunes are read (ECF `kp`, `ki`; GDA `beta`; EKF its four noise
//! statistics); everything else keeps the filters crate's default, and the filter starts from
//! its first sample.
//!
//! ```
//! use margemu::vfc::{FilterKind, FilterParams};
//! let p = FilterParams::from_toml("[gda]\nbeta = 0.25\n", "p.toml".as_ref(), FilterKind::Gda)?;
//! assert_eq!(p.values(), vec![("beta", 0.25)]);
//! let ecf = FilterParams::from_toml("[gda]\nbeta = 0.25\n", "p.toml".as_ref(), FilterKind::Ecf)?;
//! assert_eq!(ecf, FilterParams::defaults(FilterKind::Ecf));
//! # Ok::<(), margemu::scene::SceneError>(())
//! ```

use crate::scene::SceneError;
use margemu_filters::{AttitudeFilter, Ecf, EcfConfig, Ekf, EkfConfig, Gda, GdaConfig, Initial};
use serde::{Deserialize, Deserializer};
use std::fmt;
use std::path::Path;

/// One of the paper's three reference filters (`--vfc ecf|gda|ekf`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum FilterKind {
    /// Explicit complementary filter (eq. 24).
    Ecf,
    /// Gradient-descent filter (eq. 25).
    Gda,
    /// Quaternion extended Kalman filter (eq. 26).
    Ekf,
}

impl FilterKind {
    /// The three, in the paper's order.
    pub const ALL: [Self; 3] = [Self::Ecf, Self::Gda, Self::Ekf];

    /// `ecf`, `gda` or `ekf`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Ecf => "ecf",
            Self::Gda => "gda",
            Self::Ekf => "ekf",
        }
    }
}

impl fmt::Display for FilterKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A filter with its configuration (the magnetic reference and the start are set when it is
/// built).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FilterParams {
    /// The ECF.
    Ecf(EcfConfig),
    /// The GDA.
    Gda(GdaConfig),
    /// The EKF.
    Ekf(EkfConfig),
}

impl FilterParams {
    /// The filters crate's defaults.
    pub fn defaults(kind: FilterKind) -> Self {
        match kind {
            FilterKind::Ecf => Self::Ecf(EcfConfig::default()),
            FilterKind::Gda => Self::Gda(GdaConfig::default()),
            FilterKind::Ekf => Self::Ekf(EkfConfig::default()),
        }
    }

    /// Which filter.
    pub fn kind(&self) -> FilterKind {
        match self {
            Self::Ecf(_) => FilterKind::Ecf,
            Self::Gda(_) => FilterKind::Gda,
            Self::Ekf(_) => FilterKind::Ekf,
        }
    }

    /// The tuned parameters by name, in the file's order.
    pub fn values(&self) -> Vec<(&'static str, f64)> {
        match self {
            Self::Ecf(c) => vec![("kp", c.kp), ("ki", c.ki)],
            Self::Gda(c) => vec![("beta", c.beta)],
            Self::Ekf(c) => vec![
                ("gyro_noise", c.gyro_noise),
                ("gyro_bias_walk", c.gyro_bias_walk),
                ("accel_noise", c.accel_noise),
                ("mag_noise", c.mag_noise),
            ],
        }
    }

    /// `kp = 0.5, ki = 0` (for reports).
    pub fn describe(&self) -> String {
        let parts: Vec<String> = self
            .values()
            .iter()
            .map(|(n, v)| format!("{n} = {v}"))
            .collect();
        parts.join(", ")
    }

    /// This filter's table of a parameters file.
    pub fn to_toml(&self) -> String {
        let mut out = format!("[{}]\n", self.kind());
        for (name, v) in self.values() {
            out.push_str(&format!("{name} = {v:?}\n"));
        }
        out
    }

    /// The `kind` table of a parameters file's `text` (`path` names it in errors); absent keys
    /// or an absent table keep the defaults.
    pub fn from_toml(text: &str, path: &Path, kind: FilterKind) -> Result<Self, SceneError> {
        let file: ParamsFile =
            toml::from_str(text).map_err(|e| SceneError::from_toml(path, text, &e))?;
        let or = |v: Option<Gain>, default: f64| v.map_or(default, |g| g.0);
        Ok(match Self::defaults(kind) {
            Self::Ecf(d) => {
                let t = file.ecf.unwrap_or_default();
                Self::Ecf(EcfConfig {
                    kp: or(t.kp, d.kp),
                    ki: or(t.ki, d.ki),
                    ..d
                })
            }
            Self::Gda(d) => {
                let t = file.gda.unwrap_or_default();
                Self::Gda(GdaConfig {
                    beta: or(t.beta, d.beta),
                    ..d
                })
            }
            Self::Ekf(d) => {
                let t = file.ekf.unwrap_or_default();
                Self::Ekf(EkfConfig {
                    gyro_noise: or(t.gyro_noise, d.gyro_noise),
                    gyro_bias_walk: or(t.gyro_bias_walk, d.gyro_bias_walk),
                    accel_noise: or(t.accel_noise, d.accel_noise),
                    mag_noise: or(t.mag_noise, d.mag_noise),
                    ..d
                })
            }
        })
    }

    /// Reads the `kind` table of the parameters file at `path`.
    pub fn load(path: &Path, kind: FilterKind) -> Result<Self, SceneError> {
        let text = std::fs::read_to_string(path).map_err(|e| SceneError::io(path, &e))?;
        Self::from_toml(&text, path, kind)
    }

    /// The filter in `f64` against the world field `mag_reference`, starting from its first
    /// sample.
    pub fn build(
        &self,
        mag_reference: [f64; 3],
    ) -> Result<Box<dyn AttitudeFilter<f64> + Send>, margemu_filters::Error> {
        let initial = Initial::FirstSample;
        Ok(match *self {
            Self::Ecf(c) => Box::new(Ecf::new(&EcfConfig {
                mag_reference,
                initial,
                ..c
            })?),
            Self::Gda(c) => Box::new(Gda::new(&GdaConfig {
                mag_reference,
                initial,
                ..c
            })?),
            Self::Ekf(c) => Box::new(Ekf::new(&EkfConfig {
                mag_reference,
                initial,
                ..c
            })?),
        })
    }
}

/// A parameter value: a finite number ≥ 0 (integers allowed).
#[derive(Clone, Copy, Debug)]
struct Gain(f64);

impl<'de> Deserialize<'de> for Gain {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = f64::deserialize(d)?;
        if v.is_finite() && v >= 0.0 {
            Ok(Self(v))
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

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct EcfTable {
    kp: Option<Gain>,
    ki: Option<Gain>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct GdaTable {
    beta: Option<Gain>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct EkfTable {
    gyro_noise: Option<Gain>,
    gyro_bias_walk: Option<Gain>,
    accel_noise: Option<Gain>,
    mag_noise: Option<Gain>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_round_trip_and_build() {
        for kind in FilterKind::ALL {
            let p = FilterParams::defaults(kind);
            let back = FilterParams::from_toml(&p.to_toml(), Path::new("p.toml"), kind).unwrap();
            assert_eq!(back, p, "{kind}");
            assert!(p.build([0.5, 0.0, -0.83]).is_ok());
        }
        let text = "[ekf]\nmag_noise = 2\n[ecf]\nkp = 3.5\n";
        let ekf = FilterParams::from_toml(text, Path::new("p.toml"), FilterKind::Ekf).unwrap();
        assert_eq!(ekf.values()[3], ("mag_noise", 2.0));
        assert_eq!(
            ekf.values()[0],
            ("gyro_noise", EkfConfig::default().gyro_noise)
        );
        let ecf = FilterParams::from_toml(text, Path::new("p.toml"), FilterKind::Ecf).unwrap();
        assert_eq!(ecf.describe(), "kp = 3.5, ki = 0");
    }

    #[test]
    fn bad_files_point_at_line_and_column() {
        let err = |text: &str| {
            FilterParams::from_toml(text, Path::new("p.toml"), FilterKind::Ecf)
                .unwrap_err()
                .to_string()
        };
        let e = err("[ecf]\nkp = -1.0\n");
        assert!(e.starts_with("p.toml:2:6: "), "{e}");
        assert!(e.contains("not a finite number ≥ 0"), "{e}");
        let e = err("[ecf]\nkp = 1.0\nbeta = 0.2\n");
        assert!(e.starts_with("p.toml:3:1: "), "{e}");
        assert!(e.contains("unknown field `beta`"), "{e}");
        let e = err("[madgwick]\nbeta = 0.2\n");
        assert!(e.starts_with("p.toml:1:"), "{e}");
    }
}
