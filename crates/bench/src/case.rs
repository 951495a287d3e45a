//! What a benchmark runs (a coin, an initial state, a duration), how a run is sampled, the references it
//! is judged against, and the error measures and the median shared by the benches.

use super::BenchError;
use coin_log::analyse::steady_path::steady_state_at;
use coin_log::integrate::{Flow, Method, MethodConfig, RunEnd, RunOutcome, RunSettings};
use coin_log::model::drift::{EnergyDrift, InvariantDrift};
use coin_log::model::{energy, Chaplygin, Coin, Dissipation, Dynamics, State, Steady, STATE_LEN};
use coin_log::scene::defaults;
use coin_log::simulation::{run_dynamics, CoinEvents};

/// Samples per natural time unit √(a/g) at which errors are measured ("100 per time unit").
pub const SAMPLES_PER_TIME_UNIT: f64 = 100.0;

/// Flat-landing margin of the bench runs: the contract's scene default (`run.flat_margin`).
pub const DEFAULT_FLAT_MARGIN: f64 = defaults::FLAT_MARGIN;

/// Reference tolerances: dop853 at atol 1e-16, rtol 1e-14.
const REFERENCE_ATOL: f64 = 1e-16;
/// See [`REFERENCE_ATOL`].
const REFERENCE_RTOL: f64 = 1e-14;

/// One benchmark scene: the body, where it starts, how long it runs and what ends it.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchCase {
    /// Scene name (kebab-case).
    pub name: String,
    /// The body and its equations.
    pub coin: Coin,
    /// State at t = 0.
    pub initial: State,
    /// The steady motion the scene starts on, when it is unperturbed: then the analytic trajectory is the
    /// reference. `None` for every other scene (the reference is then a tight dop853 run).
    pub steady: Option<Steady>,
    /// Duration \[time\].
    pub duration: f64,
    /// The run ends at |θ| ≥ π/2 − `flat_margin` \[rad\].
    pub flat_margin: f64,
    /// Friction coefficient μ; with it the run ends at a slip.
    pub friction: Option<f64>,
    /// A dissipative couple (physics §11): the run then integrates W with the state, and the energy
    /// error is that of the balance E + W.
    pub dissipation: Option<Dissipation>,
}

impl BenchCase {
    /// A case of the conservative `coin` from `initial` for `duration`: no steady reference, no friction
    /// limit, the default flat margin.
    #[must_use]
    pub fn conservative(name: &str, coin: Coin, initial: State, duration: f64) -> Self {
        Self {
            name: name.to_string(),
            coin,
            initial,
            steady: None,
            duration,
            flat_margin: DEFAULT_FLAT_MARGIN,
            friction: None,
            dissipation: None,
        }
    }

    /// The natural time unit √(a/g) \[time\].
    #[must_use]
    pub fn time_unit(&self) -> f64 {
        self.coin.params().time_unit()
    }

    /// The sample grid of the error measures: 100 samples per natural time unit.
    #[must_use]
    pub fn settings(&self) -> RunSettings {
        RunSettings {
            t0: 0.0,
            t_end: self.duration,
            sample_interval: self.time_unit() / SAMPLES_PER_TIME_UNIT,
        }
    }

    /// The physical events of the case (conservative dynamics; a dissipative run builds its own).
    #[must_use]
    pub fn events(&self) -> CoinEvents {
        CoinEvents::new(self.coin, self.flat_margin, self.friction)
    }

    /// The equations of the case: the coin, with its dissipation if any.
    #[must_use]
    pub fn dynamics(&self) -> Dynamics {
        Dynamics::new(self.coin, self.dissipation)
    }
}

/// The contract's default settings of a method, the step scaled to the case's time unit.
#[must_use]
pub fn default_config(method: Method, time_unit: f64) -> MethodConfig {
    MethodConfig {
        method,
        rtol: defaults::RTOL,
        atol: defaults::ATOL,
        // The scene default step, read in natural time units.
        step: defaults::STEP * time_unit,
    }
}

/// The samples of one run and how it ended. Buffers are reused between runs so that timed repeats do not
/// allocate.
#[derive(Debug, Clone, Default)]
pub struct Trajectory {
    /// Sample times.
    pub times: Vec<f64>,
    /// States at the sample times.
    pub states: Vec<[f64; STATE_LEN]>,
    /// The dissipated work W at the sample times (dissipative runs; empty otherwise).
    pub work: Vec<f64>,
    /// How the run ended; `None` before the first run.
    pub outcome: Option<RunOutcome>,
}

impl Trajectory {
    /// An empty trajectory with room for `samples` samples.
    #[must_use]
    pub fn with_capacity(samples: usize) -> Self {
        Self {
            times: Vec::with_capacity(samples),
            states: Vec::with_capacity(samples),
            work: Vec::new(),
            outcome: None,
        }
    }

