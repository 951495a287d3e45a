//! Why a sweep could not be loaded, run or collected. A run that fails is not an error of the sweep: it
//! is a row of the catalogue with its reason ([`super::catalogue`]).

use crate::scene::SceneProblems;
use std::path::PathBuf;

/// A sweep file that cannot be used, a folder that cannot hold the sweep, or an I/O error on the sweep's
/// own files (the catalogue, the journal, the state). `path` is the file or folder, `label` the sweep file
/// as named, `source` the cause.
#[derive(Debug, thiserror::Error)]
#[allow(missing_docs)]
pub enum SweepError {
    /// The sweep file cannot be read.
    #[error("cannot read sweep file `{}`: {source}", path.display())]
    Read {
        path: PathBuf,
        source: crate::files::InputError,
    },
    /// The sweep file is not TOML or does not fit the sweep's keys and types (serde's `message`, alone).
    #[error("sweep file `{label}`: {message}")]
    Parse { label: String, message: String },
    /// Values out of range, missing or contradictory: every problem found (at least one; boxed: a list
    /// is large beside the other variants), each with its key.
    #[error("sweep file `{label}`: {problems}")]
    Invalid {
        label: String,
        problems: Box<SceneProblems>,
    },
    /// The output folder cannot hold this sweep (not empty, another sweep's, another version's): the
    /// `reason`, and what to do.
    #[error("`{}`: {reason}", path.display())]
    Folder { path: PathBuf, reason: String },
    /// Reading or writing one of the sweep's own files failed; `what` was being done (`writing the
    /// catalogue`).
    #[error("{what} `{}`: {source}", path.display())]
    Io {
        what: &'static str,
        path: PathBuf,
        source: std::io::Error,
    },
}

impl SweepError {
    pub(super) fn folder(path: &std::path::Path) -> impl Fn(String) -> Self + '_ {
        |reason| Self::Folder {
            path: path.to_path_buf(),
            reason,
        }
    }

    pub(super) fn io(
        what: &'static str,
        path: impl Into<PathBuf>,
    ) -> impl FnOnce(std::io::Error) -> Self {
        let path = path.into();
        move |source| Self::Io { what, path, source }
    }
}
