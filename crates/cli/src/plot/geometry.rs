//! Pixel geometry of a figure: axis-aligned rectangles and the segment tests that keep labels
//! and legends off the curves. Pixel coordinates have `y` growing downwards, as in SVG.

/// A point in pixels.
pub type Pixel = (f64, f64);

/// An axis-aligned rectangle in pixels, `x0 <= x1`, `y0 <= y1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rect {
    /// Left edge.
    pub x0: f64,
    /// Top edge.
    pub y0: f64,
    /// Right edge.
    pub x1: f64,
    /// Bottom edge.
    pub y1: f64,
}

impl Rect {
    /// The rectangle with top-left corner `(x, y)`, `width` wide and `height` tall.
    pub fn new(x: f64, y: f64, width: f64, height: f64) -> Self {
        Self {
            x0: x,
            y0: y,
            x1: x + width,
            y1: y + height,
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> f64 {
        self.x1 - self.x0
    }

    /// Height in pixels.
    pub fn height(&self) -> f64 {
        self.y1 - self.y0
    }

    /// The rectangle grown by `margin` pixels on every side.
    pub fn inflated(&self, margin: f64) -> Self {
        Self {
            x0: self.x0 - margin,
            y0: self.y0 - margin,
            x1: self.x1 + margin,
            y1: self.y1 + margin,
        }
    }

    /// Whether the two rectangles share interior points (touching edges do not count).
    pub fn overlaps(&self, other: &Rect) -> bool {
        self.x0 < other.x1 && other.x0 < self.x1 && self.y0 < other.y1 && other.y0 < self.y1
    }

    /// Whether `other` lies inside this rectangle (edges included).
    pub fn contains_rect(&self, other: &Rect) -> bool {
        other.x0 >= self.x0 && other.x1 <= self.x1 && other.y0 >= self.y0 && other.y1 <= self.y1
    }

    /// Whether the point lies inside (edges included).
    pub fn contains(&self, (x, y): Pixel) -> bool {
        x >= self.x0 && x <= self.x1 && y >= self.y0 && y <= self.y1
    }

    /// Whether the segment from `a` to `b` has a point inside the rectangle (Liang-Barsky
    /// clipping of the segment's parameter range `[0, 1]` against the four edges).
    pub fn meets_segment(&self, a: Pixel, b: Pixel) -> bool {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let mut low = 0.0_f64;
        let mut high = 1.0_f64;
        for (p, q) in [
            (-dx, a.0 - self.x0),
            (dx, self.x1 - a.0),
            (-dy, a.1 - self.y0),
            (dy, self.y1 - a.1),
        ] {
            if p == 0.0 {
                if q < 0.0 {
                    return false;
                }
            } else {
                let t = q / p;
                if p < 0.0 {
                    low = low.max(t);
                } else {
                    high = high.min(t);
                }
                if low > high {
                    return false;
                }
            }
        }
        true
    }

    /// The point of the rectangle's boundary (or inside) nearest to `p`.
    pub fn nearest_point(&self, (x, y): Pixel) -> Pixel {
        (x.clamp(self.x0, self.x1), y.clamp(self.y0, self.y1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn segments_meet_a_rectangle_only_where_they_pass_through_it() {
        let r = Rect::new(10.0, 10.0, 10.0, 10.0);
        assert!(
            r.meets_segment((0.0, 15.0), (30.0, 15.0)),
            "straight through"
        );
        assert!(r.meets_segment((12.0, 12.0), (13.0, 13.0)), "wholly inside");
        assert!(!r.meets_segment((0.0, 0.0), (30.0, 5.0)), "above");
        assert!(
            !r.meets_segment((0.0, 25.0), (25.0, 35.0)),
            "below the corner"
        );
        assert!(
            r.meets_segment((5.0, 25.0), (25.0, 5.0)),
            "across a corner region"
        );
        assert!(!r.meets_segment((0.0, 0.0), (5.0, 5.0)), "stops short");
        assert!(
            r.meets_segment((15.0, 15.0), (15.0, 15.0)),
            "a point inside"
        );
        assert!(
            !r.meets_segment((5.0, 15.0), (5.0, 15.0)),
            "a point outside"
        );
    }

    #[test]
    fn overlap_excludes_touching_edges() {
        let a = Rect::new(0.0, 0.0, 10.0, 10.0);
        assert!(!a.overlaps(&Rect::new(10.0, 0.0, 5.0, 5.0)));
        assert!(a.overlaps(&Rect::new(9.0, 9.0, 5.0, 5.0)));
        assert!(a.contains_rect(&Rect::new(1.0, 1.0, 2.0, 2.0)));
    }
}
