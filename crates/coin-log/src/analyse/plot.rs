//! The stability map as SVG: one panel per branch, each grid cell coloured by the sign and size of σ²,
//! the boundary σ² = 0 in closed form, ω_c of straight rolling, and the scenes' steady motions.
//!
//! Cells of one θ₀ column with the same colour are drawn as one rectangle, so the file stays small
//! (a 200 × 200 map of the thin disk on both branches is about 2,000 rectangles, not 80,000).

use super::map::{boundary, on_branch, BoundaryPoint, Grid, MapError, MapPoint, StabilityMap};
use super::steady::Stability;
use crate::model::Branch;
use crate::palette::{svg_page, Area, DrawError, MARGINAL, STABLE, UNSTABLE};
use plotters::prelude::*;

/// Size of one panel and of the legend strip \[px\].
const PANEL: (u32, u32) = (560, 500);
/// Height of the legend strip \[px\].
const LEGEND: u32 = 70;
/// Shades per sign of σ².
const SHADES: usize = 12;
/// Decades of |σ²|, in units of Mga/(I_X + Ma²), from light to dark.
const DECADES: (f64, f64) = (-4.0, 2.0);
/// θ₀ samples of the boundary curve per panel.
const CURVE_SAMPLES: usize = 1200;

impl StabilityMap {
    /// `stability-map.svg`: one panel per branch, σ² by colour, the boundary, ω_c and the scenes; fails
    /// ([`MapError::Plot`]) if drawing does (it does not for a validated grid).
    pub fn svg(&self) -> Result<String, MapError> {
        let branches = self.options.branches.list();
        let panels = u32::try_from(branches.len()).unwrap_or(1);
        svg_page((PANEL.0 * panels, PANEL.1 + LEGEND), |root| {
            let (top, bottom) = root.split_vertically(PANEL.1);
            let areas = top.split_evenly((1, branches.len()));
            for (area, &branch) in areas.iter().zip(branches) {
                panel(self, area, branch)?;
            }
            legend(self, &bottom)
        })
        .map_err(|e| MapError::Plot(e.to_string()))
    }
}

type DrawResult = Result<(), DrawError>;

/// The plotted ranges: the grid's cells, and θ₀ = 0 (where straight rolling and the upright spin sit).
fn ranges(map: &StabilityMap) -> ((f64, f64), (f64, f64)) {
    let (t0, t1) = map.options.theta.bounds();
    let (w0, w1) = map.options.omega_z.bounds();
    let half_t = 0.5 * map.options.theta.step().max(1e-3 * t1.abs().max(t0.abs()));
    let half_w = 0.5
        * map
            .options
            .omega_z
            .step()
            .max(1e-3 * w1.abs().max(w0.abs()).max(1e-3));
    let x = if t0 > 0.0 {
        (0.0, t1 + half_t)
    } else {
        (t0 - half_t, 0.0)
    };
    (x, (w0 - half_w, w1 + half_w))
}

fn panel(map: &StabilityMap, area: &Area<'_>, branch: Branch) -> DrawResult {
    let ((x0, x1), (y0, y1)) = ranges(map);
    let sign = if branch == Branch::Plus { "+" } else { "−" };
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!("{sign} branch: σ² of the steady circles"),
            ("sans-serif", 17),
        )
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(52)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("θ0 [rad]")
        .y_desc("ω_Z0 [rad / time unit]")
        .draw()?;
    chart.draw_series(cells(map, branch))?;
    for line in boundary_lines(map, branch, (x0, x1), (y0, y1)) {
        chart.draw_series(LineSeries::new(line, BLACK.stroke_width(2)))?;
    }
    for omega in [map.critical_spin, -map.critical_spin] {
        if omega > y0 && omega < y1 {
            chart.draw_series(DashedLineSeries::new(
                [(x0, omega), (x1, omega)],
                6,
                4,
                BLACK.stroke_width(1),
            ))?;
            chart.draw_series(std::iter::once(Text::new(
                "ω_c",
                (x0 + 0.82 * (x1 - x0), omega + 0.012 * (y1 - y0)),
                ("sans-serif", 13),
            )))?;
        }
    }
    for s in map.scenes.iter().filter(|s| s.branch == branch) {
        let inside = s.theta0 >= x0 && s.theta0 <= x1 && s.omega_z0 >= y0 && s.omega_z0 <= y1;
        if inside {
            let marker = EmptyElement::at((s.theta0, s.omega_z0))
                + Circle::new((0, 0), 4, WHITE.filled())
                + Circle::new((0, 0), 4, BLACK)
                + Text::new(s.name.clone(), (7, -14), ("sans-serif", 12));
            chart.draw_series(std::iter::once(marker))?;
        }
    }
    Ok(())
}

