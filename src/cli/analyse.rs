//! `coin-log analyse`: what a scene's motion will do, without simulating it, and the stability map of the
//! steady circles (format.md: analyse). The library computes (`coin_log::analyse`); this file loads the
//! scene, prints, and writes the map's files.

use super::scene_arg::load_source;
use super::text::number as n;
use super::Outcome;
use anyhow::{anyhow, Context};
use coin_log::analyse::map::{
    band_report, stability_map, Branches, Grid, MapOptions, DEFAULT_OMEGA_Z, DEFAULT_THETA,
};
use coin_log::analyse::{motion_name, Analysis, Stability, SteadyAnalysis};
use coin_log::files::{shown, OutputFolder};
use coin_log::model::nutation::Motion;
use coin_log::model::{Coin, CoinParams, SteadyFamily};
use coin_log::scene::limits::MIN_DURATION;
use coin_log::scene::{RunFile, Scene};
use std::ffi::{OsStr, OsString};
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `coin-log analyse`.
///
/// `coin-log analyse SCENE` says what the scene's initial state will do without simulating it: E, C1, C2,
/// the range of θ, the nutation period T and the heading advance ΔΦ per period by quadrature
/// (docs/physics.md §10), the smallest normal force and the friction coefficient the motion needs; for a
/// steady motion its rates, radii, σ², the eigenvalues of its linearisation and whether it is stable
/// (docs/physics.md §9). `coin-log analyse map` maps the stability of the steady circles.
///
/// `map` is a subcommand: to analyse a scene file called `map`, write its path as `./map`.
#[derive(Debug, clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct AnalyseArgs {
    #[command(subcommand)]
    command: Option<AnalyseCommand>,
    /// A built-in scene (listed by `coin-log scenes`) or a scene file, as for `record`.
    #[arg(required = true)]
    scene: Option<OsString>,
    /// Print one JSON object (docs/format.md: analyse --json).
    #[arg(long)]
    json: bool,
    /// Set a scene key first: KEY is a dotted path (`initial.theta`, `body.shape`), VALUE a TOML value or
    /// a bare string. Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    set: Vec<String>,
}

#[derive(Debug, clap::Subcommand)]
enum AnalyseCommand {
    /// The stability map of the steady circles: σ² over a grid of (θ0, ω_Z0) on either branch, written as
    /// stability-map.csv and stability-map.svg.
    ///
    /// The CSV has the columns theta0, omega_z0, branch, omega_y0, sigma_squared, verdict. The SVG shows
    /// σ² by colour (blue stable, red unstable, darker for larger |σ²|), the boundary σ² = 0 in closed
    /// form, ω_c of straight rolling and the built-in scenes' steady motions. The summary gives the
    /// unstable band's edges and where it closes (docs/physics.md §9).
    Map(MapArgs),
}

/// Arguments of `coin-log analyse map`.
#[derive(Debug, clap::Args)]
struct MapArgs {
    /// A scene whose body to map (built-in name or scene file, as for `record`) [default: the thin disk,
    /// M = a = g = 1].
    scene: Option<OsString>,
    /// θ0 grid A:B:N: N values from A to B, each with 0 < |θ0| < π/2 [rad].
    #[arg(long, value_name = "A:B:N", default_value = DEFAULT_THETA, allow_hyphen_values = true)]
    theta: String,
    /// ω_Z0 grid A:B:N: N values from A to B [rad per time unit].
    #[arg(
        long = "omega-z",
        value_name = "A:B:N",
        default_value = DEFAULT_OMEGA_Z,
        allow_hyphen_values = true
    )]
    omega_z: String,
    /// Which root of the steady family: +, - or both.
    #[arg(
        long,
        value_name = "+|-|both",
        default_value = "both",
        allow_hyphen_values = true,
        hide_possible_values = true,
        value_parser = super::Suggested(Branches::NAMES)
    )]
    branch: String,
    /// Folder for stability-map.csv and stability-map.svg (created if missing; the files are replaced).
    #[arg(long, value_name = "DIR", default_value = ".")]
    out: PathBuf,
}

