//! Region names (`no impact`, `1 impact`, ...) placed inside the plot area so that none
//! covers a curve, another label, a marker or the legend, and each stays in its region: a name
//! is centred on one of its region's anchors (points inside the region, preferred first),
//! shifted by at most half its own size so that its box still holds the anchor. A box that
//! holds a point of the region and crosses no curve lies inside the region. Where no position
//! is free, the one crossing the fewest curve segments is taken.

use super::font::{text_box, Anchor};
use super::geometry::{Pixel, Rect};
use super::labels::Obstacles;

/// Font size of a region name, pixels.
pub const REGION_LABEL_SIZE: f64 = 13.0;

/// Clearance kept between a region name and anything else, pixels.
const CLEARANCE: f64 = 3.0;
/// Shifts of the box from centred on its anchor, in fractions of its width or height (the
/// anchor stays inside the box).
const SHIFTS: [f64; 5] = [0.0, -0.25, 0.25, -0.45, 0.45];

/// A region name in place: its text and its box (the text is centred in it).
#[derive(Debug, Clone)]
pub struct PlacedRegion {
    /// The text.
    pub text: String,
    /// The box the text occupies.
    pub bounds: Rect,
}

impl PlacedRegion {
    /// Where the text's baseline is centred.
    pub fn baseline(&self) -> Pixel {
        (
            0.5 * (self.bounds.x0 + self.bounds.x1),
            self.bounds.y1 - 0.25 * REGION_LABEL_SIZE,
        )
    }
}

/// The candidate boxes of `text` around `anchors`, preferred first.
fn candidates<'a>(text: &str, anchors: &'a [Pixel]) -> impl Iterator<Item = Rect> + 'a {
    let template = text_box(text, REGION_LABEL_SIZE, (0.0, 0.0), Anchor::Middle);
    let (w, h) = (template.width(), template.height());
    anchors.iter().flat_map(move |&(x, y)| {
        SHIFTS.into_iter().flat_map(move |fx| {
            SHIFTS
                .into_iter()
                .map(move |fy| Rect::new(x - 0.5 * w + fx * w, y - 0.5 * h + fy * h, w, h))
        })
    })
}

/// Place the names `(text, anchors in pixels)` in the given order, each clear of `obstacles`
/// and of the names placed before it; a name none of whose positions fits inside the plot
/// area is left out.
pub fn place_regions(
    names: &[(String, Vec<Pixel>)],
    obstacles: Obstacles<'_>,
) -> Vec<PlacedRegion> {
    let mut placed: Vec<PlacedRegion> = Vec::new();
    for (text, anchors) in names {
        let mut best: Option<(usize, Rect)> = None;
        for candidate in candidates(text, anchors) {
            let zone = candidate.inflated(CLEARANCE);
            let blocked = !obstacles.bounds.contains_rect(&candidate)
                || obstacles.boxes.iter().any(|b| b.overlaps(&zone))
                || placed.iter().any(|p| p.bounds.overlaps(&zone));
            if blocked {
                continue;
            }
            let crossings = obstacles
                .segments
                .iter()
                .filter(|(a, b)| zone.meets_segment(*a, *b))
                .count();
            if best.as_ref().is_none_or(|(fewest, _)| crossings < *fewest) {
                best = Some((crossings, candidate));
            }
            if crossings == 0 {
                break;
            }
        }
        if let Some((_, bounds)) = best {
            placed.push(PlacedRegion {
                text: text.clone(),
                bounds,
            });
        }
    }
    placed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_name_moves_along_its_band_to_a_free_anchor_and_names_do_not_overlap() {
        // A band between two rising lines 70 px apart; the first anchor is crossed by a third,
        // steep curve, the second is free. A second name asked at the same anchors must not
        // cover the first.
        let lower = ((0.0, 300.0), (400.0, 100.0));
        let upper = ((0.0, 230.0), (400.0, 30.0));
        let steep = ((200.0, 0.0), (200.0, 300.0));
        let segments = vec![lower, upper, steep];
        let legend = Rect::new(300.0, 200.0, 90.0, 40.0);
        let anchors = vec![(200.0, 165.0), (100.0, 215.0), (300.0, 115.0)];
        let names = vec![
            (String::from("1 impact"), anchors.clone()),
            (String::from("2 impacts"), anchors.clone()),
        ];
        let bounds = Rect::new(0.0, 0.0, 400.0, 300.0);
        let placed = place_regions(
            &names,
            Obstacles {
                bounds,
                segments: &segments,
                boxes: &[legend],
            },
        );
        assert_eq!(placed.len(), 2);
        assert!(!placed[0].bounds.overlaps(&placed[1].bounds));
        for p in &placed {
            for (a, b) in &segments {
                assert!(!p.bounds.meets_segment(*a, *b), "{p:?} crosses a curve");
            }
            assert!(!p.bounds.overlaps(&legend), "{p:?}");
            assert!(bounds.contains_rect(&p.bounds));
            // Inside the band: its centre lies between the two lines.
            let (x, y) = (
                0.5 * (p.bounds.x0 + p.bounds.x1),
                0.5 * (p.bounds.y0 + p.bounds.y1),
            );
            assert!(y < 300.0 - 0.5 * x && y > 230.0 - 0.5 * x, "{p:?}");
        }
    }
}