/// The colour of a grid point: blue when stable, red when unstable, darker as |σ²| grows (in decades of
/// Mga/(I_X + Ma²)); grey when marginal.
fn colour(p: &MapPoint, unit: f64) -> RGBColor {
    let (light, dark) = match p.verdict {
        Stability::Marginal => return MARGINAL,
        Stability::Stable => STABLE,
        Stability::Unstable => UNSTABLE,
    };
    shade(light, dark, (p.sigma_squared.abs() / unit).log10())
}

/// The shade of `decade` (log10 |σ²|/unit) between `light` and `dark`, quantised to [`SHADES`] steps.
fn shade(light: RGBColor, dark: RGBColor, decade: f64) -> RGBColor {
    let x = ((decade - DECADES.0) / (DECADES.1 - DECADES.0)).clamp(0.0, 1.0);
    #[allow(clippy::cast_precision_loss)]
    let steps = (SHADES - 1) as f64;
    let x = (x * steps).round() / steps;
    #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
    let mix = |a: u8, b: u8| (f64::from(a) + (f64::from(b) - f64::from(a)) * x).round() as u8;
    RGBColor(
        mix(light.0, dark.0),
        mix(light.1, dark.1),
        mix(light.2, dark.2),
    )
}

/// The cells of one branch, runs of one colour along ω_Z0 merged.
fn cells(map: &StabilityMap, branch: Branch) -> Vec<Rectangle<(f64, f64)>> {
    let unit = map.coin.params().topple_rate_squared();
    let (half_t, half_w) = (
        0.5 * map.options.theta.step(),
        0.5 * map.options.omega_z.step(),
    );
    let mut out = Vec::new();
    for i in 0..map.options.theta.count {
        let mut run: Option<(f64, f64, f64, RGBColor)> = None;
        for point in map.column(i, branch) {
            let c = colour(point, unit);
            let (lo, hi) = (point.omega_z0 - half_w, point.omega_z0 + half_w);
            run = match run {
                Some((t, a, b, rc)) if rc == c => Some((t, a.min(lo), b.max(hi), rc)),
                Some((t, a, b, rc)) => {
                    out.push(rectangle(t, half_t, (a, b), rc));
                    Some((point.theta0, lo, hi, c))
                }
                None => Some((point.theta0, lo, hi, c)),
            };
        }
        if let Some((t, a, b, rc)) = run {
            out.push(rectangle(t, half_t, (a, b), rc));
        }
    }
    out
}

fn rectangle(theta: f64, half: f64, (a, b): (f64, f64), c: RGBColor) -> Rectangle<(f64, f64)> {
    Rectangle::new([(theta - half, a), (theta + half, b)], c.filled())
}

