//! `coin-log info`: what each file holds, as text or JSON, or the scene stored in one file.

use super::text::{counted, padded, size, COLUMN_MAX};
use super::Outcome;
use anyhow::bail;
use coin_log::files::input::check;
use coin_log::files::{shown, shown_name, InputKind};
use coin_log::format::metadata::number_string as n;
use coin_log::format::{header_library, Encoding, RunMetadata, Termination};
use coin_log::inspect::info::{self, FileInfo};
use coin_log::inspect::seconds_text;
use coin_log_mcap::Compression;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Arguments of `coin-log info`.
///
/// Shows what each file holds without opening a viewer: its channels (topic, schema, message count,
/// rate), the time range, the body and run settings, the termination, the file's size and compression and
/// the version that wrote it. Read from the summary section when the file has one (instant whatever its
/// size), otherwise by one pass over the file. `--scene` prints the stored scene as TOML after a comment
/// with the command line that records it again into the same bytes (`coin-log record s.toml -o G
/// --encoding E --compression C`, with the same coin-log version).
#[derive(Debug, clap::Args)]
pub struct InfoArgs {
    /// MCAP files.
    #[arg(required = true, value_name = "FILE")]
    files: Vec<PathBuf>,
    /// Print `{"files": [{"path", "file_size", "channels": [...], "body", "run", "result", ...}]}`
    /// (docs/format.md: info --json).
    #[arg(long, conflicts_with = "scene")]
    json: bool,
    /// Print the scene stored in FILE as a TOML scene file (one FILE).
    #[arg(long)]
    scene: bool,
}

/// `info --json`: `{"files": [...]}`, each a file's object or, for a file that could not be read, its path
/// and problem.
#[derive(serde::Serialize)]
struct Files {
    files: Vec<serde_json::Value>,
}

#[derive(serde::Serialize)]
struct Unreadable<'a> {
    path: &'a str,
    problem: &'a str,
}

/// Runs `coin-log info`: exit 0 when every file was described, 1 otherwise.
pub fn run(args: &InfoArgs) -> anyhow::Result<Outcome> {
    if args.scene {
        return scene(args);
    }
    let mut failed = false;
    let mut json_files = Vec::new();
    for path in &args.files {
        // As given in JSON (which escapes what it must), escaped in text.
        let given = path.display().to_string();
        match read(path) {
            Ok(i) => {
                // Described up to the break on stdout, and named on stderr as every error is: exit 1
                // with nothing on stderr left a script that keeps stderr without the reason.
                if let Some(problem) = &i.problem {
                    failed = true;
                    errln!("error: {}: {problem}", shown(path));
                }
                if args.json {
                    json_files.push(serde_json::to_value(i.json(&given))?);
                } else {
                    out!("{}", text(&shown(path), &i));
                }
            }
            Err(e) => {
                failed = true;
                errln!("error: {}: {e}", shown(path));
                if args.json {
                    json_files.push(serde_json::to_value(Unreadable {
                        path: &given,
                        problem: &e,
                    })?);
                }
            }
        }
    }
    if args.json {
        super::output::json(&Files { files: json_files })?;
    }
    Ok(if failed {
        Outcome::Failure
    } else {
        Outcome::Success
    })
}

/// What the file at `path` holds; a path that is not a regular file is refused without being opened (a
/// named pipe would block: files::input).
fn read(path: &Path) -> Result<FileInfo, String> {
    check(path, InputKind::Mcap).map_err(|e| e.to_string())?;
    info::info(path).map_err(|e| e.to_string())
}

/// `--scene`: the stored scene, after comment lines saying where it comes from and how to reproduce it.
fn scene(args: &InfoArgs) -> anyhow::Result<Outcome> {
    let [path] = args.files.as_slice() else {
        // A usage error (exit 2), as `--scene --json` is clap's.
        errln!(
            "error: --scene prints the scene of one file; {} were given",
            args.files.len()
        );
        return Ok(Outcome::Unusable);
    };
    let shown = shown(path);
    let i = read(path).map_err(|e| anyhow::anyhow!("{shown}: {e}"))?;
    let run = match &i.run {
        Ok(run) => run,
        Err(e) => bail!("{shown}: {e}"),
    };
    out!(
        "{}{}",
        reproduction(&shown, &i, run),
        coin_log::scene::readable_toml(&run.scene)
    );
    // The scene is still worth having, but a file that could not be read to its end is an error, as
    // for `info` without --scene.
    if let Some(problem) = &i.problem {
        errln!("error: {shown}: {problem}");
        return Ok(Outcome::Failure);
    }
    Ok(Outcome::Success)
}

