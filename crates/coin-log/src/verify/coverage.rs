//! What `verify` will be able to judge in a recording of a scene, predicted before anything is recorded:
//! the required checks (`energy`, and `constraint` or `steady`; format.md: verify) that will not run, why,
//! and what to change, which `record` warns with, so that a user learns before a long run, not from a
//! "cannot verify" afterwards. It uses what the checks use: the channels they need, and `constraint`'s rule
//! for unresolved windows ([`constraint::resolves`]) at the default residual tolerance, applied to the
//! rates at t = 0, Ω₀ = max(|ω₀|, |φ̇₀|) plus |d ln Ω/dt| there. Those stand for the run's: a motion that
//! speeds up later loses only its later windows, while one unresolved at the start is in practice
//! unresolved throughout (the steady and high-spin scenes keep their rates).

use super::checks::constraint::{self, digits3};
use crate::format::tolerances::{RunAccuracy, Tolerances};
use crate::format::Channel;
use crate::model::magnitude;
use crate::scene::Scene;

/// One sentence per required check that will not be able to run on a recording of `scene`, saying why
/// and what to change; empty when `verify` will be able to judge the recording.
#[must_use]
pub fn coverage(scene: &Scene) -> Vec<String> {
    coverage_over(scene, scene.run.duration)
}

/// [`coverage`] of a recording of `scene` that ended at t = `span`: a run ended early by an event has
/// fewer samples and a tighter residual tolerance (format.md: Tolerances) than its duration promised, so
/// `record` asks again once it knows (Euler's disk under a viscous couple of κ = 1e-4 fell flat after 0.084
/// of its 2000 time units, its tolerance 2.4e-7 instead of 1e-6, and no window was resolved at rate 400).
#[must_use]
pub fn coverage_over(scene: &Scene, span: f64) -> Vec<String> {
    let mut out = Vec::new();
    let energy = missing(scene, &[Channel::Omega, Channel::Angles]);
    if !energy.is_empty() {
        out.push(format!(
            "`energy` will not run: it recomputes E from ω and θ, and {} not recorded; add channels {}",
            are(&energy),
            energy.join(", ")
        ));
    }
    let steady = match (scene.unperturbed_steady(), energy.is_empty()) {
        (Some(_), true) => return out,
        (Some(_), false) => "it needs the channels omega and angles",
        (None, _) => "the scene does not start on an unperturbed steady motion",
    };
    if let Some(why) = constraint_blocker(scene, span) {
        out.push(format!(
            "neither `constraint` nor `steady` will run, so the motion will not be verified: `steady` \
             does not apply ({steady}), and `constraint` {why}"
        ));
    }
    out
}

/// The channels of `needed` that `scene` does not record, by name.
fn missing(scene: &Scene, needed: &[Channel]) -> Vec<&'static str> {
    needed
        .iter()
        .filter(|c| !scene.records(**c))
        .map(|c| c.name())
        .collect()
}

fn are(names: &[&str]) -> String {
    match names {
        [one] => format!("{one} is"),
        many => format!("{} are", many.join(" and ")),
    }
}

