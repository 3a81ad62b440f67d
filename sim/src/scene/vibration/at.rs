//! Key paths into `[vibration]`, to locate refusals.

use crate::scene::error::{PathPart, Violation};
use crate::scene::ranges::Plausible;
use crate::scene::validate;

/// A key path in the scene.
#[derive(Clone, Debug)]
pub(super) struct At(Vec<PathPart>);

impl At {
    /// `vibration`.
    pub(super) fn root() -> Self {
        Self(vec![PathPart::Key("vibration".to_owned())])
    }

    /// This path's `key`.
    pub(super) fn key(&self, key: &str) -> Self {
        self.with(PathPart::Key(key.to_owned()))
    }

    /// This path's element `i`.
    pub(super) fn index(&self, i: usize) -> Self {
        self.with(PathPart::Index(i))
    }

    fn with(&self, part: PathPart) -> Self {
        let mut path = self.0.clone();
        path.push(part);
        Self(path)
    }

    /// The last index of the path, if it ends in one.
    pub(super) fn last_index(&self) -> Option<usize> {
        match self.0.last() {
            Some(PathPart::Index(i)) => Some(*i),
            _ => None,
        }
    }

    /// A refusal here.
    pub(super) fn error(&self, reason: impl Into<String>) -> Violation {
        Violation::at_path(self.0.clone(), reason)
    }

    /// A check's refusal, made at an empty path (perhaps with an element index), moved here.
    pub(super) fn check(&self, result: Result<(), Violation>) -> Result<(), Violation> {
        result.map_err(|mut v| {
            let mut path = self.0.clone();
            path.append(&mut v.path);
            v.path = path;
            v
        })
    }

    /// Each element of `xs` finite and in `range`.
    pub(super) fn vector(&self, xs: &[f64], range: Plausible) -> Result<(), Violation> {
        self.check(validate::all_finite(xs, &[], range))
    }

    /// A model refusal of the source at this path.
    pub(super) fn model(&self, e: margemu_model::Error) -> Violation {
        self.error(e.to_string())
    }
}
