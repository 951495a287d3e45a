//! The nutation of any motion by quadrature (physics §10, §12): with E, C1 and C2 fixed, θ̇² = f(θ) and
//! the turning points, the nutation period and the heading advance per period are one-dimensional
//! integrals.
//!
//! Beyond physics §10 ("Precision") and §12 ("Quadrature"): turning points by a geometric scan outwards
//! from θ₀ and bisection to adjacent floats; times to an event leg by leg, by adaptive Gauss–Legendre in v
//! with θ = r + (θ₁ − r) v² from a turning point r; the extremes of N and |F|/N by a scan of 257 points
//! refined by golden section.

use super::derived::{energy, reaction};
use super::equations::Coin;
use super::invariants::Chaplygin;
use super::quadrature::{bisect, gauss_legendre, Adaptive};
use super::state::State;
use std::f64::consts::{FRAC_PI_2, PI};
use thiserror::Error;

/// |θ − θ₀| within which U(θ) − U(θ₀) is integrated from S (see the module doc) \[rad\].
const SHORT_RANGE: f64 = 0.02;
/// Order of the Gauss–Legendre rule of that integral.
const SHORT_RULE: usize = 16;
/// A state is steady when ω_X and S(θ₀) are both below this fraction of their natural scales (64 ulp).
const STEADY_TOLERANCE: f64 = 64.0 * f64::EPSILON;
/// First step of the turning-point scan \[rad\].
const FIRST_STEP: f64 = 1e-12;
/// Largest step of the turning-point scan \[rad\].
const LARGEST_STEP: f64 = 1.0 / 128.0;
/// Agreement at which the period quadrature stops doubling its nodes.
const CONVERGED: f64 = 1e-14;
/// Below this change between doublings, a change that stops shrinking is rounding noise.
const NOISE_FLOOR: f64 = 1e-10;
/// Fewest and most nodes of the period quadrature.
const FIRST_NODES: usize = 32;
/// See [`FIRST_NODES`].
const MOST_NODES: usize = 1 << 19;
/// Relative tolerance of the adaptive travel-time integrals.
const TRAVEL_RTOL: f64 = 1e-14;
/// The matching angle of the escape from near upright (physics §12): below it θ̇² is taken as its
/// expansion to second order about the turning point, which errs by about θ_m²/(48λ) in time, 2e-8 at
/// 1e-3 \[rad\].
const MATCHING: f64 = 1e-3;
/// Points of the scan for the extremes of N and |F|/N.
const EXTREME_SCAN: usize = 257;

/// Why the quadrature cannot be done.
#[derive(Debug, Clone, PartialEq, Error)]
#[allow(missing_docs, reason = "each field is named in its variant's message")]
pub enum NutationError {
    /// The state is not finite or leans flat.
    #[error("the state is not a rolling coin: θ = {theta} must satisfy |θ| < π/2 − flat_margin = {limit}, and every ω must be finite")]
    BadState { theta: f64, limit: f64 },
}

/// What the motion does.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "FlatLanding's doc names its fields")]
pub enum Motion {
    /// ω_X = 0 and the steady family holds (to `STEADY_TOLERANCE`): θ stays where it is.
    Steady,
    /// θ oscillates between two turning points.
    Periodic {
        /// The nutation period T = 2∫dθ/|θ̇| \[time\].
        period: f64,
        /// The heading advance per period ΔΦ = 2∫φ̇ dθ/|θ̇| \[rad\].
        precession: f64,
        /// The spin advance per period ΔΨ = 2∫ψ̇ dθ/|θ̇| \[rad\].
        spin_advance: f64,
    },
    /// θ reaches the flat margin: the coin lands flat (physics §7) at the lean `theta` = ±(π/2 −
    /// flat_margin), at `time` from t = 0.
    FlatLanding { theta: f64, time: f64 },
}

/// A lean `theta` \[rad\] and the `time` from t = 0 at which the motion first reaches it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct Event {
    pub theta: f64,
    pub time: f64,
}

/// An extreme `value` over the motion and the lean `theta` \[rad\] where it is attained.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct Extremum {
    pub value: f64,
    pub theta: f64,
}

