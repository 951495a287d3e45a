//! `coin-log plot` (docs/format.md: plot): a one-page SVG overview of a recording, read in one streaming
//! pass. Memory stays bounded whatever the file's length: each time series keeps at most [`POINTS`]
//! min/max buckets (so no spike is lost), and the paths keep every k-th point with k doubling as needed.

use super::read_values;
use crate::files::shown_name;
use crate::format::fields::FieldReader;
use crate::format::{
    Channel, ResultMetadata, RunMetadata, RESULT_METADATA_NAME, RUN_METADATA_NAME,
};
use crate::model::drift::{EnergyDrift, InvariantDrift};
use crate::model::CoinParams;
use crate::palette::{
    legend_box, legend_line, svg_page, Area, DrawError, BLUE, GREEN, GREY, ORANGE, RED,
};
use crate::scene::SceneFile;
use coin_log_mcap::{self, MessageHeader, ReadError, Schema, Visitor};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::path::Path;

/// Buckets per time series (each drawn as its minimum and maximum) and points per path.
pub const POINTS: usize = 2000;
/// Size of the page \[px\].
pub const SIZE: (u32, u32) = (1400, 1560);
/// The panels' titles, in page order (a test finds each in the SVG).
pub const PANELS: [&str; 6] = [
    "contact track and centre path, seen from above",
    "lean θ(t)",
    "energy drift |E − E₀| / max(|E₀|, Mga)",
    "invariant drift |C − C₀| / (|C1₀| + |C2₀|)",
    "normal force N / (Mg)",
    "friction ratio |F| / N",
];

/// Why a file could not be plotted.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct PlotError(pub String);

/// A time series kept as min/max buckets of a doubling width.
#[derive(Debug, Clone, Default)]
struct Envelope {
    /// Samples per bucket.
    width: usize,
    /// Samples in the last bucket.
    filled: usize,
    /// (t of min, min, t of max, max) per bucket.
    buckets: Vec<(f64, f64, f64, f64)>,
}

impl Envelope {
    fn push(&mut self, t: f64, v: f64) {
        self.width = self.width.max(1);
        if self.filled == 0 || self.filled == self.width {
            if self.buckets.len() == 2 * POINTS {
                self.halve();
            }
            self.buckets.push((t, v, t, v));
            self.filled = 1;
            return;
        }
        self.filled += 1;
        if let Some(b) = self.buckets.last_mut() {
            if v < b.1 {
                (b.0, b.1) = (t, v);
            }
            if v > b.3 {
                (b.2, b.3) = (t, v);
            }
        }
    }

    /// Merges neighbouring buckets: half as many, twice as wide.
    fn halve(&mut self) {
        let merged = self
            .buckets
            .chunks(2)
            .map(|p| match p {
                [a, b] => {
                    let low = if b.1 < a.1 { (b.0, b.1) } else { (a.0, a.1) };
                    let high = if b.3 > a.3 { (b.2, b.3) } else { (a.2, a.3) };
                    (low.0, low.1, high.0, high.1)
                }
                [a] => *a,
                _ => unreachable!("chunks(2) gives one or two"),
            })
            .collect();
        self.buckets = merged;
        self.width *= 2;
    }

    /// The points to draw, in time order: each bucket's minimum and maximum.
    fn points(&self) -> Vec<(f64, f64)> {
        let mut out = Vec::with_capacity(2 * self.buckets.len());
        for &(t0, v0, t1, v1) in &self.buckets {
            if t0 == t1 {
                out.push((t0, v0));
            } else if t0 < t1 {
                out.extend([(t0, v0), (t1, v1)]);
            } else {
                out.extend([(t1, v1), (t0, v0)]);
            }
        }
        out
    }

    fn is_empty(&self) -> bool {
        self.buckets.is_empty()
    }
}

/// A path kept as every k-th point (k doubling as needed) and the last point.
#[derive(Debug, Clone, Default)]
struct Path2 {
    stride: usize,
    seen: usize,
    points: Vec<(f64, f64)>,
    last: Option<(f64, f64)>,
}

