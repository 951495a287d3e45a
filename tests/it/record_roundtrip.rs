//! Recordings read back with the `mcap` crate match the contract and the library's own computation, bit
//! for bit; writing failures surface as errors; the same scene gives the same bytes.
// Helpers outside #[test] functions panic on failure too: a failed step is a failed test.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use crate::support::record::{read_back, record_to_memory, schema_file, validate_flat, ReadBack};
use crate::support::writers::{message_json_with, COIN_CHANNELS};
use crate::support::FailingWriter;
use coin_log::format::{
    log_time, Channel, Encoding, ResultMetadata, RunMetadata, Termination, Topic,
    RESULT_METADATA_NAME, RUN_METADATA_NAME,
};
use coin_log::integrate::{run_method, Flow, MethodConfig, RunSettings};
use coin_log::model::{energy, Chaplygin, Dynamics, State, DISSIPATIVE_STATE_LEN, STATE_LEN};
use coin_log::record::{self, Foxglove3d, FoxgloveBatch, RecordOptions, RecordSummary};
use coin_log::scene::{self, presets, FlagOverrides, Scene};
use coin_log::simulation::{working_atol, CoinEvents};
use coin_log_mcap::Compression;
use std::io::Cursor;
use std::sync::atomic::AtomicBool;

/// Longest duration used here, so that every built-in scene is exercised quickly.
const TEST_DURATION: f64 = 4.0;

