//! `coin-log scenes`: list the built-in scenes, print one as TOML with every default filled in, or all
//! of them as JSON.

use super::Outcome;
use anyhow::{anyhow, bail};
use coin_log::scene::{presets, Scene, SceneFile};

/// Arguments of `coin-log scenes`.
///
/// Without arguments, lists the built-in scenes, one per line. With `--show NAME`, prints that scene as a
/// TOML scene file with every default written out (rate, integrator, tolerances, step, margin, channels):
/// save it, edit it, and pass the file to `coin-log record`. `--json` prints every built-in scene as JSON.
#[derive(Debug, clap::Args)]
pub struct ScenesArgs {
    /// Print the built-in scene NAME as TOML, every default filled in.
    #[arg(long, value_name = "NAME", conflicts_with = "json")]
    show: Option<String>,
    /// Print `[{"name", "description", "scene": {...}}]`: every built-in scene, resolved, as JSON.
    #[arg(long)]
    json: bool,
}

/// Runs `coin-log scenes`.
pub fn run(args: ScenesArgs) -> anyhow::Result<Outcome> {
    if args.json {
        #[derive(serde::Serialize)]
        struct Entry {
            name: &'static str,
            description: String,
            scene: SceneFile,
        }
        let mut all = Vec::new();
        for name in presets::NAMES {
            let scene = resolved(name)?;
            let description = scene.description.clone().unwrap_or_default();
            all.push(Entry {
                name,
                description,
                scene,
            });
        }
        super::output::json(&all)?;
        return Ok(Outcome::Success);
    }
    match args.show {
        Some(name) => {
            if presets::preset(&name).is_none() {
                bail!(
                    "no built-in scene `{name}`; built-in scenes: {}",
                    presets::NAMES.join(", ")
                );
            }
            out!("{}", show(&name, &resolved(&name)?));
        }
        None => {
            let width = presets::NAMES.iter().map(|n| n.len()).max().unwrap_or(0);
            for name in presets::NAMES {
                let description = presets::preset(name)
                    .and_then(|f| f.description)
                    .unwrap_or_default();
                outln!("{name:<width$}  {description}");
            }
        }
    }
    Ok(Outcome::Success)
}

/// The built-in scene `name` resolved: every default written out, the step as used.
fn resolved(name: &str) -> anyhow::Result<SceneFile> {
    let file = presets::preset(name).ok_or_else(|| anyhow!("no built-in scene `{name}`"))?;
    let scene = Scene::from_file(&file).map_err(|e| anyhow!("built-in scene `{name}`: {e}"))?;
    Ok(scene.to_file())
}

/// The text of `scenes --show NAME` (also the file `datasets/scenes/NAME.toml`).
fn show(name: &str, file: &SceneFile) -> String {
    format!(
        "# Built-in scene `{name}` with every default filled in; written by `coin-log scenes --show {name}`.\n{}",
        coin_log::scene::readable_toml(&coin_log::scene::to_toml(file))
    )
}
