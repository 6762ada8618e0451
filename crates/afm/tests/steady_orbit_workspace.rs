//! `steady_orbit_in` with one workspace along a branch gives the same orbits, to the bit, as
//! `steady_orbit` with fresh solvers: the Biolever on mica from a cold start at Z = 8.9 nm (one
//! impact per period) down to 8.6 nm, past G2 at 8.72 nm (two impacts), each orbit from the last.

use afm::{
    builtin_case, steady_orbit, steady_orbit_in, OrbitStart, SteadyOrbitSettings,
    SteadyOrbitWorkspace, TappingModel,
};

#[test]
fn a_reused_workspace_gives_the_same_orbits() {
    let case = builtin_case("biolever-mica").expect("built-in case");
    let model = TappingModel::from_case(&case).expect("model");
    let settings = SteadyOrbitSettings::default();
    let mut workspace = SteadyOrbitWorkspace::default();
    let (mut fresh_start, mut reused_start): (Option<Vec<f64>>, Option<Vec<f64>>) = (None, None);
    let mut impacts = Vec::new();
    for step in 0..5 {
        let z = 8.9 - 0.075 * f64::from(step);
        let fresh = steady_orbit(
            &model,
            z,
            OrbitStart::near_or_transient(fresh_start.as_deref()),
            &settings,
        )
        .expect("fresh");
        let reused = steady_orbit_in(
            &model,
            z,
            OrbitStart::near_or_transient(reused_start.as_deref()),
            &settings,
            &mut workspace,
        )
        .expect("reused");
        assert!(fresh.converged, "Z = {z}");
        assert_eq!(
            serde_json::to_string(&fresh).expect("json"),
            serde_json::to_string(&reused).expect("json"),
            "Z = {z}"
        );
        impacts.push(fresh.observables().impacts.len());
        fresh_start = Some(fresh.state);
        reused_start = Some(reused.state);
    }
    assert_eq!(impacts.first(), Some(&1));
    assert_eq!(impacts.last(), Some(&2));
}
