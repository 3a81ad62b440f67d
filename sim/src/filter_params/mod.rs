//! Which reference filter runs, with which parameters: the parameters the paper tunes (ECF:
//! `kp`, `ki`; GDA: `beta`; EKF: its four noise statistics), their defaults (the filters
//! crate's), the range a tuner searches, and the TOML file that carries tuned values.
//!
//! The other settings of a filter, not tuned but settable ([`Settings`], by `--param` and in
//! the file, default the `margemu-filters` ones): the GDA's `normalization` (`gradient`,
//! `residual` or `xio`, see `margemu_filters::gda`) and the EKF's `initial_attitude_std` and
//! `initial_bias_std`. The magnetic reference and the start have options of their own. A name
//! may carry its filter as a prefix (`gda.beta`).
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
use margemu_filters::{
    AttitudeFilter, Ecf, EcfConfig, Ekf, EkfConfig, Gda, GdaConfig, GdaNormalization, Initial,
};
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
    /// The settings that are not tuned.
    settings: Settings,
}

/// A filter's settings that tuners leave alone (see the module docs); each applies to one
/// filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// GDA: what the gradient step is divided by (`normalization`).
    pub normalization: GdaNormalization,
    /// EKF: initial standard deviation of each quaternion component (`initial_attitude_std`).
    pub initial_attitude_std: f64,
    /// EKF: initial standard deviation of each gyro bias component, rad/s (`initial_bias_std`).
    pub initial_bias_std: f64,
}

impl Default for Settings {
    fn default() -> Self {
        let ekf = EkfConfig::default();
        Self {
            normalization: GdaConfig::default().normalization,
            initial_attitude_std: ekf.initial_attitude_std,
            initial_bias_std: ekf.initial_bias_std,
        }
    }
}

/// The names of the settings of `kind`.
pub fn setting_names(kind: FilterKind) -> &'static [&'static str] {
    match kind {
        FilterKind::Ecf => &[],
        FilterKind::Gda => &["normalization"],
        FilterKind::Ekf => &["initial_attitude_std", "initial_bias_std"],
    }
}

/// The name of a GDA normalization, as `--param normalization=` spells it.
pub fn normalization_name(n: GdaNormalization) -> &'static str {
    match n {
        GdaNormalization::Gradient => "gradient",
        GdaNormalization::Residual => "residual",
        GdaNormalization::Xio => "xio",
    }
}