/// The motion from one state, by quadrature (physics §10), with the state's `energy` E (physics §3),
/// `c1` and `c2` (physics §6).
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names the fields without one")]
pub struct Orbit {
    pub energy: f64,
    pub c1: f64,
    pub c2: f64,
    /// What the motion does.
    pub motion: Motion,
    /// The smallest lean the motion reaches (up to the landing for a flat landing) \[rad\].
    pub theta_min: f64,
    /// The largest lean the motion reaches \[rad\].
    pub theta_max: f64,
    /// The smallest normal force N over [θ_min, θ_max] (negative: the rim-contact model would need the
    /// table to pull, and the coin lifts off where N first reaches 0).
    pub min_normal: Extremum,
    /// The largest |F|/N over [θ_min, θ_max], the friction coefficient the motion needs; `None` when N
    /// reaches 0 (the ratio is unbounded).
    pub max_friction_ratio: Option<Extremum>,
    /// Where and when N first reaches 0 along the motion, if it does.
    pub lift_off: Option<Event>,
    /// Estimated relative error of the period and the heading advance (or of the landing time): the
    /// quadrature's convergence and the rounding of θ̇² near the turning points.
    pub error: f64,
}

impl Orbit {
    /// The motion of `state` for `coin`, with the flat landing at |θ| = π/2 − `flat_margin`; fails
    /// ([`NutationError::BadState`]) for a non-finite state or one at or beyond the flat margin.
    ///
    /// ```
    /// use coin_log::model::{Chaplygin, Coin, CoinParams, State};
    /// use coin_log::model::nutation::{Motion, Orbit};
    /// let coin = Coin::new(CoinParams::unit_disk());
    /// let chaplygin = Chaplygin::new(coin.params()).unwrap();
    /// let wobble = State { theta: 0.5, omega_x: 0.3, omega_y: 0.2, omega_z: 1.5, ..State::default() };
    /// let orbit = Orbit::new(&coin, &chaplygin, &wobble, 1e-4).unwrap();
    /// assert!(matches!(orbit.motion, Motion::Periodic { .. }));
    /// assert!(orbit.theta_min < 0.5 && 0.5 < orbit.theta_max);
    /// ```
    pub fn new(
        coin: &Coin,
        chaplygin: &Chaplygin,
        state: &State,
        flat_margin: f64,
    ) -> Result<Self, NutationError> {
        let limit = FRAC_PI_2 - flat_margin;
        let finite = [state.theta, state.omega_x, state.omega_y, state.omega_z]
            .iter()
            .all(|v| v.is_finite());
        if !finite || state.theta.abs() >= limit {
            return Err(NutationError::BadState {
                theta: state.theta,
                limit,
            });
        }
        let mut orbit = Self::steady(coin, chaplygin, state);
        if !is_steady(coin, state) {
            Reduced::new(coin, chaplygin, state, limit).fill(&mut orbit);
        }
        Ok(orbit)
    }

    /// The motion of a state taken as steady (θ stays where it is): E, C1, C2, N and |F|/N of the state.
    #[must_use]
    pub fn steady(coin: &Coin, chaplygin: &Chaplygin, state: &State) -> Self {
        let invariants = chaplygin.of_state(state);
        let r = reaction(coin, state);
        Self {
            energy: energy(coin, state).total,
            c1: invariants.c1,
            c2: invariants.c2,
            motion: Motion::Steady,
            theta_min: state.theta,
            theta_max: state.theta,
            min_normal: Extremum {
                value: r.normal,
                theta: state.theta,
            },
            max_friction_ratio: (r.normal > 0.0).then_some(Extremum {
                value: r.friction / r.normal,
                theta: state.theta,
            }),
            lift_off: (r.normal <= 0.0).then_some(Event {
                theta: state.theta,
                time: 0.0,
            }),
            error: 0.0,
        }
    }
}

/// S(θ) = I_X tan θ ω_Y² + (I_Z + Ma²) ω_Y ω_Z − Mga sin θ and the sum of the magnitudes of its terms:
/// (I_X + Ma²) ω̇_X = −S (eq (14)); S = 0 is the steady family (physics §4).
fn steady_residual(coin: &Coin, theta: f64, omega_y: f64, omega_z: f64) -> (f64, f64) {
    let p = coin.params();
    let (st, ct) = theta.sin_cos();
    let terms = [
        p.inertia_x() * st / ct * omega_y * omega_y,
        (p.inertia_z() + p.ma2()) * omega_y * omega_z,
        -p.energy_scale() * st,
    ];
    (
        terms.iter().sum(),
        terms.iter().map(|t| t.abs()).sum::<f64>(),
    )
}

