//! Run and session directories that say what they hold: which directory a command writes to,
//! and the completion record that is written last.
//!
//! **Choosing the directory** ([`prepare`]):
//! - without an explicit directory, a command writes to its default name, `NAME`, if that does
//!   not exist or is empty, else to the first of `NAME-2`, `NAME-3`, … that does not exist; so a
//!   command run twice writes two directories, and the second run never mixes with the first;
//! - an explicit directory (`-o DIR`) that exists and is not empty is refused, unless `force`:
//!   then margemu's own files in it ([`is_own_file`]: the names its writers define, handed to [`prepare`]
//!   as [`OwnFiles`], and their `.partial` forms), and subdirectories holding only such files (`demo`'s sessions), are
//!   removed first. Anything else in it (a file margemu does not write, a subdirectory holding
//!   one) is left alone and the directory refused, naming what is there.
//!
//! **Completion record**: `meta.toml` is written (whole, under a temporary name, then renamed)
//! when a run begins, and a `[completion]` table ([`Completion`]) is appended to it when the run
//! has ended and every other file of the directory is closed:
//!
//! ```toml
//! [completion]
//! status = "complete"        # or "interrupted" (a signal or the stop flag), "failed"
//! samples_written = 3000     # samples in the files (simulate: rows; sessions: samples the device reported serving)
//! samples_expected = 3000    # the scene's samples, when known
//! ended = "completed"        # why the run ended, in words
//! ```
//!
//! The record, like the data files, is written and closed but not synced to the disk: it tells
//! runs that ended, were stopped or were killed apart, and makes no claim about a power loss
//! (syncing the record alone would not make one, since the rows it counts are not synced, and it
//! cost a `simulate` of a few milliseconds more than the rest of the run).
//!
//! A `meta.toml` with `margemu_version` but no `[completion]` table belongs to a run that was
//! killed (or is still running). [`check_complete`] is what `evaluate` asks before reading a
//! directory. Directories whose `meta.toml` has no `margemu_version` were not written by margemu
//! and are not checked.

mod completion;

pub use completion::{
    check_complete, read_completion, write_completion, Completion, CompletionRecord, Status,
};

use std::io;
use std::path::{Path, PathBuf};

/// The suffix of a file still being written.
pub const PARTIAL_SUFFIX: &str = ".partial";

/// The name of the run's metadata file, which carries the completion record.
pub const META_FILE: &str = "meta.toml";

/// A directory that cannot be used, or a run that did not complete.
#[derive(Debug, thiserror::Error, docsplay::Display)]
pub enum RunDirError {
    /// {path} is not empty: give another directory, or --force to replace margemu's files in it
    NotEmpty {
        /// The directory.
        path: PathBuf,
    },
    /// {path} holds files margemu did not write ({entries}); --force removes only margemu's own files, so move these first
    Foreign {
        /// The directory.
        path: PathBuf,
        /// What is there, comma-separated.
        entries: String,
    },
    /// cannot use {path}
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The cause.
        #[source]
        source: io::Error,
    },
    /// {path}: cannot read the completion record: {reason}
    BadMeta {
        /// The `meta.toml`.
        path: PathBuf,
        /// The parse error.
        reason: String,
    },
    /// {path} holds an incomplete run: {why} (--allow-incomplete scores it anyway)
    Incomplete {
        /// The directory.
        path: PathBuf,
        /// What its completion record says, or that it has none.
        why: String,
    },
}

/// File names that margemu writes into run and session directories, in lists, each defined next
/// to its writer ([`RUN_FILES`](crate::output::RUN_FILES) here, the session's, the device under
/// test's, the evaluation's in the layers above; the binary's `margemu::own_files` gathers them).
pub type OwnFiles<'a> = &'a [&'a [&'a str]];

/// Whether `name` is a file margemu writes into a run or session directory (or its `.partial`
/// form while it is being written): one of `own`'s names, or `meta.toml`.
pub fn is_own_file(name: &str, own: OwnFiles) -> bool {
    let name = name.strip_suffix(PARTIAL_SUFFIX).unwrap_or(name);
    name == META_FILE || own.iter().any(|files| files.contains(&name))
}

