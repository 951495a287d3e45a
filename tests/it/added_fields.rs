//! The fields added to the `coin_log.*` schemas since the format's first version (`Angles.phi_dot`,
//! `Reaction.friction_ratio`, `Energy.change`, docs/format.md: Channels and fields): recorded with their
//! defining formulas, judged by `verify`'s `consistency` check, and absent from files written before them,
//! which still verify (`tests/fixtures/wobble-first-version.mcap`, recorded by the tool before the change).
#![allow(clippy::unwrap_used)]

use crate::support::record::{read_messages, record_scene};
use crate::support::repo;
use crate::support::writers::{nudge, rewrite, Edit};
use coin_log::verify::{verify_file, CheckId, FileReport, Options, Status};

fn show(r: &FileReport) -> String {
    r.checks
        .iter()
        .map(|c| {
            format!(
                "{:<12} {} {:?}  {}",
                c.id.name(),
                c.status,
                c.value,
                c.reason
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn a_file_written_before_the_added_fields_still_verifies() {
    let path = repo().join("tests/fixtures/wobble-first-version.mcap");
    let messages = read_messages(&path);
    let energy = messages.iter().find(|m| m.0 == "/coin/energy").unwrap();
    assert!(
        energy.2.get("change").is_none(),
        "the fixture predates `change`"
    );
    let r = verify_file(&path, &Options::default());
    println!("{}", show(&r));
    assert_eq!(r.exit_code, 0, "{}", show(&r));
    let integrity = r.check(CheckId::Integrity).unwrap();
    for (schema, field) in [
        ("coin_log.Angles", "phi_dot"),
        ("coin_log.Reaction", "friction_ratio"),
        ("coin_log.Energy", "change, drift_eps"),
    ] {
        let note = format!(
            "schema `{schema}` is the first version of the type, without the fields added since ({field})"
        );
        assert!(integrity.reason.contains(&note), "{}", integrity.reason);
    }
}

#[test]
fn the_added_fields_are_recorded_with_their_formulas() {
    let dir = tempfile::tempdir().unwrap();
    let path = record_scene(dir.path(), "wobble", &["--duration", "2"]);
    let messages = read_messages(&path);
    let on = |topic: &'static str| messages.iter().filter(move |m| m.0 == topic).map(|m| &m.2);
    let e0 = on("/coin/energy").next().unwrap()["total"]
        .as_f64()
        .unwrap();
    let mut worst: f64 = 0.0;
    let mut worst_drift: f64 = 0.0;
    for ((e, a), (w, r)) in on("/coin/energy")
        .zip(on("/coin/angles"))
        .zip(on("/coin/omega").zip(on("/coin/reaction")))
    {
        let f = |v: &serde_json::Value, k: &str| v[k].as_f64().unwrap();
        // The defining formulas, on the stored numbers: the recorder computes the same, so they agree to
        // round-off (1e-15 relative).
        let phi_dot = f(w, "y") / f(a, "theta").cos();
        let ratio = f(r, "friction") / f(r, "normal").max(1e-12);
        let change = f(e, "total") - e0;
        // E₀ ≈ 2.6 > Mga = 1 for the wobble: the drift scale is |E₀|.
        let drift = change / (f64::EPSILON * e0.abs());
        worst = worst
            .max((f(a, "phi_dot") - phi_dot).abs() / phi_dot.abs().max(1.0))
            .max((f(r, "friction_ratio") - ratio).abs() / ratio.abs().max(1.0))
            .max((f(e, "change") - change).abs() / e0.abs());
        worst_drift = worst_drift.max((f(e, "drift_eps") - drift).abs());
    }
    println!("added fields vs their formulas: worst {worst:e} (tolerance 1e-15)");
    assert!(worst <= 1e-15);
    // drift_eps is in units of ε|E₀|: the JSON parsing of this test may be an ulp off on E and E₀ (serde_json
    // without float_roundtrip), which is up to ≈ 2 units; a wrong formula (no ε, another scale) is off by
    // orders of magnitude.
    println!("drift_eps vs (E − E₀)/(ε|E₀|): worst {worst_drift:e} units of ε (tolerance 4)");
    assert!(worst_drift <= 4.0);
}

/// `wobble` recorded by `coin-log record` (2 time units), with `edit` applied, verified.
fn tampered(edit: impl FnMut(Edit<'_>)) -> FileReport {
    let dir = tempfile::tempdir().unwrap();
    let good = record_scene(dir.path(), "wobble", &["--duration", "2"]);
    assert_eq!(verify_file(&good, &Options::default()).exit_code, 0);
    let bad = dir.path().join("bad.mcap");
    rewrite(&good, &bad, edit);
    let r = verify_file(&bad, &Options::default());
    println!("{}", show(&r));
    r
}

#[test]
fn a_stored_added_field_that_disagrees_fails_consistency() {
    for (topic, field, delta, scale) in [
        ("/coin/angles", "phi_dot", 1e-9, 1.0),
        ("/coin/reaction", "friction_ratio", 1e-9, 1.0),
        ("/coin/energy", "change", 1e-9, 2.6),
        // drift_eps at t = 1 is ≈ −782 (E − E₀ ≈ −4.6e-13): a nudge of 1e-3 ε.
        ("/coin/energy", "drift_eps", 1e-3, 782.0),
    ] {
        let r = tampered(|e| {
            if e.topic == topic && e.index == 100 {
                nudge(e.data, field, delta);
            }
        });
        let c = r.check(CheckId::Consistency).unwrap();
        let value = c.value.unwrap();
        // The nudge relative to the field's scale (max(|φ̇|, √(g/a)) ≈ 1; max(ratio, 1) = 1; max(|E₀|, Mga)
        // ≈ 2.6; max(|drift_eps|, 1) ≈ 782): between a third of it and the nudge itself (1 % for the round-off of the nudge).
        println!("{field}: consistency {value:e} (nudge {delta:e}, scale {scale})");
        assert_eq!(c.status, Status::Fail, "{field}\n{}", show(&r));
        assert!(
            c.reason.contains(&format!(
                "worst: {}",
                field.replace("change", "energy change")
            )),
            "{}",
            c.reason
        );
        assert!(
            (delta / scale / 3.0..=1.01 * delta).contains(&value),
            "{field}: {value:e}"
        );
    }
}

#[test]
fn a_message_without_a_field_its_schema_requires_fails_integrity() {
    let r = tampered(|e| {
        if e.topic == "/coin/energy" && e.index == 50 {
            let mut v: serde_json::Map<String, serde_json::Value> =
                serde_json::from_slice(e.data).unwrap();
            v.remove("change");
            *e.data = serde_json::to_vec(&v).unwrap();
        }
    });
    let integrity = r.check(CheckId::Integrity).unwrap();
    assert_eq!(integrity.status, Status::Fail);
    assert!(
        integrity
            .reason
            .contains("/coin/energy: message at 500000000 ns lacks fields its schema requires"),
        "{}",
        integrity.reason
    );
}
