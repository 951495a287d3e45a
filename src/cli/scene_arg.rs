//! What a SCENE argument names (format.md: Commands): a built-in scene or a scene file, by one rule for
//! every command. A path (it holds a path separator or ends in `.toml`) is a file, whatever built-in has
//! its stem; a bare name is the built-in of that name, and a file of that name in the current folder is
//! then named in a note on stderr, so that it is never shadowed silently; a bare name that is no built-in
//! is a file if one exists; a name that is not UTF-8 is no built-in's, so it is a file. [`load_source`]
//! is the one loader of `record` and `analyse`: the scene, with the `--set KEY=VALUE` edits applied
//! (format.md: Scene edits).

use anyhow::anyhow;
use coin_log::files::{escaped, read_toml, shown, InputKind};
use coin_log::scene::{self, presets, SceneFile};
use std::ffi::{OsStr, OsString};
use std::path::{Path, PathBuf};

/// The scene an argument names.
pub enum SceneArg<'a> {
    /// A built-in scene.
    Builtin(&'a str),
    /// A scene file.
    File(&'a Path),
}

/// Classifies `arg` by the module's rule; notes on stderr a local file that a built-in name leaves unused.
///
/// # Errors
/// No built-in scene of that name and no such file.
pub fn classify(arg: &OsStr) -> anyhow::Result<SceneArg<'_>> {
    let path = Path::new(arg);
    let Some(arg) = arg.to_str() else {
        return Ok(SceneArg::File(path));
    };
    if presets::is_path(arg) || arg == "-" {
        return Ok(SceneArg::File(path));
    }
    if presets::preset(arg).is_some() {
        for local in [arg.to_string(), format!("{arg}.toml")] {
            if Path::new(&local).is_file() {
                errln!(
                    "note: `{arg}` is the built-in scene; the file `{local}` in this folder is not used (give `./{local}` to use it)"
                );
            }
        }
        return Ok(SceneArg::Builtin(arg));
    }
    if path.exists() {
        return Ok(SceneArg::File(path));
    }
    anyhow::bail!(
        "no built-in scene `{}` and no such file; built-in scenes: {}",
        escaped(arg),
        presets::NAMES.join(", ")
    )
}

/// The text of the scene file at `path`, read by the rules of files::input (a regular file, at most
/// [`SCENE_MAX_BYTES`](coin_log::files::input::SCENE_MAX_BYTES)).
///
/// # Errors
/// The path is not such a file, or cannot be read.
pub fn read_scene_file(path: &Path) -> anyhow::Result<String> {
    read_toml(path, InputKind::Scene)
        .map_err(|e| anyhow!("cannot read scene file `{}`: {e}", shown(path)))
}

/// Where a scene came from: its name in messages, its default output stem, and its file if it is one.
pub struct SceneSource {
    /// SCENE as given, its control characters escaped (it names the scene in messages and summaries).
    pub label: String,
    /// The built-in name or the file's stem (its own bytes: the default output keeps them).
    pub stem: OsString,
    /// The scene with the `--set` edits applied, not yet validated.
    pub file: SceneFile,
    /// The scene file, when SCENE is one (`record` refuses to write over it).
    pub path: Option<PathBuf>,
}

/// Loads SCENE by the module's rule and applies `sets`.
///
/// # Errors
/// No such scene, an unreadable file, or a scene or edit that does not parse.
pub fn load_source(arg: &OsStr, sets: &[String]) -> anyhow::Result<SceneSource> {
    let path = match classify(arg)? {
        SceneArg::Builtin(name) => {
            let preset = presets::preset(name).unwrap_or_default();
            let file =
                scene::file_with_sets(&preset, sets).map_err(|e| anyhow!("scene `{name}`: {e}"))?;
            return Ok(SceneSource {
                label: name.to_string(),
                stem: name.into(),
                file,
                path: None,
            });
        }
        SceneArg::File(path) => path,
    };
    let text = read_scene_file(path)?;
    let label = shown(path);
    let file = scene::parse_with_sets(&text, sets).map_err(|e| anyhow!("scene `{label}`: {e}"))?;
    let stem = path.file_stem().unwrap_or(OsStr::new("scene")).to_owned();
    Ok(SceneSource {
        label,
        stem,
        file,
        path: Some(path.to_path_buf()),
    })
}
