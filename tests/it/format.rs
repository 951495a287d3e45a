//! The file format's types on their own (`coin_log::format`): the names of encodings, channels, topics and
//! terminations round-trip, the one time conversion is exact and monotone, and the tolerances and what
//! `record` promises follow from a run's settings.

#![allow(clippy::unwrap_used)]

use coin_log::format::promise::{
    check_list, dense_output_share, shortfalls, Cause, FixedSteps, Positions,
};
use coin_log::format::tolerances::{RunAccuracy, Tolerances};
use coin_log::format::{log_time, schema_data, Channel, Encoding, Termination, Topic};
use coin_log::integrate;
use proptest::prelude::*;

#[test]
fn encoding_names_round_trip_and_unknown_names_are_refused() {
    for &e in Encoding::ALL {
        assert_eq!(e.name().parse::<Encoding>(), Ok(e));
        assert_eq!(Encoding::from_schema_encoding(e.schema_encoding()), Some(e));
    }
    assert_eq!(
        "cbor".parse::<Encoding>().unwrap_err().to_string(),
        "unknown encoding `cbor`; valid: json, protobuf"
    );
    assert_eq!(Encoding::from_schema_encoding("ros2msg"), None);
}

#[test]
fn topics_have_distinct_names_and_dense_indexes() {
    let all: Vec<Topic> = Topic::all().collect();
    assert_eq!(all.len(), Topic::COUNT);
    for (i, t) in all.iter().enumerate() {
        assert_eq!(t.index(), i, "{t}");
        assert_eq!(Topic::from_name(t.name()), Some(*t));
        for &e in t.channel().encodings() {
            assert!(t.wire(e).is_some(), "{t} {e}");
            if *t != Topic::RerunRobot {
                assert!(schema_data(t.schema_name(), e).is_some(), "{t} {e}");
            }
        }
    }
    let names: std::collections::BTreeSet<&str> = all.iter().map(|t| t.name()).collect();
    assert_eq!(names.len(), all.len());
    assert_eq!(Channel::from_topic("/scene/track/15"), Some(Channel::Scene));
    assert_eq!(Channel::from_topic("/tf_static"), Some(Channel::Tf));
    assert_eq!(Channel::from_topic("/scene/track/16"), None);
    assert_eq!(Channel::from_topic("/rerun/track"), Some(Channel::Rerun));
    assert_eq!(
        Topic::RerunTrack.wire(Encoding::Json),
        None,
        "Rerun reads Protobuf"
    );
    assert!(!Channel::DEFAULT.contains(&Channel::Rerun));
    assert!(!Channel::DEFAULT.contains(&Channel::Work));
    assert_eq!(Channel::DEFAULT.len(), 10);
}

#[test]
fn termination_names_round_trip_and_unknown_names_are_refused() {
    for &t in Termination::ALL {
        assert_eq!(t.name().parse::<Termination>(), Ok(t));
        assert_eq!(t.to_string(), t.name());
    }
    assert!("finished".parse::<Termination>().is_err());
    assert_eq!(Termination::ALL.iter().filter(|t| t.is_event()).count(), 3);
}

#[test]
fn events_map_to_their_termination() {
    for (index, expected) in [
        (0, Termination::FlatLanding),
        (1, Termination::LiftOff),
        (2, Termination::Slip),
    ] {
        let end = integrate::RunEnd::Event { index, t: 1.0 };
        assert_eq!(Termination::of_run(&end), expected);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, rng_seed: proptest::test_runner::RngSeed::Fixed(11), ..ProptestConfig::default() })]

    /// Whole nanoseconds below 2^50 ns (1.1e6 time units, far beyond any run) convert exactly: there
    /// the two roundings of t = ns/1e9 and t·1e9 stay below half a nanosecond.
    #[test]
    fn whole_nanoseconds_convert_exactly(ns in 0u64..(1u64 << 50)) {
        #[allow(clippy::cast_precision_loss)]
        let t = ns as f64 / 1e9;
        prop_assert_eq!(log_time(t).unwrap(), ns);
    }

    /// The conversion never decreases: t1 ≤ t2 gives log_time(t1) ≤ log_time(t2).
    #[test]
    fn the_conversion_is_monotone(a in 0.0f64..1.8e10, b in 0.0f64..1.8e10) {
        let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
        prop_assert!(log_time(lo).unwrap() <= log_time(hi).unwrap());
    }
}

#[test]
fn non_finite_negative_and_huge_times_are_refused() {
    for t in [f64::NAN, f64::INFINITY, -1e-12, -1.0, 1.8e10, 1e300] {
        assert!(log_time(t).is_err(), "{t}");
    }
}

/// A centre that starts at the origin, heading 0 and not turning, sampled at rate 100.
const AT_ORIGIN: Positions = Positions {
    offset: 0.0,
    sample_interval: 0.01,
    heading: 0.0,
    heading_rate: 0.0,
};

fn promise_run(integrator: &str, rtol: f64, step: f64, span: f64) -> RunAccuracy {
    RunAccuracy {
        integrator: integrator.parse().unwrap(),
        rtol,
        atol: rtol,
        step,
        radius: 1.0,
        time_unit: 1.0,
        span,
        max_omega: 1.5,
    }
}