/// The directory a run writes to, created and empty (see the module docs): `explicit` if
/// given (refused if it is not empty, unless `force`), else a fresh directory named after
/// `default`.
pub fn prepare(
    explicit: Option<&Path>,
    default: &Path,
    force: bool,
    own: OwnFiles,
) -> Result<PathBuf, RunDirError> {
    let io_err = |path: &Path| {
        let path = path.to_path_buf();
        move |source| RunDirError::Io { path, source }
    };
    match explicit {
        Some(dir) => {
            std::fs::create_dir_all(dir).map_err(io_err(dir))?;
            let entries = entries(dir).map_err(io_err(dir))?;
            if entries.is_empty() {
                return Ok(dir.to_path_buf());
            }
            if !force {
                return Err(RunDirError::NotEmpty {
                    path: dir.to_path_buf(),
                });
            }
            clear_own(dir, entries, own)?;
            Ok(dir.to_path_buf())
        }
        None => fresh(default).map_err(io_err(default)),
    }
}

/// `default`, or `default-2`, `default-3`, …: the first that this call creates (or finds empty).
fn fresh(default: &Path) -> io::Result<PathBuf> {
    if let Some(parent) = default.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)?;
    }
    let name = default.file_name().unwrap_or_default().to_string_lossy();
    for k in 1u32.. {
        let dir = match k {
            1 => default.to_path_buf(),
            _ => default.with_file_name(format!("{name}-{k}")),
        };
        match std::fs::create_dir(&dir) {
            Ok(()) => return Ok(dir),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {
                if dir.is_dir() && entries(&dir)?.is_empty() {
                    return Ok(dir);
                }
            }
            Err(e) => return Err(e),
        }
    }
    unreachable!("some numbered name is free")
}

/// The names in `dir`.
fn entries(dir: &Path) -> io::Result<Vec<(String, bool)>> {
    let mut names = Vec::new();
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let is_file = entry.file_type()?.is_file();
        names.push((entry.file_name().to_string_lossy().into_owned(), is_file));
    }
    names.sort();
    Ok(names)
}

/// Whether the entry `name` of `dir` is margemu's own: one of its files, or a directory of
/// its files only (a session of `demo`).
fn is_own_entry(dir: &Path, name: &str, is_file: bool, own: OwnFiles) -> io::Result<bool> {
    if is_file {
        return Ok(is_own_file(name, own));
    }
    let sub = dir.join(name);
    if !sub.is_dir() || sub.is_symlink() {
        return Ok(false);
    }
    Ok(entries(&sub)?
        .iter()
        .all(|(name, is_file)| *is_file && is_own_file(name, own)))
}

/// Removes margemu's own files (and directories of them) from `dir`, after checking nothing
/// else is there.
fn clear_own(dir: &Path, entries: Vec<(String, bool)>, own: OwnFiles) -> Result<(), RunDirError> {
    let io_err = |path: PathBuf| move |source| RunDirError::Io { path, source };
    let mut foreign = Vec::new();
    for (name, is_file) in &entries {
        if !is_own_entry(dir, name, *is_file, own).map_err(io_err(dir.join(name)))? {
            foreign.push(name.as_str());
        }
    }
    if !foreign.is_empty() {
        return Err(RunDirError::Foreign {
            path: dir.to_path_buf(),
            entries: foreign.join(", "),
        });
    }
    for (name, is_file) in &entries {
        let path = dir.join(name);
        if *is_file {
            std::fs::remove_file(&path).map_err(io_err(path))?;
        } else {
            for (inner, _) in self::entries(&path).map_err(io_err(path.clone()))? {
                let file = path.join(inner);
                std::fs::remove_file(&file).map_err(io_err(file))?;
            }
            std::fs::remove_dir(&path).map_err(io_err(path))?;
        }
    }
    Ok(())
}

/// `dir/name.partial`: where `name` is written until [`commit_partial`].
pub fn partial_path(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}{PARTIAL_SUFFIX}"))
}

/// Renames `dir/name.partial` to `dir/name`.
pub fn commit_partial(dir: &Path, name: &str) -> io::Result<()> {
    std::fs::rename(partial_path(dir, name), dir.join(name))
}

