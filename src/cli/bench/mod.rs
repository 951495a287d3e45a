//! `coin-log bench`: accuracy against cost of every integrator, the hard-case suite, and throughput
//! and memory of record and verify.

mod sweep;
mod throughput;

use super::Outcome;
use anyhow::bail;
use coin_log::files::output::check;
use coin_log::files::{escaped, shown, Output, OutputFolder, Policy};
use coin_log::integrate::Method;
use coin_log_bench::euler::{euler_bench, EulerOptions, SLIP_FRICTION, WINDOW_TOP};
use coin_log_bench::plot::{euler_svg, work_precision_svg};
use coin_log_bench::precision::{precision_bench, PrecisionOptions};
use coin_log_bench::presets::{bench_case, bench_case_from_toml, DEFAULT_PRECISION_SCENES};
use coin_log_bench::table::{
    euler_csv, euler_table, precision_csv, precision_table, stability_csv, stability_table,
};
use coin_log_bench::BenchCase;
use coin_log_bench::{stability, suite};
use std::path::{Path, PathBuf};

/// Arguments of `coin-log bench`.
#[derive(Debug, clap::Args)]
pub struct BenchArgs {
    #[command(subcommand)]
    command: BenchCommand,
}

#[derive(Debug, clap::Subcommand)]
enum BenchCommand {
    /// Error against run time of every integrator on scenes (table, CSV, SVG work-precision diagrams).
    ///
    /// Adaptive methods sweep atol from 1e-6 to 1e-16 (rtol = min(1e3·atol, 1e-3)); fixed-step methods a
    /// geometric sweep of steps spanning the same errors. The state error is the largest of |Δθ|, |Δφ|,
    /// |Δψ|, |Δω|·√(a/g), |Δx|/a, |Δz|/a over samples at 100 per time unit, against the analytic
    /// trajectory for unperturbed steady scenes, otherwise dop853 at atol 1e-16, rtol 1e-14.
    Precision(PrecisionArgs),
    /// The hard-case suite: fast spin, near flat, landing and lift-off, marginal stability, long horizon,
    /// scale invariance; every case with every integrator.
    Stability(StabilityArgs),
    /// Record, verify and export speed and memory on the real channel set, against the zstd bound.
    ///
    /// Records `wobble` with the seven channels omega, angles, quaternion, position, contact, reaction,
    /// energy at 1 kHz with zstd, each run in a child `coin-log record` process; times zstd alone on the
    /// same JSON bytes (the bound); verifies and exports the file in a child `coin-log verify` and `coin-log
    /// export`; reports messages/s, MB/s, file size and peak RSS at two durations (100 and 1000 time units;
    /// 1000 and 10000 with --long). Medians of --repeats runs. (The integration and one RHS evaluation are
    /// criterion benchmarks: `cargo bench -p coin-log-bench`.)
    Throughput(throughput::ThroughputArgs),
    /// Euler's disk: the time law α = A (t0 − t)^n of each dissipation preset against n = 1/(1 − p).
    ///
    /// Each preset (moffatt, air-drag, viscous, rolling, pivoting) on the `euler-disk` toy from its
    /// centre-fixed motion at α0 = 0.2, κ set so that every preset has the time scale of the scene's
    /// Moffatt law (docs/physics.md §11); dop853 at the default tolerances until an event (or 3 time
    /// scales without a finite-time singularity). α = A |t0 − t|^n is fitted with t0 free on the window
    /// from α = 0.1 down to where the slow-change approximation starts to fail (|α̇|/(α σ) = 1e-3, σ the
    /// nutation frequency) or the motion has drifted off the centre-fixed family (ω_Z²/|ω|² = 1e-2),
    /// whichever comes first. Each preset is run again with μ = 0.3 to see where it slips. Writes
    /// euler.csv and euler.svg (log α against log |t0 − t| with the fitted lines).
    Euler(EulerArgs),
    /// What a sweep costs beyond its runs: --jobs 2 against --jobs 1 on 200 short runs, the cost per run
    /// besides recording and verifying it, peak memory and catalogue size of 1000 and 10 000 runs, and
    /// the resume of a finished 1000-run sweep; each sweep a child `coin-log sweep`. Writes sweep.csv.
    Sweep(sweep::SweepBenchArgs),
}

