//! `coin-log record`: load a scene, integrate it into a temporary file beside the target, move the finished
//! file into place without clobbering, print the summary. The library does the work; this file does paths,
//! signals, the progress bar, printing and exit codes.

use super::rss::peak_rss_bytes;
use super::scene_arg::{load_source, SceneSource};
use super::text::help;
use super::text::{number, size};
use super::{output, Outcome};
use anyhow::{anyhow, Context};
use coin_log::files::output::check;
use coin_log::files::{shown, Output, Policy};
use coin_log::format::Encoding;
use coin_log::format::Termination;
use coin_log::record::{self, RecordOptions, RecordSummary};
use coin_log::scene::{self, compact, FlagOverrides, Scene};
use coin_log_mcap::Compression;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use std::ffi::OsString;
use std::io::{BufWriter, IsTerminal};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

/// Runs shorter than this show no progress bar.
const PROGRESS_DELAY: Duration = Duration::from_secs(1);
/// Resolution of the progress bar.
const PROGRESS_STEPS: u64 = 1000;
/// Write buffer in front of the file: the mcap writer issues many small writes.
const WRITE_BUFFER: usize = 1 << 20;

/// Arguments of `coin-log record`.
///
/// Integrates SCENE and writes its trajectory as an MCAP file. The file is written to a temporary file
/// beside the target and moved into place only when finished; an existing file is never replaced without
/// `--overwrite`, and never anything but a regular file (not a device, pipe, symbolic link, folder or the
/// scene file). A physical event (flat landing, lift-off, slip) ends the run normally (exit 0); a
/// numerical failure leaves the file finished up to it (exit 1); Ctrl-C, SIGTERM or SIGHUP finishes the
/// file with what was recorded, marked `interrupted` (exit 130), and a second signal abandons it.
#[derive(Debug, clap::Args)]
pub struct RecordArgs {
    /// A built-in scene (listed by `coin-log scenes`) or a scene file: a path (with a `/` or ending in
    /// `.toml`) is always the file; a bare name is the built-in, with a note if a file of that name is here.
    scene: OsString,
    /// Output file [default: <scene name or file stem>.mcap in the current folder].
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
    /// The scene flags.
    #[command(flatten)]
    pub flags: SceneFlags,
    /// Chunk compression.
    #[arg(long, default_value_t, value_parser = super::named::<Compression>())]
    compression: Compression,
    /// Replace FILE if it exists.
    #[arg(long)]
    overwrite: bool,
    /// Print the end-of-run summary as one JSON object.
    #[arg(long)]
    json: bool,
    /// Resolve and validate the scene, print it with every default filled in and the estimated number of
    /// messages and file size, and exit without writing.
    #[arg(long)]
    dry_run: bool,
}

/// The flags `record` and `live` share: scene overrides, edits and the message encoding.
#[derive(Debug, Clone, clap::Args)]
pub struct SceneFlags {
    // The bounds in these help texts are the ones scene::limits enforces, printed from its constants.
    #[arg(long, value_name = "T", help = help::duration())]
    pub duration: Option<f64>,
    /// Samples per time unit, > 0, at most 1/(1e-9 + 3·2⁻⁵²·T) (just under 1e9: samples stay ≥ 1 ns apart)
    /// (overrides `run.rate`; scene default 100).
    #[arg(long, value_name = "R")]
    pub rate: Option<f64>,
    /// Integrator: rk4, dopri5, dop853, gauss4 (overrides `run.integrator`; scene default dop853).
    #[arg(long, value_name = "NAME", hide_possible_values = true,
          value_parser = super::Suggested(coin_log::integrate::Method::NAMES))]
    pub integrator: Option<String>,
    #[arg(long, value_name = "X", help = help::rtol())]
    pub rtol: Option<f64>,
    #[arg(long, value_name = "X", help = help::atol())]
    pub atol: Option<f64>,
    #[arg(long, value_name = "H", help = help::step())]
    pub step: Option<f64>,
    /// Most integrator steps, ≥ 1: a fixed-step run needing more is refused before it starts, an adaptive
    /// one stops when they are spent (termination `step-budget-spent`, exit 1) (overrides `run.max_steps`;
    /// default 100000000, under a minute of work).
    #[arg(long, value_name = "N", value_parser = whole_steps)]
    pub max_steps: Option<u64>,
    /// Comma-separated channels: omega, angles, quaternion, position, contact, reaction, energy,
    /// invariants, tf, scene, and work with dissipation, rerun with --encoding protobuf (overrides
    /// `record.channels`; default all but work and rerun).
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub channels: Option<Vec<String>>,
    /// Add the `rerun` channel: the coin, table and track as geometry for Rerun's MCAP importer (needs
    /// --encoding protobuf; about +6 % file size, docs/format.md: Rerun geometry) (sets `record.rerun`).
    #[arg(long)]
    pub rerun: bool,
    /// Message encoding: json (JSON Schemas; readable as text) or protobuf (FileDescriptorSet schemas;
    /// records about twice as fast, and Rerun reads it; the file is about 0.9× JSON's size with zstd,
    /// 0.65× with lz4, 0.5× uncompressed, measured on `wobble`: README, Performance). Both carry the same
    /// f64 values (docs/format.md: Encodings).
    #[arg(long, default_value_t, value_parser = super::named::<Encoding>())]
    pub encoding: Encoding,
    /// Set a scene key before the flags above apply: KEY is a dotted path (`initial.theta`, `run.rtol`,
    /// `body.shape`), VALUE a TOML value or a bare string. Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

