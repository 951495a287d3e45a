//! The integration loop: steps a [`Stepper`], emits samples on an exact time grid by dense output, and
//! ends at the first event, located by root finding on the dense output.

use super::{OdeSystem, Stats, StepError, Stepper};
use std::sync::atomic::{AtomicBool, Ordering};

/// Largest number of event functions a system may declare.
const MAX_EVENTS: usize = 8;

/// Event time resolution (relative to max(1, |t|)): a few dozen cheap interpolations per event.
const EVENT_TIME_TOLERANCE: f64 = 1e-13;

/// Points inside each step at which the event functions are also evaluated, so that one that dips to 0
/// and back within a step is not missed (N < 0 for 0.10 time units inside one dop853 step of 0.17 went
/// unseen without them). Three catch a dip longer than a quarter of the step.
const EVENT_PROBES: usize = 3;

/// How near 0, in steps' worth of its change, an event function must end a step to be probed inside it
/// (`dip_in_step`). 1 missed a dip at rtol 1e-3 on `lift-off`; 4 cost 15 % on a run with few samples;
/// 2 is within noise.
const PROBE_REACH: f64 = 2.0;

/// Grid samples within this time before an event are dropped in favour of the sample at the event, so
/// that no two samples round to the same nanosecond (format.md: log_time = round(t·10⁹), strictly
/// increasing per channel).
const EVENT_SAMPLE_GAP: f64 = 2e-9;

/// Scalar functions g_i(t, y) whose crossing from > 0 to ≤ 0 ends a run (flat landing, lift-off, ...).
pub trait EventFunctions<const N: usize> {
    /// Number of functions (at most `MAX_EVENTS` = 8).
    fn count(&self) -> usize;
    /// Writes g_i(t, y) into `out[..count]`.
    fn evaluate(&self, t: f64, y: &[f64; N], out: &mut [f64]);
}

/// No events.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoEvents;

impl<const N: usize> EventFunctions<N> for NoEvents {
    fn count(&self) -> usize {
        0
    }
    fn evaluate(&self, _t: f64, _y: &[f64; N], _out: &mut [f64]) {}
}

/// What the sample observer wants next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flow {
    /// Go on.
    Continue,
    /// Stop after this sample (e.g. the user pressed Ctrl-C).
    Stop,
}

/// Time span and sampling of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunSettings {
    /// Start time.
    pub t0: f64,
    /// End time (> t0).
    pub t_end: f64,
    /// Distance between samples; samples fall on t0 + k·interval and on t_end.
    pub sample_interval: f64,
}

/// Bounds on the work of a run beyond its time span, checked after every accepted step (one relaxed load
/// and one comparison: nothing beside a step's stages), so that a stop is seen within one step however far
/// apart the samples are, and no run takes more steps than it was given.
#[derive(Debug, Clone, Copy, Default)]
pub struct Bounds<'a> {
    /// Most accepted steps; the run fails with [`StepError::BudgetSpent`] instead of taking one more.
    pub max_steps: Option<u64>,
    /// Raised (by a signal handler, on another thread) to stop the run: it then ends as
    /// [`RunEnd::Stopped`] at its last sample, as when the observer returns [`Flow::Stop`].
    pub stop: Option<&'a AtomicBool>,
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
#[allow(missing_docs, reason = "each variant's doc names its fields")]
pub enum RunEnd {
    /// Reached t_end.
    Completed,
    /// Event function `index` crossed zero at the located time `t`; the last sample is at `t`.
    Event { index: usize, t: f64 },
    /// Stopped (by the observer or the stop flag) at `t`, the time of the last sample.
    Stopped { t: f64 },
    /// A numerical failure; samples up to the last good step were emitted.
    Failed(StepError),
}

/// Result of [`run`].
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutcome {
    /// Why it ended.
    pub termination: RunEnd,
    /// Work done.
    pub stats: Stats,
    /// Time of the last sample.
    pub t_last: f64,
}

/// Sample time number `k`: t0 + k·interval, computed afresh (never accumulated) so the grid does not drift.
#[inline]
#[allow(clippy::cast_precision_loss)]
fn sample_time(t0: f64, interval: f64, k: u64) -> f64 {
    t0 + k as f64 * interval
}

/// How close to t_end a grid point is taken for t_end itself: the grid t0 + k·interval rarely hits t_end
/// exactly, and a point within [`EVENT_SAMPLE_GAP`] of it would share its log time.
fn grid_slack(interval: f64) -> f64 {
    (1e-9 * interval).max(EVENT_SAMPLE_GAP)
}

