//! The branch's slope `dx/dZ` carried by each steady orbit, and orbits predicted from it: the
//! slope against central differences of converged orbits, the cubic Hermite prediction's
//! fourth order on the real branch, and Newton from a prediction converging to the same orbit
//! as from a neighbour, in one update. At the paper's Fig. 1 points (Biolever on mica,
//! A/A0 = 0.95, 0.90, 0.50).

use afm::{
    builtin_case, hermite_state, state_distance, steady_orbit, tangent_state, AfmError, OrbitStart,
    SteadyOrbit, SteadyOrbitSettings, TappingModel,
};

/// The Fig. 1 separations (nm), to the digits `drumroll simulate --amplitude-ratio` gives.
const FIGURE_1_Z_NM: [f64; 3] = [9.279985, 8.518336, 2.733157];

fn model() -> TappingModel {
    TappingModel::from_case(&builtin_case("biolever-mica").expect("case")).expect("model")
}

/// The default settings, whose Newton maps carry the monodromy and `dP/dZ` decoupled from the
/// state's steps (about 1e-6 relative), or with `sensitivity_tolerance` set, coupled and
/// error-controlled.
fn settings(sensitivity_tolerance: Option<f64>) -> SteadyOrbitSettings {
    let mut settings = SteadyOrbitSettings::default();
    settings.integration.sensitivity_tolerance = sensitivity_tolerance;
    settings
}

fn orbit(
    model: &TappingModel,
    z: f64,
    start: OrbitStart<'_>,
    settings: &SteadyOrbitSettings,
) -> SteadyOrbit {
    let orbit = steady_orbit(model, z, start, settings).expect("orbit");
    assert!(orbit.converged && orbit.multiplicity == 1, "Z = {z}");
    orbit
}

fn norm(a: &[f64]) -> f64 {
    state_distance(a, &vec![0.0; a.len()])
}

/// Orbits 0.04, 0.03, 0.02 and 0.01 nm above `z`, each from the one above it, as an approach
/// meets them.
fn approach_to(model: &TappingModel, z: f64, settings: &SteadyOrbitSettings) -> Vec<SteadyOrbit> {
    let mut above = vec![orbit(model, z + 0.04, OrbitStart::Transient, settings)];
    for k in [3.0, 2.0, 1.0] {
        let start = above.last().expect("orbit").state.clone();
        above.push(orbit(
            model,
            z + 0.01 * k,
            OrbitStart::Near(&start),
            settings,
        ));
    }
    above
}

#[test]
fn the_tangent_is_the_slope_of_the_branch() {
    let model = model();
    let h = 1e-4;
    // (sensitivity tolerance, bound on |dx/dZ - central difference| / (1 + |dx/dZ|)): the
    // decoupled sensitivities' 1e-6 relative error, or the coupled ones' control; the central
    // difference's own error (truncation x''' h^2 / 6, rounding 1e-12 / h) is ~1e-8.
    for (sensitivity_tolerance, bound) in [(None, 1e-5), (Some(1e-9), 1e-7)] {
        let settings = settings(sensitivity_tolerance);
        for z in FIGURE_1_Z_NM {
            let centre = orbit(&model, z, OrbitStart::Transient, &settings);
            let above = orbit(&model, z + h, OrbitStart::Near(&centre.state), &settings);
            let below = orbit(&model, z - h, OrbitStart::Near(&centre.state), &settings);
            let central: Vec<f64> = above
                .state
                .iter()
                .zip(&below.state)
                .map(|(a, b)| (a - b) / (2.0 * h))
                .collect();
            let tangent = centre.tangent.as_ref().expect("tangent");
            let error = state_distance(tangent, &central);
            assert!(
                error <= bound * (1.0 + norm(tangent)),
                "Z = {z}, {sensitivity_tolerance:?}: |dx/dZ - central difference| = {error:e}, \
                 |dx/dZ| = {:e}",
                norm(tangent)
            );
        }
    }
}

#[test]
fn a_hermite_prediction_converges_in_one_newton_update() {
    let model = model();
    let settings = settings(None);
    for z in FIGURE_1_Z_NM {
        let above = approach_to(&model, z, &settings);
        let (second, neighbour) = (&above[2], &above[3]);
        let from_neighbour = orbit(&model, z, OrbitStart::Near(&neighbour.state), &settings);
        let prediction = hermite_state(z, second, neighbour).expect("prediction");
        let from_prediction = orbit(&model, z, OrbitStart::Predicted(&prediction), &settings);
        assert!(
            from_prediction.iterations <= 1,
            "Z = {z}: {} Newton updates from the prediction",
            from_prediction.iterations
        );
        let apart = state_distance(&from_prediction.state, &from_neighbour.state);
        assert!(apart <= 1e-10, "Z = {z}: the two orbits {apart:e} nm apart");

        // Far better than the tangent line (by 270 to 1400 times), itself better than the
        // neighbour's state (by 10 to 150 times).
        let exact = &from_neighbour.state;
        let error = state_distance(&prediction, exact);
        let line_error = state_distance(&tangent_state(z, neighbour).expect("line"), exact);
        let neighbour_error = state_distance(&neighbour.state, exact);
        assert!(
            error < 0.02 * line_error && line_error < 0.5 * neighbour_error,
            "Z = {z}: cubic {error:e}, tangent line {line_error:e}, neighbour {neighbour_error:e}"
        );
    }
}

#[test]
fn the_hermite_prediction_is_of_fourth_order_on_the_branch() {
    // With error-controlled tangents (with the decoupled ones, their 1e-6 relative error adds
    // about `4 h |dx/dZ| 1e-6`, which dominates at A/A0 = 0.95 for h = 0.01 nm): from orbits
    // twice as far apart (0.02 and 0.04 nm above instead of 0.01 and 0.02), the error of the
    // extrapolation one interval ahead grows by 2^4 = 16.
    let model = model();
    let settings = settings(Some(1e-9));
    for z in FIGURE_1_Z_NM {
        let above = approach_to(&model, z, &settings);
        let exact = orbit(&model, z, OrbitStart::Near(&above[3].state), &settings).state;
        let fine = state_distance(
            &hermite_state(z, &above[2], &above[3]).expect("fine"),
            &exact,
        );
        let coarse = state_distance(
            &hermite_state(z, &above[0], &above[2]).expect("coarse"),
            &exact,
        );
        let ratio = coarse / fine;
        assert!(
            (12.0..=24.0).contains(&ratio),
            "Z = {z}: errors {coarse:e} (h = 0.02) and {fine:e} (h = 0.01), ratio {ratio}"
        );
    }
}

#[test]
fn a_start_of_the_wrong_size_or_not_finite_is_refused() {
    let model = model();
    let settings = SteadyOrbitSettings::default();
    for start in [vec![1.0, 0.0], vec![f64::NAN, 0.0, 0.0, 0.0]] {
        for kind in [OrbitStart::Near(&start), OrbitStart::Predicted(&start)] {
            match steady_orbit(&model, 8.0, kind, &settings) {
                Err(AfmError::InvalidField { field, .. }) => assert_eq!(field, "start"),
                other => panic!("{start:?}: {other:?}"),
            }
        }
    }
}
