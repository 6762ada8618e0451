//! The problem a continuation works on: a parametrised period map `P(x; p)` with its
//! derivatives and the structure (extrema and impacts of the contact switching function) of
//! the trajectory over the period.
//!
//! A periodic orbit is a fixed point `P(x; p) = x`; its stability follows from the eigenvalues
//! of the monodromy matrix `dP/dx` (Floquet multipliers), and pseudo-arclength continuation
//! needs `dP/dp` as well. MODEL.md Sec. 5 defines impacts and grazing in terms of the local
//! minima of the gap; [`OrbitStructure`] carries exactly those.

use nalgebra::{DMatrix, DVector};

use crate::error::ContinuationError;

/// The structure of the contact switching function `h(t)` along the trajectory over one
/// evaluation of the period map (MODEL.md Sec. 5: impacts, near impacts, grazing).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct OrbitStructure {
    /// `(time since the period start, value of h)` of every local minimum of `h` (time in the
    /// system's units, `h` in switching-function units, for the AFM the gap `d` in nm). A
    /// minimum with `h > 0` is a near impact; its value is 0 at grazing.
    ///
    /// For a hard impact (a reset map, where `h` has a corner at 0 instead of a smooth
    /// minimum) the problem reports the *virtual* minimum `-v^2 / (2 a)` of the free flight
    /// continued through the surface (`v = dh/dt` before the impact, `a = d^2h/dt^2`), which
    /// is negative and tends to 0 at grazing like the smooth minimum on the other side.
    pub minima: Vec<(f64, f64)>,
    /// `(time since the period start, value of h)` of every local maximum of `h`; a maximum
    /// with `h < 0` between two contacts means they have merged.
    pub maxima: Vec<(f64, f64)>,
    /// Number of impacts per period: `Down` crossings of (or impacts on) the contact surface,
    /// or 1 for a trajectory in contact throughout (see `permanent_contact`), so that the
    /// count is the number of maximal intervals with `h < 0` (MODEL.md Sec. 5).
    pub impacts: usize,
    /// Whether the trajectory stays inside the contact surface (`h < 0`) for the whole period,
    /// crossing it nowhere: one impact without onset or release.
    pub permanent_contact: bool,
    /// Duration of the period map (system time units): the times above lie in
    /// `[0, duration)` and are compared modulo it.
    pub duration: f64,
    /// `(time since the period start, value)` of every local maximum of a release surface's
    /// switching function `h_r` while the contact is held (MODEL.md Sec. 8, `pull-off`; empty
    /// for a system without one, [`crate::Parametrised::release_surface`]): negative while the
    /// orbit stays attached through it. At a release (the `Up` crossing of `h_r` while held)
    /// the problem reports the *virtual* maximum `v^2 / (2 |a|)` of the held flow continued
    /// through the surface (`v = dh_r/dt` at the crossing, `a = d^2h_r/dt^2` there), positive
    /// and tending to 0 as the release becomes tangential: the value is 0 at the grazing of the
    /// release surface.
    pub release_maxima: Vec<(f64, f64)>,
}

/// One evaluation of the period map `P(x; p)` and its derivatives.
#[derive(Debug, Clone, PartialEq)]
pub struct PeriodMap {
    /// `P(x; p)`: the state one period (of the map) after `x` (state units).
    pub image: DVector<f64>,
    /// The monodromy (Jacobian) `dP/dx` (`n x n`); at a fixed point its eigenvalues are the
    /// Floquet multipliers.
    pub monodromy: DMatrix<f64>,
    /// `dP/dp` at fixed `x` (state units per parameter unit).
    pub parameter_derivative: DVector<f64>,
    /// Extrema and impacts of the contact switching function along the trajectory.
    pub structure: OrbitStructure,
}

/// A parametrised period map `P(x; p)` of dimension `n`, with any origin (a hybrid solver, a
/// closed form, an algebraic map).
pub trait PeriodicProblem {
    /// Dimension `n` of the state `x`.
    fn dim(&self) -> usize;

    /// Evaluate `P(x; p)`, `dP/dx`, `dP/dp` and the orbit structure at `(x, p)`.
    ///
    /// # Errors
    /// Any failure to evaluate the map (for a hybrid problem, a failed integration) as a
    /// [`ContinuationError`], typically [`ContinuationError::PeriodMapFailed`].
    fn period_map(&self, x: &[f64], p: f64) -> Result<PeriodMap, ContinuationError>;

    /// As [`PeriodicProblem::period_map`], at a point the corrector expects to accept: an
    /// evaluation of a branch's trial point after a Newton update from a residual `r` with
    /// `r^2 <= tolerance` (quadratic convergence: usually the converged evaluation; the
    /// points sampled to locate special points never are). A problem may do more here that
    /// only an accepted point needs (the AFM diagram records the orbit's observables during
    /// the same integration); the map itself must be the same as `period_map`'s. Default:
    /// `period_map`.
    ///
    /// # Errors
    /// As [`PeriodicProblem::period_map`].
    fn period_map_likely_accepted(
        &self,
        x: &[f64],
        p: f64,
    ) -> Result<PeriodMap, ContinuationError> {
        self.period_map(x, p)
    }
}

/// Check the dimensions and finiteness of a period map returned by `problem` at parameter `p`.
pub(crate) fn check_period_map(map: &PeriodMap, n: usize, p: f64) -> Result<(), ContinuationError> {
    if map.image.len() != n {
        return Err(ContinuationError::DimensionMismatch {
            what: "image of the period map",
            expected: n,
            found: map.image.len(),
        });
    }
    if map.monodromy.nrows() != n || map.monodromy.ncols() != n {
        return Err(ContinuationError::DimensionMismatch {
            what: "monodromy matrix",
            expected: n,
            found: map.monodromy.nrows().max(map.monodromy.ncols()),
        });
    }
    if map.parameter_derivative.len() != n {
        return Err(ContinuationError::DimensionMismatch {
            what: "parameter derivative of the period map",
            expected: n,
            found: map.parameter_derivative.len(),
        });
    }
    let finite = |v: &[f64]| v.iter().all(|z| z.is_finite());
    if !finite(map.image.as_slice()) {
        return Err(ContinuationError::NonFinite {
            what: "image of the period map",
            parameter: p,
        });
    }
    if !finite(map.monodromy.as_slice()) {
        return Err(ContinuationError::NonFinite {
            what: "monodromy matrix",
            parameter: p,
        });
    }
    if !finite(map.parameter_derivative.as_slice()) {
        return Err(ContinuationError::NonFinite {
            what: "parameter derivative of the period map",
            parameter: p,
        });
    }
    Ok(())
}
