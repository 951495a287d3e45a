//! What `verify`'s default tolerances will accept, predicted from a run's settings before it runs, so that
//! `record` promises only what `verify` will grant (format.md: What record promises). Where a clamp of the
//! tolerances bites, their safety factor is gone, and the prediction uses what the errors actually reach:
//!
//!   drifts and residuals   ≈ [`GROWTH_SHARE`] · ε (1 + T/τ)
//!   nutation (relative)    ≈ [`NUTATION_SHARE`] · ε + [`NUTATION_GROWTH`] · ε (1 + T/τ)
//!   rounding of n steps    ≈ [`ROUNDING_SHARE`] · n · 2⁻⁵³       (fixed-step methods; n = T/h)
//!   rounding differenced   ≈ [`DIFFERENCE_GAIN`] · 2⁻⁵³ / (Δt Ω)  (every method, constraint)
//!   offset differenced     ≈ [`DIFFERENCE_GAIN`] · 2⁻⁵³ · (1 + k) X / (a Δt Ω)  (every method, constraint;
//!                            X = max(|x₀|, |z₀|), k the fixed steps per sample, 0 for adaptive methods)
//!   heading rounding       ≈ [`HEADING_SHARE`] · 2⁻⁵³ · Φ   (every method, constraint and nutation;
//!                            Φ = |φ₀| + T |φ̇₀|)
//!   dense output differenced ≈ [`dense_output_share`] · min(ε^(1/p), T Ω)^(p−1)  (adaptive methods of order
//!                            p, constraint)
//!
//! `tests/it/record_verify_agreement.rs` checks that no run predicted to pass fails.

use super::tolerances::{RunAccuracy, Tolerances, UNIT_ROUNDOFF};
use crate::integrate::Method;
use std::fmt;

/// Share of ε (1 + T/τ) reached by the energy drift, the invariant drift and the constraint residual.
/// Measured on `wobble` (30 time units) at rtol = atol = 1e-3: dop853 0.0095, 0.0021, 0.089; dopri5 0.039,
/// 0.017, 0.029; rk4 at hW = 0.15: 5e-4, 1e-4. The largest, 0.089, rounded up.
pub const GROWTH_SHARE: f64 = 0.1;
/// Share of ε reached by the relative error of the nutation period and heading advance. Measured on
/// `wobble` at rtol 1e-3: 0.22 (dop853), 0.62 (dopri5).
pub const NUTATION_SHARE: f64 = 1.0;
/// Share of ε (1 + T/τ) added to the nutation error over long runs: the phase error of a drifting
/// period grows with the span faster than the periods measured. Measured on `long-horizon` (1000 time
/// units) at rtol 1e-6: 4.4e-6 (dop853, 0.0044), 8.6e-6 (dopri5, 0.0086), where `NUTATION_SHARE` alone
/// promised a pass against 1.5e-6; `wobble` at 1e-6 (dopri5) 0.011; 10 000 time units at 1e-10 (dopri5)
/// 0.0042. The largest, doubled.
pub const NUTATION_GROWTH: f64 = 0.02;
/// Largest timing bound ([`nutation_timing`]) verify's `nutation` accepts: the ceiling of every default
/// tolerance (format.md: Tolerances). Above it the nutation is too small for the recorded accuracy to time,
/// and verify skips the check.
pub const MAX_NUTATION_TIMING: f64 = 1e-6;

/// The error in ω a run integrated to ε over `span` reaches: [`GROWTH_SHARE`] ε (1 + T/τ) W, W =
/// max(max|ω|, 1/τ) the state's scale (the share `record` predicts for the drifts).
#[must_use]
pub fn omega_error(epsilon: f64, span: f64, time_unit: f64, max_omega: f64) -> f64 {
    let growth = 1.0 + span.max(0.0) / time_unit;
    GROWTH_SHARE * epsilon * growth * max_omega.max(1.0 / time_unit)
}

/// Relative error of T and ΔΦ from the timing of the turning points: ω_X off by `omega_error` moves a
/// zero of ω_X by omega_error / |ω̇_X|, |ω̇_X| = A σ at a zero of a nutation of amplitude A = max|ω_X| and
/// frequency σ = 2π/T; the first and last turning points of a span each move so, 2 of them over `span`.
/// Measured on `circle-plus` kicked by δω_X = 1e-5 … 1.5e-8 (dop853 and dopri5, defaults): the error is
/// 1/65 … 1/3 of this bound, and 2.6e-8 … 1.2e-4 against the 1e-8 of the nutation tolerance alone.
#[must_use]
pub fn nutation_timing(omega_error: f64, max_omega_x: f64, period: f64, span: f64) -> f64 {
    let sigma = std::f64::consts::TAU / period;
    2.0 * omega_error / (max_omega_x * sigma * span)
}

