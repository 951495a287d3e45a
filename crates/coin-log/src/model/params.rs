//! Body parameters of the coin: mass M, radius a, gravity g and the axisymmetric inertia (physics §1–§2).

use thiserror::Error;

/// A body parameter that is NaN, infinite, zero or negative.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("`{name}` = {value} is not allowed: it must be a finite number > 0")]
pub struct ParamError {
    /// Name of the field (`mass`, `radius`, `gravity`, `inertia_x`, `inertia_z`).
    pub name: &'static str,
    /// The value that was given.
    pub value: f64,
}

/// How the axisymmetric inertia is specified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Inertia {
    /// Thin uniform disk: I_X = Ma²/4, I_Z = Ma²/2 (physics §2).
    ThinDisk,
    /// Thin ring: I_X = Ma²/2, I_Z = Ma² (physics §2).
    Hoop,
    /// Explicit moments about a diameter (`inertia_x`) and the symmetry axis (`inertia_z`), in M·length².
    Explicit {
        /// Moment of inertia about a diameter, I_X = I_Y [mass·length²].
        inertia_x: f64,
        /// Moment of inertia about the symmetry axis, I_Z [mass·length²].
        inertia_z: f64,
    },
}

/// Validated body parameters, in any consistent set of units.
///
/// Built only through [`CoinParams::new`], so every field is finite and positive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoinParams {
    mass: f64,
    radius: f64,
    gravity: f64,
    inertia_x: f64,
    inertia_z: f64,
}

fn positive(name: &'static str, value: f64, errors: &mut Vec<ParamError>) {
    if !(value.is_finite() && value > 0.0) {
        errors.push(ParamError { name, value });
    }
}

impl CoinParams {
    /// Validates M, a, g and the inertia; reports every bad field at once: one [`ParamError`] per field
    /// that is not a finite positive number.
    ///
    /// ```
    /// use coin_log::model::{CoinParams, Inertia};
    /// let p = CoinParams::new(1.0, 1.0, 1.0, Inertia::ThinDisk).unwrap();
    /// assert_eq!(p.inertia_z(), 0.5);
    /// assert!(CoinParams::new(-1.0, 1.0, 1.0, Inertia::Hoop).is_err());
    /// ```
    pub fn new(
        mass: f64,
        radius: f64,
        gravity: f64,
        inertia: Inertia,
    ) -> Result<Self, Vec<ParamError>> {
        let mut errors = Vec::new();
        positive("mass", mass, &mut errors);
        positive("radius", radius, &mut errors);
        positive("gravity", gravity, &mut errors);
        let ma2 = mass * radius * radius;
        let (inertia_x, inertia_z) = match inertia {
            Inertia::ThinDisk => (ma2 / 4.0, ma2 / 2.0),
            Inertia::Hoop => (ma2 / 2.0, ma2),
            Inertia::Explicit {
                inertia_x,
                inertia_z,
            } => (inertia_x, inertia_z),
        };
        // Explicit inertias are checked as given; a shape's (M a²/4, ...) can overflow to inf or
        // underflow to 0 when M and a are valid: checked then (not when M or a is already reported, to
        // name each problem once).
        let scale_ok = [mass, radius].iter().all(|v| v.is_finite() && *v > 0.0);
        if scale_ok || matches!(inertia, Inertia::Explicit { .. }) {
            positive("inertia_x", inertia_x, &mut errors);
            positive("inertia_z", inertia_z, &mut errors);
        }
        if errors.is_empty() {
            Ok(Self {
                mass,
                radius,
                gravity,
                inertia_x,
                inertia_z,
            })
        } else {
            Err(errors)
        }
    }

    /// The note's unit thin disk: M = a = g = 1.
    #[must_use]
    pub fn unit_disk() -> Self {
        Self {
            mass: 1.0,
            radius: 1.0,
            gravity: 1.0,
            inertia_x: 0.25,
            inertia_z: 0.5,
        }
    }

    getters! {
        /// Mass M \[mass\].
        mass: f64,
        /// Radius a \[length\].
        radius: f64,
        /// Gravitational acceleration g [length/time²].
        gravity: f64,
        /// Moment of inertia about a diameter, I_X = I_Y [mass·length²].
        inertia_x: f64,
        /// Moment of inertia about the symmetry axis, I_Z [mass·length²].
        inertia_z: f64,
    }

    /// M a² [mass·length²].
    #[must_use]
    pub fn ma2(&self) -> f64 {
        self.mass * self.radius * self.radius
    }
    /// The natural time unit √(a/g) (physics §2).
    #[must_use]
    pub fn time_unit(&self) -> f64 {
        (self.radius / self.gravity).sqrt()
    }
    /// The energy scale M g a used to make energy drift relative (format.md, verify).
    #[must_use]
    pub fn energy_scale(&self) -> f64 {
        self.mass * self.gravity * self.radius
    }
    /// K = Mga/(I_X + Ma²) [1/time²]: a coin without spin topples as θ̈ = K sin θ (eq (14) with
    /// ω_Y = ω_Z = 0), and the upright spin is stable above Ω_c² = K (physics §5).
    ///
    /// ```
    /// // Thin disk, unit scales: I_X + Ma² = 5/4.
    /// assert_eq!(coin_log::model::CoinParams::unit_disk().topple_rate_squared(), 0.8);
    /// ```
    #[must_use]
    pub fn topple_rate_squared(&self) -> f64 {
        self.energy_scale() / (self.inertia_x + self.ma2())
    }
}
