//! Acceptance of `bench euler` (physics §11): every preset's fitted exponent is within 2 % of 1/(1 − p)
//! (Moffatt: 1/3) on its window, the pivoting law shows no finite-time singularity (a decay, run to the
//! end of its time), every preset slips first with μ = 0.3 at the same α (the slow path depends only on the
//! couple's direction), and the output formats are pinned. Also `bench precision` on the dissipative
//! `euler-disk`: the energy error is that of E + W and there is no invariant error.

use coin_log::integrate::Method;
use coin_log::model::DissipationModel;
use coin_log_bench::euler::{euler_bench, EulerOptions, EulerRow, SLIP_FRICTION};
use coin_log_bench::plot::euler_svg;
use coin_log_bench::precision::{precision_bench, PrecisionOptions};
use coin_log_bench::presets::bench_case;
use coin_log_bench::table::{euler_csv, EULER_CSV_HEADER};
use std::sync::OnceLock;

/// The acceptance: fitted exponents within 2 % of 1/(1 − p).
const EXPONENT_TOLERANCE: f64 = 0.02;

fn rows() -> &'static Vec<EulerRow> {
    static ROWS: OnceLock<Vec<EulerRow>> = OnceLock::new();
    ROWS.get_or_init(|| match euler_bench(&EulerOptions::full()) {
        Ok(rows) => rows,
        Err(e) => panic!("{e}"),
    })
}

#[test]
fn every_fitted_exponent_is_within_2_percent_of_the_prediction() {
    assert_eq!(rows().len(), DissipationModel::PRESETS.len());
    for r in rows() {
        let Some(fit) = r.fit else {
            panic!("{}: no fit ({} points)", r.dissipation.model(), r.points)
        };
        let error = r.relative_error().unwrap_or(f64::INFINITY);
        println!(
            "{}: n fitted {:.5}, predicted {:.5}, relative error {:.3e} (tolerance {EXPONENT_TOLERANCE}), window α {:.4}..{:.4} ({}), t0 {:.3}, {} points",
            r.dissipation.model(),
            fit.exponent,
            r.predicted,
            error,
            r.alpha_window.0,
            r.alpha_window.1,
            r.limit.name(),
            fit.t0,
            r.points
        );
        assert!(
            error <= EXPONENT_TOLERANCE,
            "{}: {error}",
            r.dissipation.model()
        );
        assert!(r.points >= 100, "{} points", r.points);
        let singular = r.p < 1.0;
        assert_eq!(fit.singular, singular, "{}", r.dissipation.model());
        if singular {
            assert_eq!(r.end.termination, "flat-landing");
            assert!(fit.t0 > r.time_window.1 && fit.t0 < r.end.time + 1.0);
        } else {
            // No finite-time singularity: the decay runs to the end of its time and α is still far from 0.
            assert_eq!(r.end.termination, "completed");
            assert!(r.end.alpha > 0.01, "α = {}", r.end.alpha);
        }
    }
}

#[test]
fn with_mu_0_3_every_preset_slips_first_at_the_same_alpha() {
    for r in rows() {
        let e = &r.with_friction;
        println!(
            "{} with μ = {SLIP_FRICTION}: {} at t = {}, α = {}",
            r.dissipation.model(),
            e.termination,
            e.time,
            e.alpha
        );
        assert_eq!(e.termination, "slip");
        assert!((e.alpha - 0.0948).abs() < 5e-4, "α = {}", e.alpha);
    }
}

#[test]
fn the_csv_and_the_diagram_carry_every_preset() {
    let csv = euler_csv(rows());
    assert_eq!(csv.lines().next(), Some(EULER_CSV_HEADER));
    assert_eq!(csv.lines().count(), rows().len() + 1);
    let columns = EULER_CSV_HEADER.split(',').count();
    assert!(csv.lines().all(|l| l.split(',').count() == columns));
    let svg = euler_svg(rows()).unwrap();
    for model in DissipationModel::PRESETS {
        assert!(
            svg.contains(&format!("{model}: n = ")),
            "{model} not in the legend"
        );
    }
}

/// `bench precision` accepts the dissipative scene: a short run of it, the energy error is the drift of
/// E + W (tiny for dop853 at tight tolerances) and there is no C1/C2 error.
#[test]
fn bench_precision_measures_the_balance_on_euler_disk() {
    let mut case = bench_case("euler-disk").unwrap();
    case.duration = 5.0;
    let report = precision_bench(&case, &[Method::Dop853], &PrecisionOptions::reduced()).unwrap();
    for row in &report.rows {
        println!("{row:?}");
        assert!(row.invariant_error.is_none());
        assert!(row.energy_error.is_finite());
    }
    let tight = report.rows.last().unwrap();
    assert!(
        tight.energy_error < 1e-12 && tight.state_error < 1e-9,
        "{tight:?}"
    );
}
