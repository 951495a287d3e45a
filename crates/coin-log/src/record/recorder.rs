//! Scene → MCAP: integrates a [`Scene`] and streams its samples into an MCAP writer (format.md: Files,
//! Channels, Metadata). [`McapWriter`] compresses chunks on [`COMPRESSION_THREADS`] workers while this
//! thread integrates; the bytes depend on neither. Per sample only the requested quantities are computed,
//! and samples are written one sample late so that the last one can be flagged as last (the 3D scene then
//! shows the final state).

use super::foxglove::{Foxglove3d, FoxgloveBatch, PROTOBUF_MAX_SECONDS};
use super::summary::{Failure, RecordSummary};
use crate::format::messages::{
    drift_eps, friction_ratio, Angles, AngularVelocity, EnergyMessage, InvariantsMessage, Message,
    Position, QuaternionMessage, ReactionMessage, WorkMessage,
};
use crate::format::promise::{self, Shortfall};
use crate::format::tolerances::{RunAccuracy, Tolerances, MIN_SAMPLES_PER_PERIOD};
use crate::format::{
    header_library, log_time, Channel, Encoding, ResultMetadata, Termination, Topic,
    RESULT_METADATA_NAME, RUN_METADATA_NAME,
};
use crate::integrate::{self, Bounds, Flow, RunOutcome, RunSettings};
use crate::model::drift::{EnergyDrift, InvariantDrift};
use crate::model::nutation::{Motion, Orbit};
use crate::model::{
    centre, contact_point, energy, magnitude, orientation, Chaplygin, Coin, Dynamics,
    InvariantsError, State, STATE_LEN,
};
use crate::scene::Scene;
use crate::simulation::{departure_doubt, run_dynamics};
use coin_log_mcap::{Compression, McapWriter, WriteError, WriterOptions};
use std::collections::BTreeMap;
use std::io::{Seek, Write};
use std::sync::atomic::{AtomicBool, Ordering};

/// Chunk compression worker threads. One worker lets compression of a chunk overlap with the simulation
/// on the calling thread (the machine the targets are set on has 2 cores); the bytes do not depend on it.
pub const COMPRESSION_THREADS: usize = 1;

/// How often (in samples) `progress` is called: rare enough to cost nothing, often enough for a bar.
const PROGRESS_INTERVAL: u64 = 4096;

/// How to write the file (what to simulate is the [`Scene`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RecordOptions {
    /// Chunk compression.
    pub compression: Compression,
    /// Message encoding: JSON (the default) or Protobuf.
    pub encoding: Encoding,
}

/// The file could not be written; the caller should discard it. The cause (e.g. "No space left on
/// device") is the error's `source`.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The MCAP writer failed (usually an I/O error: disk full, file gone).
    #[error("writing the MCAP file failed")]
    Write(#[from] WriteError),
    /// Flushing the finished file failed.
    #[error("writing the MCAP file failed")]
    Io(#[from] std::io::Error),
    /// C1, C2 cannot be evaluated for this body (μ too large; no validated scene has such a body).
    #[error("the `invariants` channel cannot be recorded for this body")]
    Invariants(#[from] InvariantsError),
    /// The run is longer than Foxglove's Protobuf timestamps reach (u32 seconds).
    #[allow(missing_docs)]
    #[error(
        "the run lasts {duration} time units, longer than the {max} seconds a Protobuf timestamp of Foxglove's \
         schemas holds; record it with --encoding json, or shorten run.duration"
    )]
    TooLongForProtobuf { duration: f64, max: f64 },
    /// A channel the file's encoding cannot carry (`rerun` is for Rerun, which decodes Protobuf).
    #[allow(missing_docs)]
    #[error(
        "the `{channel}` channel is recorded in {} only (Rerun's MCAP importer decodes Protobuf, not JSON): \
         record it with --encoding protobuf, or leave `{channel}` out",
        channel.encodings().iter().map(|e| e.name()).collect::<Vec<_>>().join(", ")
    )]
    Encoding { channel: Channel },
}

/// Why writing a sample stopped the run.
enum SampleError {
    Write(WriteError),
    Failure(Failure),
}

impl From<WriteError> for SampleError {
    fn from(e: WriteError) -> Self {
        Self::Write(e)
    }
}
impl<E: Into<Failure>> From<E> for SampleError {
    fn from(e: E) -> Self {
        Self::Failure(e.into())
    }
}

