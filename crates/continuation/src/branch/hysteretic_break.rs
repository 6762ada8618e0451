//! The step towards a hysteretic grazing: where the period map jumps at a grazing of the
//! contact or of the release surface (a hysteretic contact law, MODEL.md Sec. 9), no orbit
//! lies past it near the branch and every correction across it fails, so the branch reaches
//! the grazing by cut steps until the minimum step (where it ends, locating the grazing,
//! [`super::Continuation::terminal_location`]). Halving the step takes about twenty failed
//! corrections from the largest step down; cutting it instead to just short of the grazing
//! extrapolated from the accepted side, and aiming the steps after it the same way, takes a
//! few steps. Next to the grazing the period map's own error exceeds Newton's tolerance (its
//! `sqrt(|g|)` term), so corrections fail there at random; once the grazing's zero is
//! extrapolated from the branch to within the location tolerance, such a failure ends the
//! branch instead of halving the step down to the minimum through more of them, and so does,
//! after one such failure, the point whose acceptance resolves the zero.

use nalgebra::DVector;

use super::detection::near_side_vanishing;
use super::Continuation;
use crate::error::ContinuationError;
use crate::extrapolated_zero::extrapolated_zero;
use crate::problem::PeriodicProblem;
use crate::test_function::{structure_changes, ExtremumKind, StructureTest};

/// The cut step's share of the way to the extrapolated grazing: short of it, so that the next
/// step is accepted on the near side (the extrapolation is linear in the parameter, off by the
/// test function's curvature along the branch).
const SHORT_OF_GRAZING: f64 = 0.99;

/// Whether a structure test is the grazing of a hysteretic contact's surface, where the period
/// map jumps: a minimum of the contact switching function or a maximum of the release surface's
/// changing sign.
fn jumps_at(test: &StructureTest) -> bool {
    matches!(
        test,
        StructureTest::Extremum {
            kind: ExtremumKind::Minimum | ExtremumKind::ReleaseMaximum,
            ..
        }
    )
}

