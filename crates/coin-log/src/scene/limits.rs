//! The limits a scene must respect beyond "finite and positive" (format.md: Scene files, Limits): what
//! double precision, the 1 ns log-time base and the integrators can deliver. A scene outside them is refused
//! before anything is written, naming the key, the value, the limit and why.

use super::file::SceneFile;
use super::problems::{number, ProblemCollector};
use super::Scene;
use crate::format::tolerances::UNIT_ROUNDOFF;
use crate::model::{energy, magnitude, CoinParams, Dissipation, DissipationModel, Inertia, State};

/// Smallest scale (mass, length, inertia, energy, ...) a scene may have: the model multiplies and divides
/// pairs of scales (I_Z·Ma² in C1, C2; |R|² ~ (Mg)²) times factors up to 1e8 (tan θ, ωτ), which stay
/// normal doubles (2.2e-308 … 1.8e308) for scales within 1e±150.
pub const SCALE_MIN: f64 = 1e-150;
/// Largest scale; see [`SCALE_MIN`].
pub const SCALE_MAX: f64 = 1e150;

/// Smallest rtol: ten units of rounding (10·2⁻⁵²), the limit Hairer's DOP853 enforces. Below it the error
/// estimate is rounding noise: `--rtol 1e-30 --atol 1e-30` gave no sample in 60 s (measured).
pub const RTOL_MIN: f64 = 10.0 * f64::EPSILON;
/// Largest rtol, the loosest common default (MATLAB's ode45). On `wobble` (dop853, 30 time units) rtol
/// 1e-3 drifts 2.0e-4 in energy; rtol 1 reports a lift-off at t = 8.71 that is an integration artefact.
pub const RTOL_MAX: f64 = 1e-3;
/// Largest atol, as a fraction of the smallest natural scale of the state: 1 rad for the angles, a for the
/// centre, 1/τ for ω (the same 1e-3 as [`RTOL_MAX`]).
pub const ATOL_MAX_FRACTION: f64 = 1e-3;
/// Largest h·W for fixed-step methods, W = max(|ω|, |φ̇|, |ψ̇|, 1/τ) at t = 0: (h W)⁴ = [`RTOL_MAX`], the
/// accuracy `verify` derives for an order-4 method (format.md: Tolerances). On `wobble` (rk4, W = 1.54)
/// h W = 0.19 drifts 2.5e-5 in energy, h W = 0.96 drifts 1.1e-2.
pub const STEP_MAX_PRODUCT: f64 = 0.177_827_941_003_892_3; // 1e-3^(1/4)
/// Largest duration × W, radians of the fastest motion: ≥ 5.6e10 steps (1/[`STEP_MAX_PRODUCT`] a radian),
/// hours of work; beyond it a run (ω = 1e100, say) would never reach its next sample, nor see Ctrl-C.
pub const MAX_RADIANS: f64 = 1e10;
/// Shortest duration: the log-time resolution, 1 ns (log_time = round(t·10⁹)); a shorter run's first and
/// last samples would share a log time, which `integrity` refuses.
pub const MIN_DURATION: f64 = 1e-9;

/// The highest rate whose samples get strictly increasing log times (round(t·10⁹) ns) over `duration`.
/// t_k = k·(1/rate) carries an error ≤ 3u·10⁹·t_k ns (u = 2⁻⁵³), so neighbours round to different
/// nanoseconds when 10⁹/rate − 6u·10⁹·duration ≥ 1: just under 10⁹ below durations of ~10⁴. (The driver
/// replaces a grid point within 2 ns of the end by the end.)
#[must_use]
pub fn max_rate(duration: f64) -> f64 {
    1.0 / (1e-9 + 6.0 * UNIT_ROUNDOFF * duration.max(0.0))
}

/// A number as a power of ten from its decimal logarithm, for scales that may not be representable
/// (`1e-400`, `2.5e310`).
fn power_of_ten(log10: f64) -> String {
    let exponent = log10.floor();
    let mantissa = 10f64.powf(log10 - exponent);
    if (mantissa - 1.0).abs() < 1e-9 || (mantissa - 10.0).abs() < 1e-8 {
        let exponent = if mantissa > 5.0 {
            exponent + 1.0
        } else {
            exponent
        };
        format!("1e{exponent}")
    } else {
        format!("{mantissa:.2}e{exponent}")
    }
}