impl Path2 {
    fn push(&mut self, p: (f64, f64)) {
        self.stride = self.stride.max(1);
        if self.seen.is_multiple_of(self.stride) {
            if self.points.len() == 2 * POINTS {
                self.points = self.points.iter().step_by(2).copied().collect();
                self.stride *= 2;
            }
            if self.seen.is_multiple_of(self.stride) {
                self.points.push(p);
            }
        }
        self.seen += 1;
        self.last = Some(p);
    }

    fn points(&self) -> Vec<(f64, f64)> {
        let mut out = self.points.clone();
        if let Some(p) = self.last {
            if out.last() != Some(&p) {
                out.push(p);
            }
        }
        out
    }
}

/// Field values by name of one message.
struct Fields<'a> {
    names: &'static [&'static str],
    values: &'a [f64],
}

impl Fields<'_> {
    fn get(&self, name: &str) -> Option<f64> {
        self.names
            .iter()
            .position(|n| *n == name)
            .map(|i| self.values[i])
    }
}

/// Everything the page draws, gathered in one pass.
#[derive(Default)]
struct Collect {
    /// The channel and field reader of each plotted channel id.
    readers: BTreeMap<u16, (Channel, FieldReader)>,
    run: Option<Result<RunMetadata, String>>,
    result: Option<ResultMetadata>,
    params: Option<CoinParams>,
    values: Vec<f64>,
    problem: Option<String>,
    contact: Path2,
    centre: Path2,
    theta: Envelope,
    energy: Envelope,
    energy_drift: Option<EnergyDrift>,
    c1: Envelope,
    c2: Envelope,
    invariant_drift: Option<InvariantDrift>,
    normal: Envelope,
    ratio: Envelope,
    last_t: f64,
}

impl Collect {
    fn observe(&mut self, channel: Channel, f: &Fields<'_>) {
        let Some(t) = f.get("t") else {
            return;
        };
        self.last_t = self.last_t.max(t);
        let Some(params) = self.params else {
            return;
        };
        let mg = params.mass() * params.gravity();
        match channel {
            Channel::Angles => {
                if let Some(theta) = f.get("theta") {
                    self.theta.push(t, theta);
                }
            }
            Channel::Position | Channel::Contact => {
                if let (Some(x), Some(z)) = (f.get("x"), f.get("z")) {
                    let path = if channel == Channel::Position {
                        &mut self.centre
                    } else {
                        &mut self.contact
                    };
                    path.push((x, z));
                }
            }
            Channel::Energy => {
                if let Some(e) = f.get("total") {
                    let drift = *self
                        .energy_drift
                        .get_or_insert_with(|| EnergyDrift::new(&params, e));
                    self.energy
                        .push(t, (e - drift.reference).abs() / drift.scale);
                }
            }
            Channel::Invariants => {
                if let (Some(c1), Some(c2)) = (f.get("c1"), f.get("c2")) {
                    let drift = *self
                        .invariant_drift
                        .get_or_insert_with(|| InvariantDrift::new(&params, c1, c2));
                    let (a, b) = drift.reference;
                    self.c1.push(t, (c1 - a).abs() / drift.scale);
                    self.c2.push(t, (c2 - b).abs() / drift.scale);
                }
            }
            Channel::Reaction => {
                if let (Some(n), Some(fr)) = (f.get("normal"), f.get("friction")) {
                    self.normal.push(t, n / mg);
                    if n > 0.0 {
                        self.ratio.push(t, fr / n);
                    }
                }
            }
            _ => {}
        }
    }

    fn run_metadata(&mut self, entries: &BTreeMap<String, String>) {
        let run = RunMetadata::from_map(entries).map_err(|e| e.to_string());
        if let Ok(r) = &run {
            match r.params() {
                Ok(p) => self.params = Some(p),
                Err(e) => self.problem = Some(format!("unusable body parameters: {e}")),
            }
        }
        self.run = Some(run);
    }
}

