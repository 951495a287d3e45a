//! Chaplygin–Appell integrals C1, C2 (physics §6) from the even and odd solutions y_e, y_o of Legendre's
//! equation in s = sin θ, by two exact series, about s = 0 and about s = 1, matched at a split; the method
//! and its measured accuracy are in physics §6, "Evaluating y_e and y_o".

use super::params::CoinParams;
use super::state::State;
use std::f64::consts::FRAC_PI_2;
use thiserror::Error;

/// |s| at which the two expansions meet for μ ≤ [`MU_SPLIT_FIXED`]: both series variables, t = s² and
/// x = (1 − |s|)/2, are ≤ ¼ there, so both series converge like 4⁻ⁿ.
const SPLIT_SIN: f64 = 0.5;
/// Above this μ the split moves towards s = 1, keeping √μ (π/2 − θ_split) at its value for μ = 4,
/// θ_split = π/6: matching there costs a factor ≈ 70 in conditioning (physics §6).
const MU_SPLIT_FIXED: f64 = 4.0;
/// The first dropped term, at the largest series variable, is below this fraction of the sum of the
/// magnitudes of the terms, and the terms have been decreasing for [`DECREASING_RUN`] steps (so the
/// geometric tail is of the same order): well under one ulp.
const TRUNCATION: f64 = 1e-18;
/// See [`TRUNCATION`].
const DECREASING_RUN: usize = 2;
/// A hard bound on the series length (μ ≤ [`MU_MAX`] needs about 1000 at most).
const MAX_TERMS: usize = 20_000;
/// Largest μ accepted (every real body has μ < 2). The tests cover μ = 20 and μ = 100.
const MU_MAX: f64 = 100.0;

/// Why the integrals cannot be built for these parameters.
#[derive(Debug, Clone, PartialEq, Error)]
#[allow(missing_docs, reason = "each field is named in its variant's message")]
pub enum InvariantsError {
    /// The parameters' μ is larger than 100 (`max`).
    #[error(
        "μ = I_Z·Ma²/(I_X·(I_Z + Ma²)) = {mu} is above {max}, where C1, C2 cannot be evaluated accurately; \
         every real body has I_Z ≤ 2·I_X and μ < 2, so check inertia_x and inertia_z"
    )]
    MuTooLarge { mu: f64, max: f64 },
}

/// The two Chaplygin–Appell integrals of one state (physics §6).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Invariants {
    /// C1 = cos²θ y_o′(s) ω_Z − cos θ y_o(s) ω_Y / k [rad/time].
    pub c1: f64,
    /// C2 = cos θ y_e(s) ω_Y / k − cos²θ y_e′(s) ω_Z [rad/time].
    pub c2: f64,
}

/// The Legendre solutions of physics §6 and their derivatives at one s = sin θ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegendreBasis {
    /// y_e(s), the even solution with y_e(0) = 1, y_e′(0) = 0.
    pub y_even: f64,
    /// y_o(s), the odd solution with y_o(0) = 0, y_o′(0) = 1.
    pub y_odd: f64,
    /// y_e′(s) = dy_e/ds (grows like 1/(1 − |s|) near ±1).
    pub dy_even: f64,
    /// y_o′(s) = dy_o/ds.
    pub dy_odd: f64,
    /// The flux (1 − s²) y_e′(s) = cos²θ y_e′, finite at s = ±1.
    pub flux_even: f64,
    /// The flux (1 − s²) y_o′(s) = cos²θ y_o′.
    pub flux_odd: f64,
}

/// y = α u₁ + β u₂ near s = 1.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Connection {
    alpha: f64,
    beta: f64,
}

/// C1, C2 for one set of body parameters: the series coefficients and connection constants, computed once.
///
/// ```
/// use coin_log::model::{Chaplygin, CoinParams};
/// let chaplygin = Chaplygin::new(&CoinParams::unit_disk()).unwrap();
/// // Upright (s = 0): y_e = 1, y_o = 0, y_e′ = 0, y_o′ = 1, k = 3/2, so C1 = ω_Z and C2 = ω_Y / k.
/// let c = chaplygin.evaluate(0.0, 0.6, 1.5);
/// assert!((c.c1 - 1.5).abs() < 1e-15 && (c.c2 - 0.4).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Chaplygin {
    mu: f64,
    /// 1/k = Ma²/(I_Z + Ma²).
    inverse_k: f64,
    /// Series about s = 0 in t = s²: [y_e, y_e′/s, y_o/s, y_o′] coefficients of tⁿ.
    centre: Vec<[f64; 4]>,
    /// Series about s = 1 in x = (1 − |s|)/2: [c_n, n c_n, d_n, n d_n] coefficients of xⁿ.
    edge: Vec<[f64; 4]>,
    /// |s| above which the expansion about s = 1 is used.
    split_sin: f64,
    even: Connection,
    odd: Connection,
}