/// Arguments of `coin-log bench euler`.
#[derive(Debug, clap::Args)]
struct EulerArgs {
    /// Folder for `euler.csv` and `euler.svg` (created if missing).
    #[arg(long, default_value = "bench-results")]
    out: PathBuf,
}

/// Arguments of `coin-log bench precision`.
#[derive(Debug, clap::Args)]
struct PrecisionArgs {
    /// Built-in scene names or scene files, as for `record` (default: wobble, circle-plus, high-spin).
    scenes: Vec<String>,
    /// Folder for `precision.csv` and `precision-<scene>.svg` (created if missing).
    #[arg(long, default_value = "bench-results")]
    out: PathBuf,
    /// Timed repeats per point after one warm-up run; the median is reported.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..))]
    repeats: u32,
}

/// Arguments of `coin-log bench stability`.
#[derive(Debug, clap::Args)]
struct StabilityArgs {
    /// Folder for `stability.csv` (created if missing).
    #[arg(long, default_value = "bench-results")]
    out: PathBuf,
}

pub fn run(args: BenchArgs) -> anyhow::Result<Outcome> {
    match args.command {
        BenchCommand::Precision(a) => precision(&a),
        BenchCommand::Stability(a) => stability_suite(&a),
        BenchCommand::Throughput(a) => throughput::run(&a),
        BenchCommand::Euler(a) => euler(&a),
        BenchCommand::Sweep(a) => sweep::run(&a),
    }
}

/// Creates the output folder and checks, before the (long) measurement, that every file the bench will
/// write there can be: a link, pipe or device in its place is refused now, not after the work.
fn create_dir(out: &Path, files: &[String]) -> anyhow::Result<()> {
    // Created as export's and man's folders are, so that a file or device in its place is named as such.
    OutputFolder::create(out, true)?.commit()?;
    for file in files {
        check(&out.join(file), &POLICY)?;
    }
    Ok(())
}

/// The result files replace an earlier run's (never a link, pipe or device: files::output). No example:
/// the files are named by the bench, so a refused one is moved away or another folder chosen (an example
/// made the fixes "choose a file path, e.g. --out bench-results" and "give the path it points to").
const POLICY: Policy = Policy {
    overwrite: true,
    overwrite_flag: false,
    flag: "--out",
    example: std::borrow::Cow::Borrowed(""),
    protect: None,
};

/// Writes a result file.
fn write(path: &Path, contents: &str) -> anyhow::Result<()> {
    Ok(Output::write(path, &POLICY, contents.as_bytes())?)
}

/// A built-in scene by name, or a scene file by path (named by its stem), by the rule of
/// [`super::scene_arg`].
fn load_case(arg: &str) -> anyhow::Result<BenchCase> {
    let path = match super::scene_arg::classify(arg.as_ref())? {
        super::scene_arg::SceneArg::Builtin(name) => return Ok(bench_case(name)?),
        super::scene_arg::SceneArg::File(path) => path,
    };
    let text = super::scene_arg::read_scene_file(path)?;
    let stem = path
        .file_stem()
        .map_or_else(|| "scene".to_string(), |s| s.to_string_lossy().into_owned());
    Ok(bench_case_from_toml(&stem, &text)?)
}