/// `x` to four significant digits, rounded towards zero (`Down`, for a ceiling to stay under) or away from
/// it (`Up`, for a floor to stay over), or to nearest.
#[derive(Clone, Copy, PartialEq)]
enum Round {
    Down,
    Up,
    Nearest,
}

fn short(x: f64, round: Round) -> String {
    if !x.is_finite() || x == 0.0 {
        return number(x);
    }
    // The correctly rounded decimal form, moved one unit when it rounded the wrong way for `round`, so that
    // a printed ceiling holds for x itself (the tests show the two cases that printed wrong).
    let magnitude = x.abs();
    let text = format!("{magnitude:.3e}");
    let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
    let mut digits: i64 = mantissa.replace('.', "").parse().unwrap_or(1000);
    let mut exponent: i32 = exponent.parse().unwrap_or(0);
    let value = |digits: i64, exponent: i32| -> f64 {
        format!("{digits}e{}", exponent - 3)
            .parse()
            .unwrap_or(f64::NAN)
    };
    match round {
        Round::Down if value(digits, exponent) > magnitude => {
            digits -= 1;
            if digits < 1000 {
                (digits, exponent) = (9999, exponent - 1);
            }
        }
        Round::Up if value(digits, exponent) < magnitude => {
            digits += 1;
            if digits > 9999 {
                (digits, exponent) = (1000, exponent + 1);
            }
        }
        _ => {}
    }
    let sign = if x < 0.0 { "-" } else { "" };
    let shown = value(digits, exponent);
    if (1e-4..1e16).contains(&shown) {
        #[allow(clippy::cast_sign_loss)]
        let decimals = (3 - exponent).max(0) as usize;
        let text = format!("{shown:.decimals$}");
        let text = if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        };
        format!("{sign}{text}")
    } else {
        #[allow(clippy::cast_precision_loss)] // four digits
        let mantissa = format!("{:.3}", digits as f64 / 1000.0);
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        format!("{sign}{mantissa}e{exponent}")
    }
}

const SCALE_WHY: &str = "the model multiplies and divides pairs of such scales (e.g. I_Z·Ma² in C1, C2), \
     so each must lie within 1e-150 … 1e150 for the products to stay normal double-precision numbers \
     (2.2e-308 … 1.8e308): express the scene in units where M, a and g are nearer 1";

fn in_scale_range(log10: f64) -> bool {
    (SCALE_MIN.log10()..=SCALE_MAX.log10()).contains(&log10)
}

/// Checks M, a, g (and explicit inertias) and the scales the model forms from them; `false` when one is
/// outside [`SCALE_MIN`] … [`SCALE_MAX`] (reported on the key that contributes most).
pub(super) fn check_scales(
    body: &super::file::BodyFile,
    inertia: Inertia,
    problems: &mut ProblemCollector,
) -> bool {
    let given = [
        ("body.mass", body.mass),
        ("body.radius", body.radius),
        ("body.gravity", body.gravity),
    ];
    let mut inputs = given.to_vec();
    if let Inertia::Explicit {
        inertia_x,
        inertia_z,
    } = inertia
    {
        inputs.push(("body.inertia_x", inertia_x));
        inputs.push(("body.inertia_z", inertia_z));
    }
    let mut ok = true;
    for (key, value) in &inputs {
        if !in_scale_range(value.log10()) {
            problems.push(
                *key,
                number(*value),
                format!("is outside {SCALE_MIN:e} … {SCALE_MAX:e}: {SCALE_WHY}"),
            );
            ok = false;
        }
    }
    ok && check_derived_scales(given, problems)
}

/// The scales formed from M, a, g: (name, exponents of M, a, g).
const DERIVED_SCALES: [(&str, [f64; 3]); 5] = [
    ("the inertia scale M·a²", [1.0, 2.0, 0.0]),
    ("the energy scale M·g·a", [1.0, 1.0, 1.0]),
    ("the force scale M·g", [1.0, 0.0, 1.0]),
    ("the squared time unit τ² = a/g", [0.0, 1.0, -1.0]),
    ("the squared speed scale a·g", [0.0, 1.0, 1.0]),
];

