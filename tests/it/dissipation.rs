//! Dissipation (physics §11): the couple −P ω/|ω|² lowers E at exactly the rate P along the equations
//! (property test), vanishes without changing the conservative equations, and a recording of a dissipative
//! scene agrees with the independent Newton–Euler model carrying the same couple (to 1e-8 in θ); the
//! `euler-disk` scene keeps E + W = E₀ to 1e-10 and verifies, a perturbed W fails `verify`, μ = 0.3 ends the
//! run at a located slip; scene keys and channels are validated with clear errors; `bench euler` fits every
//! preset's exponent within 2 % of 1/(1 − p).

// Helpers outside #[test] functions unwrap too: a failed unwrap is a failed test.
#![allow(clippy::unwrap_used)]

use crate::support::newton_euler::{Couple, Dissipating, NewtonEuler, NE_LEN};
use crate::support::physics::{self, rate_unit};
use crate::support::record::{coin_log_text, read_back, record_scene, record_to_memory};
use crate::support::writers::{nudge, rewrite};
use coin_log::format::metadata::DISSIPATION_KEYS;
use coin_log::format::{Channel, RESULT_METADATA_NAME, RUN_METADATA_NAME};
use coin_log::model::{
    energy, Coin, CoinParams, Dissipation, DissipationModel, DissipativeCoin,
    DISSIPATIVE_STATE_LEN, STATE_LEN, WORK_INDEX,
};
use coin_log::record::RecordOptions;
use coin_log::scene::{self, presets, Scene, SceneError};
use coin_log::verify::{verify_bytes, verify_file, CheckId, FileReport, Options, Status};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

/// Round-off bound of dE/dt + P relative to the largest term of the sum (O(10) operations: 1e-13).
const ROUND_OFF: f64 = 1e-13;

fn config() -> Config {
    Config {
        cases: 128,
        rng_seed: RngSeed::Fixed(0x00d1_5519),
        failure_persistence: None,
        ..Config::default()
    }
}

/// A random law for body `p`: m in [1, 3], k in [−2, 2], κ up to 2 Mga (g/a)^((1−m)/2), the size that
/// makes P comparable to Mga √(g/a) at rates of order √(g/a).
fn law(p: &CoinParams, c: f64, m: f64, k: f64) -> Dissipation {
    let kappa = c * p.energy_scale() * rate_unit(p).powf(1.0 - m);
    Dissipation::new(DissipationModel::PowerLaw, kappa, m, k).unwrap()
}

/// dE/dt along `dydt` at `y`, from the gradient of E (physics §3) written out here:
/// ∂E/∂θ = −Mga sin θ, ∂E/∂ω = ((I_X + Ma²) ω_X, I_X ω_Y, (I_Z + Ma²) ω_Z). Returns (dE/dt, the largest
/// term's magnitude).
fn energy_rate(p: &CoinParams, y: &[f64], dydt: &[f64]) -> (f64, f64) {
    let terms = [
        -p.energy_scale() * y[0].sin() * dydt[0],
        (p.inertia_x() + p.ma2()) * y[3] * dydt[3],
        p.inertia_x() * y[4] * dydt[4],
        (p.inertia_z() + p.ma2()) * y[5] * dydt[5],
    ];
    let scale = terms.iter().map(|t| t.abs()).fold(0.0, f64::max);
    (terms.iter().sum(), scale)
}

proptest! {
    #![proptest_config(config())]

    /// dE/dt = −P = −Ẇ exactly along eqs (31)–(34), for any body, state and law: the conservative terms
    /// cancel to round-off and the couple removes exactly P.
    #[test]
    fn the_energy_falls_at_exactly_the_dissipated_power(
        p in physics::random_body(),
        (theta, wx, wy, wz) in (-1.4..1.4, -5.0..5.0, -5.0..5.0, -5.0..5.0),
        (c, m, k) in (0.0..2.0, 1.0..3.0, -2.0..2.0),
    ) {
        let w = rate_unit(&p);
        let law = law(&p, c, m, k);
        let coin = DissipativeCoin::new(Coin::new(p), law);
        let y = [theta, 0.3, -0.2, wx * w, wy * w, wz * w, 0.1, -0.2, 0.0];
        let mut dydt = [0.0; DISSIPATIVE_STATE_LEN];
        coin.derivative(&y, &mut dydt);
        let power = law.power(theta, wy * w);
        prop_assert_eq!(dydt[WORK_INDEX], power);
        let (rate, scale) = energy_rate(&p, &y, &dydt);
        let residual = (rate + power).abs() / scale.max(power);
        prop_assert!(residual <= ROUND_OFF, "dE/dt = {rate:e}, P = {power:e}: relative residual {residual:e} > {ROUND_OFF:e}");
    }
}

