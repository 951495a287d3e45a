//! Judging one file: the [`Visitor`] that turns records into typed samples and feeds the checks, and the
//! verdict with its exit code.

use super::checks::{
    consistency::ConsistencyCheck, constraint::ConstraintCheck, energy::EnergyCheck, integrity,
    invariants::InvariantsCheck, nutation::NutationCheck, steady, steady::SteadyCheck,
    validity::ValidityCheck, Context, RunStats,
};
use super::report::{CheckId, CheckResult, FileReport, Status, Verdict};
use super::samples::{Assembler, Sample, MAX_PENDING};
use super::Options;
use crate::format::channels::ROS_STRING_WIRE;
use crate::format::fields::{FieldReader, ReaderError, Version};
use crate::format::messages::{message_type, Message, POINT_CLOUD, SCENE_UPDATE, VOXEL_GRID};
use crate::format::tolerances::{RunAccuracy, Tolerances, RECOMPUTE_TOLERANCE};
use crate::format::{
    log_time, schema_data, Channel, Encoding, ResultMetadata, RunMetadata, Termination, Topic,
    FORMAT_VERSION, FRAME_TRANSFORM, RESULT_METADATA_NAME, ROS_STRING, RUN_METADATA_NAME,
};
use crate::integrate::MethodConfig;
use crate::model::{Chaplygin, Coin, Dynamics};
use crate::scene::{self, Scene};
use coin_log_mcap::{
    self, read_in_log_time_order, BoundedFindings, MessageHeader, ReadError, Schema, Structure,
    Visitor,
};
use std::collections::{BTreeMap, BTreeSet};
use std::io::{Read, Seek};
use std::ops::ControlFlow;
use std::path::Path;

/// What a channel id stands for.
#[derive(Debug, Clone)]
enum Kind {
    /// A `coin_log.*` channel and how its messages are read.
    Coin(Channel, FieldReader),
    /// A Foxglove channel, its schema name and its messages' encoding.
    Foxglove(&'static str, Encoding),
    Unknown,
}

#[derive(Debug, Clone)]
struct ChannelState {
    kind: Kind,
    topic: String,
    last: Option<u64>,
}

/// The physics checks' running state.
#[derive(Debug, Default)]
struct Checks {
    stats: RunStats,
    energy: EnergyCheck,
    invariants: InvariantsCheck,
    steady: SteadyCheck,
    constraint: ConstraintCheck,
    consistency: ConsistencyCheck,
    validity: ValidityCheck,
    nutation: NutationCheck,
}

impl Checks {
    fn observe(&mut self, s: &Sample, ctx: &Context) {
        self.stats.observe(s);
        self.energy.observe(s, ctx);
        self.invariants.observe(s, ctx);
        self.steady.observe(s, ctx);
        self.constraint.observe(s, ctx.coin.params().radius());
        self.consistency.observe(s, ctx);
        self.validity.observe(s, ctx);
        self.nutation.observe(s, ctx);
    }
}

/// Whether a message of a Foxglove channel of schema `schema` is valid in its encoding: JSON text, or a
/// Protobuf message of its Foxglove type.
fn foxglove_message(encoding: Encoding, schema: &str, data: &[u8]) -> Result<(), String> {
    use foxglove::messages::{FrameTransform, PointCloud, SceneUpdate, VoxelGrid};
    use prost::Message;
    match encoding {
        Encoding::Json => serde_json::from_slice::<serde::de::IgnoredAny>(data)
            .map(|_| ())
            .map_err(|e| format!("is not JSON: {e}")),
        Encoding::Protobuf => {
            let decoded = match schema {
                FRAME_TRANSFORM => FrameTransform::decode(data).map(|_| ()),
                POINT_CLOUD => PointCloud::decode(data).map(|_| ()),
                VOXEL_GRID => VoxelGrid::decode(data).map(|_| ()),
                SCENE_UPDATE => SceneUpdate::decode(data).map(|_| ()),
                _ => Ok(()),
            };
            decoded.map_err(|e| format!("is not a valid Protobuf message of its type: {e}"))
        }
    }
}

/// What a channel's schema says about its messages.
#[derive(Default)]
struct SchemaJudged {
    /// The schema's encoding (absent for an encoding coin-log does not write).
    encoding: Option<Encoding>,
    /// It is the first version of a `coin_log.*` type.
    first_version: bool,
    /// The reader of a Protobuf `coin_log.*` schema.
    reader: Option<FieldReader>,
}

/// The visitor that judges one log while it streams by.
#[derive(Default)]
struct Judge {
    channels: Vec<Option<ChannelState>>,
    /// The channel id of each of coin-log's topics, at its first channel.
    topics: BTreeMap<Topic, u16>,
    ctx: Option<Context>,
    /// The `coin-log.result` record, kept until the end (it may come before or after `coin-log`).
    result: Option<ResultMetadata>,
    run_error: Option<String>,
    result_error: Option<String>,
    problems: BoundedFindings,
    notes: Vec<String>,
    assembler: Assembler,
    checks: Checks,
}

impl Judge {
    /// Reads a message of `coin_log.*` channel `c` logged at `log_time` strictly into a sample of its own.
    fn parse(c: Channel, r: &FieldReader, log_time: u64, data: &[u8]) -> Result<Sample, String> {
        fn read<M: Message>(
            r: &FieldReader,
            data: &[u8],
            slot: &mut Option<M>,
        ) -> Result<f64, String> {
            let m: M = r.read_message(data)?;
            *slot = Some(m);
            Ok(m.t())
        }
        let mut s = Sample {
            log_time,
            ..Sample::default()
        };
        s.t = match c {
            Channel::Omega => read(r, data, &mut s.omega),
            Channel::Angles => read(r, data, &mut s.angles),
            Channel::Quaternion => read(r, data, &mut s.quaternion),
            Channel::Position => read(r, data, &mut s.position),
            Channel::Contact => read(r, data, &mut s.contact),
            Channel::Reaction => read(r, data, &mut s.reaction),
            Channel::Energy => read(r, data, &mut s.energy),
            Channel::Invariants => read(r, data, &mut s.invariants),
            Channel::Work => read(r, data, &mut s.work),
            Channel::Tf | Channel::Scene | Channel::Rerun => {
                Err("is not a coin_log message".into())
            }
        }?;
        Ok(s)
    }

