//! Where `Z` turns back on a branch of a hysteretic law's diagram (MODEL.md sections 8 and 9):
//! at a fold of the attached orbits, the end of the attached branch; or where the tangent was
//! only oriented backwards, which ends nothing.

use crate::diagram::bifurcation_diagram::DiagramSpecialPoint;

/// Why one continued branch of a hysteretic law's diagram stopped where `Z` turned back.
#[derive(Debug, Clone)]
pub(crate) enum BranchTurn {
    /// A fold was located in the step that turned: the orbits of the branch end there, where
    /// they meet the unstable orbits of the branch turning back (a saddle-node of the period
    /// map; no orbit of that family lies past its `Z`). The located fold, `Z` in nm.
    Fold(DiagramSpecialPoint),
    /// No fold was located in the step: the branch runs on past its last point, and the
    /// continuation reversed only because the tangent's orientation did (after a corner jump
    /// the tangent is oriented along the jump's secant, whose state part can outweigh its
    /// `Z` part).
    Reversed,
}

/// The branch-end `pull-off` (MODEL.md section 8) at the located fold `fold` that ends an
/// attached branch on a retract: the fold's separation, bracket and precision (nm), the
/// orbit there, `impacts_before` impacts per period before it and none after.
pub(crate) fn pull_off_at_fold(
    fold: &DiagramSpecialPoint,
    impacts_before: usize,
) -> DiagramSpecialPoint {
    DiagramSpecialPoint {
        label: String::from("pull-off"),
        impacts_before,
        impacts_after: 0,
        ..fold.clone()
    }
}
