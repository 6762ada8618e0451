//! The end of an attached branch on a JKR retract (MODEL.md section 8, `pull-off` (branch
//! end); section 9, JKR): where the attached orbits end at a fold the branch end is that fold,
//! located, so that it agrees between two continuations with different steps within its
//! stated precision; and where the continuation only turned back after a corner jump (its
//! tangent oriented backwards) no branch end is labelled and the branch goes on.

mod approach_retract;

use afm::{BifurcationDiagram, DiagramSpecialPoint};
use approach_retract::retract;

/// The special point labelled `label` with the highest `Z`.
fn highest<'a>(diagram: &'a BifurcationDiagram, label: &str) -> &'a DiagramSpecialPoint {
    diagram
        .special_points
        .iter()
        .filter(|p| p.label == label)
        .max_by(|a, b| a.z_nm.total_cmp(&b.z_nm))
        .unwrap_or_else(|| panic!("no {label}"))
}

/// `biolever-sticky` (A0 = 10 nm): the retract's attached single-impact branch ends at a fold
/// below `G1` (its largest multiplier reaches 1 there). Continued with largest steps 0.02 and
/// 0.04 nm (the built-in `A0 / 250`), the two branch ends are located independently (different
/// branch points, different brackets) and agree within the larger of their stated precisions
/// plus 1e-10 nm (measured: 1.6e-12 nm apart, precisions about 1e-11 nm; the last branch
/// points before the fold lie 1.1e-6 nm apart). Each is converged, its bracket
/// holds it, and it lies at or beyond the last point of the branch below it.
#[test]
fn sticky_branch_end_agrees_between_step_sizes() {
    let ends: Vec<DiagramSpecialPoint> = [0.02, 0.04]
        .iter()
        .map(|&step| {
            let retract = retract("biolever-sticky", 10.0, step);
            let end = highest(&retract, "pull-off").clone();
            assert!(end.converged, "{end:?}");
            assert!(end.bracket_nm[0] <= end.z_nm && end.z_nm <= end.bracket_nm[1]);
            let below = retract
                .points
                .iter()
                .filter(|p| p.z_nm <= end.z_nm + 1e-9)
                .map(|p| p.z_nm)
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(
                end.z_nm - below < step,
                "end {} last point {below}",
                end.z_nm
            );
            end
        })
        .collect();
    let precision = ends[0].precision_nm.max(ends[1].precision_nm);
    let apart = (ends[0].z_nm - ends[1].z_nm).abs();
    assert!(
        apart <= precision + 1e-10,
        "branch ends {} and {} nm, {apart:e} apart, precision {precision:e}",
        ends[0].z_nm,
        ends[1].z_nm
    );
}

/// `biolever-adhesive` at A0 = 10 nm, largest step 0.02 nm: the retract crosses `G2` by a
/// corner jump to a single-impact orbit 0.02 nm past it, and the attached single-impact
/// branch runs on from there up to `G1` (the points past the jump have one impact and `Z`
/// rising). No `pull-off` lies between `G2` and `G1`, and the branch has points every
/// largest step or closer from `G2` to `G1` (no jump of the diagram in between).
#[test]
fn adhesive_retract_has_no_branch_end_between_g2_and_g1() {
    let step = 0.02;
    let retract = retract("biolever-adhesive", 10.0, step);
    let g2 = highest(&retract, "G2").z_nm;
    let g1 = highest(&retract, "G1").z_nm;
    let between: Vec<&DiagramSpecialPoint> = retract
        .special_points
        .iter()
        .filter(|p| p.label == "pull-off" && g2 < p.z_nm && p.z_nm < g1)
        .collect();
    assert!(
        between.is_empty(),
        "pull-off between G2 and G1: {between:?}"
    );
    let zs: Vec<f64> = retract
        .points
        .iter()
        .map(|p| p.z_nm)
        .filter(|&z| g2 <= z && z <= g1)
        .collect();
    assert!(zs.len() > 10, "{} points between G2 and G1", zs.len());
    for pair in zs.windows(2) {
        assert!(
            pair[1] > pair[0] && pair[1] - pair[0] <= step + 1e-12,
            "points at {} and {} nm",
            pair[0],
            pair[1]
        );
    }
}

/// `biolever-sticky` at A0 = 12 nm: the retract's three-impact branch ends at 4.2399 nm where
/// the corrector fails at the smallest step (a gap minimum 1e-5 nm below zero, the
/// monodromy's spectral radius about 1e3), with no grazing located. The end is reported
/// unconverged, with the bracket from the last point to the grazing extrapolated from the
/// branch; continued with largest steps 0.02 and 0.025 nm the last points lie 3.7e-5 nm apart
/// (measured), and the two brackets overlap (measured: widths 4.7e-5 and 7.8e-5 nm, the
/// extrapolated grazings 6.5e-6 nm apart), as brackets of one end must.
#[test]
fn sticky_unlocated_end_brackets_overlap() {
    let ends: Vec<DiagramSpecialPoint> = [0.02, 0.025]
        .iter()
        .map(|&step| {
            let retract = retract("biolever-sticky", 12.0, step);
            let end = retract
                .special_points
                .iter()
                .find(|p| p.label == "pull-off" && (p.z_nm - 4.2399).abs() < 1e-3)
                .expect("the branch end at 4.2399 nm")
                .clone();
            assert!(!end.converged, "{end:?}");
            assert_eq!(end.bracket_nm[0], end.z_nm);
            assert!(end.precision_nm > 0.0);
            end
        })
        .collect();
    let low = ends[0].bracket_nm[0].max(ends[1].bracket_nm[0]);
    let high = ends[0].bracket_nm[1].min(ends[1].bracket_nm[1]);
    assert!(
        low <= high,
        "brackets {:?} and {:?} do not overlap",
        ends[0].bracket_nm,
        ends[1].bracket_nm
    );
}
