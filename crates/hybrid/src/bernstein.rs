//! Range bounds of a polynomial on `[0, 1]` from its Bernstein coefficients.
//!
//! A polynomial of degree `d` written in the Bernstein basis of `[0, 1]`,
//! `p(theta) = sum_i b_i C(d, i) theta^i (1 - theta)^(d - i)`, lies between the smallest and the
//! largest `b_i` on the whole interval (the basis is a partition of unity of non-negative
//! functions), and `b_0 = p(0)`, `b_d = p(1)`. From the power-basis coefficients `a_j`,
//! `b_i = sum_{j <= i} [C(i, j) / C(d, j)] a_j` (Farouki and Rajan, *On the numerical condition
//! of polynomials in Bernstein form*, 1987). The solver uses the bound to prove, from a
//! switching function's interpolant over a step, that the step holds no crossing and no
//! extremum, without sampling it.

/// The Bernstein coefficients on `[0, 1]` of the polynomial with power-basis coefficients
/// `power` (`power[j]` multiplies `theta^j`; degree `D - 1`). The tests check the conversion on
/// the whole array; the bounds below compute the coefficients one at a time, stopping early.
#[cfg(test)]
fn bernstein_coefficients<const D: usize>(power: &[f64; D]) -> [f64; D] {
    let mut bernstein = [0.0; D];
    for (i, b) in bernstein.iter_mut().enumerate() {
        *b = bernstein_coefficient(power, i);
    }
    bernstein
}

/// Bernstein coefficient `i` of the polynomial with power-basis coefficients `power` (degree
/// `D - 1`): `sum_{j <= i} [C(i, j) / C(d, j)] a_j`, the factors from [`conversion_factors`].
#[inline]
fn bernstein_coefficient<const D: usize>(power: &[f64; D], i: usize) -> f64 {
    let factors = const { &conversion_factors::<D>() };
    factors[i][..=i]
        .iter()
        .zip(power)
        .fold(0.0, |sum, (factor, a)| sum + factor * a)
}

/// The factors `C(i, j) / C(d, j)` (`d = D - 1`, `j <= i`; zero above the diagonal) of the
/// power-to-Bernstein conversion, each built up from `j = 0` (factor 1) as
/// `prod_{m=1}^{j} (i + 1 - m) / (d + 1 - m)`, at compile time.
const fn conversion_factors<const D: usize>() -> [[f64; D]; D] {
    let mut factors = [[0.0; D]; D];
    let degree = D - 1;
    let mut i = 0;
    while i < D {
        let mut ratio = 1.0;
        factors[i][0] = 1.0;
        let mut j = 1;
        while j <= i {
            ratio *= (i + 1 - j) as f64 / (degree + 1 - j) as f64;
            factors[i][j] = ratio;
            j += 1;
        }
        i += 1;
    }
    factors
}

/// The bound on the rounding of [`bernstein_coefficient`]: each coefficient is a sum of at most
/// `D` products of `|a_j|` with factors in `[0, 1]` each rounded a few times, so its error is
/// below this multiple of `EPSILON * sum_j |a_j|` (generously).
const ROUNDING_FACTOR: f64 = 1024.0 * f64::EPSILON;

/// Whether the polynomial with power-basis coefficients `power` is proven, from its Bernstein
/// coefficients, to stay above `floor` on all of `[0, 1]`, with a margin for the rounding of
/// the coefficients.
pub(crate) fn stays_above<const D: usize>(power: &[f64; D], floor: f64) -> bool {
    let margin = rounding_margin(power);
    // The constant term dominating the rest proves it without the conversion (every Bernstein
    // coefficient is at least `a_0 - sum_{j>0} |a_j|`).
    if power[0] - spread(power) > floor + margin {
        return true;
    }
    (0..D).all(|i| bernstein_coefficient(power, i) > floor + margin)
}