    /// The checks' context from the `coin-log` record's `entries`, or why the file cannot be judged.
    fn run_metadata(&mut self, entries: &BTreeMap<String, String>) -> Result<Context, String> {
        let run = RunMetadata::from_map(entries)
            .map_err(|e| format!("its `coin-log` metadata is unusable: {e}"))?;
        if run.format_version != FORMAT_VERSION {
            return Err(format!(
                "its `coin-log` metadata has format_version {:?}; this tool reads {FORMAT_VERSION:?}",
                run.format_version
            ));
        }
        let params = run
            .params()
            .map_err(|e| format!("its `coin-log` metadata has unusable body parameters: {e}"))?;
        let coin = Coin::new(params);
        let dynamics = Dynamics::new(coin, run.dissipation);
        let scene = stored_scene(&run);
        match &scene {
            Ok(scene) => {
                for disagreement in disagreements(&run, &scene.run_metadata()) {
                    self.problems.push_with(|| disagreement);
                }
            }
            Err(e) => self.problems.push_with(|| {
                format!("{e}: record stores a scene that reads back to the run it made")
            }),
        }
        let steady = steady::plan(&coin, &run, &scene);
        let chaplygin = Chaplygin::new(&params)
            .map_err(|e| format!("C1, C2 cannot be evaluated for these parameters: {e}"));
        Ok(Context {
            coin,
            dynamics,
            run,
            result: None,
            scene,
            steady,
            chaplygin,
        })
    }

