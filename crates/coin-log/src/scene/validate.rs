//! [`SceneFile`] → [`Scene`]: every range check of format.md, all problems collected before failing, and the
//! way back (a resolved scene as a file with every default written out).

use super::file::{
    BodyFile, DissipationFile, InitialFile, PerturbationFile, RecordFile, RunFile, SceneFile,
    SteadyFile,
};
use super::limits;
use super::problems::{number, numbers, quoted, ProblemCollector, NOT_FINITE, POSITIVE};
use super::{defaults, InitialSpec, RunConfig, Scene, SceneError, SceneProblems, MAX_SAMPLES};
use crate::format::Channel;
use crate::integrate::{Method, MethodConfig};
use crate::model::{
    Coin, CoinParams, Dissipation, DissipationModel, Inertia, State, Steady, SteadyFamily,
    SteadyKind, MIN_RATE_EXPONENT,
};
use std::f64::consts::FRAC_PI_2;

/// Longest scene description, in characters: one line of `coin-log scenes` and `info` (the longest
/// built-in has 379).
pub const DESCRIPTION_MAX_CHARS: usize = 1000;

fn check_description(description: Option<&str>, problems: &mut ProblemCollector) {
    let Some(text) = description else {
        return;
    };
    let chars = text.chars().count();
    let head: String = text.chars().take(40).collect();
    let value = format!("{}{}", quoted(&head), if chars > 40 { "…" } else { "" });
    let reason = if text.chars().any(char::is_control) {
        "holds a line break or another control character: a description is one line of text (`coin-log \
         scenes` and `info` print it as one); write it on one line"
            .to_string()
    } else if chars > DESCRIPTION_MAX_CHARS {
        format!(
            "is {chars} characters long, more than the {DESCRIPTION_MAX_CHARS} of a description (one line \
             of `coin-log scenes` and `info`); shorten it"
        )
    } else {
        return;
    };
    problems.push("description", value, reason);
}

/// The lean range allowed by a flat margin (the default when it is not known), in words.
fn lean_range(margin: Option<f64>) -> String {
    let margin = margin.unwrap_or(defaults::FLAT_MARGIN);
    format!("is outside (−π/2 + {margin}, π/2 − {margin}) (run.flat_margin = {margin}): a rolling coin must lean less than flat")
}

pub(super) fn scene_from_file(
    file: &SceneFile,
    provenance: &[(&'static str, &'static str)],
) -> Result<Scene, SceneError> {
    let mut problems = ProblemCollector::new(provenance);
    let run_file = file.run.clone().unwrap_or_default();
    let flat_margin = run_file.flat_margin.unwrap_or(defaults::FLAT_MARGIN);
    let margin_ok = flat_margin.is_finite() && flat_margin > 0.0 && flat_margin < FRAC_PI_2;
    let margin = margin_ok.then_some(flat_margin);
    let body = check_body(&file.body, &mut problems);
    let initial = (body.as_ref())
        .and_then(|(params, ..)| check_initial(&file.initial, params, margin, &mut problems));
    // Without a valid body the initial state cannot be solved; still check what can be checked alone.
    if body.is_none() {
        check_initial_alone(&file.initial, margin, &mut problems);
    }
    let dissipation = check_dissipation(file.body.dissipation.as_ref(), &mut problems);
    check_description(file.description.as_deref(), &mut problems);
    let run = check_run(&run_file, flat_margin, margin_ok, &mut problems);
    let channels = check_channels(
        file.record.as_ref(),
        file.body.dissipation.is_some(),
        &mut problems,
    );
    let scene = match (body, initial, run, channels, dissipation) {
        (
            Some((params, inertia, friction, thickness)),
            Some((base, spec, perturbation)),
            Some(run),
            Some(channels),
            Some(dissipation),
        ) if problems.list.is_empty() => Some(Scene {
            description: file.description.clone().unwrap_or_default(),
            params,
            inertia,
            friction,
            thickness,
            dissipation,
            initial: perturbed(&base, &perturbation),
            base,
            spec,
            perturbation,
            run,
            channels,
        }),
        _ => None,
    };
    if let Some(scene) = &scene {
        limits::check_resolved(scene, file, &mut problems);
    }
    if problems.list.is_empty() {
        if let Some(scene) = scene {
            return Ok(scene);
        }
        // Every check that rejects a part reports why; should one ever fail to, still say something.
        problems.push("scene", "", UNEXPLAINED);
    }
    Err(SceneError::Invalid(SceneProblems(problems.list)))
}