impl Chaplygin {
    /// Precomputes the expansions of physics §6 for `params`; fails ([`InvariantsError::MuTooLarge`]) if
    /// μ > 100 (no real body).
    pub fn new(params: &CoinParams) -> Result<Self, InvariantsError> {
        let ma2 = params.ma2();
        let iz = params.inertia_z();
        let ix = params.inertia_x();
        let mu = iz * ma2 / (ix * (iz + ma2));
        if !mu.is_finite() || mu > MU_MAX {
            return Err(InvariantsError::MuTooLarge { mu, max: MU_MAX });
        }
        // θ_split = π/2 − (π/2 − π/6)·√(4/μ) beyond MU_SPLIT_FIXED (see there).
        let split_theta = if mu <= MU_SPLIT_FIXED {
            SPLIT_SIN.asin()
        } else {
            FRAC_PI_2 - (FRAC_PI_2 - SPLIT_SIN.asin()) * (MU_SPLIT_FIXED / mu).sqrt()
        };
        let (split_sin, split_cos) = split_theta.sin_cos();
        let split_cos2 = split_cos * split_cos;
        let split_x = split_cos2 / (2.0 * (1.0 + split_sin));
        let mut chaplygin = Self {
            mu,
            inverse_k: ma2 / (iz + ma2),
            centre: centre_coefficients(mu, split_sin * split_sin),
            edge: edge_coefficients(mu, split_x),
            split_sin,
            even: Connection::default(),
            odd: Connection::default(),
        };
        // Match value and flux of the two expansions at the split.
        let (y_even, flux_even, y_odd, flux_odd) = chaplygin.centre_values(split_sin, split_cos2);
        let [u1, flux1, u2, flux2] = chaplygin.edge_basis(split_x);
        // Exact Wronskian u₁ p₂ − u₂ p₁ = −2 (its value at x = 0).
        let connect = |y: f64, flux: f64| Connection {
            alpha: (y * flux2 - u2 * flux) / -2.0,
            beta: (u1 * flux - y * flux1) / -2.0,
        };
        chaplygin.even = connect(y_even, flux_even);
        chaplygin.odd = connect(y_odd, flux_odd);
        Ok(chaplygin)
    }

    getters! {
        /// μ = I_Z Ma² / (I_X (I_Z + Ma²)) (physics §6).
        mu: f64,
        /// |s| where the two expansions meet (½ for μ ≤ 4): exposed so tests can probe both sides of it.
        split_sin: f64,
    }

    /// k = (I_Z + Ma²)/(Ma²) (physics §6).
    #[must_use]
    pub fn k(&self) -> f64 {
        1.0 / self.inverse_k
    }

    /// Number of series terms summed on each side of the split (about the cost of one evaluation).
    #[must_use]
    pub fn terms(&self) -> (usize, usize) {
        (self.centre.len(), self.edge.len())
    }

    /// C1, C2 of physics §6 at lean θ (rad) and lean-frame ω_Y, ω_Z (rad/time).
    ///
    /// Meaningful for |θ| < π/2 (the rim-contact model, physics §7); the formula is evaluated literally with
    /// s = sin θ, cos θ for any finite θ. A non-finite input gives NaN. No allocation.
    #[must_use]
    #[inline]
    pub fn evaluate(&self, theta: f64, omega_y: f64, omega_z: f64) -> Invariants {
        let (sin_t, cos_t) = theta.sin_cos();
        let (y_even, flux_even, y_odd, flux_odd) = self.values(sin_t, cos_t * cos_t);
        let lever = cos_t * omega_y * self.inverse_k;
        Invariants {
            c1: flux_odd * omega_z - y_odd * lever,
            c2: y_even * lever - flux_even * omega_z,
        }
    }

