//! `coin-log scenes`: list the built-in scenes, or print one as TOML.

use super::Outcome;
use anyhow::bail;
use coin_log::scene::{presets, to_toml};

/// Arguments of `coin-log scenes`.
///
/// Without arguments, lists the built-in scenes, one per line. With `--show NAME`, prints that scene as a
/// TOML scene file (save it, edit it, and pass the file to `coin-log record`).
#[derive(Debug, clap::Args)]
pub struct ScenesArgs {
    /// Print the built-in scene NAME as TOML.
    #[arg(long, value_name = "NAME")]
    show: Option<String>,
}

/// Runs `coin-log scenes`.
pub fn run(args: ScenesArgs) -> anyhow::Result<Outcome> {
    match args.show {
        Some(name) => {
            let Some(file) = presets::preset(&name) else {
                bail!(
                    "no built-in scene `{name}`; built-in scenes: {}",
                    presets::NAMES.join(", ")
                );
            };
            out!("{}", show(&name, &file));
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

/// The text of `scenes --show NAME` (also the file `datasets/scenes/NAME.toml`).
fn show(name: &str, file: &coin_log::scene::SceneFile) -> String {
    format!(
        "# Built-in scene `{name}`; written by `coin-log scenes --show {name}`.\n{}",
        to_toml(file)
    )
}
