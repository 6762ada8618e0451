//! Thinning a series to the resolution of the figure, so that a sweep of a million cycles
//! draws as a few thousand points without losing a spike: a polyline keeps, of each run of
//! consecutive points in one pixel column, the first, the lowest, the highest and the last;
//! dots keep one point per pixel.

use std::collections::HashSet;

use super::geometry::Pixel;

/// The polyline through `points` (pixels) reduced to at most four points per run of
/// consecutive points in one pixel column (the first, the extremes in `y`, the last, in their
/// original order): drawn at one pixel per column it covers the same pixels.
pub fn decimate_polyline(points: &[Pixel]) -> Vec<Pixel> {
    let mut kept = Vec::new();
    let mut start = 0;
    while start < points.len() {
        let column = points[start].0.floor();
        let mut end = start + 1;
        while end < points.len() && points[end].0.floor() == column {
            end += 1;
        }
        let run = &points[start..end];
        let (mut low, mut high) = (0, 0);
        for (i, p) in run.iter().enumerate() {
            if p.1 < run[low].1 {
                low = i;
            }
            if p.1 > run[high].1 {
                high = i;
            }
        }
        let mut indices = vec![0, low, high, run.len() - 1];
        indices.sort_unstable();
        indices.dedup();
        kept.extend(indices.into_iter().map(|i| run[i]));
        start = end;
    }
    kept
}

/// Of `points` (pixels), the first in each pixel square.
pub fn decimate_dots(points: &[Pixel]) -> Vec<Pixel> {
    let mut seen = HashSet::new();
    points
        .iter()
        .copied()
        .filter(|p| seen.insert((p.0.floor() as i64, p.1.floor() as i64)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spike_survives_and_each_column_keeps_at_most_four_points() {
        // 100 000 points over 100 pixel columns, a smooth wave with one spike of one sample.
        let n = 100_000;
        let mut points: Vec<Pixel> = (0..n)
            .map(|i| {
                let x = i as f64 * 100.0 / n as f64;
                (x, 50.0 + 10.0 * (x / 10.0).sin())
            })
            .collect();
        points[54_321].1 = 400.0;
        let kept = decimate_polyline(&points);
        assert!(kept.len() <= 4 * 100, "{} points kept", kept.len());
        assert!(kept.contains(&points[54_321]), "the spike is kept");
        assert_eq!(kept.first(), points.first());
        assert_eq!(kept.last(), points.last());
        // The kept points stay in their original order.
        assert!(kept.windows(2).all(|w| w[0].0 <= w[1].0));
    }

    #[test]
    fn dots_keep_one_point_per_pixel() {
        let points: Vec<Pixel> = (0..1000).map(|i| (i as f64 * 0.01, 3.5)).collect();
        let kept = decimate_dots(&points);
        assert_eq!(kept.len(), 10);
    }
}
