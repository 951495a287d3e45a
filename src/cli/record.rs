//! `coin-log record`: load a scene, integrate it into a temporary file beside the target, move the finished
//! file into place without clobbering, print the summary. The library does the work; this file does paths,
//! signals, the progress bar, printing and exit codes.

use super::rss::peak_rss_bytes;
use super::scene_arg::{load_source, SceneSource};
use super::text::size;
use super::{destination, make_readable, output, Outcome};
use anyhow::{anyhow, bail, Context};
use coin_log::format::Encoding;
use coin_log::format::Termination;
use coin_log::record::{self, RecordOptions, RecordSummary};
use coin_log::scene::{self, limits, FlagOverrides, Scene};
use coin_log_mcap::Compression;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::{BufWriter, IsTerminal};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};
use tempfile::NamedTempFile;

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
    scene: String,
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
    /// Duration in the scene's time unit (overrides `run.duration`).
    #[arg(long, value_name = "T")]
    pub duration: Option<f64>,
    /// Samples per time unit (overrides `run.rate`; scene default 100).
    #[arg(long, value_name = "R")]
    pub rate: Option<f64>,
    /// Integrator: rk4, dopri5, dop853, gauss4 (overrides `run.integrator`; scene default dop853).
    #[arg(long, value_name = "NAME")]
    pub integrator: Option<String>,
    /// Relative tolerance of adaptive methods, 2.2e-15 to 1e-3 (overrides `run.rtol`; default 1e-10).
    #[arg(long, value_name = "X")]
    pub rtol: Option<f64>,
    /// Absolute tolerance of adaptive methods, at most 1e-3·min(1, a, 1/τ) (overrides `run.atol`; default
    /// 1e-12).
    #[arg(long, value_name = "X")]
    pub atol: Option<f64>,
    /// Step of fixed-step methods, rounded down to divide 1/rate; step·W ≤ 0.178 with W the fastest rate at
    /// t = 0 (overrides `run.step`; default 1e-3).
    #[arg(long, value_name = "H")]
    pub step: Option<f64>,
    /// Comma-separated channels: omega, angles, quaternion, position, contact, reaction, energy,
    /// invariants, tf, scene, and work with dissipation (overrides `record.channels`; default all).
    #[arg(long, value_name = "LIST", value_delimiter = ',')]
    pub channels: Option<Vec<String>>,
    /// Message encoding: json (JSON Schemas; readable as text) or protobuf (FileDescriptorSet schemas;
    /// about half the size, and Rerun reads it). Both carry the same f64 values (docs/format.md: Encodings).
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
            channels: self.channels.clone(),
        }
    }
}

/// Runs `coin-log record`: load → resolve → prepare the output → record → persist → summary and exit code.
pub fn run(args: RecordArgs) -> anyhow::Result<Outcome> {
    // First, so that a signal at any later stage finishes or abandons cleanly (never kills the process
    // with a temporary file behind).
    let signals = Signals::install()?;
    let source = load_source(&args.scene, &args.flags.set)?;
    let scene = resolve(&args, &source)?;
    if args.dry_run {
        return dry_run(&args, &scene, &source.label);
    }
    // Before simulating: say which required checks `verify` will not be able to run on this recording.
    for warning in coin_log::verify::coverage(&scene) {
        errln!("warning: verify will not be able to judge this recording: {warning}");
    }
    warn_if_large(&args, &scene);
    let target = output_path(&args, &source);
    let mut temp = prepare_output(&target, args.overwrite, &source, &signals)?;
    if signals.stopped() {
        errln!("interrupted before recording began: nothing was written");
        return Ok(Outcome::Interrupted);
    }
    let (summary, wall) = record_into(&args, &scene, &target, &mut temp, &signals)?;
    persist(temp, &target, args.overwrite, &signals)?;
    print_summary(&args, &scene, &source.label, &target, &summary, wall)?;
    Ok(outcome(&summary, &target))
}

/// Recordings estimated larger than this get a warning before they start \[bytes\].
const LARGE: u64 = 1 << 30;