/// Whether `state` is a steady motion to rounding: ω_X = 0 and the steady family holds, each to
/// [`STEADY_TOLERANCE`] of its natural scale (|ω| + √(g/a) for ω_X, the size of S's terms for S).
#[must_use]
fn is_steady(coin: &Coin, state: &State) -> bool {
    let p = coin.params();
    let rate = (state.omega_x.powi(2) + state.omega_y.powi(2) + state.omega_z.powi(2)).sqrt()
        + 1.0 / p.time_unit();
    let (s, terms) = steady_residual(coin, state.theta, state.omega_y, state.omega_z);
    state.omega_x.abs() <= STEADY_TOLERANCE * rate && s.abs() <= STEADY_TOLERANCE * terms
}

/// One end of the θ range in one direction from θ₀.
#[derive(Debug, Clone, Copy, PartialEq)]
enum End {
    /// A turning point (θ̇ = 0).
    Turn(f64),
    /// The flat margin, reached with θ̇ ≠ 0.
    Flat(f64),
}

/// A stretch of the path from `from` to `to`, each end possibly a turning point.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Leg {
    from: f64,
    to: f64,
    from_turns: bool,
    to_turns: bool,
}

impl Leg {
    fn new(from: f64, to: f64, from_turns: bool, to_turns: bool) -> Self {
        Self {
            from,
            to,
            from_turns,
            to_turns,
        }
    }
}

/// The motion reduced to θ alone, for one state's E, C1, C2.
struct Reduced<'a> {
    coin: &'a Coin,
    chaplygin: &'a Chaplygin,
    c1: f64,
    c2: f64,
    /// I_X + Ma².
    lever: f64,
    theta0: f64,
    omega_x0: f64,
    /// U(θ₀).
    u0: f64,
    /// |θ − θ₀| within which ΔU is integrated from S.
    short: f64,
    /// The turning points found so far, each with the distance within which θ̇² is integrated from it.
    anchors: Vec<(f64, f64)>,
    /// π/2 − flat_margin.
    limit: f64,
    rule: Vec<(f64, f64)>,
    adaptive: Adaptive,
}

impl<'a> Reduced<'a> {
    fn new(coin: &'a Coin, chaplygin: &'a Chaplygin, state: &State, limit: f64) -> Self {
        let p = coin.params();
        let c = chaplygin.of_state(state);
        let mut reduced = Self {
            coin,
            chaplygin,
            c1: c.c1,
            c2: c.c2,
            lever: p.inertia_x() + p.ma2(),
            theta0: state.theta,
            omega_x0: state.omega_x,
            u0: 0.0,
            short: SHORT_RANGE.min(0.1 * (FRAC_PI_2 - state.theta.abs())),
            anchors: Vec::new(),
            limit,
            rule: gauss_legendre(SHORT_RULE),
            adaptive: Adaptive::new(),
        };
        reduced.u0 = reduced.potential(reduced.rates(state.theta), state.theta.cos());
        reduced
    }

    /// (ω_Y, ω_Z) at θ for this motion's C1, C2 (physics §6 inverted).
    fn rates(&self, theta: f64) -> (f64, f64) {
        let b = self.chaplygin.basis(theta);
        let omega_z = self.c1 * b.y_even + self.c2 * b.y_odd;
        let omega_y =
            self.chaplygin.k() * (self.c1 * b.flux_even + self.c2 * b.flux_odd) / theta.cos();
        (omega_y, omega_z)
    }

    /// U = ½ I_X ω_Y² + ½ (I_Z + Ma²) ω_Z² + Mga cos θ, eq (25), from (ω_Y, ω_Z) and cos θ.
    fn potential(&self, (wy, wz): (f64, f64), cos_t: f64) -> f64 {
        let p = self.coin.params();
        0.5 * p.inertia_x() * wy * wy
            + 0.5 * (p.inertia_z() + p.ma2()) * wz * wz
            + p.energy_scale() * cos_t
    }

    /// S(θ) = dU/dθ, eq (26).
    fn slope(&self, theta: f64) -> f64 {
        let (wy, wz) = self.rates(theta);
        steady_residual(self.coin, theta, wy, wz).0
    }

