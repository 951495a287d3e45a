//! Drift of the conserved quantities over a run, defined once (format.md, "Drift definitions") for the
//! recorder's summary, the benches and `verify`. A NaN wins every comparison: a non-finite value makes the
//! drift NaN, which fails any tolerance.

use super::params::CoinParams;

/// A running maximum and the time it happened. NaN is larger than everything.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Worst {
    /// The largest value offered so far (0 before any).
    pub value: f64,
    /// When it was offered.
    pub t: f64,
}

impl Worst {
    /// Offers `value` at time `t`.
    #[inline]
    pub fn offer(&mut self, value: f64, t: f64) {
        if value > self.value || (value.is_nan() && !self.value.is_nan()) {
            self.value = value;
            self.t = t;
        }
    }
}

/// Running drift of conserved quantities from their reference value `R`: [`EnergyDrift`] or
/// [`InvariantDrift`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drift<R> {
    /// The reference value: E₀, or (C1₀, C2₀).
    pub reference: R,
    /// The scale the deviations are divided by.
    pub scale: f64,
    worst: Worst,
}

/// Running energy drift from a reference E₀.
pub type EnergyDrift = Drift<f64>;

/// Running drift of the Chaplygin–Appell integrals from a reference (C1₀, C2₀).
pub type InvariantDrift = Drift<(f64, f64)>;

impl<R> Drift<R> {
    /// max |deviation| / scale so far (0 before any observation).
    #[must_use]
    pub fn value(&self) -> f64 {
        self.worst.value
    }

    /// When the largest deviation happened.
    #[must_use]
    pub fn worst_time(&self) -> f64 {
        self.worst.t
    }
}

impl EnergyDrift {
    /// Drift from `e0` for a body with `params` (scale max(|E₀|, M g a)).
    ///
    /// ```
    /// use coin_log::model::{drift::EnergyDrift, CoinParams};
    /// let mut d = EnergyDrift::new(&CoinParams::unit_disk(), 0.0);
    /// d.observe(1.0, 1e-3);
    /// assert_eq!(d.value(), 1e-3); // relative to M g a = 1, since E₀ = 0
    /// ```
    #[must_use]
    pub fn new(params: &CoinParams, e0: f64) -> Self {
        Self {
            reference: e0,
            scale: e0.abs().max(params.energy_scale()),
            worst: Worst::default(),
        }
    }

    /// Accounts for the energy `e` at time `t`.
    #[inline]
    pub fn observe(&mut self, t: f64, e: f64) {
        self.worst.offer((e - self.reference).abs() / self.scale, t);
    }
}

impl InvariantDrift {
    /// Drift from (`c1`, `c2`) for a body with `params`: scale |C1₀| + |C2₀|, or √(g/a) when both are 0.
    ///
    /// ```
    /// use coin_log::model::{drift::InvariantDrift, CoinParams};
    /// let mut d = InvariantDrift::new(&CoinParams::unit_disk(), 0.0, 0.0);
    /// d.observe(2.0, 1e-9, 0.0);
    /// assert!(d.natural_scale() && d.value() == 1e-9); // √(g/a) = 1
    /// ```
    #[must_use]
    pub fn new(params: &CoinParams, c1: f64, c2: f64) -> Self {
        let sum = c1.abs() + c2.abs();
        Self {
            reference: (c1, c2),
            scale: if sum == 0.0 {
                1.0 / params.time_unit()
            } else {
                sum
            },
            worst: Worst::default(),
        }
    }

    /// Accounts for (C1, C2) at time `t`.
    #[inline]
    pub fn observe(&mut self, t: f64, c1: f64, c2: f64) {
        let (c10, c20) = self.reference;
        let d = (c1 - c10).abs().max((c2 - c20).abs());
        self.worst.offer(d / self.scale, t);
    }

    /// True when C1₀ = C2₀ = 0 and the scale is √(g/a).
    #[must_use]
    pub fn natural_scale(&self) -> bool {
        self.reference.0.abs() + self.reference.1.abs() == 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Inertia;

    #[test]
    fn nan_wins_and_stays() {
        let mut d = EnergyDrift::new(&CoinParams::unit_disk(), 2.0);
        d.observe(0.0, 2.5);
        d.observe(1.0, f64::NAN);
        d.observe(2.0, 100.0);
        assert!(d.value().is_nan());
        assert_eq!(d.worst_time(), 1.0);
    }

    #[test]
    fn scales_follow_the_definition() {
        let p = CoinParams::new(2.0, 0.5, 8.0, Inertia::ThinDisk).unwrap();
        // E₀ = 10 > Mga = 8: relative to E₀.
        let mut e = EnergyDrift::new(&p, -10.0);
        e.observe(0.0, -9.0);
        assert_eq!(e.scale, 10.0);
        assert_eq!(e.value(), 0.1);
        // E₀ = 1 < Mga = 8: relative to Mga.
        assert_eq!(EnergyDrift::new(&p, 1.0).scale, 8.0);
        let c = InvariantDrift::new(&p, 0.25, -0.5);
        assert!(!c.natural_scale());
        assert_eq!(c.scale, 0.75);
        // C₀ = 0: √(g/a) = 4.
        let mut z = InvariantDrift::new(&p, 0.0, -0.0);
        assert_eq!(z.scale, 4.0);
        z.observe(3.0, 0.0, 2.0);
        assert_eq!((z.value(), z.worst_time()), (0.5, 3.0));
    }
}
