//! The steady orbit without a previous orbit (`OrbitStart::Approach`) is the orbit of the
//! quasi-static approach: on every built-in case it equals the orbit of the continued approach
//! branch (`approach_diagram`, an independent computation: pseudo-arclength continuation from the
//! free orbit with located special points) at that branch's own separations, wherever the
//! branch holds one stable orbit per `Z`; above first contact it is the free orbit in closed
//! form; and inside the MAClever-on-mica bistable window just below first contact it is the
//! orbit of the branch coming from above, not the coexisting one.
//!
//! Tolerance: both orbits are Newton-converged to a residual of 1e-10 (nm, nm/us) on maps of
//! tolerance 1e-12, with multipliers well inside the unit circle, so their states agree to about
//! 1e-10 / (1 - spectral radius); 1e-8 leaves a factor 100 for a radius up to 0.99.

use afm::{
    approach_diagram, builtin_case, case_names, state_distance, steady_orbit, DiagramPoint,
    DiagramSettings, OrbitStart, SteadyOrbitSettings, TappingModel,
};

const STATE_TOLERANCE: f64 = 1e-8;

/// Check the approach start at the diagram point `point` of `model`.
fn check(model: &TappingModel, point: &DiagramPoint, case: &str) {
    let orbit = steady_orbit(
        model,
        point.z_nm,
        OrbitStart::Approach,
        &SteadyOrbitSettings::default(),
    )
    .expect("orbit");
    let distance = state_distance(&orbit.state, &point.state);
    assert!(
        orbit.converged && orbit.multiplicity == 1 && distance <= STATE_TOLERANCE,
        "{case} at Z = {} nm: converged {}, multiplicity {}, {distance:e} from the branch",
        point.z_nm,
        orbit.converged,
        orbit.multiplicity
    );
}

#[test]
fn equals_the_continued_approach_branch_where_it_is_the_only_attractor() {
    for name in case_names() {
        let model = TappingModel::from_case(&builtin_case(name).expect("case")).expect("model");
        let diagram =
            approach_diagram(&model, &DiagramSettings::approach(&model)).expect("diagram");
        let bistable = diagram.bistable_ranges();
        let z_g1 = model.grazing_separation_nm();
        let single: Vec<&DiagramPoint> = diagram
            .points
            .iter()
            .filter(|p| {
                p.stable
                    && p.multiplicity == 1
                    && p.z_nm < z_g1
                    && bistable
                        .iter()
                        .all(|[low, high]| p.z_nm < low - 0.01 || p.z_nm > high + 0.01)
            })
            .collect();
        assert!(single.len() >= 50, "{name}: {} points", single.len());
        // Ten points spread over the branch, its first and last among them.
        for k in 0..10 {
            check(&model, single[k * (single.len() - 1) / 9], name);
        }
    }
}

#[test]
fn is_the_free_orbit_above_first_contact() {
    let model =
        TappingModel::from_case(&builtin_case("biolever-mica").expect("case")).expect("model");
    for z in [model.grazing_separation_nm() + 1e-6, 15.0, 1e3] {
        let orbit = steady_orbit(
            &model,
            z,
            OrbitStart::Approach,
            &SteadyOrbitSettings::default(),
        )
        .expect("orbit");
        let distance = state_distance(&orbit.state, &model.free_state());
        assert!(
            orbit.converged && distance <= 1e-10 && orbit.observables().impacts.is_empty(),
            "Z = {z} nm: {distance:e} from the free orbit"
        );
    }
}

#[test]
fn follows_the_branch_from_above_inside_a_bistable_window() {
    let model =
        TappingModel::from_case(&builtin_case("maclever-mica").expect("case")).expect("model");
    let diagram = approach_diagram(&model, &DiagramSettings::approach(&model)).expect("diagram");
    let [low, high] = diagram.bistable_ranges()[0];
    // The branch from first contact down to its first fold (where Z first turns back up): the
    // part the approach follows.
    let first_fold = diagram
        .points
        .windows(2)
        .position(|w| w[1].z_nm > w[0].z_nm)
        .expect("a fold below first contact");
    let middle = 0.5 * (low + high);
    let from_above = diagram.points[..=first_fold]
        .iter()
        .filter(|p| p.stable)
        .min_by(|a, b| (a.z_nm - middle).abs().total_cmp(&(b.z_nm - middle).abs()))
        .expect("a stable point above the fold");
    assert!(
        (low..=high).contains(&from_above.z_nm),
        "the point lies in the window"
    );
    check(&model, from_above, "maclever-mica");
}
