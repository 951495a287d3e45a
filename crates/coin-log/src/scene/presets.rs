//! The built-in scenes, each also a file `datasets/scenes/<name>.toml` written by
//! `coin-log scenes --show <name>` (a test checks that the files and these presets agree).
//!
//! Unless said otherwise: the unit thin disk (M = a = g = 1, physics §2), the default run settings and all
//! channels, durations of 20–30 time units at 100 samples per unit so that recordings stay small.

use super::file::{
    BodyFile, DissipationFile, InitialFile, PerturbationFile, RunFile, SceneFile, SteadyFile,
};

/// Every built-in scene name, in listing order.
pub const NAMES: [&str; 15] = [
    "straight",
    "straight-unstable",
    "centre-fixed",
    "circle-plus",
    "circle-minus",
    "large-circle",
    "spin-upright",
    "wobble",
    "high-spin",
    "near-flat",
    "topple",
    "lift-off",
    "long-horizon",
    "five-hundred-yen",
    "euler-disk",
];

/// Dynamic viscosity of air at about 20 °C \[Pa·s\], for the `euler-disk` scene's Moffatt coefficient.
pub const AIR_VISCOSITY: f64 = 1.8e-5;

/// Radius of the `euler-disk` toy \[m\]: a 75 mm disk.
pub const EULER_DISK_RADIUS: f64 = 0.0375;

/// Moffatt's coefficient of a disk of radius `a` in air of viscosity `mu` (physics §11, eq (39)):
/// κ = (π/4) μ a³, the value for which P = κ φ̇²/sin α reproduces Moffatt's spin time
/// t₀ = α₀³ M / (2π μ a) on the thin disk's centre-fixed motion.
#[must_use]
pub fn moffatt_coefficient(mu: f64, a: f64) -> f64 {
    std::f64::consts::FRAC_PI_4 * mu * a * a * a
}

/// The built-in scene `name`, as a file.
#[must_use]
#[allow(
    clippy::too_many_lines,
    reason = "a table: one match arm per built-in scene, each a literal scene"
)]
pub fn preset(name: &str) -> Option<SceneFile> {
    Some(match name {
        "straight" => steady(
            "Upright coin rolling straight at ω_Z = 1, above the critical spin 1/√3: stable (physics §4.1, §5)",
            straight(1.0),
            20.0,
        ),
        "straight-unstable" => SceneFile {
            initial: InitialFile {
                perturbation: Some(PerturbationFile {
                    theta: Some(1e-6),
                    omega: None,
                }),
                ..steady_initial(straight(0.3))
            },
            ..steady(
                "Straight rolling at ω_Z = 0.3 < ω_c = 1/√3 with a 1e-6 tilt: the tilt grows like e^{λt}, λ = 0.764, to about 1 rad by t = 19 (physics §5)",
                straight(0.3),
                20.0,
            )
        },
        "centre-fixed" => steady(
            "Centre at rest, the coin leaning θ = 0.5 and rolling round it (physics §4.2)",
            SteadyFile {
                kind: "centre-fixed".into(),
                theta: Some(0.5),
                ..SteadyFile::default()
            },
            20.0,
        ),
        "circle-plus" => steady(
            "Steady circle θ = 0.3, ω_Z = 1 on the + branch: R_G = 4.8979, R_C = 5.1934 (physics §4.3 example)",
            circle(0.3, 1.0, "+"),
            30.0,
        ),
        "circle-minus" => steady(
            "Steady circle θ = 0.3, ω_Z = 1 on the − branch: a fast, tight turn (physics §4.3)",
            circle(0.3, 1.0, "-"),
            20.0,
        ),
        "large-circle" => steady(
            "Steady circle θ = 0.05, ω_Z = 2 on the + branch: R_G ≈ (3/2) ω_Z²/sin θ ≈ 120 (physics §4.4)",
            circle(0.05, 2.0, "+"),
            30.0,
        ),
        "spin-upright" => steady(
            "Spinning upright in place about the vertical at Ω = 2 > √(4/5): stable (physics §5)",
            SteadyFile {
                kind: "spin-upright".into(),
                omega_y: Some(2.0),
                ..SteadyFile::default()
            },
            20.0,
        ),
        "wobble" => explicit(
            "A generic motion: θ0 = 0.5, ω = (0.3, 0.2, 1.5), 30 time units",
            0.5,
            [0.3, 0.2, 1.5],
            30.0,
        ),
        "high-spin" => SceneFile {
            initial: InitialFile {
                perturbation: Some(PerturbationFile {
                    theta: Some(0.01),
                    omega: None,
                }),
                ..steady_initial(straight(50.0))
            },
            // 1000 samples per unit: at ω_Z = 50 the spin turns 0.05 rad between samples, so the stored
            // trajectory resolves the motion and `verify` can difference it (at 100 it cannot).
            run: Some(RunFile {
                duration: Some(5.0),
                rate: Some(1000.0),
                ..RunFile::default()
            }),
            ..steady(
                "Straight rolling at ω_Z = 50 kicked by a 0.01 tilt: fast spin, a small fast wobble, sampled at 1 kHz",
                straight(50.0),
                5.0,
            )
        },
        "near-flat" => SceneFile {
            initial: InitialFile {
                perturbation: Some(PerturbationFile {
                    theta: Some(1e-3),
                    omega: None,
                }),
                ..steady_initial(SteadyFile {
                    kind: "centre-fixed".into(),
                    theta: Some(1.5),
                    ..SteadyFile::default()
                })
            },
            ..steady(
                "Centre-fixed motion at θ = 1.5, 0.07 rad from flat, kicked by 1e-3: tan θ ≈ 14, fast φ̇ (physics §7)",
                SteadyFile::default(),
                20.0,
            )
        },
        "topple" => explicit(
            "Released at θ0 = 0.6 without spin: the coin falls and the run ends at the flat landing",
            0.6,
            [0.0, 0.0, 0.0],
            30.0,
        ),
        "lift-off" => explicit(
            "Released at θ0 = 0.2 without spin: it falls from high up and the run ends when N reaches 0",
            0.2,
            [0.0, 0.0, 0.0],
            30.0,
        ),
        "long-horizon" => SceneFile {
            run: Some(RunFile {
                duration: Some(1000.0),
                rate: Some(10.0),
                ..RunFile::default()
            }),
            ..explicit(
                "The wobble for 1000 time units at 10 samples per unit: long-time drift of E, C1, C2",
                0.5,
                [0.3, 0.2, 1.5],
                1000.0,
            )
        },
        "five-hundred-yen" => SceneFile {
            description: Some(
                "A 500-yen coin in SI units (M = 7 g, a = 13.25 mm, g = 9.81 m/s²; time unit √(a/g) = 36.75 ms) rolling on a steady circle θ = 0.3, ω_Z = 30 rad/s; 3 s at 200 samples/s".into(),
            ),
            body: BodyFile {
                mass: 0.007,
                radius: 0.01325,
                gravity: 9.81,
                shape: Some("thin-disk".into()),
                // 1.8 mm thick for 13.25 mm radius.
                thickness: Some(0.136),
                ..BodyFile::default()
            },
            initial: steady_initial(circle(0.3, 30.0, "+")),
            run: Some(RunFile {
                duration: Some(3.0),
                rate: Some(200.0),
                ..RunFile::default()
            }),
            record: None,
        },
        "euler-disk" => euler_disk(),
        _ => return None,
    })
}