/// Why the constraint check will not run on a recording of `scene`, if it will not.
fn constraint_blocker(scene: &Scene, span: f64) -> Option<String> {
    let needed = missing(scene, &[Channel::Omega, Channel::Angles, Channel::Position]);
    if !needed.is_empty() {
        return Some(format!(
            "needs the centre's positions with ω and θ, and {} not recorded; add channels {}",
            are(&needed),
            needed.join(", ")
        ));
    }
    let run = &scene.run;
    let samples = (span * run.rate).floor() + 1.0;
    if samples < constraint::WINDOW as f64 {
        return Some(format!(
            "needs {} evenly spaced samples in a row and the run has {samples} on its sampling grid; raise --rate or --duration",
            constraint::WINDOW
        ));
    }
    let s = &scene.initial;
    let omega = magnitude(s.omega_x, s.omega_y, s.omega_z);
    if omega == 0.0 && s.theta == 0.0 {
        // Upright at rest: eqs (14)–(16) give ω̇ = 0 (sin θ = 0, every other term has a factor ω, and the
        // dissipative couple is 0 at ω = 0), so ω stays 0 and the check finds nothing moving.
        return Some(
            "will find nothing to compare: the coin starts upright at rest (θ = 0, ω = 0), an equilibrium \
             it never leaves, so its centre does not move; give it a motion (a tilt or a spin), or start \
             it as the steady motion `steady = { kind = \"straight\", omega_z = 0 }`, which `steady` judges"
                .to_string(),
        );
    }
    let phi_dot = (s.omega_y / s.theta.cos()).abs();
    let fastest = omega.max(phi_dot);
    let rate = fastest + initial_steepness(scene, omega, phi_dot);
    let accuracy = RunAccuracy::new(&run.method, &scene.params, span, omega);
    let tol = Tolerances::derive(&accuracy, None, None).residual;
    let h = run.sample_interval();
    if constraint::resolves(h, rate, tol) {
        return None;
    }
    // Ω is the rate plus its relative change; the change is named when it shows in the digits printed (a
    // braking couple's: Ω = 1.23e8 on a coin whose |ω| and |φ̇| were 14 and 73 was called max(|ω|, |φ̇|)).
    let (shown_rate, shown_fastest) = (digits3(rate, f64::round), digits3(fastest, f64::round));
    let omega_text = if shown_rate == shown_fastest {
        format!("max(|ω|, |φ̇|) = {shown_rate}")
    } else {
        format!(
            "max(|ω|, |φ̇|) + |d ln Ω/dt| = {shown_fastest} + {} = {shown_rate}",
            digits3(rate - fastest, f64::round),
        )
    };
    Some(format!(
        "will find no window the sampling resolves: at {} samples per time unit, h·Ω = {} (Ω = \
         {omega_text} at t = 0), and the finite difference's error 4(hΩ)^8/630 = {:.1e} exceeds a \
         tenth of the residual tolerance {tol:.1e}; {}",
        run.rate,
        digits3(h * rate, f64::round),
        constraint::truncation(h, rate),
        rate_fix(
            digits3(constraint::min_rate(rate, tol), f64::ceil),
            run.duration
        )
    ))
}

/// What to do for a recording of `duration` to resolve the motion at `needed` samples per time unit: raise
/// --rate, where a rate that high is allowed (samples ≥ 1 ns apart; with a shorter duration past
/// [`crate::scene::MAX_SAMPLES`] in all; format.md: Keys), and otherwise what can help instead (an advice of 6.39e11 on `euler-disk` under a
/// viscous κ = 1e6 was refused as it stood). The rates are those at t = 0: that couple's braking is a
/// transient, and at rate 911 verify judged the windows after it.
fn rate_fix(needed: f64, duration: f64) -> String {
    let what = "the motion as it starts";
    if let Some(none) = constraint::no_rate_resolves(what, needed, &needed.to_string(), duration) {
        return format!(
            "{none} (a motion that slows down later may still be judged where a rate allowed resolves it)"
        );
    }
    let shorter = constraint::shorter_duration(needed, duration);
    format!("raise --rate to at least {needed}{shorter}")
}

/// |d ln Ω/dt| at t = 0 for Ω = max(|ω|, |φ̇|), the relative change the check adds to the rate of each
/// window ([`constraint`]'s steepest term), from ω̇ of the scene's equations: a dissipative couple brakes
/// from the first instant, and one strong enough changes the rates within a sample.
fn initial_steepness(scene: &Scene, omega: f64, phi_dot: f64) -> f64 {
    let s = &scene.initial;
    let acc = scene.dynamics().angular_acceleration(s);
    let steepness = if phi_dot > omega {
        acc.y / s.omega_y + s.theta.tan() * s.omega_x
    } else {
        (s.omega_x * acc.x + s.omega_y * acc.y + s.omega_z * acc.z) / (omega * omega)
    };
    if steepness.is_finite() {
        steepness.abs()
    } else {
        0.0
    }
}
