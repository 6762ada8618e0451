//! The coexistence check of a cold orbit (`coexisting_orbit`, which stops the transient start
//! as soon as its transient enters the found orbit's basin) gives the answer of the check done
//! in full: the transient start's own orbit (20 transient periods, Newton, recurrence) compared
//! with the approach start's at `COEXISTING_DISTANCE`. On every built-in case at separations
//! across its approach, and inside the MAClever-on-mica bistable window just below first
//! contact.
//!
//! Where they differ, the fast check runs the transient start's Newton from the same iterate,
//! so its orbit equals the full check's to rounding: 1e-12 (nm, nm/us). The fast check's
//! linearisation test (a transient that moves as the found orbit's monodromy predicts) must
//! not stop a transient that heads for another orbit: from the retract orbit of the bistable
//! window, the check finds the approach orbit.

use afm::orbit::steady_orbit::{coexisting_orbit, COEXISTING_DISTANCE};
use afm::{
    builtin_case, case_names, state_distance, steady_orbit, OrbitStart, SteadyOrbitSettings,
    TappingModel,
};

fn compare(model: &TappingModel, z: f64, case: &str) -> bool {
    let settings = SteadyOrbitSettings::default();
    let orbit = steady_orbit(model, z, OrbitStart::Approach, &settings).expect("approach orbit");
    let fast = coexisting_orbit(model, &orbit, OrbitStart::Transient, &settings);
    let full = steady_orbit(model, z, OrbitStart::Transient, &settings)
        .ok()
        .filter(|other| {
            orbit.converged && other.converged && !orbit.is_same_orbit(other, COEXISTING_DISTANCE)
        });
    match (&fast, &full) {
        (None, None) => false,
        (Some(fast), Some(full)) => {
            let distance = state_distance(&fast.state, &full.state);
            assert!(
                distance <= 1e-12 && fast.multiplicity == full.multiplicity,
                "{case} at Z = {z} nm: the coexisting orbits differ by {distance:e}"
            );
            true
        }
        _ => panic!(
            "{case} at Z = {z} nm: fast check {}, full check {}",
            fast.is_some(),
            full.is_some()
        ),
    }
}

#[test]
fn the_fast_check_agrees_with_the_full_one_on_every_case() {
    for name in case_names() {
        let model = TappingModel::from_case(&builtin_case(name).expect("case")).expect("model");
        let z_g1 = model.grazing_separation_nm();
        for fraction in [1.02, 0.97, 0.8, 0.5, 0.2] {
            compare(&model, fraction * z_g1, name);
        }
    }
}

#[test]
fn inside_the_bistable_window_both_checks_agree() {
    // The window Z in [19.995844456, 19.998175421] nm of `continue --case maclever-mica
    // --retract` (docs/guide/continue.md): both starts come from above and reach the approach
    // branch's orbit, which both checks must see (the retract branch's orbit is reached from
    // below only).
    let model =
        TappingModel::from_case(&builtin_case("maclever-mica").expect("case")).expect("model");
    for z in [19.9959, 19.9962, 19.997, 19.9975, 19.9981] {
        compare(&model, z, "maclever-mica");
    }
}

#[test]
fn the_retract_orbit_of_the_bistable_window_has_the_approach_orbit_beside_it() {
    // Below the window the approach reaches the retract branch's orbit; followed up into the
    // window (at 19.997 nm) it coexists with the approach branch's, which the transient from
    // the free state reaches. The check from the retract orbit must find that one (the
    // linearisation test must not take the transient for the retract orbit's), equal to the
    // full check's and to the approach start's own orbit to Newton's tolerance.
    let model =
        TappingModel::from_case(&builtin_case("maclever-mica").expect("case")).expect("model");
    let settings = SteadyOrbitSettings::default();
    let below = steady_orbit(&model, 19.995, OrbitStart::Approach, &settings).expect("below");
    let mut retract = below;
    for z in [19.996, 19.997] {
        retract = steady_orbit(&model, z, OrbitStart::Near(&retract.state), &settings)
            .expect("retract orbit");
    }
    let approach = steady_orbit(&model, 19.997, OrbitStart::Approach, &settings).expect("approach");
    assert!(retract.converged && retract.stable && approach.converged && approach.stable);
    let apart = state_distance(&retract.state, &approach.state);
    assert!(
        apart > 1e3 * COEXISTING_DISTANCE,
        "the two branches' orbits are {apart:e} apart"
    );
    let found = coexisting_orbit(&model, &retract, OrbitStart::Transient, &settings)
        .expect("the transient start's orbit beside the retract orbit");
    assert!(
        state_distance(&found.state, &approach.state) <= 1e-9,
        "the coexisting orbit is not the approach orbit: {:e}",
        state_distance(&found.state, &approach.state)
    );
    // And from the approach orbit, the transient start finds nothing else.
    assert!(coexisting_orbit(&model, &approach, OrbitStart::Transient, &settings).is_none());
}
