//! What resolving a scene did to what was asked, for `record` and `live` to tell the user (format.md:
//! record): settings the integrator does not use are ignored, and a fixed step is rounded down to the
//! sampling grid.

use super::file::SceneFile;
use super::problems::flag_of;
use super::{defaults, Scene, Short};
use crate::integrate::Method;
use std::fmt;

/// One thing resolving did to what was asked.
#[allow(missing_docs)]
#[derive(Debug, Clone, PartialEq)]
pub enum Note {
    /// A `key` that `method` does not use (`run.step` for adaptive methods, `run.rtol` and `run.atol` for
    /// fixed-step ones), given as `value` (by `flag`, if one did): ignored and stored as 0, never used to
    /// loosen `verify`'s tolerances. A warning.
    Ignored {
        key: &'static str,
        value: f64,
        flag: Option<&'static str>,
        method: Method,
    },
    /// The fixed step `asked` (or the default), rounded down to `used` so that a whole number of steps fits
    /// between samples (`interval`, 1/rate).
    StepRounded {
        asked: f64,
        used: f64,
        interval: f64,
    },
}

impl Note {
    /// True for a warning (something given is not used), false for a note.
    #[must_use]
    pub fn is_warning(&self) -> bool {
        matches!(self, Self::Ignored { .. })
    }
}

impl fmt::Display for Note {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Ignored {
                key,
                value,
                flag,
                method,
            } => {
                let by = flag.map_or_else(String::new, |flag| format!(" (set by `{flag}`)"));
                let uses = if method.is_adaptive() {
                    "an adaptive method: it uses rtol and atol"
                } else {
                    "a fixed-step method: it uses the step"
                };
                write!(
                    f,
                    "`{key}` = {}{by} does not apply to {method}, {uses}; ignored (stored as 0)",
                    Short(*value)
                )
            }
            Self::StepRounded {
                asked,
                used,
                interval,
            } => write!(
                f,
                "step {} rounded down to {} so that a whole number of steps ({}) fits between \
                 samples (1/rate = {})",
                Short(*asked),
                compact(*used),
                (interval / used).round(),
                compact(*interval)
            ),
        }
    }
}

/// The notes of `scene`, resolved from `file` (flags applied, `provenance` naming the flag of each key).
pub(super) fn notes(
    scene: &Scene,
    file: &SceneFile,
    provenance: &[(&'static str, &'static str)],
) -> Vec<Note> {
    let method = scene.run.method.method;
    let run = file.run.clone().unwrap_or_default();
    let candidates = [
        ("run.rtol", run.rtol, !method.is_adaptive()),
        ("run.atol", run.atol, !method.is_adaptive()),
        ("run.step", run.step, method.is_adaptive()),
    ];
    let mut notes: Vec<Note> = candidates
        .into_iter()
        .filter_map(|(key, value, ignored)| Some((key, value.filter(|_| ignored)?)))
        .map(|(key, value)| Note::Ignored {
            key,
            value,
            flag: flag_of(provenance, key),
            method,
        })
        .collect();
    let (asked, used) = (run.step.unwrap_or(defaults::STEP), scene.run.method.step);
    if !method.is_adaptive() && (asked - used).abs() > 1e-12 * asked {
        notes.push(Note::StepRounded {
            asked,
            used,
            interval: scene.run.sample_interval(),
        });
    }
    notes
}

/// A number in its shortest form when that is short (`0.001`, `0.0025`), else to 5 digits (`8.3333e-4`).
#[must_use]
pub fn compact(x: f64) -> String {
    let shortest = x.to_string();
    let digits = shortest.trim_start_matches(['-', '0', '.']).len();
    if digits <= 6 {
        shortest
    } else {
        format!("{x:.4e}")
    }
}
