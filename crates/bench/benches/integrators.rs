//! Criterion benchmarks of each integrator on the `wobble` scene's motion (unit thin disk, θ0 = 0.5,
//! ω = (0.3, 0.2, 1.5), 30 time units) at a state error of about 1e-10, and of one C1/C2 evaluation, so
//! that a speed regression shows next to the accuracy tests. The adaptive methods run at the loosest
//! tolerance that reaches 1e-10 against the dop853 reference (atol 1e-16; the error is measured on samples
//! at 100 per time unit); the timed runs check the scene's events as `record` does but keep only the last
//! state, so that they time the integration, not the output. The target of issue 9 for dop853 is 0.5 ms.
//! CI only compiles them; run with `cargo bench -p coin-log-bench --bench integrators`.
// A benchmark that cannot set itself up has nothing to measure: it stops with the reason.
#![allow(clippy::expect_used)]

use coin_log::integrate::{run_method, Flow, Method, MethodConfig, RunSettings};
use coin_log::model::{Chaplygin, CoinParams};
use coin_log_bench::precision::loosest_accurate;
use coin_log_bench::presets::bench_case;
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

/// The state error each method is timed at.
const STATE_ERROR: f64 = 1e-10;
/// atol values tried for the adaptive methods, loosest first (rtol = min(1e3·atol, 1e-3)).
const ATOLS: [f64; 9] = [1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14, 1e-15, 1e-16];
/// Fixed step of rk4 and gauss4, at which they reach about [`STATE_ERROR`] on this motion.
const FIXED_STEP: f64 = 2e-3;

fn integrators(c: &mut Criterion) {
    let case = bench_case("wobble").expect("the built-in wobble scene");
    let y0 = case.initial.to_array();
    let events = case.events();
    let settings = RunSettings {
        sample_interval: case.duration,
        ..case.settings()
    };
    for &method in Method::ALL {
        let config = if method.is_adaptive() {
            loosest_accurate(&case, method, &ATOLS, STATE_ERROR)
                .expect("a tolerance that reaches the state error")
                .0
        } else {
            MethodConfig {
                method,
                rtol: 0.0,
                atol: 0.0,
                step: FIXED_STEP,
            }
        };
        c.bench_function(&format!("{method} on wobble, 30 time units"), |b| {
            b.iter(|| {
                let mut last = 0.0;
                let outcome = run_method(&config, &case.coin, &y0, &settings, &events, |_, y| {
                    last = y[0];
                    Flow::Continue
                });
                black_box((outcome.stats, last))
            });
        });
    }
}

fn invariants(c: &mut Criterion) {
    let chaplygin = Chaplygin::new(&CoinParams::unit_disk()).expect("C1, C2 of the thin disk");
    for theta in [0.3, 1.2, 1.5705] {
        c.bench_function(&format!("Chaplygin::evaluate at theta = {theta}"), |b| {
            b.iter(|| {
                black_box(chaplygin.evaluate(black_box(theta), black_box(0.2), black_box(1.5)))
            });
        });
    }
}

criterion_group!(benches, integrators, invariants);
criterion_main!(benches);
