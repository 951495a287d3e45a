//! `coin-log plot`: the one-page SVG overview of a file, written beside it or where `--out` says,
//! never over an existing file without `--overwrite`.

use super::Outcome;
use anyhow::{anyhow, bail, Context};
use coin_log::inspect::plot;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `coin-log plot`.
///
/// Draws a one-page SVG overview of FILE: the contact track and the centre's path seen from above (equal
/// axes), θ(t), the energy and invariant drifts |E − E₀| and |C − C₀| (relative, log scales), N/(Mg), and
/// |F|/N with μ when the scene gives one; the termination is marked on every time axis.
#[derive(Debug, clap::Args)]
pub struct PlotArgs {
    /// An MCAP file written by `coin-log record`.
    #[arg(value_name = "FILE")]
    file: PathBuf,
    /// Output SVG file [default: <FILE stem>.svg in the current folder].
    #[arg(short, long, value_name = "FILE.svg")]
    out: Option<PathBuf>,
    /// Replace the output file if it exists.
    #[arg(long)]
    overwrite: bool,
}

/// Runs `coin-log plot`.
pub fn run(args: &PlotArgs) -> anyhow::Result<Outcome> {
    let target = args.out.clone().unwrap_or_else(|| {
        let stem = args
            .file
            .file_stem()
            .map_or_else(|| "plot".into(), |s| s.to_string_lossy().into_owned());
        PathBuf::from(format!("{stem}.svg"))
    });
    if target.is_dir() {
        bail!(
            "`{}` is a folder; give the picture a file name, e.g. --out {}",
            target.display(),
            target.join("plot.svg").display()
        );
    }
    super::destination::refuse_special(&target)?;
    if target.exists() && !args.overwrite {
        bail!("`{}` already exists; pass --overwrite to replace it, or choose another file with --out", target.display());
    }
    let name = args.file.file_name().map_or_else(
        || args.file.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let svg = plot::plot(&args.file, &name).map_err(|e| anyhow!("{}: {e}", args.file.display()))?;
    let folder = super::destination::folder_of(&target);
    let mut temp = tempfile::Builder::new()
        .prefix(".coin-log-")
        .suffix(".svg.tmp")
        .tempfile_in(&folder)
        .with_context(|| format!("cannot write in `{}`", folder.display()))?;
    temp.write_all(svg.as_bytes())
        .and_then(|()| temp.as_file().sync_all())
        .with_context(|| format!("writing `{}`", target.display()))?;
    super::make_readable(temp.as_file());
    let moved = if args.overwrite {
        temp.persist(&target).map(|_| ()).map_err(|e| e.error)
    } else {
        temp.persist_noclobber(&target)
            .map(|_| ())
            .map_err(|e| e.error)
    };
    moved.map_err(|e| anyhow!("cannot move the picture to `{}`: {e}", target.display()))?;
    outln!("{}", target.display());
    Ok(Outcome::Success)
}