/// A topic's channel as the file declares it: what a [`Tap`] needs to announce it elsewhere.
#[derive(Debug, Clone, Copy)]
pub struct ChannelDeclaration {
    /// The topic.
    pub topic: Topic,
    /// Schema name (e.g. `coin_log.Energy`).
    pub schema_name: &'static str,
    /// Schema encoding (`jsonschema` or `protobuf`).
    pub schema_encoding: &'static str,
    /// The schema's bytes, as written to the file.
    pub schema: &'static [u8],
    /// Message encoding (`json` or `protobuf`).
    pub message_encoding: &'static str,
}

impl ChannelDeclaration {
    /// `topic`'s channel in a file of `encoding` ([`Topic::wire`]; an empty schema if it has none there:
    /// every topic has one in each encoding of its channel, a test checks it).
    #[must_use]
    pub fn new(topic: Topic, encoding: Encoding) -> Self {
        let (schema_encoding, schema, message_encoding) = topic.wire(encoding).unwrap_or((
            encoding.schema_encoding(),
            &[],
            encoding.message_encoding(),
        ));
        Self {
            topic,
            schema_name: topic.schema_name(),
            schema_encoding,
            schema,
            message_encoding,
        }
    }
}

/// Sees the recording as it is written (e.g. `coin-log live` serves it to a viewer): each topic's channel
/// before its first message, then every message with its log time, in the file's order. Called on the
/// simulation's thread, so a tap that blocks (to pace the run in real time) slows the run.
pub trait Tap {
    /// A topic's channel, once, before its first message.
    fn channel(&mut self, info: &ChannelDeclaration);
    /// A message, after it went to the file.
    fn message(&mut self, topic: Topic, log_time: u64, data: &[u8]);
}

/// The tap of a plain recording: sees nothing (and costs nothing: it is inlined away).
#[derive(Debug, Clone, Copy, Default)]
pub struct NoTap;

impl Tap for NoTap {
    #[inline]
    fn channel(&mut self, _: &ChannelDeclaration) {}
    #[inline]
    fn message(&mut self, _: Topic, _: u64, _: &[u8]) {}
}

/// The writer with its topics: registers a topic's MCAP channel at its first message, numbers messages per
/// topic, and shows both to the tap.
struct Output<'t, W: Write + Seek, T: Tap> {
    writer: McapWriter<W>,
    tap: &'t mut T,
    encoding: Encoding,
    ids: [Option<u16>; Topic::COUNT],
    sequence: [u32; Topic::COUNT],
    messages: u64,
}

impl<W: Write + Seek, T: Tap> Output<'_, W, T> {
    #[inline]
    fn write(&mut self, topic: Topic, log_time: u64, data: &[u8]) -> Result<(), SampleError> {
        let index = topic.index();
        let channel_id = match self.ids[index] {
            Some(id) => id,
            None => self.register(topic)?,
        };
        let sequence = self.sequence[index];
        self.sequence[index] = sequence.wrapping_add(1);
        self.writer
            .write_message(channel_id, sequence, log_time, log_time, data)?;
        self.messages += 1;
        self.tap.message(topic, log_time, data);
        Ok(())
    }

    /// Registers `topic`'s channel (`start` refused a channel the file's encoding cannot carry).
    #[cold]
    fn register(&mut self, topic: Topic) -> Result<u16, WriteError> {
        let info = ChannelDeclaration::new(topic, self.encoding);
        let schema_id =
            self.writer
                .add_schema(info.schema_name, info.schema_encoding, info.schema)?;
        let id = self.writer.add_channel(
            schema_id,
            topic.name(),
            info.message_encoding,
            &BTreeMap::new(),
        )?;
        self.ids[topic.index()] = Some(id);
        self.tap.channel(&info);
        Ok(id)
    }
}

/// Running measures for the summary: energy (or, with dissipation, energy balance E + W) and invariant
/// drift, distance from the steady motion, and the last sample's W and θ.
struct Drift {
    energy: EnergyDrift,
    /// The last sample's W (dissipative runs) and θ.
    last_work: Option<f64>,
    last_theta: f64,
    /// Set at the first sample that has C1, C2.
    invariants: Option<InvariantDrift>,
    /// (θ*, ω_X*, ω_Y*, ω_Z*) of an unperturbed steady scene.
    steady: Option<[f64; 4]>,
    time_unit: f64,
    steady_residual: f64,
    /// max|ω| over the samples (for the tolerance `verify` will derive).
    max_omega: f64,
    /// max|ω_X| over the samples: the nutation's amplitude, which `verify`'s timing bound divides by.
    max_omega_x: f64,
}

