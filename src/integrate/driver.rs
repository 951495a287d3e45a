//! The integration loop: steps a [`Stepper`], emits samples on an exact time grid by dense output, and
//! ends at the first event, located by root finding on the dense output.

use super::{OdeSystem, Stats, StepError, Stepper};

/// Largest number of event functions a system may declare.
pub const MAX_EVENTS: usize = 8;

/// Event time resolution: the bracket is shrunk below this (relative to max(1, |t|)); the issue asks for
/// ≤ 1e-10 and bisection to 1e-13 costs a few dozen cheap interpolations per event.
const EVENT_TIME_TOLERANCE: f64 = 1e-13;

/// Grid samples within this time before an event are dropped in favour of the sample at the event, so
/// that no two samples round to the same nanosecond (CONTRACT: log_time = round(t·10⁹), strictly
/// increasing per channel).
pub const EVENT_SAMPLE_GAP: f64 = 2e-9;

/// Scalar functions g_i(t, y) whose crossing from > 0 to ≤ 0 ends a run (flat landing, lift-off, ...).
pub trait EventFunctions<const N: usize> {
    /// Number of functions (≤ [`MAX_EVENTS`]).
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

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Termination {
    /// Reached t_end.
    Completed,
    /// Event function `index` crossed zero at `t`; the last sample is at `t`.
    Event {
        /// Which event function.
        index: usize,
        /// Located time.
        t: f64,
    },
    /// The observer asked to stop at `t`.
    Stopped {
        /// Time of the last sample.
        t: f64,
    },
    /// A numerical failure; samples up to the last good step were emitted.
    Failed(StepError),
}

/// Result of [`run`].
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutcome {
    /// Why it ended.
    pub termination: Termination,
    /// Work done.
    pub stats: Stats,
    /// Time of the last sample.
    pub t_last: f64,
}

/// Sample time number `k`: t0 + k·interval, computed afresh (never accumulated) so the grid does not drift.
#[inline]
#[allow(clippy::cast_precision_loss)]
fn sample_time(settings: &RunSettings, k: u64) -> f64 {
    settings.t0 + k as f64 * settings.sample_interval
}

/// Integrates `sys` from `y0`, calling `observe(t, y)` at every sample time, until t_end, an event, a
/// failure, or `observe` returns [`Flow::Stop`].
pub fn run<const N: usize, S, M, E, O>(
    sys: &S,
    stepper: &mut M,
    y0: &[f64; N],
    settings: &RunSettings,
    events: &E,
    mut observe: O,
) -> RunOutcome
where
    S: OdeSystem<N>,
    M: Stepper<N>,
    E: EventFunctions<N>,
    O: FnMut(f64, &[f64; N]) -> Flow,
{
    let n_events = events.count().min(MAX_EVENTS);
    let mut g_old = [0.0; MAX_EVENTS];
    let mut g_new = [0.0; MAX_EVENTS];
    let t0 = settings.t0;
    let outcome = |termination, stepper: &M, t_last| RunOutcome {
        termination,
        stats: stepper.stats(),
        t_last,
    };

    if let Err(e) = stepper.init(sys, t0, y0, settings.t_end) {
        return outcome(Termination::Failed(e), stepper, t0);
    }
    let flow = observe(t0, y0);
    events.evaluate(t0, y0, &mut g_old[..n_events]);
    if let Some(index) = g_old[..n_events].iter().position(|&g| g <= 0.0) {
        return outcome(Termination::Event { index, t: t0 }, stepper, t0);
    }
    if flow == Flow::Stop {
        return outcome(Termination::Stopped { t: t0 }, stepper, t0);
    }

    // A grid point this close to t_end is t_end (the grid t0 + k·interval rarely hits it exactly).
    let grid_slack = 1e-9 * settings.sample_interval;
    let mut k: u64 = 1;
    let mut t_last = t0;
    let mut buffer = [0.0; N];
    loop {
        if let Err(e) = stepper.step(sys, settings.t_end) {
            return outcome(Termination::Failed(e), stepper, t_last);
        }
        let t_new = stepper.t();
        let reached_end = t_new >= settings.t_end;
        let mut dense_ready = false;

        // Event check at the end of the step; locate the earliest crossing on the dense output.
        events.evaluate(t_new, stepper.y(), &mut g_new[..n_events]);
        let mut event: Option<(usize, f64)> = None;
        for i in 0..n_events {
            if g_old[i] > 0.0 && g_new[i] <= 0.0 {
                if !dense_ready {
                    stepper.prepare_interpolation(sys);
                    dense_ready = true;
                }
                let t_root = locate(stepper, events, i, n_events, &mut buffer);
                if event.is_none_or(|(_, t)| t_root < t) {
                    event = Some((i, t_root));
                }
            }
        }
        let t_stop = event.map_or(t_new, |(_, t)| t);

        // Samples on the grid up to the step's end (or strictly before the event).
        loop {
            let mut t_k = sample_time(settings, k);
            if t_k > settings.t_end - grid_slack {
                t_k = settings.t_end;
            }
            // A grid sample closer than EVENT_SAMPLE_GAP before the event gives way to the event's own
            // sample, so sample times stay apart by more than a nanosecond of log time.
            if t_k > t_stop || (event.is_some() && t_k > t_stop - EVENT_SAMPLE_GAP) {
                break;
            }
            #[allow(clippy::float_cmp)] // exact: a grid time that is the step's end uses y itself
            let flow = if t_k == t_new {
                observe(t_k, stepper.y())
            } else {
                if !dense_ready {
                    stepper.prepare_interpolation(sys);
                    dense_ready = true;
                }
                stepper.interpolate(t_k, &mut buffer);
                observe(t_k, &buffer)
            };
            t_last = t_k;
            k += 1;
            if t_k >= settings.t_end {
                return outcome(Termination::Completed, stepper, t_last);
            }
            if flow == Flow::Stop {
                return outcome(Termination::Stopped { t: t_k }, stepper, t_last);
            }
        }
        if let Some((index, t)) = event {
            // The last sample is the state at the event, unless a sample already stands within
            // EVENT_SAMPLE_GAP before it (a grid point ending the previous step): that one is the event's
            // sample to within the log time's nanosecond, and a second would repeat its log time.
            if t - t_last >= EVENT_SAMPLE_GAP {
                // (Locating the event prepared the dense output.)
                stepper.interpolate(t, &mut buffer);
                let _ = observe(t, &buffer);
                t_last = t;
            }
            return outcome(Termination::Event { index, t }, stepper, t_last);
        }
        if reached_end {
            // Unreachable in practice (the grid loop emits t_end); kept so t_end is always sampled.
            if t_last < settings.t_end {
                let _ = observe(settings.t_end, stepper.y());
                t_last = settings.t_end;
            }
            return outcome(Termination::Completed, stepper, t_last);
        }
        g_old[..n_events].copy_from_slice(&g_new[..n_events]);
    }
}

/// Locates the crossing of event `i` in the last step by bisection with a secant (Illinois) update,
/// returning the earliest time where g_i ≤ 0 within [`EVENT_TIME_TOLERANCE`].
fn locate<const N: usize, M: Stepper<N>, E: EventFunctions<N>>(
    stepper: &M,
    events: &E,
    i: usize,
    n_events: usize,
    buffer: &mut [f64; N],
) -> f64 {
    let mut g = [0.0; MAX_EVENTS];
    let mut eval = |t: f64, buffer: &mut [f64; N]| {
        stepper.interpolate(t, buffer);
        events.evaluate(t, buffer, &mut g[..n_events]);
        g[i]
    };
    let (mut lo, mut hi) = (stepper.t_previous(), stepper.t());
    let (mut g_lo, mut g_hi) = (eval(lo, buffer), eval(hi, buffer));
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
        let g_t = eval(t, buffer);
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
