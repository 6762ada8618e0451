//! The zero of a grazing test function on the near side of a hysteretic grazing, extrapolated
//! past the last orbit Newton's method reaches.
//!
//! Where the period map jumps at a grazing (a hysteretic contact law: the attachment's force
//! sets in at a finite value, or drops to zero at a release), the orbit on the side where the
//! surface is crossed has a map with a term in `sqrt(|g|)` on top of the finite jump (the
//! crossing time moves by `sqrt(|g|)` from the extremum's, `g` the extremum's value). Its
//! fixed point's extremum then vanishes quadratically, `g ~ -c (p_G - p)^2`: `s = sqrt(|g|)` is
//! linear in `p` (MODEL.md section 8). Newton's method stops converging a little short of the
//! grazing (its basin shrinks with `s`), so a location whose failed trials count as the far
//! side ends where Newton gives up, not at the zero. The zero is extrapolated instead, linearly
//! in `s`, from the near-side orbit nearest it and one with at least twice its `s` (at least as
//! far back as the distance extrapolated over, so that the rounding of `g` is not magnified);
//! the same extrapolation from the next such pair back gives its error (the curvature of `s`),
//! to which the rounding of `g` carried along the secant is added.
//!
//! On the other side (the orbit stays clear of the contact surface, or attached through the
//! release surface's maximum) the map is smooth and the extremum vanishes linearly, but
//! Newton's basin shrinks towards the grazing all the same (its iterates cross the surface and
//! meet the jump): where the location ends at a failed trial, the zero is extrapolated the same
//! way in `g` itself (measured on `biolever-sticky --a0 8`'s retract `pull-off` at 5.4765 nm:
//! `dg/dZ` about 2e-3, the last orbit 3e-8 to 1e-7 nm short of the zero).

/// How a test function vanishes at its zero, seen from the side its values come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Vanishing {
    /// `g ~ c (p_G - p)`: extrapolated in `g`.
    Linearly,
    /// `g ~ c (p_G - p)^2`: extrapolated in `sqrt(|g|)`.
    Quadratically,
}

impl Vanishing {
    /// The quantity linear in `p` near the zero: `|g|` or `sqrt(|g|)`.
    fn linear_in_p(self, g: f64) -> f64 {
        match self {
            Vanishing::Linearly => g.abs(),
            Vanishing::Quadratically => g.abs().sqrt(),
        }
    }

    /// How far a rounding `dg` of `g` moves [`Vanishing::linear_in_p`] at `g`: `dg`, or
    /// `sqrt(|g| + dg) - sqrt(|g|)`.
    fn rounding_in_s(self, g: f64, dg: f64) -> f64 {
        match self {
            Vanishing::Linearly => dg,
            Vanishing::Quadratically => (g.abs() + dg).sqrt() - g.abs().sqrt(),
        }
    }
}

/// The rounding of a test function, in units in the last place of the parameter (or of the
/// value, if larger): a grazing's extremum sums the parameter with terms that cancel it there
/// (the gap `Z + sum_i q_i`). Measured on `biolever-adhesive`'s retract `G1` (`Z` about 10 nm):
/// the zeros extrapolated under four step sizes scatter by 1.5e-10 nm, `g` by about 1e-14 nm
/// where `sqrt(-g)` is 2e-6 nm^(1/2).
const ROUNDING_ULPS: f64 = 4.0;

/// The extrapolated zero of a test function and its estimated error (parameter units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ExtrapolatedZero {
    /// The parameter where `|g|` or `sqrt(|g|)`, extrapolated linearly, reaches 0.
    pub parameter: f64,
    /// `|p_1 - p_2|` of the extrapolations from the nearest pair and from the next pair back
    /// (the whole distance extrapolated over where there is no such pair), plus twice the
    /// rounding of `g` ([`ROUNDING_ULPS`]) carried along the nearest pair's secant.
    pub error: f64,
    /// The parameter of the near-side orbit nearest the zero (the first of `points`).
    pub nearest: f64,
}

/// The zero of `s` (`|g|` or `sqrt(|g|)`), extrapolated linearly through `(p_near, g_near)`
/// and `(p_back, g_back)`.
fn zero_through(vanishing: Vanishing, near: (f64, f64), back: (f64, f64)) -> f64 {
    let (s_near, s_back) = (vanishing.linear_in_p(near.1), vanishing.linear_in_p(back.1));
    near.0 + s_near * (near.0 - back.0) / (s_back - s_near)
}

/// The first point of `points` after `from` whose `s` (`|g|` or `sqrt(|g|)`) is at least twice
/// that of `points[from]`: with `s` linear, at least as far from `points[from]` as that is from
/// the zero.
fn back_of(vanishing: Vanishing, points: &[(f64, f64)], from: usize) -> Option<usize> {
    let s = vanishing.linear_in_p(points[from].1);
    (from + 1..points.len()).find(|&j| vanishing.linear_in_p(points[j].1) >= 2.0 * s)
}

/// The point of `points` after the first with the largest `s` (`|g|` or `sqrt(|g|)`), if that
/// exceeds the first's: the pair for the extrapolation where no point has twice the first's
/// `s` (the branch crept towards the zero in steps so short that all the points kept lie
/// within a factor of 2 of it in `s`).
fn largest_back(vanishing: Vanishing, points: &[(f64, f64)]) -> Option<usize> {
    let s = vanishing.linear_in_p(points.first()?.1);
    (1..points.len())
        .filter(|&j| vanishing.linear_in_p(points[j].1) > s)
        .max_by(|&i, &j| {
            vanishing
                .linear_in_p(points[i].1)
                .total_cmp(&vanishing.linear_in_p(points[j].1))
        })
}