fn precision(args: &PrecisionArgs) -> anyhow::Result<Outcome> {
    let names: Vec<String> = if args.scenes.is_empty() {
        DEFAULT_PRECISION_SCENES
            .iter()
            .map(|s| (*s).to_string())
            .collect()
    } else {
        args.scenes.clone()
    };
    // Resolve every scene before the (long) runs, so a typo fails at once.
    let cases = names
        .iter()
        .map(|n| load_case(n))
        .collect::<anyhow::Result<Vec<_>>>()?;
    // A scene is named in the CSV and the diagram's file by its name (a file's stem): two of one name
    // would share their rows' name and one diagram, the second replacing the first.
    for (i, case) in cases.iter().enumerate() {
        if let Some(j) = cases[..i].iter().position(|c| c.name == case.name) {
            let name = escaped(&case.name);
            let given = if names[j] == names[i] {
                format!("scene `{}` is given twice", escaped(&names[i]))
            } else {
                let (a, b) = (escaped(&names[j]), escaped(&names[i]));
                format!("scenes `{a}` and `{b}` are both named `{name}`")
            };
            bail!(
                "{given}: their rows in precision.csv and their diagram precision-{name}.svg could not be \
                 told apart; give each scene once, from files of different names"
            );
        }
    }
    let mut files: Vec<String> = cases
        .iter()
        .map(|c| format!("precision-{}.svg", c.name))
        .collect();
    files.push("precision.csv".into());
    create_dir(&args.out, &files)?;
    let options = PrecisionOptions::full(args.repeats as usize);
    let mut all_rows = Vec::new();
    for case in &cases {
        let report = precision_bench(case, Method::ALL, &options)?;
        outln!("scene {} — reference: {}", report.scene, report.reference);
        out!("{}", precision_table(&report.rows));
        for s in &report.slopes {
            let expected = s.integrator.order();
            outln!(
                "  {:>8}: slope {} (vs time), {} (vs RHS evaluations), order -{expected}, {} points",
                s.integrator.name(),
                s.time.map_or_else(|| "-".into(), |v| format!("{v:.2}")),
                s.work.map_or_else(|| "-".into(), |v| format!("{v:.2}")),
                s.points
            );
        }
        let svg_path = args.out.join(format!("precision-{}.svg", report.scene));
        write(&svg_path, &work_precision_svg(&report)?)?;
        outln!("  diagram: {}\n", shown(&svg_path));
        all_rows.extend(report.rows);
    }
    let csv_path = args.out.join("precision.csv");
    write(&csv_path, &precision_csv(&all_rows))?;
    outln!("CSV: {}", shown(&csv_path));
    Ok(Outcome::Success)
}

fn stability_suite(args: &StabilityArgs) -> anyhow::Result<Outcome> {
    create_dir(&args.out, &["stability.csv".into()])?;
    let rows = suite::run_suite(&stability::SuiteOptions::full())?;
    out!("{}", stability_table(&rows));
    let csv_path = args.out.join("stability.csv");
    write(&csv_path, &stability_csv(&rows))?;
    outln!("CSV: {}", shown(&csv_path));
    Ok(Outcome::Success)
}

fn euler(args: &EulerArgs) -> anyhow::Result<Outcome> {
    create_dir(&args.out, &["euler.csv".into(), "euler.svg".into()])?;
    let options = EulerOptions::full();
    let rows = euler_bench(&options)?;
    if let Some(first) = rows.first() {
        outln!(
            "euler-disk toy, every preset at the time scale T = {:.2} s of its Moffatt law; window from α = {WINDOW_TOP} down to |α̇|/(α σ) = {:e} or ω_Z²/|ω|² = {:e}, whichever comes first; ends without μ and with μ = {SLIP_FRICTION}",
            first.time_scale, options.epsilon, options.spin_share
        );
    }
    out!("{}", euler_table(&rows));
    let csv_path = args.out.join("euler.csv");
    write(&csv_path, &euler_csv(&rows))?;
    let svg_path = args.out.join("euler.svg");
    write(&svg_path, &euler_svg(&rows)?)?;
    outln!("CSV: {}\ndiagram: {}", shown(&csv_path), shown(&svg_path));
    Ok(Outcome::Success)
}