impl Drift {
    /// α = π/2 − |θ| at the last sample, for dissipative runs (format.md: `termination_alpha`).
    fn termination_alpha(&self) -> Option<f64> {
        self.last_work
            .map(|_| std::f64::consts::FRAC_PI_2 - self.last_theta.abs())
    }

    fn new(scene: &Scene, coin: &Coin) -> Self {
        let params = scene.params;
        Self {
            energy: EnergyDrift::new(&params, energy(coin, &scene.initial).total),
            last_work: None,
            last_theta: scene.initial.theta,
            invariants: None,
            steady: scene.unperturbed_steady().map(|s| {
                let s = &s.state;
                [s.theta, s.omega_x, s.omega_y, s.omega_z]
            }),
            time_unit: params.time_unit(),
            steady_residual: 0.0,
            max_omega: 0.0,
            max_omega_x: 0.0,
        }
    }
}

/// Everything a sample needs, built once.
struct Sampler<'t, W: Write + Seek, T: Tap> {
    out: Output<'t, W, T>,
    /// The coin and its equations with the scene's dissipation, for the reaction (physics §11).
    dynamics: Dynamics,
    on: [bool; Channel::ALL.len()],
    /// The messages of the current sample, written once all are formatted.
    batch: FoxgloveBatch,
    foxglove: Foxglove3d,
    /// C1, C2, only when the `invariants` channel is recorded.
    chaplygin: Option<Chaplygin>,
    drift: Drift,
    /// E at the first sample (E₀ of the energy's `change`).
    energy0: Option<f64>,
    /// Samples written.
    samples: u64,
}