    /// The mean of S over [a, b] by the 16-point Gauss–Legendre rule (a, b close: see the module doc).
    fn mean_slope(&self, a: f64, b: f64) -> f64 {
        let (centre, half) = (0.5 * (a + b), 0.5 * (b - a));
        0.5 * self
            .rule
            .iter()
            .map(|&(x, w)| w * self.slope(centre + half * x))
            .sum::<f64>()
    }

    /// The turning point θ is integrated from, if it is close to one.
    fn anchor(&self, theta: f64) -> Option<f64> {
        self.anchors
            .iter()
            .find(|(a, reach)| (theta - a).abs() <= *reach)
            .map(|&(a, _)| a)
    }

    /// θ̇² = f(θ) = ω_X0² − 2(U(θ) − U(θ₀))/(I_X + Ma²), eq (27). Close to a turning point r (once found)
    /// f = −2(θ − r) mean(S)/(I_X + Ma²), close to θ₀ U(θ) − U(θ₀) = (θ − θ₀) mean(S), and elsewhere
    /// the difference of the two potentials.
    fn theta_dot_squared(&self, theta: f64) -> f64 {
        if let Some(r) = self.anchor(theta) {
            return -2.0 * (theta - r) * self.mean_slope(r, theta) / self.lever;
        }
        let offset = theta - self.theta0;
        let change = if offset.abs() <= self.short {
            offset * self.mean_slope(self.theta0, theta)
        } else {
            self.potential(self.rates(theta), theta.cos()) - self.u0
        };
        self.omega_x0 * self.omega_x0 - 2.0 * change / self.lever
    }

    /// f(θ)/((θ − lo)(hi − θ)) between the turning points lo < hi, without dividing small by small near
    /// them: there f = −2(θ − r) mean(S)/(I_X + Ma²) and the factor θ − r cancels.
    fn reduced_rate(&self, theta: f64, below: f64, above: f64) -> f64 {
        match self.anchor(theta) {
            Some(r) if below <= above => -2.0 * self.mean_slope(r, theta) / self.lever / above,
            Some(r) => 2.0 * self.mean_slope(theta, r) / self.lever / below,
            None => self.theta_dot_squared(theta) / (below * above),
        }
    }

    /// The state on the orbit at θ (ω_X ≥ 0; N and |F| do not depend on its sign).
    fn state(&self, theta: f64) -> State {
        let (omega_y, omega_z) = self.rates(theta);
        State {
            theta,
            omega_x: self.theta_dot_squared(theta).max(0.0).sqrt(),
            omega_y,
            omega_z,
            ..State::default()
        }
    }

    /// |f′| = |2S/(I_X + Ma²)| at θ: how fast θ̇² opens from a turning point there.
    fn turn_slope(&self, theta: f64) -> f64 {
        (2.0 * self.slope(theta) / self.lever).abs()
    }

    /// N on the orbit at θ.
    fn normal(&self, theta: f64) -> f64 {
        reaction(self.coin, &self.state(theta)).normal
    }

    /// The direction θ moves in at t = 0: the sign of ω_X0, or of θ̈ = −S/(I_X + Ma²) when ω_X0 = 0.
    fn direction(&self) -> f64 {
        if self.omega_x0 != 0.0 {
            self.omega_x0.signum()
        } else {
            -self.slope(self.theta0).signum()
        }
    }

    /// The end of the θ range from θ₀ in `direction` (±1).
    fn end(&self, direction: f64) -> End {
        let limit = direction * self.limit;
        let inside = |theta: f64| self.theta_dot_squared(theta) > 0.0;
        let (mut last_inside, mut step, mut offset) = (self.theta0, FIRST_STEP, 0.0);
        let outside = loop {
            offset += step;
            step = (2.0 * step).min(LARGEST_STEP);
            let theta = self.theta0 + direction * offset;
            if direction * (theta - limit) >= 0.0 {
                if inside(limit) {
                    return End::Flat(limit);
                }
                break limit;
            }
            if !inside(theta) {
                break theta;
            }
            last_inside = theta;
        };
        let (a, b) = bisect(inside, last_inside, outside);
        End::Turn(0.5 * (a + b))
    }

