//! What a SCENE argument names (format.md: Commands): a built-in scene or a scene file, by one rule for
//! every command. A path (it holds a path separator or ends in `.toml`) is a file, whatever built-in has
//! its stem; a bare name is the built-in of that name, and a file of that name in the current folder is
//! then named in a note on stderr, so that it is never shadowed silently; a bare name that is no built-in
//! is a file if one exists.

use coin_log::scene::presets;
use std::path::Path;

/// The scene an argument names.
pub enum SceneArg<'a> {
    /// A built-in scene.
    Builtin(&'a str),
    /// A scene file.
    File(&'a Path),
}

/// True when `arg` is written as a path rather than a name.
fn looks_like_a_path(arg: &str) -> bool {
    arg.contains('/') || arg.contains(std::path::MAIN_SEPARATOR) || arg.ends_with(".toml")
}

/// Classifies `arg` by the module's rule; notes on stderr a local file that a built-in name leaves unused.
///
/// # Errors
/// No built-in scene of that name and no such file.
pub fn classify(arg: &str) -> anyhow::Result<SceneArg<'_>> {
    let path = Path::new(arg);
    if looks_like_a_path(arg) {
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
        "no built-in scene `{arg}` and no such file; built-in scenes: {}",
        presets::NAMES.join(", ")
    )
}