/// The samples a run from `t0` that reaches `t_end` writes at `interval` (what [`run`] calls `observe`
/// with): t0, the grid points t0 + k·interval (k ≥ 1) more than the slack before t_end, and t_end.
#[must_use]
#[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
pub fn samples_to_end(t0: f64, t_end: f64, interval: f64) -> u64 {
    let limit = t_end - grid_slack(interval);
    let at = |k| sample_time(t0, interval, k);
    // The grid points k ≥ 1 at or before `limit`: the quotient's floor, corrected for its rounding.
    let mut k = ((limit - t0) / interval).floor().max(0.0) as u64;
    while k > 0 && at(k) > limit {
        k -= 1;
    }
    while at(k + 1) <= limit {
        k += 1;
    }
    k + 2
}

/// Integrates `sys` from `y0`, calling `observe(t, y)` at every sample time, until t_end, an event, a
/// failure, `observe` returns [`Flow::Stop`], the step budget is spent or the stop flag is raised.
pub fn run<const N: usize, S, M, E, O>(
    sys: &S,
    stepper: &mut M,
    y0: &[f64; N],
    settings: &RunSettings,
    bounds: &Bounds<'_>,
    events: &E,
    observe: O,
) -> RunOutcome
where
    S: OdeSystem<N>,
    M: Stepper<N>,
    E: EventFunctions<N>,
    O: FnMut(f64, &[f64; N]) -> Flow,
{
    let mut run = Run {
        sys,
        stepper,
        settings,
        bounds: *bounds,
        events,
        observe,
        n_events: events.count().min(MAX_EVENTS),
        g_old: [0.0; MAX_EVENTS],
        g_new: [0.0; MAX_EVENTS],
        g_change: [f64::INFINITY; MAX_EVENTS],
        k: 1,
        t_last: settings.t0,
        buffer: [0.0; N],
        dense_ready: false,
    };
    let termination = run.start(y0).err().unwrap_or_else(|| run.steps());
    RunOutcome {
        termination,
        stats: run.stepper.state().stats,
        t_last: run.t_last,
    }
}

/// The state of one [`run`] between its stages.
struct Run<'a, const N: usize, S, M, E, O> {
    sys: &'a S,
    stepper: &'a mut M,
    settings: &'a RunSettings,
    bounds: Bounds<'a>,
    events: &'a E,
    observe: O,
    n_events: usize,
    /// Event functions at the start and at the end of the current step.
    g_old: [f64; MAX_EVENTS],
    g_new: [f64; MAX_EVENTS],
    /// |Δg| over the previous step (infinite before the first): how far g moves in a step.
    g_change: [f64; MAX_EVENTS],
    /// Number of the next grid sample.
    k: u64,
    /// Time of the last sample emitted.
    t_last: f64,
    buffer: [f64; N],
    /// Whether the dense output of the current step is ready.
    dense_ready: bool,
}