impl Visitor for Collect {
    fn channel(&mut self, id: u16, topic: &str, _: &str, schema: Option<&Schema<'_>>) {
        let reader = schema.and_then(|s| {
            let c = Channel::from_topic(topic).filter(|c| c.schema_name() == s.name)?;
            Some((c, FieldReader::new(&s.encoding, c.message_type()?, &s.data)))
        });
        match reader {
            Some((c, Ok((r, _)))) => {
                self.readers.insert(id, (c, r));
            }
            Some((_, Err(e))) => {
                self.problem.get_or_insert_with(|| format!("{topic}: {e}"));
            }
            None => {}
        }
    }
    fn metadata(&mut self, name: &str, entries: &BTreeMap<String, String>) {
        if name == RUN_METADATA_NAME && self.run.is_none() {
            self.run_metadata(entries);
        } else if name == RESULT_METADATA_NAME {
            self.result = ResultMetadata::from_map(entries).ok();
        }
    }
    fn message(&mut self, h: &MessageHeader, data: &[u8]) -> ControlFlow<()> {
        if self.run.is_none() {
            return ControlFlow::Break(());
        }
        let Some((channel, reader)) = self.readers.get(&h.channel_id) else {
            return ControlFlow::Continue(());
        };
        let (channel, names) = (*channel, reader.fields());
        let mut values = std::mem::take(&mut self.values);
        if let Err(e) = read_values(reader, data, &mut values, (channel.topic(), h.log_time)) {
            self.problem = Some(e);
            return ControlFlow::Break(());
        }
        let fields = Fields {
            names,
            values: &values,
        };
        self.observe(channel, &fields);
        self.values = values;
        ControlFlow::Continue(())
    }
}

/// A drawn overview.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Plot {
    /// The SVG document.
    pub svg: String,
    /// Why the file breaks off (truncated or corrupt part way): the picture shows it up to there, and
    /// says so in its title.
    pub broken: Option<String>,
}

/// The one-page overview of the file at `path` as an SVG document; `name` is shown in the title.
///
/// # Errors
/// [`PlotError`] if the file cannot be read, is not a coin-log file, breaks off before its `coin-log`
/// metadata, or a message does not fit its schema. A file that breaks off later is drawn up to the break
/// ([`Plot::broken`]).
pub fn plot(path: &Path, name: &str) -> Result<Plot, PlotError> {
    let mut c = Collect::default();
    let (_, error) = coin_log_mcap::read(path, &mut c);
    let broken = ReadError::broken_off(error)
        .map_err(|e| PlotError(e.detail))?
        .map(|e| e.detail);
    if let Some(p) = c.problem.take() {
        return Err(PlotError(p));
    }
    let run = match (c.run.take(), broken.as_deref()) {
        (Some(Ok(run)), _) => run,
        (Some(Err(e)), _) => {
            return Err(PlotError(format!(
                "its `coin-log` metadata is unusable: {e}"
            )))
        }
        (None, Some(broken)) => return Err(PlotError(format!(
            "{broken}; the file breaks off before its `coin-log` metadata record, so there is nothing to draw"
        ))),
        (None, None) => return Err(PlotError(
            "not a coin-log file: it has no `coin-log` metadata record before its first message"
                .into(),
        )),
    };
    let svg = draw(&c, &run, name, broken.as_deref()).map_err(PlotError)?;
    Ok(Plot { svg, broken })
}

/// The page's title: the file, the scene's description, how the run ended.
fn title(c: &Collect, run: &RunMetadata, name: &str, broken: Option<&str>) -> (String, String) {
    let description = toml::from_str::<SceneFile>(&run.scene)
        .ok()
        .and_then(|s| s.description)
        .map(|d| shown_name(&d))
        .unwrap_or_default();
    let end = match (&c.result, broken) {
        (_, Some(b)) => format!("file breaks off after t = {}: {b}", c.last_t),
        (Some(r), None) => format!("{} at t = {}", r.termination, r.termination_time),
        (None, None) => format!(
            "no coin-log.result record: unfinished, last sample t = {}",
            c.last_t
        ),
    };
    let friction = run
        .friction
        .map_or_else(|| "no μ".to_string(), |m| format!("μ = {}", number(m)));
    (
        format!("{name}: {end}"),
        format!(
            "{description} — M = {}, a = {}, g = {}, I_X = {}, I_Z = {}, {friction}; {} rtol {:e} atol {:e}, rate {}",
            number(run.mass), number(run.radius), number(run.gravity), number(run.inertia_x),
            number(run.inertia_z), run.integrator, run.rtol, run.atol, number(run.rate)
        ),
    )
}

