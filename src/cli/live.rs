//! `coin-log live`: simulate a scene at a chosen pace and serve it to Foxglove over the Foxglove WebSocket
//! protocol, optionally recording the same messages to a file. The library (`coin_log::live`) serves and
//! paces; this file does the address, signals, the optional file (as `record` does it), printing and exit
//! codes.

use super::record::{self, SceneFlags, Signals};
use super::scene_arg::load_source;
use super::text::number;
use super::{output, Outcome};
use anyhow::{anyhow, Context};
use coin_log::files::{shown, Output};
use coin_log::live::{Discard, LiveEvent, LiveServer, LiveTap, Pacing, DEFAULT_PORT};
use coin_log::record::{record_with_tap, RecordOptions, RecordSummary};
use coin_log::scene::Scene;
use coin_log_mcap::Compression;
use std::ffi::OsString;
use std::io::BufWriter;
use std::net::IpAddr;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Write buffer in front of the optional file.
const WRITE_BUFFER: usize = 1 << 20;
/// With `--exit`, time left to viewers to receive what is queued for them before the server closes.
const DRAIN: Duration = Duration::from_millis(500);
/// Falling further behind the pace than this gets a warning after the run.
const LAG_WARNING: Duration = Duration::from_millis(500);
/// How often the server, once the run is over, looks for Ctrl-C.
const SERVE_POLL: Duration = Duration::from_millis(100);

/// Arguments of `coin-log live` (the command's description is on its variant in `cli/mod.rs`).
#[derive(Debug, clap::Args)]
pub struct LiveArgs {
    /// A built-in scene (listed by `coin-log scenes`) or a scene file, as for `record`.
    scene: OsString,
    /// Simulated time units per second of wall time: 1 real time, 10 ten times faster, 0.1 slow motion
    /// (finite, above 0).
    #[arg(long, value_name = "X", default_value_t = 1.0, value_parser = parse_speed,
          allow_negative_numbers = true)]
    speed: f64,
    /// TCP port to serve on; 0 picks a free one (the URL printed says which).
    #[arg(long, value_name = "P", default_value_t = DEFAULT_PORT)]
    port: u16,
    /// IP address to listen on: 127.0.0.1 (this machine only), 0.0.0.0 or :: (every interface: anyone on
    /// the network can connect), or one interface's address.
    #[arg(long, value_name = "H", default_value = "127.0.0.1", value_parser = parse_host)]
    host: IpAddr,
    /// Start the clock at once instead of waiting for a viewer to subscribe.
    #[arg(long)]
    no_wait: bool,
    /// Exit when the run ends instead of serving its final state until Ctrl-C.
    #[arg(long)]
    exit: bool,
    /// Also record to FILE, exactly as `record -o FILE` would (temporary file, moved into place when
    /// finished, never replacing a file without --overwrite).
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
    /// Replace FILE if it exists.
    #[arg(long, requires = "output")]
    overwrite: bool,
    /// The scene flags, as for `record`.
    #[command(flatten)]
    flags: SceneFlags,
    /// Print the end-of-run summary as one JSON object.
    #[arg(long)]
    json: bool,
}

fn parse_speed(s: &str) -> Result<f64, String> {
    let x: f64 = s.trim().parse().map_err(|_| {
        format!("`{s}` is not a number; give simulated time units per wall second, e.g. 1 or 10")
    })?;
    Pacing::new(x, true).map(|p| p.speed()).ok_or_else(|| {
        format!("the speed must be a finite number above 0 (got {s}); 1 is real time, 10 ten times faster")
    })
}

fn parse_host(s: &str) -> Result<IpAddr, String> {
    let use_instead =
        "use 127.0.0.1 (this machine only), 0.0.0.0 (every interface) or one interface's address";
    let host: IpAddr = s
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not an IP address; {use_instead}"))?;
    // The system lets a server bind these, and then no viewer can ever connect: live waited forever.
    let group = match host {
        IpAddr::V4(v4) => v4.is_broadcast() || v4.is_multicast(),
        IpAddr::V6(v6) => v6.is_multicast(),
    };
    if group {
        return Err(format!(
            "`{s}` is a broadcast or multicast address, which no viewer can connect to; {use_instead}"
        ));
    }
    Ok(host)
}

