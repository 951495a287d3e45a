//! Acceptance of `bench precision` on a reduced sweep: on `wobble`, dop853 reaches a state error
//! ≤ 1e-10, and every integrator's measured slope (log error against log RHS evaluations, the
//! deterministic cost; wall time is never asserted) matches its order within ±0.5. The output formats
//! (CSV columns, SVG) are pinned too.

use coin_log::integrate::Method;
use coin_log_bench::plot::work_precision_svg;
use coin_log_bench::precision::{
    loosest_accurate, precision_bench, rtol_for, PrecisionOptions, PrecisionReport,
};
use coin_log_bench::presets::bench_case;
use coin_log_bench::table::{precision_csv, PRECISION_CSV_HEADER};
use coin_log_bench::BenchError;
use coin_log_bench::ReferenceKind;
use std::sync::OnceLock;

/// Slopes must match the orders within this.
const SLOPE_TOLERANCE: f64 = 0.5;
/// dop853 must reach this state error on wobble.
const DOP853_TARGET: f64 = 1e-10;

/// The reduced sweep on wobble, computed once for the tests of this file.
fn wobble_report() -> &'static PrecisionReport {
    static REPORT: OnceLock<PrecisionReport> = OnceLock::new();
    REPORT.get_or_init(|| {
        let case = match bench_case("wobble") {
            Ok(case) => case,
            Err(e) => panic!("{e}"),
        };
        match precision_bench(&case, Method::ALL, &PrecisionOptions::reduced()) {
            Ok(report) => report,
            Err(e) => panic!("{e}"),
        }
    })
}

#[test]
fn dop853_reaches_a_state_error_of_1e_10_on_wobble() {
    let report = wobble_report();
    assert!(
        matches!(report.reference, ReferenceKind::Numerical(_)),
        "wobble is not steady: its reference must be the tight dop853 run, got {}",
        report.reference
    );
    let best = report
        .rows
        .iter()
        .filter(|r| r.integrator == Method::Dop853)
        .map(|r| r.state_error)
        .fold(f64::INFINITY, f64::min);
    println!("dop853 best state error on wobble: measured {best:e}, required ≤ {DOP853_TARGET:e}");
    assert!(best <= DOP853_TARGET);
}

#[test]
fn energy_and_invariant_errors_shrink_with_the_tolerance() {
    let dop853: Vec<_> = wobble_report()
        .rows
        .iter()
        .filter(|r| r.integrator == Method::Dop853)
        .collect();
    let (loose, tight) = (dop853[0], dop853[dop853.len() - 1]);
    let (c_loose, c_tight) = (
        loose.invariant_error.unwrap(),
        tight.invariant_error.unwrap(),
    );
    println!(
        "dop853 atol {:e}: E {:e}, C1/C2 {c_loose:e}; atol {:e}: E {:e}, C1/C2 {c_tight:e} (≤ 1e-11)",
        loose.tolerance.unwrap(),
        loose.energy_error,
        tight.tolerance.unwrap(),
        tight.energy_error
    );
    assert!(tight.energy_error <= 1e-11 && c_tight <= 1e-11);
    assert!(loose.energy_error > 1e3 * tight.energy_error && c_loose > 1e3 * c_tight);
}

#[test]
fn measured_slopes_match_the_orders_of_the_integrators() {
    let report = wobble_report();
    for slope in &report.slopes {
        let order = f64::from(slope.integrator.order());
        let measured = slope.work.unwrap();
        println!(
            "{}: slope vs RHS evaluations {measured:.3}, expected {:.0} ± {SLOPE_TOLERANCE} ({} points)",
            slope.integrator, -order, slope.points
        );
        assert!(
            slope.points >= 3,
            "{}: too few points in the fit",
            slope.integrator
        );
        assert!(
            (measured + order).abs() <= SLOPE_TOLERANCE,
            "{}: slope {measured:.3} is not -{order} ± {SLOPE_TOLERANCE}",
            slope.integrator
        );
    }
}

#[test]
fn every_sweep_point_finishes_with_finite_errors() {
    for r in &wobble_report().rows {
        assert_eq!(r.termination, "completed", "{r:?}");
        assert!(
            r.state_error.is_finite() && r.energy_error.is_finite(),
            "{r:?}"
        );
        assert!(r.rhs_evaluations > 0 && r.steps > 0, "{r:?}");
    }
}

