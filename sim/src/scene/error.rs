//! Scene errors that point at the file, line and column.

use std::fmt;
use std::path::{Path, PathBuf};

/// Why a scene was refused, and where.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    /// The scene file.
    pub file: PathBuf,
    /// 1-based line and column of the offending text, when it has a place in the file.
    pub position: Option<(usize, usize)>,
    /// What is wrong.
    pub reason: String,
}

impl std::error::Error for SceneError {}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.position {
            Some((line, col)) => write!(f, "{}:{line}:{col}: {}", self.file.display(), self.reason),
            None => write!(f, "{}: {}", self.file.display(), self.reason),
        }
    }
}

/// A legal but likely wrong input, located like an error.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneWarning(pub SceneError);

impl fmt::Display for SceneWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

/// A validation failure: the key path of the offending value and the reason.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Violation {
    pub path: Vec<PathPart>,
    pub reason: String,
}

/// One step of a key path: a table key or an array index.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum PathPart {
    Key(String),
    Index(usize),
}

impl Violation {
    pub fn at(path: &[&str], reason: impl Into<String>) -> Self {
        Self {
            path: path
                .iter()
                .map(|k| PathPart::Key((*k).to_owned()))
                .collect(),
            reason: reason.into(),
        }
    }

    pub fn at_keys(path: Vec<String>, reason: impl Into<String>) -> Self {
        Self {
            path: path.into_iter().map(PathPart::Key).collect(),
            reason: reason.into(),
        }
    }

    pub fn at_path(path: Vec<PathPart>, reason: impl Into<String>) -> Self {
        Self {
            path,
            reason: reason.into(),
        }
    }

    pub fn index(mut self, i: usize) -> Self {
        self.path.push(PathPart::Index(i));
        self
    }

    fn dotted(&self) -> String {
        let mut s = String::new();
        for part in &self.path {
            match part {
                PathPart::Key(k) if s.is_empty() => s.push_str(k),
                PathPart::Key(k) => {
                    s.push('.');
                    s.push_str(k)
                }
                PathPart::Index(i) => s.push_str(&format!("[{i}]")),
            }
        }
        s
    }
}

impl SceneError {
    pub(crate) fn input(path: &Path, e: &crate::input_file::InputFileError) -> Self {
        Self {
            file: path.to_path_buf(),
            position: None,
            reason: e.reason(),
        }
    }

    /// Bytes that are not UTF-8, located at the first invalid byte.
    pub(crate) fn not_utf8(path: &Path, bytes: &[u8], e: &std::str::Utf8Error) -> Self {
        let valid = &bytes[..e.valid_up_to()];
        let text = std::str::from_utf8(valid).unwrap_or_default();
        Self {
            file: path.to_path_buf(),
            position: Some(line_col(text, text.len())),
            reason: format!(
                "byte 0x{:02x} at offset {} is not UTF-8",
                bytes[e.valid_up_to()],
                e.valid_up_to()
            ),
        }
    }

    /// An error at the value of the key path `keys` (or its nearest ancestor in the file).
    pub(crate) fn at_keys(path: &Path, text: &str, keys: &[&str], reason: String) -> Self {
        Self::from_violation(path, text, Violation::at(keys, reason))
    }

    /// `file:line:col` of the value at the key path `keys`, or `file` alone.
    pub(crate) fn location(path: &Path, text: &str, keys: &[&str]) -> String {
        let v = Violation::at(keys, "");
        match locate(text, &v.path).map(|at| line_col(text, at)) {
            Some((line, col)) => format!("{}:{line}:{col}", path.display()),
            None => path.display().to_string(),
        }
    }

    pub(crate) fn from_toml(path: &Path, text: &str, e: &toml::de::Error) -> Self {
        let position = e.span().map(|s| line_col(text, s.start));
        Self {
            file: path.to_path_buf(),
            position,
            reason: e.message().trim().to_owned(),
        }
    }

    pub(crate) fn from_violation(path: &Path, text: &str, v: Violation) -> Self {
        let span = locate(text, &v.path);
        let reason = if v.path.is_empty() {
            v.reason.clone()
        } else {
            format!("`{}`: {}", v.dotted(), v.reason)
        };
        Self {
            file: path.to_path_buf(),
            position: span.map(|s| line_col(text, s)),
            reason,
        }
    }
}

/// 1-based line and column (in characters) of byte offset `at`.
fn line_col(text: &str, at: usize) -> (usize, usize) {
    let at = at.min(text.len());
    let before = text.get(..at).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// Byte offset of the value at `path`, or of its nearest ancestor that is in the file.
fn locate(text: &str, path: &[PathPart]) -> Option<usize> {
    let doc = toml_edit::Document::parse(text).ok()?;
    let mut item: &toml_edit::Item = doc.as_item();
    let mut best = None;
    for part in path {
        let next = match part {
            PathPart::Key(k) => item.get(k.as_str()),
            PathPart::Index(i) => item.get(*i),
        };
        let Some(next) = next else { break };
        item = next;
        if let Some(span) = item.span() {
            best = Some(span.start);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_column_are_one_based() {
        let text = "a = 1\nbb = 2\n";
        assert_eq!(line_col(text, 0), (1, 1));
        assert_eq!(line_col(text, 6), (2, 1));
        assert_eq!(line_col(text, 11), (2, 6));
    }

    #[test]
    fn values_are_located_by_key_path() {
        let text = "x = 1\n[bench]\nplate_mass = -2.0\ninitial = [0, 1, 2]\n";
        let v = Violation::at(&["bench", "plate_mass"], "must be positive");
        assert_eq!(
            locate(text, &v.path).map(|at| line_col(text, at)),
            Some((3, 14))
        );
        let v = Violation::at(&["bench", "initial"], "bad").index(2);
        assert_eq!(
            locate(text, &v.path).map(|at| line_col(text, at)),
            Some((4, 18))
        );
        let missing = Violation::at(&["bench", "nothing"], "absent");
        assert_eq!(
            locate(text, &missing.path).map(|at| line_col(text, at)),
            Some((2, 1))
        );
    }
}