fn check_derived_scales(given: [(&str, f64); 3], problems: &mut ProblemCollector) -> bool {
    let (keys, values) = (given.map(|(k, _)| k), given.map(|(_, v)| v));
    let logs = values.map(f64::log10);
    // Per key, the scales it puts out of range (a key is blamed when its share of the exponent is largest).
    let mut blamed: Vec<(usize, Vec<String>)> = Vec::new();
    for (name, exponents) in DERIVED_SCALES {
        let shares: Vec<f64> = exponents.iter().zip(&logs).map(|(e, l)| e * l).collect();
        let log10: f64 = shares.iter().sum();
        if in_scale_range(log10) {
            continue;
        }
        let culprit = (0..3)
            .max_by(|&i, &j| shares[i].abs().total_cmp(&shares[j].abs()))
            .unwrap_or(0);
        let text = format!("{name} = {}", power_of_ten(log10));
        match blamed.iter_mut().find(|(k, _)| *k == culprit) {
            Some((_, list)) => list.push(text),
            None => blamed.push((culprit, vec![text])),
        }
    }
    for (key, scales) in &blamed {
        let others: Vec<String> = (0..3)
            .filter(|i| i != key)
            .map(|i| format!("`{}` = {}", keys[i], number(values[i])))
            .collect();
        problems.push(
            keys[*key],
            number(values[*key]),
            format!(
                "with {} gives {}, outside {SCALE_MIN:e} … {SCALE_MAX:e}: {SCALE_WHY}",
                others.join(" and "),
                scales.join(" and ")
            ),
        );
    }
    blamed.is_empty()
}

/// The range of a positive rtol, for an adaptive method (atol's ceiling needs the body: [`check_atol`]).
pub(super) fn check_rtol(rtol: f64, problems: &mut ProblemCollector) {
    let reason = if rtol < RTOL_MIN {
        format!(
            "is below {}, ten units of double-precision rounding (10·2⁻⁵²): the error estimate would be rounding noise and the step would shrink without end; use rtol ≥ {}",
            short(RTOL_MIN, Round::Nearest),
            number(RTOL_MIN)
        )
    } else if rtol > RTOL_MAX {
        format!("is above {RTOL_MAX:e}: an adaptive method's error estimate does not hold at such tolerances, and its events (lift-off, slip) would be artefacts; use rtol ≤ {RTOL_MAX:e}")
    } else {
        return;
    };
    problems.push("run.rtol", number(rtol), reason);
}

pub(super) fn check_duration(duration: f64, problems: &mut ProblemCollector) {
    let reason = if duration < MIN_DURATION {
        format!("is below {MIN_DURATION:e}, the log-time resolution (log times are whole nanoseconds, round(t·1e9), so the first and last samples would share one): use duration ≥ {MIN_DURATION:e}")
    } else if crate::format::log_time(duration).is_err() {
        "is too long: log times must fit in 64-bit nanoseconds (duration < 1.8e10)".to_string()
    } else {
        return;
    };
    problems.push("run.duration", number(duration), reason);
}