#[test]
fn csv_has_exactly_the_issue_columns_and_one_line_per_point() {
    let report = wobble_report();
    let csv = precision_csv(&report.rows);
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "scene,integrator,tolerance,step,state_error,energy_error,invariant_error,wall_seconds,rhs_evaluations,steps,rejected"
    );
    assert_eq!(PRECISION_CSV_HEADER.split(',').count(), 11);
    let body: Vec<&str> = lines.collect();
    assert_eq!(body.len(), report.rows.len());
    for line in body {
        let fields: Vec<&str> = line.split(',').collect();
        assert_eq!(fields.len(), 11, "{line}");
        assert_eq!(fields[0], "wobble");
        // Exactly one of tolerance (adaptive) and step (fixed) is given.
        assert!(fields[2].is_empty() != fields[3].is_empty(), "{line}");
        let error: f64 = fields[4].parse().unwrap();
        assert!(error.is_finite(), "{line}");
    }
}

#[test]
fn diagram_is_an_svg_with_one_legend_entry_per_integrator() {
    let report = wobble_report();
    let svg = work_precision_svg(report).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..svg.len().min(80)]);
    for m in Method::ALL {
        assert!(
            svg.contains(&format!("{} (slope ", m.name())),
            "legend entry of {m} missing"
        );
    }
}

#[test]
fn steady_scenes_are_measured_against_the_analytic_trajectory() {
    let case = bench_case("circle-plus").unwrap();
    let options = PrecisionOptions {
        repeats: 1,
        adaptive_atols: vec![1e-8, 1e-12],
        fixed_points: 2,
    };
    let report = precision_bench(&case, &[Method::Dop853], &options).unwrap();
    assert_eq!(report.reference, ReferenceKind::Analytic);
    let tight = report.rows.last().unwrap();
    println!(
        "circle-plus dop853 atol 1e-12: state error {:e} (≤ 1e-8)",
        tight.state_error
    );
    assert!(tight.state_error <= 1e-8);
}

#[test]
fn the_timed_dop853_setting_is_the_loosest_that_reaches_1e_10_on_wobble() {
    // The setting criterion times dop853 at (benches/integrators.rs): the loosest atol of the list whose
    // state error is ≤ 1e-10; the next looser one does not reach it, and an unreachable target is an error.
    let case = bench_case("wobble").unwrap();
    let atols = [1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14];
    let (config, error) = loosest_accurate(&case, Method::Dop853, &atols, DOP853_TARGET).unwrap();
    println!(
        "dop853 on wobble: atol {:e}, rtol {:e}, state error {error:e} (≤ {DOP853_TARGET:e})",
        config.atol, config.rtol
    );
    assert!(error <= DOP853_TARGET);
    assert!((config.rtol - rtol_for(config.atol)).abs() <= 1e-3 * config.rtol);
    let looser: Vec<f64> = atols.iter().copied().filter(|&a| a > config.atol).collect();
    let missed = loosest_accurate(&case, Method::Dop853, &looser, DOP853_TARGET);
    println!("looser atols {looser:?}: {missed:?}");
    assert!(matches!(missed, Err(BenchError::Inaccurate { best, .. }) if best > DOP853_TARGET));
}

/// Two scenes of one name (two files of one stem, or one scene given twice) would share their rows' name in
/// precision.csv and one diagram, the second replacing the first: refused before any work, nothing written.
#[test]
fn two_scenes_of_one_name_are_refused_before_any_work() {
    use crate::support::record::coin_log;
    let dir = tempfile::tempdir().unwrap();
    let scene = std::fs::read_to_string(crate::support::repo().join("datasets/scenes/wobble.toml"))
        .unwrap();
    for sub in ["a", "b"] {
        std::fs::create_dir(dir.path().join(sub)).unwrap();
        std::fs::write(dir.path().join(sub).join("x.toml"), &scene).unwrap();
    }
    for (args, says) in [
        (
            ["./a/x.toml", "./b/x.toml"],
            "scenes `./a/x.toml` and `./b/x.toml` are both named `x`",
        ),
        (["wobble", "wobble"], "scene `wobble` is given twice"),
    ] {
        let out = coin_log(
            dir.path(),
            &[
                "bench",
                "precision",
                args[0],
                args[1],
                "--repeats",
                "1",
                "--out",
                "o",
            ],
        );
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
        assert!(stderr.contains("precision-"), "{args:?}: {stderr}");
        assert!(out.stdout.is_empty(), "{args:?}: nothing measured");
        assert!(!dir.path().join("o").exists(), "{args:?}: nothing written");
    }
}
