//! `coin-log export`: a file's channels as CSV tables in a folder. Every table is written to a temporary
//! file in the folder and moved into place only when the whole file has been exported, so an error leaves
//! the folder as it was (and removes it if export created it); an existing table is never replaced
//! without `--overwrite` (files::output).

use super::progress::FileProgress;
use super::rss::peak_rss_bytes;
use super::Outcome;
use anyhow::{anyhow, bail};
use coin_log::files::input::check;
use coin_log::files::{shown, shown_name, InputKind, OutputFolder};
use coin_log::inspect::export::{self, ExportSummary, Layout};
use std::path::{Path, PathBuf};

/// The one-liners that turn the CSV tables into Parquet (pandas' default float parser is not exact; its
/// `round_trip` parser and polars' are).
pub const PARQUET_HINT: &str = "export CSV and convert it, e.g. with polars: python -c \"import polars as pl; \
pl.read_csv('DIR/omega.csv').write_parquet('omega.parquet')\", or with pandas: python -c \"import pandas as pd; \
pd.read_csv('DIR/omega.csv', float_precision='round_trip').to_parquet('omega.parquet')\"";

/// Arguments of `coin-log export`.
///
/// Writes the channels of FILE as CSV tables into DIR: one table per channel (`omega.csv`, `angles.csv`,
/// ..., `tf.csv` for the frame transforms flattened; `/scene` is display geometry and is skipped), or with
/// `--wide` one table `samples.csv` joined on t. The header is the field names; every number is written in
/// its shortest form that reads back to the same double, bit for bit. Memory stays flat whatever the
/// file's size.
#[derive(Debug, clap::Args)]
pub struct ExportArgs {
    /// An MCAP file written by `coin-log record`.
    #[arg(value_name = "FILE")]
    file: PathBuf,
    /// Folder for the tables (created if missing) [default: <FILE stem>-csv in the current folder].
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Table format. Only csv is built in (parquet would double the build; the error says how to convert).
    #[arg(long, value_enum, default_value_t = FormatArg::Csv)]
    format: FormatArg,
    /// One table `samples.csv`: t, then `<channel>.<field>` for every coin_log channel, one row per sample.
    #[arg(long)]
    wide: bool,
    /// Replace tables that exist in DIR (other CSV files there are left alone, and named in a warning).
    #[arg(long)]
    overwrite: bool,
    /// Print what was written as one JSON object: `{"file", "out", "messages", "tables": [{"name",
    /// "topics", "columns", "rows"}], "skipped": [{"topic", "reason"}], "peak_rss_bytes"}`.
    #[arg(long)]
    json: bool,
}

/// `--format`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum FormatArg {
    /// Comma-separated values, one header line.
    Csv,
    /// Apache Parquet (not built in: the error says how to convert the CSV).
    Parquet,
}

/// Runs `coin-log export`.
pub fn run(args: &ExportArgs) -> anyhow::Result<Outcome> {
    if args.format == FormatArg::Parquet {
        bail!(
            "--format parquet is not built in: the parquet and arrow crates would add 73 crates and \
             about 27 minutes to a cold build on a 2-core machine, against a few seconds to convert \
             the CSV tables, which hold the same numbers exactly; {PARQUET_HINT}"
        );
    }
    let shown_file = shown(&args.file);
    let len = check(&args.file, InputKind::Mcap)
        .map_err(|e| anyhow!("{shown_file}: {e}"))?
        .len();
    let dir = args.out.clone().unwrap_or_else(|| {
        // The stem's own bytes, not a lossy copy: a name that is not UTF-8 keeps them.
        let mut name = args
            .file
            .file_stem()
            .map_or_else(|| "export".into(), ToOwned::to_owned);
        name.push("-csv");
        PathBuf::from(name)
    });
    // Dropped on an error: every table and the folders it created go with it.
    let mut folder = OutputFolder::create(&dir, args.overwrite)?
        .with_overwrite_flag()
        .protecting(&args.file, "the recording being exported");
    let progress = FileProgress::new(&shown_file, len);
    let layout = if args.wide {
        Layout::Wide
    } else {
        Layout::PerChannel
    };
    let mut open = |name: &str| folder.file(name).map_err(std::io::Error::other);
    let result = export::export(&args.file, layout, &mut open, &|b| progress.update(b));
    progress.finish();
    let summary = result.map_err(|e| anyhow!("{shown_file}: {e}"))?;
    folder.commit()?;
    report(args, &dir, &summary)?;
    warn_of_other_tables(&dir, &summary);
    Ok(Outcome::Success)
}

/// Names the CSV files in `dir` this export did not write (an earlier export of another recording, with
/// other channels, into the same folder): they are left alone, since they may be the user's, but read
/// beside this export's tables they would mix two recordings.
fn warn_of_other_tables(dir: &Path, summary: &ExportSummary) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut others: Vec<String> = entries
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|name| name.ends_with(".csv") && !summary.tables.iter().any(|t| t.name == *name))
        .collect();
    if others.is_empty() {
        return;
    }
    others.sort();
    errln!(
        "warning: {} also holds {}, which this export did not write (an earlier export of another \
         recording?): remove them, or export into an empty folder, before reading the tables together",
        shown(dir),
        others.join(", ")
    );
}

fn report(args: &ExportArgs, dir: &Path, s: &ExportSummary) -> anyhow::Result<()> {
    if args.json {
        #[derive(serde::Serialize)]
        struct Json<'a> {
            file: String,
            out: String,
            #[serde(flatten)]
            summary: &'a ExportSummary,
            peak_rss_bytes: Option<u64>,
        }
        return Ok(super::output::json(&Json {
            file: args.file.display().to_string(),
            out: dir.display().to_string(),
            summary: s,
            peak_rss_bytes: peak_rss_bytes(),
        })?);
    }
    for t in &s.tables {
        outln!(
            "{}: {} rows × {} columns ({})",
            shown(&dir.join(&t.name)),
            t.rows,
            t.columns.len(),
            t.topics.join(", ")
        );
    }
    for k in &s.skipped {
        outln!("skipped {}: {}", shown_name(&k.topic), k.reason);
    }
    Ok(())
}