impl SceneFlags {
    /// The flags that override scene keys.
    pub(super) fn overrides(&self) -> FlagOverrides {
        FlagOverrides {
            duration: self.duration,
            rate: self.rate,
            integrator: self.integrator.clone(),
            rtol: self.rtol,
            atol: self.atol,
            step: self.step,
            max_steps: self.max_steps,
            channels: self.channels.clone(),
            rerun: self.rerun,
        }
    }
}

/// `--max-steps N`: a whole number in digits (the parser's "invalid digit found in string" said neither
/// what was wrong with `1e8` nor what to write).
fn whole_steps(text: &str) -> Result<u64, String> {
    text.parse().map_err(|_| {
        "not a whole number of steps in digits: write e.g. 100000000 (not 1e8, 1_000 or 1.5)"
            .to_string()
    })
}

/// Runs `coin-log record`: load → resolve → prepare the output → record → persist → summary and exit code.
pub fn run(args: RecordArgs) -> anyhow::Result<Outcome> {
    // First, so that a signal at any later stage finishes or abandons cleanly (never kills the process
    // with a temporary file behind).
    let signals = Signals::install()?;
    let source = load_source(&args.scene, &args.flags.set)?;
    let scene = resolve(&args, &source)?;
    if args.dry_run {
        // The output is checked as the recording would check it (creating nothing), so that a dry run
        // that passes is not followed by a recording refused at once; a warning, since the resolved scene
        // it prints does not depend on it (`--dry-run > scene.toml` beside an earlier recording).
        let target = output_path(&args, &source);
        if let Err(e) = check(&target, &output_policy(args.overwrite, &source)) {
            errln!("warning: the recording itself would be refused: {e}");
        }
        return dry_run(&args, &scene, &source.label);
    }
    // Before simulating: say which required checks `verify` will not be able to run on this recording.
    let coverage = coin_log::verify::coverage(&scene);
    for warning in &coverage {
        errln!("warning: verify will not be able to judge this recording: {warning}");
    }
    warn_if_large(&args, &scene);
    let shortfalls = record::expected_shortfalls(&scene);
    if !shortfalls.is_empty() {
        let said: Vec<String> = shortfalls.iter().map(ToString::to_string).collect();
        errln!(
            "warning: verify is expected to refuse this recording (the summary and the file's metadata say so too): {}",
            said.join("; ")
        );
    }
    let target = output_path(&args, &source);
    let mut output = prepare_output(&target, args.overwrite, &source, &signals)?;
    if signals.stopped() {
        errln!("interrupted before recording began: nothing was written");
        return Ok(Outcome::Interrupted);
    }
    let (summary, wall) = record_into(&args, &scene, &mut output, &signals)?;
    persist(output, &signals)?;
    print_summary(&args, &scene, &source.label, &target, &summary, wall)?;
    // A run that ended early has fewer samples and a tighter tolerance than its duration promised.
    if summary.termination_time < scene.run.duration {
        for warning in coin_log::verify::coverage_over(&scene, summary.termination_time) {
            if !coverage.contains(&warning) {
                errln!(
                    "warning: verify will not be able to judge this recording, which ended at t = {} \
                     before its duration: {warning}",
                    number(summary.termination_time)
                );
            }
        }
    }
    Ok(outcome(&summary, &scene, &target))
}