/// The boundary σ² = 0 of one branch as polylines inside the plotted ranges: the closed-form points at
/// [`CURVE_SAMPLES`] leans and at each closure, joined in order of lean, one line per sign of ω_Z0 and per
/// root (smaller, larger |ω_Z0|); both roots' lines end at the closure where they meet.
fn boundary_lines(
    map: &StabilityMap,
    branch: Branch,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> Vec<Vec<(f64, f64)>> {
    let coin = &map.coin;
    let curve = Grid {
        from: x0,
        to: x1,
        count: CURVE_SAMPLES + 1,
    };
    let mut leans: Vec<f64> = (1..CURVE_SAMPLES).map(|j| curve.value(j)).collect();
    let mut folds: Vec<BoundaryPoint> = Vec::new();
    for c in &map.closures {
        for (theta, omega, omega_y) in [
            (c.theta0, c.omega_z0, c.omega_y0),
            (c.theta0, -c.omega_z0, -c.omega_y0),
            (-c.theta0, c.omega_z0, -c.omega_y0),
            (-c.theta0, -c.omega_z0, c.omega_y0),
        ] {
            folds.push(on_branch(coin, theta, omega, omega_y));
            leans.push(theta);
        }
    }
    leans.retain(|t| *t > x0 && *t < x1 && *t != 0.0);
    leans.sort_by(f64::total_cmp);
    // (sign of ω_Z0, rank by |ω_Z0|) → open polyline; finished lines.
    let mut open: [[Vec<(f64, f64)>; 2]; 2] = Default::default();
    let mut lines = Vec::new();
    for &theta in &leans {
        let fold = folds
            .iter()
            .filter(|f| f.theta0 == theta && f.branch == branch)
            .copied();
        let mut here: [Vec<BoundaryPoint>; 2] = Default::default();
        for b in boundary(coin, theta)
            .into_iter()
            .filter(|b| b.branch == branch)
            .chain(fold.clone())
            .chain(fold)
        {
            here[usize::from(b.omega_z0 < 0.0)].push(b);
        }
        for (points, lines_of_sign) in here.iter_mut().zip(open.iter_mut()) {
            points.sort_by(|a, b| a.omega_z0.abs().total_cmp(&b.omega_z0.abs()));
            for (rank, line) in lines_of_sign.iter_mut().enumerate() {
                let inside = points
                    .get(rank)
                    .filter(|p| p.omega_z0 >= y0 && p.omega_z0 <= y1);
                match inside {
                    Some(p) => line.push((p.theta0, p.omega_z0)),
                    None => lines.push(std::mem::take(line)),
                }
            }
        }
    }
    lines.extend(open.into_iter().flatten());
    lines.retain(|l| l.len() > 1);
    lines
}

/// The colour scales and what the lines and dots are.
fn legend(map: &StabilityMap, area: &Area<'_>) -> DrawResult {
    let style = ("sans-serif", 13).into_font();
    let box_width = 18;
    for (row, (label, (light, dark))) in
        [("σ² > 0, stable", STABLE), ("σ² < 0, unstable", UNSTABLE)]
            .into_iter()
            .enumerate()
    {
        let y = 8 + 22 * i32::try_from(row).unwrap_or(0);
        area.draw(&Text::new(label, (12, y + 2), style.clone()))?;
        for k in 0..SHADES {
            #[allow(clippy::cast_precision_loss)]
            let decade = DECADES.0 + (DECADES.1 - DECADES.0) * k as f64 / (SHADES - 1) as f64;
            let x = 130 + box_width * i32::try_from(k).unwrap_or(0);
            area.draw(&Rectangle::new(
                [(x, y), (x + box_width, y + 16)],
                shade(light, dark, decade).filled(),
            ))?;
        }
    }
    let scale_x = 130 + box_width * i32::try_from(SHADES).unwrap_or(0) + 10;
    area.draw(&Text::new(
        format!(
            "|σ²| from 1e{:.0} to 1e{:.0} × Mga/(I_X + Ma²)",
            DECADES.0, DECADES.1
        ),
        (scale_x, 10),
        style.clone(),
    ))?;
    area.draw(&Text::new(
        format!(
            "black: σ² = 0; dashed: ω_c = {:.6}; dots: the scenes' steady motions",
            map.critical_spin
        ),
        (scale_x, 32),
        style,
    ))?;
    Ok(())
}