    /// Judges a channel's schema: its encoding, and its bytes against this tool's (or the versions its
    /// messages may follow).
    fn schema(&mut self, schema: &Schema<'_>) -> SchemaJudged {
        let (name, encoding, data) = (
            schema.name.as_str(),
            schema.encoding.as_str(),
            &schema.data[..],
        );
        let Some(e) = Encoding::from_schema_encoding(encoding) else {
            self.problems.push_with(|| {
                format!(
                    "schema `{name}` has encoding {encoding:?}; coin-log writes {:?} or {:?}",
                    Encoding::Json.schema_encoding(),
                    Encoding::Protobuf.schema_encoding()
                )
            });
            return SchemaJudged::default();
        };
        let mut judged = SchemaJudged {
            encoding: Some(e),
            ..SchemaJudged::default()
        };
        let Some(t) = message_type(name) else {
            match schema_data(name, e) {
                Some(ours) if ours == data => {}
                Some(_) => self.notes.push(format!(
                    "schema `{name}` differs from this tool's copy (Foxglove type, not validated)"
                )),
                None => self
                    .problems
                    .push_with(|| format!("schema `{name}` is not one of coin-log's")),
            }
            return judged;
        };
        let (reader, version) = match FieldReader::new(encoding, t, data) {
            Ok(r) => r,
            Err(ReaderError::Descriptor(e)) => {
                self.problems
                    .push_with(|| format!("schema `{name}` (protobuf) {e}"));
                return judged;
            }
            Err(ReaderError::Encoding(_)) => return judged,
        };
        match version {
            Version::Ours => {}
            Version::Other if e == Encoding::Json => self.notes.push(format!(
                "schema `{name}` is another version than this tool's; the messages conform to it"
            )),
            Version::Other => self.notes.push(format!(
                "schema `{name}` is another version than this tool's; its messages are read by the field numbers it declares"
            )),
            Version::First => {
                judged.first_version = true;
                self.notes.push(format!(
                    "schema `{name}` is the first version of the type, without the fields added since ({})",
                    t.fields[t.first_fields.len()..].join(", ")
                ));
            }
            Version::Nonconforming(why) => self.problems.push_with(|| {
                format!("schema `{name}` is another version than this tool's and {why}")
            }),
        }
        judged.reader = (e == Encoding::Protobuf).then_some(reader);
        judged
    }

    /// Judges the samples again in log-time order (format.md: verify) after the stream cut some: the
    /// messages of the file's chunks through its chunk indexes, parsed as before, into a fresh assembler
    /// and fresh checks; the stream's structural findings stand. A file that cannot be read so keeps the
    /// stream's judgement, and a note says how many samples it judged in pieces.
    fn reorder(&mut self, structure: &Structure, source: impl Read + Seek) {
        let Some(ctx) = self.ctx.as_ref() else {
            return;
        };
        let (mut assembler, mut checks) = (self.assembler.afresh(), Checks::default());
        let channels = &self.channels;
        let mut judge = |h: &MessageHeader, data: &[u8]| {
            let Some(Some(ChannelState {
                kind: Kind::Coin(c, reader),
                ..
            })) = channels.get(usize::from(h.channel_id))
            else {
                return;
            };
            // A message that does not parse is already an integrity problem of the stream's.
            if let Ok(s) = Self::parse(*c, reader, h.log_time, data) {
                assembler.push(*c, &s, &mut |s| checks.observe(s, ctx));
            }
        };
        let messages = structure.summary.messages;
        let why = match read_in_log_time_order(source, structure.summary.file_len, &mut judge) {
            Ok(Some(n)) if n == messages => {
                assembler.finish(&mut |s| checks.observe(s, ctx));
                let cut = self.assembler.cut();
                self.notes.push(format!(
                    "its channels lie far apart in the file (more than {MAX_PENDING} samples): {cut} \
                     samples were incomplete when read in file order, so every sample was judged in \
                     log-time order through the chunk indexes"
                ));
                (self.assembler, self.checks) = (assembler, checks);
                return;
            }
            Ok(Some(n)) => format!("its chunks hold {n} of its {messages} messages"),
            Ok(None) => "it has no summary that lists its chunks".to_string(),
            Err(e) => e.to_string(),
        };
        self.reorder_failed(&why);
    }

    /// Notes that the samples the stream cut were judged in pieces, and `why` they were not read again.
    fn reorder_failed(&mut self, why: &str) {
        let cut = self.assembler.cut();
        self.notes.push(format!(
            "{cut} samples were judged before all their channels had arrived (the file's channels lie \
             more than {MAX_PENDING} samples apart) and it cannot be read in log-time order: {why}; \
             rewrite it with its messages in log-time order to judge every sample whole"
        ));
    }