fn preset_scene(name: &str, flags: FlagOverrides) -> Scene {
    let file = presets::preset(name).expect("built-in");
    let duration = file
        .run
        .as_ref()
        .and_then(|r| r.duration)
        .expect("duration");
    let flags = FlagOverrides {
        duration: flags.duration.or(Some(duration.min(TEST_DURATION))),
        ..flags
    };
    scene::resolve(&file, &flags).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The samples of a scene's run, (t, y, W), integrated here with the library's integrator on the scene's
/// own equations (W only with dissipation, physics §11).
fn simulated_samples(scene: &Scene) -> Vec<(f64, [f64; STATE_LEN], Option<f64>)> {
    let settings = RunSettings {
        t0: 0.0,
        t_end: scene.run.duration,
        sample_interval: 1.0 / scene.run.rate,
    };
    let (margin, mu) = (scene.run.flat_margin, scene.friction);
    // The tolerance the library integrates to: the scene's, tightened near upright (physics §12).
    let method = MethodConfig {
        atol: working_atol(&scene.run.method, &scene.coin(), &scene.initial),
        ..scene.run.method
    };
    let mut samples = Vec::new();
    match scene.dynamics() {
        Dynamics::Conservative(coin) => {
            let events = CoinEvents::new(coin, margin, mu);
            let y0 = scene.initial.to_array();
            let _ = run_method(&method, &coin, &y0, &settings, &events, |t, y| {
                samples.push((t, *y, None));
                Flow::Continue
            });
        }
        Dynamics::Dissipative(coin) => {
            let events = CoinEvents::new(coin, margin, mu);
            let mut y0 = [0.0; DISSIPATIVE_STATE_LEN];
            y0[..STATE_LEN].copy_from_slice(&scene.initial.to_array());
            let _ = run_method(&method, &coin, &y0, &settings, &events, |t, y| {
                let mut s = [0.0; STATE_LEN];
                s.copy_from_slice(&y[..STATE_LEN]);
                samples.push((t, s, Some(y[STATE_LEN])));
                Flow::Continue
            });
        }
    }
    samples
}

/// The messages the recorder should write, computed here from the model and the message types
/// (`support::writers::message_json_with`, which shares no code with the recorder).
fn expected_messages(scene: &Scene) -> Vec<(Topic, u64, Vec<u8>)> {
    let dynamics = scene.dynamics();
    let coin = scene.coin();
    let samples = simulated_samples(scene);
    let (tf, scene_on) = (scene.records(Channel::Tf), scene.records(Channel::Scene));
    let mut foxglove = Foxglove3d::new(&coin, scene.thickness, &scene.channels, Encoding::Json);
    let mut batch = FoxgloveBatch::default();
    let chaplygin = Chaplygin::new(&scene.params).unwrap();
    let e0 = energy(&coin, &State::from_array(&samples[0].1)).total;
    let mut out = Vec::new();
    let last = samples.len() - 1;
    for (k, (t, y, work)) in samples.iter().enumerate() {
        let (t, s) = (*t, State::from_array(y));
        let ns = log_time(t).expect("log time");
        // The coin_log channels in the contract's table order: work after invariants, before /tf.
        for channel in COIN_CHANNELS.into_iter().chain([Channel::Work]) {
            if scene.records(channel) {
                let data = message_json_with(&dynamics, &chaplygin, channel, t, &s, *work, e0);
                out.push((Topic::Main(channel), ns, data));
            }
        }
        if tf || scene_on {
            batch.clear();
            foxglove.sample(t, ns, &s, k == last, &mut batch).unwrap();
            for (topic, data) in batch.iter() {
                out.push((topic, ns, data.to_vec()));
            }
        }
    }
    out
}

/// The per-sample coin_log channels a scene records (those with exactly one message per sample).
fn per_sample_channels(scene: &Scene) -> Vec<Channel> {
    scene
        .channels
        .iter()
        .copied()
        .filter(|c| !matches!(c, Channel::Tf | Channel::Scene))
        .collect()
}

fn check_recording(name: &str, scene: &Scene, bytes: &[u8], summary: &RecordSummary) {
    let file: ReadBack = read_back(bytes);
    let per_sample = per_sample_channels(scene);

    // Topics: exactly the channels that have messages, each with one message per sample.
    let mut expected_topics: Vec<String> = file
        .messages
        .iter()
        .map(|m| m.topic.clone())
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    expected_topics.sort();
    assert_eq!(
        file.topics(),
        expected_topics,
        "{name}: every registered channel has messages"
    );
    for channel in &per_sample {
        let count = file.on_topic(channel.topic()).len() as u64;
        assert_eq!(
            count,
            summary.samples,
            "{name}: {} has {count} messages, expected one per sample ({})",
            channel.topic(),
            summary.samples
        );
    }
    for topic in &expected_topics {
        let channel = Channel::from_topic(topic).expect("a contract topic");
        assert!(
            scene.records(channel),
            "{name}: {topic} written but not requested"
        );
    }

    // Times: log_time = publish_time = round(t·1e9) of the message's own t, increasing; sequence = index.
    for channel in &per_sample {
        let messages = file.on_topic(channel.topic());
        let mut previous = None;
        for (k, m) in messages.iter().enumerate() {
            let value: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
            let t = value["t"].as_f64().expect("t");
            assert_eq!(
                m.log_time,
                log_time(t).unwrap(),
                "{name}: {} log_time vs t = {t}",
                channel.topic()
            );
            assert_eq!(m.publish_time, m.log_time);
            assert_eq!(
                m.sequence as usize, k,
                "{name}: sequence numbers count the channel's messages"
            );
            if let Some(p) = previous {
                assert!(
                    m.log_time > p,
                    "{name}: {} log times increase: {} then {}",
                    channel.topic(),
                    p,
                    m.log_time
                );
            }
            previous = Some(m.log_time);
        }
    }

    // Schemas: the bytes of the files in schemas/.
    for (schema_name, data) in &file.schemas {
        assert_eq!(
            data,
            &schema_file(schema_name),
            "{name}: schema {schema_name} differs from schemas/{schema_name}.json"
        );
    }

    // Statistics equal the counts.
    let stats = file.summary.stats.as_ref().expect("statistics");
    assert_eq!(stats.message_count, file.messages.len() as u64);
    assert_eq!(stats.message_count, summary.messages);
    for (id, channel) in &file.summary.channels {
        let counted = file.on_topic(&channel.topic).len() as u64;
        assert_eq!(
            stats.channel_message_counts.get(id).copied().unwrap_or(0),
            counted,
            "{name}: statistics of {}",
            channel.topic
        );
    }
    assert!(
        !file.summary.chunk_indexes.is_empty(),
        "{name}: chunk indexes present"
    );
    assert_eq!(summary.bytes, bytes.len() as u64);

    // Values: bit for bit what the library computes.
    let expected = expected_messages(scene);
    assert_eq!(
        file.messages.len(),
        expected.len(),
        "{name}: message count vs re-simulation"
    );
    for (k, (m, (channel, ns, data))) in file.messages.iter().zip(&expected).enumerate() {
        assert_eq!(m.topic, channel.name(), "{name}: message {k} topic");
        assert_eq!(m.log_time, *ns, "{name}: message {k} log time");
        assert!(
            m.data == *data,
            "{name}: message {k} on {}: file {} vs computed {}",
            m.topic,
            String::from_utf8_lossy(&m.data),
            String::from_utf8_lossy(data)
        );
    }

    // Metadata: `coin-log` before the first chunk, `coin-log.result` after; both parse.
    let (run_offset, run_map) = file
        .metadata
        .get(RUN_METADATA_NAME)
        .expect("coin-log metadata");
    let first_chunk = file
        .summary
        .chunk_indexes
        .iter()
        .map(|c| c.chunk_start_offset)
        .min()
        .unwrap();
    assert!(
        *run_offset < first_chunk,
        "{name}: coin-log metadata at {run_offset}, first chunk at {first_chunk}"
    );
    let run = RunMetadata::from_map(run_map).expect("coin-log metadata parses");
    assert_eq!(run, scene.run_metadata());
    let back = scene::parse_with_sets(&run.scene, &[])
        .and_then(|f| Scene::from_file(&f))
        .expect("scene metadata parses");
    assert_eq!(
        &back, scene,
        "{name}: the scene in the metadata reads back to the same scene"
    );
    let (_, result_map) = file
        .metadata
        .get(RESULT_METADATA_NAME)
        .expect("coin-log.result metadata");
    let result = ResultMetadata::from_map(result_map).expect("coin-log.result parses");
    assert_eq!(result.termination, summary.termination);
    assert_eq!(
        result.termination_time.to_bits(),
        summary.termination_time.to_bits()
    );
    assert_eq!(result.steps, summary.stats.steps);
    println!(
        "{name:<18} {:>6} samples {:>7} messages {:>8} bytes, termination {} at t = {}, energy drift {:.2e}, C1/C2 drift {:?}",
        summary.samples, summary.messages, summary.bytes, summary.termination.name(), summary.termination_time, summary.energy_drift, summary.invariant_drift
    );
    // With dissipation C1, C2 are not conserved, so there is no drift to report (physics §11).
    assert_eq!(
        summary.invariant_drift.is_some(),
        scene.records(Channel::Invariants) && scene.dissipation.is_none()
    );
}

#[test]
fn every_built_in_scene_reads_back_as_the_contract_and_the_library_say() {
    for name in presets::NAMES {
        let scene = preset_scene(name, FlagOverrides::default());
        let (bytes, summary) = record_to_memory(&scene, &RecordOptions::default());
        check_recording(name, &scene, &bytes, &summary);
    }
}

#[test]
fn every_compression_gives_a_readable_file_with_the_same_messages() {
    let scene = preset_scene(
        "wobble",
        FlagOverrides {
            duration: Some(2.0),
            ..FlagOverrides::default()
        },
    );
    let mut all = Vec::new();
    for &compression in Compression::ALL {
        let (bytes, summary) = record_to_memory(
            &scene,
            &RecordOptions {
                compression,
                ..RecordOptions::default()
            },
        );
        check_recording(compression.name(), &scene, &bytes, &summary);
        let messages: Vec<Vec<u8>> = read_back(&bytes)
            .messages
            .into_iter()
            .map(|m| m.data)
            .collect();
        println!("{compression}: {} bytes", bytes.len());
        all.push(messages);
    }
    assert!(all.windows(2).all(|w| w[0] == w[1]));
}

#[test]
fn a_scene_records_only_its_channels() {
    let scene = preset_scene(
        "circle-plus",
        FlagOverrides {
            channels: Some(vec!["energy".into(), "omega".into()]),
            ..FlagOverrides::default()
        },
    );
    let (bytes, summary) = record_to_memory(&scene, &RecordOptions::default());
    let file = read_back(&bytes);
    println!(
        "topics {:?}, schemas {:?}",
        file.topics(),
        file.schemas.keys().collect::<Vec<_>>()
    );
    assert_eq!(
        file.topics(),
        vec!["/coin/energy".to_string(), "/coin/omega".to_string()]
    );
    assert_eq!(file.schemas.len(), 2);
    assert_eq!(summary.messages, 2 * summary.samples);
    check_recording("circle-plus (omega, energy)", &scene, &bytes, &summary);
}

#[test]
fn the_same_scene_gives_the_same_bytes() {
    let scene = preset_scene("wobble", FlagOverrides::default());
    let (a, _) = record_to_memory(&scene, &RecordOptions::default());
    let (b, _) = record_to_memory(&scene, &RecordOptions::default());
    println!("two recordings: {} and {} bytes", a.len(), b.len());
    assert!(a == b, "recordings differ");
}

#[test]
fn every_coin_log_message_validates_against_its_schema_file() {
    let scene = preset_scene("wobble", FlagOverrides::default());
    let (bytes, _) = record_to_memory(&scene, &RecordOptions::default());
    let file = read_back(&bytes);
    let mut checked = std::collections::BTreeMap::<String, usize>::new();
    for m in file
        .messages
        .iter()
        .filter(|m| m.schema_name.starts_with("coin_log."))
    {
        let schema: serde_json::Value =
            serde_json::from_slice(&schema_file(&m.schema_name)).unwrap();
        if let Err(e) = validate_flat(&schema, &m.data) {
            panic!(
                "{} message {} fails {}: {e}",
                m.topic,
                String::from_utf8_lossy(&m.data),
                m.schema_name
            );
        }
        *checked.entry(m.schema_name.clone()).or_default() += 1;
    }
    println!("validated: {checked:?}");
    assert!(
        checked.len() >= 6,
        "every coin_log schema exercised: {checked:?}"
    );
}

#[test]
fn a_message_with_a_missing_or_an_extra_field_fails_validation() {
    let schema: serde_json::Value =
        serde_json::from_slice(&schema_file("coin_log.Energy")).unwrap();
    let good =
        br#"{"t":0.5,"total":1.0,"kinetic":0.25,"potential":0.75,"change":0.0,"drift_eps":0.0}"#;
    let missing = br#"{"t":0.5,"total":1.0,"kinetic":0.25,"change":0.0,"drift_eps":0.0}"#;
    let extra = br#"{"t":0.5,"total":1.0,"kinetic":0.25,"potential":0.75,"change":0.0,"drift_eps":0.0,"spin":2}"#;
    let string =
        br#"{"t":0.5,"total":"1","kinetic":0.25,"potential":0.75,"change":0.0,"drift_eps":0.0}"#;
    println!("good: {:?}", validate_flat(&schema, good));
    println!("missing: {:?}", validate_flat(&schema, missing));
    println!("extra: {:?}", validate_flat(&schema, extra));
    println!("string: {:?}", validate_flat(&schema, string));
    assert!(validate_flat(&schema, good).is_ok());
    assert!(validate_flat(&schema, missing)
        .unwrap_err()
        .contains("potential"));
    assert!(validate_flat(&schema, extra).unwrap_err().contains("spin"));
    assert!(validate_flat(&schema, string).is_err());
}

#[test]
fn a_write_failure_at_any_point_is_an_error_not_a_file() {
    let scene = preset_scene("wobble", FlagOverrides::default());
    let (full, _) = record_to_memory(&scene, &RecordOptions::default());
    let size = full.len() as u64;
    for limit in [0, 10, 100, 1_000, 100_000, size / 2, size - 100, size - 1] {
        let writer = FailingWriter::new(limit);
        let result = record::record(
            &scene,
            &RecordOptions::default(),
            writer,
            &AtomicBool::new(false),
            |_| {},
        );
        match result {
            Err(e) => {
                let mut chain = e.to_string();
                let mut source = std::error::Error::source(&e);
                while let Some(cause) = source {
                    chain.push_str(&format!(": {cause}"));
                    source = cause.source();
                }
                println!("fails after {limit} of {size} bytes: {chain}");
                assert!(
                    chain.contains("no space left on device (test)"),
                    "the cause is kept: {chain}"
                );
            }
            Ok(s) => panic!("a writer failing after {limit} of {size} bytes gave a summary: {s:?}"),
        }
    }
    let writer = FailingWriter::new(size);
    assert!(record::record(
        &scene,
        &RecordOptions::default(),
        writer,
        &AtomicBool::new(false),
        |_| {}
    )
    .is_ok());
}

#[test]
fn a_raised_stop_flag_finishes_the_file_marked_interrupted() {
    let scene = preset_scene("wobble", FlagOverrides::default());
    let mut cursor = Cursor::new(Vec::new());
    let summary = record::record(
        &scene,
        &RecordOptions::default(),
        &mut cursor,
        &AtomicBool::new(true),
        |_| {},
    )
    .unwrap();
    let file = read_back(cursor.get_ref());
    let result = ResultMetadata::from_map(&file.metadata[RESULT_METADATA_NAME].1).unwrap();
    println!(
        "samples {}, termination {} at {}",
        summary.samples, result.termination, result.termination_time
    );
    assert_eq!(summary.termination, Termination::Interrupted);
    assert_eq!(result.termination, Termination::Interrupted);
    assert_eq!(summary.samples, 1);
    assert_eq!(file.on_topic("/coin/omega").len(), 1);
}

#[test]
fn a_run_ended_by_an_event_writes_a_last_sample_at_the_event_time() {
    for (name, event) in [("topple", "flat-landing"), ("lift-off", "lift-off")] {
        let scene = preset_scene(
            name,
            FlagOverrides {
                duration: Some(30.0),
                ..FlagOverrides::default()
            },
        );
        let (bytes, summary) = record_to_memory(&scene, &RecordOptions::default());
        let file = read_back(&bytes);
        let last = file
            .on_topic("/coin/angles")
            .last()
            .map(|m| m.log_time)
            .unwrap();
        println!(
            "{name}: {} at t = {}, last sample at {last} ns",
            summary.termination.name(),
            summary.termination_time
        );
        assert_eq!(summary.termination.name(), event);
        assert_eq!(last, log_time(summary.termination_time).unwrap());
        check_recording(name, &scene, &bytes, &summary);
    }
}

/// `wobble` with rk4 and the initial ω replaced by `omega` after validation: scene validation refuses such
/// states (tests/it/cli_record.rs checks that), but the recorder must still end cleanly on one.
fn wobble_rk4_with_omega(omega: [f64; 3]) -> Scene {
    let file = presets::preset("wobble").unwrap();
    let mut scene = scene::resolve(
        &file,
        &FlagOverrides {
            integrator: Some("rk4".into()),
            ..FlagOverrides::default()
        },
    )
    .unwrap();
    [
        scene.initial.omega_x,
        scene.initial.omega_y,
        scene.initial.omega_z,
    ] = omega;
    scene
}

#[test]
fn a_sample_that_cannot_be_written_whole_is_not_written_at_all() {
    // ω_Z = 1e200: the state is finite but its energy overflows, so the first sample cannot be formatted.
    let scene = wobble_rk4_with_omega([0.0, 0.0, 1e200]);
    let (bytes, summary) = record_to_memory(&scene, &RecordOptions::default());
    let back = read_back(&bytes);
    println!(
        "termination {}: {:?}; {} samples, {} messages",
        summary.termination.name(),
        summary.termination,
        summary.samples,
        back.messages.len()
    );
    assert_eq!(summary.termination.name(), "non-finite");
    assert_eq!(
        (summary.samples, summary.messages, back.messages.len()),
        (0, 0, 0)
    );
    assert!(back.topics().is_empty(), "no channel without messages");
}

/// A numerical failure finishes the file with the samples up to it, marked `non-finite` (format.md:
/// Metadata records). ω_Z = 1e150 is finite, but the first rk4 step overflows.
#[test]
fn a_numerical_failure_finishes_the_file_with_the_samples_up_to_it() {
    let scene = wobble_rk4_with_omega([0.0, 0.0, 1e150]);
    let (bytes, summary) = record_to_memory(&scene, &RecordOptions::default());
    let file = read_back(&bytes);
    let result = ResultMetadata::from_map(&file.metadata[RESULT_METADATA_NAME].1).unwrap();
    println!(
        "termination {} at {} ({:?}), {} messages",
        result.termination,
        result.termination_time,
        summary.failure,
        file.messages.len()
    );
    assert_eq!(result.termination, Termination::NonFinite);
    assert!(summary.failure.is_some(), "the summary carries the failure");
    assert_eq!(
        file.on_topic("/coin/omega").len(),
        1,
        "the sample at t = 0 is in the file"
    );
    // Its termination_time is the failing step's, which verify accepts (within a sample of the last).
    let report = coin_log::verify::verify_bytes("failed.mcap", &bytes, &Default::default());
    let integrity = report.check(coin_log::verify::CheckId::Integrity).unwrap();
    assert_eq!(
        integrity.status,
        coin_log::verify::Status::Pass,
        "{}",
        integrity.reason
    );
}

/// The message types alone: strict reading, exact writing, the fields in schema order.
mod messages {
    use coin_log::format::messages::{
        Angles, AngularVelocity, EnergyMessage, InvariantsMessage, Message, Position,
        QuaternionMessage, ReactionMessage,
    };

    #[test]
    fn messages_round_trip_bit_for_bit_through_json() {
        let m = EnergyMessage {
            t: 0.01,
            total: 1.0 / 3.0,
            kinetic: -0.0,
            potential: 1e-300,
            change: Some(-2.5e-17),
            drift_eps: Some(-3.0),
        };
        let mut buf = Vec::new();
        m.write_json(&mut buf).unwrap();
        let back: EnergyMessage = serde_json::from_slice(&buf).unwrap();
        assert_eq!(format!("{back:?}"), format!("{m:?}"));
        assert_eq!(back.total.to_bits(), m.total.to_bits());
        assert_eq!(back.change.map(f64::to_bits), m.change.map(f64::to_bits));
    }

    #[test]
    fn a_message_of_the_first_version_parses_without_its_added_fields_and_writes_back_the_same() {
        let old = r#"{"t":0.5,"total":1.75,"kinetic":0.75,"potential":1}"#;
        let m: EnergyMessage = serde_json::from_str(old).unwrap();
        assert_eq!(m.change, None);
        assert!(!m.is_complete());
        let mut buf = Vec::new();
        m.write_json(&mut buf).unwrap();
        assert_eq!(
            String::from_utf8(buf).unwrap(),
            r#"{"t":0.5,"total":1.75,"kinetic":0.75,"potential":1.0}"#
        );
        // An added field is a number: `null` is refused, not read as absent.
        let null = r#"{"t":0.5,"total":1.75,"kinetic":0.75,"potential":1,"change":null}"#;
        assert!(serde_json::from_str::<EnergyMessage>(null).is_err());
        assert_eq!(
            EnergyMessage::TYPE.fields,
            &["t", "total", "kinetic", "potential", "change", "drift_eps"]
        );
        assert_eq!(
            EnergyMessage::TYPE.first_fields,
            &["t", "total", "kinetic", "potential"]
        );
    }

    /// The readers' fast path reads the fields in the order the recorder writes them.
    #[test]
    fn the_fields_are_in_schema_order() {
        for (fields, expected) in [
            (AngularVelocity::TYPE.fields, &["t", "x", "y", "z"][..]),
            (Position::TYPE.fields, &["t", "x", "y", "z"]),
            (
                Angles::TYPE.fields,
                &["t", "theta", "phi", "psi", "phi_dot"],
            ),
            (QuaternionMessage::TYPE.fields, &["t", "x", "y", "z", "w"]),
            (InvariantsMessage::TYPE.fields, &["t", "c1", "c2"]),
            (
                ReactionMessage::TYPE.fields,
                &["t", "x", "y", "z", "friction", "normal", "friction_ratio"],
            ),
        ] {
            assert_eq!(fields, expected);
        }
    }

    /// A NaN field, or an infinite added one, is refused by name and leaves the buffer alone.
    #[test]
    fn non_finite_numbers_are_refused_and_leave_the_buffer_alone() {
        let omega = AngularVelocity {
            t: 0.0,
            x: f64::NAN,
            y: 0.0,
            z: 0.0,
        };
        let reaction = ReactionMessage {
            t: 0.0,
            x: 0.0,
            y: 1.0,
            z: 0.0,
            friction: 0.0,
            normal: 1.0,
            friction_ratio: Some(f64::INFINITY),
        };
        let mut buf = b"x".to_vec();
        assert_eq!(omega.write_json(&mut buf).unwrap_err().field, "x");
        assert_eq!(
            reaction.write_json(&mut buf).unwrap_err().field,
            "friction_ratio"
        );
        assert_eq!(buf, b"x");
    }

    #[test]
    fn unknown_and_missing_fields_are_rejected() {
        assert!(
            serde_json::from_str::<InvariantsMessage>(r#"{"t":0,"c1":1,"c2":2,"c3":3}"#).is_err()
        );
        assert!(serde_json::from_str::<InvariantsMessage>(r#"{"t":0,"c1":1}"#).is_err());
    }
}