/// The `euler-disk` scene: a toy-like steel disk in SI units on its centre-fixed motion at α₀ = 0.2,
/// losing energy by Moffatt's air film (physics §11) until an event ends the run. No μ: the rolling model
/// is followed to the end of the collapse (`bench euler` reports where μ = 0.3 would slip first).
fn euler_disk() -> SceneFile {
    let a = EULER_DISK_RADIUS;
    SceneFile {
        description: Some(
            "Euler's disk: a 75 mm, 0.45 kg steel toy in SI units (a = 37.5 mm, g = 9.81 m/s²; time unit 61.8 ms) started on its centre-fixed motion at α0 = 0.2 rad from the table, losing energy to Moffatt's air film (κ = (π/4)·1.8e-5 Pa·s·a³, physics §11) until an event ends the run (the flat landing, 860 s later; with --set body.friction=0.3 a slip at α = 0.095)".into(),
        ),
        body: BodyFile {
            mass: 0.45,
            radius: a,
            gravity: 9.81,
            shape: Some("thin-disk".into()),
            // 13 mm thick for a 37.5 mm radius.
            thickness: Some(0.35),
            dissipation: Some(DissipationFile {
                model: "moffatt".into(),
                coefficient: Some(moffatt_coefficient(AIR_VISCOSITY, a)),
                m: None,
                k: None,
            }),
            ..BodyFile::default()
        },
        initial: steady_initial(SteadyFile {
            kind: "centre-fixed".into(),
            theta: Some(std::f64::consts::FRAC_PI_2 - 0.2),
            ..SteadyFile::default()
        }),
        // Longer than the collapse (≈ 860 s): an event ends the run. 400 samples/s resolve the precession
        // (72 rad/s at α = 0.2, 100 rad/s at α = 0.1) for verify's constraint check over most of the run.
        run: Some(RunFile {
            duration: Some(2000.0),
            rate: Some(400.0),
            ..RunFile::default()
        }),
        record: None,
    }
}

fn unit_disk() -> BodyFile {
    BodyFile {
        mass: 1.0,
        radius: 1.0,
        gravity: 1.0,
        shape: Some("thin-disk".into()),
        ..BodyFile::default()
    }
}

fn run(duration: f64) -> Option<RunFile> {
    Some(RunFile {
        duration: Some(duration),
        ..RunFile::default()
    })
}

fn straight(omega_z: f64) -> SteadyFile {
    SteadyFile {
        kind: "straight".into(),
        omega_z: Some(omega_z),
        ..SteadyFile::default()
    }
}

fn circle(theta: f64, omega_z: f64, branch: &str) -> SteadyFile {
    SteadyFile {
        kind: "circle".into(),
        theta: Some(theta),
        omega_z: Some(omega_z),
        branch: Some(branch.into()),
        ..SteadyFile::default()
    }
}

fn steady_initial(steady: SteadyFile) -> InitialFile {
    InitialFile {
        steady: Some(steady),
        ..InitialFile::default()
    }
}

fn steady(description: &str, motion: SteadyFile, duration: f64) -> SceneFile {
    SceneFile {
        description: Some(description.into()),
        body: unit_disk(),
        initial: steady_initial(motion),
        run: run(duration),
        record: None,
    }
}

fn explicit(description: &str, theta: f64, omega: [f64; 3], duration: f64) -> SceneFile {
    SceneFile {
        description: Some(description.into()),
        body: unit_disk(),
        initial: InitialFile {
            theta: Some(theta),
            omega: Some(omega.to_vec()),
            ..InitialFile::default()
        },
        run: run(duration),
        record: None,
    }
}