impl<W: Write + Seek, T: Tap> Sampler<'_, W, T> {
    /// Formats the message `m()` into the sample's batch when `channel` is recorded (an error abandons the
    /// sample).
    #[inline]
    fn stage<M: Message>(
        &mut self,
        channel: Channel,
        m: impl FnOnce() -> M,
    ) -> Result<(), SampleError> {
        if !self.on[channel as usize] {
            return Ok(());
        }
        let (encoding, mut formatted) = (self.out.encoding, Ok(()));
        self.batch
            .push(Topic::Main(channel), |b| formatted = m().write(encoding, b));
        Ok(formatted?)
    }

    /// Writes the sample (t, y) with the dissipated work W of a dissipative run: all its messages or, if
    /// one cannot be formatted, none.
    fn sample(
        &mut self,
        t: f64,
        y: &[f64; STATE_LEN],
        work: Option<f64>,
        last: bool,
    ) -> Result<(), SampleError> {
        let ns = log_time(t)?;
        let s = State::from_array(y);
        self.batch.clear();
        self.stage_kinematics(t, &s)?;
        let (total, invariants) = self.stage_dynamics(t, &s)?;
        let total = match work {
            Some(w) => self.stage_work(t, total, w)?,
            None => total,
        };
        self.foxglove.sample(t, ns, &s, last, &mut self.batch)?;
        for (topic, data) in self.batch.iter() {
            self.out.write(topic, ns, data)?;
        }
        self.track(t, &s, total, invariants);
        self.drift.last_work = work;
        self.samples += 1;
        Ok(())
    }

    /// Stages `/coin/work` (when recorded) and returns the balance E + W, which the summary's drift
    /// follows in place of E (physics §11).
    #[inline]
    fn stage_work(&mut self, t: f64, total: f64, work: f64) -> Result<f64, SampleError> {
        let balance = total + work;
        self.stage(Channel::Work, || WorkMessage {
            t,
            dissipated: work,
            balance,
        })?;
        Ok(balance)
    }

    /// Stages the messages of the state alone: ω, angles, quaternion, centre, contact point.
    #[inline]
    fn stage_kinematics(&mut self, t: f64, s: &State) -> Result<(), SampleError> {
        let coin = *self.dynamics.coin();
        self.stage(Channel::Omega, || AngularVelocity {
            t,
            x: s.omega_x,
            y: s.omega_y,
            z: s.omega_z,
        })?;
        self.stage(Channel::Angles, || Angles {
            t,
            theta: s.theta,
            phi: s.phi,
            psi: s.psi,
            phi_dot: Some(s.omega_y / s.theta.cos()),
        })?;
        self.stage(Channel::Quaternion, || {
            let q = orientation(s);
            QuaternionMessage {
                t,
                x: q.i,
                y: q.j,
                z: q.k,
                w: q.w,
            }
        })?;
        let points = [
            (Channel::Position, centre as fn(&_, &_) -> _),
            (Channel::Contact, contact_point),
        ];
        for (channel, point) in points {
            self.stage(channel, || {
                let c = point(&coin, s);
                Position {
                    t,
                    x: c.x,
                    y: c.y,
                    z: c.z,
                }
            })?;
        }
        Ok(())
    }

    /// Stages the messages that need the equations or the integrals: reaction, energy, C1 and C2. Returns
    /// E and (C1, C2) when computed, for the summary's drift.
    #[inline]
    fn stage_dynamics(
        &mut self,
        t: f64,
        s: &State,
    ) -> Result<(f64, Option<(f64, f64)>), SampleError> {
        let dynamics = self.dynamics;
        let coin = dynamics.coin();
        self.stage(Channel::Reaction, || {
            let r = dynamics.reaction(s);
            let p = coin.params();
            ReactionMessage {
                t,
                x: r.force.x,
                y: r.force.y,
                z: r.force.z,
                friction: r.friction,
                normal: r.normal,
                friction_ratio: Some(friction_ratio(r.friction, r.normal, p.mass(), p.gravity())),
            }
        })?;
        // Energy is always computed: the summary's drift needs it, and it is a handful of flops.
        let e = energy(coin, s);
        let e0 = *self.energy0.get_or_insert(e.total);
        self.stage(Channel::Energy, || EnergyMessage {
            t,
            total: e.total,
            kinetic: e.kinetic,
            potential: e.potential,
            change: Some(e.total - e0),
            drift_eps: Some(drift_eps(e.total, e0, coin.params().energy_scale())),
        })?;
        let invariants = self.chaplygin.as_ref().map(|c| c.of_state(s));
        if let Some(c) = invariants {
            self.stage(Channel::Invariants, || InvariantsMessage {
                t,
                c1: c.c1,
                c2: c.c2,
            })?;
        }
        Ok((e.total, invariants.map(|c| (c.c1, c.c2))))
    }

    #[inline]
    fn track(&mut self, t: f64, s: &State, total: f64, invariants: Option<(f64, f64)>) {
        let d = &mut self.drift;
        d.energy.observe(t, total);
        let omega = magnitude(s.omega_x, s.omega_y, s.omega_z);
        d.max_omega = d.max_omega.max(omega);
        d.max_omega_x = d.max_omega_x.max(s.omega_x.abs());
        d.last_theta = s.theta;
        // With dissipation C1, C2 are not conserved (physics §11): their change is no drift.
        if let (Some((c1, c2)), None) = (invariants, self.dynamics.dissipation()) {
            let params = self.dynamics.coin().params();
            d.invariants
                .get_or_insert_with(|| InvariantDrift::new(params, c1, c2))
                .observe(t, c1, c2);
        }
        if let Some([theta, wx, wy, wz]) = d.steady {
            let dw = (s.omega_x - wx)
                .abs()
                .max((s.omega_y - wy).abs())
                .max((s.omega_z - wz).abs());
            let r = (s.theta - theta).abs().max(dw * d.time_unit);
            d.steady_residual = d.steady_residual.max(r);
        }
    }
}

/// Integrates `scene` and writes it to `writer` as a finished MCAP file, calling `progress(t)` now and
/// then and stopping (termination `interrupted`) within one integrator step after `stop` is raised,
/// whatever the sampling rate: the file then ends with the samples recorded so far.
///
/// A physical event or a numerical failure still gives a finished file; the returned summary says which
/// ([`Termination`]). The writer is flushed before returning.
///
/// # Errors
/// [`RecordError`] when writing fails: the output is then unusable and should be deleted.
pub fn record<W: Write + Seek>(
    scene: &Scene,
    options: &RecordOptions,
    writer: W,
    stop: &AtomicBool,
    progress: impl FnMut(f64),
) -> Result<RecordSummary, RecordError> {
    record_with_tap(scene, options, writer, &mut NoTap, stop, progress)
}

