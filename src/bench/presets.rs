//! The scenes the bench knows by name, as [`BenchCase`]s (the record issue's built-ins that the bench
//! uses, with the same physics: wobble, circle-plus, high-spin, ...).

use super::{BenchCase, BenchError, DEFAULT_FLAT_MARGIN};
use crate::model::{Branch, Coin, CoinParams, State, Steady, SteadyKind};

/// Scenes `bench precision` runs when none are given.
pub const DEFAULT_PRECISION_SCENES: &[&str] = &["wobble", "circle-plus", "high-spin"];

/// Every scene name the bench accepts.
pub const BENCH_SCENES: &[&str] = &[
    "wobble",
    "circle-plus",
    "circle-minus",
    "centre-fixed",
    "straight",
    "high-spin",
    "near-flat",
];

/// A bench case from a built-in scene name.
///
/// # Errors
/// [`BenchError::UnknownScene`] for a name not in [`BENCH_SCENES`]; [`BenchError::InvalidScene`] if the
/// steady motion cannot be built (it always can for the built-ins).
pub fn bench_case(name: &str) -> Result<BenchCase, BenchError> {
    let coin = Coin::new(CoinParams::unit_disk());
    let explicit = |state: State, duration: f64| BenchCase {
        name: name.to_string(),
        coin,
        initial: state,
        steady: None,
        duration,
        flat_margin: DEFAULT_FLAT_MARGIN,
        friction: None,
    };
    let steady = |kind: SteadyKind, duration: f64| -> Result<BenchCase, BenchError> {
        let s = Steady::new(&coin, kind).map_err(|e| BenchError::InvalidScene {
            scene: name.to_string(),
            reason: e.to_string(),
        })?;
        Ok(BenchCase {
            steady: Some(s),
            ..explicit(s.state, duration)
        })
    };
    match name {
        // A generic wobbling motion (issue 4's test motion): θ₀ = 0.5, ω = (0.3, 0.2, 1.5).
        "wobble" => Ok(explicit(
            State {
                theta: 0.5,
                omega_x: 0.3,
                omega_y: 0.2,
                omega_z: 1.5,
                ..State::default()
            },
            30.0,
        )),
        "circle-plus" => steady(
            SteadyKind::Circle {
                theta: 0.3,
                omega_z: 1.0,
                branch: Branch::Plus,
            },
            20.0,
        ),
        "circle-minus" => steady(
            SteadyKind::Circle {
                theta: 0.3,
                omega_z: 1.0,
                branch: Branch::Minus,
            },
            20.0,
        ),
        "centre-fixed" => steady(
            SteadyKind::CentreFixed {
                theta: 0.3,
                branch: Branch::Plus,
            },
            20.0,
        ),
        "straight" => steady(SteadyKind::Straight { omega_z: 1.0 }, 20.0),
        // Fast spin (NOTES §7): ω_Z = 50 on a steady circle at tilt 0.2; nutation period ≈ 0.08.
        "high-spin" => steady(
            SteadyKind::Circle {
                theta: 0.2,
                omega_z: 50.0,
                branch: Branch::Plus,
            },
            5.0,
        ),
        // Near flat (NOTES §7): centre-fixed at θ = 1.5 with a kick in ω_X.
        "near-flat" => {
            let mut case = steady(
                SteadyKind::CentreFixed {
                    theta: 1.5,
                    branch: Branch::Plus,
                },
                10.0,
            )?;
            case.initial.omega_x += 1e-2;
            case.steady = None;
            Ok(case)
        }
        _ => Err(BenchError::UnknownScene {
            name: name.to_string(),
            valid: BENCH_SCENES.join(", "),
        }),
    }
}