/// A fixed-step run, known before it starts (an adaptive one spends `run.max_steps` as it goes): its step
/// must advance time at t = duration, the largest t of the run, where floating point is coarsest.
fn check_fixed_step(scene: &Scene, given: Option<f64>, w: f64, problems: &mut ProblemCollector) {
    let run = &scene.run;
    let (h, duration) = (run.method.step, run.duration);
    let shown = number(given.unwrap_or(h));
    #[allow(clippy::float_cmp)] // exactly the question: does t + h round back to t?
    let stuck = duration + h == duration;
    // The step's fitting to the sample grid counts steps so too: 0.001/1e-10 is 1e7 steps, not 1e7 + 1.
    let steps = super::validate::steps_over(duration, h);
    #[allow(clippy::cast_precision_loss)]
    let max = run.max_steps as f64;
    let too_many = if stuck {
        Some(format!(
            "cannot advance time: t + step rounds back to t at t = duration = {} (the spacing of doubles there is {}), so the run would never end; use step ≥ {}",
            number(duration),
            short(duration * f64::EPSILON, Round::Nearest),
            short((duration / max).max(duration * f64::EPSILON), Round::Up)
        ))
    } else {
        (steps > max).then(|| format!(
            "takes {} steps over duration {}, more than run.max_steps = {} (about 0.15 µs of work a step): use step ≥ {}, a shorter duration, or raise run.max_steps (--max-steps)",
            power_of_ten(steps.log10()),
            number(duration),
            run.max_steps,
            short(duration / max, Round::Up)
        ))
    };
    if let Some(reason) = too_many {
        problems.push("run.step", &shown, reason);
    }
    if h * w > STEP_MAX_PRODUCT {
        let used = match given {
            Some(g) if g != h => format!("(used: {}, rounded to divide 1/rate) ", number(h)),
            _ => String::new(),
        };
        let ceiling = short(STEP_MAX_PRODUCT / w, Round::Down);
        problems.push(
            "run.step",
            &shown,
            format!(
                "{used}is above 0.178/W = {ceiling}, where W = {} = {} at t = 0: {}'s error (hW)⁴ would exceed 1e-3; use step ≤ {ceiling}",
                rates_named(scene),
                short(w, Round::Nearest),
                run.method.method,
            ),
        );
    }
}

/// A positive sample rate against the 1 ns log-time base ([`max_rate`]), over a positive duration.
pub(super) fn check_rate(rate: f64, duration: f64, problems: &mut ProblemCollector) {
    let max = max_rate(duration);
    if rate > max {
        // Whole rates are shown whole; below 1 (durations past ~1e15) flooring printed "use rate ≤ 0".
        let max = if max >= 1.0 {
            number(max.floor())
        } else {
            short(max, Round::Down)
        };
        problems.push(
            "run.rate",
            number(rate),
            format!(
                "is above {max}, the highest rate whose samples stay ≥ 1 ns apart over duration {} (log times are whole nanoseconds, round(t·1e9), and must increase from sample to sample): use rate ≤ {max}",
                number(duration)
            ),
        );
    }
}

/// W = max(|ω|, |φ̇|, |ψ̇|, 1/τ) of a state: the fastest rate of the equations.
fn fastest_rate(params: &CoinParams, s: &State) -> f64 {
    let omega = magnitude(s.omega_x, s.omega_y, s.omega_z);
    let (sin_t, cos_t) = s.theta.sin_cos();
    let phi_dot = s.omega_y / cos_t;
    let psi_dot = s.omega_z + s.omega_y * sin_t / cos_t;
    omega
        .max(phi_dot.abs())
        .max(psi_dot.abs())
        .max(1.0 / params.time_unit())
}

/// The rates W is the largest of, as the refusals name them: λ, the couple's, only with dissipation.
fn rates_named(scene: &Scene) -> &'static str {
    if scene.dissipation.is_some() {
        "max(|ω|, |φ̇|, |ψ̇|, 1/τ, λ)"
    } else {
        "max(|ω|, |φ̇|, |ψ̇|, 1/τ)"
    }
}

/// λ = P/(|ω|²·min(I_X, I_Z + Ma²)) at t = 0: the rate at which the dissipative couple −P ω/|ω|² changes
/// ω (eqs (31)–(33): |ω̇|/|ω| of the couple alone, the largest of its three inertias' rates), and so the
/// rate an explicit integrator's step must resolve (physics §11); 0 without dissipation. |ω|² as the
/// equations form it, so that a state whose |ω|² underflows to 0 (couple 0 there) has λ = 0.
fn couple_rate(scene: &Scene) -> f64 {
    let Some(d) = &scene.dissipation else {
        return 0.0;
    };
    let s = &scene.initial;
    let p = &scene.params;
    let w2 = s.omega_x * s.omega_x + s.omega_y * s.omega_y + s.omega_z * s.omega_z;
    if w2 > 0.0 {
        d.power(s.theta, s.omega_y) / w2 / p.inertia_x().min(p.inertia_z() + p.ma2())
    } else {
        0.0
    }
}