/// The reason given if a scene were refused without a problem (a bug; the fuzz targets look for it).
pub const UNEXPLAINED: &str =
    "could not be resolved, and no check said why: this is a bug in coin-log, please report it with the scene";

type Body = (CoinParams, Inertia, Option<f64>, f64);

fn check_body(body: &BodyFile, problems: &mut ProblemCollector) -> Option<Body> {
    let mut ok = problems.positive("body.mass", body.mass);
    ok &= problems.positive("body.radius", body.radius);
    ok &= problems.positive("body.gravity", body.gravity);
    let inertia = check_inertia(body, problems);
    if let Some(mu) = body.friction {
        ok &= problems.positive("body.friction", mu);
    }
    let thickness = body.thickness.unwrap_or(defaults::THICKNESS);
    ok &= problems.positive("body.thickness", thickness);
    let inertia = inertia?;
    if !ok || !limits::check_scales(body, inertia, problems) {
        return None;
    }
    // Each value positive, each scale in range: the model accepts them (else UNEXPLAINED says so).
    let params = CoinParams::new(body.mass, body.radius, body.gravity, inertia).ok()?;
    Some((params, inertia, body.friction, thickness))
}

fn check_inertia(body: &BodyFile, problems: &mut ProblemCollector) -> Option<Inertia> {
    match (&body.shape, body.inertia_x, body.inertia_z) {
        (Some(shape), None, None) => match shape.as_str() {
            "thin-disk" => Some(Inertia::ThinDisk),
            "hoop" => Some(Inertia::Hoop),
            other => problems.reject(
                "body.shape",
                quoted(other),
                "is not a known shape: use \"thin-disk\" or \"hoop\", or give inertia_x and inertia_z instead",
            ),
        },
        (Some(shape), _, _) => problems.reject(
            "body.shape",
            quoted(shape),
            "is given together with inertia_x/inertia_z: give either a shape or both inertias, not both",
        ),
        (None, Some(ix), Some(iz)) => {
            let good =
                problems.positive("body.inertia_x", ix) & problems.positive("body.inertia_z", iz);
            if good && iz > 2.0 * ix {
                problems.reject(
                    "body.inertia_z",
                    number(iz),
                    format!(
                        "is more than 2·inertia_x = {}: no rigid axisymmetric body has I_Z > 2 I_X",
                        number(2.0 * ix)
                    ),
                )
            } else {
                good.then_some(Inertia::Explicit {
                    inertia_x: ix,
                    inertia_z: iz,
                })
            }
        }
        (None, Some(_), None) => problems.missing(
            "body.inertia_z",
            "is missing: inertia_x needs inertia_z too",
        ),
        (None, None, Some(_)) => problems.missing(
            "body.inertia_x",
            "is missing: inertia_z needs inertia_x too",
        ),
        (None, None, None) => problems.missing(
            "body.shape",
            "is missing: give shape = \"thin-disk\" or \"hoop\", or both inertia_x and inertia_z",
        ),
    }
}

type Initial = (State, InitialSpec, [f64; 4]);

/// `body.dissipation` (physics §11): `Some(None)` without one, `Some(Some(law))` for a valid one, `None`
/// when something is wrong (reported).
fn check_dissipation(
    file: Option<&DissipationFile>,
    problems: &mut ProblemCollector,
) -> Option<Option<Dissipation>> {
    let Some(d) = file else {
        return Some(None);
    };
    let before = problems.list.len();
    let model = problems.parse::<DissipationModel>("body.dissipation.model", &d.model, |e| {
        format!(
            "is not a dissipation model: use one of {}",
            e.valid.join(", ")
        )
    });
    let coefficient = problems.required(
        "body.dissipation.coefficient",
        d.coefficient,
        |c| c >= 0.0,
        "is outside [0, ∞): give κ as a finite number ≥ 0, in the scene's units",
        "is missing: give κ of P = κ |φ̇|^m (sin α)^(−k), e.g. coefficient = 1e-6",
    );
    let (m, k) = match model.map(|model| (model, model.exponents())) {
        Some((model, Some((m, k)))) => {
            for (name, value) in [("m", d.m), ("k", d.k)] {
                if let Some(v) = value {
                    problems.push(
                        format!("body.dissipation.{name}"),
                        number(v),
                        format!(
                            "does not apply to model \"{model}\", which fixes m = {m}, k = {k}: use model = \"power-law\" to choose m and k"
                        ),
                    );
                }
            }
            (m, k)
        }
        Some((_, None)) => power_law_exponents(d, problems),
        None => (f64::NAN, f64::NAN),
    };
    if problems.list.len() != before {
        return None;
    }
    // Each value checked above as the model checks it (else UNEXPLAINED says so).
    Dissipation::new(model?, coefficient, m, k).ok().map(Some)
}