impl<const N: usize, S, M, E, O> Run<'_, N, S, M, E, O>
where
    S: OdeSystem<N>,
    M: Stepper<N>,
    E: EventFunctions<N>,
    O: FnMut(f64, &[f64; N]) -> Flow,
{
    /// Initialises the stepper and emits the first sample; `Err` holds the termination when the run ends
    /// right there (failure, an event already true at t0, or a stop).
    fn start(&mut self, y0: &[f64; N]) -> Result<(), RunEnd> {
        let t0 = self.settings.t0;
        self.stepper
            .init(self.sys, t0, y0, self.settings.t_end)
            .map_err(RunEnd::Failed)?;
        let flow = (self.observe)(t0, y0);
        let n = self.n_events;
        self.events.evaluate(t0, y0, &mut self.g_old[..n]);
        if let Some(index) = self.g_old[..n].iter().position(|&g| g <= 0.0) {
            return Err(RunEnd::Event { index, t: t0 });
        }
        if flow == Flow::Stop {
            return Err(RunEnd::Stopped { t: t0 });
        }
        Ok(())
    }

    /// Steps until the run ends; returns how it ended.
    fn steps(&mut self) -> RunEnd {
        loop {
            if let Some(end) = self.out_of_bounds() {
                return end;
            }
            if let Err(e) = self.stepper.step(self.sys, self.settings.t_end) {
                return RunEnd::Failed(e);
            }
            self.dense_ready = false;
            let t_new = self.stepper.state().t;
            let event = self.event_in_step(t_new);
            if let Some(end) = self.samples_up_to(t_new, event) {
                return end;
            }
            if let Some((index, t)) = event {
                self.sample_event(t);
                return RunEnd::Event { index, t };
            }
            if t_new >= self.settings.t_end {
                // Unreachable in practice (the grid loop emits t_end); kept so t_end is always sampled.
                if self.t_last < self.settings.t_end {
                    let _ = (self.observe)(self.settings.t_end, &self.stepper.state().y);
                    self.t_last = self.settings.t_end;
                }
                return RunEnd::Completed;
            }
            let n = self.n_events;
            for i in 0..n {
                self.g_change[i] = (self.g_new[i] - self.g_old[i]).abs();
            }
            self.g_old[..n].copy_from_slice(&self.g_new[..n]);
        }
    }

    /// How the run ends before its next step, if the stop flag is up or the step budget is spent.
    #[inline]
    fn out_of_bounds(&self) -> Option<RunEnd> {
        if self.bounds.stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            return Some(RunEnd::Stopped { t: self.t_last });
        }
        let state = self.stepper.state();
        match self.bounds.max_steps {
            Some(max) if state.stats.steps >= max => Some(RunEnd::Failed(StepError::BudgetSpent {
                t: state.t,
                steps: state.stats.steps,
            })),
            _ => None,
        }
    }

    fn prepare_dense(&mut self) {
        if !self.dense_ready {
            self.stepper.prepare_interpolation(self.sys);
            self.dense_ready = true;
        }
    }

    /// The earliest event crossing in the last step, located on the dense output: (index, time).
    fn event_in_step(&mut self, t_new: f64) -> Option<(usize, f64)> {
        let n = self.n_events;
        self.events
            .evaluate(t_new, &self.stepper.state().y, &mut self.g_new[..n]);
        let (t_old, mut event): (f64, Option<(usize, f64)>) = (self.stepper.state().t_prev, None);
        for i in 0..n {
            if self.g_old[i] > 0.0 && self.g_new[i] <= 0.0 {
                self.prepare_dense();
                let t_root = locate(&*self.stepper, self.events, i, n, (t_old, t_new));
                if event.is_none_or(|(_, t)| t_root < t) {
                    event = Some((i, t_root));
                }
            }
        }
        if let Some(dip) = self.dip_in_step(t_old, t_new) {
            if event.is_none_or(|(_, t)| dip.1 < t) {
                event = Some(dip);
            }
        }
        event
    }

    /// The earliest crossing of an event function that is positive at both ends of the last step but
    /// not throughout: looked for at [`EVENT_PROBES`] points inside the step, then located between the
    /// probes around it. Only functions that end the step near 0 against how far they move in a step
    /// are probed: a parabola dipping below 0 between two ends at m > 0 moved by more than 8m in the
    /// step before (of the same length), so min(g_old, g_new) ≤ [`PROBE_REACH`] · max(|Δg| now, |Δg|
    /// in the step before) selects every such dip with room to spare, and leaves out the steps of a
    /// rolling coin far from every event (probing every step cost 20 %).
    fn dip_in_step(&mut self, t_old: f64, t_new: f64) -> Option<(usize, f64)> {
        let n = self.n_events;
        let mut near = [false; MAX_EVENTS];
        for (i, near) in near.iter_mut().enumerate().take(n) {
            let (g0, g1) = (self.g_old[i], self.g_new[i]);
            *near = g0 > 0.0
                && g1 > 0.0
                && g0.min(g1) <= PROBE_REACH * (g1 - g0).abs().max(self.g_change[i]);
        }
        if !near[..n].contains(&true) {
            return None;
        }
        let mut lo = t_old;
        let mut g = [0.0; MAX_EVENTS];
        for j in 1..=EVENT_PROBES {
            #[allow(clippy::cast_precision_loss)] // j ≤ EVENT_PROBES
            let t = t_old + (t_new - t_old) * (j as f64 / (EVENT_PROBES + 1) as f64);
            // Probed on the dense output as it stands: for dop853 in a step without samples, its cubic
            // part, so that a step costs no extra stages (and a run's counts stay those of a run without
            // probes). A dip seen there is confirmed on the full dense output.
            self.stepper.interpolate(t, &mut self.buffer);
            self.events.evaluate(t, &self.buffer, &mut g[..n]);
            if !self.dense_ready && (0..n).any(|i| near[i] && g[i] <= 0.0) {
                self.prepare_dense();
                self.stepper.interpolate(t, &mut self.buffer);
                self.events.evaluate(t, &self.buffer, &mut g[..n]);
            }
            let dips = (0..n).filter(|&i| near[i] && g[i] <= 0.0);
            let roots = dips.map(|i| (i, locate(&*self.stepper, self.events, i, n, (lo, t))));
            if let Some(first) = roots.min_by(|a, b| a.1.total_cmp(&b.1)) {
                return Some(first);
            }
            lo = t;
        }
        None
    }

    /// Emits the grid samples up to the step's end, or strictly before the event; `Some` when the run
    /// ends on one of them (t_end reached, or the observer stopped).
    fn samples_up_to(&mut self, t_new: f64, event: Option<(usize, f64)>) -> Option<RunEnd> {
        let grid_slack = grid_slack(self.settings.sample_interval);
        let t_stop = event.map_or(t_new, |(_, t)| t);
        loop {
            let mut t_k = sample_time(self.settings.t0, self.settings.sample_interval, self.k);
            if t_k > self.settings.t_end - grid_slack {
                t_k = self.settings.t_end;
            }
            if t_k > t_stop || (event.is_some() && t_k > t_stop - EVENT_SAMPLE_GAP) {
                return None;
            }
            #[allow(clippy::float_cmp)] // exact: a grid time that is the step's end uses y itself
            let flow = if t_k == t_new {
                (self.observe)(t_k, &self.stepper.state().y)
            } else {
                self.prepare_dense();
                self.stepper.interpolate(t_k, &mut self.buffer);
                (self.observe)(t_k, &self.buffer)
            };
            self.t_last = t_k;
            self.k += 1;
            if t_k >= self.settings.t_end {
                return Some(RunEnd::Completed);
            }
            if flow == Flow::Stop {
                return Some(RunEnd::Stopped { t: t_k });
            }
        }
    }

    /// The last sample is the state at the event, unless a sample already stands within
    /// EVENT_SAMPLE_GAP before it (a grid point ending the previous step): that one is the event's sample
    /// to within the log time's nanosecond, and a second would repeat its log time.
    fn sample_event(&mut self, t: f64) {
        if t - self.t_last >= EVENT_SAMPLE_GAP {
            // (Locating the event prepared the dense output.)
            self.stepper.interpolate(t, &mut self.buffer);
            let _ = (self.observe)(t, &self.buffer);
            self.t_last = t;
        }
    }
}