/// The GDA normalization named `text`.
pub fn parse_normalization(text: &str) -> Result<GdaNormalization, ParamError> {
    [
        GdaNormalization::Gradient,
        GdaNormalization::Residual,
        GdaNormalization::Xio,
    ]
    .into_iter()
    .find(|n| normalization_name(*n) == text)
    .ok_or_else(|| ParamError::Setting {
        name: "normalization",
        reason: format!("`{text}` is not gradient, residual or xio"),
    })
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
    /// `{name}`: {reason}
    Setting {
        /// The setting.
        name: &'static str,
        /// Why the value was refused.
        reason: String,
    },
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
            settings: Settings::default(),
        }
    }

    /// The settings that are not tuned.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Sets the setting `name` of this filter from its text (see the module docs).
    pub fn set_setting(&mut self, name: &str, text: &str) -> Result<(), ParamError> {
        let std = |name: &'static str| -> Result<f64, ParamError> {
            match text.parse::<f64>() {
                Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
                _ => Err(ParamError::Setting {
                    name,
                    reason: format!("`{text}` is not a finite number > 0"),
                }),
            }
        };
        match (self.kind, name) {
            (FilterKind::Gda, "normalization") => {
                self.settings.normalization = parse_normalization(text)?;
            }
            (FilterKind::Ekf, "initial_attitude_std") => {
                self.settings.initial_attitude_std = std("initial_attitude_std")?;
            }
            (FilterKind::Ekf, "initial_bias_std") => {
                self.settings.initial_bias_std = std("initial_bias_std")?;
            }
            _ => return Err(self.unknown(name)),
        }
        Ok(())
    }

    /// `NAME=VALUE` of every parameter, then of every setting, of this filter (what a run used).
    pub fn assignments(&self) -> Vec<String> {
        let mut out: Vec<String> = self
            .iter()
            .map(|(p, v)| format!("{}={v}", p.name))
            .collect();
        for name in setting_names(self.kind) {
            let value = match *name {
                "normalization" => normalization_name(self.settings.normalization).to_owned(),
                "initial_attitude_std" => self.settings.initial_attitude_std.to_string(),
                _ => self.settings.initial_bias_std.to_string(),
            };
            out.push(format!("{name}={value}"));
        }
        out
    }

    fn unknown(&self, name: &str) -> ParamError {
        let specs = self.kind.params().iter().map(|p| p.name);
        ParamError::Unknown {
            kind: self.kind,
            name: name.to_owned(),
            names: specs
                .chain(setting_names(self.kind).iter().copied())
                .collect::<Vec<_>>()
                .join(", "),
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
            .ok_or_else(|| self.unknown(name))?;
        if !(value.is_finite() && value >= 0.0) {
            return Err(ParamError::Value {
                name: specs[i].name,
                value,
            });
        }
        self.values[i] = value;
        Ok(())
    }

    /// Sets a parameter or a setting from `NAME=VALUE` (the command line's `--param`); `NAME`
    /// may carry the filter as a prefix (`gda.beta=0.2`).
    pub fn set_assignment(&mut self, text: &str) -> Result<(), ParamError> {
        let syntax = || ParamError::Syntax(text.to_owned());
        let (name, value) = text.split_once('=').ok_or_else(syntax)?;
        let (name, value) = (name.trim(), value.trim());
        let prefix = format!("{}.", self.kind);
        let name = name.strip_prefix(prefix.as_str()).unwrap_or(name);
        if setting_names(self.kind).contains(&name) {
            return self.set_setting(name, value);
        }
        let value: f64 = value.parse().map_err(|_| syntax())?;
        self.set(name, value)
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
                normalization: self.settings.normalization,
                mag_reference,
                initial,
            })
            .map(|f| Box::new(f) as _),
            FilterKind::Ekf => Ekf::new(&EkfConfig {
                gyro_noise: v("gyro_noise"),
                gyro_bias_walk: v("gyro_bias_walk"),
                accel_noise: v("accel_noise"),
                mag_noise: v("mag_noise"),
                initial_attitude_std: self.settings.initial_attitude_std,
                initial_bias_std: self.settings.initial_bias_std,
                mag_reference,
                initial,
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
        assert_eq!(e, "gda has no parameter `kp` (it has: beta, normalization)");
        let e = p.set_assignment("beta").unwrap_err().to_string();
        assert_eq!(e, "`beta`: expected NAME=VALUE");
        let e = p.set_assignment("beta=nan").unwrap_err().to_string();
        assert_eq!(e, "`beta` = NaN: must be finite and ≥ 0");
        p.set_assignment("gda.beta=0.4").unwrap();
        assert_eq!(p.get("beta"), Some(0.4));
        p.set_assignment("normalization = xio").unwrap();
        assert_eq!(p.settings().normalization, GdaNormalization::Xio);
        let e = p
            .set_assignment("gda.normalization=fast")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "`normalization`: `fast` is not gradient, residual or xio"
        );
        let e = p.set_assignment("ekf.beta=1").unwrap_err().to_string();
        assert_eq!(
            e,
            "gda has no parameter `ekf.beta` (it has: beta, normalization)"
        );
        let mut k = FilterParams::defaults(FilterKind::Ekf);
        k.set_assignment("initial_bias_std=0.01").unwrap();
        assert_eq!(k.settings().initial_bias_std, 0.01);
        let e = k
            .set_assignment("initial_attitude_std=0")
            .unwrap_err()
            .to_string();
        assert_eq!(e, "`initial_attitude_std`: `0` is not a finite number > 0");
    }
}