/// Recordings estimated larger than this get a warning before they start \[bytes\].
const LARGE: u64 = 1 << 30;

/// `--dry-run`: the resolved scene as TOML after comment lines with the estimate (so the output is itself
/// a scene file), or with `--json` one object; nothing is written.
fn dry_run(args: &RecordArgs, scene: &Scene, label: &str) -> anyhow::Result<Outcome> {
    let e = record::estimate(scene, args.compression, args.flags.encoding);
    let toml = coin_log::scene::readable_toml(&scene.to_toml());
    if args.json {
        #[derive(Serialize)]
        struct DryRun<'a> {
            scene: &'a str,
            resolved: &'a str,
            samples: u64,
            messages: u64,
            channels: std::collections::BTreeMap<&'static str, u64>,
            estimated_bytes: u64,
        }
        output::json(&DryRun {
            scene: label,
            resolved: &toml,
            samples: e.samples,
            messages: e.messages,
            channels: e.per_channel.iter().map(|(c, n)| (c.name(), *n)).collect(),
            estimated_bytes: e.bytes,
        })?;
        return Ok(Outcome::Success);
    }
    out!(
        "# `{label}` resolved, every default filled in (coin-log record --dry-run: nothing written).\n\
         # Estimate for the full duration: {} samples, {} messages, about {} with {} chunks{}\n\
         # (within a factor of {} on typical scenes; a run ended by an event writes less).\n{toml}",
        e.samples,
        e.messages,
        size(e.bytes),
        args.compression,
        match args.flags.encoding {
            Encoding::Json => "",
            Encoding::Protobuf => " of Protobuf messages",
        },
        record::estimate::ACCURACY
    );
    Ok(Outcome::Success)
}

/// Warns on stderr before a recording estimated larger than [`LARGE`].
fn warn_if_large(args: &RecordArgs, scene: &Scene) {
    let e = record::estimate(scene, args.compression, args.flags.encoding);
    if e.bytes > LARGE {
        errln!(
            "warning: this recording is estimated at {} ({} messages); `--dry-run` shows the estimate, \
             --duration, --rate and --channels make it smaller",
            size(e.bytes),
            e.messages
        );
    }
}

/// SIGINT, SIGTERM and SIGHUP (ctrlc's `termination` feature): the first finishes the file with what was
/// recorded, marked `interrupted`; a second abandons the recording at once, deleting the temporary file.
pub(super) struct Signals {
    pub(super) stop: Arc<AtomicBool>,
    /// What the first signal says it does (`live` says more than "finishing the file").
    #[cfg_attr(not(feature = "live"), allow(dead_code))]
    first: Arc<Mutex<&'static str>>,
    /// What a second signal says as it quits at once, and the exit code (`live`: once the run is over its
    /// file is complete and nothing is abandoned).
    #[cfg_attr(not(feature = "live"), allow(dead_code))]
    again: Arc<Mutex<(&'static str, u8)>>,
    /// The temporary file while it exists (locked while it is created and moved into place).
    temp: Arc<Mutex<Option<PathBuf>>>,
}

impl Signals {
    pub(super) fn install() -> anyhow::Result<Self> {
        let stop = Arc::new(AtomicBool::new(false));
        let temp: Arc<Mutex<Option<PathBuf>>> = Arc::new(Mutex::new(None));
        let first = Arc::new(Mutex::new(
            "stopping: finishing the file with what was recorded (signal again to abandon it)",
        ));
        let again = Arc::new(Mutex::new((
            "stopped again: the recording is abandoned and nothing is written",
            130,
        )));
        let (flag, slot, said) = (Arc::clone(&stop), Arc::clone(&temp), Arc::clone(&first));
        let quit = Arc::clone(&again);
        ctrlc::set_handler(move || {
            if !flag.swap(true, Ordering::SeqCst) {
                errln!("{}", *said.lock().unwrap_or_else(PoisonError::into_inner));
                return;
            }
            let slot = slot.lock().unwrap_or_else(PoisonError::into_inner);
            if let Some(path) = slot.as_ref() {
                let _ = std::fs::remove_file(path);
            }
            let (message, code) = *quit.lock().unwrap_or_else(PoisonError::into_inner);
            errln!("{message}");
            #[allow(
                clippy::disallowed_methods,
                reason = "a second signal abandons the run at once; its temporary file is removed above"
            )]
            std::process::exit(i32::from(code));
        })
        .context("cannot install the handler of SIGINT, SIGTERM and SIGHUP")?;
        Ok(Self {
            stop,
            temp,
            first,
            again,
        })
    }

    /// What a second signal will say as it quits at once, and the exit code, from now on.
    #[cfg_attr(not(feature = "live"), allow(dead_code))]
    pub(super) fn on_second_signal(&self, message: &'static str, code: u8) {
        *self.again.lock().unwrap_or_else(PoisonError::into_inner) = (message, code);
    }

    /// What the first signal will say it does from now on.
    #[cfg_attr(not(feature = "live"), allow(dead_code))]
    pub(super) fn on_first_signal(&self, message: &'static str) {
        *self.first.lock().unwrap_or_else(PoisonError::into_inner) = message;
    }

    pub(super) fn stopped(&self) -> bool {
        self.stop.load(Ordering::SeqCst)
    }

    fn slot(&self) -> MutexGuard<'_, Option<PathBuf>> {
        self.temp.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// The scene with the command-line flags applied and validated; warns about settings the integrator does