    /// The termination as the contract names it (`completed`, `flat-landing`, `lift-off`, `slip`,
    /// `step-size-underflow`, `non-finite`; `newton-failure` for the implicit methods).
    #[must_use]
    pub fn termination_name(&self) -> String {
        self.outcome.as_ref().map_or_else(
            || "not-run".to_string(),
            |o| termination_name(&o.termination),
        )
    }

    /// True when the run reached its end time.
    #[must_use]
    pub fn completed(&self) -> bool {
        matches!(
            self.outcome.as_ref().map(|o| &o.termination),
            Some(RunEnd::Completed)
        )
    }
}

/// The format's name of a termination.
#[must_use]
pub fn termination_name(termination: &RunEnd) -> String {
    coin_log::format::Termination::of_run(termination).to_string()
}

/// Runs `config` on `case`, storing every sample in `out` (cleared first).
pub fn run_sampled(config: &MethodConfig, case: &BenchCase, out: &mut Trajectory) {
    run_sampled_with(config, case, &case.settings(), out);
}

/// Like [`run_sampled`] with explicit run settings.
pub fn run_sampled_with(
    config: &MethodConfig,
    case: &BenchCase,
    settings: &RunSettings,
    out: &mut Trajectory,
) {
    out.times.clear();
    out.states.clear();
    out.work.clear();
    let (times, states, work) = (&mut out.times, &mut out.states, &mut out.work);
    let outcome = run_dynamics(
        config,
        &case.dynamics(),
        &case.initial,
        settings,
        &coin_log::integrate::Bounds::default(),
        case.flat_margin,
        case.friction,
        |t, y, w| {
            times.push(t);
            states.push(*y);
            if let Some(w) = w {
                work.push(w);
            }
            Flow::Continue
        },
    );
    out.outcome = Some(outcome);
}

/// Which reference a case's errors are measured against.
#[derive(Debug, Clone, PartialEq)]
pub enum ReferenceKind {
    /// The analytic steady trajectory (θ, ω constant, φ = φ̇t, ψ = ψ̇t, centre on its circle).
    Analytic,
    /// A tight numerical run.
    Numerical(MethodConfig),
}

impl std::fmt::Display for ReferenceKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Analytic => f.write_str("analytic steady trajectory"),
            Self::Numerical(c) if c.method.is_adaptive() => {
                write!(f, "{} at atol {:e}, rtol {:e}", c.method, c.atol, c.rtol)
            }
            Self::Numerical(c) => write!(f, "{} at step {:e}", c.method, c.step),
        }
    }
}

/// The trajectory errors are measured against.
#[derive(Debug, Clone)]
pub enum Reference {
    /// The analytic steady motion from the case's initial state.
    Analytic {
        /// The steady motion.
        steady: Steady,
        /// Its state at t = 0 (φ₀, ψ₀, x₀, z₀ may be non-zero).
        start: State,
    },
    /// A tight numerical run on the same sample grid.
    Numerical {
        /// How it was computed.
        config: MethodConfig,
        /// Its samples.
        trajectory: Trajectory,
    },
}

impl Reference {
    /// Which reference this is.
    #[must_use]
    pub fn kind(&self) -> ReferenceKind {
        match self {
            Self::Analytic { .. } => ReferenceKind::Analytic,
            Self::Numerical { config, .. } => ReferenceKind::Numerical(*config),
        }
    }

    /// The reference state at sample `index`, time `t`.
    #[must_use]
    pub fn state_at(&self, coin: &Coin, index: usize, t: f64) -> Option<[f64; STATE_LEN]> {
        match self {
            Self::Analytic { steady, start } => {
                Some(steady_state_at(coin, steady, start, t).to_array())
            }
            Self::Numerical { trajectory, .. } => trajectory.states.get(index).copied(),
        }
    }
}

/// The reference of a case: analytic when the case is an unperturbed steady motion, otherwise dop853 at
/// atol 1e-16, rtol 1e-14.
///
/// # Errors
/// [`BenchError::ReferenceFailed`] when the numerical reference does not reach the end of the case.
pub fn reference_trajectory(case: &BenchCase) -> Result<Reference, BenchError> {
    reference_trajectory_with(case, &case.settings())
}

/// Like [`reference_trajectory`] on the sample grid of `settings`.
///
/// # Errors
/// As [`reference_trajectory`].
pub fn reference_trajectory_with(
    case: &BenchCase,
    settings: &RunSettings,
) -> Result<Reference, BenchError> {
    if let Some(steady) = case.steady {
        return Ok(Reference::Analytic {
            steady,
            start: case.initial,
        });
    }
    let config = MethodConfig {
        method: Method::Dop853,
        rtol: REFERENCE_RTOL,
        atol: REFERENCE_ATOL,
        step: 0.0,
    };
    let mut trajectory = Trajectory::default();
    run_sampled_with(&config, case, settings, &mut trajectory);
    if !trajectory.completed() && trajectory.outcome.is_some() {
        // An event ends the reference and the runs alike: judge the common samples.
        if !matches!(
            trajectory.outcome.as_ref().map(|o| &o.termination),
            Some(RunEnd::Event { .. })
        ) {
            return Err(BenchError::ReferenceFailed {
                scene: case.name.clone(),
                reference: ReferenceKind::Numerical(config).to_string(),
                termination: trajectory.termination_name(),
            });
        }
    }
    Ok(Reference::Numerical { config, trajectory })
}

