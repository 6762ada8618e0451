//! Gauss-Legendre quadrature on one solver step: the observables (Fourier coefficients of `u`,
//! force integrals) are integrated step by step, where the dense output (or the exact flow) is a
//! smooth function of time, so a few nodes per step reach rounding accuracy.

use crate::phase;

/// A symmetric Gauss-Legendre rule on `[-1, 1]`: its positive nodes and their weights (each
/// node `x` stands for the pair `+-x`).
#[derive(Debug, Clone, Copy)]
pub struct GaussLegendre {
    nodes: &'static [f64],
    weights: &'static [f64],
}

/// The 8-point rule (exact for polynomials of degree 15).
pub const GAUSS_LEGENDRE_8: GaussLegendre = GaussLegendre {
    nodes: &[
        0.183_434_642_495_649_8,
        0.525_532_409_916_329,
        0.796_666_477_413_626_7,
        0.960_289_856_497_536_3,
    ],
    weights: &[
        0.362_683_783_378_362,
        0.313_706_645_877_887_3,
        0.222_381_034_453_374_5,
        0.101_228_536_290_376_3,
    ],
};

/// The 4-point rule (exact for polynomials of degree 7).
pub const GAUSS_LEGENDRE_4: GaussLegendre = GaussLegendre {
    nodes: &[0.339_981_043_584_856_3, 0.861_136_311_594_052_6],
    weights: &[0.652_145_154_862_546_1, 0.347_854_845_137_453_8],
};

impl GaussLegendre {
    /// The rule on `[a, b]` as `(offset, weight)` pairs: the nodes are `(a + b)/2 -+ offset`,
    /// each with `weight` (already scaled by `(b - a)/2`), so that
    /// `int_a^b f dt ~ sum weight * (f(mid - offset) + f(mid + offset))`.
    pub fn pairs(&self, a: f64, b: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        let half = 0.5 * (b - a);
        self.nodes
            .iter()
            .zip(self.weights)
            .map(move |(node, weight)| (half * node, half * weight))
    }

    /// The rule's nodes on `[a, b]` with the drive phase there: `(t, weight, (sin w t,
    /// cos w t))` for every node, the pair `mid -+ offset` in turn. The phase comes by angle
    /// addition from the middle (`phase::sin_cos` at the middle and at each offset: one
    /// evaluation per pair of nodes, plus one).
    pub fn drive_nodes(
        &self,
        a: f64,
        b: f64,
        angular_frequency: f64,
    ) -> impl Iterator<Item = (f64, f64, (f64, f64))> + '_ {
        let middle = 0.5 * (a + b);
        let (sin_m, cos_m) = phase::sin_cos(angular_frequency * middle);
        self.pairs(a, b).flat_map(move |(offset, weight)| {
            let (sin_d, cos_d) = phase::sin_cos(angular_frequency * offset);
            [(middle - offset, -1.0), (middle + offset, 1.0)].map(|(t, sign)| {
                let sin = sin_m * cos_d + sign * cos_m * sin_d;
                let cos = cos_m * cos_d - sign * sin_m * sin_d;
                (t, weight, (sin, cos))
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each rule integrates the polynomials of its degree exactly: int_0^2 t^k dt = 2^(k+1)/(k+1).
    #[test]
    fn rules_are_exact_to_their_degree() {
        for (rule, degree) in [(GAUSS_LEGENDRE_8, 15), (GAUSS_LEGENDRE_4, 7)] {
            for k in 0..=degree {
                let integral: f64 = rule
                    .pairs(0.0, 2.0)
                    .map(|(offset, weight)| {
                        weight * ((1.0 - offset).powi(k) + (1.0 + offset).powi(k))
                    })
                    .sum();
                let exact = 2f64.powi(k + 1) / f64::from(k + 1);
                assert!(
                    (integral - exact).abs() < 1e-13 * exact,
                    "degree {k}: {integral} vs {exact}"
                );
            }
        }
    }

    /// The drive phases by angle addition are those of the library's `sin_cos` at each node to
    /// a few ulps, the nodes are those of `pairs`, and the weights integrate 1 to `b - a`.
    #[test]
    fn drive_nodes_carry_the_phase_at_each_node() {
        let (a, b, w) = (123.456, 123.789, 0.0584);
        for rule in [GAUSS_LEGENDRE_8, GAUSS_LEGENDRE_4] {
            let nodes: Vec<_> = rule.drive_nodes(a, b, w).collect();
            assert_eq!(nodes.len(), 2 * rule.pairs(a, b).count());
            let total: f64 = nodes.iter().map(|node| node.1).sum();
            assert!((total - (b - a)).abs() < 1e-15);
            for (t, _, (sin, cos)) in nodes {
                assert!(t > a && t < b);
                let (sin_t, cos_t) = (w * t).sin_cos();
                assert!(
                    (sin - sin_t).abs() < 1e-15 && (cos - cos_t).abs() < 1e-15,
                    "{t}"
                );
            }
        }
    }
}