/// not use and notes a step rounded to the sampling grid.
fn resolve(args: &RecordArgs, source: &SceneSource) -> anyhow::Result<Scene> {
    resolve_flags(args.flags.overrides(), args.flags.encoding, source)
}

/// [`resolve`] with the flags given as scene overrides (shared with `live`); a run too long for the
/// Protobuf timestamps of `encoding` is refused.
pub(super) fn resolve_flags(
    flags: FlagOverrides,
    encoding: Encoding,
    source: &SceneSource,
) -> anyhow::Result<Scene> {
    let (scene, notes) = scene::resolve_with_notes(&source.file, &flags)
        .map_err(|e| anyhow!("scene `{}`: {e}", source.label))?;
    let max = record::foxglove::PROTOBUF_MAX_SECONDS;
    if encoding == Encoding::Protobuf && scene.run.duration > max {
        return Err(anyhow!(
            "scene `{}`: run.duration = {} is longer than {max} time units, the most Foxglove's Protobuf \
             timestamps hold (32-bit seconds); record it with --encoding json, or shorten it with --duration",
            source.label,
            scene.run.duration
        ));
    }
    if let Some(c) = scene
        .channels
        .iter()
        .find(|c| !c.encodings().contains(&encoding))
    {
        return Err(anyhow!(
            "scene `{}`: {}",
            source.label,
            record::RecordError::Encoding { channel: *c }
        ));
    }
    for note in notes {
        let kind = if note.is_warning() { "warning" } else { "note" };
        errln!("{kind}: {note}");
    }
    Ok(scene)
}

/// Where the recording goes (`-o`, or the scene's stem in the current folder).
fn output_path(args: &RecordArgs, source: &SceneSource) -> PathBuf {
    args.output.clone().unwrap_or_else(|| {
        let mut name = source.stem.clone();
        name.push(".mcap");
        PathBuf::from(name)
    })
}

/// What the recording's target may be: a regular file (replaced with `--overwrite`), never the scene.
fn output_policy(overwrite: bool, source: &SceneSource) -> Policy {
    Policy {
        overwrite,
        overwrite_flag: true,
        flag: "-o",
        example: format!("{}.mcap", source.stem.to_string_lossy()).into(),
        protect: source
            .path
            .clone()
            .map(|p| (p, "the scene file being recorded")),
    }
}

/// Checks the target and creates the temporary file beside it, all before simulating (files::output):
/// the target must be absent or (with `--overwrite`) a regular file other than the scene.
pub(super) fn prepare_output(
    target: &Path,
    overwrite: bool,
    source: &SceneSource,
    signals: &Signals,
) -> anyhow::Result<Output> {
    let policy = output_policy(overwrite, source);
    // Locked while the temporary file is created, so that a second signal finds it to delete.
    let mut slot = signals.slot();
    let output = Output::create(target, &policy)?;
    *slot = Some(output.temp_path().to_path_buf());
    Ok(output)
}

