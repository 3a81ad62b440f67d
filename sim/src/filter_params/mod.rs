//! Which reference filter runs, with which parameters: the parameters the paper tunes (ECF:
//! `kp`, `ki`; GDA: `beta`; EKF: its four noise statistics), their defaults (the filters
//! crate's), the range a tuner searches, and the TOML file that carries tuned values.
//!
//! Every other setting of a filter keeps the `margemu-filters` default (the GDA's Madgwick
//! normalization, the EKF's initial standard deviations, the start from the first sample); the
//! magnetic reference comes from the recording.
//!
//! A parameters file has one table per filter, each key optional (absent keys keep their
//! default), so one file can hold the tuned values of all three:
//!
//! ```toml
//! [ecf]
//! kp = 1.8
//! ki = 0.0
//!
//! [ekf]
//! gyro_noise = 0.05
//! ```
//!
//! ```
//! use margemu_sim::filter_params::{FilterKind, FilterParams};
//! let mut p = FilterParams::defaults(FilterKind::Ecf);
//! p.set("kp", 2.0)?;
//! assert_eq!(p.get("kp"), Some(2.0));
//! assert!(p.set("beta", 0.1).is_err()); // not an ECF parameter
//! let text = p.to_toml();
//! let back = FilterParams::from_toml(&text, std::path::Path::new("p.toml"), FilterKind::Ecf)?;
//! assert_eq!(back, p);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::scene::SceneError;
use margemu_filters::{AttitudeFilter, Ecf, EcfConfig, Ekf, EkfConfig, Gda, GdaConfig, Initial};
use std::fmt;
use std::str::FromStr;

mod file;

/// One of the paper's three reference filters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum FilterKind {
    /// Explicit complementary filter, eq. 24.
    Ecf,
    /// Gradient-descent filter, eq. 25.
    Gda,
    /// Quaternion extended Kalman filter, eq. 26.
    Ekf,
}

/// A tunable parameter of a filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamSpec {
    /// Its name, as the filter's configuration and the parameters file spell it.
    pub name: &'static str,
    /// The filter's default.
    pub default: f64,
    /// Smallest value a tuner tries (> 0: tuners search `ln` of the value).
    pub lower: f64,
    /// Largest value a tuner tries.
    pub upper: f64,
    /// Whether the value at `lower` stands for 0 (a gain that may be switched off).
    pub zero_at_lower: bool,
}

const fn spec(name: &'static str, default: f64, lower: f64, upper: f64) -> ParamSpec {
    ParamSpec {
        name,
        default,
        lower,
        upper,
        zero_at_lower: false,
    }
}

const ECF: [ParamSpec; 2] = [
    spec("kp", 0.5, 1e-3, 100.0),
    ParamSpec {
        zero_at_lower: true,
        ..spec("ki", 0.0, 1e-4, 10.0)
    },
];
const GDA: [ParamSpec; 1] = [spec("beta", 0.1, 1e-4, 10.0)];
const EKF: [ParamSpec; 4] = [
    spec("gyro_noise", 0.0224, 1e-4, 10.0),
    spec("gyro_bias_walk", 1e-4, 1e-8, 1.0),
    spec("accel_noise", 0.5, 1e-3, 100.0),
    spec("mag_noise", 0.5, 1e-3, 100.0),
];

impl FilterKind {
    /// The three filters, in the paper's order.
    pub const ALL: [Self; 3] = [Self::Ecf, Self::Gda, Self::Ekf];

    /// Lower-case name (`ecf`, `gda`, `ekf`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Ecf => "ecf",
            Self::Gda => "gda",
            Self::Ekf => "ekf",
        }
    }

    /// Its tunable parameters.
    pub fn params(self) -> &'static [ParamSpec] {
        match self {
            Self::Ecf => &ECF,
            Self::Gda => &GDA,
            Self::Ekf => &EKF,
        }
    }
}

impl fmt::Display for FilterKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for FilterKind {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s.to_ascii_lowercase())
            .ok_or_else(|| format!("unknown filter `{s}` (ecf, gda or ekf)"))
    }
}

/// A filter and values for its tunable parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct FilterParams {
    kind: FilterKind,
    /// In the order of `kind.params()`.
    values: Vec<f64>,
}

/// A parameter name or value that was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error, docsplay::Display)]
pub enum ParamError {
    /// {kind} has no parameter `{name}` (it has: {names})
    Unknown {
        /// The filter.
        kind: FilterKind,
        /// The name given.
        name: String,
        /// The names there are.
        names: String,
    },
    /// `{name}` = {value}: must be finite and ≥ 0
    Value {
        /// The parameter.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// `{0}`: expected NAME=VALUE
    Syntax(String),
    /// {0}
    File(SceneError),
    /// {0}
    Filter(margemu_filters::Error),
}

impl FilterParams {
    /// The filter's defaults.
    pub fn defaults(kind: FilterKind) -> Self {
        Self {
            kind,
            values: kind.params().iter().map(|p| p.default).collect(),
        }
    }

