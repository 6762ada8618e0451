//! JKR's Taylor-series steps while attached (MODEL.md section 9, JKR: series reversion of
//! `b^4/R - k b = delta` in `b = sqrt(a)`, up to the approach to pull-off) against DOP853
//! everywhere (`Settings::taylor_series = false`) and against central finite differences of that
//! DOP853 flow: three drive periods of the Biolever on the built-in `adhesive-soft` sample (W =
//! 0.5 mJ/m^2) at Z = 3 nm (two attached contacts per period) from the steady orbit, with the
//! transition matrix and `dx/dZ`.

mod series_reference;

use afm::{builtin_case, steady_orbit, OrbitStart, Separation, SteadyOrbitSettings, TappingModel};
use hybrid::{FlowMap, Sensitivity};
use series_reference::{compare, periods, relative_difference, tight, FlowDifference};

fn model(z: f64) -> TappingModel {
    // (A separation of a few nm: the orbit's gap stays far from the finite-difference steps.)
    let case = builtin_case("biolever-adhesive").expect("built-in case");
    let mut model = TappingModel::from_case(&case).expect("model");
    model
        .set_separation(Separation::Constant(z))
        .expect("finite");
    model
}

/// Three drive periods from `x0`, by series in contact when `series`, at tolerance 1e-13.
fn three_periods(
    model: &TappingModel,
    x0: &[f64],
    sensitivity: Sensitivity,
    series: bool,
) -> FlowMap {
    periods(model, x0, 3.0, sensitivity, &tight(series))
}

/// Central differences of the DOP853 flow's state in each initial coordinate (step `h`, nm and
/// nm/us), column-major like the transition matrix.
fn state_differences(model: &TappingModel, x0: &[f64], h: f64) -> Vec<f64> {
    let n = x0.len();
    let mut differences = vec![0.0; n * n];
    for j in 0..n {
        let (mut up, mut down) = (x0.to_vec(), x0.to_vec());
        up[j] += h;
        down[j] -= h;
        let a = three_periods(model, &up, Sensitivity::None, false);
        let b = three_periods(model, &down, Sensitivity::None, false);
        for i in 0..n {
            differences[j * n + i] = (a.state[i] - b.state[i]) / (2.0 * h);
        }
    }
    differences
}

/// Central differences of the DOP853 flow's end state in `Z` (step `h`, nm) from `x0`.
fn separation_differences(z: f64, x0: &[f64], h: f64) -> Vec<f64> {
    let up = three_periods(&model(z + h), x0, Sensitivity::None, false);
    let down = three_periods(&model(z - h), x0, Sensitivity::None, false);
    up.state
        .iter()
        .zip(&down.state)
        .map(|(a, b)| (a - b) / (2.0 * h))
        .collect()
}

/// The series steps give DOP853's flow: the state to 1e-10 relative, the same events to 1e-10
/// of a period; the transition matrix and `dx/dZ` within 2e-4 of their largest entries of
/// central differences of the DOP853 state at step 1e-4 (nm, nm/us), a reference that the
/// differences at step 1e-3 confirm to 2e-6 (their truncation, `O(h^2)`, and their noise, the
/// integration's 1e-13 divided by `h`, both below that; at step 1e-6 the noise is 5e-5). The
/// series steps now run up to the approach to pull-off, where the slope `dF/dd` has its
/// square-root pole; DOP853 integrates the last approach on the square-root clock. Measured: 102
/// series steps of 210; the state within 5e-13 of DOP853's; against the differences the
/// transition matrix 8.7e-5 (DOP853's own 4.0e-5: both carry an error of that size near
/// pull-off that a tighter tolerance does not remove), `dx/dZ` 3.2e-5 (DOP853's 1.5e-5).
#[test]
fn attached_series_steps_match_runge_kutta_and_finite_differences() {
    let z = 3.0;
    let model = model(z);
    let orbit = steady_orbit(
        &model,
        z,
        OrbitStart::Approach,
        &SteadyOrbitSettings::default(),
    )
    .expect("steady orbit");
    let x0 = orbit.state.clone();
    let series = three_periods(&model, &x0, Sensitivity::TransitionAndParameter, true);
    let reference = three_periods(&model, &x0, Sensitivity::TransitionAndParameter, false);
    assert_eq!(reference.statistics.series_steps, 0);
    let attachments = series
        .events
        .iter()
        .filter(|e| e.surface == 0 && e.direction == hybrid::Direction::Down)
        .count();
    assert!(attachments >= 4, "{attachments} attachments");
    assert!(
        series.statistics.series_steps >= attachments,
        "{:?}",
        series.statistics
    );
    let FlowDifference {
        state,
        transition,
        parameter,
    } = compare(&model, &series, &reference, 1e-10);
    let differences = state_differences(&model, &x0, 1e-4);
    let coarse = state_differences(&model, &x0, 1e-3);
    let resolved = relative_difference(&coarse, &differences);
    let against_differences = relative_difference(series.transition.as_slice(), &differences);
    let reference_against_differences =
        relative_difference(reference.transition.as_slice(), &differences);
    let z_differences = separation_differences(z, &x0, 1e-4);
    let z_coarse = separation_differences(z, &x0, 1e-3);
    let z_resolved = relative_difference(&z_coarse, &z_differences);
    let parameter_against = relative_difference(&series.parameter_sensitivity, &z_differences);
    let reference_parameter_against =
        relative_difference(&reference.parameter_sensitivity, &z_differences);
    println!(
        "series steps {} of {}; against DOP853: state {state:.1e}, transition {transition:.1e}, dx/dZ {parameter:.1e}; against differences (resolved to {resolved:.1e}, dZ {z_resolved:.1e}): transition {against_differences:.1e} (DOP853's {reference_against_differences:.1e}), dx/dZ {parameter_against:.1e} (DOP853's {reference_parameter_against:.1e})",
        series.statistics.series_steps, series.statistics.steps
    );
    assert!(state < 1e-10, "state {state:.2e}");
    assert!(resolved < 2e-6, "differences resolved to {resolved:.2e}");
    assert!(
        z_resolved < 2e-6,
        "dZ differences resolved to {z_resolved:.2e}"
    );
    assert!(
        against_differences < 2e-4,
        "against differences {against_differences:.2e}"
    );
    assert!(
        parameter_against < 2e-4,
        "dx/dZ against differences {parameter_against:.2e}"
    );
}