/// The sign (`1` or `-1`) the polynomial with power-basis coefficients `power` is proven to
/// keep strictly on all of `[0, 1]`, if its Bernstein coefficients prove one; `None` if not.
#[inline(always)]
pub(crate) fn strict_sign<const D: usize>(power: &[f64; D]) -> Option<f64> {
    let margin = rounding_margin(power);
    // A dominant constant term proves the sign without the conversion (every Bernstein
    // coefficient lies within `sum_{j>0} |a_j|` of `a_0`).
    if power[0].abs() - spread(power) > margin {
        return Some(power[0].signum());
    }
    // Coefficient by coefficient, stopping at the first that leaves `b_0`'s side.
    let sign = power[0].signum();
    (0..D)
        .all(|i| sign * bernstein_coefficient(power, i) > margin)
        .then_some(sign)
}

/// `sum_{j>0} |a_j|`: how far the polynomial can move from its constant term on `[0, 1]`.
fn spread<const D: usize>(power: &[f64; D]) -> f64 {
    power[1..].iter().map(|a| a.abs()).sum()
}

fn rounding_margin<const D: usize>(power: &[f64; D]) -> f64 {
    ROUNDING_FACTOR * power.iter().map(|a| a.abs()).sum::<f64>()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn evaluate(power: &[f64], theta: f64) -> f64 {
        power.iter().rev().fold(0.0, |acc, &a| acc * theta + a)
    }

    /// The Bernstein form reproduces the polynomial (evaluated by de Casteljau's algorithm,
    /// independent of the conversion's formula) and its end values.
    #[test]
    fn bernstein_form_reproduces_the_polynomial() {
        let power = [0.3, -2.0, 5.5, 1.25, -7.0, 3.0, 0.5, -1.0];
        let bernstein = bernstein_coefficients(&power);
        assert!((bernstein[0] - evaluate(&power, 0.0)).abs() < 1e-15);
        assert!((bernstein[7] - evaluate(&power, 1.0)).abs() < 1e-13);
        for theta in [0.1, 0.37, 0.5, 0.83] {
            let mut points = bernstein;
            for level in 1..points.len() {
                for i in 0..points.len() - level {
                    points[i] = (1.0 - theta) * points[i] + theta * points[i + 1];
                }
            }
            assert!(
                (points[0] - evaluate(&power, theta)).abs() < 1e-13,
                "theta {theta}: {} vs {}",
                points[0],
                evaluate(&power, theta)
            );
        }
    }

    /// The range bound holds and is usable: a parabola with its minimum 0.01 above the floor
    /// inside the interval is proven above a floor 0.1 below it but not above one just under
    /// its minimum (the bound is not tight), and never above a floor it dips below.
    #[test]
    fn stays_above_is_conservative() {
        // (theta - 0.37)^2 + m, degree 2 padded to 8 coefficients.
        let parabola = |m: f64| [0.37 * 0.37 + m, -0.74, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert!(stays_above(&parabola(0.01), -0.5));
        assert!(!stays_above(&parabola(0.01), 0.009));
        assert!(!stays_above(&parabola(-1e-9), 0.0));
        // Brute force: wherever the bound claims clearance, every point of a fine grid agrees.
        for m in [-0.2, -0.05, 0.0, 0.02, 0.3] {
            for floor in [-0.5, -0.1, 0.0, 0.01, 0.1] {
                if stays_above(&parabola(m), floor) {
                    let lowest = (0..=10_000)
                        .map(|i| evaluate(&parabola(m), i as f64 / 10_000.0))
                        .fold(f64::INFINITY, f64::min);
                    assert!(lowest > floor, "m {m}, floor {floor}");
                }
            }
        }
    }

    /// A strictly monotone cubic's derivative is proven of one sign; a derivative with a zero
    /// inside is not.
    #[test]
    fn strict_sign_of_a_derivative() {
        assert_eq!(strict_sign(&[1.0, 0.5, 0.3]), Some(1.0));
        assert_eq!(strict_sign(&[-1.0, -0.5, -0.3]), Some(-1.0));
        // (theta - 0.5) changes sign inside.
        assert_eq!(strict_sign(&[-0.5, 1.0, 0.0]), None);
        // theta^2 touches zero at the end: not strict.
        assert_eq!(strict_sign(&[0.0, 0.0, 1.0]), None);
    }
}