/// [`record`], showing every channel and message to `tap` as it is written (lent, so that the caller reads
/// its state afterwards).
///
/// # Errors
/// As [`record`].
pub fn record_with_tap<W: Write + Seek, T: Tap>(
    scene: &Scene,
    options: &RecordOptions,
    writer: W,
    tap: &mut T,
    stop: &AtomicBool,
    progress: impl FnMut(f64),
) -> Result<RecordSummary, RecordError> {
    let mut sampler = Sampler::start(scene, options, writer, tap)?;
    let (outcome, error) = integrate_into(scene, &mut sampler, stop, progress);
    let (termination, termination_time, failure) = match error {
        Some(SampleError::Write(e)) => return Err(e.into()),
        Some(SampleError::Failure(f)) => (f.termination(), outcome.t_last, Some(f)),
        None => ending(&outcome.termination, outcome.t_last),
    };
    let accuracy = RunAccuracy::new(
        &scene.run.method,
        &scene.params,
        termination_time,
        sampler.drift.max_omega,
    );
    let tolerance = Tolerances::derive(&accuracy, None, None).energy;
    let shortfalls = shortfalls(scene, &accuracy, Some(sampler.drift.max_omega_x));
    let doubt = departure_doubt(&scene.coin(), &scene.initial).filter(|_| termination.is_event());
    sampler.finish(
        outcome.stats,
        (termination, termination_time),
        failure,
        shortfalls,
        (tolerance, doubt),
    )
}

/// The checks `verify` is expected to fail on a recording of `scene`, predicted before it runs from the
/// settings, the duration and |ω| at t = 0 ([`promise`]); the summary repeats the prediction with the
/// run's own span and max|ω|.
#[must_use]
pub fn expected_shortfalls(scene: &Scene) -> Vec<Shortfall> {
    let s = &scene.initial;
    let omega = crate::model::magnitude(s.omega_x, s.omega_y, s.omega_z);
    let span = scene.run.duration;
    let accuracy = RunAccuracy::new(&scene.run.method, &scene.params, span, omega);
    shortfalls(scene, &accuracy, None)
}

/// [`promise::shortfalls`] of a recording of `scene` integrated as `accuracy`, naming only checks verify
/// will run on it (format.md: verify): `steady` only on an unperturbed steady start; `invariants` and
/// `nutation` only without dissipation (E, C1, C2 change), `nutation` only off a steady start (which does
/// not nutate) and when the quadrature finds a period (else "there is no period"). Skipped checks were
/// promised by `wobble --rtol 1e-7` (`steady`), Euler's disk (14 000 time units), `circle-plus --rtol 1e-3
/// --atol 1e-3` and `topple --rtol 1e-6 --atol 1e-8`, which lands flat (`nutation`). After the run,
/// `max_omega_x` (max|ω_X| over the samples) also leaves out a `nutation` too small to time
/// (`wobble --rtol 1e-5 --atol 1e-7`: 5.5e-6 of T, above 1e-6).
fn shortfalls(scene: &Scene, accuracy: &RunAccuracy, max_omega_x: Option<f64>) -> Vec<Shortfall> {
    let mut shortfalls = promise::shortfalls(
        accuracy,
        fixed_steps(scene, accuracy.span),
        positions(scene),
    );
    let dissipative = scene.dissipation.is_some();
    let steady = scene.unperturbed_steady().is_some();
    let nutates = || nutates(scene, accuracy, max_omega_x);
    let runs = |check: &str| match check {
        "steady" => steady,
        "invariants" => !dissipative,
        "nutation" => !dissipative && !steady && nutates(),
        _ => true,
    };
    for s in &mut shortfalls {
        // The skipped check of a pair is its second, so what is kept is a prefix of the static list.
        let kept = s.checks.iter().take_while(|c| runs(c)).count();
        s.checks = &s.checks[..kept];
    }
    shortfalls.retain(|s| !s.checks.is_empty());
    shortfalls
}