/// Runs `coin-log analyse`.
pub fn run(args: AnalyseArgs) -> anyhow::Result<Outcome> {
    match (args.command, args.scene) {
        (Some(AnalyseCommand::Map(map)), _) => run_map(&map),
        (None, Some(scene)) => run_scene(&scene, &args.set, args.json),
        (None, None) => Err(anyhow!("give a SCENE to analyse, or `map`")),
    }
}

/// The scene SCENE with `sets`, validated, and its name in messages. Of the run settings analyse uses
/// only `run.flat_margin`: the others (duration, rate, integrator, tolerances, budget) are left out, so
/// that a value only record refuses does not refuse the analysis (a spin of 1e9 with the scene's duration
/// 30 was refused for its samples). The duration stands at the shortest, which bounds no motion.
fn load_scene(arg: &OsStr, sets: &[String]) -> anyhow::Result<(String, Scene)> {
    let mut source = load_source(arg, sets)?;
    let flat_margin = source.file.run.as_ref().and_then(|r| r.flat_margin);
    source.file.run = Some(RunFile {
        duration: Some(MIN_DURATION),
        flat_margin,
        ..RunFile::default()
    });
    let label = source.label;
    let scene = Scene::from_file(&source.file).map_err(|e| anyhow!("scene `{label}`: {e}"))?;
    Ok((label, scene))
}

/// An estimated relative error of the quadrature above which its numbers get a warning (they are
/// ~1e-13 on ordinary scenes).
const UNRELIABLE: f64 = 1e-2;

fn run_scene(arg: &OsStr, sets: &[String], json: bool) -> anyhow::Result<Outcome> {
    let (arg, scene) = load_scene(arg, sets)?;
    let analysis = Analysis::of_scene(&scene).map_err(|e| anyhow!("scene `{arg}`: {e}"))?;
    if let Some(d) = &scene.dissipation {
        errln!(
            "note: scene `{arg}` has dissipation ({}): this is the conservative motion from its initial \
             state; the couple changes E, C1 and C2 (docs/physics.md §11), so the prediction holds for \
             times short against the dissipation's",
            d.model()
        );
    }
    if analysis.orbit.error > UNRELIABLE {
        errln!(
            "warning: scene `{arg}`: the quadrature's estimated relative error is {:.1e}: the period and \
             the advances per period (or the landing time) are not reliable to better than that (e.g. a \
             kick too small for double precision to resolve near a marginal state)",
            analysis.orbit.error
        );
    }
    if json {
        super::output::json(&analysis.json())?;
    } else {
        for (key, value) in summary(&arg, &scene, &analysis) {
            outln!("{key:<16} {value}");
        }
    }
    Ok(Outcome::Success)
}

fn body(p: &CoinParams) -> String {
    format!(
        "M = {}, a = {}, g = {}, I_X = {}, I_Z = {}",
        n(p.mass()),
        n(p.radius()),
        n(p.gravity()),
        n(p.inertia_x()),
        n(p.inertia_z())
    )
}

/// The rows of the human summary.
fn summary(label: &str, scene: &Scene, a: &Analysis) -> Vec<(&'static str, String)> {
    let s = &a.state;
    let o = &a.orbit;
    let mut rows = vec![
        ("scene", label.to_string()),
        ("body", body(&scene.params)),
        (
            "state",
            format!(
                "θ = {}, ω = ({}, {}, {})",
                n(s.theta),
                n(s.omega_x),
                n(s.omega_y),
                n(s.omega_z)
            ),
        ),
        ("energy", format!("E = {}", n(o.energy))),
        ("invariants", format!("C1 = {}, C2 = {}", n(o.c1), n(o.c2))),
    ];
    match (&a.steady, o.motion) {
        (Some(steady), _) => rows.extend(steady_rows(steady)),
        (None, motion) => rows.extend(motion_rows(a, motion, scene.run.flat_margin)),
    }
    if let Some(base) = &a.base_steady {
        rows.push((
            "perturbed from",
            format!(
                "{}; σ² = {}, {}",
                family(base),
                n(base.sigma_squared),
                verdict(base)
            ),
        ));
    }
    rows.extend(force_rows(a));
    rows
}

