//! Where a panel's parts go: the data range, the plot area inside the panel's rectangle (room
//! for the title lines, tick labels and axis labels, and a legend outside when no corner
//! inside is free), and the map from data coordinates to pixels.

use super::axis::{ticks, Ticks};
use super::font::text_width;
use super::geometry::{Pixel, Rect};
use super::Panel;

/// Font sizes in pixels.
pub const TITLE_SIZE: f64 = 14.0;
/// Axis labels.
pub const AXIS_LABEL_SIZE: f64 = 13.0;
/// Tick labels.
pub const TICK_SIZE: f64 = 11.0;
/// Special-point labels.
pub const MARKER_LABEL_SIZE: f64 = 12.0;
/// Legend entries.
pub const LEGEND_SIZE: f64 = 12.0;

/// Line height of a title line, pixels.
pub const TITLE_LINE: f64 = 18.0;
/// Length of a tick mark, pixels.
pub const TICK_LENGTH: f64 = 5.0;
/// Number of ticks aimed at on the horizontal and the vertical axis.
const X_TICK_TARGET: usize = 6;
const Y_TICK_TARGET: usize = 5;

/// A panel's plot area, data ranges and ticks.
#[derive(Debug, Clone)]
pub struct Frame {
    /// The rectangle the curves are drawn in, pixels.
    pub plot: Rect,
    /// Horizontal data range `(lo, hi)` mapped to the plot area's left and right edges.
    pub x_range: (f64, f64),
    /// Vertical data range `(lo, hi)` mapped to its bottom and top edges.
    pub y_range: (f64, f64),
    /// Horizontal ticks.
    pub x_ticks: Ticks,
    /// Vertical ticks.
    pub y_ticks: Ticks,
}

impl Frame {
    /// The pixel of the data point `(x, y)`.
    pub fn to_pixel(&self, (x, y): (f64, f64)) -> Pixel {
        let (x0, x1) = self.x_range;
        let (y0, y1) = self.y_range;
        (
            self.plot.x0 + (x - x0) / (x1 - x0) * self.plot.width(),
            self.plot.y1 - (y - y0) / (y1 - y0) * self.plot.height(),
        )
    }
}

/// The data range of a panel's finite points, markers, region anchors, shaded polygons and
/// cells, padded by 5 % on each side (a degenerate range is widened to a unit around its
/// value).
pub fn data_range(panel: &Panel) -> ((f64, f64), (f64, f64)) {
    let points = panel
        .series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .chain(panel.markers.iter().map(|m| m.at))
        .chain(panel.regions.iter().flat_map(|r| r.anchors.iter().copied()))
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

/// The frame of `panel` drawn in `outer`, with `right_reserve` pixels kept free right of the
/// plot area (for a legend placed outside).
pub fn frame(panel: &Panel, outer: Rect, right_reserve: f64) -> Frame {
    let (x_range, y_range) = data_range(panel);
    let x_ticks = ticks(x_range.0, x_range.1, X_TICK_TARGET, false);
    let y_ticks = ticks(y_range.0, y_range.1, Y_TICK_TARGET, panel.y_integer_ticks);
    let widest_y_tick = y_ticks
        .values
        .iter()
        .map(|&v| text_width(&y_ticks.label(v), TICK_SIZE))
        .fold(0.0, f64::max);
    let title_lines = panel.title.lines().count() as f64;
    let top = outer.y0 + 8.0 + title_lines * TITLE_LINE + 8.0;
    let left = outer.x0 + 10.0 + AXIS_LABEL_SIZE + 8.0 + widest_y_tick + TICK_LENGTH + 4.0;
    let bottom = outer.y1 - (10.0 + AXIS_LABEL_SIZE + 8.0 + TICK_SIZE + TICK_LENGTH + 6.0);
    let right = outer.x1 - 16.0 - right_reserve;
    Frame {
        plot: Rect {
            x0: left,
            y0: top,
            x1: right.max(left + 40.0),
            y1: bottom.max(top + 40.0),
        },
        x_range,
        y_range,
        x_ticks,
        y_ticks,
    }
}
