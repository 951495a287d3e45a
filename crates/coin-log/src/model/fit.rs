//! Least-squares fits of measured series: a straight line, a straight line in log–log coordinates (the
//! slope of a work-precision diagram, the growth exponent of a drift), and the power law α = A |t₀ − t|^n
//! with t₀ free (the time law of a dissipating coin, physics §11).

/// Geometric scan of |t₀ − t at the window's end| in [`power_law`], in units of the points' time span.
const SCAN: (f64, f64, usize) = (1e-7, 1e4, 221);
/// Golden-section refinement steps of t₀ in [`power_law`].
const REFINE_STEPS: usize = 100;

/// The least-squares line y = intercept + slope·x, and the sum of its squared residuals, `residual`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names each field")]
pub struct FittedLine {
    pub slope: f64,
    pub intercept: f64,
    pub residual: f64,
}

/// The least-squares line through `points` (x, y); `None` when the x values do not spread (fewer than two
/// distinct values, or NaN).
///
/// ```
/// let line = coin_log::model::fit::line(&[(0.0, 1.0), (1.0, 3.0), (2.0, 5.0)]).unwrap();
/// assert!((line.slope - 2.0).abs() < 1e-15 && (line.intercept - 1.0).abs() < 1e-15);
/// ```
#[must_use]
pub fn line(points: &[(f64, f64)]) -> Option<FittedLine> {
    #[allow(clippy::cast_precision_loss)]
    let n = points.len() as f64;
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = points.iter().map(|p| (p.0 - mx) * (p.0 - mx)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    if sxx.is_nan() || sxx <= 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let residual = points
        .iter()
        .map(|p| (p.1 - intercept - slope * p.0).powi(2))
        .sum();
    Some(FittedLine {
        slope,
        intercept,
        residual,
    })
}

/// The least-squares slope of log10 y against log10 x over the points with both positive and finite;
/// `None` with fewer than two such points or no spread in x.
///
/// ```
/// // y = x⁻⁴: slope −4.
/// let points: Vec<(f64, f64)> = (1..6).map(|k| (f64::from(k), f64::from(k).powi(-4))).collect();
/// assert!((coin_log::model::fit::log_log_slope(&points).unwrap() + 4.0).abs() < 1e-12);
/// ```
#[must_use]
pub fn log_log_slope(points: &[(f64, f64)]) -> Option<f64> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && x.is_finite() && y.is_finite())
        .map(|(x, y)| (x.log10(), y.log10()))
        .collect();
    line(&logs).map(|l| l.slope)
}

/// The fitted law α = A |t₀ − t|^n: n = `exponent`, A = `amplitude`, `t0`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs, reason = "the struct's doc names the fields without one")]
pub struct PowerLaw {
    pub exponent: f64,
    pub amplitude: f64,
    pub t0: f64,
    /// True when t₀ lies after the points (a finite-time singularity), false before them (a decay).
    pub singular: bool,
    /// Root-mean-square residual of ln α.
    pub rms: f64,
}

impl PowerLaw {
    /// α of the law at time t.
    #[must_use]
    pub fn alpha(&self, t: f64) -> f64 {
        self.amplitude * (self.t0 - t).abs().powf(self.exponent)
    }
}