/// Negative control of the property: the conservative equations at the same state keep E (dE/dt = 0), so
/// they miss P by P itself, far above the round-off bound.
#[test]
fn the_conservative_equations_miss_the_dissipated_power() {
    let p = physics::general();
    let law = law(&p, 1.0, 2.0, 1.0);
    let s = physics::wobbling(&p);
    let mut dydt = [0.0; STATE_LEN];
    Coin::new(p).derivative(&s.to_array(), &mut dydt);
    let (rate, scale) = energy_rate(&p, &s.to_array(), &dydt);
    let power = law.power(s.theta, s.omega_y);
    let residual = (rate + power).abs() / scale.max(power);
    println!("conservative: dE/dt = {rate:e}, P = {power:e}, relative residual {residual:e}");
    assert!(residual > 1e6 * ROUND_OFF, "residual {residual:e}");
}

/// κ = 0: the dissipative equations are the conservative ones, bit for bit, and W stays 0.
#[test]
fn a_zero_coefficient_gives_the_conservative_equations_bit_for_bit() {
    for p in [
        physics::unit_disk(),
        physics::unit_hoop(),
        physics::general(),
    ] {
        let law = Dissipation::preset(DissipationModel::Moffatt, 0.0).unwrap();
        let s = physics::wobbling(&p);
        let mut conservative = [0.0; STATE_LEN];
        Coin::new(p).derivative(&s.to_array(), &mut conservative);
        let mut y = [0.0; DISSIPATIVE_STATE_LEN];
        y[..STATE_LEN].copy_from_slice(&s.to_array());
        let mut dissipative = [0.0; DISSIPATIVE_STATE_LEN];
        DissipativeCoin::new(Coin::new(p), law).derivative(&y, &mut dissipative);
        assert_eq!(dissipative[..STATE_LEN], conservative);
        assert_eq!(dissipative[WORK_INDEX], 0.0);
    }
}

/// A validated scene from TOML text.
fn scene_from(text: &str, sets: &[String]) -> Scene {
    Scene::from_file(&scene::parse_with_sets(text, sets).unwrap()).unwrap()
}

/// A built-in scene with `--set` edits.
fn preset(name: &str, sets: &[&str]) -> Scene {
    let sets: Vec<String> = sets.iter().map(|s| (*s).to_string()).collect();
    let file = scene::file_with_sets(&presets::preset(name).unwrap(), &sets).unwrap();
    Scene::from_file(&file).unwrap()
}

/// (t, JSON) of every message on `topic`.
fn messages(bytes: &[u8], topic: &str) -> Vec<serde_json::Value> {
    read_back(bytes)
        .on_topic(topic)
        .iter()
        .map(|m| serde_json::from_slice(&m.data).unwrap())
        .collect()
}