    /// Classifies the motion and computes everything else.
    fn fill(&mut self, orbit: &mut Orbit) {
        let d = self.direction();
        let forward = self.end(d);
        // With ω_X0 = 0, θ₀ is itself the turning point behind.
        let backward = if self.omega_x0 == 0.0 {
            End::Turn(self.theta0)
        } else {
            self.end(-d)
        };
        self.anchor_at(forward, backward);
        let from_turns = self.omega_x0 == 0.0;
        let (legs, motion, error) = match (forward, backward) {
            (End::Flat(flat), _) => self.landing(&[Leg::new(self.theta0, flat, from_turns, false)]),
            (End::Turn(turn), End::Flat(flat)) => self.landing(&[
                Leg::new(self.theta0, turn, from_turns, true),
                Leg::new(turn, flat, true, false),
            ]),
            (End::Turn(a), End::Turn(b)) => self.periodic(a, b),
        };
        orbit.motion = motion;
        orbit.error = error;
        let ends = legs.iter().flat_map(|l| [l.from, l.to]);
        orbit.theta_min = ends.clone().fold(self.theta0, f64::min);
        orbit.theta_max = ends.fold(self.theta0, f64::max);
        self.extremes(orbit);
        orbit.lift_off = self.lift_off(&legs);
        let lean = orbit.theta_min.abs().max(orbit.theta_max.abs());
        orbit.error = orbit.error.max(self.underflow(lean));
    }

    /// The relative error that leaving the normal doubles brings to a motion leaning at most `lean`: U and
    /// S differ from their values at θ₀ by terms of order θ² times the energy scales (Mga, I g/a), which
    /// below the smallest normal double (2.2e-308) are subnormal, held to an absolute 4.9e-324 (θ below
    /// ~1e-154 at unit scales, 1e-104 with M = 1e-100): a few of those over the terms' size. The
    /// quadrature's own estimate did not see it: θ₀ = 1e-160 on straight rolling at ω_Z = 1 gave a
    /// turning point 1.2e-4 off (now estimated 2e-3), θ₀ = 1e-200 a period of 0 (now 1), each with an
    /// estimated error below 1e-10. At most 1: nothing of the result can be trusted.
    fn underflow(&self, lean: f64) -> f64 {
        let p = self.coin.params();
        let g_over_a = p.gravity() / p.radius();
        let scale = p
            .energy_scale()
            .min(p.inertia_x() * g_over_a)
            .min(p.inertia_z() * g_over_a)
            .min(1.0);
        (4.0 * f64::from_bits(1) / (lean * lean * scale)).min(1.0)
    }

    /// Records the turning points among the two ends, each with the reach of its integral form: at most
    /// [`SHORT_RANGE`], half the distance to the other end, and a tenth of its distance from flat.
    fn anchor_at(&mut self, forward: End, backward: End) {
        let (a, b) = match (forward, backward) {
            (End::Turn(a) | End::Flat(a), End::Turn(b) | End::Flat(b)) => (a, b),
        };
        for end in [forward, backward] {
            if let End::Turn(r) = end {
                let other = if r == a { b } else { a };
                let reach = SHORT_RANGE
                    .min(0.5 * (other - r).abs())
                    .min(0.1 * (FRAC_PI_2 - r.abs()));
                self.anchors.push((r, reach));
            }
        }
    }

    /// A motion that lands flat along `legs`.
    fn landing(&self, legs: &[Leg]) -> (Vec<Leg>, Motion, f64) {
        let (mut time, mut error) = (0.0, 0.0);
        for leg in legs {
            let (t, e) = self.travel(leg);
            time += t;
            error += e;
        }
        let theta = legs.last().map_or(self.theta0, |l| l.to);
        (
            legs.to_vec(),
            Motion::FlatLanding { theta, time },
            error / time,
        )
    }

    /// A periodic motion between the turning points `a` and `b` (any order).
    fn periodic(&self, a: f64, b: f64) -> (Vec<Leg>, Motion, f64) {
        let (lo, hi) = (a.min(b), a.max(b));
        let (period, precession, spin_advance, error) = self.period_integrals(lo, hi);
        // The path: from θ₀ on to the turning point ahead, then across to the other.
        let (ahead, behind) = if self.direction() > 0.0 {
            (hi, lo)
        } else {
            (lo, hi)
        };
        let legs = vec![
            Leg::new(self.theta0, ahead, self.omega_x0 == 0.0, true),
            Leg::new(ahead, behind, true, true),
        ];
        (
            legs,
            Motion::Periodic {
                period,
                precession,
                spin_advance,
            },
            error,
        )
    }