/// The zero of a test function that vanishes as `vanishing` says, from its values `(p, g)` on
/// orbits on one side of it (all of one sign), extrapolated in the direction `direction` (the
/// sign of `p_G - p`) as the module documentation says: from the point nearest the zero and
/// the first one back whose `s` (`|g|` or `sqrt(|g|)`) is at least twice as large, and for the
/// error from that one and the next such. Without a point of twice the `s`, from the one with
/// the largest `s`, with the whole distance extrapolated over as the error (no second pair).
/// `None` without a point of larger `s` or where the zero would lie behind the nearest
/// point.
pub(crate) fn extrapolated_zero(
    points: &[(f64, f64)],
    direction: f64,
    vanishing: Vanishing,
) -> Option<ExtrapolatedZero> {
    let mut sorted: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(p, g)| p.is_finite() && g.is_finite() && *g != 0.0)
        .collect();
    // Nearest the zero first.
    sorted.sort_by(|x, y| (direction * y.0).total_cmp(&(direction * x.0)));
    let nearest = *sorted.first()?;
    let back = back_of(vanishing, &sorted, 0).or_else(|| largest_back(vanishing, &sorted))?;
    let zero = zero_through(vanishing, nearest, sorted[back]);
    let distance = direction * (zero - nearest.0);
    if distance.is_nan() || distance < 0.0 || direction * (nearest.0 - sorted[back].0) <= 0.0 {
        return None;
    }
    let check =
        back_of(vanishing, &sorted, back).map(|j| zero_through(vanishing, sorted[back], sorted[j]));
    // The rounding of `g` carried into the zero along the pair's secant, twice (the
    // extrapolation spans up to the pair's spacing).
    let rounding = ROUNDING_ULPS * f64::EPSILON * nearest.0.abs().max(nearest.1.abs());
    let (s_near, s_back) = (
        vanishing.linear_in_p(nearest.1),
        vanishing.linear_in_p(sorted[back].1),
    );
    let slope = (s_back - s_near) / (sorted[back].0 - nearest.0).abs();
    let rounding_in_p = 2.0 * vanishing.rounding_in_s(nearest.1, rounding) / slope;
    let error = check.map_or(distance, |other| (other - zero).abs()) + rounding_in_p;
    Some(ExtrapolatedZero {
        parameter: zero,
        error,
        nearest: nearest.0,
    })
}

#[cfg(test)]
mod tests {
    use super::{extrapolated_zero, Vanishing};

    /// A quadratic `g = -(p_G - p)^2 (1 + (p_G - p))` sampled at shrinking distances: the zero
    /// within the curvature term of the extrapolation (about `distance^2`), and its error
    /// estimate bounding the actual error.
    #[test]
    fn extrapolates_the_zero_of_a_quadratic() {
        let p_g = 2.0;
        let g = |p: f64| -(p_g - p).powi(2) * (1.0 + (p_g - p));
        let points: Vec<(f64, f64)> = [1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 4e-6]
            .iter()
            .map(|d| (p_g - d, g(p_g - d)))
            .collect();
        let zero = extrapolated_zero(&points, 1.0, Vanishing::Quadratically).unwrap();
        let actual = (zero.parameter - p_g).abs();
        assert!(actual < 1e-9, "zero {} off by {actual}", zero.parameter);
        assert!(zero.error >= actual, "error {} below {actual}", zero.error);
        assert_eq!(zero.nearest, p_g - 4e-6);
    }

    /// A line `g = 0.5 (p - p_G) (1 + (p - p_G))` from above the zero, extrapolated downwards
    /// in `g`: within the curvature term, bounded by the error estimate.
    #[test]
    fn extrapolates_the_zero_of_a_line() {
        let p_g = -1.0;
        let g = |p: f64| 0.5 * (p - p_g) * (1.0 + (p - p_g));
        let points: Vec<(f64, f64)> = [2e-4, 1e-5, 3e-5, 1e-4, 3e-4, 1e-3]
            .iter()
            .map(|d| (p_g + d, g(p_g + d)))
            .collect();
        let zero = extrapolated_zero(&points, -1.0, Vanishing::Linearly).unwrap();
        let actual = (zero.parameter - p_g).abs();
        assert!(actual < 1e-9, "zero {} off by {actual}", zero.parameter);
        assert!(zero.error >= actual, "error {} below {actual}", zero.error);
        assert_eq!(zero.nearest, p_g + 1e-5);
    }

    /// Points within a factor of 2 of each other in `sqrt(|g|)` (a branch that crept towards
    /// the zero): the zero from the nearest point and the one of largest `sqrt(|g|)`, with an
    /// error that covers the whole distance extrapolated over.
    #[test]
    fn extrapolates_from_points_within_a_factor_of_two() {
        let p_g = 2.0;
        let g = |p: f64| -(p_g - p).powi(2) * (1.0 + (p_g - p));
        let points: Vec<(f64, f64)> = [1.5e-6, 1.2e-6, 1.0e-6, 9e-7, 8e-7]
            .iter()
            .map(|d| (p_g - d, g(p_g - d)))
            .collect();
        let zero = extrapolated_zero(&points, 1.0, Vanishing::Quadratically).unwrap();
        let actual = (zero.parameter - p_g).abs();
        assert!(actual < 1e-11, "zero {} off by {actual}", zero.parameter);
        assert!(zero.error >= 8e-7, "error {}", zero.error);
        assert_eq!(zero.nearest, p_g - 8e-7);
    }

    /// Values that do not fall towards the far side give no zero.
    #[test]
    fn no_zero_where_the_values_grow() {
        let points = [(1.0, -1e-6), (1.1, -2e-6)];
        assert!(extrapolated_zero(&points, 1.0, Vanishing::Quadratically).is_none());
        assert!(extrapolated_zero(&points, 1.0, Vanishing::Linearly).is_none());
    }
}