fn show(r: &FileReport) -> String {
    r.checks
        .iter()
        .map(|c| {
            format!(
                "{:<12} {:<5} {:?} {}",
                c.id.name(),
                c.status.to_string(),
                c.value,
                c.reason
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Max |θ_recording − θ_Newton–Euler| and |W_recording − W_Newton–Euler| / E₀ over the samples of a
/// recording of `scene` (rate 10), the Newton–Euler model integrated by rk4 at 400 steps per sample.
fn disagreement_with_newton_euler(scene: &Scene, couple: Couple) -> (f64, f64) {
    let (bytes, summary) = record_to_memory(scene, &RecordOptions::default());
    assert!(summary.failure.is_none());
    let angles = messages(&bytes, "/coin/angles");
    let work = messages(&bytes, "/coin/work");
    let ne = Dissipating(NewtonEuler::from_params(&scene.params).with_couple(couple));
    let steps_per_sample = 400;
    let h = 1.0 / (scene.run.rate * f64::from(steps_per_sample));
    let steps = (angles.len() - 1) * steps_per_sample as usize;
    let trajectory = physics::rk4_trajectory(
        &ne,
        &ne.state_from(&scene.initial),
        h,
        steps,
        steps_per_sample as usize,
    );
    assert_eq!(trajectory.len(), angles.len());
    let e0 = energy(&scene.coin(), &scene.initial).total;
    let (mut theta, mut w) = (0.0_f64, 0.0_f64);
    for ((t, y), (a, wm)) in trajectory.iter().zip(angles.iter().zip(&work)) {
        assert!((a["t"].as_f64().unwrap() - t).abs() < 1e-9);
        theta = theta.max((a["theta"].as_f64().unwrap() - NewtonEuler::lean(y)).abs());
        w = w.max((wm["dissipated"].as_f64().unwrap() - y[NE_LEN]).abs() / e0.abs());
    }
    let lost = work.last().unwrap()["dissipated"].as_f64().unwrap() / e0;
    println!(
        "{} samples, W/E0 at the end {lost:.3}: max |Δθ| {theta:.3e}, max |ΔW|/E0 {w:.3e}",
        angles.len()
    );
    assert!(
        lost > 0.05,
        "the couple must matter over the run: W/E0 = {lost}"
    );
    (theta, w)
}

/// The two dissipative scenes of the comparison: a general body wobbling under Moffatt's law, and a hoop
/// leaving its centre-fixed motion under rolling resistance (m = 1).
fn comparison_scenes() -> Vec<(&'static str, Scene, Couple)> {
    let wobble = "[body]\nmass = 0.5\nradius = 2.0\ngravity = 9.81\ninertia_x = 0.35\ninertia_z = 0.6\n\
        dissipation = { model = \"moffatt\", coefficient = 0.2 }\n[initial]\ntheta = 0.4\n\
        omega = [0.7752, -1.3288, 4.8727]\nphi = 0.3\npsi = -0.2\n[run]\nduration = 20.0\nrate = 10.0\n\
        [record]\nchannels = [\"omega\", \"angles\", \"work\"]\n";
    let hoop = "[body]\nmass = 1.0\nradius = 1.0\ngravity = 1.0\nshape = \"hoop\"\n\
        dissipation = { model = \"power-law\", coefficient = 0.005, m = 1.0, k = -0.5 }\n\
        [initial]\nsteady = { kind = \"centre-fixed\", theta = 1.2 }\n[run]\nduration = 20.0\nrate = 10.0\n\
        [record]\nchannels = [\"omega\", \"angles\", \"work\"]\n";
    vec![
        (
            "general body, moffatt",
            scene_from(wobble, &[]),
            Couple {
                kappa: 0.2,
                m: 2.0,
                k: 1.0,
            },
        ),
        (
            "hoop, m = 1, k = -0.5",
            scene_from(hoop, &[]),
            Couple {
                kappa: 0.005,
                m: 1.0,
                k: -0.5,
            },
        ),
    ]
}

/// Agreement required in θ (rad) and in W / E₀: dop853 at the default rtol 1e-10 and rk4 at 400 steps per
/// 0.1 time units are both ~1e-10 accurate over 20 time units; a wrong factor in the couple is ≥ 1e-3.
const MODEL_AGREEMENT: f64 = 1e-8;

#[test]
fn a_dissipative_recording_agrees_with_the_newton_euler_model_with_its_own_couple() {
    for (label, scene, couple) in comparison_scenes() {
        let (theta, w) = disagreement_with_newton_euler(&scene, couple);
        physics::check(
            &format!("{label}: max |Δθ| [rad]"),
            theta,
            0.0,
            MODEL_AGREEMENT,
        );
        physics::check(&format!("{label}: max |ΔW| / E0"), w, 0.0, MODEL_AGREEMENT);
    }
}

/// Negative control: the Newton–Euler model with κ 1 % off disagrees by orders of magnitude more.
#[test]
fn a_couple_one_percent_off_disagrees_with_the_recording() {
    let (label, scene, couple) = comparison_scenes().remove(0);
    let off = Couple {
        kappa: couple.kappa * 1.01,
        ..couple
    };
    let (theta, w) = disagreement_with_newton_euler(&scene, off);
    println!("{label}, κ·1.01: max |Δθ| {theta:e}, max |ΔW|/E0 {w:e}");
    assert!(theta.max(w) > 100.0 * MODEL_AGREEMENT, "{theta:e} {w:e}");
}

/// The `euler-disk` scene at its own settings (dop853, rtol 1e-10, atol 1e-12, 400 samples/s), recorded
/// with the channels verify needs: E + W = E₀ to 1e-10 relative over the whole collapse, and the file
/// verifies with invariants and steady skipped for the dissipation.
#[test]
fn euler_disk_keeps_e_plus_w_to_1e_10_and_verifies() {
    let scene = preset(
        "euler-disk",
        &["record.channels=[\"omega\", \"angles\", \"position\", \"work\"]"],
    );
    let (bytes, summary) = record_to_memory(&scene, &RecordOptions::default());
    println!("{summary:?}");
    physics::check(
        "max |E + W - E0| / max(|E0|, Mga)",
        summary.energy_drift,
        0.0,
        1e-10,
    );
    assert_eq!(summary.termination.name(), "flat-landing");
    let e0 = energy(&scene.coin(), &scene.initial).total;
    let w = summary.dissipated_work.unwrap();
    assert!(w > 0.2 * e0 && w < e0, "W = {w}, E0 = {e0}");
    let report = verify_bytes("euler-disk.mcap", &bytes, &Options::default());
    println!("{}", show(&report));
    assert_eq!(report.exit_code, 0, "{}", show(&report));
    let energy_check = report.check(CheckId::Energy).unwrap();
    assert!(energy_check.value.unwrap() <= 1e-10, "{}", show(&report));
    for id in [CheckId::Invariants, CheckId::Steady] {
        let c = report.check(id).unwrap();
        assert_eq!(c.status, Status::Skip);
        assert!(c.reason.contains("dissipation"), "{}", c.reason);
    }
    assert_eq!(
        report.check(CheckId::Constraint).unwrap().status,
        Status::Pass
    );
    let back = read_back(&bytes);
    let run = &back.metadata[RUN_METADATA_NAME].1;
    assert_eq!(run["dissipation"], "moffatt");
    assert_eq!(run["dissipation_m"], "2.0");
    let result = &back.metadata[RESULT_METADATA_NAME].1;
    let alpha: f64 = result["termination_alpha"].parse().unwrap();
    assert!(
        (alpha - scene.run.flat_margin).abs() < 1e-9,
        "α at the end {alpha}"
    );
}

/// A short `euler-disk` file: passes; with W changed at one sample (both fields, consistently, or the
/// dissipated work alone) the energy check fails.
#[test]
fn a_perturbed_work_channel_fails_the_energy_check() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("euler.mcap");
    let (code, out, err) = coin_log_text(&[
        "record",
        "euler-disk",
        "--duration",
        "20",
        "-o",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{out}{err}");
    let good = verify_file(&path, &Options::default());
    assert_eq!(good.exit_code, 0, "{}", show(&good));
    let e0 = 1.5 * 0.45 * 9.81 * 0.0375 * 0.2_f64.sin();
    for fields in [&["dissipated", "balance"][..], &["dissipated"][..]] {
        let bad = dir.path().join("bad.mcap");
        rewrite(&path, &bad, |e| {
            if e.topic == "/coin/work" && e.index == 4000 {
                for f in fields {
                    nudge(e.data, f, 1e-4 * e0);
                }
            }
        });
        let r = verify_file(&bad, &Options::default());
        println!("W perturbed in {fields:?}:\n{}", show(&r));
        assert_eq!(r.exit_code, 1);
        assert_eq!(r.check(CheckId::Energy).unwrap().status, Status::Fail);
    }
}

/// With dissipation C1, C2 drift, so `invariants` does not judge their drift; but the stored
/// `/coin/invariants` are still C1, C2 of the stored state, and verify holds them to 1e-12 as it does
/// without dissipation. A short `euler-disk` file passes; with C1 changed at one sample (even its sign
/// flipped) the `invariants` check fails. It used to be skipped whole, and the file verified `ok`.
#[test]
fn a_perturbed_invariants_channel_fails_with_dissipation() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "euler-disk", &["--duration", "2"]);
    let good = verify_file(&path, &Options::default());
    assert_eq!(good.exit_code, 0, "{}", show(&good));
    let check = good.check(CheckId::Invariants).unwrap();
    assert_eq!(check.status, Status::Pass, "{}", show(&good));
    assert!(check.reason.contains("dissipation"), "{}", check.reason);
    assert!(check.reason.contains("not judged"), "{}", check.reason);
    let bad = dir.path().join("bad.mcap");
    rewrite(&path, &bad, |e| {
        if e.topic == "/coin/invariants" && e.index == 400 {
            let c1 = serde_json::from_slice::<serde_json::Value>(e.data).unwrap()["c1"]
                .as_f64()
                .unwrap();
            nudge(e.data, "c1", -2.0 * c1);
        }
    });
    let r = verify_file(&bad, &Options::default());
    println!("C1 negated at one sample:\n{}", show(&r));
    assert_eq!(r.exit_code, 1, "{}", show(&r));
    assert_eq!(r.check(CheckId::Invariants).unwrap().status, Status::Fail);
}

/// With μ = 0.3 the collapse ends at a located slip, |F| = μN there, at α = 0.095 (physics §11).
#[test]
fn with_friction_the_run_ends_at_a_located_slip() {
    let scene = preset(
        "euler-disk",
        &[
            "body.friction=0.3",
            "run.rate=5",
            "record.channels=[\"angles\", \"reaction\", \"work\"]",
        ],
    );
    let (bytes, summary) = record_to_memory(&scene, &RecordOptions::default());
    assert_eq!(summary.termination.name(), "slip");
    let last = messages(&bytes, "/coin/reaction").pop().unwrap();
    let (f, n) = (
        last["friction"].as_f64().unwrap(),
        last["normal"].as_f64().unwrap(),
    );
    let weight = 0.45 * 9.81;
    physics::check(
        "(|F| - 0.3 N) / (Mg) at the slip",
        (f - 0.3 * n) / weight,
        0.0,
        1e-9,
    );
    let alpha = summary.termination_alpha.unwrap();
    physics::check("α at the slip", alpha, 0.0948, 5e-4);
    let t = summary.termination_time;
    assert!(t > 700.0 && t < 800.0, "slip at t = {t}");
}

/// The problems of one scene text.
fn problems(text: &str) -> Vec<String> {
    let file = scene::parse_with_sets(text, &[]).unwrap();
    match Scene::from_file(&file) {
        Err(SceneError::Invalid(list)) => list.iter().map(ToString::to_string).collect(),
        other => panic!("expected problems, got {other:?}"),
    }
}

const BODY: &str = "[body]\nmass = 1.0\nradius = 1.0\ngravity = 1.0\nshape = \"thin-disk\"\n";
const REST: &str = "[initial]\ntheta = 0.3\nomega = [0.0, 1.0, 0.0]\n[run]\nduration = 1.0\n";

#[test]
fn bad_dissipation_keys_are_refused_naming_key_value_and_fix() {
    for (dissipation, needles) in [
        (
            "{ model = \"stokes\", coefficient = 1.0 }",
            &["body.dissipation.model", "\"stokes\"", "power-law"][..],
        ),
        (
            "{ model = \"moffatt\", coefficient = -1.0 }",
            &["body.dissipation.coefficient", "-1", "≥ 0"][..],
        ),
        (
            "{ model = \"moffatt\" }",
            &["body.dissipation.coefficient", "is missing"][..],
        ),
        (
            "{ model = \"moffatt\", coefficient = 1.0, m = 3.0 }",
            &["body.dissipation.m", "fixes m = 2", "power-law"][..],
        ),
        (
            "{ model = \"power-law\", coefficient = 1.0, m = 0.5, k = 0.0 }",
            &["body.dissipation.m", "0.5", "[1, ∞)"][..],
        ),
        (
            "{ model = \"power-law\", coefficient = 1.0, m = 2.0 }",
            &["body.dissipation.k", "is missing"][..],
        ),
    ] {
        let text = format!("{BODY}dissipation = {dissipation}\n{REST}");
        let found = problems(&text).join("\n");
        println!("{dissipation}:\n  {found}");
        for n in needles {
            assert!(found.contains(n), "`{n}` not in: {found}");
        }
    }
}

#[test]
fn the_work_channel_needs_dissipation_and_is_recorded_by_default_with_it() {
    let found = problems(&format!(
        "{BODY}{REST}[record]\nchannels = [\"omega\", \"work\"]\n"
    ))
    .join("\n");
    assert!(
        found.contains("record.channels") && found.contains("body.dissipation"),
        "{found}"
    );
    let conservative = scene_from(&format!("{BODY}{REST}"), &[]);
    assert_eq!(conservative.channels, Channel::DEFAULT.to_vec());
    let dissipative = scene_from(
        &format!("{BODY}dissipation = {{ model = \"viscous\", coefficient = 0.1 }}\n{REST}"),
        &[],
    );
    let mut expected = Channel::DEFAULT.to_vec();
    expected.push(Channel::Work);
    assert_eq!(dissipative.channels, expected);
    assert!(dissipative.unperturbed_steady().is_none());
    // Through the command line: the error names the key, the flag and the fix; nothing is written.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.mcap");
    let (code, _, err) = coin_log_text(&[
        "record",
        "wobble",
        "--channels",
        "omega,work",
        "-o",
        out.to_str().unwrap(),
    ]);
    println!("{err}");
    assert_eq!(code, 1);
    for needle in [
        "record.channels",
        "\"work\"",
        "--channels",
        "body.dissipation",
    ] {
        assert!(err.contains(needle), "`{needle}` not in: {err}");
    }
    assert!(!out.exists());
}

/// A conservative recording has none of the dissipation metadata keys; a dissipative one has all four and
/// its resolved scene reads back to the same law.
#[test]
fn dissipation_metadata_is_written_only_with_dissipation() {
    let (bytes, _) = record_to_memory(
        &preset("wobble", &["run.duration=1"]),
        &RecordOptions::default(),
    );
    let run = &read_back(&bytes).metadata[RUN_METADATA_NAME].1;
    for key in DISSIPATION_KEYS {
        assert!(!run.contains_key(key), "{key} in a conservative file");
    }
    assert!(!read_back(&bytes).metadata[RESULT_METADATA_NAME]
        .1
        .contains_key("termination_alpha"));
    let scene = preset(
        "euler-disk",
        &[
            "run.duration=1",
            "body.dissipation={ model = \"power-law\", coefficient = 1e-9, m = 1.5, k = -0.25 }",
        ],
    );
    let (bytes, _) = record_to_memory(&scene, &RecordOptions::default());
    let run = &read_back(&bytes).metadata[RUN_METADATA_NAME].1;
    assert_eq!(run["dissipation"], "power-law");
    assert_eq!(run["dissipation_m"], "1.5");
    assert_eq!(run["dissipation_k"], "-0.25");
    let back = scene_from(&run["scene"], &[]);
    assert_eq!(back.dissipation, scene.dissipation);
}

/// The `euler-disk` coefficient is Moffatt's (π/4) μ a³ for air at 1.8e-5 Pa·s and a = 37.5 mm, and its
/// slow-change time scale is Moffatt's spin time α₀³ M / (2π μ a) up to the O(α₀²) of sin α against α.
#[test]
fn the_euler_disk_coefficient_is_moffatts() {
    let scene = preset("euler-disk", &[]);
    let law = scene.dissipation.unwrap();
    // Air at about 20 °C [Pa·s], and the toy's 75 mm disk [m].
    let (mu, a) = (1.8e-5, 0.0375);
    assert_eq!(scene.params.radius(), a);
    physics::check_relative(
        "κ",
        law.coefficient(),
        std::f64::consts::FRAC_PI_4 * mu * a.powi(3),
        1e-15,
    );
    let t0 = coin_log::analyse::slow_change::slow_change_time_scale(&scene.coin(), &law, 0.2);
    let moffatt = 0.2_f64.powi(3) * 0.45 / (2.0 * std::f64::consts::PI * mu * a);
    // sin^3 α₀ / α₀³ = 1 − α₀²/2 + …: 2 % at α₀ = 0.2.
    physics::check_relative(
        "t0 against Moffatt's α0³M/(2πμa)",
        t0,
        moffatt * 0.2_f64.sin().powi(3) / 0.008,
        1e-12,
    );
}

#[test]
fn presets_have_the_documented_exponents_and_names_round_trip() {
    for &m in DissipationModel::ALL {
        assert_eq!(m.name().parse::<DissipationModel>(), Ok(m));
    }
    assert!("stokes".parse::<DissipationModel>().is_err());
    let n = |model| {
        Dissipation::preset(model, 1.0)
            .unwrap()
            .predicted_exponent()
    };
    assert_eq!(n(DissipationModel::Moffatt), 1.0 / 3.0);
    assert_eq!(n(DissipationModel::AirDrag), 4.0 / 9.0);
    assert_eq!(n(DissipationModel::Viscous), 0.5);
    assert_eq!(n(DissipationModel::Rolling), 2.0 / 3.0);
    assert_eq!(n(DissipationModel::Pivoting), -2.0);
    assert!(Dissipation::preset(DissipationModel::PowerLaw, 1.0).is_err());
}

#[test]
fn bad_values_are_refused() {
    let m = DissipationModel::PowerLaw;
    assert!(Dissipation::new(m, -1.0, 2.0, 0.0).is_err());
    assert!(Dissipation::new(m, f64::NAN, 2.0, 0.0).is_err());
    assert!(Dissipation::new(m, 1.0, 0.5, 0.0).is_err());
    assert!(Dissipation::new(m, 1.0, 2.0, f64::INFINITY).is_err());
    assert!(Dissipation::new(m, 0.0, 1.0, -3.0).is_ok());
}

#[test]
fn the_couple_vanishes_at_rest_without_nan() {
    let d = Dissipation::preset(DissipationModel::Rolling, 2.0).unwrap();
    let coin = DissipativeCoin::new(Coin::new(CoinParams::unit_disk()), d);
    let r = coin.rates(0.3, 0.0, 0.0, 0.0);
    assert_eq!(r.power, 0.0);
    let conservative = Coin::new(CoinParams::unit_disk()).angular_acceleration(0.3, 0.0, 0.0, 0.0);
    assert_eq!(r.acceleration, conservative);
}

/// P = κ |φ̇|^m (sin α)^(−k) is 0 without φ̇ and finite wherever its value is, even where a factor is not:
/// with k = 400, (sin α)^(−k) overflows below α = 0.18, and `topple` (released without spin, φ̇ = 0
/// throughout) ended "non-finite at t = 1.75" (exit 1) with W = 0, its P = 0·∞; it now lands flat. With
/// κ = 1e-300 the product at α = 0.12 is 2e67 though the angle factor alone overflows.
#[test]
fn the_power_is_zero_without_phi_dot_and_finite_where_its_value_is() {
    let d = Dissipation::new(DissipationModel::PowerLaw, 1e-10, 1.0, 400.0).unwrap();
    assert_eq!(d.power(1.45, 0.0), 0.0);
    let d = Dissipation::new(DissipationModel::PowerLaw, 1e-300, 1.0, 400.0).unwrap();
    let theta: f64 = 1.45;
    let expected = (1e-300f64.ln() - 400.0 * theta.cos().ln()).exp();
    let p = d.power(theta, theta.cos());
    assert!(
        (p / expected - 1.0).abs() < 1e-10,
        "{p:e} against {expected:e}"
    );
    let law = "body.dissipation={model=\"power-law\",coefficient=1e-10,m=1,k=400}";
    let scene = preset("topple", &[law]);
    let (_, summary) = record_to_memory(&scene, &RecordOptions::default());
    assert_eq!(summary.termination.name(), "flat-landing");
}