    /// Why a file without a usable `coin-log` metadata record is not judged.
    fn not_coin_log(&mut self, library: &str) -> String {
        self.run_error.take().unwrap_or_else(|| {
            let by = if library.is_empty() {
                String::new()
            } else {
                format!(" (written by `{library}`)")
            };
            format!("not a coin-log file: it has no `coin-log` metadata record{by}")
        })
    }

    /// Every integrity problem: the reader's, the judge's, the result record's, and the read error's.
    fn all_problems(
        &mut self,
        structure: &Structure,
        ctx: &Context,
        read_whole: bool,
        read_problem: Option<&String>,
    ) -> BoundedFindings {
        if let Some(e) = &self.result_error {
            self.problems
                .push_with(|| format!("the `coin-log.result` metadata is unusable: {e}"));
        }
        if ctx.run.dissipation.is_none() && self.assembler.declared(Channel::Work) {
            self.problems.push_with(|| {
                "the file has /coin/work but its `coin-log` metadata has no dissipation (a conservative run has no dissipated work)".into()
            });
        }
        let stats = &self.checks.stats;
        let (last, interval) = (stats.last_t, 1.0 / ctx.run.rate);
        let judged = read_whole && stats.samples > 0;
        let says = "the `coin-log.result` metadata says termination_time =";
        let problem = match ctx
            .result
            .as_ref()
            .map(|r| (r.termination_time, r.termination))
        {
            None => read_whole.then(|| {
                "no `coin-log.result` metadata record (the run did not finish writing)".to_string()
            }),
            Some((t, _)) if !t.is_finite() || t < 0.0 => {
                Some(format!("{says} {t}, not a finite time ≥ 0"))
            }
            // A run that completed or ended at an event ends at its last sample (`record` writes one
            // there); one that failed or was stopped, before the next grid point (format.md:
            // `coin-log.result`); only a file read whole shows its last sample.
            Some((t, termination))
                if (termination == Termination::Completed || termination.is_event()) && judged =>
            {
                // Rounding of k/rate: far below 1e-12 of the time.
                let slack = 1e-12 * last.abs().max(f64::MIN_POSITIVE);
                ((t - last).abs() > slack).then(|| {
                    format!(
                        "{says} {t}, but the last sample is at t = {last}: a run whose termination \
                         is `{termination}` ends at its last sample"
                    )
                })
            }
            Some((t, _)) if judged && interval.is_finite() => {
                // Rounding of k/rate and of the failing step's time: far below 1e-12 of either.
                let slack = 1e-12 * last.abs().max(interval);
                (!(last - slack..=last + interval + slack).contains(&t)).then(|| {
                    format!(
                        "{says} {t}, but the last sample is at t = {last}: a run ends at its last \
                         sample or, failing, before the next, 1/rate = {interval} later"
                    )
                })
            }
            Some(_) => None,
        };
        if let Some(p) = problem {
            self.problems.push_with(|| p);
        }
        self.termination_alpha(ctx, read_whole);
        let mut problems = structure.problems.clone();
        problems.extend(&self.problems);
        if let Some(p) = read_problem {
            problems.push_with(|| p.clone());
        }
        problems
    }

