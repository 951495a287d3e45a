//! The values of a grid axis (format.md: Sweep files, Grid axes): a list as given, `linspace` or
//! `logspace`, each defined to the bit so that another tool gives the same numbers.

/// `n` evenly spaced values from `first` to `last`, both included: v_0 = first, v_(n−1) = last, and
/// v_k = (first·(n − 1 − k) + last·k) / (n − 1) between (symmetric, and exact for decimal steps more often
/// than first + k·step); `[first]` when n = 1.
///
/// ```
/// assert_eq!(coin_log::sweep::linspace(0.2, 0.6, 3), vec![0.2, 0.4, 0.6]);
/// ```
#[must_use]
#[allow(clippy::cast_precision_loss)] // n is at most the sweep's run limit, far below 2⁵³
pub fn linspace(first: f64, last: f64, n: u64) -> Vec<f64> {
    if n <= 1 {
        return vec![first];
    }
    let span = (n - 1) as f64;
    (0..n)
        .map(|k| match k {
            0 => first,
            k if k == n - 1 => last,
            k => (first * (span - k as f64) + last * k as f64) / span,
        })
        .collect()
}

/// `n` values from 10^first_exp to 10^last_exp, evenly spaced in the exponent: 10^e_k with e_k the
/// [`linspace`] of the exponents. A whole exponent gives the double nearest its power of ten (`1e-3` is
/// 0.001); others are `10f64.powf(e)`.
///
/// ```
/// assert_eq!(coin_log::sweep::logspace(-3.0, 0.0, 4), vec![1e-3, 1e-2, 0.1, 1.0]);
/// ```
#[must_use]
pub fn logspace(first_exp: f64, last_exp: f64, n: u64) -> Vec<f64> {
    linspace(first_exp, last_exp, n)
        .into_iter()
        .map(power_of_ten)
        .collect()
}

/// 10^e: for a whole exponent the decimal `1eN` read as a double (correctly rounded), else `powf`.
fn power_of_ten(e: f64) -> f64 {
    if e.fract() == 0.0 && e.abs() < 400.0 {
        format!("1e{e:.0}")
            .parse()
            .unwrap_or_else(|_| 10f64.powf(e))
    } else {
        10f64.powf(e)
    }
}