/// Rounding per fixed step, in units of 2⁻⁵³: each step's increment h·f is rounded into y, with a bias
/// once h·f is far below y's last digits. Measured on `wobble` with rk4 over 0.01 time units: 1e7 steps
/// drift 2.2e-14 in C1, C2 (2e-5 a step), 1e8 steps 8.9e-12 (8e-4 a step); 5e-4 puts them on either side of
/// the 1e-12 floor, as verify judged them.
pub const ROUNDING_SHARE: f64 = 5e-4;

/// Share of ε^((p−1)/p) reached by the constraint residual of an adaptive method of order p (0 for
/// fixed-step methods, whose positions are each a step's end). The positions between steps come from the
/// dense output, whose velocity errs by about the local error ε over one step; a step spans ε^(1/p)
/// radians of the motion or more (the mean step of the 12 scenes below: 1.2 to 260 times that,
/// Ω = max(max|ω|, 1/τ)) and never more than the run, hence min(ε^(1/p), T Ω)^(p−1). Independent of the
/// sampling (rates 100 and 1000 agree). Measured at rtol 1e-6 … 1e-9 on 12 built-in scenes: dop853
/// (p = 8) up to 4.75 (`straight-unstable`), dopri5 (p = 5) up to 7.5 (`five-hundred-yen`); on 29 random
/// leans, spins and shapes (78 runs) dop853 up to 10.6 (a hoop at θ₀ = 1.365), dopri5 up to 1.8. The
/// largest of each, rounded up. `wobble --rtol 1e-7` (dop853) reached 1.67e-6 against the ceiling 1e-6
/// without a word before.
#[must_use]
pub fn dense_output_share(method: Method) -> f64 {
    match method {
        Method::Dop853 => 12.0,
        Method::Dopri5 => 8.0,
        Method::Rk4 | Method::Gauss4 => 0.0,
    }
}

/// Share of 2⁻⁵³ Φ reached by the constraint residual and the nutation error of a run whose heading
/// reaches Φ rad: φ is rounded to 2⁻⁵³ Φ at every step, which turns the velocity and shifts the heading
/// advance. Measured on `wobble` with φ₀ = 1e6 … 1e9: the constraint 36 (dop853), 2 (dopri5), 1.4 (rk4,
/// gauss4); the nutation 13 (rk4, gauss4, failing from φ₀ = 1e7), 1.2–8.4 (dop853, failing from 3e8),
/// 2.2 (dopri5), and more beyond 1e9 (dop853: 318 at 1e10, far past every tolerance). Before, `wobble
/// --set initial.phi=1e12` recorded without a word and failed both checks. The largest, rounded up.
pub const HEADING_SHARE: f64 = 50.0;

/// Gain of the constraint's 8th-order central difference on independent rounding of its samples:
/// 2 Σ|wₖ| = 2 (4/5 + 1/5 + 4/105 + 1/280) = 2.08. Measured on `wobble` at the highest rate (samples 1 ns
/// apart, over 1e-3 time units): rk4 and gauss4 fail `constraint`, whose floor 1e-10 this puts below
/// 2.08·2⁻⁵³/(1e-9·1.54) = 1.5e-7. An adaptive method's dense output rounds its positions at every sample
/// too, by about 2⁻⁵³ of a step's increment: dop853 reached 8.5e-8 there (0.57 of this), 8.6e-9 at
/// 1e-8 apart, 3.1e-9 on `high-spin` (0.67), and failed at rtol 1e-12 (tolerance 1e-9) without a word
/// before.
pub const DIFFERENCE_GAIN: f64 = 2.08;

/// Why a check is expected to fail: `epsilon` is the tolerances' ε, `sample_interval` the distance Δt
/// between samples.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(
    missing_docs,
    reason = "the enum's and each variant's doc name the fields"
)]
pub enum Cause {
    /// The accuracy asked for (ε) is looser than the tolerance's ceiling allows.
    Accuracy { epsilon: f64 },
    /// The rounding of very many `fixed` steps, or of fixed steps differenced over samples very close
    /// together, exceeds the tolerance's floor.
    Rounding { fixed: FixedSteps },
    /// The dense output of an adaptive method, differentiated for the rolling constraint, errs by more
    /// than the tolerance; it is half the tolerance (the other half left to the other errors) at the ε
    /// `enough`.
    DenseOutput { epsilon: f64, enough: f64 },
    /// The `heading` φ grows so large (|φ₀| + T |φ̇₀| \[rad\] expected at most) that its rounding changes
    /// the velocity's direction and the heading advance by more than the tolerance.
    Heading { heading: f64 },
    /// Samples so close together that the rounding of the positions an adaptive method's dense output
    /// gives, differenced over them, exceeds the constraint's tolerance.
    Sampling { sample_interval: f64 },
    /// The centre starts so far from the origin that the rounding of its stored coordinates
    /// (`positions`), differenced over samples close together, exceeds the constraint's tolerance.
    Offset { positions: Positions },
}

