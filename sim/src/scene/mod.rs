//! Scenes: one TOML file describes one run.
//!
//! A scene names its duration, output rate and seed, how the plate moves ([`MotionMode`]: the
//! closed-loop bench of the paper, prescribed kinematics, or a static pose), the bench parameters
//! (Table 1 as defaults), the control requirements (Table 2 as defaults), the integrator, the
//! reference magnetic field, per joint a reference source, the sensor error terms and the
//! magnetic perturbation ([`sensors`]). The schema is documented in the
//! user guide (`docs/scene-files.md`); every key is optional except `duration`, `rate` and `seed`.
//!
//! [`Scene::load`] reads, parses and validates a file. Every failure is a [`SceneError`] that
//! names the file, the line and column, and the reason. The fixture scenes are built in
//! ([`builtin`]): commands take a scene argument through [`builtin::resolve`], a file's path or
//! a built-in scene's name.
//!
//! ```
//! let scene = margemu_sim::scene::Scene::parse_str(
//!     "duration = 1.0\nrate = 200.0\nseed = 7\nmotion = \"static\"\n",
//!     std::path::Path::new("inline.toml"),
//! ).unwrap();
//! assert_eq!(scene.samples(), 200);
//! ```

pub mod builtin;
pub mod chip;
mod error;
pub mod fault;
pub mod ranges;
pub mod rig;
mod schema;
pub mod sensors;
pub mod size;
mod validate;
pub mod vibration;
mod warnings;

pub use error::{SceneError, SceneWarning};
pub use schema::*;

use margemu_model::time::{Nanos, SampleClock};
use std::path::{Path, PathBuf};

/// A parsed and validated scene, with where it came from.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The scene's content.
    pub spec: SceneSpec,
    /// The file it was read from (relative paths inside it resolve against its folder), or
    /// `builtin:NAME` for a built-in scene ([`builtin`]).
    pub path: PathBuf,
    /// The exact text of the file (kept for the run's metadata and hash).
    pub text: String,
    /// Output sample clock.
    pub clock: SampleClock,
    /// Run length in nanoseconds.
    pub duration_ns: Nanos,
    /// Integrator sub-step in nanoseconds.
    pub step_ns: Nanos,
    /// The primary chip, device 0 of the rig: `[chip]`, the first `[[device]]`, or the default
    /// MPU-9250.
    pub chip: chip::ChipSetup,
    /// Device 0's name in the logs.
    pub chip_name: String,
    /// The rig's other devices (`[[device]]` after the first), in order ([`rig`]).
    pub other_devices: Vec<rig::Device>,
    /// The vibration reaching each device, in [`Scene::devices`]' order (empty entries when the
    /// scene has no `[vibration]`).
    pub vibration: Vec<vibration::DeviceVibration>,
    /// Where the devices' sampling chains run (`[vibration] path`).
    pub sampling: vibration::SamplingPath,
    /// Legal but likely wrong inputs, located (commands print them once, to stderr).
    pub warnings: Vec<SceneWarning>,
    /// The fault schedule (`[[fault]]`), validated, in file order; each fault's `device` is its
    /// index in [`Scene::devices`]. Empty when the scene has none.
    pub faults: Vec<margemu_model::fault::Fault>,
}

impl Scene {
    /// Reads, parses and validates the scene file at `path` (a regular file of at most
    /// [`crate::input_file::MAX_INPUT_BYTES`], UTF-8).
    pub fn load(path: &Path) -> Result<Self, SceneError> {
        let bytes = crate::input_file::read(path).map_err(|e| SceneError::input(path, &e))?;
        let text =
            std::str::from_utf8(&bytes).map_err(|e| SceneError::not_utf8(path, &bytes, &e))?;
        Self::parse_str(text, path)
    }

    /// Parses and validates scene text; `path` names it in errors and anchors relative paths.
    pub fn parse_str(text: &str, path: &Path) -> Result<Self, SceneError> {
        let spec: SceneSpec =
            toml::from_str(text).map_err(|e| SceneError::from_toml(path, text, &e))?;
        let checked =
            validate::check(&spec).map_err(|v| SceneError::from_violation(path, text, v))?;
        let warnings = checked
            .warnings
            .into_iter()
            .map(|v| SceneWarning(SceneError::from_violation(path, text, v)))
            .collect();
        let mut scene = Self {
            spec,
            path: path.to_path_buf(),
            text: text.to_owned(),
            clock: checked.clock,
            duration_ns: checked.duration_ns,
            step_ns: checked.step_ns,
            chip: checked.primary.chip,
            chip_name: checked.primary.name,
            other_devices: checked.others,
            vibration: Vec::new(),
            sampling: vibration::SamplingPath::Auto,
            warnings,
            faults: checked.faults,
        };
        scene.check_gains()?;
        scene.resolve_vibration()?;
        Ok(scene)
    }

