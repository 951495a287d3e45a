//! The SCENE argument of `record` and `analyse`: a built-in scene's name or a `.toml` file's path, with
//! `--set KEY=VALUE` edits applied (format.md: Commands, Scene edits). One loader, so both commands read
//! a scene the same way.

use anyhow::{anyhow, bail, Context};
use coin_log::scene::{self, presets, SceneFile};
use std::path::Path;

/// Where a scene came from: its name in messages and its default output stem.
pub struct SceneSource {
    /// SCENE as given.
    pub label: String,
    /// The built-in name or the file's stem.
    pub stem: String,
    /// The scene with the `--set` edits applied, not yet validated.
    pub file: SceneFile,
}

/// Loads SCENE (a built-in name wins over a file of the same name) and applies `sets`.
pub fn load_source(arg: &str, sets: &[String]) -> anyhow::Result<SceneSource> {
    if let Some(preset) = presets::preset(arg) {
        let file =
            scene::file_with_sets(&preset, sets).map_err(|e| anyhow!("scene `{arg}`: {e}"))?;
        return Ok(SceneSource {
            label: arg.to_string(),
            stem: arg.to_string(),
            file,
        });
    }
    let path = Path::new(arg);
    if !path.exists() && !arg.ends_with(".toml") && !arg.contains(std::path::MAIN_SEPARATOR) {
        bail!(
            "no built-in scene `{arg}` and no such file; built-in scenes: {}",
            presets::NAMES.join(", ")
        );
    }
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read scene file `{}`", path.display()))?;
    let file = scene::parse_with_sets(&text, sets).map_err(|e| anyhow!("scene `{arg}`: {e}"))?;
    let stem = path
        .file_stem()
        .map_or_else(|| "scene".to_string(), |s| s.to_string_lossy().into_owned());
    Ok(SceneSource {
        label: arg.to_string(),
        stem,
        file,
    })
}