/// Runs `coin-log live`: load → resolve → serve → record and serve at the pace → summary → serve the final
/// state until Ctrl-C (or `--exit`).
pub fn run(args: LiveArgs) -> anyhow::Result<Outcome> {
    let signals = Signals::install()?;
    if args.output.is_none() {
        signals.on_first_signal("stopping the run (signal again to quit at once)");
        signals.on_second_signal(
            "stopped again: quitting at once",
            Outcome::Interrupted.code(),
        );
    }
    let source = load_source(&args.scene, &args.flags.set)?;
    let scene = record::resolve_flags(args.flags.overrides(), args.flags.encoding, &source)?;
    let pacing = Pacing::new(args.speed, !args.no_wait)
        .ok_or_else(|| anyhow!("the speed must be a finite number above 0"))?;
    // The output first: a file that cannot be written is refused before a viewer is invited to connect
    // (a temporary file left by a server that cannot start is removed as the error returns).
    let mut file = args
        .output
        .as_ref()
        .map(|target| record::prepare_output(target, args.overwrite, &source, &signals))
        .transpose()?;
    let server =
        match LiveServer::start(args.host, args.port, &format!("coin-log {}", source.label)) {
            Ok(server) => server,
            Err(e) => {
                errln!("error: {e:#}; {}", bind_hint(&e.to_string()));
                return Ok(Outcome::Unusable);
            }
        };
    let mut tap = LiveTap::new(&server, pacing, &signals.stop, |event| tell(event, pacing));
    tap.announce_topics(&scene.channels, args.flags.encoding);
    announce(&args, &server, &source.label);
    let started = Instant::now();
    let options = RecordOptions {
        compression: Compression::default(),
        encoding: args.flags.encoding,
    };
    let summary = run_scene(&scene, &options, &mut tap, file.as_mut(), &signals)?;
    let wall = started.elapsed();
    if let Some(e) = tap.error() {
        errln!("warning: a topic could not be served: {e}");
    }
    let stats = Stats {
        served: tap.messages(),
        max_lag: tap.max_lag(),
        clock: tap.elapsed(),
        url: server.url(),
    };
    if let Some(output) = file.take() {
        record::persist(output, &signals)?;
    }
    print_summary(&args, &scene, &source.label, &summary, wall, &stats)?;
    let outcome = match &args.output {
        Some(target) => record::outcome(&summary, &scene, target),
        None => run_outcome(&summary),
    };
    // The run is over and its file complete: a signal now only closes the server, and a second one while
    // it closes abandons nothing.
    signals.on_first_signal("stopping the server");
    signals.on_second_signal(
        "stopped again: quitting at once (the run was over)",
        outcome.code(),
    );
    serve_final_state(&args, server, &signals);
    Ok(outcome)
}

/// What to do about an address that cannot be served.
fn bind_hint(error: &str) -> &'static str {
    if error.contains("in use") {
        "another program (or another `coin-log live`) uses this port: pick another with --port, or --port 0 \
         for any free one"
    } else {
        "check --host (an address of this machine) and --port"
    }
}

/// The URL to connect to, on stderr in a line of its own (`serving ws://…`), and what the address exposes.
fn announce(args: &LiveArgs, server: &LiveServer, label: &str) {
    errln!("serving `{label}` live at {}", server.url());
    errln!(
        "  open it in Foxglove: Open connection → Foxglove WebSocket → {}",
        server.url()
    );
    if args.host.is_loopback() {
        errln!("  (this machine only; --host 0.0.0.0 exposes it to the network)");
    } else {
        errln!(
            "  warning: listening on {}: anyone who can reach this machine on port {} can connect and watch \
             (no authentication, no encryption)",
            args.host,
            server.port()
        );
    }
}

fn tell(event: LiveEvent, pacing: Pacing) {
    match event {
        LiveEvent::Waiting => errln!(
            "waiting for a viewer: the clock starts when one subscribes (--no-wait starts it at once)"
        ),
        LiveEvent::Started { viewers } => errln!(
            "running at {}× real time ({viewers} viewer{} connected)",
            number(pacing.speed()),
            if viewers == 1 { "" } else { "s" }
        ),
    }
}