/// The comment lines before `--scene`'s TOML: the `coin-log record` command line that writes the file's
/// bytes again from that text (every setting the scene does not hold: encoding and compression), or why
/// no command can (mixed encodings or compressions, a file that could not be read to its end, or one
/// whose header names another library).
fn reproduction(shown: &str, i: &FileInfo, run: &RunMetadata) -> String {
    let mut text = format!(
        "# The scene stored in `{shown}` (written by coin-log {}).\n",
        run.tool_version
    );
    if i.problem.is_some() && i.read_to_end {
        // Read whole, but its summary is damaged (a file from another writer's layout, or a flipped
        // byte): `record` writes no such bytes. It said the file could not be read to its end.
        let _ = writeln!(
            text,
            "# Its summary section is damaged (the error says why), so no command line writes the same \
             bytes\n# again; the whole file was read."
        );
        return text;
    }
    if i.problem.is_some() {
        // Its encoding and compression are those of the part read, and its bytes are not all known.
        let _ = writeln!(
            text,
            "# It could not be read to its end (the error says why), so no command line is known to \
             write\n# the same bytes again."
        );
        return text;
    }
    let (encoding, compression) = (i.recorded_encoding(), i.compression());
    let named = |word: &str, names: &[&str]| names.contains(&word);
    if !named(&encoding, Encoding::NAMES) || !named(&compression, Compression::NAMES) {
        let _ = writeln!(
            text,
            "# Its encoding ({encoding}) and compression ({compression}) are not those of one `coin-log \
             record`,\n# so no command line writes the same bytes again."
        );
        return text;
    }
    // `record` names itself in the header: a file whose header names another library was rewritten by
    // another program (Python's or Rust's `mcap` writer), whatever it kept or changed.
    let library = &i.summary.library;
    if *library != header_library(&run.tool_version) {
        let _ = writeln!(
            text,
            "# Its header names the library `{}`, not coin-log {}: another program wrote these bytes,\n# so \
             no command line writes the same bytes again.",
            shown_name(library),
            run.tool_version
        );
        return text;
    }
    let _ = writeln!(
        text,
        "# Saved as SCENE.toml, with coin-log {} this writes the same bytes again:\n{REPRODUCE}SCENE.toml -o \
         OUT.mcap --encoding {encoding} --compression {compression}",
        run.tool_version
    );
    if let Some(result) = i
        .result
        .as_ref()
        .ok()
        .filter(|r| r.termination == Termination::Interrupted)
    {
        let _ = writeln!(
            text,
            "# (up to t = {}, where the run was interrupted: a run that is not interrupted goes on, and \
             ends differently)",
            n(result.termination_time)
        );
    }
    text
}

/// How the command line starts in `--scene`'s comment (tests find it by this).
pub const REPRODUCE: &str = "#     coin-log record ";

/// The text description of one file: a row per property, then the channels.
fn text(shown: &str, i: &FileInfo) -> String {
    let mut rows = file_rows(i);
    rows.extend(coin_log_rows(i));
    rows.push((
        "read from",
        match i.source {
            info::Source::Summary => "the summary section".into(),
            info::Source::Scan => "the whole file (it has no complete summary section)".into(),
        },
    ));
    if let Some(p) = &i.problem {
        rows.push(("problem", p.clone()));
    }
    let mut out = format!("{shown}\n");
    for (key, value) in rows {
        let _ = writeln!(out, "  {key:<13} {value}");
    }
    channels(&mut out, i);
    out
}

/// Size, compression, writer, description, time span and message count.
fn file_rows(i: &FileInfo) -> Vec<(&'static str, String)> {
    let (packed, unpacked) = (i.summary.compressed_bytes, i.summary.uncompressed_bytes);
    // A file cut inside its only chunk has seen that chunk's compression but counts no (complete) chunk.
    let chunks = match (i.summary.chunks, i.summary.compressions.is_empty()) {
        (0, true) => "no chunks".to_string(),
        (0, false) => format!("no complete chunk ({})", i.compression()),
        (n, _) => format!("{} {}", counted(n, "chunk"), i.compression()),
    };
    let mut rows = vec![(
        "file",
        format!(
            "{} ({} B), {chunks}, {} of records in {}",
            size(i.summary.file_len),
            i.summary.file_len,
            size(unpacked),
            size(packed)
        ),
    )];
    let schemas = match i.encoding().as_str() {
        "json" => "json (JSON Schemas)".to_string(),
        "protobuf" => "protobuf (FileDescriptorSet schemas)".to_string(),
        other => other.to_string(),
    };
    rows.push(("encoding", schemas));
    let version = i.run.as_ref().map_or_else(
        |_| String::new(),
        |r| format!(", format {}", r.format_version),
    );
    let library = if i.summary.library.is_empty() {
        "(no library named: no header, or an empty one)".into()
    } else {
        shown_name(&i.summary.library)
    };
    rows.push(("written by", format!("{library}{version}")));
    if let Some(d) = i.scene.as_ref().and_then(|s| s.description.as_ref()) {
        rows.push(("scene", shown_name(d)));
    }
    let span = i.summary.time_range.map_or_else(
        || "no messages".into(),
        |(a, b)| format!("t = {} … {}", seconds_text(a), seconds_text(b)),
    );
    rows.push(("time", span));
    rows.push(("messages", i.summary.messages.to_string()));
    rows
}

