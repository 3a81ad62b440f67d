//! Helpers shared by the system tests in `tests/tests/`: where the fixtures live and how to run
//! the `margemu` binary on them; [`qemu`] builds the QEMU board firmware and boots it.

use std::path::PathBuf;

pub mod qemu;

/// The workspace root.
pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A scene from `hil-fixtures/scenes/`.
pub fn fixture_scene(name: &str) -> PathBuf {
    workspace_root().join("hil-fixtures/scenes").join(name)
}