/// Whether the quadrature of physics §10 from the initial state finds a nutation period that the samples
/// resolve, as verify's `nutation` check computes it from the first stored state: a coin that lands flat
/// (or a state with no orbit) has none, and fewer than [`MIN_SAMPLES_PER_PERIOD`] samples a period are
/// "undersampled"; verify skips the check either way. (A period within 1e-9 of the sampling limit still
/// counts as resolved, so rounding of the stored times cannot make verify run a check not named.) With
/// `max_omega_x` known, a nutation whose timing bound exceeds the one verify accepts does not count: the
/// bound here takes the run's whole span, which is at least the span verify measures between turning
/// points, so it is at most verify's, and a nutation left out here is one verify skips.
fn nutates(scene: &Scene, accuracy: &RunAccuracy, max_omega_x: Option<f64>) -> bool {
    let coin = scene.coin();
    let resolved =
        |period: f64| period >= MIN_SAMPLES_PER_PERIOD * scene.run.sample_interval() * (1.0 - 1e-9);
    let timed = |period: f64| {
        max_omega_x.is_none_or(|amplitude| {
            let a = accuracy;
            let epsilon = Tolerances::derive(a, None, None).epsilon;
            let error = promise::omega_error(epsilon, a.span, a.time_unit, a.max_omega);
            promise::nutation_timing(error, amplitude, period, a.span)
                <= promise::MAX_NUTATION_TIMING
        })
    };
    Chaplygin::new(coin.params())
        .ok()
        .and_then(|chaplygin| {
            Orbit::new(&coin, &chaplygin, &scene.initial, scene.run.flat_margin).ok()
        })
        .is_some_and(
            |orbit| matches!(orbit.motion, Motion::Periodic { period, .. } if resolved(period) && timed(period)),
        )
}

/// Where the centre and the heading start, how fast the heading turns, and how far apart the stored
/// coordinates are sampled.
fn positions(scene: &Scene) -> promise::Positions {
    let s = &scene.initial;
    promise::Positions {
        offset: s.x.abs().max(s.z.abs()) / scene.params.radius(),
        sample_interval: scene.run.sample_interval(),
        heading: s.phi.abs(),
        heading_rate: (s.omega_y / s.theta.cos()).abs(),
    }
}

/// The steps a fixed-step method takes over `span`; `None` for adaptive methods.
fn fixed_steps(scene: &Scene, span: f64) -> Option<promise::FixedSteps> {
    let m = &scene.run.method;
    (!m.method.is_adaptive()).then(|| promise::FixedSteps {
        steps: (span / m.step).ceil(),
        sample_interval: scene.run.sample_interval(),
    })
}

/// How the integration ended, as the file records it: termination, its time, and the failure if any.
fn ending(end: &integrate::RunEnd, t_last: f64) -> (Termination, f64, Option<Failure>) {
    use integrate::{RunEnd, StepError};
    let (t, failure) = match end {
        RunEnd::Completed => (t_last, None),
        RunEnd::Event { t, .. } | RunEnd::Stopped { t } => (*t, None),
        RunEnd::Failed(e) => match e {
            StepError::NonFinite { t }
            | StepError::StepSizeUnderflow { t, .. }
            | StepError::NewtonFailure { t, .. }
            | StepError::BudgetSpent { t, .. } => (*t, Some(Failure::Step(e.clone()))),
        },
    };
    (Termination::of_run(end), t, failure)
}

/// Runs the scene's integrator, writing each sample one sample late (module docs), reporting progress and
/// honouring `stop`; returns the integrator's outcome and the error that stopped writing, if one did.
fn integrate_into<W: Write + Seek, T: Tap>(
    scene: &Scene,
    sampler: &mut Sampler<'_, W, T>,
    stop: &AtomicBool,
    mut progress: impl FnMut(f64),
) -> (RunOutcome, Option<SampleError>) {
    let settings = RunSettings {
        t0: 0.0,
        t_end: scene.run.duration,
        sample_interval: scene.run.sample_interval(),
    };
    let dynamics = sampler.dynamics;
    let mut pending: Option<(f64, [f64; STATE_LEN], Option<f64>)> = None;
    let mut error: Option<SampleError> = None;
    let mut observed: u64 = 0;
    // Fixed-step runs were refused up front beyond the budget (scene::limits); counting their steps again
    // would only trip on the final partial step.
    let bounds = Bounds {
        max_steps: scene
            .run
            .method
            .method
            .is_adaptive()
            .then_some(scene.run.max_steps),
        stop: Some(stop),
    };
    let outcome = run_dynamics(
        &scene.run.method,
        &dynamics,
        &scene.initial,
        &settings,
        &bounds,
        scene.run.flat_margin,
        scene.friction,
        |t, y, work| {
            if let Some((tp, yp, wp)) = pending.replace((t, *y, work)) {
                if let Err(e) = sampler.sample(tp, &yp, wp, false) {
                    error = Some(e);
                    return Flow::Stop;
                }
            }
            observed += 1;
            if observed.is_multiple_of(PROGRESS_INTERVAL) {
                progress(t);
            }
            if stop.load(Ordering::Relaxed) {
                Flow::Stop
            } else {
                Flow::Continue
            }
        },
    );
    if error.is_none() {
        if let Some((t, y, w)) = pending {
            error = sampler.sample(t, &y, w, true).err();
        }
    }
    progress(outcome.t_last);
    (outcome, error)
}