/// Records into the optional file (or nowhere) through the live tap.
fn run_scene<F: FnMut(LiveEvent)>(
    scene: &Scene,
    options: &RecordOptions,
    tap: &mut LiveTap<'_, F>,
    file: Option<&mut Output>,
    signals: &Signals,
) -> anyhow::Result<RecordSummary> {
    let stop = &signals.stop;
    let Some(output) = file else {
        return record_with_tap(scene, options, Discard::default(), tap, stop, |_| {})
            .context("running the scene");
    };
    let shown = shown(output.target());
    let writer = BufWriter::with_capacity(WRITE_BUFFER, output.file());
    record_with_tap(scene, options, writer, tap, stop, |_| {})
        .with_context(|| format!("recording `{shown}`"))
}

/// The exit code of a run without a file.
fn run_outcome(summary: &RecordSummary) -> Outcome {
    match &summary.failure {
        Some(f) => {
            errln!(
                "error: the integration failed at t = {}: {f}",
                summary.termination_time
            );
            Outcome::Failure
        }
        None if summary.termination == coin_log::format::Termination::Interrupted => {
            Outcome::Interrupted
        }
        None => Outcome::Success,
    }
}

/// What the live side of a run did.
struct Stats {
    /// Messages served.
    served: u64,
    /// At worst, how late a sample was served.
    max_lag: Duration,
    /// Wall time from the start of the clock to the end of the run.
    clock: Duration,
    url: String,
}

/// What `live --json` adds to `record`'s summary.
#[derive(serde::Serialize)]
struct LiveJson<'a> {
    url: &'a str,
    speed: f64,
    served_messages: u64,
    clock_s: f64,
    max_lag_s: f64,
}

/// `record`'s summary (the file row says when there is none) with the live rows; or one JSON object.
fn print_summary(
    args: &LiveArgs,
    scene: &Scene,
    label: &str,
    s: &RecordSummary,
    wall: Duration,
    live: &Stats,
) -> anyhow::Result<()> {
    let target = args.output.clone().unwrap_or_default();
    if args.json {
        let mut json = record::json_summary(scene, label, &target, s, wall);
        json.file = args.output.as_ref().map(|p| p.display().to_string());
        json.live = Some(LiveJson {
            url: &live.url,
            speed: args.speed,
            served_messages: live.served,
            clock_s: live.clock.as_secs_f64(),
            max_lag_s: live.max_lag.as_secs_f64(),
        });
        output::json(&json)?;
    } else {
        let mut rows = record::summary_rows(scene, label, &target, s, wall);
        if args.output.is_none() {
            for row in rows.iter_mut().filter(|r| r.0 == "file") {
                row.1 = "none (-o FILE records one)".to_string();
            }
        }
        rows.push((
            "live",
            format!(
                "{} at {}× real time: {} messages served in {:.3} s, at worst {:.1} ms behind the clock",
                live.url,
                number(args.speed),
                live.served,
                live.clock.as_secs_f64(),
                live.max_lag.as_secs_f64() * 1e3
            ),
        ));
        for (key, value) in rows {
            outln!("{key:<16} {value}");
        }
    }
    if s.event_trusted == Some(false) {
        errln!("warning: {}", record::untrusted_event(s));
    }
    if live.max_lag > LAG_WARNING {
        errln!(
            "warning: the run fell up to {:.1} s behind {}× real time (the simulation and serving were \
             slower than that); lower --speed, or --rate or --channels for fewer messages",
            live.max_lag.as_secs_f64(),
            number(args.speed)
        );
    }
    if output::stdout_failed() {
        errln!("note: only the summary was lost");
    }
    Ok(())
}

/// After the run: unless `--exit` or the run was stopped, keep serving the final state (a viewer that
/// connects now gets every topic's latest message) until Ctrl-C; then close the server.
fn serve_final_state(args: &LiveArgs, server: LiveServer, signals: &Signals) {
    if args.exit || signals.stopped() {
        if server.clients() > 0 {
            std::thread::sleep(DRAIN);
        }
    } else {
        errln!(
            "the run is over; still serving its final state at {} (Ctrl-C to stop)",
            server.url()
        );
        while !signals.stopped() {
            std::thread::sleep(SERVE_POLL);
        }
    }
    server.stop();
}
