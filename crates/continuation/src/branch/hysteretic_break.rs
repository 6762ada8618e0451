//! The step towards a hysteretic grazing: where the period map jumps at a grazing of the
//! contact or of the release surface (a hysteretic contact law, MODEL.md Sec. 9), no orbit
//! lies past it near the branch and every correction across it fails, so the branch reaches
//! the grazing by cut steps until the minimum step (where it ends, locating the grazing,
//! [`super::Continuation::terminal_location`]). Halving the step takes about twenty failed
//! corrections from the largest step down; cutting it instead to just short of the grazing
//! estimated from the failed step's prediction takes a few.

use nalgebra::DVector;

use super::Continuation;
use crate::error::ContinuationError;
use crate::problem::PeriodicProblem;
use crate::test_function::{structure_changes, ExtremumKind, StructureTest};

/// The cut step's share of the way to the grazing estimated along the failed step: short of
/// it, so that the next step is accepted on the near side (the estimate is linear in the test
/// function along the tangent, off the branch by the step's curvature).
const SHORT_OF_GRAZING: f64 = 0.9;

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
    /// ([`crate::ContinuationSettings::hysteretic_grazing`]): the factor to cut the step by, when
    /// the trajectory from `predicted` has crossed a grazing of the contact or release surface
    /// since the current point: [`SHORT_OF_GRAZING`] of the fraction of the step at the
    /// linearly interpolated zero of the first such test function, where that cuts more than
    /// `step_cut`. `None` (cut by `step_cut`) otherwise, or when the period map fails there.
    pub(super) fn grazing_fraction(
        &self,
        predicted: &DVector<f64>,
    ) -> Result<Option<f64>, ContinuationError> {
        if !self.settings.hysteretic_grazing {
            return Ok(None);
        }
        let n = self.problem.dim();
        let Ok(map) = self.problem.period_map(&predicted.as_slice()[..n], predicted[n]) else {
            return Ok(None);
        };
        let root = structure_changes(&self.current.map.structure, &map.structure)
            .iter()
            .filter(|t| jumps_at(t))
            .map(StructureTest::linear_root)
            .fold(f64::INFINITY, f64::min);
        let fraction = SHORT_OF_GRAZING * root;
        Ok((fraction.is_finite() && fraction < self.settings.step_cut).then_some(fraction))
    }
}