    /// Fills [`Scene::vibration`] and [`Scene::sampling`] from `[vibration]`, and adds its
    /// warnings.
    fn resolve_vibration(&mut self) -> Result<(), SceneError> {
        let devices = self.devices();
        let (spec, located) = (&self.spec, |v| {
            SceneError::from_violation(&self.path, &self.text, v)
        });
        let per_device = vibration::resolve(&spec.vibration, &devices, spec.rate, self.base_dir())
            .map_err(located)?;
        let warnings = vibration::warnings(
            &spec.vibration,
            &devices,
            &per_device,
            spec.rate,
            spec.duration,
        );
        let warnings: Vec<_> = warnings
            .into_iter()
            .map(|v| SceneWarning(located(v)))
            .collect();
        self.sampling = spec.vibration.path;
        self.vibration = per_device;
        self.warnings.extend(warnings);
        Ok(())
    }

    /// Every device of the scene's rig, device 0 ([`Scene::chip`]) first.
    pub fn devices(&self) -> Vec<rig::Device> {
        let primary = rig::Device {
            name: self.chip_name.clone(),
            chip: self.chip,
        };
        std::iter::once(primary)
            .chain(self.other_devices.iter().cloned())
            .collect()
    }

    /// Whether the scene serves several devices at once.
    pub fn is_rig(&self) -> bool {
        !self.other_devices.is_empty()
    }

    /// The PID gains a bench scene derives (or gives) must be finite; they are refused at the
    /// `[bench]` and `[control]` inputs they come from.
    fn check_gains(&self) -> Result<(), SceneError> {
        if self.spec.motion != MotionMode::Bench || self.spec.control.gains.is_some() {
            return Ok(());
        }
        let designs = crate::bench::designs(self);
        for (i, design) in designs.iter().enumerate() {
            let Some(d) = design else { continue };
            let g = d.gains;
            if [g.kp, g.ki, g.kd, d.time_constant]
                .iter()
                .all(|x| x.is_finite())
            {
                continue;
            }
            let mass_key = if i < 3 { "link_mass" } else { "plate_inertia" };
            let (masses, _) = crate::bench::masses_and_loads(self);
            return Err(SceneError::at_keys(
                &self.path,
                &self.text,
                &["bench", mass_key],
                format!(
                    "the PID gains of joint {} are not finite (Kp {}, Ki {}, Kd {}) for the                      mass {} from [bench] (link_mass, plate_mass, plate_inertia),                      viscous_friction {} and [control] settling_time {} s",
                    JOINT_NAMES[i],
                    g.kp,
                    g.ki,
                    g.kd,
                    ranges::number(masses[i]),
                    ranges::number(self.spec.bench.viscous_friction[i]),
                    ranges::number(self.spec.control.settling_time[i]),
                ),
            ));
        }
        Ok(())
    }

    /// Number of output samples: those latched in `[0, duration)`.
    pub fn samples(&self) -> u64 {
        self.clock.count_before(self.duration_ns)
    }

    /// `file:line:col` of the value at key path `keys` (or of its nearest ancestor in the
    /// file), for messages about what that value caused.
    pub fn location(&self, keys: &[&str]) -> String {
        SceneError::location(&self.path, &self.text, keys)
    }

    /// The scene's short name, which default run and session directory names use: a built-in
    /// scene's name, or the file's name without its extension.
    pub fn stem(&self) -> String {
        match builtin::name_of(&self.path) {
            Some(name) => name.to_owned(),
            None => self
                .path
                .file_stem()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned(),
        }
    }

    /// The folder relative paths in the scene resolve against.
    pub fn base_dir(&self) -> &Path {
        self.path.parent().unwrap_or(Path::new("."))
    }

    /// SHA-256 of the scene text, as lowercase hex.
    pub fn hash(&self) -> String {
        use sha2::{Digest, Sha256};
        Sha256::digest(self.text.as_bytes())
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gains that overflow are refused at the `[bench]` input they come from (validation's
    /// ranges keep loaded scenes from getting here; this checks the last line of defence).
    #[test]
    fn non_finite_gains_are_refused_at_the_bench() {
        let text = "duration = 1.0\nrate = 100.0\nseed = 1\n[bench]\nlink_mass = [1.0, 1.0, 1.0]\n";
        let mut scene = Scene::parse_str(text, Path::new("gains.toml")).unwrap();
        scene.spec.bench.link_mass = [1e300; 3];
        scene.spec.bench.plate_mass = 1e308;
        let e = scene.check_gains().unwrap_err().to_string();
        assert!(
            e.starts_with(
                "gains.toml:5:13: `bench.link_mass`: the PID gains of joint x are not finite \
                 (Kp inf"
            ),
            "{e}"
        );
        assert!(
            e.contains("from [bench] (link_mass, plate_mass, plate_inertia)"),
            "{e}"
        );
    }
}