    /// (T, ΔΦ, ΔΨ, estimated relative error) over one period between the turning points lo < hi, by the
    /// midpoint rule in u with θ = lo + (hi − lo)(1 − cos u)/2 (see the module doc).
    fn period_integrals(&self, lo: f64, hi: f64) -> (f64, f64, f64, f64) {
        let width = hi - lo;
        // g → f′/(hi − lo) at the ends, f′ = −2S/(I_X + Ma²): the limit where rounding leaves f ≤ 0.
        let end_g = [lo, hi].map(|t| self.turn_slope(t) / width);
        let sums = |n: usize| {
            let (mut time, mut heading, mut spin, mut heading_scale, mut f_max) =
                (0.0, 0.0, 0.0, 0.0, 0.0_f64);
            for j in 0..n {
                #[allow(clippy::cast_precision_loss)]
                let u = PI * (j as f64 + 0.5) / n as f64;
                let (below, above) = (
                    width * (0.5 * u).sin().powi(2),
                    width * (0.5 * u).cos().powi(2),
                );
                let theta = if below <= above {
                    lo + below
                } else {
                    hi - above
                };
                let g = self.reduced_rate(theta, below, above);
                f_max = f_max.max(g * below * above);
                let g = if g > 0.0 {
                    g
                } else {
                    end_g[usize::from(below > above)]
                };
                let w = 1.0 / g.sqrt();
                let (wy, wz) = self.rates(theta);
                let (st, ct) = theta.sin_cos();
                let phi_dot = wy / ct;
                time += w;
                heading += w * phi_dot;
                heading_scale += w * phi_dot.abs();
                spin += w * (wz + wy * st / ct);
            }
            #[allow(clippy::cast_precision_loss)]
            let step = 2.0 * PI / n as f64;
            (
                time * step,
                heading * step,
                spin * step,
                heading_scale * step,
                f_max,
            )
        };
        let mut n = FIRST_NODES;
        let mut previous = sums(n);
        let mut previous_change = f64::INFINITY;
        loop {
            n *= 2;
            let next = sums(n);
            let change_t = (next.0 - previous.0).abs() / next.0;
            let change_phi = (next.1 - previous.1).abs() / next.3.max(f64::MIN_POSITIVE);
            let change = change_t.max(change_phi);
            // Geometric convergence shrinks the change by orders of magnitude per doubling; a change that
            // no longer shrinks fourfold below NOISE_FLOOR is the rounding noise of θ̇².
            let noisy = change <= NOISE_FLOOR && change > 0.25 * previous_change;
            previous_change = change;
            let converged = change <= CONVERGED || noisy;
            if converged || n >= MOST_NODES {
                let rounding = self.rounding(lo, hi, next.4);
                return (next.0, next.1, next.2, change.max(rounding));
            }
            previous = next;
        }
    }

    /// Relative rounding error of θ̇² at the scale of its largest value `f_max` on [lo, hi]: a few ulp of
    /// the terms of U where U(θ) − U(θ₀) is a difference, of the terms of S times the distance where it
    /// is an integral (module doc); the period inherits about half of it.
    fn rounding(&self, lo: f64, hi: f64, f_max: f64) -> f64 {
        let mid = 0.5 * (lo + hi);
        let (wy, wz) = self.rates(mid);
        // The terms of U, Mga cos θ at its largest.
        let u_terms = self.potential((wy, wz), 1.0);
        let reach = (hi - self.theta0).abs().max((lo - self.theta0).abs());
        let (_, s_terms) = steady_residual(self.coin, mid, wy, wz);
        let du = if reach <= self.short {
            s_terms * reach
        } else {
            u_terms
        };
        16.0 * f64::EPSILON * 2.0 * du / self.lever / f_max.max(f64::MIN_POSITIVE)
    }

    /// ∫dθ/|θ̇| along `leg` and its error bound.
    fn travel(&self, leg: &Leg) -> (f64, f64) {
        match (leg.from_turns, leg.to_turns) {
            (true, true) => {
                let mid = 0.5 * (leg.from + leg.to);
                let (a, ea) = self.leaving_turning_point(leg.from, mid);
                let (b, eb) = self.leaving_turning_point(leg.to, mid);
                (a + b, ea + eb)
            }
            (true, false) => self.leaving_turning_point(leg.from, leg.to),
            (false, true) => self.leaving_turning_point(leg.to, leg.from),
            (false, false) => self.between(leg.from, leg.to),
        }
    }