    /// C1, C2 of a state (see [`Chaplygin::evaluate`]).
    #[must_use]
    #[inline]
    pub fn of_state(&self, state: &State) -> Invariants {
        self.evaluate(state.theta, state.omega_y, state.omega_z)
    }

    /// y_e, y_o, their derivatives and fluxes at s = sin θ, with cos²θ taken from θ (full precision near
    /// flat, as in [`Chaplygin::evaluate`]).
    #[must_use]
    pub fn basis(&self, theta: f64) -> LegendreBasis {
        let (sin_t, cos_t) = theta.sin_cos();
        self.basis_from(sin_t, cos_t * cos_t)
    }

    /// y_e, y_o, their derivatives and fluxes at s, for |s| < 1; 1 − |s| is exact here, so this is as
    /// accurate as the given s is.
    #[must_use]
    pub fn basis_at_sin(&self, s: f64) -> LegendreBasis {
        let a = s.abs();
        self.basis_from(s, (1.0 - a) * (1.0 + a))
    }

    fn basis_from(&self, s: f64, cos2: f64) -> LegendreBasis {
        let (y_even, flux_even, y_odd, flux_odd) = self.values(s, cos2);
        LegendreBasis {
            y_even,
            y_odd,
            dy_even: flux_even / cos2,
            dy_odd: flux_odd / cos2,
            flux_even,
            flux_odd,
        }
    }

    /// (y_e, p_e, y_o, p_o) at s with cos²θ = 1 − s² given separately (for its precision near |s| = 1).
    #[inline]
    fn values(&self, s: f64, cos2: f64) -> (f64, f64, f64, f64) {
        let a = s.abs();
        if a <= self.split_sin {
            return self.centre_values(s, cos2);
        }
        // x = (1 − |s|)/2 = cos²θ / (2(1 + |s|)), without forming 1 − |s|.
        let two_one_plus = 2.0 * (1.0 + a);
        let x = cos2 / two_one_plus;
        let log_x = cos2.ln() - two_one_plus.ln();
        let [big_u, big_ud, w, wd] = horner(&self.edge, x);
        let scale = -2.0 * (1.0 - x);
        let at = |c: Connection| {
            let regular = c.alpha + c.beta * log_x;
            (
                regular * big_u + c.beta * w,
                scale * (regular * big_ud + c.beta * (big_u + wd)),
            )
        };
        let (y_even, flux_even) = at(self.even);
        let (y_odd, flux_odd) = at(self.odd);
        // y_e even, y_o odd; so p_e = (1 − s²) y_e′ is odd and p_o even.
        let sign = 1.0_f64.copysign(s);
        (y_even, sign * flux_even, sign * y_odd, flux_odd)
    }

    #[inline]
    fn centre_values(&self, s: f64, cos2: f64) -> (f64, f64, f64, f64) {
        let [y_even, dy_even_over_s, y_odd_over_s, dy_odd] = horner(&self.centre, s * s);
        (
            y_even,
            cos2 * s * dy_even_over_s,
            s * y_odd_over_s,
            cos2 * dy_odd,
        )
    }

    /// [u₁, p₁, u₂, p₂] at x (x > 0).
    fn edge_basis(&self, x: f64) -> [f64; 4] {
        let [big_u, big_ud, w, wd] = horner(&self.edge, x);
        let log_x = x.ln();
        let scale = -2.0 * (1.0 - x);
        [
            big_u,
            scale * big_ud,
            big_u * log_x + w,
            scale * (big_ud * log_x + big_u + wd),
        ]
    }
}

/// Four polynomials with interleaved coefficients (an even count of them), by Horner's rule in z² on the
/// even and odd powers separately: eight independent chains, half the latency of plain Horner.
#[inline]
fn horner(coefficients: &[[f64; 4]], z: f64) -> [f64; 4] {
    let z2 = z * z;
    let mut even = [0.0; 4];
    let mut odd = [0.0; 4];
    for pair in coefficients.rchunks_exact(2) {
        for i in 0..4 {
            even[i] = even[i] * z2 + pair[0][i];
            odd[i] = odd[i] * z2 + pair[1][i];
        }
    }
    std::array::from_fn(|i| even[i] + z * odd[i])
}