/// `--dry-run`: the resolved scene as TOML after comment lines with the estimate (so the output is itself
/// a scene file), or with `--json` one object; nothing is written.
fn dry_run(args: &RecordArgs, scene: &Scene, label: &str) -> anyhow::Result<Outcome> {
    let e = record::estimate(scene, args.compression, args.flags.encoding);
    let toml = scene.to_toml();
    if args.json {
        let json = serde_json::json!({
            "scene": label,
            "resolved": toml,
            "samples": e.samples,
            "messages": e.messages,
            "channels": e.per_channel.iter().map(|(c, n)| (c.name().to_string(), *n)).collect::<std::collections::BTreeMap<_, _>>(),
            "estimated_bytes": e.bytes,
        });
        outln!("{}", serde_json::to_string(&json)?);
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
        let (flag, slot, said) = (Arc::clone(&stop), Arc::clone(&temp), Arc::clone(&first));
        ctrlc::set_handler(move || {
            if !flag.swap(true, Ordering::SeqCst) {
                errln!("{}", *said.lock().unwrap_or_else(PoisonError::into_inner));
                return;
            }
            let slot = slot.lock().unwrap_or_else(PoisonError::into_inner);
            if let Some(path) = slot.as_ref() {
                let _ = std::fs::remove_file(path);
            }
            errln!("stopped again: the recording is abandoned and nothing is written");
            #[allow(
                clippy::disallowed_methods,
                reason = "a second signal abandons the run at once; its temporary file is removed above"
            )]
            std::process::exit(130);
        })
        .context("cannot install the handler of SIGINT, SIGTERM and SIGHUP")?;
        Ok(Self { stop, temp, first })
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
    let scene = scene::resolve(&source.file, &flags)
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
    let (file, provenance) = flags.apply(&source.file);
    let method = scene.run.method.method;
    for (key, value) in limits::ignored_settings(file.run.as_ref(), method) {
        let by = provenance
            .iter()
            .find(|(k, _)| *k == key)
            .map_or_else(String::new, |(_, flag)| format!(" (set by `{flag}`)"));
        let uses = if method.is_adaptive() {
            "an adaptive method: it uses rtol and atol"
        } else {
            "a fixed-step method: it uses the step"
        };
        errln!(
            "warning: `{key}` = {value}{by} does not apply to {method}, {uses}; ignored (stored as 0)"
        );
    }
    if !method.is_adaptive() {
        let asked = file
            .run
            .as_ref()
            .and_then(|r| r.step)
            .unwrap_or(scene::defaults::STEP);
        let used = scene.run.method.step;
        if (asked - used).abs() > 1e-12 * asked {
            errln!(
                "note: step {asked} rounded down to {} so that a whole number of steps ({}) fits between samples (1/rate = {})",
                compact(used),
                (scene.run.sample_interval() / used).round(),
                compact(scene.run.sample_interval())
            );
        }
    }
    Ok(scene)
}

/// Where the recording goes (`-o`, or the scene's stem in the current folder).
fn output_path(args: &RecordArgs, source: &SceneSource) -> PathBuf {
    args.output
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("{}.mcap", source.stem)))
}

/// Checks the target and creates the temporary file beside it, all before simulating: the target must be
/// absent or (with `--overwrite`) a regular file other than the scene, and its name must be creatable.
pub(super) fn prepare_output(
    target: &Path,
    overwrite: bool,
    source: &SceneSource,
    signals: &Signals,
) -> anyhow::Result<NamedTempFile> {
    let existing =
        destination::check_target(target, overwrite, source.path.as_deref(), &source.stem)?;
    let mut slot = signals.slot();
    let temp = temp_file_beside(target)?;
    *slot = Some(temp.path().to_path_buf());
    drop(slot);
    destination::probe_target(target, existing.as_ref(), &temp)?;
    Ok(temp)
}

/// A temporary file in the target's folder, so that the finished recording is moved, not copied.
fn temp_file_beside(target: &Path) -> anyhow::Result<NamedTempFile> {
    let folder = destination::folder_of(target);
    tempfile::Builder::new()
        .prefix(".coin-log-")
        .suffix(".mcap.tmp")
        .tempfile_in(&folder)
        .with_context(|| {
            format!(
                "cannot write in `{}` (for `{}`)",
                folder.display(),
                target.display()
            )
        })
}

/// Records the scene into `temp` with a signal finishing the file early and a progress bar on long runs;
/// returns the summary and the wall time, the file synced to disk and readable.
fn record_into(
    args: &RecordArgs,
    scene: &Scene,
    target: &Path,
    temp: &mut NamedTempFile,
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
        BufWriter::with_capacity(WRITE_BUFFER, temp.as_file_mut()),
        &signals.stop,
        |t| update_progress(&bar, started, t / duration),
    );
    bar.finish_and_clear();
    let summary = result.with_context(|| format!("recording `{}`", target.display()))?;
    temp.as_file()
        .sync_all()
        .with_context(|| format!("writing `{}`", target.display()))?;
    let wall = started.elapsed();
    make_readable(temp.as_file());
    Ok((summary, wall))
}