    /// ∫dθ/|θ̇| between `a` and `b` (either order, θ̇ ≠ 0 on the way) and its error bound.
    fn between(&self, a: f64, b: f64) -> (f64, f64) {
        let f = |theta: f64| 1.0 / self.theta_dot_squared(theta).max(0.0).sqrt();
        let r = self.adaptive.integrate(&f, a.min(b), a.max(b), TRAVEL_RTOL);
        (r.value, r.error)
    }

    /// ∫dθ/|θ̇| from the turning point `turn` to `other` (where θ̇ ≠ 0): the escape from near upright
    /// when that applies ([`Self::escape`]), otherwise [`Self::leaving_by_quadrature`].
    fn leaving_turning_point(&self, turn: f64, other: f64) -> (f64, f64) {
        self.escape(turn, other)
            .unwrap_or_else(|| self.leaving_by_quadrature(turn, other))
    }

    /// The escape from a turning point `turn` close to upright (|turn| ≤ [`MATCHING`]/64) out past the
    /// matching angle θ_m = turn ± [`MATCHING`], eq (41) of physics §12, with θ̇² = x g(x),
    /// g = p + q x + O(x²), x = |θ − turn|; Richardson from halving x_m. `None` where it does not apply
    /// (the quadrature in v resolves the singularity there: at θ₀ = 1e-5 within 2e-16 of the ln law).
    fn escape(&self, turn: f64, other: f64) -> Option<(f64, f64)> {
        let (span, direction) = ((other - turn).abs(), (other - turn).signum());
        if turn.abs() > MATCHING / 64.0 || span <= 2.0 * MATCHING {
            return None;
        }
        let p = self.turn_slope(turn);
        let g = |x: f64| self.theta_dot_squared(turn + direction * x) / x;
        // q = g′(0) by Richardson from the secants at two small x: the O(x) and O(x²) terms of the
        // secant cancel to O(x₁x₂) ~ 1e-13 relative; rounding of g − p adds ~1e-15 (1 + p/(q x)).
        let secant = |x: f64| (g(x) - p) / x;
        let (x1, x2) = (MATCHING / 512.0, MATCHING / 1024.0);
        let q = 2.0 * secant(x2) - secant(x1);
        if !(p > 0.0 && q > 0.0) {
            return None;
        }
        // asinh(z) = ln(2z) to rounding for z² > 1e30, and q x/p overflows for a subnormal turn.
        let linear = |x: f64| {
            let z2 = q * x / p;
            let asinh = if z2 < 1e30 {
                z2.sqrt().asinh()
            } else {
                0.5 * ((4.0 * q * x).ln() - p.ln())
            };
            2.0 / q.sqrt() * asinh
        };
        let time_from = |x: f64| {
            let (t, e) = self.between(turn + direction * x, other);
            (linear(x) + t, e)
        };
        let (t, e) = time_from(MATCHING);
        let (t_half, e_half) = time_from(0.5 * MATCHING);
        // p to a few ulp, or to the smallest subnormal (2/(I_X + Ma²) 2^-1074 absolute) below 2.2e-308.
        let p_error = (4.0 * f64::EPSILON).max(2.0 * f64::from_bits(1) / self.lever / p);
        let rounding =
            64.0 * f64::EPSILON * (1.0 + p / (q * x2)) * linear(MATCHING) + p_error / q.sqrt();
        // Richardson on the O(x_m²) term; were it O(x_m) (an upright without symmetry), 2|t − t_half|
        // still bounds what is left.
        let extrapolated = t_half + (t_half - t) / 3.0;
        Some((
            extrapolated,
            e + e_half + 2.0 * (t - t_half).abs() + rounding,
        ))
    }

