//! One-dimensional quadrature and root finding for the nutation integrals (physics §10): Gauss–Legendre
//! rules, an adaptive Gauss–Legendre integrator, and bisection on a bracket; no crate in the dependency
//! tree offers an adaptive rule that compares two Gauss rules per panel without allocating per call.

/// Nodes and weights of n-point Gauss–Legendre quadrature on [−1, 1] (Newton on P_n from Chebyshev
/// guesses; Abramowitz & Stegun 25.4.29). The nodes come in decreasing order.
#[must_use]
#[allow(clippy::cast_precision_loss)]
pub(super) fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let nf = n as f64;
    (1..=n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 - 0.25) / (nf + 0.5)).cos();
            let mut dp = 1.0;
            for _ in 0..100 {
                // P_n(x) and P_n'(x) by the three-term recurrence.
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let kf = k as f64;
                    let p2 = ((2.0 * kf - 1.0) * x * p1 - (kf - 1.0) * p0) / kf;
                    p0 = p1;
                    p1 = p2;
                }
                dp = nf * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * dp * dp))
        })
        .collect()
}

/// Points of the coarse rule of [`Adaptive`].
const COARSE: usize = 10;
/// Points of the fine rule of [`Adaptive`].
const FINE: usize = 20;
/// Deepest panel splitting of [`Adaptive`]: panels of 2⁻²⁴ ≈ 6e-8 of the interval. Rounding noise in the
/// integrand can keep two rules from agreeing however small the panel; below this the panel is taken as
/// it is (its difference still counts in the error).
const MAX_DEPTH: u32 = 24;
/// A halved panel whose two halves together still differ by more than this fraction of the whole
/// panel's difference is noise-limited (see [`Adaptive`]).
const NOISE_RATIO: f64 = 0.25;
/// The two rules of a noise-limited panel agree to this fraction of ∫|f| over it.
const NOISE_FLOOR: f64 = 1e-10;
/// Most integrand evaluations of one [`Adaptive::integrate`]; past it every panel is accepted as it is.
const MAX_EVALUATIONS: usize = 200_000;

/// Adaptive Gauss–Legendre quadrature: a panel whose 10- and 20-point rules differ by more than the
/// tolerance's share is halved. On an analytic integrand the 20-point rule is then far more accurate than
/// the difference, an error bound in practice, and halving shrinks the difference by orders of magnitude;
/// where it does not shrink by at least `NOISE_RATIO`, the difference is the integrand's rounding noise,
/// which no further halving removes, and the panel is accepted.
#[derive(Debug, Clone)]
pub(super) struct Adaptive {
    coarse: Vec<(f64, f64)>,
    fine: Vec<(f64, f64)>,
}

/// The result of [`Adaptive::integrate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Integral {
    /// The integral (the sum of the fine rule over the accepted panels).
    pub value: f64,
    /// The sum of |coarse − fine| over the accepted panels: an error bound in practice.
    pub error: f64,
    /// Integrand evaluations.
    pub evaluations: usize,
}

impl Adaptive {
    #[must_use]
    pub(super) fn new() -> Self {
        Self {
            coarse: gauss_legendre(COARSE),
            fine: gauss_legendre(FINE),
        }
    }

    /// ∫ₐᵇ f to the relative tolerance `rtol` of ∫ₐᵇ |f| (estimated from a first pass).
    pub(super) fn integrate(&self, f: &impl Fn(f64) -> f64, a: f64, b: f64, rtol: f64) -> Integral {
        let mut out = Integral {
            value: 0.0,
            error: 0.0,
            evaluations: 0,
        };
        // The size of the integral sets the absolute tolerance each panel must meet (a share of it
        // proportional to the panel's width).
        let (_, magnitude) = self.rule(&self.fine, f, a, b, &mut out.evaluations);
        let tolerance = rtol * magnitude.max(f64::MIN_POSITIVE);
        self.panel(
            f,
            (a, b),
            tolerance / (b - a).abs(),
            (0, f64::INFINITY),
            &mut out,
        );
        out
    }