/// The factors that make a state dimensionless: angles as they are, ω·T (T = √(a/g)), x/a, z/a.
#[must_use]
pub fn natural_scales(coin: &Coin) -> [f64; STATE_LEN] {
    let p = coin.params();
    let (t_unit, a) = (p.time_unit(), p.radius());
    [1.0, 1.0, 1.0, t_unit, t_unit, t_unit, 1.0 / a, 1.0 / a]
}

/// The dimensionless difference of two states: the largest of |Δθ|, |Δφ|, |Δψ|, |Δω_i|·T (T = √(a/g)),
/// |Δx|/a, |Δz|/a ([`natural_scales`]).
#[must_use]
pub fn state_difference(coin: &Coin, y: &[f64; STATE_LEN], r: &[f64; STATE_LEN]) -> f64 {
    let scale = natural_scales(coin);
    let mut worst = 0.0_f64;
    for i in 0..STATE_LEN {
        let d = (y[i] - r[i]).abs() * scale[i];
        if d.is_nan() {
            return f64::INFINITY;
        }
        worst = worst.max(d);
    }
    worst
}

/// State error of a run: the largest [`state_difference`] over the samples, against the
/// reference on the same grid. Infinite when the run stopped before the reference did (or vice versa):
/// a run that ends early is not accurate.
#[must_use]
pub fn state_error(case: &BenchCase, run: &Trajectory, reference: &Reference) -> f64 {
    if let Reference::Numerical { trajectory, .. } = reference {
        if trajectory.states.len() != run.states.len() {
            return f64::INFINITY;
        }
    } else if !run.completed() {
        return f64::INFINITY;
    }
    let mut worst = 0.0_f64;
    for (i, (t, y)) in run.times.iter().zip(&run.states).enumerate() {
        match reference.state_at(&case.coin, i, *t) {
            Some(r) => worst = worst.max(state_difference(&case.coin, y, &r)),
            None => return f64::INFINITY,
        }
    }
    worst
}

/// Energy drift ([`EnergyDrift`]) over the samples.
#[must_use]
pub fn energy_drift(coin: &Coin, states: &[[f64; STATE_LEN]]) -> f64 {
    let Some(first) = states.first() else {
        return 0.0;
    };
    let mut drift = EnergyDrift::new(coin.params(), energy(coin, &State::from_array(first)).total);
    for y in states {
        drift.observe(0.0, energy(coin, &State::from_array(y)).total);
    }
    drift.value()
}

/// Drift of the energy balance E + W over the samples of a dissipative run (physics §11), defined as the
/// energy drift ([`EnergyDrift`]) with E + W in place of E; the plain energy drift when `work` is empty.
#[must_use]
pub fn balance_drift(coin: &Coin, states: &[[f64; STATE_LEN]], work: &[f64]) -> f64 {
    if work.is_empty() {
        return energy_drift(coin, states);
    }
    let balance = |y: &[f64; STATE_LEN], w: f64| energy(coin, &State::from_array(y)).total + w;
    let Some((first, w0)) = states.first().zip(work.first()) else {
        return 0.0;
    };
    let mut drift = EnergyDrift::new(coin.params(), balance(first, *w0));
    for (y, w) in states.iter().zip(work) {
        drift.observe(0.0, balance(y, *w));
    }
    drift.value()
}

/// Invariant drift ([`InvariantDrift`]) over the samples and both Chaplygin–Appell integrals (physics §6);
/// `None` when they cannot be evaluated for the body.
#[must_use]
pub fn invariant_drift(coin: &Coin, states: &[[f64; STATE_LEN]]) -> Option<f64> {
    let chaplygin = Chaplygin::new(coin.params()).ok()?;
    let first = chaplygin.of_state(&State::from_array(states.first()?));
    let mut drift = InvariantDrift::new(coin.params(), first.c1, first.c2);
    for y in states {
        let c = chaplygin.of_state(&State::from_array(y));
        drift.observe(0.0, c.c1, c.c2);
    }
    Some(drift.value())
}

/// The median of `values` (the mean of the middle two for an even count); NaN when empty.
#[must_use]
pub fn median(values: &[f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::median;

    #[test]
    fn medians_of_odd_and_even_counts() {
        assert!((median(&[3.0, 1.0, 2.0]) - 2.0).abs() < 1e-15);
        assert!((median(&[4.0, 1.0, 2.0, 3.0]) - 2.5).abs() < 1e-15);
        assert!(median(&[]).is_nan());
    }
}