    /// ∫dθ/|θ̇| from the turning point `turn` to `other` (where θ̇ ≠ 0), with θ = turn + (other − turn) v².
    fn leaving_by_quadrature(&self, turn: f64, other: f64) -> (f64, f64) {
        let span = other - turn;
        if span == 0.0 {
            return (0.0, 0.0);
        }
        let slope = self.turn_slope(turn);
        let f = |v: f64| {
            let theta = turn + span * v * v;
            // Near the turning point f = −2 span v² mean(S)/(I_X + Ma²): the factor v² cancels.
            let per_v2 = match self.anchor(theta) {
                Some(r) if r == turn => -2.0 * span * self.mean_slope(turn, theta) / self.lever,
                _ => self.theta_dot_squared(theta) / (v * v),
            };
            if per_v2 > 0.0 {
                2.0 * span.abs() / per_v2.sqrt()
            } else {
                // Rounding at the turning point: f ≈ f′(turn)(θ − turn) there.
                2.0 * (span.abs() / slope).sqrt()
            }
        };
        let r = self.adaptive.integrate(&f, 0.0, 1.0, TRAVEL_RTOL);
        (r.value, r.error)
    }

    /// The smallest N and the largest |F|/N over [θ_min, θ_max].
    fn extremes(&self, orbit: &mut Orbit) {
        orbit.min_normal = extreme(orbit.theta_min, orbit.theta_max, |t| -self.normal(t));
        orbit.min_normal.value = -orbit.min_normal.value;
        orbit.max_friction_ratio = (orbit.min_normal.value > 0.0).then(|| {
            extreme(orbit.theta_min, orbit.theta_max, |t| {
                let r = reaction(self.coin, &self.state(t));
                r.friction / r.normal
            })
        });
    }

    /// The first place along `legs` where N reaches 0, and when.
    fn lift_off(&self, legs: &[Leg]) -> Option<Event> {
        if self.normal(self.theta0) <= 0.0 {
            return Some(Event {
                theta: self.theta0,
                time: 0.0,
            });
        }
        let mut elapsed = 0.0;
        for leg in legs {
            let scan = EXTREME_SCAN - 1;
            let mut previous = leg.from;
            for j in 1..=scan {
                #[allow(clippy::cast_precision_loss)]
                let theta = leg.from + (leg.to - leg.from) * j as f64 / scan as f64;
                if self.normal(theta) <= 0.0 {
                    let (_, at) = bisect(|t| self.normal(t) > 0.0, previous, theta);
                    let part = Leg {
                        to: at,
                        to_turns: false,
                        ..*leg
                    };
                    return Some(Event {
                        theta: at,
                        time: elapsed + self.travel(&part).0,
                    });
                }
                previous = theta;
            }
            elapsed += self.travel(leg).0;
        }
        None
    }
}

/// The largest value of `h` on [lo, hi] and where: the best of [`EXTREME_SCAN`] points (denser towards
/// the ends), refined by golden-section search between its neighbours.
fn extreme(lo: f64, hi: f64, h: impl Fn(f64) -> f64) -> Extremum {
    if hi <= lo {
        return Extremum {
            value: h(lo),
            theta: lo,
        };
    }
    let at = |j: usize| {
        #[allow(clippy::cast_precision_loss)]
        let u = PI * j as f64 / (EXTREME_SCAN - 1) as f64;
        lo + (hi - lo) * 0.5 * (1.0 - u.cos())
    };
    let (mut best, mut best_value) = (0, f64::NEG_INFINITY);
    for j in 0..EXTREME_SCAN {
        let v = h(at(j));
        if v > best_value || v.is_nan() {
            best = j;
            best_value = v;
        }
    }
    let (mut a, mut b) = (
        at(best.saturating_sub(1)),
        at((best + 1).min(EXTREME_SCAN - 1)),
    );
    // Golden section; the ends count, so an extreme at lo or hi is found too.
    let ratio = 0.5 * (5.0_f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (b - ratio * (b - a), a + ratio * (b - a));
    let (mut h1, mut h2) = (h(x1), h(x2));
    for _ in 0..200 {
        if b - a <= 4.0 * f64::EPSILON * (a.abs() + b.abs()) {
            break;
        }
        if h1 >= h2 {
            b = x2;
            x2 = x1;
            h2 = h1;
            x1 = b - ratio * (b - a);
            h1 = h(x1);
        } else {
            a = x1;
            x1 = x2;
            h1 = h2;
            x2 = a + ratio * (b - a);
            h2 = h(x2);
        }
    }
    let mut m = Extremum {
        value: f64::NEG_INFINITY,
        theta: lo,
    };
    for (value, theta) in [
        (best_value, at(best)),
        (h1, x1),
        (h2, x2),
        (h(lo), lo),
        (h(hi), hi),
    ] {
        if value > m.value {
            m = Extremum { value, theta };
        }
    }
    m
}