/// The `checks` (their ids, format.md: verify) expected to fail on a recording, with the error
/// `predicted`, verify's default `tolerance` they will be judged by, and the `cause`, the larger share of
/// the prediction.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct Shortfall {
    pub checks: &'static [&'static str],
    pub predicted: f64,
    pub tolerance: f64,
    pub cause: Cause,
}

impl fmt::Display for Shortfall {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let checks: Vec<String> = self.checks.iter().map(|c| format!("`{c}`")).collect();
        write!(
            f,
            "{} will likely fail: ",
            checks.join(if checks.len() == 2 { " and " } else { ", " })
        )?;
        match self.cause {
            Cause::Accuracy { epsilon } => write!(
                f,
                "these settings allow an error of about {:.1e} (ε = {epsilon:.1e}), above the tolerance \
                 {:.1e} verify judges by; tighten --rtol/--atol (dopri5, dop853) or --step (rk4, gauss4)",
                self.predicted, self.tolerance
            ),
            Cause::Rounding { fixed } => write!(
                f,
                "{:.1e} fixed steps with samples {:.1e} apart leave rounding of about {:.1e}, above the \
                 tolerance {:.1e} verify judges by; take a larger --step (fewer steps) or a lower --rate",
                fixed.steps, fixed.sample_interval, self.predicted, self.tolerance
            ),
            Cause::DenseOutput { epsilon, enough } => write!(
                f,
                "between its steps the integrator's dense output, whose velocity the constraint check \
                 compares, errs by up to about {:.1e} at ε = {epsilon:.1e}, above the tolerance {:.1e} \
                 verify judges by; tighten --rtol/--atol to ε ≤ {enough:.1e}",
                self.predicted, self.tolerance
            ),
            Cause::Heading { heading } => write!(
                f,
                "the heading φ reaches about {heading:.1e} rad (|φ₀| + T |φ̇₀|), whose rounding moves the \
                 velocity's direction and the heading advance by about {:.1e}, above the tolerance {:.1e} \
                 verify judges by; start from initial.phi within a turn of 0, or record a shorter run",
                self.predicted, self.tolerance
            ),
            Cause::Sampling { sample_interval } => write!(
                f,
                "samples {sample_interval:.1e} apart are so close that the rounding of the positions \
                 between the integrator's steps, differenced over them, is about {:.1e}, above the \
                 tolerance {:.1e} verify judges by; take a lower --rate",
                self.predicted, self.tolerance
            ),
            Cause::Offset { positions } => write!(
                f,
                "the centre starts {:.1e} radii from the origin, and the rounding of its stored coordinates, \
                 differenced over samples {:.1e} apart, is about {:.1e}, above the tolerance {:.1e} verify \
                 judges by; put the origin near the coin (initial.x, initial.z) or take a lower --rate",
                positions.offset, positions.sample_interval, self.predicted, self.tolerance
            ),
        }
    }
}

/// The fixed steps of a run, as far as their rounding goes: the `steps` over the span and the distance
/// Δt between samples, `sample_interval`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct FixedSteps {
    pub steps: f64,
    pub sample_interval: f64,
}

/// The stored coordinates whose size costs digits, as far as their rounding goes. The centre's are each
/// rounded to 2⁻⁵³ of their size (at every fixed step between samples), and the constraint check
/// differentiates them over samples `sample_interval` apart. Measured on `wobble` with x₀ = 1e8 … 1e10:
/// dop853 reaches 0.5–0.7 of the prediction, rk4 (10 steps a sample) 0.3–0.4. The heading's rounding
/// turns the velocity and the heading advance ([`HEADING_SHARE`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Positions {
    /// The largest initial centre coordinate, max(|x₀|, |z₀|), in radii a.
    pub offset: f64,
    /// Distance between samples Δt.
    pub sample_interval: f64,
    /// |φ₀| \[rad\].
    pub heading: f64,
    /// |φ̇₀| \[rad/time\], which carries the heading to |φ₀| + T |φ̇₀| over the span T.
    pub heading_rate: f64,
}