fn power_law_exponents(d: &DissipationFile, problems: &mut ProblemCollector) -> (f64, f64) {
    const NEEDS: &str = "is missing: model \"power-law\" needs m (≥ 1) and k";
    let m = problems.required(
        "body.dissipation.m",
        d.m,
        |m| m >= MIN_RATE_EXPONENT,
        "is outside [1, ∞): the couple P/|ω| ∝ |ω|^(m−1) must stay bounded as the coin stops",
        NEEDS,
    );
    let k = problems.required("body.dissipation.k", d.k, |_| true, NOT_FINITE, NEEDS);
    (m, k)
}

/// Checks of `[initial]` that need no body (used when the body is invalid).
fn check_initial_alone(
    initial: &InitialFile,
    flat_margin: Option<f64>,
    problems: &mut ProblemCollector,
) {
    if let Some(theta) = initial.theta {
        check_theta(theta, flat_margin.or(Some(defaults::FLAT_MARGIN)), problems);
    }
    offsets(initial, problems);
    if let Some(omega) = &initial.omega {
        problems.vector3("initial.omega", omega);
    }
}

fn check_initial(
    initial: &InitialFile,
    params: &CoinParams,
    flat_margin: Option<f64>,
    problems: &mut ProblemCollector,
) -> Option<Initial> {
    let before = problems.list.len();
    let [phi, psi, x, z] = offsets(initial, problems);
    let coin = Coin::new(*params);
    let base = initial_base(initial, &coin, flat_margin, problems);
    let perturbation = initial
        .perturbation
        .as_ref()
        .map_or(Some([0.0; 4]), |p| check_perturbation(p, problems));
    let (mut state, spec) = base?;
    let perturbation = perturbation?;
    state.phi += phi;
    state.psi += psi;
    state.x += x;
    state.z += z;
    let kicked = perturbed(&state, &perturbation);
    if perturbation[0] != 0.0 && !leans_less_than_flat(kicked.theta, flat_margin) {
        problems.push(
            "initial.perturbation.theta",
            number(perturbation[0]),
            format!(
                "takes theta to {}, which {}",
                number(kicked.theta),
                lean_range(flat_margin)
            ),
        );
    }
    (problems.list.len() == before).then_some((state, spec, perturbation))
}

/// The offsets φ, ψ, x, z of `[initial]`: each finite, or 0 (not given, or reported).
fn offsets(initial: &InitialFile, problems: &mut ProblemCollector) -> [f64; 4] {
    let given = [
        ("initial.phi", initial.phi),
        ("initial.psi", initial.psi),
        ("initial.x", initial.x),
        ("initial.z", initial.z),
    ];
    given.map(|(key, value)| value.filter(|&v| problems.finite(key, v)).unwrap_or(0.0))
}

/// |θ| < π/2 − margin, or the margin is not known (it is reported itself).
fn leans_less_than_flat(theta: f64, flat_margin: Option<f64>) -> bool {
    flat_margin.is_none_or(|m| theta.abs() < FRAC_PI_2 - m)
}

fn check_theta(theta: f64, flat_margin: Option<f64>, problems: &mut ProblemCollector) {
    if problems.finite("initial.theta", theta) && !leans_less_than_flat(theta, flat_margin) {
        problems.push("initial.theta", number(theta), lean_range(flat_margin));
    }
}