    /// The result record's `termination_alpha`: α = π/2 − |θ| at the last sample with dissipation (record
    /// computes it from the very θ it stores, so they agree to the rounding of one subtraction), null
    /// without. Judged when the file was read whole and its last sample has the angles.
    fn termination_alpha(&mut self, ctx: &Context, read_whole: bool) {
        let Some(alpha) = ctx.result.as_ref().map(|r| r.termination_alpha) else {
            return;
        };
        let problem = match (
            alpha,
            ctx.run.dissipation.is_some(),
            self.checks.stats.last_theta,
        ) {
            (Some(a), false, _) => format!(
                "the `coin-log.result` metadata says termination_alpha = {a}, but the run has no \
                 dissipation (it is null without)"
            ),
            (None, true, Some(_)) if read_whole => "the `coin-log.result` metadata has no \
                termination_alpha, which a run with dissipation records"
                .to_string(),
            (Some(a), true, Some(theta)) if read_whole => {
                let expected = std::f64::consts::FRAC_PI_2 - theta.abs();
                // One rounding of π/2 − |θ| is below 2.2e-16; 1e-12 as the other recomputed values.
                if (a - expected).abs() <= RECOMPUTE_TOLERANCE {
                    return;
                }
                format!(
                    "the `coin-log.result` metadata says termination_alpha = {a}, but the last sample's \
                     θ = {theta} gives α = π/2 − |θ| = {expected}"
                )
            }
            _ => return,
        };
        self.problems.push_with(|| problem);
    }
}

/// The scene of the `coin-log` record, read and validated as `record` reads a scene file.
fn stored_scene(run: &RunMetadata) -> Result<Scene, String> {
    let file = scene::parse_with_sets(&run.scene, &[])
        .map_err(|e| format!("the metadata's scene does not parse: {e}"))?;
    Scene::from_file(&file).map_err(|e| format!("the metadata's scene is not valid: {e}"))
}

/// Where the `coin-log` record's fields differ from those its own scene gives (`expected`): the body, the
/// run settings the integrator uses, the steady motion, the dissipation. Numbers agree within
/// [`RECOMPUTE_TOLERANCE`] relative (the same computation on the same numbers). Not compared: the versions,
/// the scene text, and the settings the integrator does not use (earlier versions wrote the rounded step
/// for adaptive methods too: `tests/fixtures/wobble-first-version.mcap` has step = 0.00098 with dop853).
fn disagreements(file: &RunMetadata, expected: &RunMetadata) -> Vec<String> {
    let unused: &[&str] = if file.integrator.is_adaptive() {
        &["step"]
    } else {
        &["rtol", "atol"]
    };
    let (file, expected) = (file.to_map(), expected.to_map());
    let keys: BTreeSet<&String> = file.keys().chain(expected.keys()).collect();
    let absent = String::from("(absent)");
    keys.into_iter()
        .filter(|k| !matches!(k.as_str(), "format_version" | "tool_version" | "scene"))
        .filter(|k| !unused.contains(&k.as_str()))
        .filter_map(|k| {
            let (f, e) = (
                file.get(k).unwrap_or(&absent),
                expected.get(k).unwrap_or(&absent),
            );
            let agree = match (f.parse::<f64>(), e.parse::<f64>()) {
                (Ok(x), Ok(y)) => (x - y).abs() <= RECOMPUTE_TOLERANCE * x.abs().max(y.abs()),
                _ => f == e,
            };
            (!agree).then(|| {
                format!("the `coin-log` metadata says {k} = {f}, but the scene it stores gives {e}")
            })
        })
        .collect()
}

impl Visitor for Judge {
    fn channel(
        &mut self,
        id: u16,
        topic: &str,
        message_encoding: &str,
        schema: Option<&Schema<'_>>,
    ) {
        let known = Topic::from_name(topic);
        // MCAP allows several channels on one topic; the contract has one, and a second would be read
        // beside the first unseen (a sample keeps one message per channel of the table).
        if let Some(t) = known {
            let first = *self.topics.entry(t).or_insert(id);
            if first != id {
                self.problems.push_with(|| {
                    format!(
                        "topic `{topic}` is on two channels ({first} and {id}); the contract has one \
                         channel per topic"
                    )
                });
            }
        }
        // A topic of fixed wire form (the CDR robot description) is judged by that form, not by the file's.
        let fixed = known == Some(Topic::RerunRobot);
        let mut judged = match schema {
            Some(s) if fixed => {
                let (encoding, data, _) = ROS_STRING_WIRE;
                if (s.encoding.as_str(), &s.data[..]) != (encoding, data) {
                    self.problems.push_with(|| {
                        format!("topic `{topic}` has a schema other than ROS 2's {ROS_STRING} ({encoding})")
                    });
                }
                SchemaJudged::default()
            }
            Some(s) => self.schema(s),
            None => SchemaJudged::default(),
        };
        let kind = match known {
            None => {
                self.problems
                    .push_with(|| format!("topic `{topic}` is not one of coin-log's"));
                Kind::Unknown
            }
            Some(t) => {
                let schema = schema.map_or("", |s| s.name.as_str());
                if schema != t.schema_name() {
                    self.problems.push_with(|| {
                        format!(
                            "topic `{topic}` has schema `{schema}`, the contract says `{}`",
                            t.schema_name()
                        )
                    });
                }
                let expected = if fixed {
                    ROS_STRING_WIRE.2
                } else {
                    judged.encoding.unwrap_or_default().message_encoding()
                };
                if message_encoding != expected {
                    self.problems.push_with(|| {
                        format!("topic `{topic}` has message encoding {message_encoding:?}, not {expected:?} as its schema's encoding says")
                    });
                }
                match t.channel().message_type() {
                    // The robot description is CDR, whatever the file's encoding: its schema is judged.
                    _ if fixed => Kind::Unknown,
                    Some(m) => {
                        let c = t.channel();
                        self.assembler.declare(c);
                        // A JSON channel is read as its own type, whatever type its schema names.
                        let reader = judged.reader.take();
                        let json = || FieldReader::json(m, judged.first_version);
                        Kind::Coin(c, reader.unwrap_or_else(json))
                    }
                    None => Kind::Foxglove(t.schema_name(), judged.encoding.unwrap_or_default()),
                }
            }
        };
        let i = usize::from(id);
        if self.channels.len() <= i {
            self.channels.resize(i + 1, None);
        }
        self.channels[i] = Some(ChannelState {
            kind,
            topic: topic.to_string(),
            last: None,
        });
    }

