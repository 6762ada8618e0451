//! The zero of a grazing test function that vanishes quadratically on the near side of a
//! hysteretic grazing, extrapolated past the last orbit Newton's method reaches.
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
//! the same extrapolation from the next such pair back gives its error (the curvature of `s`
//! and the rounding of `g`).

/// The extrapolated zero of a test function and its estimated error (parameter units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ExtrapolatedZero {
    /// The parameter where `sqrt(|g|)`, extrapolated linearly, reaches 0.
    pub parameter: f64,
    /// `|p_1 - p_2|` of the extrapolations from the nearest pair and from the next pair back;
    /// the whole distance extrapolated over where there is no such pair.
    pub error: f64,
    /// The parameter of the near-side orbit nearest the zero (the first of `points`).
    pub nearest: f64,
}

/// The zero of `s = sqrt(|g|)`, extrapolated linearly through `(p_near, g_near)` and
/// `(p_back, g_back)`.
fn zero_through(near: (f64, f64), back: (f64, f64)) -> f64 {
    let (s_near, s_back) = (near.1.abs().sqrt(), back.1.abs().sqrt());
    near.0 + s_near * (near.0 - back.0) / (s_back - s_near)
}

/// The first point of `points` after `from` whose `sqrt(|g|)` is at least twice that of
/// `points[from]`: with `s` linear, at least as far from `points[from]` as that is from the zero.
fn back_of(points: &[(f64, f64)], from: usize) -> Option<usize> {
    let s = points[from].1.abs().sqrt();
    (from + 1..points.len()).find(|&j| points[j].1.abs().sqrt() >= 2.0 * s)
}

/// The zero of a test function that vanishes quadratically, `g ~ -c (p_G - p)^2`, from its
/// values `(p, g)` on orbits on one side of it (all of one sign), extrapolated in the direction
/// `direction` (the sign of `p_G - p`) as the module documentation says: from the point
/// nearest the zero and the first one back whose `sqrt(|g|)` is at least twice as large, and
/// for the error from that one and the next such. `None` without such a pair or where the
/// zero would lie behind the nearest point.
pub(crate) fn square_root_zero(points: &[(f64, f64)], direction: f64) -> Option<ExtrapolatedZero> {
    let mut sorted: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(p, g)| p.is_finite() && g.is_finite() && *g != 0.0)
        .collect();
    // Nearest the zero first.
    sorted.sort_by(|x, y| (direction * y.0).total_cmp(&(direction * x.0)));
    let nearest = *sorted.first()?;
    let back = back_of(&sorted, 0)?;
    let zero = zero_through(nearest, sorted[back]);
    let distance = direction * (zero - nearest.0);
    if distance.is_nan() || distance < 0.0 || direction * (nearest.0 - sorted[back].0) <= 0.0 {
        return None;
    }
    let check = back_of(&sorted, back).map(|j| zero_through(sorted[back], sorted[j]));
    let error = check.map_or(distance, |other| (other - zero).abs());
    Some(ExtrapolatedZero {
        parameter: zero,
        error,
        nearest: nearest.0,
    })
}

#[cfg(test)]
mod tests {
    use super::square_root_zero;

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
        let zero = square_root_zero(&points, 1.0).unwrap();
        let actual = (zero.parameter - p_g).abs();
        assert!(actual < 1e-9, "zero {} off by {actual}", zero.parameter);
        assert!(zero.error >= actual, "error {} below {actual}", zero.error);
        assert_eq!(zero.nearest, p_g - 4e-6);
    }

    /// Values that do not fall towards the far side give no zero.
    #[test]
    fn no_zero_where_the_values_grow() {
        let points = [(1.0, -1e-6), (1.1, -2e-6)];
        assert!(square_root_zero(&points, 1.0).is_none());
    }
}
