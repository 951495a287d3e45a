//! rk4's observed order of convergence on the coin: the error at t = 4 natural time units, against a
//! reference computed with a step 16× smaller than the finest tested step (its truncation error is
//! 16⁴ ≈ 7e4 times smaller), halves the step repeatedly; log₂ of successive error ratios must be 4 ± 0.15 wherever
//! both errors stay above 1e3 × machine epsilon (below that, round-off dominates the ratio).

use crate::support::physics::{self, rate_unit, wobbling};
use coin_log::model::{Coin, CoinParams};

/// Error floor below which a ratio is not trusted: 1e3 × machine epsilon.
const FLOOR: f64 = 1e3 * f64::EPSILON;
/// Allowed deviation of the observed order from 4.
const ORDER_SLACK: f64 = 0.15;

/// Largest component error, each scaled by its natural unit (radians, √(g/a), a).
fn scaled_error(p: &CoinParams, y: &[f64; 8], reference: &[f64; 8]) -> f64 {
    let units = [
        1.0,
        1.0,
        1.0,
        rate_unit(p),
        rate_unit(p),
        rate_unit(p),
        p.radius(),
        p.radius(),
    ];
    (0..8)
        .map(|i| (y[i] - reference[i]).abs() / units[i])
        .fold(0.0, f64::max)
}

fn observed_orders(label: &str, p: &CoinParams) {
    let coin = Coin::new(*p);
    let y0 = wobbling(p).to_array();
    let tu = p.time_unit();
    let span = 4.0 * tu;
    let finest_steps = 40 << 6;
    #[allow(clippy::cast_precision_loss)]
    let reference = physics::rk4_final(
        &coin,
        &y0,
        span / (16 * finest_steps) as f64,
        16 * finest_steps,
    );
    let mut errors = Vec::new();
    for k in 0..7 {
        let steps = 40usize << k; // h = 0.1 .. 0.0016 natural units (h = 0.2 is not yet asymptotic)
        #[allow(clippy::cast_precision_loss)]
        let h = span / steps as f64;
        let e = scaled_error(p, &physics::rk4_final(&coin, &y0, h, steps), &reference);
        println!("{label}: h = {:.5} (natural units): error {e:.3e}", h / tu);
        errors.push(e);
        assert!(steps <= finest_steps);
    }
    let mut checked = 0;
    for pair in errors.windows(2) {
        if pair[1] < FLOOR {
            println!(
                "{label}: error {:.3e} below the floor {FLOOR:.1e}; ratio not used",
                pair[1]
            );
            continue;
        }
        let order = (pair[0] / pair[1]).log2();
        physics::check(&format!("{label}: observed order"), order, 4.0, ORDER_SLACK);
        checked += 1;
    }
    assert!(
        checked >= 4,
        "only {checked} step pairs above the error floor"
    );
}

#[test]
fn rk4_converges_at_fourth_order_on_the_thin_disk() {
    observed_orders("unit thin disk", &physics::unit_disk());
}

#[test]
fn rk4_converges_at_fourth_order_for_general_parameters() {
    observed_orders("general", &physics::general());
}
