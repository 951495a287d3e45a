//! The built-in scenes: the files `datasets/scenes/<name>.toml`, embedded at build time and read by the same
//! parser as a user's scene file. Each file is its scene with every default written out, as
//! `coin-log scenes --show <name>` prints it (a test checks that the two agree).

use super::file::{RunFile, SceneFile};
use super::{defaults, validate};

/// Declares the built-ins by name, each with the text of its file.
macro_rules! builtins {
    ($($name:literal),+ $(,)?) => {
        /// Every built-in scene name, in listing order.
        pub const NAMES: [&str; [$($name),+].len()] = [$($name),+];
        /// Every built-in's file text, in the order of [`NAMES`].
        const TEXTS: &[&str] =
            &[$(include_str!(concat!("../../../../datasets/scenes/", $name, ".toml"))),+];
    };
}

builtins!(
    "straight",
    "straight-unstable",
    "centre-fixed",
    "circle-plus",
    "circle-minus",
    "large-circle",
    "spin-upright",
    "wobble",
    "high-spin",
    "near-flat",
    "topple",
    "lift-off",
    "long-horizon",
    "five-hundred-yen",
    "euler-disk",
);

/// The built-in scene `name`, as a file, without the keys in which its file only repeats a default: flags
/// and edits then change a built-in as they change a scene that never set those keys (`--integrator rk4`
/// finds no rtol to warn about, a dissipation added with `--set` adds the `work` channel).
#[must_use]
pub fn preset(name: &str) -> Option<SceneFile> {
    let text = NAMES.iter().position(|n| *n == name).map(|i| TEXTS[i])?;
    // Every file parses: a test reads each one.
    super::parse_with_sets(text, &[]).ok().map(without_defaults)
}

/// True when a scene argument is written as a path rather than a built-in's name: it holds a path
/// separator or ends in `.toml` (format.md: Commands).
#[must_use]
pub fn is_path(arg: &str) -> bool {
    arg.contains('/') || arg.contains(std::path::MAIN_SEPARATOR) || arg.ends_with(".toml")
}

/// `file` without the keys whose value is the default (the inverse of [`super::Scene::to_file`]).
fn without_defaults(mut file: SceneFile) -> SceneFile {
    fn drop_if<T: PartialEq>(slot: &mut Option<T>, default: &T) {
        if slot.as_ref() == Some(default) {
            *slot = None;
        }
    }
    drop_if(&mut file.body.thickness, &defaults::THICKNESS);
    if let Some(steady) = &mut file.initial.steady {
        drop_if(&mut steady.branch, &defaults::BRANCH.name().to_string());
    }
    if let Some(p) = &mut file.initial.perturbation {
        drop_if(&mut p.omega, &vec![0.0; 3]);
    }
    let run = file.run.get_or_insert_with(RunFile::default);
    drop_if(&mut run.rate, &defaults::RATE);
    drop_if(&mut run.integrator, &defaults::INTEGRATOR.to_string());
    drop_if(&mut run.rtol, &defaults::RTOL);
    drop_if(&mut run.atol, &defaults::ATOL);
    drop_if(&mut run.step, &defaults::STEP);
    drop_if(&mut run.flat_margin, &defaults::FLAT_MARGIN);
    let channels = validate::default_channels(file.body.dissipation.is_some());
    drop_if(&mut file.record, &validate::record_file(&channels));
    file
}