    /// The filter.
    pub fn kind(&self) -> FilterKind {
        self.kind
    }

    /// `(spec, value)` per parameter, in order.
    pub fn iter(&self) -> impl Iterator<Item = (&'static ParamSpec, f64)> + '_ {
        self.kind.params().iter().zip(self.values.iter().copied())
    }

    /// The values, in the order of `kind().params()`.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The value of parameter `name`.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.iter().find(|(p, _)| p.name == name).map(|(_, v)| v)
    }

    /// Sets parameter `name` (finite, ≥ 0).
    pub fn set(&mut self, name: &str, value: f64) -> Result<(), ParamError> {
        let specs = self.kind.params();
        let i = specs
            .iter()
            .position(|p| p.name == name)
            .ok_or_else(|| ParamError::Unknown {
                kind: self.kind,
                name: name.to_owned(),
                names: specs.iter().map(|p| p.name).collect::<Vec<_>>().join(", "),
            })?;
        if !(value.is_finite() && value >= 0.0) {
            return Err(ParamError::Value {
                name: specs[i].name,
                value,
            });
        }
        self.values[i] = value;
        Ok(())
    }

    /// Sets a parameter from `NAME=VALUE` (the command line's `--param`).
    pub fn set_assignment(&mut self, text: &str) -> Result<(), ParamError> {
        let syntax = || ParamError::Syntax(text.to_owned());
        let (name, value) = text.split_once('=').ok_or_else(syntax)?;
        let value: f64 = value.trim().parse().map_err(|_| syntax())?;
        self.set(name.trim(), value)
    }

    /// A filter in `f64` with these parameters, the magnetic reference `mag_reference` (world
    /// frame) and the start `initial`.
    pub fn build(
        &self,
        mag_reference: [f64; 3],
        initial: Initial,
    ) -> Result<Box<dyn AttitudeFilter<f64> + Send>, ParamError> {
        let v = |name| self.get(name).expect("a parameter of this kind");
        let built: Result<Box<dyn AttitudeFilter<f64> + Send>, _> = match self.kind {
            FilterKind::Ecf => Ecf::new(&EcfConfig {
                kp: v("kp"),
                ki: v("ki"),
                mag_reference,
                initial,
            })
            .map(|f| Box::new(f) as _),
            FilterKind::Gda => Gda::new(&GdaConfig {
                beta: v("beta"),
                mag_reference,
                initial,
                ..GdaConfig::default()
            })
            .map(|f| Box::new(f) as _),
            FilterKind::Ekf => Ekf::new(&EkfConfig {
                gyro_noise: v("gyro_noise"),
                gyro_bias_walk: v("gyro_bias_walk"),
                accel_noise: v("accel_noise"),
                mag_noise: v("mag_noise"),
                mag_reference,
                initial,
                ..EkfConfig::default()
            })
            .map(|f| Box::new(f) as _),
        };
        built.map_err(ParamError::Filter)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_and_specs_agree_with_the_filters_crate() {
        let ecf = EcfConfig::default();
        let ekf = EkfConfig::default();
        let d = |k| FilterParams::defaults(k);
        assert_eq!(d(FilterKind::Ecf).values(), &[ecf.kp, ecf.ki]);
        assert_eq!(d(FilterKind::Gda).values(), &[GdaConfig::default().beta]);
        assert_eq!(
            d(FilterKind::Ekf).values(),
            &[
                ekf.gyro_noise,
                ekf.gyro_bias_walk,
                ekf.accel_noise,
                ekf.mag_noise
            ]
        );
        for kind in FilterKind::ALL {
            for p in kind.params() {
                assert!(0.0 < p.lower && p.lower < p.upper, "{}", p.name);
                let inside = p.lower <= p.default && p.default <= p.upper;
                assert!(
                    inside || (p.zero_at_lower && p.default == 0.0),
                    "{}",
                    p.name
                );
            }
        }
    }

    #[test]
    fn assignments_parse_and_refuse() {
        let mut p = FilterParams::defaults(FilterKind::Gda);
        p.set_assignment("beta = 0.3").unwrap();
        assert_eq!(p.get("beta"), Some(0.3));
        let e = p.set_assignment("kp=1").unwrap_err().to_string();
        assert_eq!(e, "gda has no parameter `kp` (it has: beta)");
        let e = p.set_assignment("beta").unwrap_err().to_string();
        assert_eq!(e, "`beta`: expected NAME=VALUE");
        let e = p.set_assignment("beta=nan").unwrap_err().to_string();
        assert_eq!(e, "`beta` = NaN: must be finite and ≥ 0");
    }
}
