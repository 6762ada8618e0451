//! Special-point labels placed so that none covers another label, a marker, the legend or a
//! curve: each label tries positions around its marker at growing distances, in 16 directions,
//! and takes the first free one; a label set off from its marker gets a leader line back to it.
//! Two special points a few thousandths of a nanometre apart (a grazing and a fold) thus get
//! labels on either side, each tied to its own dot.

use super::font::{text_box, Anchor};
use super::geometry::{Pixel, Rect};
use super::layout::MARKER_LABEL_SIZE;

/// Radius of a special-point marker, pixels.
pub const MARKER_RADIUS: f64 = 3.5;

/// Gaps tried between a marker and its label, pixels.
const DISTANCES: [f64; 11] = [
    4.0, 10.0, 18.0, 28.0, 40.0, 56.0, 76.0, 100.0, 130.0, 170.0, 220.0,
];
/// Directions tried, counted in sixteenths of a turn from "right", upper right first.
const DIRECTIONS: [i32; 16] = [-2, 2, -6, 6, -4, 4, 0, 8, -1, -3, 1, 3, -5, -7, 5, 7];
/// Clearance kept between a label and anything else, pixels.
const CLEARANCE: f64 = 3.0;
/// A label farther than this from its marker's centre gets a leader line, pixels.
const LEADER_FROM: f64 = MARKER_RADIUS + 6.0;

/// A label in place.
#[derive(Debug, Clone)]
pub struct PlacedLabel {
    /// The text.
    pub text: String,
    /// The marker's centre.
    pub at: Pixel,
    /// The box the text occupies.
    pub bounds: Rect,
    /// Where the text starts: left end of its baseline.
    pub baseline: Pixel,
    /// A line from the marker's edge to the label's box, when the label is set off.
    pub leader: Option<(Pixel, Pixel)>,
}

/// What labels must stay clear of.
#[derive(Debug, Clone, Copy)]
pub struct Obstacles<'a> {
    /// Labels stay inside this rectangle (the plot area).
    pub bounds: Rect,
    /// Curve segments (a dot is a segment of zero length).
    pub segments: &'a [(Pixel, Pixel)],
    /// Other boxes (the legend).
    pub boxes: &'a [Rect],
}

/// Place the labels `(text, marker centre)` in order of their markers from left to right.
pub fn place_labels(markers: &[(String, Pixel)], obstacles: Obstacles<'_>) -> Vec<PlacedLabel> {
    let dots: Vec<Rect> = markers
        .iter()
        .map(|(_, (x, y))| {
            Rect::new(
                x - MARKER_RADIUS,
                y - MARKER_RADIUS,
                2.0 * MARKER_RADIUS,
                2.0 * MARKER_RADIUS,
            )
        })
        .collect();
    let mut order: Vec<usize> = (0..markers.len()).collect();
    order.sort_by(|&a, &b| markers[a].1 .0.total_cmp(&markers[b].1 .0));
    let mut placed: Vec<Option<PlacedLabel>> = vec![None; markers.len()];
    let mut taken: Vec<PlacedLabel> = Vec::new();
    for index in order {
        let (text, at) = &markers[index];
        let label = best_position(text, *at, &obstacles, &dots, &taken);
        taken.push(label.clone());
        placed[index] = Some(label);
    }
    placed.into_iter().flatten().collect()
}

/// The candidate positions of a label of `text` at marker `at`, nearest first.
fn candidates(text: &str, at: Pixel) -> impl Iterator<Item = PlacedLabel> + '_ {
    let template = text_box(text, MARKER_LABEL_SIZE, (0.0, 0.0), Anchor::Start);
    let (w, h) = (template.width(), template.height());
    DISTANCES.into_iter().flat_map(move |gap| {
        DIRECTIONS.into_iter().map(move |sixteenth| {
            let angle = f64::from(sixteenth) * std::f64::consts::PI / 8.0;
            let (c, s) = (angle.cos(), angle.sin());
            let reach = MARKER_RADIUS + gap;
            let centre = (at.0 + c * (reach + 0.5 * w), at.1 + s * (reach + 0.5 * h));
            let bounds = Rect::new(centre.0 - 0.5 * w, centre.1 - 0.5 * h, w, h);
            let baseline = (bounds.x0, bounds.y0 - template.y0);
            let nearest = bounds.nearest_point(at);
            let distance = (nearest.0 - at.0).hypot(nearest.1 - at.1);
            let leader = (distance > LEADER_FROM).then(|| {
                let unit = ((nearest.0 - at.0) / distance, (nearest.1 - at.1) / distance);
                (
                    (at.0 + unit.0 * MARKER_RADIUS, at.1 + unit.1 * MARKER_RADIUS),
                    nearest,
                )
            });
            PlacedLabel {
                text: text.to_string(),
                at,
                bounds,
                baseline,
                leader,
            }
        })
    })
}

