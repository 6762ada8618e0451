//! Trigonometric polynomials `p(theta) = c + sum_{k=1}^{K} (a_k cos k theta + b_k sin k theta)`
//! and their global minimum over a period: the lowest gap of a free orbit (first contact G1,
//! MODEL.md section 5) for a drive at one frequency (K = 1, in closed form) or at several
//! harmonics of it (K > 1, by sampling and Newton refinement).

use std::f64::consts::PI;

/// `p(theta) = constant + sum_k (a_k cos k theta + b_k sin k theta)`; `harmonics[k-1] = [a_k, b_k]`.
#[derive(Debug, Clone, PartialEq)]
pub struct TrigonometricPolynomial {
    /// The constant term `c`.
    pub constant: f64,
    /// `[a_k, b_k]` for k = 1..K.
    pub harmonics: Vec<[f64; 2]>,
}

/// Samples per harmonic order used to bracket the minima when K > 1.
const SAMPLES_PER_ORDER: usize = 64;

impl TrigonometricPolynomial {
    /// The value `p(theta)` and its first two derivatives.
    pub fn evaluate(&self, theta: f64) -> [f64; 3] {
        let mut value = self.constant;
        let mut first = 0.0;
        let mut second = 0.0;
        for (index, [a, b]) in self.harmonics.iter().enumerate() {
            let k = (index + 1) as f64;
            let (sin, cos) = (k * theta).sin_cos();
            value += a * cos + b * sin;
            first += k * (b * cos - a * sin);
            second -= k * k * (a * cos + b * sin);
        }
        [value, first, second]
    }

    /// The global minimum over one period: `(theta, p(theta))` with `theta` in `[0, 2 pi)`.
    ///
    /// With only the first harmonic, `p = c + C cos(theta - psi)`, `C = hypot(a_1, b_1)`,
    /// `psi = atan2(b_1, a_1)`, so the minimum is `c - C` at `theta = psi + pi` (exact).
    /// Otherwise every sampled local minimum is refined by Newton's method on `p'` inside its
    /// bracket (bisection when Newton leaves it), and the lowest is returned.
    pub fn minimum(&self) -> (f64, f64) {
        let order = self
            .harmonics
            .iter()
            .rposition(|&[a, b]| a != 0.0 || b != 0.0)
            .map_or(0, |index| index + 1);
        match order {
            0 => (0.0, self.constant),
            1 => {
                let [a, b] = self.harmonics[0];
                let theta = (b.atan2(a) + PI).rem_euclid(2.0 * PI);
                (theta, self.constant - a.hypot(b))
            }
            _ => self.sampled_minimum(order),
        }
    }

    fn sampled_minimum(&self, order: usize) -> (f64, f64) {
        let count = SAMPLES_PER_ORDER * order;
        let step = 2.0 * PI / count as f64;
        let mut best = (0.0, f64::INFINITY);
        for index in 0..count {
            let left = index as f64 * step;
            let right = left + step;
            let slope_left = self.evaluate(left)[1];
            let slope_right = self.evaluate(right)[1];
            if slope_left < 0.0 && slope_right >= 0.0 {
                let theta = self.refine_minimum(left, right);
                let value = self.evaluate(theta)[0];
                if value < best.1 {
                    best = (theta.rem_euclid(2.0 * PI), value);
                }
            }
        }
        best
    }

    /// Zero of `p'` in `[left, right]` with `p'(left) < 0 <= p'(right)`: safeguarded Newton.
    fn refine_minimum(&self, mut left: f64, mut right: f64) -> f64 {
        let mut theta = 0.5 * (left + right);
        for _ in 0..100 {
            let [_, slope, curvature] = self.evaluate(theta);
            if slope < 0.0 {
                left = theta;
            } else {
                right = theta;
            }
            let newton = theta - slope / curvature;
            let next = if curvature > 0.0 && newton > left && newton < right {
                newton
            } else {
                0.5 * (left + right)
            };
            if (next - theta).abs() <= 4.0 * f64::EPSILON * theta.abs().max(1.0) {
                return next;
            }
            theta = next;
        }
        theta
    }
}
