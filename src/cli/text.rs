//! Small text helpers shared by the commands' printed output.

/// A size in bytes as `1.1 MiB`, `12.0 KiB` or `512 B`.
#[allow(clippy::cast_precision_loss)]
pub fn size(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 30 => format!("{:.2} GiB", b as f64 / f64::from(1 << 30)),
        b if b >= 1 << 20 => format!("{:.1} MiB", b as f64 / f64::from(1 << 20)),
        b if b >= 1 << 10 => format!("{:.1} KiB", b as f64 / f64::from(1 << 10)),
        b => format!("{b} B"),
    }
}

/// `n` things: `1 job`, `2 jobs`, `0 runs`.
pub fn counted(n: impl TryInto<u64>, thing: &str) -> String {
    let n = n.try_into().unwrap_or(u64::MAX);
    format!("{n} {thing}{}", if n == 1 { "" } else { "s" })
}

/// A number for a table or message: as Rust prints it when that is short (1e-4 ≤ |x| < 1e16, or 0:
/// `0.25`, `1`, `30.5`), else in the shortest exponent form that reads back the same (`1e-300`,
/// `2.5e20`), never as hundreds of digits: the library's [`coin_log::scene::Short`].
pub fn number(x: f64) -> String {
    coin_log::scene::Short(x).to_string()
}

/// The widest a table column grows for its longest cell; a longer cell overflows its column.
pub const COLUMN_MAX: usize = 64;

/// `text` and spaces after it up to `width` characters; never cut. `format!("{:<w$}")` panics for a
/// width above 65 535, which a crafted file's 1 MB topic name and a sweep's 70 000-character value reached.
pub fn padded(text: &str, width: usize) -> String {
    let fill = width.saturating_sub(text.chars().count());
    let mut out = String::with_capacity(text.len() + fill);
    out.push_str(text);
    out.extend(std::iter::repeat_n(' ', fill));
    out
}

/// The help texts of the flags whose values the scene limits bound (coin_log::scene::limits), with each
/// bound printed from the constant that enforces it, exactly (`2.220446049250313e-15`, not a rounded
/// `2.2e-15` that is refused), so that the text cannot drift from the check.
pub mod help {
    use coin_log::scene::defaults;
    use coin_log::scene::limits::{
        ATOL_MAX_FRACTION, MAX_RADIANS, MIN_DURATION, RTOL_MAX, RTOL_MIN, STEP_MAX_PRODUCT,
    };

    /// A bound as it must be typed to be the bound: the shortest text that reads back to the same double,
    /// in exponent form outside 0.01 … 1000 (`1e10`, `1e-3`).
    pub fn bound(x: f64) -> String {
        if (0.01..1000.0).contains(&x.abs()) {
            x.to_string()
        } else {
            format!("{x:e}")
        }
    }

    pub fn duration() -> String {
        format!(
            "Duration in the scene's time unit, ≥ {} (the 1 ns log-time resolution), with T·W ≤ {} radians \
             of the fastest motion W = max(|ω|, |φ̇|, |ψ̇|, 1/τ) at t = 0 (overrides `run.duration`)",
            bound(MIN_DURATION),
            bound(MAX_RADIANS)
        )
    }

    pub fn rtol() -> String {
        format!(
            "Relative tolerance of adaptive methods, {} (ten units of rounding, 10·2⁻⁵²) to {} (overrides \
             `run.rtol`; default {})",
            bound(RTOL_MIN),
            bound(RTOL_MAX),
            bound(defaults::RTOL)
        )
    }

    pub fn atol() -> String {
        format!(
            "Absolute tolerance of adaptive methods, at most {}·min(1, a, 1/τ) (overrides `run.atol`; \
             default {})",
            bound(ATOL_MAX_FRACTION),
            bound(defaults::ATOL)
        )
    }

    pub fn step() -> String {
        format!(
            "Step of fixed-step methods, rounded down to divide 1/rate; then step·W ≤ {} (1e-3^(1/4)) with W \
             the fastest rate at t = 0, as for --duration, and duration/step ≤ --max-steps (overrides `run.step`; \
             default {})",
            bound(STEP_MAX_PRODUCT),
            bound(defaults::STEP)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::number;

    #[test]
    fn numbers_print_short_at_every_scale() {
        for (x, text) in [
            (0.25, "0.25"),
            (30.0, "30"),
            (0.0, "0"),
            (1e-300, "1e-300"),
            (-2.5e20, "-2.5e20"),
            (5e-324, "5e-324"),
            (f64::NAN, "NaN"),
        ] {
            assert_eq!(number(x), text);
        }
    }
}
