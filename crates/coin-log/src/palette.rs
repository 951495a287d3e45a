//! The colours and the SVG page of every plot coin-log draws (`plot`, `analyse map`, the benchmark
//! figures), so that a colour means one thing everywhere: Matplotlib's tab10 for lines, ColorBrewer's
//! sequential blues and reds for the stability map's σ² > 0 and σ² < 0.

use plotters::coord::Shift;
use plotters::prelude::*;

/// Line colours in order (tab10): blue, orange, green, red, purple, brown.
pub const LINES: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
];
/// The first line colour.
pub const BLUE: RGBColor = LINES[0];
/// The second line colour.
pub const ORANGE: RGBColor = LINES[1];
/// The third line colour: reference values.
pub const GREEN: RGBColor = LINES[2];
/// The fourth line colour: where a run ends.
pub const RED: RGBColor = LINES[3];
/// Secondary text.
pub const GREY: RGBColor = RGBColor(120, 120, 120);

/// Light and dark ends of the stable (blue) scale of the stability map.
pub const STABLE: (RGBColor, RGBColor) = (RGBColor(222, 235, 247), RGBColor(8, 48, 107));
/// Light and dark ends of the unstable (red) scale of the stability map.
pub const UNSTABLE: (RGBColor, RGBColor) = (RGBColor(254, 224, 210), RGBColor(165, 15, 21));
/// The stability map's cells with σ² = 0 to rounding.
pub const MARGINAL: RGBColor = RGBColor(150, 150, 150);

/// A drawing area of an SVG page.
pub type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// What drawing on an SVG page can fail with.
pub type DrawError = DrawingAreaErrorKind<std::io::Error>;

/// An SVG document of `size` pixels: a white page with what `draw` puts on it (plotters' SVG backend:
/// no fonts are needed, text is written as SVG `<text>`), or the first error of `draw` or the backend.
pub fn svg_page(
    size: (u32, u32),
    draw: impl FnOnce(&Area<'_>) -> Result<(), DrawError>,
) -> Result<String, DrawError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
        root.present()?;
    }
    Ok(xml_chars(svg))
}

/// `svg` with U+FFFE, U+FFFF (which XML 1.0 does not allow in a document) and the control characters
/// other than tab, LF and CR (C0 ones it does not allow, C1 ones it discourages) escaped (`\u{fffe}`):
/// plotters escapes `<`, `&` and quotes but writes text as given, and a scene's description (which
/// `record` accepts with U+FFFE) made the SVG not well-formed. (Not through `files`' escaping: `palette`
/// and `files` are modules of one layer, docs/architecture.md.)
fn xml_chars(svg: String) -> String {
    let bad = |c: char| {
        matches!(c, '\u{fffe}' | '\u{ffff}') || (c.is_control() && !matches!(c, '\t' | '\n' | '\r'))
    };
    if !svg.contains(bad) {
        return svg;
    }
    let each = |c: char| {
        if bad(c) {
            c.escape_unicode().to_string()
        } else {
            c.to_string()
        }
    };
    svg.chars().map(each).collect()
}

/// The legend of `chart`'s labelled series at `position`, on a light box with a black border (or the
/// backend's error).
pub fn legend_box<'a, DB: DrawingBackend + 'a, X: Ranged, Y: Ranged>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<X, Y>>,
    position: SeriesLabelPosition,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
}

/// A legend entry's sample: a line 20 px long in `colour`, `width` px wide.
pub fn legend_line(colour: RGBColor, width: u32) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(width))
}