/// `v` in its shortest form: as `{}` writes it (`1`, `0.25`) within 1e-4 … 1e16, in exponent form
/// beyond (`1e70`, not 71 digits; `2.5e-7`, not `0.00000025`), as `info` writes the settings.
fn number(v: f64) -> String {
    if v != 0.0 && !(1e-4..1e16).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

fn draw(
    c: &Collect,
    run: &RunMetadata,
    name: &str,
    broken: Option<&str>,
) -> Result<String, String> {
    let (heading, subheading) = title(c, run, name, broken);
    let end = c
        .result
        .as_ref()
        .map(|r| (r.termination.name(), r.termination_time));
    // 2 % beyond the last time, so that the termination's mark stands clear of the frame.
    let t_max = 1.02 * c.last_t.max(end.map_or(0.0, |e| e.1)).max(1e-9);
    svg_page(SIZE, |root| {
        let (top, body) = root.split_vertically(70);
        top.draw_text(
            &heading,
            &("sans-serif", 22).into_font().color(&BLACK),
            (20, 12),
        )?;
        top.draw_text(
            &subheading,
            &("sans-serif", 14).into_font().color(&GREY),
            (20, 44),
        )?;
        let panels = body.split_evenly((3, 2));
        track(&panels[0], c)?;
        let time = TimeAxis { t_max, end };
        time.linear(
            &panels[1],
            PANELS[1],
            "θ [rad]",
            &[("θ", &c.theta, BLUE)],
            None,
        )?;
        time.log(&panels[2], PANELS[2], &[("energy", &c.energy, BLUE)])?;
        time.log(
            &panels[3],
            PANELS[3],
            &[("C1", &c.c1, BLUE), ("C2", &c.c2, ORANGE)],
        )?;
        time.linear(
            &panels[4],
            PANELS[4],
            "N / (Mg)",
            &[("N/(Mg)", &c.normal, BLUE)],
            Some(("N", 0.0)),
        )?;
        let mu = run.friction.map(|m| ("μ", m));
        time.linear(
            &panels[5],
            PANELS[5],
            "|F| / N",
            &[("|F|/N", &c.ratio, BLUE)],
            mu,
        )
    })
    .map_err(|e| e.to_string())
}

/// A panel that says why it is empty.
fn empty(area: &Area<'_>, title: &str, why: &str) -> Result<(), DrawError> {
    let area = area.titled(title, ("sans-serif", 16))?;
    area.draw_text(why, &("sans-serif", 14).into_font().color(&GREY), (40, 60))
}

/// Range `lo..hi` widened by 5 % of its span on each side (a fixed span when it is empty). The ends are
/// first held within ±`f64::MAX`/4, so that the span and the widened range stay finite: plotters' axes
/// loop without end on an infinite range.
fn padded((lo, hi): (f64, f64)) -> (f64, f64) {
    if lo > hi {
        // No finite value.
        return (-1.0, 1.0);
    }
    let (lo, hi) = (clamp_finite(lo), clamp_finite(hi));
    let span = hi - lo;
    if span > 0.0 {
        (lo - 0.05 * span, hi + 0.05 * span)
    } else {
        let w = if lo == 0.0 { 1.0 } else { lo.abs() * 0.1 };
        (lo - w, hi + w)
    }
}

/// Tick labels of an axis over `lo..hi`: plotters' own (at most 5 decimals, no exponent) when the span is
/// wide enough for those to tell the ticks apart, as on every ordinary recording; otherwise, for a short
/// span near 0 (the time axis of a run of a microsecond, where plotters' would print `0.0` on every tick),
/// each tick in exponent form with the few significant digits its step needs. A value constant to
/// rounding (θ of a steady motion) keeps plotters' labels, which show the value. Values of [`LARGE`] and
/// beyond are in exponent form too (at most [`SHORT_DIGITS`] digits after the leading one): plotters'
/// labels write every digit, 70 of them for a track in units where a = 1e70.
fn tick_label(lo: f64, hi: f64) -> impl Fn(&f64) -> String {
    let span = (hi - lo).abs();
    // Ticks are about a tenth of the span apart: the digits between the largest value's leading digit and
    // the step's.
    let decade = |x: f64| x.log10().floor();
    let largest = lo.abs().max(hi.abs());
    let digits = decade(largest) - decade(span / 10.0);
    let short = span < WIDE_SPAN && digits <= SHORT_DIGITS;
    let digits = (short || largest >= LARGE).then(|| {
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let digits = digits.clamp(0.0, SHORT_DIGITS) as usize;
        digits
    });
    move |v: &f64| match digits {
        None => <RangedCoordf64 as plotters::coord::ranged1d::ValueFormatter<f64>>::format(v),
        // Plotters computes ticks as sums of steps: the one at 0 can be off by rounding (-9.2e54 on an
        // axis of ±2e70).
        Some(_) if v.abs() <= 1e-12 * span => "0".to_string(),
        Some(d) => format!("{v:.d$e}"),
    }
}

/// The narrowest span whose ticks plotters' labels (5 decimals) tell apart: ticks a tenth of it apart.
const WIDE_SPAN: f64 = 1e-3;
/// The most digits after the leading one of an exponent-form tick label (it fits the label area).
const SHORT_DIGITS: f64 = 6.0;
/// The magnitude from which tick labels are in exponent form (`1.5e6`, not `1500000.0`).
const LARGE: f64 = 1e6;

/// The widest span of a track drawn in units of a power of ten ([`track`]): far above plotters' limit
/// (2.2e-16), far below any track of an ordinary scale.
const TINY_SPAN: f64 = 1e-12;

/// `label` of a value drawn in units of `unit`.
fn in_units(unit: f64, label: impl Fn(&f64) -> String) -> impl Fn(&f64) -> String {
    move |v: &f64| label(&(v * unit))
}

/// `x` held within ±`f64::MAX`/4.
fn clamp_finite(x: f64) -> f64 {
    x.clamp(-f64::MAX / 4.0, f64::MAX / 4.0)
}

/// The least and largest finite value of `pick` over `points` (`(inf, -inf)` when there is none): a value
/// that overflowed (an energy of 1e300 divided by its scale, |F| over N = 1e-320) is drawn at the edge,
/// not given an infinite axis.
fn min_max<'a>(
    points: impl Iterator<Item = &'a (f64, f64)>,
    pick: fn(&(f64, f64)) -> f64,
) -> (f64, f64) {
    points
        .map(pick)
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        })
}