/// How many curve segments cross a candidate (with the clearance).
fn curve_crossings(candidate: &PlacedLabel, segments: &[(Pixel, Pixel)]) -> usize {
    let zone = candidate.bounds.inflated(CLEARANCE);
    segments
        .iter()
        .filter(|(a, b)| zone.meets_segment(*a, *b))
        .count()
}

/// Whether a candidate stays inside the plot area and clear of the legend, every marker and
/// every label placed so far (boxes and leader lines both ways).
fn clear_of_labels(
    candidate: &PlacedLabel,
    obstacles: &Obstacles<'_>,
    dots: &[Rect],
    taken: &[PlacedLabel],
) -> bool {
    let zone = candidate.bounds.inflated(CLEARANCE);
    obstacles.bounds.contains_rect(&candidate.bounds)
        && !obstacles.boxes.iter().any(|b| b.overlaps(&zone))
        && !dots.iter().any(|d| d.overlaps(&zone))
        && !taken.iter().any(|other| {
            other.bounds.inflated(CLEARANCE).overlaps(&zone)
                || other.leader.is_some_and(|(a, b)| zone.meets_segment(a, b))
                || candidate
                    .leader
                    .is_some_and(|(a, b)| other.bounds.meets_segment(a, b))
        })
}

/// The nearest candidate clear of everything; else the one clear of labels, markers and
/// legend that crosses the fewest curve segments; else the nearest inside the plot area.
fn best_position(
    text: &str,
    at: Pixel,
    obstacles: &Obstacles<'_>,
    dots: &[Rect],
    taken: &[PlacedLabel],
) -> PlacedLabel {
    let mut fallback: Option<(usize, PlacedLabel)> = None;
    for candidate in candidates(text, at) {
        if !clear_of_labels(&candidate, obstacles, dots, taken) {
            continue;
        }
        let crossings = curve_crossings(&candidate, obstacles.segments);
        if crossings == 0 {
            return candidate;
        }
        if fallback.as_ref().is_none_or(|(best, _)| crossings < *best) {
            fallback = Some((crossings, candidate));
        }
    }
    if let Some((_, label)) = fallback {
        return label;
    }
    candidates(text, at)
        .find(|c| obstacles.bounds.contains_rect(&c.bounds))
        .unwrap_or_else(|| candidates(text, at).next().expect("a first candidate"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_markers_a_pixel_apart_get_separate_labels_off_the_curve() {
        // A grazing and a fold 0.003 nm apart land on nearly the same pixel of a curve.
        let curve: Vec<(Pixel, Pixel)> = (0..100)
            .map(|i| {
                let x = f64::from(i) * 4.0;
                ((x, 200.0 - 0.3 * x), (x + 4.0, 200.0 - 0.3 * (x + 4.0)))
            })
            .collect();
        let markers = vec![
            (String::from("G1"), (200.0, 140.0)),
            (String::from("fold"), (201.0, 139.7)),
        ];
        let labels = place_labels(
            &markers,
            Obstacles {
                bounds: Rect::new(0.0, 0.0, 400.0, 300.0),
                segments: &curve,
                boxes: &[],
            },
        );
        assert_eq!(labels.len(), 2);
        assert!(!labels[0].bounds.overlaps(&labels[1].bounds));
        for label in &labels {
            assert_eq!(curve_crossings(label, &curve), 0, "{label:?}");
        }
        for label in &labels {
            let near = label.bounds.nearest_point(label.at);
            let distance = (near.0 - label.at.0).hypot(near.1 - label.at.1);
            assert!(distance < 60.0, "{label:?} stays near its marker");
            // A label set off by more than a few pixels is tied to its marker.
            assert_eq!(label.leader.is_some(), distance > LEADER_FROM);
        }
    }
}
