//! The physics checks. Each is a running accumulator: `observe` sees every sample once, in time order, and
//! keeps only maxima, sums and a short window; `finish` turns them into a [`CheckResult`](crate::verify::CheckResult).

pub mod consistency;
pub mod constraint;
pub mod energy;
pub mod integrity;
pub mod invariants;
pub mod nutation;
pub mod steady;
pub mod validity;

pub use crate::model::drift::Worst as Max;

use super::samples::Sample;
use crate::format::{ResultMetadata, RunMetadata};
use crate::model::{magnitude, Chaplygin, Coin, Dynamics, Steady};
use crate::scene::Scene;

/// What the checks know about the run besides its samples: the file's metadata.
#[derive(Debug, Clone)]
pub struct Context {
    /// The coin built from the metadata's M, a, g, I_X, I_Z.
    pub coin: Coin,
    /// Its equations with the metadata's dissipation, if any (physics §11): the reaction follows them.
    pub dynamics: Dynamics,
    /// The `coin-log` record.
    pub run: RunMetadata,
    /// The `coin-log.result` record, if the run finished writing it.
    pub result: Option<ResultMetadata>,
    /// The scene the `coin-log` record stores, read and validated as `record` reads one, or why it cannot
    /// be.
    pub scene: Result<Scene, String>,
    /// The steady motion the scene asks for, or why the steady check does not apply.
    pub steady: Result<Steady, String>,
    /// C1, C2 for these parameters (physics §6), or why they cannot be evaluated.
    pub chaplygin: Result<Chaplygin, String>,
}

/// Run-wide quantities the tolerances and scales need.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RunStats {
    pub first_t: Option<f64>,
    pub last_t: f64,
    pub samples: u64,
    /// max|ω| over samples with ω.
    pub max_omega: f64,
    /// θ of the last sample, when it has the angles.
    pub last_theta: Option<f64>,
}

impl RunStats {
    pub fn observe(&mut self, s: &Sample) {
        self.first_t.get_or_insert(s.t);
        self.last_t = s.t;
        self.samples += 1;
        self.last_theta = s.angles.map(|a| a.theta);
        if let Some(w) = s.omega {
            self.max_omega = self.max_omega.max(magnitude(w.x, w.y, w.z));
        }
    }

    #[must_use]
    pub fn span(&self) -> f64 {
        self.first_t.map_or(0.0, |t0| self.last_t - t0)
    }
}

/// The worst of `first` and `rest`, (value, tolerance, label) measures: the one with the largest
/// value/tolerance (the last of equals).
#[must_use]
pub fn worst<'a>(first: (f64, f64, &'a str), rest: &[(f64, f64, &'a str)]) -> (f64, f64, &'a str) {
    let ratio = |m: &(f64, f64, &str)| {
        if m.0.is_nan() {
            f64::INFINITY
        } else {
            m.0 / m.1
        }
    };
    rest.iter().copied().fold(first, |w, m| {
        if ratio(&m).total_cmp(&ratio(&w)).is_ge() {
            m
        } else {
            w
        }
    })
}

/// Shortest readable form of a number for reasons: 3 significant digits.
#[must_use]
pub fn fmt_num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if (1e-3..1e4).contains(&x.abs()) {
        format!("{x:.4}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{x:.2e}")
    }
}