/// The path of the contact point and of the centre in the table plane: x across, z down the page,
/// one length unit the same on both axes.
fn track(area: &Area<'_>, c: &Collect) -> Result<(), DrawError> {
    let (contact, centre) = (c.contact.points(), c.centre.points());
    if contact.is_empty() && centre.is_empty() {
        return empty(
            area,
            PANELS[0],
            "/coin/contact and /coin/position were not recorded",
        );
    }
    let all = || contact.iter().chain(&centre);
    let (x0, x1) = padded(min_max(all(), |p| p.0));
    let (z0, z1) = padded(min_max(all(), |p| p.1));
    // Plotters puts one tick on an axis narrower than about 2.2e-16 (a track where a = 1e-70): such a
    // track is drawn in units of a power of ten near its span, and its ticks labelled in the true values.
    let span = (x1 - x0).max(z1 - z0);
    let unit = if span < TINY_SPAN {
        10f64.powf(span.log10().floor())
    } else {
        1.0
    };
    let scaled = |points: &[(f64, f64)]| -> Vec<(f64, f64)> {
        points.iter().map(|&(x, z)| (x / unit, z / unit)).collect()
    };
    let (contact, centre) = (scaled(&contact), scaled(&centre));
    let (x0, x1, z0, z1) = (x0 / unit, x1 / unit, z0 / unit, z1 / unit);
    // Equal axes: widen the shorter range to the plotting area's aspect ratio.
    let (label_x, label_y, margin) = (40u32, 60u32, 12u32);
    let (w, h) = area.dim_in_pixel();
    let plot_w = f64::from(w.saturating_sub(label_y + 2 * margin).max(1));
    let plot_h = f64::from(h.saturating_sub(label_x + 2 * margin + 24).max(1));
    let scale = ((x1 - x0) / plot_w).max((z1 - z0) / plot_h);
    let (xc, zc) = (0.5 * (x0 + x1), 0.5 * (z0 + z1));
    let (hx, hz) = (0.5 * scale * plot_w, 0.5 * scale * plot_h);
    let mut chart = ChartBuilder::on(area)
        .caption(PANELS[0], ("sans-serif", 16))
        .margin(margin)
        .x_label_area_size(label_x)
        .y_label_area_size(label_y)
        .build_cartesian_2d(xc - hx..xc + hx, zc + hz..zc - hz)?;
    chart
        .configure_mesh()
        .x_desc("x")
        .y_desc("z (down the page: the view from above)")
        .x_label_formatter(&in_units(
            unit,
            tick_label(unit * (xc - hx), unit * (xc + hx)),
        ))
        .y_label_formatter(&in_units(
            unit,
            tick_label(unit * (zc - hz), unit * (zc + hz)),
        ))
        .draw()?;
    for (label, points, colour) in [
        ("contact track", &contact, BLUE),
        ("centre", &centre, ORANGE),
    ] {
        if points.is_empty() {
            continue;
        }
        chart
            .draw_series(LineSeries::new(
                points.iter().copied(),
                colour.stroke_width(1),
            ))?
            .label(label)
            .legend(legend_line(colour, 2));
        let (first, last) = (points[0], points[points.len() - 1]);
        chart.draw_series([Circle::new(first, 4, colour.filled())])?;
        chart.draw_series([Cross::new(last, 6, RED.stroke_width(2))])?;
    }
    legend_box(&mut chart, SeriesLabelPosition::UpperRight)
}