/// The 3-parameter fit α = A |t₀ − t|^n to (t, α) points in time order, α > 0: for each trial t₀, n and
/// ln A follow by linear least squares in (ln |t₀ − t|, ln α), and t₀ minimises the residual, on a
/// geometric scan of its distance from the points refined by golden section. Both sides are tried: t₀ after
/// the last point (a finite-time singularity, n > 0) and before the first (a power-law decay, n < 0); the
/// better fit wins.
///
/// ```
/// use coin_log::model::fit::power_law;
/// // α = 0.7 (100 − t)^(1/3).
/// let points: Vec<(f64, f64)> = (0..300)
///     .map(|i| f64::from(i) * 0.3)
///     .map(|t| (t, 0.7 * (100.0 - t).powf(1.0 / 3.0)))
///     .collect();
/// let law = power_law(&points).unwrap();
/// assert!(law.singular && (law.exponent - 1.0 / 3.0).abs() < 1e-6 && (law.t0 - 100.0).abs() < 1e-3);
/// ```
#[must_use]
pub fn power_law(points: &[(f64, f64)]) -> Option<PowerLaw> {
    let (first, last) = (points.first()?.0, points.last()?.0);
    let span = last - first;
    if span.is_nan() || span <= 0.0 {
        return None;
    }
    let after = power_law_on_side(points, last, 1.0, span);
    let before = power_law_on_side(points, first, -1.0, span);
    match (after, before) {
        (Some(a), Some(b)) => Some(if a.rms <= b.rms { a } else { b }),
        (a, b) => a.or(b),
    }
}

/// Least squares of ln α = ln A + n ln |t₀ − t| for a fixed t₀; `None` unless its residual is finite.
fn log_line(points: &[(f64, f64)], t0: f64) -> Option<FittedLine> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .map(|(t, a)| ((t0 - t).abs().ln(), a.ln()))
        .collect();
    line(&logs).filter(|l| l.residual.is_finite())
}

/// The best fit with t₀ on one side of the points: t₀ = anchor + side·d, d scanned geometrically over
/// [`SCAN`] (in units of the points' span) and refined by golden section in ln d around the best.
fn power_law_on_side(points: &[(f64, f64)], anchor: f64, side: f64, span: f64) -> Option<PowerLaw> {
    let rss_at = |ln_d: f64| {
        log_line(points, anchor + side * ln_d.exp()).map_or(f64::INFINITY, |l| l.residual)
    };
    let (lo, hi, steps) = SCAN;
    let (ln_lo, ln_hi) = ((lo * span).ln(), (hi * span).ln());
    #[allow(clippy::cast_precision_loss)]
    let grid: Vec<f64> = (0..steps)
        .map(|i| ln_lo + (ln_hi - ln_lo) * i as f64 / (steps - 1) as f64)
        .collect();
    let best = (0..steps).min_by(|&i, &j| rss_at(grid[i]).total_cmp(&rss_at(grid[j])))?;
    let (mut a, mut b) = (
        grid[best.saturating_sub(1)],
        grid[(best + 1).min(steps - 1)],
    );
    let golden = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..REFINE_STEPS {
        let (x1, x2) = (b - golden * (b - a), a + golden * (b - a));
        if rss_at(x1) < rss_at(x2) {
            b = x2;
        } else {
            a = x1;
        }
    }
    let t0 = anchor + side * (0.5 * (a + b)).exp();
    let fit = log_line(points, t0)?;
    #[allow(clippy::cast_precision_loss)]
    let rms = (fit.residual / points.len() as f64).sqrt();
    Some(PowerLaw {
        exponent: fit.slope,
        amplitude: fit.intercept.exp(),
        t0,
        singular: side > 0.0,
        rms,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// t₀ before the points (a decay); the doctest of [`power_law`] fits one after them.
    #[test]
    fn an_exact_power_law_decay_is_fitted_with_its_t0_before_the_points() {
        let points: Vec<(f64, f64)> = (0..300)
            .map(|i| f64::from(i) * 0.3)
            .map(|t| (t, 0.7 * (-40.0 - t).abs().powf(-2.0)))
            .collect();
        let fit = power_law(&points).unwrap();
        assert!(
            !fit.singular && (fit.exponent + 2.0).abs() < 1e-6,
            "{fit:?}"
        );
    }

    #[test]
    fn a_line_needs_two_distinct_abscissae() {
        assert!(line(&[]).is_none());
        assert!(line(&[(1.0, 2.0)]).is_none());
        assert!(line(&[(1.0, 2.0), (1.0, 3.0)]).is_none());
        assert!(line(&[(f64::NAN, 2.0), (1.0, 3.0)]).is_none());
        assert!(log_log_slope(&[(1.0, 1.0), (-1.0, 2.0)]).is_none());
    }
}
