//! Where a hysteretic law's approach branch gets stuck short of a grazing (the corrector fails
//! at the continuation's smallest step next to it) the diagram jumps to the orbit the
//! cantilever settles on; that end is reported as a special point, not converged, whose
//! bracket runs from the last point to the grazing extrapolated in `sqrt(|g|)`. Before, only a
//! retract reported it, and an approach jumped with no point at all (`biolever-sticky` with
//! A0 = 6 nm at 1.4945 nm, with A0 = 8 nm at largest step 0.02 at 5.5114 nm).

mod approach_retract;

use afm::BifurcationDiagram;
use approach_retract::{approach, model};

/// The approach diagram of `biolever-sticky` with free amplitude `a0_nm` (nm) and largest step
/// `max_step` (nm, `None`: the default).
fn sticky_approach(a0_nm: f64, max_step: Option<f64>) -> BifurcationDiagram {
    approach(&model("biolever-sticky", Some(a0_nm)), max_step)
}

/// The consecutive points `(z_before, z_after)` (nm) between which `A/A0` changes by more than
/// 0.1: jumps of the diagram between branches (a step along one branch changes it by less
/// than 0.01 here).
fn jumps(diagram: &BifurcationDiagram) -> Vec<(f64, f64)> {
    diagram
        .points
        .windows(2)
        .filter(|w| (w[0].amplitude_ratio - w[1].amplitude_ratio).abs() > 0.1)
        .map(|w| (w[0].z_nm, w[1].z_nm))
        .collect()
}

/// Every jump of the approach has a grazing (`G<n>` or `pull-off`) whose bracket meets the
/// interval from the last point before it to the first after it.
fn every_jump_is_reported(diagram: &BifurcationDiagram, what: &str) {
    let found = jumps(diagram);
    assert!(!found.is_empty(), "{what}: no jump");
    for (before, after) in found {
        let reported = diagram.special_points.iter().any(|p| {
            (p.label.starts_with('G') || p.label == "pull-off")
                && p.bracket_nm[0] <= before
                && p.bracket_nm[1] >= after
        });
        assert!(
            reported,
            "{what}: the jump from {before} to {after} nm has no grazing; special points {:?}",
            diagram
                .special_points
                .iter()
                .map(|p| (&p.label, p.z_nm, p.bracket_nm))
                .collect::<Vec<_>>()
        );
    }
}

#[test]
fn a_stuck_approach_reports_the_grazing_it_jumps_at() {
    every_jump_is_reported(&sticky_approach(6.0, None), "A0 6");
    every_jump_is_reported(&sticky_approach(8.0, Some(0.02)), "A0 8, largest step 0.02");
}

/// The unlocated `pull-off` of A0 = 8 nm at largest step 0.02 brackets the one extrapolated
/// and located (to its stated precision) by the run at step 0.03, an independent estimate.
#[test]
fn a_stuck_end_brackets_the_pull_off_located_at_another_step() {
    let stuck = sticky_approach(8.0, Some(0.02));
    let located = sticky_approach(8.0, Some(0.03));
    let in_range =
        |p: &&afm::DiagramSpecialPoint| p.label == "pull-off" && (5.4..5.6).contains(&p.z_nm);
    let end = stuck
        .special_points
        .iter()
        .find(in_range)
        .expect("a pull-off at the stuck end");
    let reference = located
        .special_points
        .iter()
        .find(in_range)
        .expect("a pull-off at 0.03");
    println!(
        "stuck end {} bracket {:?}; at 0.03: {} +- {:e}",
        end.z_nm, end.bracket_nm, reference.z_nm, reference.precision_nm
    );
    assert!(!end.converged);
    assert!(
        end.bracket_nm[0] <= reference.z_nm + reference.precision_nm
            && reference.z_nm - reference.precision_nm <= end.bracket_nm[1],
        "{} +- {:e} outside {:?}",
        reference.z_nm,
        reference.precision_nm,
        end.bracket_nm
    );
}