/// Locates the crossing of event `i` within `(lo, hi)` of the last step (g_i > 0 at lo, ≤ 0 at hi) by
/// bisection with a secant (Illinois) update, returning a time where g_i ≤ 0 within
/// [`EVENT_TIME_TOLERANCE`] after one where it is > 0.
fn locate<const N: usize, M: Stepper<N>, E: EventFunctions<N>>(
    stepper: &M,
    events: &E,
    i: usize,
    n_events: usize,
    (lo, hi): (f64, f64),
) -> f64 {
    let mut y = [0.0; N];
    let mut g = [0.0; MAX_EVENTS];
    let mut eval = |t: f64| {
        stepper.interpolate(t, &mut y);
        events.evaluate(t, &y, &mut g[..n_events]);
        g[i]
    };
    let (mut lo, mut hi) = (lo, hi);
    let (mut g_lo, mut g_hi) = (eval(lo), eval(hi));
    if g_lo <= 0.0 {
        return lo;
    }
    let mut side = 0i8;
    for _ in 0..200 {
        if hi - lo <= EVENT_TIME_TOLERANCE * hi.abs().max(1.0) {
            break;
        }
        // Illinois false position, safeguarded by bisection when it would land at the ends.
        let mut t = (lo * g_hi - hi * g_lo) / (g_hi - g_lo);
        if !(t > lo && t < hi && t.is_finite()) {
            t = 0.5 * (lo + hi);
        }
        let g_t = eval(t);
        if g_t <= 0.0 {
            hi = t;
            g_hi = g_t;
            if side == -1 {
                g_lo *= 0.5;
            }
            side = -1;
        } else {
            lo = t;
            g_lo = g_t;
            if side == 1 {
                g_hi *= 0.5;
            }
            side = 1;
        }
    }
    hi
}
