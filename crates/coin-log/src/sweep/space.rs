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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linspace_is_exact_at_the_ends_and_even_between() {
        let v = linspace(0.1, 0.7, 7);
        assert_eq!(v.first().map(|x| x.to_bits()), Some(0.1f64.to_bits()));
        assert_eq!(v.last().map(|x| x.to_bits()), Some(0.7f64.to_bits()));
        for (k, x) in v.iter().enumerate() {
            let expected = 0.1 + 0.1 * k as f64;
            assert!(
                (x - expected).abs() < 1e-15,
                "v[{k}] = {x}, expected {expected}"
            );
        }
        assert_eq!(linspace(3.0, 5.0, 1), vec![3.0]);
        assert_eq!(linspace(1.0, -1.0, 3), vec![1.0, 0.0, -1.0]);
    }

    #[test]
    fn logspace_gives_exact_decades_and_powf_between() {
        let v = logspace(-12.0, -6.0, 4);
        assert_eq!(v, vec![1e-12, 1e-10, 1e-8, 1e-6]);
        let half = logspace(0.0, 1.0, 3);
        assert_eq!(half[1].to_bits(), 10f64.powf(0.5).to_bits());
    }
}
