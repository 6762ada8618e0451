//! Special points of a branch: where a test function changes sign, located by root finding
//! along the branch, with the precision of the location (MODEL.md sections 5 and 8 for the
//! labels).

use nalgebra::{Complex, DVector};

/// What kind of special point was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SpecialPointKind {
    /// A turning point of the branch (the parameter component of the tangent vanishes).
    Fold,
    /// A real Floquet multiplier crosses `-1`.
    PeriodDoubling,
    /// A complex pair of multipliers crosses the unit circle.
    NeimarkSacker,
    /// A local minimum of the contact switching function crosses zero: a grazing trajectory
    /// (MODEL.md section 5), labelled `G<n>` with `n` the larger impact count on either side:
    /// the grazing between `n - 1` and `n` impacts, whichever way the branch passes it.
    Grazing,
    /// A local maximum of the switching function between two contacts dips below zero: the
    /// two impacts merge into one.
    Merge,
    /// A local maximum of the switching function rises above zero: one impact splits in two.
    Split,
    /// The only local maximum of the switching function dips below zero: the free flight of a
    /// single-impact orbit vanishes and the trajectory stays in contact throughout the period
    /// (the impact merges with its own next period's copy; one impact on both sides).
    PermanentContact,
    /// A local maximum of a trajectory in contact throughout rises above zero: free flight
    /// appears, the reverse of [`SpecialPointKind::PermanentContact`].
    LiftOff,
    /// A maximum of a release surface's switching function while the contact is held touches
    /// zero: the grazing of the release surface (for the AFM, JKR's pull-off gap), where an
    /// orbit that stays attached through the maximum meets one that releases there.
    PullOff,
    /// The impact count decreases with no extremum crossing zero.
    ImpactVanish,
    /// The impact count increases with no extremum crossing zero.
    ImpactAppear,
}

impl SpecialPointKind {
    /// The label of a point of this kind with `impacts` the larger impact count per period on
    /// either side of it: `G<n>`, `fold`, `period-doubling`, `neimark-sacker`, `merge`,
    /// `split`, `permanent-contact`, `lift-off`, `pull-off`, `impact-vanish`,
    /// `impact-appear`.
    pub fn label(self, impacts: usize) -> String {
        match self {
            SpecialPointKind::Fold => "fold".into(),
            SpecialPointKind::PeriodDoubling => "period-doubling".into(),
            SpecialPointKind::NeimarkSacker => "neimark-sacker".into(),
            SpecialPointKind::Grazing => format!("G{impacts}"),
            SpecialPointKind::Merge => "merge".into(),
            SpecialPointKind::Split => "split".into(),
            SpecialPointKind::PermanentContact => "permanent-contact".into(),
            SpecialPointKind::LiftOff => "lift-off".into(),
            SpecialPointKind::PullOff => "pull-off".into(),
            SpecialPointKind::ImpactVanish => "impact-vanish".into(),
            SpecialPointKind::ImpactAppear => "impact-appear".into(),
        }
    }
}

/// A located special point of a branch.
#[derive(Debug, Clone, PartialEq)]
pub struct SpecialPoint {
    /// `G1`, `G2`, ..., `fold`, `period-doubling`, `neimark-sacker`, `merge`, `split`,
    /// `permanent-contact`, `lift-off`, `pull-off`, `impact-vanish`, `impact-appear`
    /// ([`SpecialPointKind::label`]).
    pub label: String,
    /// The kind of point.
    pub kind: SpecialPointKind,
    /// The parameter at the located point (parameter units; for the AFM, `Z` in nm).
    pub parameter: f64,
    /// The final parameter bracket `(low, high)` of the sign change (parameter units).
    pub bracket: (f64, f64),
    /// `high - low` of the bracket: the achieved precision (parameter units).
    pub precision: f64,
    /// Whether the bracket reached the location tolerance with a sign change between its ends.
    /// False when the root finder ran out of iterations, a trial point failed, or the test
    /// function jumped across a structure change (a discontinuous crossing, reported at the
    /// structure change's bracket). At a hard-impact corner (a jump, or the end of a branch
    /// that cannot go on) the far end of the bracket may be a parameter at which no orbit was
    /// found, which counts as the far side (see [`crate::Continuation`]).
    pub converged: bool,
    /// Impacts per period on the side of the bracket the branch comes from.
    pub impacts_before: usize,
    /// Impacts per period on the side of the bracket the branch goes to.
    pub impacts_after: usize,
    /// The state `x` of the orbit at the located point (state units).
    pub state: DVector<f64>,
    /// The parameter of the orbit `state` (parameter units): `parameter`, except at a
    /// hysteretic grazing whose zero is extrapolated past the last orbit Newton's method
    /// converged on (MODEL.md section 8), where it is that orbit's parameter.
    pub orbit_parameter: f64,
    /// The Floquet multipliers at the located point.
    pub multipliers: Vec<Complex<f64>>,
    /// Root-finding iterations (corrected trial points) spent on the location.
    pub iterations: usize,
    /// Index of the branch point that ends the step in which the point was found.
    pub branch_index: usize,
}
