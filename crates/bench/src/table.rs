//! Text tables and CSV of bench results, returned as strings (the CLI prints or writes them).

use super::euler::EulerRow;
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
        out.push_str(&coin_log::csv::record(&fields));
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
        out.push_str(&coin_log::csv::record(&fields));
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

/// The CSV header of `bench euler`.
pub const EULER_CSV_HEADER: &str = "model,m,k,p,kappa,time_scale,predicted_n,fitted_n,relative_error,singular,t0,alpha_min,alpha_max,window_limit,t_start,t_end,points,termination,end_time,end_alpha,min_normal,min_normal_alpha,termination_mu,end_time_mu,end_alpha_mu,wall_seconds";

/// The Euler's disk rows as CSV with [`EULER_CSV_HEADER`]; `_mu` columns are the run with μ = 0.3.
#[must_use]
pub fn euler_csv(rows: &[EulerRow]) -> String {
    let mut out = String::from(EULER_CSV_HEADER);
    out.push('\n');
    for r in rows {
        let d = &r.dissipation;
        let fields = [
            d.model().name().to_string(),
            number(Some(d.m())),
            number(Some(d.k())),
            number(Some(r.p)),
            number(Some(d.coefficient())),
            number(Some(r.time_scale)),
            number(Some(r.predicted)),
            number(r.fit.map(|f| f.exponent)),
            number(r.relative_error()),
            r.fit.map_or_else(String::new, |f| f.singular.to_string()),
            number(r.fit.map(|f| f.t0)),
            number(Some(r.alpha_window.0)),
            number(Some(r.alpha_window.1)),
            r.limit.name().to_string(),
            number(Some(r.time_window.0)),
            number(Some(r.time_window.1)),
            r.points.to_string(),
            r.end.termination.clone(),
            number(Some(r.end.time)),
            number(Some(r.end.alpha)),
            number(Some(r.lowest_normal.0)),
            number(Some(r.lowest_normal.1)),
            r.with_friction.termination.clone(),
            number(Some(r.with_friction.time)),
            number(Some(r.with_friction.alpha)),
            number(Some(r.wall_seconds)),
        ];
        out.push_str(&coin_log::csv::record(&fields));
    }
    out
}

/// The Euler's disk rows as a text table.
#[must_use]
pub fn euler_table(rows: &[EulerRow]) -> String {
    let header = [
        "model",
        "m",
        "k",
        "p",
        "kappa",
        "n = 1/(1-p)",
        "n fitted",
        "rel. error",
        "t0 fitted",
        "window alpha",
        "window t",
        "end (no mu)",
        "min N/Mg (at alpha)",
        "end (mu = 0.3)",
    ];
    let end =
        |e: &super::euler::DiskEnd| format!("{} t={:.4} a={:.3e}", e.termination, e.time, e.alpha);
    let body: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let d = &r.dissipation;
            vec![
                d.model().name().to_string(),
                format!("{}", d.m()),
                format!("{}", d.k()),
                format!("{}", r.p),
                short(Some(d.coefficient())),
                format!("{:.4}", r.predicted),
                r.fit
                    .map_or_else(|| "-".into(), |f| format!("{:.4}", f.exponent)),
                r.relative_error()
                    .map_or_else(|| "-".into(), |e| format!("{:.2}%", 100.0 * e)),
                r.fit.map_or_else(|| "-".into(), |f| format!("{:.2}", f.t0)),
                format!(
                    "{:.4}..{:.4} ({})",
                    r.alpha_window.0,
                    r.alpha_window.1,
                    r.limit.name()
                ),
                format!("{:.1}..{:.1}", r.time_window.0, r.time_window.1),
                end(&r.end),
                format!("{:.5} ({:.2e})", r.lowest_normal.0, r.lowest_normal.1),
                end(&r.with_friction),
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
