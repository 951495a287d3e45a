//! `nutation`: the nutation period T and the heading advance per period ΔΦ, measured from the stored angles
//! and ω ([`TurningPoints`]), against the quadrature of physics §10 from the first stored state;
//! format.md (verify, Checks) gives the measurement and the four terms of the tolerance. Energy and the
//! integrals C1, C2 are blind to an error of phase or timing (a recording whose clock runs 1e-6 fast keeps
//! every value on the right orbit); this check is not.

use super::{fmt_num, worst, Context, RunStats};
use crate::format::promise::{nutation_timing, omega_error, MAX_NUTATION_TIMING};
use crate::format::tolerances::{Tolerances, MIN_SAMPLES_PER_PERIOD};
use crate::model::nutation::{Motion, Orbit};
use crate::model::{State, TurningPoints};
use crate::scene::defaults;
use crate::verify::report::{CheckId, CheckResult};
use crate::verify::samples::Sample;

/// The interpolation bound may use at most this share of the tolerance, or the file is undersampled.
const INTERPOLATION_SHARE: f64 = 0.1;
/// Smallest θ range worth measuring \[rad\]: below it the crossings of ω_X are the integrator's noise.
const MIN_AMPLITUDE: f64 = 1e-8;

#[derive(Debug, Default, Clone)]
pub struct NutationCheck {
    initial: Option<State>,
    turning_points: TurningPoints,
    /// max|ω_X| over the samples: the nutation's amplitude in ω_X.
    max_omega_x: f64,
}

impl NutationCheck {
    pub fn observe(&mut self, s: &Sample, ctx: &Context) {
        let Some(state) = s.state() else {
            return;
        };
        self.initial.get_or_insert(state);
        self.max_omega_x = self.max_omega_x.max(state.omega_x.abs());
        self.turning_points.observe(&ctx.coin, s.t, &state);
    }

    /// The result: T and ΔΦ against the quadrature, or why they cannot be compared.
    #[must_use]
    pub fn finish(&self, ctx: &Context, tol: &Tolerances, stats: &RunStats) -> CheckResult {
        self.judge(ctx, tol, stats)
            .unwrap_or_else(|reason| CheckResult::skip(CheckId::Nutation, reason))
    }

    fn judge(
        &self,
        ctx: &Context,
        tol: &Tolerances,
        stats: &RunStats,
    ) -> Result<CheckResult, String> {
        if let Some(d) = ctx.dynamics.dissipation() {
            return Err(format!(
                "the run has dissipation ({}): E, C1 and C2 change, so θ does not nutate periodically and the quadrature (physics §10) does not apply",
                d.model()
            ));
        }
        if let Some(kind) = ctx.run.steady_kind {
            return Err(format!(
                "a steady motion ({kind}) does not nutate; the steady check judges it"
            ));
        }
        let initial = self.initial.ok_or(
            "no sample has both /coin/omega and /coin/angles, so θ's turning points cannot be found",
        )?;
        let chaplygin = ctx.chaplygin.as_ref().map_err(Clone::clone)?;
        let orbit = Orbit::new(&ctx.coin, chaplygin, &initial, flat_margin(ctx))
            .map_err(|e| format!("the first stored state has no orbit: {e}"))?;
        let (period, precession) = match orbit.motion {
            Motion::Periodic {
                period, precession, ..
            } => (period, precession),
            Motion::Steady => {
                return Err("the first stored state is steady: θ does not nutate".into())
            }
            Motion::FlatLanding { time, .. } => {
                return Err(format!(
                    "the quadrature says the coin lands flat at t = {}: there is no period",
                    fmt_num(time)
                ))
            }
        };
        if orbit.theta_max - orbit.theta_min < MIN_AMPLITUDE {
            return Err(format!(
                "θ nutates by {} rad only: below {MIN_AMPLITUDE:e} its turning points are the integrator's noise",
                fmt_num(orbit.theta_max - orbit.theta_min)
            ));
        }
        let time_unit = ctx.coin.params().time_unit();
        let span = stats.last_t - stats.first_t.unwrap_or(0.0);
        let omega_error = omega_error(tol.epsilon, span, time_unit, stats.max_omega);
        self.compare(&orbit, (period, precession), tol, omega_error)
    }

    fn compare(
        &self,
        orbit: &Orbit,
        (period, precession): (f64, f64),
        tol: &Tolerances,
        omega_error: f64,
    ) -> Result<CheckResult, String> {
        let meter = &self.turning_points;
        let measured = meter.measure().ok_or_else(|| {
            format!(
                "fewer than two nutation periods recorded ({} maxima and {} minima of θ; T = {} by quadrature)",
                meter.maxima(),
                meter.minima(),
                fmt_num(period)
            )
        })?;
        let h = meter.largest_interval();
        if h * MIN_SAMPLES_PER_PERIOD > period {
            return Err(format!(
                "undersampled: samples {} apart, fewer than {MIN_SAMPLES_PER_PERIOD} per nutation period T = {}; record with a higher --rate",
                fmt_num(h),
                fmt_num(period)
            ));
        }
        let (t_measured, phi_measured) = (measured.period, measured.precession);
        let interpolation = meter.interpolation_error(&measured, period);
        if interpolation > INTERPOLATION_SHARE * tol.nutation {
            return Err(format!(
                "undersampled: interpolating the turning points between samples {} apart may be off by {} of T, more than {} of the tolerance {}; record with a higher --rate",
                fmt_num(h),
                fmt_num(interpolation),
                INTERPOLATION_SHARE,
                fmt_num(tol.nutation)
            ));
        }
        let timing = nutation_timing(omega_error, self.max_omega_x, period, measured.span);
        if timing > MAX_NUTATION_TIMING {
            return Err(format!(
                "the nutation is too small for the recorded accuracy: ω_X swings by {} only, and an error of {} in ω (0.1 ε (1 + T/τ) W, what the integrator's errors reach) times its turning points to {} of T, above {MAX_NUTATION_TIMING:e}; record with a tighter --rtol/--atol (--step) or a larger nutation",
                fmt_num(self.max_omega_x),
                fmt_num(omega_error),
                fmt_num(timing)
            ));
        }
        let tolerance = tol.nutation + orbit.error + interpolation + timing;
        let t_error = (t_measured - period).abs() / period;
        let phi_error = (phi_measured - precession).abs() / precession.abs().max(1.0);
        let (value, _, which) = worst(
            (t_error, tolerance, "period"),
            &[(phi_error, tolerance, "heading advance")],
        );
        Ok(CheckResult::measured(
            CheckId::Nutation,
            value,
            tolerance,
            format!(
                "{which} is the worst measure: T = {} measured over {} periods ({} maxima, {} minima of θ) vs {} by quadrature, relative {}; ΔΦ = {} vs {} rad, off by {} (relative to max(|ΔΦ|, 1 rad)); tolerance {} + quadrature {} + interpolation {} + timing {}",
                t_measured,
                fmt_num(measured.periods),
                meter.maxima(),
                meter.minima(),
                period,
                fmt_num(t_error),
                phi_measured,
                precession,
                fmt_num(phi_error),
                fmt_num(tol.nutation),
                fmt_num(orbit.error),
                fmt_num(interpolation),
                fmt_num(timing)
            ),
        ))
    }
}

/// The flat margin of the stored scene (the default when the scene cannot be read).
fn flat_margin(ctx: &Context) -> f64 {
    ctx.scene
        .as_ref()
        .map_or(defaults::FLAT_MARGIN, |s| s.run.flat_margin)
}
