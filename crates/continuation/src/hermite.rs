//! The cubic Hermite basis, shared by the branch's cubic predictor ([`crate::branch`]) and any
//! predictor of a curve from two points with their slopes.

/// The cubic Hermite basis at `s`: `[h00, h10, h01, h11]` with `h00 = 2s^3 - 3s^2 + 1`,
/// `h10 = s^3 - 2s^2 + s`, `h01 = -2s^3 + 3s^2`, `h11 = s^3 - s^2`. The cubic through points
/// `p0` (at `s = 0`) and `p1` (at `s = 1`) with slopes `m0`, `m1` per unit of a parameter
/// spanning the interval `h` is `h00 p0 + h10 h m0 + h01 p1 + h11 h m1`; `s` outside `[0, 1]`
/// extrapolates. Dimensionless.
pub fn hermite_basis(s: f64) -> [f64; 4] {
    let (s2, s3) = (s * s, s * s * s);
    [
        2.0 * s3 - 3.0 * s2 + 1.0,
        s3 - 2.0 * s2 + s,
        -2.0 * s3 + 3.0 * s2,
        s3 - s2,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The basis reproduces every cubic: `p(s) = 1 + 2s - s^2 + 4s^3` from its values and
    /// slopes at 0 and 1 (h = 1), inside and outside the interval.
    #[test]
    fn reproduces_a_cubic() {
        let p = |s: f64| 1.0 + s * (2.0 + s * (-1.0 + 4.0 * s));
        let dp = |s: f64| 2.0 + s * (-2.0 + 12.0 * s);
        for s in [-2.0, -0.5, 0.0, 0.3, 1.0, 2.5] {
            let [h00, h10, h01, h11] = hermite_basis(s);
            let value = h00 * p(0.0) + h10 * dp(0.0) + h01 * p(1.0) + h11 * dp(1.0);
            assert!(
                (value - p(s)).abs() <= 1e-12 * (1.0 + p(s).abs()),
                "s = {s}"
            );
        }
    }
}