    fn metadata(&mut self, name: &str, entries: &BTreeMap<String, String>) {
        if name == RUN_METADATA_NAME {
            if self.ctx.is_some() || self.run_error.is_some() {
                self.problems
                    .push_with(|| "more than one `coin-log` metadata record".into());
                return;
            }
            match self.run_metadata(entries) {
                Ok(ctx) => {
                    // The channels the run recorded are known before the first message (the reader
                    // passes this record on first): a sample waits for all of them, also when a
                    // rewriting tool writes a channel's record only just before its first message,
                    // after the messages of other channels (its samples were judged in pieces).
                    if let Ok(scene) = &ctx.scene {
                        for c in &scene.channels {
                            if c.message_type().is_some() {
                                self.assembler.declare(*c);
                            }
                        }
                    }
                    self.ctx = Some(ctx);
                }
                Err(e) => self.run_error = Some(e),
            }
        } else if name == RESULT_METADATA_NAME {
            match ResultMetadata::from_map(entries) {
                Ok(r) => self.result = Some(r),
                Err(e) => self.result_error = Some(e.to_string()),
            }
        }
    }

    fn message(&mut self, h: &MessageHeader, data: &[u8]) -> ControlFlow<()> {
        // The reader passes every metadata record it can find before the first message: without the
        // `coin-log` one by now, the file has none to judge it by.
        if self.ctx.is_none() {
            return ControlFlow::Break(());
        }
        let Some(Some(channel)) = self.channels.get_mut(usize::from(h.channel_id)) else {
            let id = h.channel_id;
            self.problems.push_with(|| {
                format!("a message on channel {id}, which no channel record declares")
            });
            return ControlFlow::Continue(());
        };
        let (lt, topic) = (h.log_time, &channel.topic);
        if h.publish_time != lt {
            let p = h.publish_time;
            self.problems
                .push_with(|| format!("{topic}: publish_time {p} differs from log_time {lt}"));
        }
        if let Some(last) = channel.last {
            // One coin_log message per sample: strictly increasing. /tf and /scene may carry several
            // messages at one time (the static world → table transform and the coin's at t = 0).
            let strict = matches!(channel.kind, Kind::Coin(..));
            if lt < last || (strict && lt == last) {
                let what = if strict {
                    "increasing"
                } else {
                    "non-decreasing"
                };
                self.problems.push_with(|| {
                    format!("{topic}: log times not {what}: {lt} ns after {last} ns")
                });
            }
        }
        channel.last = Some(lt);
        match &channel.kind {
            Kind::Coin(c, reader) => {
                let s = match Self::parse(*c, reader, lt, data) {
                    Ok(s) => s,
                    Err(e) => {
                        self.problems
                            .push_with(|| format!("{topic}: message at {lt} ns {e}"));
                        return ControlFlow::Continue(());
                    }
                };
                match log_time(s.t) {
                    Ok(expected) if expected == lt => {}
                    Ok(expected) => {
                        let t = s.t;
                        self.problems.push_with(|| {
                            format!("{topic}: log_time {lt} ns is not round(t·1e9) = {expected} ns for t = {t}")
                        });
                    }
                    Err(e) => self.problems.push_with(|| format!("{topic}: {e}")),
                }
                let checks = &mut self.checks;
                let Some(ctx) = self.ctx.as_ref() else {
                    return ControlFlow::Break(());
                };
                self.assembler.push(*c, &s, &mut |s| checks.observe(s, ctx));
            }
            Kind::Foxglove(schema, encoding) => {
                if let Err(e) = foxglove_message(*encoding, schema, data) {
                    self.problems
                        .push_with(|| format!("{topic}: message at {lt} ns {e}"));
                }
            }
            Kind::Unknown => {}
        }
        ControlFlow::Continue(())
    }
}

/// Judges one file. Never fails: an unreadable file is a report with exit code 2 and the reason in
/// [`FileReport::problem`].
#[must_use]
pub fn verify_file(path: &Path, options: &Options) -> FileReport {
    verify_file_with_progress(path, options, &|_| {})
}

/// [`verify_file`], calling `progress` with the bytes read so far (from the reading thread).
#[must_use]
pub fn verify_file_with_progress(
    path: &Path,
    options: &Options,
    progress: &(dyn Fn(u64) + Sync),
) -> FileReport {
    let mut judge = Judge::default();
    let read = coin_log_mcap::read_with_progress(path, &mut judge, progress);
    let shown = path.display().to_string();
    verdict(shown, judge, read, || std::fs::File::open(path), options)
}

/// Judges an MCAP file held in memory, named `name` in the report (for tests and fuzzing).
#[must_use]
pub fn verify_bytes(name: &str, bytes: &[u8], options: &Options) -> FileReport {
    let mut judge = Judge::default();
    let source = std::io::Cursor::new(bytes);
    let read = coin_log_mcap::read_from(source, bytes.len() as u64, &mut judge);
    let again = || Ok(std::io::Cursor::new(bytes));
    verdict(name.to_string(), judge, read, again, options)
}

/// The report on what `judge` read (read `again` in log-time order if the stream judged samples in pieces).
fn verdict<R: Read + Seek>(
    shown: String,
    mut judge: Judge,
    (structure, error): (Structure, Option<ReadError>),
    again: impl FnOnce() -> std::io::Result<R>,
    options: &Options,
) -> FileReport {
    if error.is_none() && judge.assembler.cut() > 0 {
        match again() {
            Ok(source) => judge.reorder(&structure, source),
            Err(e) => judge.reorder_failed(&format!("it cannot be opened again: {e}")),
        }
    }
    let read_whole = error.is_none();
    // A truncated or corrupt file is judged on what could be read, and is unusable (exit 2).
    let read_problem = match ReadError::broken_off(error) {
        Ok(broken) => broken,
        Err(e) => return FileReport::unusable(shown, e.to_string()),
    };
    let Some(mut ctx) = judge.ctx.take() else {
        let why = match (judge.run_error.take(), read_problem) {
            (Some(run), Some(e)) => format!("{run}; {e}"),
            (Some(run), None) => run,
            (None, Some(e)) => format!(
                "{}; no `coin-log` metadata record comes before that point, so there is nothing to \
                 judge",
                e.detail
            ),
            (None, None) => judge.not_coin_log(&structure.summary.library),
        };
        return FileReport::unusable(shown, why);
    };
    ctx.result = judge.result.take();
    let problem = read_problem.as_ref().map(ToString::to_string);
    let checks = &mut judge.checks;
    judge.assembler.finish(&mut |s| checks.observe(s, &ctx));
    let problems = judge.all_problems(&structure, &ctx, read_whole, problem.as_ref());
    let tol = tolerances(&ctx, &judge.checks.stats, options);
    let read = format!(
        "{} messages in {} chunks, {} samples",
        structure.summary.messages, structure.summary.chunks, judge.checks.stats.samples
    );
    let c = &judge.checks;
    let results = vec![
        integrity::finish(&problems, &read, &judge.notes),
        c.energy.finish(&tol, &ctx),
        c.invariants.finish(&tol, &ctx),
        c.steady.finish(&ctx, &tol),
        c.constraint
            .finish(ctx.coin.params().radius(), &tol, c.stats.span()),
        c.consistency.finish(),
        c.validity.finish(&ctx),
        c.nutation.finish(&ctx, &tol, &c.stats),
    ];
    let failed = results.iter().any(|r| r.status == Status::Fail);
    let missing = missing_required(&results);
    let (verdict, problem) = match (problem, failed, missing) {
        (Some(p), _, _) => (Verdict::Unusable, Some(p)),
        (None, true, _) => (Verdict::Failed, None),
        (None, false, Some(why)) => (Verdict::CannotVerify, Some(why)),
        (None, false, None) => (Verdict::Ok, None),
    };
    FileReport {
        path: shown,
        exit_code: verdict.exit_code(),
        verdict,
        problem,
        checks: results,
    }
}

/// The tolerances of this file: derived from its recorded settings and span, or the flags'.
fn tolerances(ctx: &Context, stats: &RunStats, options: &Options) -> Tolerances {
    let run = &ctx.run;
    let method = MethodConfig {
        method: run.integrator,
        rtol: run.rtol,
        atol: run.atol,
        step: run.step,
    };
    let accuracy = RunAccuracy::new(&method, ctx.coin.params(), stats.span(), stats.max_omega);
    Tolerances::derive(&accuracy, options.energy_tol, options.residual_tol)
}

/// Which of the required checks (format.md: verify) could not run, whatever else passed, or `None`; the
/// skipped checks keep their status and their reasons (which say what to record).
fn missing_required(results: &[CheckResult]) -> Option<String> {
    let skipped = |id: CheckId| {
        results
            .iter()
            .any(|r| r.id == id && r.status == Status::Skip)
    };
    let [integrity, energy, constraint, steady] = CheckId::REQUIRED;
    let mut missing: Vec<&str> = [integrity, energy]
        .into_iter()
        .filter(|id| skipped(*id))
        .map(CheckId::name)
        .collect();
    if skipped(constraint) && skipped(steady) {
        missing.push("constraint or steady (the motion)");
    }
    (!missing.is_empty()).then(|| {
        format!(
            "cannot verify: the required check{} {} could not run (each check's reason says why and \
             what to record)",
            if missing.len() > 1 { "s" } else { "" },
            missing.join(", ")
        )
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::format::messages::ReactionMessage;

    #[test]
    fn a_message_reads_as_the_version_of_its_schema() {
        let mut buf = Vec::new();
        let m = ReactionMessage {
            t: 0.5,
            x: 0.1,
            y: -0.2,
            z: 1e-17,
            friction: 3.0,
            normal: 0.75,
            friction_ratio: Some(4.0),
        };
        m.write_json(&mut buf).unwrap();
        let parse = |data, first| {
            let r = FieldReader::json(&ReactionMessage::TYPE, first);
            Judge::parse(Channel::Reaction, &r, 0, data)
        };
        let s = parse(&buf, false).unwrap();
        assert_eq!(s.t.to_bits(), 0.5_f64.to_bits());
        assert_eq!(s.reaction, Some(m));
        // The same message read as the first version (no friction_ratio in its schema) has a field too
        // many; one without it is read without it.
        assert_eq!(
            parse(&buf, true).unwrap_err(),
            "has fields its schema (the first version) does not declare"
        );
        let old = br#"{"t":0.5,"x":0.1,"y":-0.2,"z":1e-17,"friction":3.0,"normal":0.75}"#;
        let s = parse(old, true).unwrap();
        assert!(s.reaction.unwrap().friction_ratio.is_none());
        for c in Channel::ALL {
            let Some(t) = c.message_type() else {
                continue;
            };
            let text: Vec<String> = t.fields.iter().map(|f| format!("\"{f}\":1")).collect();
            let text = format!("{{{}}}", text.join(","));
            let r = FieldReader::json(t, false);
            assert!(Judge::parse(*c, &r, 0, text.as_bytes()).is_ok(), "{text}");
        }
    }
}