/// The axes of a time panel.
type TimeChart<'a, 'b, Y> = ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, Y>>;

/// The common time axis of the time panels, with the termination marked.
struct TimeAxis<'a> {
    t_max: f64,
    end: Option<(&'a str, f64)>,
}

impl TimeAxis<'_> {
    /// A panel of `series` against t; `line` draws a labelled horizontal line (N = 0, μ).
    fn linear(
        &self,
        area: &Area<'_>,
        title: &str,
        y_desc: &str,
        series: &[(&str, &Envelope, RGBColor)],
        line: Option<(&str, f64)>,
    ) -> Result<(), DrawError> {
        if series.iter().all(|s| s.1.is_empty()) {
            return empty(area, title, "the channel this needs was not recorded");
        }
        let points: Vec<Vec<(f64, f64)>> = series.iter().map(|s| s.1.points()).collect();
        let (mut lo, mut hi) = min_max(points.iter().flatten(), |p| p.1);
        if let Some((_, v)) = line {
            (lo, hi) = (lo.min(v), hi.max(v));
        }
        let (y0, y1) = padded((lo, hi));
        let mut chart = ChartBuilder::on(area)
            .caption(title, ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..self.t_max, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc("t")
            .y_desc(y_desc)
            .x_label_formatter(&tick_label(0.0, self.t_max))
            .y_label_formatter(&tick_label(y0, y1))
            .draw()?;
        self.finish(&mut chart, series, &points, |v| v, line, (y0, y1))
    }

    /// A panel of non-negative `series` on a log scale; zeros are drawn on the bottom edge, which sits a
    /// decade below the smallest positive value (at 1e-17 when every value is 0).
    fn log(
        &self,
        area: &Area<'_>,
        title: &str,
        series: &[(&str, &Envelope, RGBColor)],
    ) -> Result<(), DrawError> {
        if series.iter().all(|s| s.1.is_empty()) {
            return empty(area, title, "the channel this needs was not recorded");
        }
        let points: Vec<Vec<(f64, f64)>> = series.iter().map(|s| s.1.points()).collect();
        let positive = points.iter().flatten().filter(|p| p.1 >= f64::MIN_POSITIVE);
        let (lo, hi) = min_max(positive, |p| p.1);
        // At most 300 decades between the edges: plotters counts a log axis's decades from the ratio of
        // its ends, and loops without end when that ratio overflows.
        let (floor, top) = if hi > 0.0 {
            let top = (hi * 10.0).min(f64::MAX);
            ((lo / 10.0).max(f64::MIN_POSITIVE).max(top / 1e300), top)
        } else {
            (1e-17, 1e-15)
        };
        let mut chart = ChartBuilder::on(area)
            .caption(title, ("sans-serif", 16))
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..self.t_max, (floor..top).log_scale())?;
        chart
            .configure_mesh()
            .x_desc("t")
            .x_label_formatter(&tick_label(0.0, self.t_max))
            .y_desc(if hi > 0.0 {
                "relative drift (0 on the bottom edge)"
            } else {
                "identically 0"
            })
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()?;
        self.finish(
            &mut chart,
            series,
            &points,
            |v| v.max(floor).min(top),
            None,
            (floor, top),
        )
    }

    /// Draws each of `series` as a line through its `points` (values mapped by `value`), the labelled
    /// horizontal `line` if any, the termination as a dashed red vertical line over y0..y1, and the
    /// legend.
    fn finish<'a, 'b: 'a, Y: Ranged<ValueType = f64>>(
        &self,
        chart: &mut TimeChart<'a, 'b, Y>,
        series: &[(&str, &Envelope, RGBColor)],
        points: &[Vec<(f64, f64)>],
        value: impl Fn(f64) -> f64,
        line: Option<(&str, f64)>,
        (y0, y1): (f64, f64),
    ) -> Result<(), DrawError> {
        for ((label, _, colour), points) in series.iter().zip(points) {
            chart
                .draw_series(LineSeries::new(
                    points.iter().map(|&(t, v)| (t, value(v))),
                    colour.stroke_width(1),
                ))?
                .label(*label)
                .legend(legend_line(*colour, 2));
        }
        let mut dashed = |ends: [(f64, f64); 2], dash, colour: RGBColor, label: String| {
            chart
                .draw_series(DashedLineSeries::new(ends, dash, 4, colour.stroke_width(2)))?
                .label(label)
                .legend(legend_line(colour, 2));
            Ok::<_, DrawError>(())
        };
        if let Some((label, v)) = line {
            dashed(
                [(0.0, v), (self.t_max, v)],
                6,
                GREEN,
                format!("{label} = {v}"),
            )?;
        }
        if let Some((name, t)) = self.end {
            dashed([(t, y0), (t, y1)], 5, RED, format!("{name} at t = {t}"))?;
        }
        legend_box(chart, SeriesLabelPosition::UpperRight)
    }
}