/// The defaults promise everything; the cases (rtol 1e-3, rk4 at step 0.1, 1e9 steps of rk4)
/// do not, each for its reason.
#[test]
fn loose_settings_and_very_many_steps_are_predicted_to_fail() {
    assert!(shortfalls(&promise_run("dop853", 1e-10, 0.0, 30.0), None, AT_ORIGIN).is_empty());
    let fixed = |steps: f64, sample_interval: f64| {
        Some(FixedSteps {
            steps,
            sample_interval,
        })
    };
    assert!(shortfalls(
        &promise_run("rk4", 0.0, 1e-3, 30.0),
        fixed(3e4, 0.01),
        AT_ORIGIN
    )
    .is_empty());
    let loose = shortfalls(&promise_run("dop853", 1e-3, 0.0, 30.0), None, AT_ORIGIN);
    println!("{}", loose[0]);
    assert_eq!(
        check_list(&loose, ","),
        "energy,invariants,constraint,steady,nutation"
    );
    let long = shortfalls(
        &promise_run("rk4", 0.0, 0.1, 30.0),
        fixed(300.0, 1.0),
        AT_ORIGIN,
    );
    assert!(matches!(long[0].cause, Cause::Accuracy { .. }), "{long:?}");
    let many = shortfalls(
        &promise_run("rk4", 0.0, 1e-12, 1e-3),
        fixed(1e9, 1e-3),
        AT_ORIGIN,
    );
    println!("{}", many[0]);
    assert!(matches!(many[0].cause, Cause::Rounding { .. }), "{many:?}");
    assert_eq!(check_list(&many, ","), "energy,invariants");
    let dense = shortfalls(
        &promise_run("rk4", 0.0, 1e-9, 1e-3),
        fixed(1e6, 1e-9),
        AT_ORIGIN,
    );
    assert_eq!(check_list(&dense, ","), "constraint,steady");
}

/// An adaptive method's dense output, differenced for the constraint, errs by about ε^((p−1)/p):
/// `wobble` at rtol 1e-7 (dop853) failed `constraint` at 1.67e-6 against 1e-6 with nothing predicted.
/// The suggested ε is enough, a run shorter than a step is not blamed, and fixed-step methods are not
/// concerned.
#[test]
fn the_dense_output_of_loose_adaptive_runs_is_predicted_to_fail_the_constraint() {
    for (integrator, rtol) in [("dop853", 1e-7), ("dopri5", 1e-8)] {
        let run = promise_run(integrator, rtol, 0.0, 30.0);
        let loose = shortfalls(&run, None, AT_ORIGIN);
        println!("{}", loose[0]);
        assert_eq!(check_list(&loose, ","), "constraint,steady", "{integrator}");
        let Cause::DenseOutput { enough, .. } = loose[0].cause else {
            panic!("{integrator}: {loose:?}");
        };
        let tight = RunAccuracy {
            rtol: enough,
            atol: enough,
            ..run
        };
        assert!(
            shortfalls(&tight, None, AT_ORIGIN).is_empty(),
            "{integrator} at {enough}"
        );
    }
    // Within the measured share: dop853 at 1e-9 reached 2.9e-8 on `wobble`, dopri5 at 1e-9 4.7e-7 on
    // `five-hundred-yen`.
    for integrator in ["dop853", "dopri5"] {
        let run = promise_run(integrator, 1e-9, 0.0, 30.0);
        assert!(shortfalls(&run, None, AT_ORIGIN).is_empty(), "{integrator}");
    }
    // One step covers a run of 1e-3 time units: its dense output is not differenced across steps.
    let short = promise_run("dopri5", 1e-10, 0.0, 1e-3);
    assert!(shortfalls(&short, None, AT_ORIGIN).is_empty());
    assert_eq!(dense_output_share("rk4".parse().unwrap()), 0.0);
}

fn tolerance_run(integrator: &str, rtol: f64, span: f64) -> RunAccuracy {
    RunAccuracy {
        integrator: integrator.parse().unwrap(),
        rtol,
        atol: 1e-12,
        step: 1e-3,
        radius: 1.0,
        time_unit: 1.0,
        span,
        max_omega: 1.0,
    }
}

#[test]
fn defaults_follow_the_formula_from_the_settings_the_method_uses() {
    let close = |x: f64, want: f64| (x - want).abs() < 1e-12 * want;
    // Never looser than the contract ceilings.
    let t = Tolerances::derive(&tolerance_run("dop853", 1e-3, 1e4), None, None);
    assert_eq!((t.energy, t.residual), (1e-6, 1e-6));
    // ε = max(rtol, atol/a) = 1e-12 (atol dominates), T/τ = 9: 100·1e-12·10 and 1000·1e-12·10.
    let t = Tolerances::derive(&tolerance_run("dop853", 1e-13, 9.0), None, None);
    assert!(close(t.energy, 1e-9) && close(t.residual, 1e-8), "{t:?}");
    // rk4 counts its step (1e-3, Ω = 1: ε = 1e-12) whatever rtol, dop853 its rtol whatever the step.
    for rtol in [1e-14, 1e-3] {
        let rk4 = Tolerances::derive(&tolerance_run("rk4", rtol, 0.0), None, None);
        assert!(close(rk4.epsilon, 1e-12), "rk4 with rtol {rtol}: {rk4:?}");
    }
    let step_1 = RunAccuracy {
        step: 1.0,
        ..tolerance_run("dop853", 1e-10, 0.0)
    };
    let dop853 = Tolerances::derive(&step_1, None, None);
    assert!(
        close(dop853.epsilon, 1e-10),
        "dop853 with step 1: {dop853:?}"
    );
    // The flags override the defaults.
    let t = Tolerances::derive(&tolerance_run("dop853", 1e-10, 1.0), Some(0.5), Some(0.25));
    assert_eq!((t.energy, t.residual), (0.5, 0.25));
}
