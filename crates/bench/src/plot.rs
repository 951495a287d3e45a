//! Work-precision diagrams as SVG.

use super::euler::EulerRow;
use super::precision::PrecisionReport;
use super::BenchError;
use coin_log::palette::{legend_box, legend_line, svg_page, DrawError, LINES as PALETTE};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

/// Size of the diagram \[px\].
const SIZE: (u32, u32) = (800, 560);

/// A diagram's axes, as the series are drawn on them.
type Chart<'a, 'b> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The frame both diagrams share: a white page of [`SIZE`] with `caption` (text, font size), the axes
/// over `(x0, x1, y0, y1)` labelled `(x, y)`, the series `draw` puts on them, and their legend at
/// `legend`. Returns the SVG document; a drawing error is reported as [`BenchError::Plot`] of `scene`.
fn diagram(
    scene: &str,
    caption: (&str, u32),
    (x_desc, y_desc): (&str, &str),
    (x0, x1, y0, y1): (f64, f64, f64, f64),
    legend: SeriesLabelPosition,
    draw: impl FnOnce(&mut Chart<'_, '_>) -> Result<(), DrawError>,
) -> Result<String, BenchError> {
    svg_page(SIZE, |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(caption.0, ("sans-serif", caption.1))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(56)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .draw()?;
        draw(&mut chart)?;
        legend_box(&mut chart, legend)
    })
    .map_err(|e| BenchError::Plot {
        scene: scene.to_string(),
        reason: e.to_string(),
    })
}

/// The work-precision diagram of one scene: log10 state error against log10 wall time, one line per
/// integrator, its measured slope in the legend. Returns the SVG document.
///
/// # Errors
/// [`BenchError::Plot`] if drawing fails (it does not for finite data).
pub fn work_precision_svg(report: &PrecisionReport) -> Result<String, BenchError> {
    let series = series(report);
    diagram(
        &report.scene,
        (
            &format!("{}: work-precision ({})", report.scene, report.reference),
            18,
        ),
        ("log10 wall time [s]", "log10 state error"),
        bounds(&series),
        SeriesLabelPosition::UpperRight,
        |chart| {
            for (i, (label, points)) in series.iter().enumerate() {
                let colour = PALETTE[i % PALETTE.len()];
                chart
                    .draw_series(LineSeries::new(
                        points.iter().copied(),
                        colour.stroke_width(2),
                    ))?
                    .label(label.clone())
                    .legend(legend_line(colour, 2));
                chart.draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))?;
            }
            Ok(())
        },
    )
}

/// One (label, points) series per integrator: (log10 wall time, log10 state error), sorted by time; the
/// label carries the measured slope.
fn series(report: &PrecisionReport) -> Vec<(String, Vec<(f64, f64)>)> {
    report
        .slopes
        .iter()
        .map(|slope| {
            let mut points: Vec<(f64, f64)> = report
                .rows
                .iter()
                .filter(|r| r.integrator == slope.integrator)
                .filter(|r| r.state_error > 0.0 && r.state_error.is_finite())
                .filter(|r| r.wall_seconds > 0.0)
                .map(|r| (r.wall_seconds.log10(), r.state_error.log10()))
                .collect();
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            let label = match slope.time {
                Some(s) => format!("{} (slope {s:.2})", slope.integrator),
                None => slope.integrator.to_string(),
            };
            (label, points)
        })
        .collect()
}

/// The axes' ranges (x0, x1, y0, y1): the points' extent rounded out to whole decades (with a margin),
/// or a default frame when there is no point.
fn bounds(series: &[(String, Vec<(f64, f64)>)]) -> (f64, f64, f64, f64) {
    let all = series.iter().flat_map(|(_, p)| p.iter());
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in all {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        (x0, x1, y0, y1) = (-6.0, 0.0, -16.0, 0.0);
    }
    (
        x0.floor() - 0.1,
        x1.ceil() + 0.1,
        y0.floor() - 0.5,
        y1.ceil() + 0.5,
    )
}

/// Points of each fitted line in the Euler's disk diagram.
const FIT_LINE_POINTS: usize = 50;

/// The exponent diagram of `bench euler`: log10 α against log10 |t₀ − t| for each preset (t₀ its fitted
/// singular time, or the decay's origin), the run as a thin line and the fitted law α = A |t₀ − t|^n over
/// the window as a thick one; the legend gives the fitted n against 1/(1 − p). Returns the SVG document.
///
/// # Errors
/// [`BenchError::Plot`] if drawing fails (it does not for finite data).
pub fn euler_svg(rows: &[EulerRow]) -> Result<String, BenchError> {
    let curves = euler_curves(rows);
    let all: Vec<(String, Vec<(f64, f64)>)> = curves
        .iter()
        .flat_map(|(label, run, fit)| [(label.clone(), run.clone()), (label.clone(), fit.clone())])
        .collect();
    diagram(
        "euler",
        (
            "Euler's disk: α = A |t0 − t|^n, fitted on the window (thick) of each run (thin)",
            16,
        ),
        ("log10 |t0 − t| [s]", "log10 α [rad]"),
        bounds(&all),
        SeriesLabelPosition::LowerRight,
        |chart| {
            for (i, (label, run, fit)) in curves.iter().enumerate() {
                let colour = PALETTE[i % PALETTE.len()];
                chart.draw_series(LineSeries::new(
                    run.iter().copied(),
                    colour.mix(0.5).stroke_width(1),
                ))?;
                chart
                    .draw_series(LineSeries::new(fit.iter().copied(), colour.stroke_width(4)))?
                    .label(label.clone())
                    .legend(legend_line(colour, 4));
            }
            Ok(())
        },
    )
}

/// One law in the Euler's disk diagram: its label, the run's (log10 |t₀ − t|, log10 α) and the fitted
/// line's.
type EulerCurve = (String, Vec<(f64, f64)>, Vec<(f64, f64)>);

/// For each fitted row: its label, the run's (log10 |t₀ − t|, log10 α) and the fitted line's.
fn euler_curves(rows: &[EulerRow]) -> Vec<EulerCurve> {
    rows.iter()
        .filter_map(|r| {
            let fit = r.fit?;
            // Only the side of t₀ the law describes: before a singularity, after a decay's origin (a run
            // that goes on past its fitted t₀ would fold back on the logarithmic axis).
            let point = |t: f64, alpha: f64| {
                let d = if fit.singular { fit.t0 - t } else { t - fit.t0 };
                (d > 0.0 && alpha > 0.0).then(|| (d.log10(), alpha.log10()))
            };
            let run: Vec<(f64, f64)> = r.samples.iter().filter_map(|&(t, a)| point(t, a)).collect();
            let (t_a, t_b) = r.time_window;
            #[allow(clippy::cast_precision_loss)]
            let line: Vec<(f64, f64)> = (0..=FIT_LINE_POINTS)
                .filter_map(|i| {
                    let t = t_a + (t_b - t_a) * i as f64 / FIT_LINE_POINTS as f64;
                    point(t, fit.alpha(t))
                })
                .collect();
            let kind = if fit.singular { "" } else { ", decay" };
            let label = format!(
                "{}: n = {:.4} (1/(1 − p) = {:.4}{kind})",
                r.dissipation.model(),
                fit.exponent,
                r.predicted
            );
            Some((label, run, line))
        })
        .collect()
}