/// The checks of a recording integrated as `run` that verify's default tolerances are expected to fail;
/// `fixed` describes the steps of a fixed-step method (`None` for adaptive ones, whose steps are few
/// enough for their rounding to stay below the floors); `positions` where the centre starts.
#[must_use]
pub fn shortfalls(
    run: &RunAccuracy,
    fixed: Option<FixedSteps>,
    positions: Positions,
) -> Vec<Shortfall> {
    let tolerances = Tolerances::derive(run, None, None);
    let epsilon = tolerances.epsilon;
    let growth = epsilon * (1.0 + (run.span / run.time_unit).max(0.0));
    let fixed_steps = fixed.map(|f| f.steps);
    let rounding = fixed_steps.map_or(0.0, |n| ROUNDING_SHARE * n * UNIT_ROUNDOFF);
    let omega = run.max_omega.max(1.0 / run.time_unit);
    // Every stored position is rounded: at a fixed step's end, or by the dense output between steps.
    let interval = fixed.map_or(positions.sample_interval, |f| f.sample_interval);
    let differenced = DIFFERENCE_GAIN * UNIT_ROUNDOFF / (interval * omega);
    // A fixed-step method rounds the coordinates at each of its steps between two samples, an adaptive
    // one's dense output once per sample.
    let roundings = 1.0 + fixed.map_or(0.0, |f| (f.sample_interval / run.step).round());
    let offset = DIFFERENCE_GAIN * UNIT_ROUNDOFF * roundings * positions.offset
        / (positions.sample_interval * omega);
    let order = f64::from(run.integrator.order());
    let dense_share = dense_output_share(run.integrator);
    let heading = positions.heading + run.span.max(0.0) * positions.heading_rate;
    let heading_error = HEADING_SHARE * UNIT_ROUNDOFF * heading;
    let accumulated = GROWTH_SHARE * growth;
    let accuracy = Cause::Accuracy { epsilon };
    let rounded = fixed.map_or(
        Cause::Sampling {
            sample_interval: positions.sample_interval,
        },
        |fixed| Cause::Rounding { fixed },
    );
    let (dense, interpolated) = if dense_share > 0.0 {
        let step_radians = epsilon.powf(order.recip()).min(run.span.max(0.0) * omega);
        let enough = (0.5 * tolerances.residual / dense_share).powf(order / (order - 1.0));
        (
            dense_share * step_radians.powf(order - 1.0),
            Cause::DenseOutput {
                epsilon,
                enough: two_digits_down(enough),
            },
        )
    } else {
        (0.0, accuracy)
    };
    let heading_cause = Cause::Heading { heading };
    [
        judge(
            &["energy", "invariants"],
            &[(accumulated, accuracy), (rounding, rounded)],
            tolerances.energy,
        ),
        judge(
            &["constraint", "steady"],
            &[
                (accumulated, accuracy),
                (rounding + differenced, rounded),
                (offset, Cause::Offset { positions }),
                (dense, interpolated),
                (heading_error, heading_cause),
            ],
            tolerances.residual,
        ),
        judge(
            &["nutation"],
            &[
                (
                    NUTATION_SHARE * epsilon + NUTATION_GROWTH * growth,
                    accuracy,
                ),
                (heading_error, heading_cause),
            ],
            tolerances.nutation,
        ),
    ]
    .into_iter()
    .flatten()
    .collect()
}

/// The shortfall of `checks` whose predicted error is the sum of `parts`, each with its cause, if it
/// exceeds `tolerance`; the largest part names the cause.
fn judge(
    checks: &'static [&'static str],
    parts: &[(f64, Cause)],
    tolerance: f64,
) -> Option<Shortfall> {
    let predicted = parts.iter().fold(0.0, |sum, (part, _)| sum + part);
    let (_, cause) =
        parts
            .iter()
            .copied()
            .reduce(|largest, part| if part.0 > largest.0 { part } else { largest })?;
    (predicted > tolerance).then_some(Shortfall {
        checks,
        predicted,
        tolerance,
        cause,
    })
}

/// `x` > 0 rounded down to two significant digits, so that the ε a message suggests, as printed, is
/// enough.
fn two_digits_down(x: f64) -> f64 {
    let unit = 10f64.powf(x.log10().floor() - 1.0);
    (x / unit).floor() * unit
}

/// The check ids of `shortfalls`, joined by `separator` (`,` in the `expected_to_fail` metadata value).
#[must_use]
pub fn check_list(shortfalls: &[Shortfall], separator: &str) -> String {
    shortfalls
        .iter()
        .flat_map(|s| s.checks.iter().copied())
        .collect::<Vec<_>>()
        .join(separator)
}