/// The state before offsets and perturbation: an explicit (θ, ω) or a solved steady motion.
fn initial_base(
    initial: &InitialFile,
    coin: &Coin,
    flat_margin: Option<f64>,
    problems: &mut ProblemCollector,
) -> Option<(State, InitialSpec)> {
    const EITHER: &str = "is given together with `initial.steady`: give either an explicit state (theta, omega) or a steady motion";
    match (&initial.steady, initial.theta, &initial.omega) {
        (Some(steady), theta, omega) => {
            if let Some(t) = theta {
                problems.push("initial.theta", number(t), EITHER);
            }
            if let Some(o) = omega {
                problems.push("initial.omega", numbers(o), EITHER);
            }
            check_steady(steady, coin, flat_margin, problems)
                .map(|s| (s.state, InitialSpec::Steady(s)))
        }
        (None, Some(theta), Some(omega)) => {
            check_theta(theta, flat_margin, problems);
            let [omega_x, omega_y, omega_z] = problems.vector3("initial.omega", omega)?;
            let state = State {
                theta,
                omega_x,
                omega_y,
                omega_z,
                ..State::default()
            };
            Some((state, InitialSpec::Explicit))
        }
        (None, None, omega) => {
            if let Some(o) = omega {
                problems.vector3("initial.omega", o);
            }
            problems.missing("initial.theta", "is missing: give theta and omega, or a steady motion (initial.steady = { kind = ... })")
        }
        (None, Some(theta), None) => {
            problems.finite("initial.theta", theta);
            problems.missing(
                "initial.omega",
                "is missing: theta needs omega = [ω_X, ω_Y, ω_Z] (the lean of a steady motion is `initial.steady.theta`)",
            )
        }
    }
}

fn perturbed(base: &State, perturbation: &[f64; 4]) -> State {
    State {
        theta: base.theta + perturbation[0],
        omega_x: base.omega_x + perturbation[1],
        omega_y: base.omega_y + perturbation[2],
        omega_z: base.omega_z + perturbation[3],
        ..*base
    }
}

fn check_perturbation(p: &PerturbationFile, problems: &mut ProblemCollector) -> Option<[f64; 4]> {
    let theta = p.theta.unwrap_or(0.0);
    let theta_ok = problems.finite("initial.perturbation.theta", theta);
    let omega = match &p.omega {
        Some(o) => problems.vector3("initial.perturbation.omega", o),
        None => Some([0.0; 3]),
    };
    let [wx, wy, wz] = omega?;
    theta_ok.then_some([theta, wx, wy, wz])
}

/// The keys of `initial.steady` each steady family takes (besides `kind`).
fn steady_keys(family: SteadyFamily) -> &'static [&'static str] {
    match family {
        SteadyFamily::Straight => &["omega_z"],
        SteadyFamily::CentreFixed => &["theta", "branch"],
        SteadyFamily::Circle => &["theta", "omega_z", "branch"],
        SteadyFamily::SpinUpright => &["omega_y"],
    }
}

fn check_steady(
    steady: &SteadyFile,
    coin: &Coin,
    flat_margin: Option<f64>,
    problems: &mut ProblemCollector,
) -> Option<Steady> {
    let before = problems.list.len();
    let family = problems.parse::<SteadyFamily>("initial.steady.kind", &steady.kind, |_| {
        "is not a steady motion: use \"straight\", \"centre-fixed\", \"circle\" or \"spin-upright\"".into()
    })?;
    check_steady_keys(steady, family, problems);
    let kind = steady_kind(steady, family, flat_margin, problems);
    if problems.list.len() != before {
        return None;
    }
    solve_steady(coin, kind, family, problems)
}

fn check_steady_keys(steady: &SteadyFile, family: SteadyFamily, problems: &mut ProblemCollector) {
    let allowed = steady_keys(family);
    let given = [
        ("theta", steady.theta.map(number)),
        ("omega_y", steady.omega_y.map(number)),
        ("omega_z", steady.omega_z.map(number)),
        ("branch", steady.branch.as_deref().map(quoted)),
    ];
    for (name, value) in given {
        if let Some(v) = value.filter(|_| !allowed.contains(&name)) {
            problems.push(
                format!("initial.steady.{name}"),
                v,
                format!(
                    "does not apply to a \"{family}\" steady motion, which takes: kind, {}",
                    allowed.join(", ")
                ),
            );
        }
    }
}

