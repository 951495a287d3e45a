//! Criterion benchmark of one right-hand side evaluation of the coin (`Coin::derivative`, eqs (14)–(19)
//! plus ẋ, ż), for the thin disk and general parameters, at a generic wobbling state; and of the
//! dissipative coin (`DissipativeCoin::derivative`, eqs (30)–(34) of physics §11, with Moffatt's law), a
//! separate system, so that the conservative evaluation is exactly what it is without dissipation.
//! The target of issue 9 is 50 ns per evaluation. CI only compiles it; run with `cargo bench --bench rhs`.

use coin_log::model::{
    Coin, CoinParams, Dissipation, DissipationModel, DissipativeCoin, Inertia, State,
    DISSIPATIVE_STATE_LEN, STATE_LEN,
};
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;

fn wobbling() -> [f64; STATE_LEN] {
    State {
        theta: 0.4,
        phi: 0.3,
        psi: -0.2,
        omega_x: 0.35,
        omega_y: -0.6,
        omega_z: 2.2,
        x: 0.1,
        z: -0.2,
    }
    .to_array()
}

fn rhs(c: &mut Criterion) {
    let general = CoinParams::new(
        0.5,
        2.0,
        9.81,
        Inertia::Explicit {
            inertia_x: 0.35,
            inertia_z: 0.6,
        },
    );
    let mut cases = vec![("thin disk", Coin::new(CoinParams::unit_disk()))];
    if let Ok(p) = general {
        cases.push(("general parameters", Coin::new(p)));
    }
    let y = wobbling();
    for (label, coin) in &cases {
        c.bench_function(&format!("Coin::derivative, {label}"), |b| {
            let mut dydt = [0.0; STATE_LEN];
            b.iter(|| {
                coin.derivative(black_box(&y), &mut dydt);
                black_box(&dydt);
            });
        });
    }
    let mut yd = [0.0; DISSIPATIVE_STATE_LEN];
    yd[..STATE_LEN].copy_from_slice(&y);
    if let Ok(law) = Dissipation::preset(DissipationModel::Moffatt, 1e-3) {
        let coin = DissipativeCoin::new(cases[0].1, law);
        c.bench_function("DissipativeCoin::derivative, thin disk, moffatt", |b| {
            let mut dydt = [0.0; DISSIPATIVE_STATE_LEN];
            b.iter(|| {
                coin.derivative(black_box(&yd), &mut dydt);
                black_box(&dydt);
            });
        });
    }
}

criterion_group!(benches, rhs);
criterion_main!(benches);