#[cfg(test)]
mod tests {
    use super::{Envelope, Path2, POINTS};

    #[test]
    fn the_envelope_stays_bounded_and_keeps_every_extreme() {
        let mut e = Envelope::default();
        let n = 10 * POINTS + 7;
        for i in 0..n {
            let spike = if i == 12_345 { 1e3 } else { 0.0 };
            #[allow(clippy::cast_precision_loss)]
            e.push(i as f64, (i as f64).sin() + spike);
        }
        assert!(e.buckets.len() <= 2 * POINTS, "{} buckets", e.buckets.len());
        let max = e.points().iter().map(|p| p.1).fold(f64::MIN, f64::max);
        assert!(max > 1e3 - 1.0, "the spike survives decimation: max {max}");
        let times: Vec<f64> = e.points().iter().map(|p| p.0).collect();
        assert!(
            times.windows(2).all(|w| w[0] <= w[1]),
            "points in time order"
        );
    }

    #[test]
    fn the_path_stays_bounded_and_ends_at_the_last_point() {
        let mut p = Path2::default();
        let n = 7 * POINTS + 3;
        for i in 0..n {
            #[allow(clippy::cast_precision_loss)]
            p.push((i as f64, 0.0));
        }
        let points = p.points();
        assert!(points.len() <= 2 * POINTS + 1, "{} points", points.len());
        assert_eq!(points[0], (0.0, 0.0));
        #[allow(clippy::cast_precision_loss)]
        let last = (n - 1) as f64;
        assert_eq!(points[points.len() - 1], (last, 0.0));
    }
}