/// With dissipation, the couple at t = 0 must be finite and, for an adaptive method, within what its error
/// estimate can square: P = κ |φ̇|^m (sin α)^(−k) finite (k = 1e300 made (sin α)^(−k) infinite) and P,
/// λ|ω| ≤ 1e150·atol (κ = 1e300 gave P = 3e304). Each ended the run "non-finite at t = 0" with one sample
/// written. `true` when a problem was reported.
fn check_couple(scene: &Scene, d: &Dissipation, problems: &mut ProblemCollector) -> bool {
    let s = &scene.initial;
    let power = d.power(s.theta, s.omega_y);
    let kappa = d.coefficient();
    if !power.is_finite() {
        refuse_power(scene, d, problems);
        return true;
    }
    // An adaptive method squares each component of its error estimate over its weight (≥ atol): Ẇ = P
    // and the couple's ω̇ (λ|ω|) beyond 1e150·atol overflow it whatever the step, and every trial step is
    // rejected as non-finite (κ = 1e200 on `euler-disk`: P = 5e203). The same 1e150 as the scales'.
    let method = &scene.run.method;
    if method.method.is_adaptive() {
        let rate = power.max(couple_rate(scene) * magnitude(s.omega_x, s.omega_y, s.omega_z));
        let max = SCALE_MAX * method.atol;
        if rate > max {
            // The bound is linear in atol too: an atol tiny for the scene (`--atol 5e-324`) is the
            // problem as much as κ, and a larger one, where allowed (check_atol), does as well.
            let atol_needed = rate / SCALE_MAX;
            let or_atol = if atol_needed <= atol_max(&scene.params) {
                format!(", or atol ≥ {}", short(atol_needed, Round::Up))
            } else {
                String::new()
            };
            problems.push(
                "body.dissipation.coefficient",
                number(kappa),
                format!(
                    "gives the couple a rate of change max(P, λ|ω|) = {} at t = 0 (P = {}, λ = P/(|ω|²·min(I_X, I_Z + Ma²)) = {}), more than {SCALE_MAX:e}·atol = {}: {}'s error estimate squares it over atol and would overflow at every step, ending the run at t = 0; use coefficient ≤ {}{or_atol}",
                    short(rate, Round::Nearest),
                    short(power, Round::Nearest),
                    short(couple_rate(scene), Round::Nearest),
                    short(max, Round::Nearest),
                    method.method,
                    // Both terms are linear in κ.
                    short(kappa * (max / rate), Round::Down)
                ),
            );
            return true;
        }
    }
    false
}

/// Reports a non-finite P = κ |φ̇|^m (sin α)^(−k) at t = 0 on the factor that overflows, with the bound
/// ln P < ln(MAX) solved for that key.
fn refuse_power(scene: &Scene, d: &Dissipation, problems: &mut ProblemCollector) {
    let s = &scene.initial;
    let (kappa, m, k) = (d.coefficient(), d.m(), d.k());
    let sin_alpha = s.theta.cos();
    let phi_dot = (s.omega_y / sin_alpha).abs();
    let angle_factor = sin_alpha.powf(-k);
    let rate_factor = phi_dot.powf(m);
    let laws = format!(
        "gives a non-finite dissipated power P = κ |φ̇|^m (sin α)^(−k) at t = 0 (κ = {}, |φ̇| = {}, sin α = {}, m = {}, k = {})",
        number(kappa),
        short(phi_dot, Round::Nearest),
        short(sin_alpha, Round::Nearest),
        number(m),
        number(k)
    );
    let ln_max = f64::MAX.ln();
    let bound = |name: &str, max: f64| format!("use {name} < {}", short(max, Round::Down));
    let (key, value, factor, fix) = if !angle_factor.is_finite() {
        // ln P = ln(κ |φ̇|^m) + k ln(1/sin α) < ln(MAX); the factor alone must stay finite too.
        let ln_rest = (kappa.ln() + m * phi_dot.ln()).max(0.0);
        let k_max = (ln_max - ln_rest) / -sin_alpha.ln();
        (
            "body.dissipation.k",
            number(k),
            "(sin α)^(−k)",
            bound("k", k_max),
        )
    } else if !rate_factor.is_finite() && d.model() == DissipationModel::PowerLaw && phi_dot > 1.0 {
        // ln P = ln(κ (sin α)^(−k)) + m ln|φ̇| < ln(MAX), and m ≥ 1.
        let ln_rest = (kappa.ln() + angle_factor.ln()).max(0.0);
        let m_max = (ln_max - ln_rest) / phi_dot.ln();
        ("body.dissipation.m", number(m), "|φ̇|^m", bound("m", m_max))
    } else if !rate_factor.is_finite() {
        let fix = "lower the spin".to_string();
        (initial_key(scene), describe_state(s), "|φ̇|^m", fix)
    } else {
        let kappa_max = f64::MAX / rate_factor / angle_factor;
        let fix = bound("coefficient", kappa_max);
        ("body.dissipation.coefficient", number(kappa), "P", fix)
    };
    let reason = format!("{laws}: {factor} overflows double precision; {fix}");
    problems.push(key, value, reason);
}

