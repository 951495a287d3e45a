//! `coin-log plot`: the one-page SVG overview of a file, written beside it or where `--out` says,
//! never over an existing file without `--overwrite`.

use super::Outcome;
use anyhow::anyhow;
use coin_log::files::input::check;
use coin_log::files::{shown, InputKind, Output, Policy};
use coin_log::inspect::plot;
use std::io::Write;
use std::path::{Path, PathBuf};

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

/// Runs `coin-log plot`: exit 0 for a picture of the whole file; a file that breaks off part way is drawn
/// up to the break, and the problem is an error (exit 1).
pub fn run(args: &PlotArgs) -> anyhow::Result<Outcome> {
    if let Some((out, kind)) = args
        .out
        .as_deref()
        .and_then(|o| Some((o, other_picture(o)?)))
    {
        errln!(
            "error: --out {}: plot draws SVG only, and a {kind} name would hold SVG; give --out {} and \
             convert it afterwards if you need {kind} (rsvg-convert, Inkscape or a browser do)",
            shown(out),
            shown(&out.with_extension("svg")),
        );
        return Ok(Outcome::Unusable);
    }
    let shown_file = shown(&args.file);
    let target = args.out.clone().unwrap_or_else(|| {
        // The stem's own bytes, not a lossy copy: a name that is not UTF-8 keeps them.
        let mut name = args
            .file
            .file_stem()
            .map_or_else(|| "plot".into(), ToOwned::to_owned);
        name.push(".svg");
        PathBuf::from(name)
    });
    let policy = Policy {
        overwrite: args.overwrite,
        overwrite_flag: true,
        flag: "--out",
        example: "plot.svg".into(),
        protect: Some((args.file.clone(), "the recording being plotted")),
    };
    // Before reading: a bad target costs nothing.
    let mut output = Output::create(&target, &policy)?;
    check(&args.file, InputKind::Mcap).map_err(|e| anyhow!("{shown_file}: {e}"))?;
    let name = args
        .file
        .file_name()
        .map_or_else(|| shown_file.clone(), |n| shown(Path::new(n)));
    let picture = plot::plot(&args.file, &name).map_err(|e| anyhow!("{shown_file}: {e}"))?;
    output
        .file()
        .write_all(picture.svg.as_bytes())
        .map_err(|e| output.write_error(e))?;
    output.commit()?;
    outln!("{}", shown(&target));
    Ok(match picture.broken {
        Some(broken) => {
            errln!(
                "error: {shown_file}: {broken}; `{}` shows the file up to the break",
                shown(&target)
            );
            Outcome::Failure
        }
        None => Outcome::Success,
    })
}

/// The picture format that `target`'s extension names when it is one plot does not draw (PNG, PDF, ...):
/// `-o plot.png` wrote SVG under a PNG name without a word. Other extensions (`.svg`, `.v2`, none) pass.
fn other_picture(target: &Path) -> Option<&'static str> {
    let ext = target.extension()?.to_str()?.to_ascii_lowercase();
    Some(match ext.as_str() {
        "png" => "PNG",
        "pdf" => "PDF",
        "jpg" | "jpeg" => "JPEG",
        "gif" => "GIF",
        "webp" => "WEBP",
        "eps" => "EPS",
        "ps" => "PS",
        "tif" | "tiff" => "TIFF",
        "bmp" => "BMP",
        _ => return None,
    })
}