fn family(s: &SteadyAnalysis) -> String {
    let name = match s.steady.kind.family() {
        SteadyFamily::Straight => "steady: straight rolling",
        SteadyFamily::CentreFixed => "steady: centre at rest",
        SteadyFamily::Circle => "steady circle",
        SteadyFamily::SpinUpright => "steady: spinning upright in place",
    };
    match s.steady.kind.branch() {
        Some(b) => format!("{name} ({b} branch)"),
        None => name.to_string(),
    }
}

fn verdict(s: &SteadyAnalysis) -> String {
    match s.verdict {
        Stability::Stable => format!(
            "stable: small perturbations nutate with period 2π/σ = {}",
            n(s.nutation_period().unwrap_or(f64::NAN))
        ),
        Stability::Unstable => format!(
            "unstable: small perturbations grow like e^(t/τ), τ = 1/√(−σ²) = {}",
            n(s.e_folding_time().unwrap_or(f64::NAN))
        ),
        Stability::Marginal => {
            "marginal: σ² = 0 to rounding, the linearisation does not decide".to_string()
        }
    }
}

fn steady_rows(s: &SteadyAnalysis) -> Vec<(&'static str, String)> {
    let m = &s.steady;
    let radius = |r: Option<f64>| r.map_or_else(|| "∞".to_string(), n);
    let root = s.eigenvalues[2];
    let pair = if root.1 != 0.0 {
        format!("±{} i", n(root.1))
    } else {
        format!("±{}", n(root.0))
    };
    vec![
        ("motion", family(s)),
        (
            "rates",
            format!(
                "ω_Y = {}, φ̇ = {}, ψ̇ = {}",
                n(m.state.omega_y),
                n(m.phi_dot),
                n(m.psi_dot)
            ),
        ),
        (
            "radii",
            format!("R_G = {}, R_C = {}", radius(m.r_g), radius(m.r_c)),
        ),
        (
            "forces",
            format!("N = {}, |F| = {}", n(s.normal), n(s.friction)),
        ),
        (
            "σ²",
            format!("{} (docs/physics.md §9, eq (21))", n(s.sigma_squared)),
        ),
        ("eigenvalues", format!("0, 0, {pair}")),
        ("verdict", verdict(s)),
    ]
}

fn motion_rows(a: &Analysis, motion: Motion, flat_margin: f64) -> Vec<(&'static str, String)> {
    let o = &a.orbit;
    let mut rows = Vec::new();
    match motion {
        Motion::Periodic {
            period,
            precession,
            spin_advance,
        } => {
            rows.push((
                "motion",
                format!(
                    "{}: θ between {} and {}",
                    motion_name(&motion),
                    n(o.theta_min),
                    n(o.theta_max)
                ),
            ));
            rows.push(("period", format!("T = {}", n(period))));
            rows.push((
                "heading",
                format!(
                    "ΔΦ = {} rad per period (mean φ̇ = {})",
                    n(precession),
                    n(precession / period)
                ),
            ));
            rows.push(("spin", format!("ΔΨ = {} rad per period", n(spin_advance))));
        }
        Motion::FlatLanding { theta, time } => {
            let first = match o.lift_off {
                Some(e) if e.time < time => format!(
                    "lifts off at t = {} (N reaches 0, θ = {}) before it would land flat: ",
                    n(e.time),
                    n(e.theta)
                ),
                _ => String::new(),
            };
            rows.push((
                "motion",
                format!(
                    "{first}lands flat: θ reaches {} (flat margin {}) at t = {}, from θ = {}",
                    n(theta),
                    n(flat_margin),
                    n(time),
                    n(if theta > 0.0 {
                        o.theta_min
                    } else {
                        o.theta_max
                    })
                ),
            ));
        }
        Motion::Steady => {}
    }
    rows.push((
        "quadrature",
        format!("estimated relative error {:.1e}", o.error),
    ));
    rows
}