/// Taylor coefficients about s = 0 in t = s²: y_e = Σ E_n tⁿ, y_e′ = s Σ 2(n + 1) E_{n+1} tⁿ,
/// y_o = s Σ O_n tⁿ, y_o′ = Σ (2n + 1) O_n tⁿ, from a_{m+2} = (m² + m + μ)/((m + 2)(m + 1)) a_m.
fn centre_coefficients(mu: f64, t_max: f64) -> Vec<[f64; 4]> {
    let mut even = 1.0; // E_n = a_{2n}
    let mut odd = 1.0; // O_n = a_{2n+1}
    let next = |a: f64, m: f64| a * (m * m + m + mu) / ((m + 2.0) * (m + 1.0));
    collect_series(t_max, |n| {
        let m = index_f64(2 * n);
        let m1 = m + 1.0;
        let (even_next, odd_next) = (next(even, m), next(odd, m1));
        let term = [even, (m + 2.0) * even_next, odd, m1 * odd];
        even = even_next;
        odd = odd_next;
        term
    })
}

/// Frobenius coefficients about s = 1 in x: u₁ = Σ c_n xⁿ, w = Σ d_n xⁿ, stored as [c_n, n c_n, d_n, n d_n].
fn edge_coefficients(mu: f64, x_max: f64) -> Vec<[f64; 4]> {
    let mut c = 1.0;
    let mut d = 0.0;
    collect_series(x_max, |n| {
        let nf = index_f64(n);
        let term = [c, nf * c, d, nf * d];
        let n1 = nf + 1.0;
        let factor = nf * nf + nf + mu;
        let c_next = c * factor / (n1 * n1);
        d = (factor * d + (2.0 * nf + 1.0) * c - 2.0 * n1 * c_next) / (n1 * n1);
        c = c_next;
        term
    })
}

/// Collects coefficients from `next(n)` until every chain's terms at `variable_max` meet [`TRUNCATION`].
fn collect_series(variable_max: f64, mut next: impl FnMut(usize) -> [f64; 4]) -> Vec<[f64; 4]> {
    let mut out = Vec::new();
    let mut magnitude = [0.0_f64; 4];
    let mut previous = [f64::INFINITY; 4];
    let mut quiet = 0;
    let mut power = 1.0;
    for n in 0..MAX_TERMS {
        let c = next(n);
        out.push(c);
        let mut small = true;
        for i in 0..4 {
            let term = c[i].abs() * power;
            magnitude[i] += term;
            small &= term <= previous[i] && term <= TRUNCATION * magnitude[i];
            previous[i] = term;
        }
        quiet = if small { quiet + 1 } else { 0 };
        if quiet >= DECREASING_RUN {
            break;
        }
        power *= variable_max;
    }
    // [`horner`] takes the coefficients in pairs.
    if out.len() % 2 == 1 {
        out.push([0.0; 4]);
    }
    out
}

/// A small term index as f64 (exact: indices are < 2⁵³).
#[allow(clippy::cast_precision_loss)]
fn index_f64(n: usize) -> f64 {
    n as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Inertia;

    #[test]
    fn edge_basis_has_the_exact_wronskian_minus_two() {
        for mu in [0.01, 0.25, 1.0, 4.0 / 3.0, 2.7, 30.0] {
            let p = CoinParams::new(
                1.0,
                1.0,
                1.0,
                Inertia::Explicit {
                    inertia_x: 1.0 / mu / 2.0,
                    inertia_z: 1.0,
                },
            )
            .unwrap();
            let ch = Chaplygin::new(&p).unwrap();
            assert!((ch.mu() - mu).abs() < 1e-12 * mu);
            let split_x = (1.0 - ch.split_sin) / 2.0;
            for x in [1e-6, 0.01, 0.1, split_x]
                .into_iter()
                .filter(|&x| x <= split_x)
            {
                let [u1, p1, u2, p2] = ch.edge_basis(x);
                let w = u1 * p2 - u2 * p1;
                let scale = (u1 * p2).abs() + (u2 * p1).abs();
                println!("μ = {mu}, x = {x}: W = {w:.17} (expected −2, tol 1e-15·{scale:.3})");
                assert!((w + 2.0).abs() < 1e-15 * scale);
            }
        }
    }
}