/// The steady motion's parameters from the keys `family` takes; missing or bad ones are reported (their
/// value is then a placeholder that is never used).
fn steady_kind(
    steady: &SteadyFile,
    family: SteadyFamily,
    flat_margin: Option<f64>,
    problems: &mut ProblemCollector,
) -> SteadyKind {
    let needs = steady_keys(family).join(", ");
    let needs = format!("is missing: a \"{family}\" steady motion needs {needs}");
    let mut required = |name: &str, value: Option<f64>| {
        let key = format!("initial.steady.{name}");
        problems.required(&key, value, |_| true, NOT_FINITE, needs.as_str())
    };
    match family {
        SteadyFamily::Straight => SteadyKind::Straight {
            omega_z: required("omega_z", steady.omega_z),
        },
        SteadyFamily::SpinUpright => SteadyKind::SpinUpright {
            omega_y: required("omega_y", steady.omega_y),
        },
        SteadyFamily::CentreFixed | SteadyFamily::Circle => {
            let theta = required("theta", steady.theta);
            let omega_z = if family == SteadyFamily::Circle {
                required("omega_z", steady.omega_z)
            } else {
                0.0
            };
            let branch = steady.branch.as_deref().and_then(|name| {
                problems.parse("initial.steady.branch", name, |_| {
                    "is not a branch: use \"+\" or \"-\"".into()
                })
            });
            let branch = branch.unwrap_or(defaults::BRANCH);
            if theta.is_finite() && (theta == 0.0 || !leans_less_than_flat(theta, flat_margin)) {
                let margin = flat_margin.unwrap_or(defaults::FLAT_MARGIN);
                let why = if theta == 0.0 {
                    "this steady motion needs a leaning coin; use kind = \"straight\" for θ = 0"
                } else {
                    "a rolling coin must lean less than flat"
                };
                problems.push(
                    "initial.steady.theta",
                    number(theta),
                    format!("is outside 0 < |θ| < π/2 − {margin} (run.flat_margin): {why}"),
                );
            }
            if family == SteadyFamily::Circle {
                SteadyKind::Circle {
                    theta,
                    omega_z,
                    branch,
                }
            } else {
                SteadyKind::CentreFixed { theta, branch }
            }
        }
    }
}

fn solve_steady(
    coin: &Coin,
    kind: SteadyKind,
    family: SteadyFamily,
    problems: &mut ProblemCollector,
) -> Option<Steady> {
    let reason = match Steady::new(coin, kind) {
        Ok(s) if s.state.is_finite() => return Some(s),
        Ok(s) => format!(
            "has no finite solution here (ω_Y = {})",
            number(s.state.omega_y)
        ),
        Err(e) => format!("cannot be built: {e}"),
    };
    problems.reject(
        "initial.steady",
        format!("{{ kind = \"{family}\" }}"),
        reason,
    )
}

fn check_run(
    run: &RunFile,
    flat_margin: f64,
    margin_ok: bool,
    problems: &mut ProblemCollector,
) -> Option<RunConfig> {
    let before = problems.list.len();
    let duration = problems.required(
        "run.duration",
        run.duration,
        |d| d > 0.0,
        POSITIVE,
        "is missing: give the run's length in time units, e.g. duration = 20.0",
    );
    if duration.is_finite() {
        limits::check_duration(duration, problems);
    }
    let rate = run.rate.unwrap_or(defaults::RATE);
    // Both finite and > 0 (a bad duration is NaN here).
    let rate_ok = problems.positive("run.rate", rate) && duration.is_finite();
    if rate_ok && duration * rate > MAX_SAMPLES {
        problems.push(
            "run.rate",
            number(rate),
            format!(
                "gives {:e} samples over duration {}: more than {MAX_SAMPLES:e}",
                duration * rate,
                number(duration)
            ),
        );
    }
    let integrator = run.integrator.as_deref().unwrap_or(defaults::INTEGRATOR);
    let method = problems.parse::<Method>("run.integrator", integrator, |e| {
        format!(
            "is not a known integrator: use one of {}",
            e.valid.join(", ")
        )
    });
    if rate_ok {
        limits::check_rate(rate, duration, problems);
    }
    let rtol = run.rtol.unwrap_or(defaults::RTOL);
    if problems.positive("run.rtol", rtol) && method.is_some_and(Method::is_adaptive) {
        limits::check_rtol(rtol, problems);
    }
    let atol = run.atol.unwrap_or(defaults::ATOL);
    problems.positive("run.atol", atol);
    let step = run.step.unwrap_or(defaults::STEP);
    problems.positive("run.step", step);
    let max_steps = run.max_steps.unwrap_or(defaults::MAX_STEPS);
    if max_steps == 0 {
        problems.push(
            "run.max_steps",
            "0".to_string(),
            "is not positive: give the most integrator steps the run may take, e.g. max_steps = 100_000_000",
        );
    }
    if !margin_ok {
        problems.push(
            "run.flat_margin",
            number(flat_margin),
            "is outside (0, π/2): give a small positive angle, e.g. 1e-4",
        );
    }
    if problems.list.len() != before {
        return None;
    }
    let method = method?;
    Some(RunConfig {
        duration,
        rate,
        method: used_settings(method, rtol, atol, step, rate),
        flat_margin,
        max_steps,
    })
}