/// Moves the finished recording into place; without `--overwrite` a file that appeared meanwhile is left
/// alone and the recording kept under its temporary name.
pub(super) fn persist(
    temp: NamedTempFile,
    target: &Path,
    overwrite: bool,
    signals: &Signals,
) -> anyhow::Result<()> {
    // Held until the move is done, so that a second signal cannot delete a file being moved.
    let mut slot = signals.slot();
    *slot = None;
    if overwrite {
        temp.persist(target).map_err(|e| {
            anyhow!(
                "cannot move the recording to `{}`: {}",
                target.display(),
                e.error
            )
        })?;
    } else if let Err(e) = temp.persist_noclobber(target) {
        // The target appeared while we were recording: keep our file rather than lose it.
        let kept = e.file.keep().map(|(_, p)| p);
        let kept = kept.map_or_else(|_| "(lost)".to_string(), |p| p.display().to_string());
        bail!(
            "`{}` appeared while recording and was left alone; the recording is kept at `{kept}`",
            target.display()
        );
    }
    Ok(())
}

/// The exit code of a finished recording; a numerical failure says where the samples stop.
pub(super) fn outcome(summary: &RecordSummary, target: &Path) -> Outcome {
    match &summary.failure {
        Some(f) => {
            errln!(
                "error: the integration failed at t = {}: {f}; `{}` holds the samples up to it",
                summary.termination_time,
                target.display()
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
        let json = json_summary(scene, label, target, s, wall);
        outln!("{}", serde_json::to_string(&json)?);
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
            target.display()
        );
    }
    Ok(())
}

/// Why an event is not to be trusted, in one sentence.
pub(super) fn untrusted_event(s: &RecordSummary) -> String {
    format!(
        "the {} at t = {} is not to be trusted: the energy drift {:.3e} is above {:.3e}, the energy \
         tolerance verify derives from these integrator settings, so the integration had gone wrong \
         before the event, which may be an artefact of it; tighten --rtol/--atol (dopri5, dop853) or \
         --step (rk4, gauss4)",
        s.termination.name(),
        s.termination_time,
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

/// A number in its shortest form when that is short (`0.001`, `0.0025`), else to 5 digits (`8.3333e-4`).
fn compact(x: f64) -> String {
    let shortest = x.to_string();
    let digits = shortest.trim_start_matches(['-', '0', '.']).len();
    if digits <= 6 {
        shortest
    } else {
        format!("{x:.4e}")
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

pub(super) fn json_summary(
    scene: &Scene,
    label: &str,
    target: &Path,
    s: &RecordSummary,
    wall: Duration,
) -> serde_json::Value {
    let seconds = wall.as_secs_f64();
    let m = &scene.run.method;
    let adaptive = m.method.is_adaptive();
    serde_json::json!({
        "scene": label,
        "file": target.display().to_string(),
        "samples": s.samples,
        "messages": s.messages,
        "bytes": s.bytes,
        "wall_time_s": seconds,
        "messages_per_second": messages_per_second(s, seconds),
        "integrator": m.method.name(),
        "rtol": adaptive.then_some(m.rtol),
        "atol": adaptive.then_some(m.atol),
        "step": (!adaptive).then_some(m.step),
        "steps": s.stats.steps,
        "rhs_evaluations": s.stats.rhs_evaluations,
        "rejected_steps": s.stats.rejected_steps,
        "energy_drift": s.energy_drift,
        "energy_tolerance": s.energy_tolerance,
        "invariant_drift": s.invariant_drift,
        "steady_residual": s.steady_residual,
        "termination": s.termination.name(),
        "termination_time": s.termination_time,
        "event_trusted": s.event_trusted,
        "dissipated_work": s.dissipated_work,
        "termination_alpha": s.termination_alpha,
        "peak_rss_bytes": peak_rss_bytes(),
    })
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
        ("file", format!("{} ({})", target.display(), size(s.bytes))),
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
    let mut termination = format!("{} at t = {}", s.termination.name(), s.termination_time);
    if let Some(a) = s.termination_alpha {
        termination.push_str(&format!(" (α = {a:.4e} rad from the table)"));
    }
    if s.event_trusted == Some(false) {
        termination.push_str(" (not to be trusted: energy drift above the tolerance)");
    }
    rows.push(("termination", termination));
    rows
}