/// Body, run settings, steady motion and termination from the coin-log metadata.
fn coin_log_rows(i: &FileInfo) -> Vec<(&'static str, String)> {
    let r = match &i.run {
        Ok(r) => r,
        Err(e) => return vec![("coin-log", e.clone())],
    };
    let friction = r.friction.map_or_else(|| "none".into(), n);
    let mut rows = vec![
        (
            "body",
            format!(
                "M = {}, a = {}, g = {}, I_X = {}, I_Z = {}, μ {friction}, time unit √(a/g) = {}",
                n(r.mass),
                n(r.radius),
                n(r.gravity),
                n(r.inertia_x),
                n(r.inertia_z),
                n(r.time_unit)
            ),
        ),
        (
            "run",
            // The settings the method used (the others are stored as 0: docs/format.md).
            if r.integrator.is_adaptive() {
                format!(
                    "{}, rtol {}, atol {}, rate {}",
                    r.integrator,
                    n(r.rtol),
                    n(r.atol),
                    n(r.rate)
                )
            } else {
                format!("{}, step {}, rate {}", r.integrator, n(r.step), n(r.rate))
            },
        ),
    ];
    if let Some(k) = r.steady_kind {
        let opt = |v: Option<f64>| v.map_or_else(|| "-".into(), n);
        rows.push((
            "steady",
            format!(
                "{k}: φ̇ = {}, ψ̇ = {}, R_G = {}, R_C = {}",
                opt(r.phi_dot),
                opt(r.psi_dot),
                opt(r.r_g),
                opt(r.r_c)
            ),
        ));
    }
    rows.push((
        "termination",
        match &i.result {
            Ok(r) => format!(
                "{} at t = {} ({} steps, {} RHS evaluations, {} rejected)",
                r.termination,
                n(r.termination_time),
                r.steps,
                r.rhs_evaluations,
                r.rejected_steps
            ),
            Err(e) => e.clone(),
        },
    ));
    rows
}

fn channels(out: &mut String, i: &FileInfo) {
    let channels = i.channels();
    if channels.is_empty() {
        return; // the `encoding` row says "no channels"
    }
    // Each name escaped and cut once; the columns as wide as the widest, up to COLUMN_MAX.
    let cells: Vec<[String; 2]> = channels
        .iter()
        .map(|c| [shown_name(&c.topic), shown_name(&c.schema)])
        .collect();
    let width = |k: usize, header: &str| {
        let widest = cells.iter().map(|c| c[k].chars().count()).max();
        widest.unwrap_or(0).clamp(header.len(), COLUMN_MAX)
    };
    let (topic_w, schema_w) = (width(0, "topic"), width(1, "schema"));
    let _ = writeln!(
        out,
        "  {}  {}  {:>9}  {:>9}",
        padded("topic", topic_w),
        padded("schema", schema_w),
        "messages",
        "rate"
    );
    for (c, [topic, schema]) in channels.iter().zip(&cells) {
        let rate = c.rate.map_or_else(|| "-".into(), rate_text);
        let _ = writeln!(
            out,
            "  {}  {}  {:>9}  {rate:>9}",
            padded(topic, topic_w),
            padded(schema, schema_w),
            c.messages
        );
    }
}

/// A channel's rate with two decimals, or, below what two decimals show (a recording at 0.001 samples
/// per time unit printed `0.00`, as if it had no rate), with three significant digits: `1.00e-3`.
fn rate_text(rate: f64) -> String {
    let text = format!("{rate:.2}");
    if rate > 0.0 && text == "0.00" {
        format!("{rate:.2e}")
    } else {
        text
    }
}
