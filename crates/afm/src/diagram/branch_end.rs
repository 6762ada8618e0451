//! How one continued branch of a hysteretic law's diagram ended short of its requested end
//! (MODEL.md sections 8 and 9): at a fold of its orbits (where `Z` turns back), where only the
//! tangent's orientation turned back (no end at all), or where the corrector failed at the
//! smallest step, with the grazing the branch was running into extrapolated.

use continuation::{BranchPoint, OrbitStructure};

use crate::diagram::bifurcation_diagram::DiagramSpecialPoint;

/// Why one continued branch of a hysteretic law's diagram ended short of its requested end.
#[derive(Debug, Clone)]
pub(crate) enum BranchEnd {
    /// `Z` turned back at a located fold: the orbits of the branch end there, where they meet
    /// the unstable orbits of the branch turning back (a saddle-node of the period map; no
    /// orbit of that family lies past its `Z`). The located fold.
    Fold(DiagramSpecialPoint),
    /// `Z` turned back with no fold located in the step: the branch runs on past its last
    /// point, and the continuation reversed only because the tangent's orientation did (after
    /// a corner jump the tangent is oriented along the jump's secant, whose state part can
    /// outweigh its `Z` part).
    Reversed,
    /// The corrector failed at the continuation's smallest step with no grazing located there
    /// (next to a grazing of a hysteretic surface the monodromy grows without bound). The
    /// nearest grazing the branch was running into, extrapolated from its last points
    /// ([`extrapolated_grazing`]), if any.
    Stuck(Option<GrazingAhead>),
}

/// The grazing a stuck branch was running into, extrapolated from its last points
/// ([`extrapolated_grazing`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GrazingAhead {
    /// The farthest `Z` (nm) the grazing can lie at: where `sqrt(|g|)` of its extremum `g`,
    /// extrapolated linearly, reaches zero. Exact to first order where `g` vanishes
    /// quadratically (the side of a hysteretic grazing that crosses the surface, MODEL.md
    /// section 8), past the zero where it vanishes linearly (`sqrt` is concave there, its
    /// secant overshoots), so the grazing lies between the last point and this `Z`.
    pub(crate) z_nm: f64,
    /// Whether the extremum is a maximum of the release surface (the grazing is a `pull-off`),
    /// not a gap minimum (a `G<n>`).
    pub(crate) release: bool,
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

/// The least `Z` distance (nm) between two branch points from which
/// [`extrapolated_grazing`] draws its secant: far enough apart that the orbits' Newton
/// residual (1e-10) does not swamp the change of the test functions.
const SECANT_BASE_NM: f64 = 1e-6;

/// The grazing the branch `points` (last the end) was running into in the direction `sign` of
/// `Z`: every gap minimum and every maximum of the release surface (MODEL.md section 8: `G<n>`,
/// `pull-off`) of the last point whose value approaches zero is extrapolated to zero along the
/// secant of `sqrt(|g|)` in `Z` from the latest earlier point with the same numbers of extrema
/// at least [`SECANT_BASE_NM`] away (else the farthest such point), and the nearest zero ahead
/// is returned ([`GrazingAhead::z_nm`]: the farthest the grazing can lie). `None` where no
/// extremum approaches zero.
pub(crate) fn extrapolated_grazing(points: &[BranchPoint], sign: f64) -> Option<GrazingAhead> {
    let (last, earlier) = points.split_last()?;
    let same_counts = |s: &OrbitStructure| {
        s.minima.len() == last.structure.minima.len()
            && s.release_maxima.len() == last.structure.release_maxima.len()
    };
    let mut base: Option<&BranchPoint> = None;
    for point in earlier.iter().rev() {
        if !same_counts(&point.structure) {
            break;
        }
        if point.parameter != last.parameter {
            base = Some(point);
        }
        if (point.parameter - last.parameter).abs() >= SECANT_BASE_NM {
            break;
        }
    }
    let base = base?;
    // Each extremum's value, with whether it is the release surface's.
    let extrema = |s: &OrbitStructure| -> Vec<(f64, bool)> {
        s.minima
            .iter()
            .map(|&(_, value)| (value, false))
            .chain(s.release_maxima.iter().map(|&(_, value)| (value, true)))
            .collect()
    };
    let (p_a, p_b) = (base.parameter, last.parameter);
    extrema(&base.structure)
        .into_iter()
        .zip(extrema(&last.structure))
        .filter(|&((v_a, _), (v_b, _))| (v_a < 0.0) == (v_b < 0.0) && v_b.abs() < v_a.abs())
        .map(|((v_a, _), (v_b, release))| {
            let (s_a, s_b) = (v_a.abs().sqrt(), v_b.abs().sqrt());
            GrazingAhead {
                z_nm: p_b + s_b * (p_b - p_a) / (s_a - s_b),
                release,
            }
        })
        .filter(|g| g.z_nm.is_finite() && sign * (g.z_nm - p_b) > 0.0)
        .min_by(|x, y| (sign * (x.z_nm - p_b)).total_cmp(&(sign * (y.z_nm - p_b))))
}