/// Writes `dir/meta.toml` whole: under its temporary name, then renamed.
pub fn write_meta(dir: &Path, text: &str) -> io::Result<()> {
    std::fs::write(partial_path(dir, META_FILE), text)?;
    commit_partial(dir, META_FILE)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The run's files and, standing for the layers above, a few of theirs.
    const OWN: OwnFiles = &[
        &crate::output::RUN_FILES,
        &["dut_attitude.csv", "report.md", "table3.md"],
    ];

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("margemu-rundir-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn default_names_are_numbered_once_taken() {
        let base = scratch("numbered").join("run");
        assert_eq!(prepare(None, &base, false, OWN).unwrap(), base);
        // Empty: still free.
        assert_eq!(prepare(None, &base, false, OWN).unwrap(), base);
        std::fs::write(base.join("truth.csv"), "t_ns\n").unwrap();
        let second = prepare(None, &base, false, OWN).unwrap();
        assert_eq!(second.file_name().unwrap(), "run-2");
        std::fs::write(second.join("truth.csv"), "t_ns\n").unwrap();
        assert_eq!(
            prepare(None, &base, false, OWN)
                .unwrap()
                .file_name()
                .unwrap(),
            "run-3"
        );
    }

    #[test]
    fn force_removes_own_files_and_refuses_foreign_ones() {
        let dir = scratch("force");
        std::fs::create_dir_all(&dir).unwrap();
        for name in [
            "meta.toml",
            "perturbation.csv",
            "dut_attitude.csv",
            "truth.csv.partial",
        ] {
            std::fs::write(dir.join(name), "x").unwrap();
        }
        let e = prepare(Some(&dir), Path::new("unused"), false, OWN).unwrap_err();
        assert!(matches!(e, RunDirError::NotEmpty { .. }), "{e}");
        assert_eq!(
            prepare(Some(&dir), Path::new("unused"), true, OWN).unwrap(),
            dir
        );
        assert!(entries(&dir).unwrap().is_empty());
        std::fs::create_dir_all(dir.join("ecf-initial")).unwrap();
        std::fs::write(dir.join("ecf-initial/report.md"), "x").unwrap();
        std::fs::write(dir.join("table3.md"), "x").unwrap();
        assert_eq!(
            prepare(Some(&dir), Path::new("unused"), true, OWN).unwrap(),
            dir
        );
        assert!(entries(&dir).unwrap().is_empty());
        std::fs::create_dir_all(dir.join("photos")).unwrap();
        std::fs::write(dir.join("photos/bench.jpg"), "x").unwrap();
        std::fs::write(dir.join("notes.txt"), "mine").unwrap();
        std::fs::write(dir.join("truth.csv"), "x").unwrap();
        let e = prepare(Some(&dir), Path::new("unused"), true, OWN).unwrap_err();
        assert!(e.to_string().contains("(notes.txt, photos)"), "{e}");
        assert!(dir.join("notes.txt").exists() && dir.join("truth.csv").exists());
        assert!(dir.join("photos/bench.jpg").exists());
    }

    #[test]
    fn completion_is_written_by_the_last_holder() {
        let dir = scratch("holders");
        std::fs::create_dir_all(&dir).unwrap();
        let scene = crate::scene::Scene::parse_str(
            "duration = 0.1\nrate = 100.0\nseed = 1\n",
            Path::new("s.toml"),
        )
        .unwrap();
        crate::meta::write(&dir, &crate::run::metadata(&scene)).unwrap();
        let record = CompletionRecord::new(&dir);
        let other = record.clone();
        record.update(|c| {
            c.status = Status::Complete;
            c.samples_written = 7;
            c.ended = "completed".into();
        });
        record.release().unwrap();
        assert_eq!(read_completion(&dir).unwrap(), None);
        let e = check_complete(&dir, false).unwrap_err();
        assert!(e.to_string().contains("incomplete"), "{e}");
        other.update(|c| c.fail("the reader failed"));
        other.release().unwrap();
        let c = read_completion(&dir).unwrap().unwrap();
        assert_eq!((c.status, c.samples_written), (Status::Failed, 7));
        assert!(check_complete(&dir, true)
            .unwrap()
            .unwrap()
            .contains("failed, 7 samples"));
    }
}
