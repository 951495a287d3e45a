//! Criterion benchmarks of each integrator on the `wobble` motion (unit thin disk, θ0 = 0.5,
//! ω = (0.3, 0.2, 1.5), 30 time units, sampled at 100 per unit) and of one C1/C2 evaluation, so that a
//! speed regression shows next to the accuracy tests. CI only compiles them (`cargo bench --no-run`).

use coin_log::integrate::{run_method, Flow, Method, MethodConfig, NoEvents, RunSettings};
use coin_log::model::{Chaplygin, CoinParams};
use coin_log_bench::presets::bench_case;
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

fn integrators(c: &mut Criterion) {
    let Ok(case) = bench_case("wobble") else {
        return;
    };
    let (coin, y0) = (case.coin, case.initial.to_array());
    let settings = RunSettings {
        t0: 0.0,
        t_end: 30.0,
        sample_interval: 0.01,
    };
    // Settings at which each method reaches a state error of about 1e-10 on this motion.
    let configs = [
        MethodConfig {
            method: Method::Dop853,
            rtol: 1e-12,
            atol: 1e-14,
            step: 0.0,
        },
        MethodConfig {
            method: Method::Dopri5,
            rtol: 1e-12,
            atol: 1e-14,
            step: 0.0,
        },
        MethodConfig {
            method: Method::Rk4,
            rtol: 0.0,
            atol: 0.0,
            step: 2e-3,
        },
        MethodConfig {
            method: Method::Gauss4,
            rtol: 0.0,
            atol: 0.0,
            step: 2e-3,
        },
    ];
    for config in configs {
        c.bench_function(
            &format!("{} on wobble, 30 time units", config.method),
            |b| {
                b.iter(|| {
                    let mut last = 0.0;
                    let outcome = run_method(&config, &coin, &y0, &settings, &NoEvents, |_, y| {
                        last = y[0];
                        Flow::Continue
                    });
                    black_box((outcome.stats, last))
                });
            },
        );
    }
}

fn invariants(c: &mut Criterion) {
    let Ok(chaplygin) = Chaplygin::new(&CoinParams::unit_disk()) else {
        return;
    };
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
