//! The legend: its size, and a place for it that covers no curve: the first free corner of
//! the plot area (upper right, upper left, lower right, lower left), else outside it.

use super::font::text_width;
use super::geometry::{Pixel, Rect};
use super::layout::LEGEND_SIZE;
use super::Stroke;

/// One legend line: a sample of the stroke in its colour, then the text.
#[derive(Debug, Clone)]
pub struct LegendEntry {
    /// Text.
    pub label: String,
    /// Palette index.
    pub colour: usize,
    /// Line style.
    pub stroke: Stroke,
}

/// Height of one legend line, pixels.
pub const LEGEND_LINE: f64 = 17.0;
/// Length of the stroke sample, pixels.
pub const SWATCH: f64 = 26.0;
/// Inner padding of the legend box, pixels.
pub const LEGEND_PADDING: f64 = 6.0;
/// Distance kept between the legend box and the plot area's edges, pixels.
const INSET: f64 = 6.0;

/// Width and height of the legend box of `entries`, pixels.
pub fn legend_size(entries: &[LegendEntry]) -> (f64, f64) {
    let widest = entries
        .iter()
        .map(|e| text_width(&e.label, LEGEND_SIZE))
        .fold(0.0, f64::max);
    (
        2.0 * LEGEND_PADDING + SWATCH + 6.0 + widest,
        2.0 * LEGEND_PADDING + LEGEND_LINE * entries.len() as f64,
    )
}

/// The first corner of `plot` where a legend of `size` meets none of `segments` (with 3 pixels
/// to spare) nor any of `keep_clear`; `None` when every corner is taken.
pub fn free_corner(
    plot: Rect,
    size: (f64, f64),
    segments: &[(Pixel, Pixel)],
    keep_clear: &[Rect],
) -> Option<Rect> {
    let (w, h) = size;
    let corners = [
        (plot.x1 - INSET - w, plot.y0 + INSET),
        (plot.x0 + INSET, plot.y0 + INSET),
        (plot.x1 - INSET - w, plot.y1 - INSET - h),
        (plot.x0 + INSET, plot.y1 - INSET - h),
    ];
    corners
        .into_iter()
        .map(|(x, y)| Rect::new(x, y, w, h))
        .find(|candidate| {
            plot.contains_rect(candidate)
                && !keep_clear.iter().any(|r| r.overlaps(candidate))
                && !segments
                    .iter()
                    .any(|(a, b)| candidate.inflated(3.0).meets_segment(*a, *b))
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_legend_goes_to_the_first_corner_the_curves_leave_free() {
        let plot = Rect::new(0.0, 0.0, 400.0, 300.0);
        // A curve along the top edge region: the upper corners are taken.
        let top = vec![((0.0, 20.0), (400.0, 20.0))];
        let placed = free_corner(plot, (80.0, 40.0), &top, &[]).expect("a free corner");
        assert!(
            placed.y0 > 150.0 && placed.x0 > 200.0,
            "lower right: {placed:?}"
        );
        // A curve crossing every corner: nowhere inside.
        let everywhere = vec![((0.0, 20.0), (400.0, 20.0)), ((0.0, 280.0), (400.0, 280.0))];
        assert_eq!(free_corner(plot, (80.0, 40.0), &everywhere, &[]), None);
    }
}
