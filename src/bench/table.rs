//! Text tables and CSV of bench results, returned as strings (the CLI prints or writes them).

use super::precision::PrecisionRow;
use super::stability::StabilityRow;

/// The CSV header of `bench precision` (fixed column set).
pub const PRECISION_CSV_HEADER: &str = "scene,integrator,tolerance,step,state_error,energy_error,invariant_error,wall_seconds,rhs_evaluations,steps,rejected";

/// A number for CSV and tables: shortest round-trip, `inf` for infinity, empty for `None`.
#[must_use]
pub fn number(x: Option<f64>) -> String {
    match x {
        None => String::new(),
        Some(v) if v.is_infinite() => if v > 0.0 { "inf" } else { "-inf" }.to_string(),
        Some(v) if v.is_nan() => "nan".to_string(),
        Some(v) => ryu::Buffer::new().format_finite(v).to_string(),
    }
}

/// A number in short scientific notation for the human-readable tables (`1.23e-10`).
#[must_use]
pub fn short(x: Option<f64>) -> String {
    match x {
        None => "-".to_string(),
        Some(v) if !v.is_finite() => number(Some(v)),
        Some(v) => format!("{v:.2e}"),
    }
}

/// The precision rows as CSV with [`PRECISION_CSV_HEADER`]; one line per row, `\n` line ends.
#[must_use]
pub fn precision_csv(rows: &[PrecisionRow]) -> String {
    let mut out = String::from(PRECISION_CSV_HEADER);
    out.push('\n');
    for r in rows {
        let fields = [
            r.scene.clone(),
            r.integrator.name().to_string(),
            number(r.tolerance),
            number(r.step),
            number(Some(r.state_error)),
            number(Some(r.energy_error)),
            number(r.invariant_error),
            number(Some(r.wall_seconds)),
            r.rhs_evaluations.to_string(),
            r.steps.to_string(),
            r.rejected.to_string(),
        ];
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

/// A plain-text table with right-aligned columns under a header, columns separated by two spaces.
#[must_use]
pub fn render(header: &[&str], rows: &[Vec<String>]) -> String {
    let mut widths: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for row in rows {
        for (w, cell) in widths.iter_mut().zip(row) {
            *w = (*w).max(cell.chars().count());
        }
    }
    let line = |cells: &mut dyn Iterator<Item = &str>| -> String {
        let parts: Vec<String> = cells
            .zip(&widths)
            .map(|(c, w)| format!("{c:>w$}", w = *w))
            .collect();
        parts.join("  ").trim_end().to_string()
    };
    let mut out = line(&mut header.iter().copied());
    out.push('\n');
    for row in rows {
        out.push_str(&line(&mut row.iter().map(String::as_str)));
        out.push('\n');
    }
    out
}

/// The precision rows as a text table.
#[must_use]
pub fn precision_table(rows: &[PrecisionRow]) -> String {
    let header = [
        "integrator",
        "atol",
        "step",
        "state err",
        "energy err",
        "C1/C2 err",
        "wall [s]",
        "rhs evals",
        "steps",
        "rejected",
        "end",
    ];
    let body: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.integrator.name().to_string(),
                short(r.tolerance),
                short(r.step),
                short(Some(r.state_error)),
                short(Some(r.energy_error)),
                short(r.invariant_error),
                short(Some(r.wall_seconds)),
                r.rhs_evaluations.to_string(),
                r.steps.to_string(),
                r.rejected.to_string(),
                r.termination.clone(),
            ]
        })
        .collect();
    render(&header, &body)
}

/// The CSV header of `bench stability`.
pub const STABILITY_CSV_HEADER: &str = "case,integrator,setting,termination,end_time,max_error,energy_drift,wall_seconds,quantity,measured,expected";

/// The stability rows as CSV with [`STABILITY_CSV_HEADER`] (settings and quantities contain no commas).
#[must_use]
pub fn stability_csv(rows: &[StabilityRow]) -> String {
    let mut out = String::from(STABILITY_CSV_HEADER);
    out.push('\n');
    for r in rows {
        let fields = [
            r.case.clone(),
            r.integrator.name().to_string(),
            r.setting.clone(),
            r.termination.clone(),
            number(Some(r.end_time)),
            number(r.max_error),
            number(Some(r.energy_drift)),
            number(Some(r.wall_seconds)),
            r.quantity.clone(),
            number(r.measured),
            number(r.expected),
        ];
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

/// The stability rows as a text table.
#[must_use]
pub fn stability_table(rows: &[StabilityRow]) -> String {
    let header = [
        "case",
        "integrator",
        "setting",
        "end",
        "t end",
        "max error",
        "energy drift",
        "wall [s]",
        "quantity",
        "measured",
        "expected",
    ];
    let body: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.case.clone(),
                r.integrator.name().to_string(),
                r.setting.clone(),
                r.termination.clone(),
                format!("{:.6}", r.end_time),
                short(r.max_error),
                short(Some(r.energy_drift)),
                short(Some(r.wall_seconds)),
                r.quantity.clone(),
                r.measured
                    .map_or_else(|| "-".into(), |v| format!("{v:.10e}")),
                r.expected
                    .map_or_else(|| "-".into(), |v| format!("{v:.10e}")),
            ]
        })
        .collect();
    render(&header, &body)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_round_trip_and_infinity_is_spelt_out() {
        assert_eq!(number(Some(0.1)), "0.1");
        assert_eq!(number(Some(f64::INFINITY)), "inf");
        assert_eq!(number(None), "");
    }

    #[test]
    fn table_columns_are_aligned() {
        let t = render(&["a", "bb"], &[vec!["100".into(), "1".into()]]);
        assert_eq!(t, "  a  bb\n100   1\n");
    }
}