fn force_rows(a: &Analysis) -> Vec<(&'static str, String)> {
    let o = &a.orbit;
    let normal = match o.lift_off {
        Some(event) => format!(
            "min N = {} at θ = {}: N reaches 0 at θ = {}, t = {}, where the coin lifts off",
            n(o.min_normal.value),
            n(o.min_normal.theta),
            n(event.theta),
            n(event.time)
        ),
        None => format!(
            "min N = {} at θ = {}: stays positive",
            n(o.min_normal.value),
            n(o.min_normal.theta)
        ),
    };
    let need = o.max_friction_ratio.map_or_else(
        || "|F|/N grows without bound as N reaches 0: no μ keeps it rolling".to_string(),
        |e| {
            format!(
                "needs μ ≥ max |F|/N = {} (at θ = {})",
                n(e.value),
                n(e.theta)
            )
        },
    );
    let friction = match (a.friction, a.slips()) {
        (Some(mu), Some(true)) => format!("{need}; the scene's μ = {}: it slips", n(mu)),
        (Some(mu), _) => format!("{need}; the scene's μ = {} holds", n(mu)),
        (None, _) => need,
    };
    vec![("normal force", normal), ("friction", friction)]
}

/// The map's files.
const CSV: &str = "stability-map.csv";
const SVG: &str = "stability-map.svg";

fn run_map(args: &MapArgs) -> anyhow::Result<Outcome> {
    let options = MapOptions {
        theta: Grid::parse("--theta", &args.theta)?,
        omega_z: Grid::parse("--omega-z", &args.omega_z)?,
        branches: args.branch.parse::<Branches>()?,
    };
    let scene = args
        .scene
        .as_deref()
        .map(|s| load_scene(s, &[]))
        .transpose()?;
    let coin = scene
        .as_ref()
        .map_or_else(|| Coin::new(CoinParams::unit_disk()), |(_, s)| s.coin());
    // Checked before any work (the grid, its CSV and SVG are 1.2 s and 0.8 GB at the largest), creating
    // nothing, so that the work leaves nothing behind if it fails or a signal stops it.
    OutputFolder::check(&args.out, true, &[CSV, SVG])?;
    let started = Instant::now();
    let map = stability_map(
        &coin,
        &options,
        scene.as_ref().map(|(n, s)| (n.as_str(), s)),
    )?;
    let csv = map.csv();
    let svg = map.svg()?;
    let elapsed = started.elapsed().as_secs_f64();
    // The map replaces its own files; both are checked before either is moved into place.
    let mut folder = OutputFolder::create(&args.out, true)?;
    for (name, text) in [(CSV, &csv), (SVG, &svg)] {
        let shown_name = shown(&args.out.join(name));
        let mut file = folder.file(name)?;
        file.write_all(text.as_bytes())
            .with_context(|| format!("writing `{shown_name}`"))?;
    }
    folder.commit()?;
    let (csv_path, svg_path) = (args.out.join(CSV), args.out.join(SVG));
    let branches = match options.branches {
        Branches::Plus => "the + branch",
        Branches::Minus => "the − branch",
        Branches::Both => "both branches",
    };
    outln!("{:<16} {}", "body", body(coin.params()));
    outln!(
        "{:<16} θ0 {} × ω_Z0 {} on {branches}: {} circles, {} unstable",
        "grid",
        options.theta,
        options.omega_z,
        map.points.len(),
        map.unstable_count()
    );
    outln!(
        "{:<16} {} (straight rolling is unstable below it, docs/physics.md §5)",
        "ω_c",
        n(map.critical_spin)
    );
    let report = band_report(&coin);
    if !report.is_empty() {
        outln!("unstable band    σ² = 0 in closed form (docs/physics.md §9):");
        out!("{report}");
    }
    outln!(
        "{:<16} {}, {} ({elapsed:.3} s)",
        "wrote",
        shown(&csv_path),
        shown(&svg_path)
    );
    Ok(Outcome::Success)
}
