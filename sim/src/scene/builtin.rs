//! Built-in scenes: the fixture scenes of `hil-fixtures/scenes/`, compiled into the library
//! (their text is the files' text, byte for byte) and addressed by name, so a command runs one
//! from any directory.
//!
//! **A scene argument** ([`resolve`]) is, in this order:
//! 1. `builtin:NAME`: the built-in scene `NAME` (whatever files exist);
//! 2. a path at which something exists: that file, read by [`Scene::load`];
//! 3. the name of a built-in scene (`figure3`);
//! 4. otherwise an error naming the argument, saying no such file exists and listing the
//!    built-in names.
//!
//! **Recorded as** `builtin:NAME`: that is a built-in scene's [`Scene::path`], so errors name
//! it (`builtin:figure3:5:1: …`) and run metadata records it as `scene_file` (beside the text
//! and its SHA-256, which equal the fixture file's). [`Scene::stem`] is `NAME`, which default
//! run and session directory names use.
//!
//! Built-in scenes read no other files (no CSV joint sources or rpm profiles); a unit test holds
//! them to it.

use super::{Scene, SceneError};
use std::path::{Path, PathBuf};

/// What a built-in scene's [`Scene::path`] starts with, and what an argument may start with to
/// ask for a built-in scene whatever files exist.
pub const PREFIX: &str = "builtin:";

macro_rules! builtins {
    ($($name:literal),* $(,)?) => {
        /// The built-in scenes' names, sorted.
        pub const NAMES: &[&str] = &[$($name),*];
        /// Their text, in the order of [`NAMES`].
        const TEXTS: &[&str] =
            &[$(include_str!(concat!("../../../hil-fixtures/scenes/", $name, ".toml"))),*];
    };
}

builtins!(
    "bmi270",
    "case-study",
    "figure3",
    "gimbal-lock",
    "icm42688p",
    "mpu6000",
    "rig",
    "static",
    "vibration"
);

/// The text of the built-in scene `name` (a bare name, without [`PREFIX`]).
pub fn get(name: &str) -> Option<&'static str> {
    NAMES.iter().position(|n| *n == name).map(|i| TEXTS[i])
}

/// The built-in scene `name` (a bare name), parsed and validated; its path is `builtin:NAME`.
pub fn load(name: &str) -> Result<Scene, SceneError> {
    match get(name) {
        Some(text) => Scene::parse_str(text, &path_of(name)),
        None => Err(unknown(Path::new(&format!("{PREFIX}{name}")), false)),
    }
}

/// The built-in name `path` stands for, if it is a built-in scene's path (`builtin:NAME`).
pub fn name_of(path: &Path) -> Option<&'static str> {
    let name = path.to_str()?.strip_prefix(PREFIX)?;
    NAMES.iter().copied().find(|n| *n == name)
}

/// The scene an argument stands for: a file if one exists at `arg`, else a built-in scene's
/// name (see the module's documentation for the order and the error).
pub fn resolve(arg: &Path) -> Result<Scene, SceneError> {
    if let Some(name) = arg.to_str().and_then(|a| a.strip_prefix(PREFIX)) {
        return load(name);
    }
    // Anything there (or a path that cannot be looked at) is the user's file: loading it says
    // what is wrong with it.
    let missing = matches!(
        std::fs::symlink_metadata(arg),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound
    );
    if !missing {
        return Scene::load(arg);
    }
    match arg.to_str().filter(|a| get(a).is_some()) {
        Some(name) => load(name),
        None => Err(unknown(arg, true)),
    }
}

fn path_of(name: &str) -> PathBuf {
    PathBuf::from(format!("{PREFIX}{name}"))
}

/// The error for an argument that is neither an existing file (`as_file`: it was looked for as
/// one) nor a built-in scene.
fn unknown(arg: &Path, as_file: bool) -> SceneError {
    let names = NAMES.join(", ");
    let reason = if !as_file {
        format!("no built-in scene has that name (built-in scenes: {names})")
    } else if looks_like_a_path(arg) {
        format!("no such file (built-in scenes, by name: {names})")
    } else {
        format!("no such file, and no built-in scene has that name (built-in scenes: {names})")
    };
    SceneError {
        file: arg.to_path_buf(),
        position: None,
        reason,
    }
}

/// Whether `arg` was meant as a file rather than a name: it has a folder or an extension.
fn looks_like_a_path(arg: &Path) -> bool {
    arg.components().count() > 1 || arg.extension().is_some()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::SourceSpec;

    /// Every fixture scene is built in (none forgotten), under its file's stem.
    #[test]
    fn every_fixture_scene_is_built_in() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../hil-fixtures/scenes");
        let mut stems: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
            .collect();
        stems.sort();
        assert_eq!(stems, NAMES);
        for name in NAMES {
            let file = std::fs::read_to_string(dir.join(format!("{name}.toml"))).unwrap();
            assert_eq!(get(name), Some(file.as_str()), "{name}");
        }
    }

    /// Every built-in scene loads without warnings, reads no file (so it runs from any
    /// directory) and names itself `builtin:NAME`.
    #[test]
    fn built_in_scenes_load_cleanly_and_read_no_files() {
        for name in NAMES {
            let scene = load(name).unwrap();
            assert_eq!(scene.path, Path::new(&format!("builtin:{name}")));
            assert_eq!(scene.stem(), *name);
            assert_eq!(name_of(&scene.path), Some(*name));
            assert!(scene.warnings.is_empty(), "{name}: {:?}", scene.warnings);
            for (joint, source) in &scene.spec.joints {
                assert!(
                    !matches!(source, SourceSpec::Csv { .. }),
                    "{name}: joint {joint} reads a CSV file"
                );
            }
            for (i, tone) in scene.spec.vibration.tones.iter().enumerate() {
                assert!(tone.rpm_csv.is_none(), "{name}: tone {i} reads a CSV file");
            }
            crate::motion::Motion::new(&scene).unwrap();
        }
    }

    #[test]
    fn names_resolve_to_built_in_scenes_and_paths_to_files() {
        let dir = std::env::temp_dir().join(format!("margemu-builtin-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // A file shadows a name; `builtin:` does not look at files.
        let file = dir.join("figure3");
        std::fs::write(&file, "duration = 1.0\nrate = 10.0\nseed = 1\n").unwrap();
        assert_eq!(resolve(&file).unwrap().path, file);
        assert_eq!(resolve(Path::new("figure3")).unwrap().stem(), "figure3");
        let explicit = resolve(Path::new("builtin:figure3")).unwrap();
        assert_eq!(explicit.text, get("figure3").unwrap());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn unknown_arguments_list_the_built_in_names() {
        let list =
            "bmi270, case-study, figure3, gimbal-lock, icm42688p, mpu6000, rig, static, vibration";
        let e = resolve(Path::new("figure4")).unwrap_err().to_string();
        assert_eq!(
            e,
            format!(
                "figure4: no such file, and no built-in scene has that name (built-in scenes: {list})"
            )
        );
        let e = resolve(Path::new("scenes/figure3.toml"))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            format!("scenes/figure3.toml: no such file (built-in scenes, by name: {list})")
        );
        let e = resolve(Path::new("builtin:figure4"))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            format!("builtin:figure4: no built-in scene has that name (built-in scenes: {list})")
        );
    }
}