/// Records the scene into `output` with a signal finishing the file early and a progress bar on long runs;
/// returns the summary and the wall time.
fn record_into(
    args: &RecordArgs,
    scene: &Scene,
    output: &mut Output,
    signals: &Signals,
) -> anyhow::Result<(RecordSummary, Duration)> {
    let options = RecordOptions {
        compression: args.compression,
        encoding: args.flags.encoding,
    };
    let bar = progress_bar();
    let started = Instant::now();
    let duration = scene.run.duration;
    let result = record::record(
        scene,
        &options,
        BufWriter::with_capacity(WRITE_BUFFER, output.file()),
        &signals.stop,
        |t| update_progress(&bar, started, t / duration),
    );
    bar.finish_and_clear();
    let summary = result.with_context(|| format!("recording `{}`", shown(output.target())))?;
    Ok((summary, started.elapsed()))
}

/// Moves the finished recording into place (synced; kept under the name the error gives if the move fails).
pub(super) fn persist(output: Output, signals: &Signals) -> anyhow::Result<()> {
    // Held until the move is done, so that a second signal cannot delete a file being moved.
    let mut slot = signals.slot();
    *slot = None;
    Ok(output.commit()?)
}

/// The exit code of a finished recording; a numerical failure says where the samples stop.
pub(super) fn outcome(summary: &RecordSummary, scene: &Scene, target: &Path) -> Outcome {
    match &summary.failure {
        Some(f) => {
            let fix = summary
                .budget_advice(scene.run.duration, scene.dissipation.is_some())
                .map_or_else(String::new, |advice| format!(" ({advice})"));
            errln!(
                "error: the integration failed at t = {}: {f}{fix}; `{}` holds the samples up to it",
                number(summary.termination_time),
                shown(target)
            );
            Outcome::Failure
        }
        None if summary.termination == Termination::Interrupted => Outcome::Interrupted,
        None => Outcome::Success,
    }
}

/// A bar that stays hidden for the first second and when stderr is not a terminal.
fn progress_bar() -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(PROGRESS_STEPS), ProgressDrawTarget::hidden());
    if let Ok(style) = ProgressStyle::with_template("{bar:40} {percent:>3}% {elapsed} (eta {eta})")
    {
        bar.set_style(style);
    }
    bar
}

fn update_progress(bar: &ProgressBar, started: Instant, fraction: f64) {
    if bar.is_hidden() && started.elapsed() > PROGRESS_DELAY && std::io::stderr().is_terminal() {
        bar.set_draw_target(ProgressDrawTarget::stderr());
    }
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    bar.set_position((fraction.clamp(0.0, 1.0) * PROGRESS_STEPS as f64) as u64);
}

/// The end-of-run summary on stdout (format.md: record, Summary): a table, or one JSON object.
fn print_summary(
    args: &RecordArgs,
    scene: &Scene,
    label: &str,
    target: &Path,
    s: &RecordSummary,
    wall: Duration,
) -> anyhow::Result<()> {
    if args.json {
        output::json(&json_summary::<()>(scene, label, target, s, wall))?;
    } else {
        for (key, value) in summary_rows(scene, label, target, s, wall) {
            outln!("{key:<16} {value}");
        }
    }
    if s.event_trusted == Some(false) {
        errln!("warning: {}", untrusted_event(s));
    }
    if output::stdout_failed() {
        errln!(
            "note: the recording `{}` is complete; only its summary was lost",
            shown(target)
        );
    }
    Ok(())
}

/// Why an event is not to be trusted, in one sentence.
pub(super) fn untrusted_event(s: &RecordSummary) -> String {
    if let Some(doubt) = &s.event_doubt {
        return format!(
            "the {} at t = {} is not to be trusted: {doubt}",
            s.termination.name(),
            number(s.termination_time)
        );
    }
    format!(
        "the {} at t = {} is not to be trusted: the energy drift {:.3e} is above {:.3e}, the energy \
         tolerance verify derives from these integrator settings, so the integration had gone wrong \
         before the event, which may be an artefact of it; tighten --rtol/--atol (dopri5, dop853) or \
         --step (rk4, gauss4)",
        s.termination.name(),
        number(s.termination_time),
        s.energy_drift,
        s.energy_tolerance
    )
}

/// The integrator with the settings it used: `dop853 (rtol 1e-10, atol 1e-12)`, `rk4 (step 0.001)`.
fn integrator_settings(scene: &Scene) -> String {
    let m = &scene.run.method;
    if m.method.is_adaptive() {
        format!("{} (rtol {:e}, atol {:e})", m.method, m.rtol, m.atol)
    } else {
        format!("{} (step {})", m.method, compact(m.step))
    }
}

#[allow(clippy::cast_precision_loss)]
fn messages_per_second(s: &RecordSummary, seconds: f64) -> f64 {
    if seconds > 0.0 {
        s.messages as f64 / seconds
    } else {
        0.0
    }
}