/// The settings `method` uses, the others 0 (format.md: Metadata records).
fn used_settings(method: Method, rtol: f64, atol: f64, step: f64, rate: f64) -> MethodConfig {
    let adaptive = method.is_adaptive();
    let used = |uses: bool, value: f64| if uses { value } else { 0.0 };
    MethodConfig {
        method,
        rtol: used(adaptive, rtol),
        atol: used(adaptive, atol),
        step: used(!adaptive, fitted_step(step, 1.0 / rate)),
    }
}

/// The largest step ≤ `step` that divides the sample interval into a whole number of steps, so that fixed
/// steps land on the sample grid.
fn fitted_step(step: f64, interval: f64) -> f64 {
    interval / steps_over(interval, step).max(1.0)
}

/// The number of steps `step` takes over `span`: a relative slack of 1e-12 keeps 0.01/0.001 =
/// 10.000000000000002 at 10.
pub(super) fn steps_over(span: f64, step: f64) -> f64 {
    (span / step * (1.0 - 1e-12)).ceil()
}

/// The channels of a scene that lists none: all ten, and `work` with dissipation (format.md: Channels).
pub(super) fn default_channels(dissipative: bool) -> Vec<Channel> {
    let mut channels = Channel::DEFAULT.to_vec();
    if dissipative {
        channels.push(Channel::Work);
    }
    channels
}

fn check_channels(
    record: Option<&RecordFile>,
    dissipative: bool,
    problems: &mut ProblemCollector,
) -> Option<Vec<Channel>> {
    let rerun = record.and_then(|r| r.rerun) == Some(true);
    let mut channels = listed_channels(record, dissipative, problems)?;
    if rerun && !channels.contains(&Channel::Rerun) {
        channels.push(Channel::Rerun);
    }
    if channels.contains(&Channel::Rerun) && !channels.contains(&Channel::Scene) {
        return problems.reject(
            "record.channels",
            quoted(Channel::Rerun.name()),
            "draws the coin in the frames of the `scene` channel, which is not recorded: add \"scene\" or leave \"rerun\" out",
        );
    }
    Some(channels)
}

fn listed_channels(
    record: Option<&RecordFile>,
    dissipative: bool,
    problems: &mut ProblemCollector,
) -> Option<Vec<Channel>> {
    let Some(names) = record.and_then(|r| r.channels.as_ref()) else {
        return Some(default_channels(dissipative));
    };
    let before = problems.list.len();
    let mut channels = Vec::new();
    // Each name's problem once: `--channels omega,omega,…` 5000 times printed 4999 lines, `,` two.
    let mut reported: Vec<&str> = Vec::new();
    for name in names {
        // `--channels "omega, angles"`: spaces around a name are not part of it.
        let name = name.trim();
        if reported.contains(&name) {
            continue;
        }
        let reason = match name.parse::<Channel>() {
            Ok(c) if channels.contains(&c) => {
                match names.iter().filter(|n| n.trim() == name).count() {
                    2 => "is listed twice: list each channel once".into(),
                    n => format!("is listed {n} times: list each channel once"),
                }
            }
            Ok(Channel::Work) if !dissipative => "records the work of a dissipative couple, and the scene has none: add body.dissipation = { model = \"moffatt\", coefficient = ... } (format.md: Dissipation) or leave \"work\" out".into(),
            Ok(c) => {
                channels.push(c);
                continue;
            }
            Err(_) => format!("is not a channel: use {}", Channel::names()),
        };
        reported.push(name);
        problems.push("record.channels", quoted(name), reason);
    }
    if names.is_empty() {
        problems.push(
            "record.channels",
            "[]",
            format!("is empty: list at least one channel ({})", Channel::names()),
        );
    }
    channels.sort();
    (problems.list.len() == before).then_some(channels)
}