fn initial_key(scene: &Scene) -> &'static str {
    match scene.spec {
        super::InitialSpec::Explicit => "initial.omega",
        super::InitialSpec::Steady(_) => "initial.steady",
    }
}

/// Checks that need the whole scene: the initial state, atol, the fixed step and the duration against
/// the fastest motion.
pub(super) fn check_resolved(scene: &Scene, file: &SceneFile, problems: &mut ProblemCollector) {
    let before = problems.list.len();
    check_start(scene, problems);
    if problems.list.len() != before {
        return; // the rates below are meaningless for a state outside the model
    }
    let run = &scene.run;
    let w = fastest_rate(&scene.params, &scene.initial);
    if run.method.method.is_adaptive() {
        check_atol(scene, problems);
    } else {
        // A fixed step must resolve the couple's rate too (rk4 at h·λ = 130 on `euler-disk` with κ = 100
        // "landed flat" at t = 9e-14 with no drift shown). An adaptive step follows it as the couple
        // decays: λ at t = 0 does not bound its work.
        let w = w.max(couple_rate(scene));
        check_fixed_step(scene, file.run.as_ref().and_then(|r| r.step), w, problems);
    }
    if run.duration * w > MAX_RADIANS {
        let fix = if MAX_RADIANS / w >= MIN_DURATION {
            format!(
                ": use duration ≤ {}, or slow the motion",
                short(MAX_RADIANS / w, Round::Down)
            )
        } else {
            // No duration would do: even the shortest run, 1 ns, is too many radians.
            let fix = if w * scene.params.time_unit() <= 1.0 {
                format!(
                    "the body's own time unit τ = √(a/g) = {} is too short: express the scene in units where τ is nearer 1",
                    short(scene.params.time_unit(), Round::Nearest)
                )
            } else {
                format!(
                    "slow the motion to W ≤ {}",
                    short(MAX_RADIANS / MIN_DURATION, Round::Down)
                )
            };
            format!(
                ", and so would the shortest duration, {MIN_DURATION:e} (the log-time resolution): {fix}"
            )
        };
        problems.push(
            "run.duration",
            number(run.duration),
            format!(
                "times W = max(|ω|, |φ̇|, |ψ̇|, 1/τ) = {} at t = 0 is {} radians of the fastest motion, more than {MAX_RADIANS:e} (≥ 5.6e10 integrator steps){fix}",
                short(w, Round::Nearest),
                short(run.duration * w, Round::Nearest),
            ),
        );
    }
}

/// The largest atol: [`ATOL_MAX_FRACTION`] of the smallest natural scale of the state.
fn atol_max(p: &CoinParams) -> f64 {
    ATOL_MAX_FRACTION * 1f64.min(p.radius()).min(1.0 / p.time_unit())
}

fn check_atol(scene: &Scene, problems: &mut ProblemCollector) {
    let p = &scene.params;
    let atol = scene.run.method.atol;
    let max = atol_max(p);
    if atol > max {
        let max = short(max, Round::Down);
        problems.push(
            "run.atol",
            number(atol),
            format!(
                "is above {max}, {ATOL_MAX_FRACTION:e} of the smallest scale of the state (1 rad for the angles, a = {} for the centre, 1/τ = {} for ω): the error estimate would not hold; use atol ≤ {max}",
                number(p.radius()),
                short(1.0 / p.time_unit(), Round::Nearest),
            ),
        );
    }
}

