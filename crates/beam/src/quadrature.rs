//! Composite Gauss-Legendre quadrature, used to check the closed-form modal integrals and to
//! form the mass and stiffness matrices of several modes (orthogonality).

use crate::error::BeamError;

/// Largest number of Gauss-Legendre points per panel accepted by [`GaussLegendre::new`].
pub const MAX_ORDER: usize = 64;
/// Largest number of panels accepted by [`GaussLegendre::integrate`].
pub const MAX_PANELS: usize = 100_000;

/// An `order`-point Gauss-Legendre rule on `[-1, 1]`, exact for polynomials of degree
/// `2 order - 1`, applied on equal panels of an interval.
///
/// Nodes are the roots of the Legendre polynomial `P_order`, found by Newton's method from the
/// asymptotic guesses `cos(pi (i + 3/4) / (order + 1/2))`, with `P_order` and its derivative
/// from the three-term recurrence; weights are `2 / ((1 - x^2) P_order'(x)^2)`.
#[derive(Debug, Clone, PartialEq)]
pub struct GaussLegendre {
    nodes: Vec<f64>,
    weights: Vec<f64>,
}

impl GaussLegendre {
    /// The `order`-point rule.
    ///
    /// # Errors
    /// [`BeamError::QuadratureOutOfRange`] unless `1 <= order <= MAX_ORDER`.
    pub fn new(order: usize) -> Result<Self, BeamError> {
        if !(1..=MAX_ORDER).contains(&order) {
            return Err(BeamError::QuadratureOutOfRange {
                field: "order",
                value: order,
                min: 1,
                max: MAX_ORDER,
            });
        }
        let n = order as f64;
        let mut nodes = Vec::with_capacity(order);
        let mut weights = Vec::with_capacity(order);
        for i in 0..order {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n + 0.5)).cos();
            let mut derivative = 0.0;
            // Newton's method converges quadratically from these guesses; stop when the update
            // is at rounding level, and in any case after a fixed number of iterations.
            for _ in 0..100 {
                let (value, slope) = legendre(order, x);
                derivative = slope;
                let step = value / slope;
                x -= step;
                if step.abs() <= 4.0 * f64::EPSILON {
                    derivative = legendre(order, x).1;
                    break;
                }
            }
            nodes.push(x);
            weights.push(2.0 / ((1.0 - x * x) * derivative * derivative));
        }
        Ok(Self { nodes, weights })
    }

    /// Number of points per panel.
    #[must_use]
    pub fn order(&self) -> usize {
        self.nodes.len()
    }

    /// Nodes on `[-1, 1]`, in decreasing order.
    #[must_use]
    pub fn nodes(&self) -> &[f64] {
        &self.nodes
    }

    /// Weights matching [`Self::nodes`]; they sum to 2.
    #[must_use]
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// `int_a^b f(x) dx` by the rule on `panels` equal panels (units: those of `f` times `x`).
    ///
    /// # Errors
    /// [`BeamError::QuadratureOutOfRange`] unless `1 <= panels <= MAX_PANELS`.
    pub fn integrate<F: FnMut(f64) -> f64>(
        &self,
        mut f: F,
        a: f64,
        b: f64,
        panels: usize,
    ) -> Result<f64, BeamError> {
        if !(1..=MAX_PANELS).contains(&panels) {
            return Err(BeamError::QuadratureOutOfRange {
                field: "panels",
                value: panels,
                min: 1,
                max: MAX_PANELS,
            });
        }
        let width = (b - a) / panels as f64;
        let half = 0.5 * width;
        let mut total = 0.0;
        for panel in 0..panels {
            let centre = a + (panel as f64 + 0.5) * width;
            let mut sum = 0.0;
            for (x, w) in self.nodes.iter().zip(&self.weights) {
                sum += w * f(centre + half * x);
            }
            total += half * sum;
        }
        Ok(total)
    }
}

/// `(P_n(x), P_n'(x))` by the recurrence `k P_k = (2k - 1) x P_{k-1} - (k - 1) P_{k-2}` and
/// `P_n' = n (x P_n - P_{n-1}) / (x^2 - 1)` (valid inside `(-1, 1)`, where the nodes lie).
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let mut previous = 1.0;
    let mut current = x;
    for k in 2..=n {
        let k = k as f64;
        let next = ((2.0 * k - 1.0) * x * current - (k - 1.0) * previous) / k;
        previous = current;
        current = next;
    }
    if n == 0 {
        return (1.0, 0.0);
    }
    let derivative = n as f64 * (x * current - previous) / (x * x - 1.0);
    (current, derivative)
}
