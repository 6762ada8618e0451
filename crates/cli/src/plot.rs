//! SVG figures: a row or grid of x-y panels drawn with `plotters` into a string, which the caller
//! writes to disk atomically (see [`crate::output::write_atomically`]).

use anyhow::{anyhow, Result};
use plotters::prelude::*;

/// How a series is stroked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stroke {
    /// A continuous line (stable branches, time series).
    Solid,
    /// A dashed line (unstable branches).
    Dashed,
    /// Unconnected dots (per-cycle samples of a sweep).
    Dots,
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
    /// Text written at data positions without a marker (region names such as `1 impact`).
    pub regions: Vec<Marker>,
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
fn unwrapped_pieces(points: Vec<(f64, f64)>, period: Option<f64>) -> Vec<Vec<(f64, f64)>> {
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

const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

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
    let mut svg = String::new();
    {
        let size = (panel_size.0 * columns as u32, panel_size.1 * rows as u32);
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(plot_error)?;
        let areas = root.split_evenly((rows, columns));
        for (panel, area) in panels.iter().zip(areas.iter()) {
            draw_panel(panel, area)?;
        }
        root.present().map_err(plot_error)?;
    }
    Ok(svg)
}

fn plot_error<E: std::fmt::Debug>(error: E) -> anyhow::Error {
    anyhow!("drawing the figure failed: {error:?}")
}

/// The data range of a panel's finite points and markers, padded by 5 % on each side.
fn data_range(panel: &Panel) -> ((f64, f64), (f64, f64)) {
    let points = panel
        .series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .chain(panel.markers.iter().map(|m| m.at))
        .chain(panel.shaded.iter().flatten().copied())
        .chain(
            panel
                .cells
                .iter()
                .flat_map(|c| [(c.x.0, c.y.0), (c.x.1, c.y.1)]),
        )
        .filter(|(x, y)| x.is_finite() && y.is_finite());
    let (mut x0, mut x1, mut y0, mut y1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for (x, y) in points {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    let pad = |lo: f64, hi: f64| -> (f64, f64) {
        if !lo.is_finite() {
            return (0.0, 1.0);
        }
        let span = if hi > lo { hi - lo } else { lo.abs().max(1.0) };
        (lo - 0.05 * span, hi + 0.05 * span)
    };
    (pad(x0, x1), pad(y0, y1))
}

fn draw_panel<DB: DrawingBackend>(
    panel: &Panel,
    area: &DrawingArea<DB, plotters::coord::Shift>,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let ((x0, x1), (y0, y1)) = data_range(panel);
    let mut chart = ChartBuilder::on(area)
        .caption(&panel.title, ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(plot_error)?;
    for cell in &panel.cells {
        let finite = [cell.x.0, cell.x.1, cell.y.0, cell.y.1]
            .iter()
            .all(|v| v.is_finite());
        if !finite {
            continue;
        }
        let fill = match cell.colour {
            Some(i) => PALETTE[i % PALETTE.len()].mix(0.25).filled(),
            None => RGBColor(150, 150, 150).mix(0.5).filled(),
        };
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(cell.x.0, cell.y.0), (cell.x.1, cell.y.1)],
                fill,
            )))
            .map_err(plot_error)?;
    }
    for polygon in &panel.shaded {
        let finite: Vec<(f64, f64)> = polygon
            .iter()
            .copied()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .collect();
        if finite.len() >= 3 {
            chart
                .draw_series(std::iter::once(Polygon::new(
                    finite,
                    RGBColor(200, 200, 200).mix(0.6).filled(),
                )))
                .map_err(plot_error)?;
        }
    }
    let mut legend = false;
    for series in &panel.series {
        let colour = PALETTE[series.colour % PALETTE.len()];
        let style = ShapeStyle::from(&colour).stroke_width(2);
        let finite: Vec<(f64, f64)> = series
            .points
            .iter()
            .copied()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .collect();
        let pieces = unwrapped_pieces(finite, panel.y_period);
        let drawn = match series.stroke {
            Stroke::Solid => chart
                .draw_series(
                    pieces
                        .into_iter()
                        .map(|piece| PathElement::new(piece, style)),
                )
                .map_err(plot_error)?,
            Stroke::Dashed => chart
                .draw_series(
                    pieces
                        .into_iter()
                        .flat_map(|piece| DashedLineSeries::new(piece, 6, 4, style)),
                )
                .map_err(plot_error)?,
            Stroke::Dots => chart
                .draw_series(
                    pieces
                        .into_iter()
                        .flatten()
                        .map(|p| Circle::new(p, 1, colour.filled())),
                )
                .map_err(plot_error)?,
        };
        if !series.label.is_empty() {
            legend = true;
            drawn.label(series.label.as_str()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
            });
        }
    }
    for marker in &panel.markers {
        chart
            .draw_series(std::iter::once(Circle::new(marker.at, 4, BLACK.filled())))
            .map_err(plot_error)?;
        chart
            .draw_series(std::iter::once(Text::new(
                marker.label.clone(),
                marker.at,
                ("sans-serif", 14).into_font(),
            )))
            .map_err(plot_error)?;
    }
    for region in &panel.regions {
        chart
            .draw_series(std::iter::once(Text::new(
                region.label.clone(),
                region.at,
                ("sans-serif", 15).into_font().color(&RGBColor(90, 90, 90)),
            )))
            .map_err(plot_error)?;
    }
    if legend {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(plot_error)?;
    }
    Ok(())
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
