//! The colours of every plot coin-log draws (`plot`, `analyse map`, the benchmark figures), so that a
//! colour means one thing everywhere: Matplotlib's tab10 for lines, ColorBrewer's sequential blues and reds
//! for the stability map's σ² > 0 and σ² < 0.

use plotters::style::RGBColor;

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