impl<P: PeriodicProblem + ?Sized> Continuation<'_, P> {
    /// After a failed correction of the step to `predicted` (the tangent prediction, `(x, p)`)
    /// on a branch whose period map jumps at its grazings
    /// ([`crate::ContinuationSettings::hysteretic_grazing`]): the factor to cut the step by when
    /// the trajectory from `predicted` has crossed a grazing of the contact or release surface
    /// since the current point. The grazing's parameter is extrapolated linearly from the test
    /// function's values at the previous and the current point (secant in `p`, both on the
    /// branch; the prediction's own value belongs to the other mode's flow), or, without a
    /// previous point on that side, interpolated between the current point and the
    /// prediction; the factor is [`SHORT_OF_GRAZING`] of the step's share up to the nearest
    /// such grazing, used where it cuts more than `step_cut` (so that repeated failures still
    /// shrink the step). `None` (cut by `step_cut`) otherwise, or when the period map fails
    /// at the prediction.
    pub(super) fn grazing_fraction(
        &mut self,
        predicted: &DVector<f64>,
    ) -> Result<Option<f64>, ContinuationError> {
        self.grazing_test = None;
        if !self.settings.hysteretic_grazing {
            return Ok(None);
        }
        let n = self.problem.dim();
        let (p_a, p_far) = (self.current.parameter(), predicted[n]);
        if p_far == p_a {
            return Ok(None);
        }
        let Ok(map) = self.problem.period_map(&predicted.as_slice()[..n], p_far) else {
            return Ok(None);
        };
        let nearest = structure_changes(&self.current.map.structure, &map.structure)
            .into_iter()
            .filter(jumps_at)
            .map(|test| (self.share_to_grazing(&test, p_a, p_far), test))
            .min_by(|x, y| x.0.total_cmp(&y.0));
        let Some((share, test)) = nearest else {
            return Ok(None);
        };
        self.bracketed_grazing = Some(test);
        let fraction = SHORT_OF_GRAZING * share;
        let cuts = fraction > 0.0 && fraction < self.settings.step_cut;
        if cuts {
            self.grazing_test = Some(test);
        }
        Ok(cuts.then_some(fraction))
    }

    /// After a point is accepted on a step cut towards a hysteretic grazing
    /// ([`Continuation::grazing_fraction`]): set the next step to [`SHORT_OF_GRAZING`] of the
    /// way to the grazing extrapolated again from the new point and the one before it (in
    /// arclength along the current tangent), instead of growing it past the grazing into a
    /// certain failure; not below the minimum step, where the next failure ends the branch.
    /// Does nothing (and stops aiming) where the test function is not approaching zero.
    pub(super) fn aim_at_grazing(&mut self) {
        let Some(test) = self.grazing_test.take() else {
            return;
        };
        let Some((p_prev, previous)) = self.recent_structures.back() else {
            return;
        };
        let n = self.problem.dim();
        let p_a = self.current.parameter();
        let value_a = test.value(0.0, &self.current.map.structure);
        let value_prev = test.value(0.0, previous);
        let tp = self.current.tangent[n];
        let approaching = value_a.is_finite()
            && value_prev.is_finite()
            && (value_prev < 0.0) == (value_a < 0.0)
            && value_prev.abs() > value_a.abs()
            && *p_prev != p_a
            && tp.is_finite()
            && tp != 0.0;
        if !approaching {
            return;
        }
        let p_zero = p_a + value_a * (p_a - p_prev) / (value_prev - value_a);
        let ds = SHORT_OF_GRAZING * (p_zero - p_a) / tp;
        if ds.is_finite() && ds > 0.0 {
            self.step = ds.clamp(self.settings.min_step, self.settings.max_step);
            self.grazing_test = Some(test);
        }
    }

    /// The share of the step from the current point (parameter `p_a`) to the prediction (`p_far`)
    /// at which `test` is estimated to reach zero (see [`Continuation::grazing_fraction`]).
    fn share_to_grazing(&self, test: &StructureTest, p_a: f64, p_far: f64) -> f64 {
        let StructureTest::Extremum { value_a, .. } = *test else {
            return test.linear_root();
        };
        let secant = self
            .recent_structures
            .back()
            .and_then(|(p_prev, previous)| {
                let value_prev = test.value(0.0, previous);
                let approaching = value_prev.is_finite()
                    && (value_prev < 0.0) == (value_a < 0.0)
                    && value_prev.abs() > value_a.abs()
                    && *p_prev != p_a;
                approaching.then(|| {
                    let p_zero = p_a + value_a * (p_a - p_prev) / (value_prev - value_a);
                    (p_zero - p_a) / (p_far - p_a)
                })
            });
        match secant {
            Some(share) if share.is_finite() && share > 0.0 => share,
            _ => test.linear_root(),
        }
    }

    /// After a failed correction of a step, whether it ends the branch at the hysteretic
    /// grazing the branch approaches: where it failed at the period map's noise floor
    /// (`at_noise_floor`: its smallest residual within [`crate::corrector::NOISE_FLOOR`] times
    /// Newton's tolerance, it came that near an orbit; next to the grazing the map's `sqrt(|g|)`
    /// term puts its own error above the tolerance) while a grazing is bracketed, and the
    /// grazing's zero is resolved ([`Continuation::grazing_resolved`]). Such a failure is
    /// remembered until the next jump: a point accepted afterwards that resolves the zero ends
    /// the branch too (`Continuation::accept`).
    pub(super) fn at_resolved_grazing(&mut self, at_noise_floor: bool) -> bool {
        if !(at_noise_floor && self.bracketed_grazing.is_some()) {
            return false;
        }
        self.noise_floor_met = true;
        self.grazing_resolved()
    }

    /// Whether the zero of the test function of the grazing a failed prediction crossed since
    /// the last jump ([`Continuation::grazing_fraction`]), extrapolated from the current point
    /// and the branch's recent points as a located grazing's is ([`extrapolated_zero`]: linearly
    /// in `g` or `sqrt(|g|)`), lies ahead with an error of at most the location tolerance.
    /// Where corrections fail at the period map's noise floor next to it, halving the step
    /// further only repeats them: each succeeds or fails as the last bits of the flow fall, and
    /// where the branch ends moves the zero by no more than its error.
    pub(super) fn grazing_resolved(&self) -> bool {
        let Some(test) = self.bracketed_grazing else {
            return false;
        };
        let Some(vanishing) = near_side_vanishing(&test) else {
            return false;
        };
        let n = self.problem.dim();
        let (p_a, t_p) = (self.current.parameter(), self.current.tangent[n]);
        let g_a = test.value(0.0, &self.current.map.structure);
        let near_side = |g: f64| g.is_finite() && g != 0.0 && (g < 0.0) == (g_a < 0.0);
        let points: Vec<(f64, f64)> = std::iter::once((p_a, g_a))
            .chain(
                self.recent_structures
                    .iter()
                    .map(|(p, structure)| (*p, test.value(0.0, structure))),
            )
            .filter(|&(_, g)| near_side(g))
            .collect();
        t_p != 0.0
            && extrapolated_zero(&points, t_p.signum(), vanishing)
                .is_some_and(|zero| zero.error <= self.settings.location_tolerance)
    }
}