impl<'t, W: Write + Seek, T: Tap> Sampler<'t, W, T> {
    /// Opens the file: writer, `coin-log` metadata, and what each sample will compute. A body whose C1, C2
    /// cannot be evaluated fails here, before the first byte, so no half-written file is left.
    fn start(
        scene: &Scene,
        options: &RecordOptions,
        writer: W,
        tap: &'t mut T,
    ) -> Result<Self, RecordError> {
        let dynamics = scene.dynamics();
        let coin = *dynamics.coin();
        let on = std::array::from_fn(|c| scene.records(Channel::ALL[c]));
        if options.encoding == Encoding::Protobuf && scene.run.duration > PROTOBUF_MAX_SECONDS {
            return Err(RecordError::TooLongForProtobuf {
                duration: scene.run.duration,
                max: PROTOBUF_MAX_SECONDS,
            });
        }
        if let Some(&channel) = scene
            .channels
            .iter()
            .find(|c| !c.encodings().contains(&options.encoding))
        {
            return Err(RecordError::Encoding { channel });
        }
        let chaplygin = scene
            .records(Channel::Invariants)
            .then(|| Chaplygin::new(&scene.params))
            .transpose()?;
        let library = header_library(env!("CARGO_PKG_VERSION"));
        let write_options = WriterOptions {
            workers: COMPRESSION_THREADS,
            ..WriterOptions::new(options.compression, library)
        };
        let mut writer = McapWriter::new(writer, &write_options)?;
        writer.write_metadata(RUN_METADATA_NAME, &scene.run_metadata().to_map())?;
        Ok(Self {
            out: Output {
                writer,
                tap,
                encoding: options.encoding,
                ids: [None; Topic::COUNT],
                sequence: [0; Topic::COUNT],
                messages: 0,
            },
            dynamics,
            on,
            batch: FoxgloveBatch::default(),
            foxglove: Foxglove3d::new(&coin, scene.thickness, &scene.channels, options.encoding),
            chaplygin,
            energy0: None,
            samples: 0,
            drift: Drift::new(scene, &coin),
        })
    }

    /// Closes the file: `coin-log.result` metadata, summary section, flush; returns the summary, with the
    /// energy tolerance `verify` will derive and why an event is in doubt, if it is.
    fn finish(
        self,
        stats: integrate::Stats,
        (termination, termination_time): (Termination, f64),
        failure: Option<Failure>,
        shortfalls: Vec<Shortfall>,
        (energy_tolerance, event_doubt): (f64, Option<String>),
    ) -> Result<RecordSummary, RecordError> {
        let Self {
            mut out,
            drift,
            samples,
            ..
        } = self;
        out.writer.write_metadata(
            RESULT_METADATA_NAME,
            &ResultMetadata {
                steps: stats.steps,
                rhs_evaluations: stats.rhs_evaluations,
                rejected_steps: stats.rejected_steps,
                termination,
                termination_time,
                termination_alpha: drift.termination_alpha(),
                expected_to_fail: (!shortfalls.is_empty())
                    .then(|| promise::check_list(&shortfalls, ",")),
            }
            .to_map(),
        )?;
        let (mut inner, bytes) = out.writer.finish()?;
        inner.flush()?;
        let energy_drift = drift.energy.value();
        Ok(RecordSummary {
            samples,
            messages: out.messages,
            bytes,
            stats,
            termination,
            termination_time,
            failure,
            energy_drift,
            invariant_drift: drift.invariants.map(|d| d.value()),
            steady_residual: drift.steady.map(|_| drift.steady_residual),
            energy_tolerance,
            event_trusted: termination
                .is_event()
                .then_some(energy_drift <= energy_tolerance && event_doubt.is_none()),
            event_doubt,
            dissipated_work: drift.last_work,
            termination_alpha: drift.termination_alpha(),
            shortfalls,
        })
    }
}
