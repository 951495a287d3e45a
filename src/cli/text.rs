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

/// A number for a table or message: as Rust prints it when that is short (1e-4 ≤ |x| < 1e16, or 0:
/// `0.25`, `1`, `30.5`), else in the shortest exponent form that reads back the same (`1e-300`,
/// `2.5e20`), never as hundreds of digits. The rule of the scene errors' numbers.
pub fn number(x: f64) -> String {
    if x.is_finite() && x != 0.0 && !(1e-4..1e16).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        x.to_string()
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
