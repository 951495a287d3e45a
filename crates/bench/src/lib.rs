//! Benchmarks of accuracy, cost and robustness on top of the library: work-precision sweeps of every
//! integrator on a scene ([`precision`]), a fixed suite of hard cases ([`suite`]), Euler's disk time laws
//! ([`euler`]), the throughput workloads ([`throughput`]), and their output as tables, CSV ([`table`]) and
//! SVG diagrams ([`plot`]). The micro-benchmarks (one right-hand side, each integrator on `wobble`, one
//! C1/C2 evaluation) are criterion's, in `benches/`.
//!
//! The physics they measure against is the library's (`coin_log::model`, `coin_log::analyse`). The crate
//! returns rows; only the `coin-log bench` command prints them, writes files, or starts processes (the
//! throughput bench's record, verify and export runs).

mod case;
pub mod euler;
pub mod nutation;
pub mod plot;
pub mod precision;
pub mod presets;
pub mod stability;
pub mod suite;
pub mod table;
pub mod throughput;

pub use case::{
    balance_drift, default_config, energy_drift, invariant_drift, median, natural_scales,
    reference_trajectory, run_sampled, state_difference, state_error, BenchCase, Reference,
    ReferenceKind, Trajectory, DEFAULT_FLAT_MARGIN, SAMPLES_PER_TIME_UNIT,
};

use coin_log::integrate::Method;
use thiserror::Error;

/// Why a benchmark could not run.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum BenchError {
    /// A scene name that is not a built-in.
    #[error("no built-in scene `{name}`; built-in scenes: {valid}")]
    UnknownScene {
        /// What was given.
        name: String,
        /// Comma-separated valid names.
        valid: String,
    },
    /// The scene's parameters or steady motion are invalid.
    #[error("scene `{scene}`: {reason}")]
    InvalidScene {
        /// Scene name.
        scene: String,
        /// What is wrong.
        reason: String,
    },
    /// The reference run did not reach the end of the scene.
    #[error("scene `{scene}`: the reference run ({reference}) ended early: {termination}")]
    ReferenceFailed {
        /// Scene name.
        scene: String,
        /// Which reference.
        reference: String,
        /// How it ended.
        termination: String,
    },
    /// No setting of a method reaches the state error asked for.
    #[error("scene `{scene}`: {method} does not reach a state error of {error:e} (best {best:e})")]
    Inaccurate {
        /// Scene name.
        scene: String,
        /// The method.
        method: Method,
        /// The state error asked for.
        error: f64,
        /// The smallest it reached.
        best: f64,
    },
    /// Drawing the SVG failed.
    #[error("drawing the work-precision diagram of `{scene}`: {reason}")]
    Plot {
        /// Scene name.
        scene: String,
        /// The drawing backend's message.
        reason: String,
    },
}