    /// Adds the integral over [a, b] to `out`, halving while the two rules disagree by more than
    /// `density`·|b − a| and halving still helps; `parent` is (depth, the parent panel's difference).
    fn panel(
        &self,
        f: &impl Fn(f64) -> f64,
        (a, b): (f64, f64),
        density: f64,
        (depth, parent): (u32, f64),
        out: &mut Integral,
    ) {
        let (coarse, _) = self.rule(&self.coarse, f, a, b, &mut out.evaluations);
        let (fine, magnitude) = self.rule(&self.fine, f, a, b, &mut out.evaluations);
        let difference = (fine - coarse).abs();
        let exhausted = depth >= MAX_DEPTH || out.evaluations >= MAX_EVALUATIONS;
        // Each half gets the parent's difference: the pair is noise-limited when each half differs by
        // more than NOISE_RATIO/2 of it while the rules agree to NOISE_FLOOR (an unresolved feature keeps
        // halves differing by far more).
        let noisy =
            difference > 0.5 * NOISE_RATIO * parent && difference <= NOISE_FLOOR * magnitude;
        if difference <= density * (b - a).abs() || exhausted || noisy || difference.is_nan() {
            out.value += fine;
            out.error += difference;
            return;
        }
        let mid = 0.5 * (a + b);
        self.panel(f, (a, mid), density, (depth + 1, difference), out);
        self.panel(f, (mid, b), density, (depth + 1, difference), out);
    }

    /// (Σ w f, Σ w |f|) of one rule on [a, b].
    fn rule(
        &self,
        rule: &[(f64, f64)],
        f: &impl Fn(f64) -> f64,
        a: f64,
        b: f64,
        evaluations: &mut usize,
    ) -> (f64, f64) {
        let (centre, half) = (0.5 * (a + b), 0.5 * (b - a));
        let (mut sum, mut magnitude) = (0.0, 0.0);
        for &(x, w) in rule {
            let v = f(centre + half * x);
            sum += w * v;
            magnitude += w * v.abs();
        }
        *evaluations += rule.len();
        (half * sum, half.abs() * magnitude)
    }
}

/// The most halvings [`bisect`] takes: from the widest bracket of doubles (2·1.8e308) to adjacent
/// subnormals, 1024 + 1074 binary orders and the 53 bits of a significand.
const MAX_HALVINGS: usize = 1024 + 1074 + 53;

/// The boundary between `inside` (where `is_inside` holds) and `outside`, by bisection down to adjacent
/// floating-point numbers. Returns the last point found inside and the first outside.
///
/// Halving reaches adjacent numbers in 53 steps plus one per binary order of magnitude the boundary lies
/// below the bracket's width: at most `MAX_HALVINGS` (2151). (A cap of 200 stopped `analyse` 1e-12 above
/// θ₀ = 1e-100 at 3.1e-73, 1e27 times the turning point 2e-100, with a period of 1.4e14 for 4.97.)
pub fn bisect(is_inside: impl Fn(f64) -> bool, mut inside: f64, mut outside: f64) -> (f64, f64) {
    for _ in 0..MAX_HALVINGS {
        let mid = 0.5 * (inside + outside);
        if mid == inside || mid == outside {
            break;
        }
        if is_inside(mid) {
            inside = mid;
        } else {
            outside = mid;
        }
    }
    (inside, outside)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials_of_degree_2n_minus_1_exactly() {
        for n in [5, 10, 20] {
            let rule = gauss_legendre(n);
            // ∫₋₁¹ x^(2n−2) dx = 2/(2n − 1).
            let k = i32::try_from(2 * n - 2).unwrap_or(0);
            let sum: f64 = rule.iter().map(|(x, w)| w * x.powi(k)).sum();
            let expected = 2.0 / (f64::from(k) + 1.0);
            println!("n = {n}: ∫x^{k} = {sum:.17} vs {expected:.17}");
            assert!((sum - expected).abs() < 1e-14);
        }
    }

    #[test]
    fn the_adaptive_rule_integrates_a_near_singular_function() {
        // ∫₀¹ dx/√(x + 1e-6) = 2(√(1 + 1e-6) − √1e-6): the singularity sits 1e-6 outside the interval.
        let f = |x: f64| 1.0 / (x + 1e-6).sqrt();
        let expected = 2.0 * ((1.0_f64 + 1e-6).sqrt() - 1e-3);
        let got = Adaptive::new().integrate(&f, 0.0, 1.0, 1e-14);
        println!(
            "{:.17} vs {expected:.17} (error bound {:.1e}, {} evaluations)",
            got.value, got.error, got.evaluations
        );
        assert!((got.value - expected).abs() < 1e-13 * expected);
    }

    #[test]
    fn bisection_finds_the_boundary_to_adjacent_floats() {
        let (inside, outside) = bisect(|x| x * x < 2.0, 1.0, 2.0);
        assert!(inside * inside < 2.0 && outside * outside >= 2.0);
        assert!(outside - inside <= 2.0 * f64::EPSILON * 2.0);
    }
}
