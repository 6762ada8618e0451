//! Figures: a grid of x-y panels drawn as SVG (axes with units, integer ticks where a count is
//! plotted, curves thinned to the figure's resolution, special points labelled clear of the
//! curves, a legend in a free corner), saved as SVG, PNG or PDF by the file's extension.
//!
//! One concept per submodule: [`axis`] (ticks), [`geometry`] (pixel rectangles),
//! [`decimate`] (thinning), [`layout`] (plot area and data-to-pixel map), [`legend`],
//! [`labels`] (leader-line placement), [`regions`] (region names placed clear of curves),
//! [`font`] (the embedded typeface), [`svg`] (the
//! document), [`raster`] (PNG and PDF), [`file`] (format by extension).

pub mod axis;
pub mod decimate;
pub mod file;
pub mod font;
pub mod geometry;
pub mod labels;
pub mod layout;
pub mod legend;
pub mod raster;
pub mod regions;
pub mod svg;

pub use file::{FigureFile, FigureFormat};

use anyhow::{anyhow, Result};

/// How a series is stroked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stroke {
    /// A continuous line (stable branches, time series).
    Solid,
    /// A dashed line (unstable branches).
    Dashed,
    /// Unconnected dots (per-cycle samples of a sweep).
    Dots,
    /// Smaller unconnected dots (a sweep's retract, drawn over the approach's larger dots so
    /// that both show where they coincide).
    FineDots,
    /// A dash-dot line (a retract branch's stable parts, drawn over the approach).
    DashDot,
    /// A dotted line (a retract branch's unstable parts).
    Dotted,
}

/// One curve of a panel: a polyline through `points` in data coordinates.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text; empty for no legend entry.
    pub label: String,
    /// Points in data coordinates; non-finite points are skipped.
    pub points: Vec<(f64, f64)>,
    /// Line style.
    pub stroke: Stroke,
    /// Index into the figure palette.
    pub colour: usize,
}

/// A labelled marker (a special point such as `G2`) drawn on a panel.
#[derive(Debug, Clone)]
pub struct Marker {
    /// Text written beside the marker.
    pub label: String,
    /// Position in data coordinates.
    pub at: (f64, f64),
}

/// A region of the plane named by a text without a marker (such as `1 impact` between two
/// grazing curves): the text is centred on the first of `anchors` where it covers no curve,
/// label or legend (see [`regions`]).
#[derive(Debug, Clone)]
pub struct Region {
    /// The name.
    pub label: String,
    /// Points inside the region in data coordinates, preferred first.
    pub anchors: Vec<(f64, f64)>,
}

/// A filled rectangle in data coordinates (a cell of a brute-force grid), drawn under
/// everything else in a light tint of a palette colour, or grey for `None`.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    /// Horizontal extent `(low, high)`.
    pub x: (f64, f64),
    /// Vertical extent `(low, high)`.
    pub y: (f64, f64),
    /// Index into the palette, or `None` for grey.
    pub colour: Option<usize>,
}

/// One x-y chart of a figure.
#[derive(Debug, Clone, Default)]
pub struct Panel {
    /// Title above the chart.
    pub title: String,
    /// Label of the horizontal axis, with units.
    pub x_label: String,
    /// Label of the vertical axis, with units.
    pub y_label: String,
    /// The curves.
    pub series: Vec<Series>,
    /// Labelled points.
    pub markers: Vec<Marker>,
    /// `Some(p)` when the vertical axis is an angle modulo `p` (360 for a phase in degrees,
    /// wrapped to `(-180, 180]`): a line is broken, not drawn, between consecutive points more
    /// than `p / 2` apart, so that a wrap does not draw a vertical line across the chart.
    pub y_period: Option<f64>,
    /// Whether the vertical axis counts something (impacts per period): ticks at integers only.
    pub y_integer_ticks: bool,
    /// Names written inside regions of the plane, without a marker (such as `1 impact`).
    pub regions: Vec<Region>,
    /// Closed polygons in data coordinates filled in a light grey under the series (regions
    /// such as a bistable range).
    pub shaded: Vec<Vec<(f64, f64)>>,
    /// Filled rectangles drawn first, under the shading and the series.
    pub cells: Vec<Cell>,
}

/// The period of a phase axis in degrees (see [`Panel::y_period`]).
pub const PHASE_PERIOD_DEG: f64 = 360.0;

/// `points` cut into polylines wherever consecutive `y` values are more than `period / 2`
/// apart (a wrap of an angle modulo `period`); one polyline without a period.
pub(crate) fn unwrapped_pieces(
    points: Vec<(f64, f64)>,
    period: Option<f64>,
) -> Vec<Vec<(f64, f64)>> {
    let Some(period) = period else {
        return vec![points];
    };
    let mut pieces: Vec<Vec<(f64, f64)>> = Vec::new();
    for point in points {
        match pieces.last_mut() {
            Some(piece)
                if piece
                    .last()
                    .is_some_and(|last| (point.1 - last.1).abs() <= 0.5 * period) =>
            {
                piece.push(point)
            }
            _ => pieces.push(vec![point]),
        }
    }
    pieces
}

/// Draw `panels` on a grid of `rows` x `columns` charts, each `panel_size` pixels, and return the
/// SVG document as a string.
pub fn render_svg(
    panels: &[Panel],
    rows: usize,
    columns: usize,
    panel_size: (u32, u32),
) -> Result<String> {
    if rows * columns < panels.len() {
        return Err(anyhow!(
            "a {rows} x {columns} grid cannot hold {} panels",
            panels.len()
        ));
    }
    Ok(svg::document(panels, columns, panel_size))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_phase_wrap_breaks_the_line_and_nothing_else_does() {
        // A branch's phase running past -180 deg comes back at +180: two pieces, no segment
        // spanning the wrap. Steps up to half the period stay joined.
        let points = vec![(0.3, -170.0), (0.2, -179.0), (0.1, 179.5), (0.0, 170.0)];
        let pieces = unwrapped_pieces(points.clone(), Some(PHASE_PERIOD_DEG));
        assert_eq!(pieces, vec![points[..2].to_vec(), points[2..].to_vec()]);
        let steep = vec![(0.0, -90.0), (1.0, 90.0)];
        assert_eq!(unwrapped_pieces(steep.clone(), Some(360.0)), vec![steep]);
        assert_eq!(unwrapped_pieces(points.clone(), None), vec![points]);
    }
}
