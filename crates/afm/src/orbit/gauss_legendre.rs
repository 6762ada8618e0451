//! Gauss-Legendre quadrature on one solver step: the observables (Fourier coefficients of `u`,
//! force integrals) are integrated step by step, where the dense output (or the exact flow) is a
//! smooth function of time, so a few nodes per step reach rounding accuracy.

use hybrid::{Clock, HybridSystem, Solver};

use crate::model::phase;

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

    /// The rule's nodes on the part `[a, b]` of a solver step whose states are polynomial in
    /// `clock`'s reading `sigma` (hybrid's `Solver::last_step_clock`), with the drive phase
    /// there: a [`ClockNode`] for every node. The nodes are the rule's on
    /// `[sigma(a), sigma(b)]` and the weights carry `dt/dsigma`, so that an integrand smooth in
    /// `sigma` but not in `t` (the Hertz force `~ (t - t_c)^{3/2}` from a contact's onset or up
    /// to its release, on the square-root clock) is integrated to the rule's order; on the time
    /// clock they are the rule's nodes on `[a, b]`.
    pub fn clock_drive_nodes(
        &self,
        clock: Clock,
        a: f64,
        b: f64,
        angular_frequency: f64,
    ) -> impl Iterator<Item = ClockNode> + '_ {
        let (sigma_a, sigma_b) = (clock.sigma(a), clock.sigma(b));
        let middle = 0.5 * (sigma_a + sigma_b);
        self.pairs(sigma_a, sigma_b)
            .flat_map(move |(offset, weight)| {
                [middle - offset, middle + offset].map(|sigma| (sigma, weight))
            })
            .map(move |(sigma, weight)| {
                let t = clock.time(sigma).clamp(a, b);
                ClockNode {
                    sigma,
                    t,
                    weight: weight * clock.rate(sigma),
                    drive: phase::sin_cos(angular_frequency * t),
                }
            })
    }

    /// The rule's nodes on the part `[a, b]` of `solver`'s last step, on its clock
    /// ([`GaussLegendre::clock_drive_nodes`]), each with the state there: the states are
    /// written into `states` (`n` per node, room for [`MAX_RULE_NODES`]) by one
    /// `Solver::interpolate_clock` (on a Taylor step, one pass over the series).
    pub fn step_nodes<'s, S: HybridSystem + ?Sized>(
        &self,
        solver: &Solver<S>,
        a: f64,
        b: f64,
        angular_frequency: f64,
        states: &'s mut [f64],
    ) -> impl Iterator<Item = (ClockNode, &'s [f64])> + 's {
        let mut nodes = [ClockNode::default(); MAX_RULE_NODES];
        let mut sigma = [0.0; MAX_RULE_NODES];
        let mut count = 0;
        let clock = solver.last_step_clock();
        for (slot, node) in
            nodes
                .iter_mut()
                .zip(self.clock_drive_nodes(clock, a, b, angular_frequency))
        {
            (*slot, sigma[count]) = (node, node.sigma);
            count += 1;
        }
        let n = solver.system().dim();
        let states = &mut states[..count * n];
        solver.interpolate_clock(&sigma[..count], states);
        let states: &'s [f64] = states;
        nodes.into_iter().take(count).zip(states.chunks_exact(n))
    }

    /// The number of nodes of the rule.
    pub const fn len(&self) -> usize {
        2 * self.nodes.len()
    }

    /// Whether the rule has no nodes (none of the rules here).
    pub const fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }
}

/// The most nodes of the rules here ([`GAUSS_LEGENDRE_8`]): the room
/// [`GaussLegendre::step_nodes`] needs.
pub const MAX_RULE_NODES: usize = GAUSS_LEGENDRE_8.len();

/// A node of [`GaussLegendre::clock_drive_nodes`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ClockNode {
    /// The clock reading `sigma` of the node (hybrid's `Solver::interpolate_clock` takes it).
    pub sigma: f64,
    /// Its time, us.
    pub t: f64,
    /// Its weight, times `dt/dsigma` there (us): `int f dt ~ sum weight f(t)`.
    pub weight: f64,
    /// The drive phase there, `(sin w t, cos w t)`.
    pub drive: (f64, f64),
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

    /// On the time clock the nodes are those of `pairs` with the library's `sin_cos` there, and
    /// the weights integrate 1 to `b - a`.
    #[test]
    fn time_clock_nodes_carry_the_phase_at_each_node() {
        let (a, b, w) = (123.456, 123.789, 0.0584);
        for rule in [GAUSS_LEGENDRE_8, GAUSS_LEGENDRE_4] {
            let nodes: Vec<_> = rule.clock_drive_nodes(Clock::Time, a, b, w).collect();
            assert_eq!(nodes.len(), 2 * rule.pairs(a, b).count());
            assert_eq!(nodes.len(), rule.len());
            assert!(rule.len() <= MAX_RULE_NODES);
            let total: f64 = nodes.iter().map(|node| node.weight).sum();
            assert!((total - (b - a)).abs() < 1e-15);
            for ClockNode {
                sigma,
                t,
                drive: (sin, cos),
                ..
            } in nodes
            {
                assert!(t > a && t < b);
                assert_eq!(sigma, t, "the time clock reads time");
                let (sin_t, cos_t) = (w * t).sin_cos();
                assert!(
                    (sin - sin_t).abs() < 1e-15 && (cos - cos_t).abs() < 1e-15,
                    "{t}"
                );
            }
        }
    }

    /// On a square-root clock from a contact onset `t_c = a`, the force's shape `(t - t_c)^{3/2}`
    /// is `sigma^3` and integrates exactly (to `(2/5) (b - t_c)^{5/2}`); the same rule in `t`
    /// misses by ~1e-5 relative. Also on a clock centred past the interval (a release ahead).
    #[test]
    fn square_root_clock_nodes_integrate_the_onset_power_exactly() {
        let (a, b) = (2.0, 2.7);
        let onset = Clock::SquareRoot { reference: a };
        let release = Clock::SquareRoot {
            reference: b + 0.01,
        };
        for rule in [GAUSS_LEGENDRE_8, GAUSS_LEGENDRE_4] {
            let on_clock: f64 = rule
                .clock_drive_nodes(onset, a, b, 1.0)
                .map(|node| node.weight * (node.t - a).powf(1.5))
                .sum();
            let exact = 0.4 * (b - a).powf(2.5);
            assert!(
                (on_clock - exact).abs() < 1e-14 * exact,
                "{on_clock} vs {exact}"
            );
            let in_time: f64 = rule
                .clock_drive_nodes(Clock::Time, a, b, 1.0)
                .map(|node| node.weight * (node.t - a).powf(1.5))
                .sum();
            assert!((in_time - exact).abs() > 1e-7 * exact);
            let end = b + 0.01;
            let ahead: f64 = rule
                .clock_drive_nodes(release, a, b, 1.0)
                .map(|node| node.weight * (end - node.t).powf(1.5))
                .sum();
            let exact = 0.4 * ((end - a).powf(2.5) - (end - b).powf(2.5));
            assert!((ahead - exact).abs() < 1e-14 * exact, "{ahead} vs {exact}");
        }
    }
}