/// The object `record --json` prints: the library's summary with what the command adds (format.md:
/// record, Summary); `live` adds its own fields.
#[derive(Serialize)]
pub(super) struct SummaryJson<'a, Live: Serialize> {
    scene: &'a str,
    /// The output file; `null` for `live` without `-o`.
    pub(super) file: Option<String>,
    #[serde(flatten)]
    summary: &'a RecordSummary,
    wall_time_s: f64,
    messages_per_second: f64,
    integrator: &'static str,
    rtol: Option<f64>,
    atol: Option<f64>,
    step: Option<f64>,
    peak_rss_bytes: Option<u64>,
    #[serde(flatten)]
    pub(super) live: Option<Live>,
}

pub(super) fn json_summary<'a, Live: Serialize>(
    scene: &Scene,
    label: &'a str,
    target: &Path,
    s: &'a RecordSummary,
    wall: Duration,
) -> SummaryJson<'a, Live> {
    let seconds = wall.as_secs_f64();
    let m = &scene.run.method;
    let adaptive = m.method.is_adaptive();
    SummaryJson {
        scene: label,
        file: Some(target.display().to_string()),
        summary: s,
        wall_time_s: seconds,
        messages_per_second: messages_per_second(s, seconds),
        integrator: m.method.name(),
        rtol: adaptive.then_some(m.rtol),
        atol: adaptive.then_some(m.atol),
        step: (!adaptive).then_some(m.step),
        peak_rss_bytes: peak_rss_bytes(),
        live: None,
    }
}

pub(super) fn summary_rows(
    scene: &Scene,
    label: &str,
    target: &Path,
    s: &RecordSummary,
    wall: Duration,
) -> Vec<(&'static str, String)> {
    let seconds = wall.as_secs_f64();
    let mut rows: Vec<(&str, String)> = vec![
        ("scene", label.to_string()),
        ("file", format!("{} ({})", shown(target), size(s.bytes))),
        ("samples", s.samples.to_string()),
        ("messages", s.messages.to_string()),
        (
            "wall time",
            format!(
                "{seconds:.3} s ({:.0} messages/s)",
                messages_per_second(s, seconds)
            ),
        ),
        (
            "integrator",
            format!(
                "{}: {} steps, {} RHS evaluations, {} rejected",
                integrator_settings(scene),
                s.stats.steps,
                s.stats.rhs_evaluations,
                s.stats.rejected_steps
            ),
        ),
    ];
    rows.extend(physics_rows(s));
    rows
}

/// The summary's rows after the integrator: drift (of E + W with dissipation, physics §11), W, C1/C2
/// drift, steady residual, termination (with α for a dissipative run, and a warning when the event is
/// not to be trusted).
fn physics_rows(s: &RecordSummary) -> Vec<(&'static str, String)> {
    let mut rows = Vec::new();
    match s.dissipated_work {
        Some(w) => {
            rows.push((
                "energy balance",
                format!("{:.3e} (drift of E + W)", s.energy_drift),
            ));
            rows.push(("dissipated W", format!("{w:.6e}")));
        }
        None => rows.push(("energy drift", format!("{:.3e}", s.energy_drift))),
    }
    if let Some(d) = s.invariant_drift {
        rows.push(("C1/C2 drift", format!("{d:.3e}")));
    }
    if let Some(r) = s.steady_residual {
        rows.push(("steady residual", format!("{r:.3e}")));
    }
    let mut termination = format!(
        "{} at t = {}",
        s.termination.name(),
        number(s.termination_time)
    );
    if let Some(a) = s.termination_alpha {
        termination.push_str(&format!(" (α = {a:.4e} rad from the table)"));
    }
    if s.event_trusted == Some(false) {
        termination.push_str(if s.event_doubt.is_some() {
            " (not to be trusted: the departure from upright is subnormal)"
        } else {
            " (not to be trusted: energy drift above the tolerance)"
        });
    }
    rows.push(("termination", termination));
    if !s.shortfalls.is_empty() {
        let checks: Vec<&str> = s
            .shortfalls
            .iter()
            .flat_map(|f| f.checks.iter().copied())
            .collect();
        rows.push((
            "verify",
            format!(
                "expected to fail {} (settings looser than its tolerances)",
                checks.join(", ")
            ),
        ));
    }
    rows
}