pub(super) fn file_from_scene(scene: &Scene) -> SceneFile {
    let p = &scene.params;
    let (shape, inertia_x, inertia_z) = match scene.inertia {
        Inertia::ThinDisk => (Some("thin-disk".to_string()), None, None),
        Inertia::Hoop => (Some("hoop".to_string()), None, None),
        Inertia::Explicit {
            inertia_x,
            inertia_z,
        } => (None, Some(inertia_x), Some(inertia_z)),
    };
    let s = &scene.base;
    let [dt, dwx, dwy, dwz] = scene.perturbation;
    let perturbed = scene.perturbation.iter().any(|&v| v != 0.0);
    let (theta, omega, steady) = match &scene.spec {
        InitialSpec::Explicit => (
            Some(s.theta),
            Some(vec![s.omega_x, s.omega_y, s.omega_z]),
            None,
        ),
        InitialSpec::Steady(st) => (None, None, Some(steady_file(&st.kind))),
    };
    // Steady motions start at φ = ψ = x = z = 0, so these are the file's offsets in both forms.
    let nonzero = |v: f64| Some(v).filter(|v| *v != 0.0);
    SceneFile {
        description: Some(scene.description.clone()),
        body: BodyFile {
            mass: p.mass(),
            radius: p.radius(),
            gravity: p.gravity(),
            shape,
            inertia_x,
            inertia_z,
            friction: scene.friction,
            thickness: Some(scene.thickness),
            dissipation: scene.dissipation.as_ref().map(dissipation_file),
        },
        initial: InitialFile {
            theta,
            omega,
            phi: nonzero(s.phi),
            psi: nonzero(s.psi),
            x: nonzero(s.x),
            z: nonzero(s.z),
            steady,
            perturbation: perturbed.then(|| PerturbationFile {
                theta: Some(dt),
                omega: Some(vec![dwx, dwy, dwz]),
            }),
        },
        run: Some(run_file(&scene.run)),
        record: Some(record_file(&scene.channels)),
    }
}

/// `[record]` listing `channels` by name.
pub(super) fn record_file(channels: &[Channel]) -> RecordFile {
    let names = channels.iter().map(|c| c.name().to_string()).collect();
    RecordFile {
        channels: Some(names),
        rerun: None,
    }
}

/// `[run]` of a resolved scene: every key the integrator uses, none it ignores.
fn run_file(run: &RunConfig) -> RunFile {
    let m = &run.method;
    let adaptive = m.method.is_adaptive();
    RunFile {
        duration: Some(run.duration),
        rate: Some(run.rate),
        integrator: Some(m.method.name().to_string()),
        rtol: adaptive.then_some(m.rtol),
        atol: adaptive.then_some(m.atol),
        step: (!adaptive).then_some(m.step),
        // Only when not the default, so that the stored scene of every earlier file is unchanged.
        max_steps: (run.max_steps != defaults::MAX_STEPS).then_some(run.max_steps),
        flat_margin: Some(run.flat_margin),
    }
}

/// The scene keys of a dissipation law: m and k only for `power-law` (a preset fixes them).
fn dissipation_file(d: &Dissipation) -> DissipationFile {
    let explicit = d.model().exponents().is_none();
    DissipationFile {
        model: d.model().name().to_string(),
        coefficient: Some(d.coefficient()),
        m: explicit.then_some(d.m()),
        k: explicit.then_some(d.k()),
    }
}

fn steady_file(kind: &SteadyKind) -> SteadyFile {
    let (theta, omega_y, omega_z, branch) = match *kind {
        SteadyKind::Straight { omega_z } => (None, None, Some(omega_z), None),
        SteadyKind::SpinUpright { omega_y } => (None, Some(omega_y), None, None),
        SteadyKind::CentreFixed { theta, branch } => (Some(theta), None, None, Some(branch)),
        SteadyKind::Circle {
            theta,
            omega_z,
            branch,
        } => (Some(theta), None, Some(omega_z), Some(branch)),
    };
    SteadyFile {
        kind: kind.family().name().to_string(),
        theta,
        omega_y,
        omega_z,
        branch: branch.map(|b| b.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::fitted_step;

    #[test]
    fn the_step_is_rounded_down_to_divide_the_sample_interval() {
        for (step, interval, expected) in [
            (1e-3, 0.01, 1e-3),
            (3e-3, 0.01, 0.0025),
            (1.0, 0.01, 0.01),
            (0.004, 0.01, 0.01 / 3.0),
        ] {
            let got = fitted_step(step, interval);
            println!("step {step}, interval {interval}: got {got}, expected {expected}");
            assert!((got - expected).abs() <= 1e-18, "{got} vs {expected}");
        }
    }
}
