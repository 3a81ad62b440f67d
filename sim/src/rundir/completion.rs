//! The completion record: the `[completion]` table of `meta.toml` ([`Completion`], one serde
//! type for writing and reading, a table of the [`crate::meta`] schema), the check `evaluate` makes, and the record shared by the
//! writers of one directory ([`CompletionRecord`]).

use super::{RunDirError, META_FILE};
use crate::meta::{Appended, MetaFile};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Every file holds the whole run.
    Complete,
    /// Stopped early by a signal (SIGINT, SIGTERM, SIGHUP) or the stop flag; the files hold
    /// everything up to then.
    Interrupted,
    /// Ended by an error (a device, a port, a full disk); the files hold what was written.
    Failed,
}

impl fmt::Display for Status {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Complete => "complete",
            Self::Interrupted => "interrupted",
            Self::Failed => "failed",
        })
    }
}

/// The `[completion]` table of `meta.toml` (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Completion {
    /// How the run ended.
    pub status: Status,
    /// Samples in the files.
    pub samples_written: u64,
    /// The scene's samples, when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples_expected: Option<u64>,
    /// Why the run ended, in words.
    pub ended: String,
}

impl Completion {
    /// Marks the record failed for `why`, unless it already says interrupted or failed.
    pub fn fail(&mut self, why: impl Into<String>) {
        if self.status == Status::Complete {
            self.status = Status::Failed;
            self.ended = why.into();
        }
    }
}

impl fmt::Display for Completion {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}, {} samples written",
            self.status, self.samples_written
        )?;
        if let Some(n) = self.samples_expected {
            write!(f, " of {n}")?;
        }
        write!(f, " ({})", self.ended)
    }
}

/// Appends the `[completion]` table to `dir/meta.toml` (not synced: [`crate::rundir`]).
pub fn write_completion(dir: &Path, completion: &Completion) -> io::Result<()> {
    crate::meta::append(dir, Appended::Completion(completion))
}

/// The completion record of `dir`: `Ok(None)` if margemu wrote `meta.toml` but the run has no
/// record (it was killed, or is still running). Fails if there is no `meta.toml` or it does not
/// parse.
pub fn read_completion(dir: &Path) -> Result<Option<Completion>, RunDirError> {
    Ok(read_meta(dir)?.completion().cloned())
}

fn read_meta(dir: &Path) -> Result<MetaFile, RunDirError> {
    crate::meta::read(dir).map_err(|e| RunDirError::BadMeta {
        path: e.path,
        reason: e.reason,
    })
}

/// Whether `dir` may be read as a finished run: `Ok(None)` if its completion record says
/// complete (or it has no `meta.toml` by margemu); otherwise an [`RunDirError::Incomplete`]
/// naming the status, the samples written and why it ended, or, with `allow_incomplete`, that
/// text as `Ok(Some(note))` for the caller to show.
pub fn check_complete(dir: &Path, allow_incomplete: bool) -> Result<Option<String>, RunDirError> {
    if !dir.join(META_FILE).is_file() {
        return Ok(None);
    }
    let meta = read_meta(dir)?;
    if let MetaFile::Foreign(_) = meta {
        return Ok(None);
    }
    let why = match meta.completion().cloned() {
        Some(c) if c.status == Status::Complete => return Ok(None),
        Some(c) => format!("meta.toml's completion record says {c}"),
        None => {
            "meta.toml has no completion record: the run was killed or is still running".to_string()
        }
    };
    match allow_incomplete {
        true => Ok(Some(format!("INCOMPLETE RUN, scored anyway: {why}"))),
        false => Err(RunDirError::Incomplete {
            path: dir.to_path_buf(),
            why,
        }),
    }
}

/// The completion record of a directory that several writers share (a session and the device
/// under test's reader): each holds a clone, and the record is written to `meta.toml` when the
/// last one is released ([`CompletionRecord::release`]) or dropped. Until a writer sets it, the
/// record says the run failed before it began.
#[derive(Clone, Debug)]
pub struct CompletionRecord(Arc<Mutex<Pending>>);

#[derive(Debug)]
struct Pending {
    dir: PathBuf,
    record: Completion,
    written: bool,
}

impl Pending {
    fn write(&mut self) -> io::Result<()> {
        self.written = true;
        write_completion(&self.dir, &self.record)
    }
}

impl Drop for Pending {
    fn drop(&mut self) {
        if !self.written {
            let _ = self.write();
        }
    }
}

impl CompletionRecord {
    /// The record of `dir`, whose `meta.toml` exists.
    pub fn new(dir: &Path) -> Self {
        Self(Arc::new(Mutex::new(Pending {
            dir: dir.to_path_buf(),
            record: Completion {
                status: Status::Failed,
                samples_written: 0,
                samples_expected: None,
                ended: "the run ended before it began".into(),
            },
            written: false,
        })))
    }

    /// Changes the record.
    pub fn update(&self, change: impl FnOnce(&mut Completion)) {
        let mut pending = self.0.lock().unwrap_or_else(|e| e.into_inner());
        change(&mut pending.record);
    }

    /// Lets go of this clone; if it is the last, writes the record now and reports the outcome.
    pub fn release(self) -> io::Result<()> {
        match Arc::try_unwrap(self.0) {
            Ok(pending) => pending
                .into_inner()
                .unwrap_or_else(|e| e.into_inner())
                .write(),
            Err(_) => Ok(()),
        }
    }
}