/// The initial state must be inside the model: finite energy and reaction, the table pushing (N > 0)
/// and, with μ, friction within the cone (|F| < μN). Otherwise the run would end at t = 0 with one sample.
fn check_start(scene: &Scene, problems: &mut ProblemCollector) {
    if let Some(d) = &scene.dissipation {
        if check_couple(scene, d, problems) {
            return;
        }
    }
    let coin = scene.coin();
    let s = &scene.initial;
    let e = energy(&coin, s).total;
    // The reaction of the equations the run integrates (with the couple's ω̇ when there is one).
    let r = scene.dynamics().reaction(s);
    let p = &scene.params;
    let weight = p.mass() * p.gravity();
    let reason = if !(e.is_finite() && r.normal.is_finite() && r.friction.is_finite()) {
        format!(
            "gives a non-finite energy or reaction at t = 0 (E = {}, N = {}): ω is too large for double precision; keep |ω| well below 1e150/τ = {}",
            short(e, Round::Nearest),
            short(r.normal, Round::Nearest),
            power_of_ten(150.0 - p.time_unit().log10())
        )
    } else if r.normal <= 0.0 {
        format!(
            "gives N = {} = {}·Mg ≤ 0 at t = 0: the coin would leave the table at once (lift-off), outside the rolling model; lower the spin or the lean so that N > 0",
            short(r.normal, Round::Nearest),
            short(r.normal / weight, Round::Nearest)
        )
    } else {
        let needed = r.friction / r.normal;
        if let Some(mu) = scene.friction.filter(|&mu| needed >= mu) {
            problems.push(
                "body.friction",
                number(mu),
                format!(
                    "is below |F|/N = {} needed at t = 0 (|F| = {}, N = {}): the coin would slip at once; give friction ≥ {} or leave it out",
                    short(needed, Round::Nearest),
                    short(r.friction, Round::Nearest),
                    short(r.normal, Round::Nearest),
                    short(needed * (1.0 + 1e-9), Round::Up)
                ),
            );
        }
        return;
    };
    problems.push(initial_key(scene), describe_state(s), reason);
}

fn describe_state(s: &State) -> String {
    format!(
        "(θ = {}, ω = [{}, {}, {}])",
        number(s.theta),
        number(s.omega_x),
        number(s.omega_y),
        number(s.omega_z)
    )
}

#[cfg(test)]
mod tests {
    use super::{power_of_ten, short, Round};

    #[test]
    fn limits_print_with_four_digits_rounded_the_safe_way() {
        assert_eq!(short(0.110_502_893, Round::Down), "0.1105");
        assert_eq!(short(0.204_171, Round::Up), "0.2042");
        assert_eq!(short(999_980_016.38, Round::Down), "999900000");
        assert_eq!(short(2.220_446e-15, Round::Up), "2.221e-15");
        assert_eq!(short(1.609_26, Round::Nearest), "1.609");
        assert_eq!(short(-0.5, Round::Nearest), "-0.5");
        // 1e-65 / 1e-68 is 999.99999999999989 in double precision: it printed "0.999e-65".
        assert_eq!(short(1e-65, Round::Down), "1e-65");
        assert_eq!(short(1e-65, Round::Up), "1e-65");
        // A ceiling printed rounded down holds for the number itself: 1e-3/τ for τ = 1e50 is
        // 9.999999999999999e-54, and "use atol ≤ 1e-53" was refused as above it.
        let ceiling = 1e-3 * (1.0 / (1e50_f64 / 1e-50).sqrt());
        assert_eq!(short(ceiling, Round::Down), "9.999e-54");
        assert!("9.999e-54".parse::<f64>().unwrap() <= ceiling);
        assert_eq!(short(-999_980_016.38, Round::Down), "-999900000");
        assert_eq!(
            short(0.177_827_941_003_892_3 / 1.609, Round::Down),
            "0.1105"
        );
    }

    #[test]
    fn powers_of_ten_print_beyond_double_precision() {
        assert_eq!(power_of_ten(-400.0), "1e-400");
        assert_eq!(power_of_ten(300.0), "1e300");
        assert_eq!(power_of_ten(2.0_f64.log10() + 310.0), "2.00e310");
    }
}
