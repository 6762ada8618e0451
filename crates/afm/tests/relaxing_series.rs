//! The standard linear solid's Taylor-series steps in contact (MODEL.md section 9, "Standard
//! linear solid": the state with the sample's `rho`, its tangents, and the contact surface
//! `h_0 = d + rho^{2/3}` along them) against DOP853 everywhere (`Settings::taylor_series =
//! false`) and against central finite differences of that DOP853 flow: three drive periods of
//! the built-in `biolever-soft-viscoelastic` at Z = 8.5 nm (two impacts a period, the second on
//! a surface not yet recovered), from the steady orbit (`rho > 0`) and from the same state with a
//! recovered sample (`rho = 0`: the first contact enters at `d = 0`, Hertz's onset), with the
//! transition matrix and `dx/dZ`; under acoustic and bimodal drives; and the diagram's grazing
//! points against a finer DOP853 diagram.

use afm::model::drive_spec::DriveSpec;
use afm::{
    approach_diagram, builtin_case, steady_orbit, DiagramSettings, OrbitStart, Separation,
    SteadyOrbitSettings, TappingModel,
};
use hybrid::{FlowMap, Sensitivity};
use series_reference::{compare, periods, relative_difference, tight, FlowDifference};

mod series_reference;

fn model(z: f64) -> TappingModel {
    model_driven(z, DriveSpec::Direct)
}

/// The built-in case under drive `drive` at `Z = z`.
fn model_driven(z: f64, drive: DriveSpec) -> TappingModel {
    let mut case = builtin_case("biolever-soft-viscoelastic").expect("built-in case");
    case.drive = drive;
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

/// From `x0`: the series steps give DOP853's flow (the state to 1e-10 relative, the same events
/// to 1e-10 of a period, the transition matrix and `dx/dZ` to 1e-6 of their largest entries),
/// and the series' transition matrix is within 1e-6 of central differences of the DOP853 state
/// (step 1e-5 in each coordinate, whose truncation error, `h^2` times the flow's third
/// derivatives, and rounding, 1e-13 / h, are both below 1e-7 here). Measured: from the orbit
/// (`rho_0 = 2.9e-3`) 63 series steps of 156, the state within 1.6e-14, the transition matrix
/// 8.8e-10, `dx/dZ` 1.8e-10, against the differences 4.9e-8; from the recovered sample 59 of 153,
/// 1.3e-15, 6.6e-10, 1.8e-10, 8.9e-8.
fn check_from(model: &TappingModel, x0: &[f64]) {
    let series = three_periods(model, x0, Sensitivity::TransitionAndParameter, true);
    let reference = three_periods(model, x0, Sensitivity::TransitionAndParameter, false);
    assert_eq!(reference.statistics.series_steps, 0);
    let contacts = series
        .events
        .iter()
        .filter(|e| e.surface == 0 && e.direction == hybrid::Direction::Down)
        .count();
    assert!(contacts >= 6, "{contacts} contacts");
    assert!(
        series.statistics.series_steps >= 2 * contacts,
        "{:?}",
        series.statistics
    );
    let FlowDifference {
        state,
        transition,
        parameter,
    } = compare(model, &series, &reference, 1e-10);
    let n = x0.len();
    let h = 1e-5;
    let mut differences = vec![0.0; n * n];
    for j in 0..n {
        let (mut up, mut down) = (x0.to_vec(), x0.to_vec());
        up[j] += h;
        down[j] -= h;
        // rho stays non-negative.
        if down[j] < 0.0 && j == n - 1 {
            down[j] = 0.0;
            up[j] = 2.0 * h;
        }
        let a = three_periods(model, &up, Sensitivity::None, false);
        let b = three_periods(model, &down, Sensitivity::None, false);
        for i in 0..n {
            differences[j * n + i] = (a.state[i] - b.state[i]) / (up[j] - down[j]);
        }
    }
    let against_differences = relative_difference(series.transition.as_slice(), &differences);
    println!(
        "rho_0 = {:.3e}: series steps {} of {}; state {state:.1e}, transition {transition:.1e}, dx/dZ {parameter:.1e}, transition vs differences {against_differences:.1e}",
        x0[n - 1],
        series.statistics.series_steps,
        series.statistics.steps
    );
    assert!(state < 1e-10, "state {state:.2e}");
    assert!(transition < 1e-6, "transition {transition:.2e}");
    assert!(parameter < 1e-6, "dx/dZ {parameter:.2e}");
    assert!(
        against_differences < 1e-6,
        "against differences {against_differences:.2e}"
    );
}

#[test]
fn contact_series_steps_match_runge_kutta_and_finite_differences() {
    let z = 8.5;
    let model = model(z);
    let orbit = steady_orbit(
        &model,
        z,
        OrbitStart::Approach,
        &SteadyOrbitSettings::default(),
    )
    .expect("steady orbit");
    let x0 = orbit.state.clone();
    assert!(x0[4] > 1e-4, "rho = {}", x0[4]);
    check_from(&model, &x0);
    let mut recovered = x0;
    recovered[4] = 0.0;
    check_from(&model, &recovered);
}

/// The approach diagram's grazing points at the default tolerance (1e-12, contact by series)
/// against those of a finer reference, DOP853 everywhere at tolerance 1e-13: within 1e-10 nm
/// (measured: G1 1e-12, G2 1e-12, G3 7e-12 nm; DOP853 at the default tolerance, the path before
/// the series, was 3.3e-10 and 2.0e-9 nm off at G2 and G3).
#[test]
fn grazing_points_match_a_finer_runge_kutta_diagram() {
    let case = builtin_case("biolever-soft-viscoelastic").expect("built-in case");
    let model = TappingModel::from_case(&case).expect("model");
    let settings = DiagramSettings::approach(&model);
    let mut finer = settings.clone();
    finer.orbit.integration.relative_tolerance = 1e-13;
    finer.orbit.integration.absolute_tolerance = 1e-13;
    finer.orbit.integration.taylor_series = false;
    let diagram = approach_diagram(&model, &settings).expect("diagram");
    let reference = approach_diagram(&model, &finer).expect("reference diagram");
    let labels = |d: &afm::BifurcationDiagram| {
        d.special_points
            .iter()
            .map(|p| p.label.clone())
            .collect::<Vec<_>>()
    };
    assert_eq!(labels(&diagram), ["G1", "G2", "G3"]);
    assert_eq!(labels(&diagram), labels(&reference));
    for (a, b) in diagram.special_points.iter().zip(&reference.special_points) {
        println!("{}: {:.13} vs {:.13}", a.label, a.z_nm, b.z_nm);
        assert!(
            (a.z_nm - b.z_nm).abs() < 1e-10,
            "{} {} vs {}",
            a.label,
            a.z_nm,
            b.z_nm
        );
    }
}

/// Under an acoustic drive (the base motion in the gap and in `h_0`'s series) and a bimodal one
/// (a second drive at 8 `f_1`, `A0_b` = 1 nm), three periods from the free state with the sample
/// unrecovered (`rho` = 0.01 nm^{3/2}) at Z = 8.5 nm: the series steps give DOP853's state to
/// 1e-10 relative, its events to 1e-10 of a period and its transition matrix and `dx/dZ` to 1e-6
/// (all at tolerance 1e-13). Measured: acoustic 4.5e-14, 8.3e-9, 1.9e-9; bimodal 1.3e-13,
/// 1.5e-9, 5.1e-10.
#[test]
fn series_steps_match_runge_kutta_under_acoustic_and_bimodal_drives() {
    let z = 8.5;
    for drive in [
        DriveSpec::Acoustic {
            base_participation: None,
        },
        DriveSpec::Bimodal {
            second_frequency_khz: 8.0
                * builtin_case("biolever-soft-viscoelastic")
                    .map(|case| TappingModel::from_case(&case).expect("model"))
                    .expect("built-in case")
                    .drive_frequency_khz(),
            second_free_amplitude_nm: 1.0,
        },
    ] {
        let model = model_driven(z, drive.clone());
        let mut x0 = model.free_state();
        x0[4] = 0.01;
        let series = three_periods(&model, &x0, Sensitivity::TransitionAndParameter, true);
        let reference = three_periods(&model, &x0, Sensitivity::TransitionAndParameter, false);
        assert!(series.statistics.series_steps > 0, "{drive:?}");
        println!("{drive:?}");
        let FlowDifference {
            state,
            transition,
            parameter,
        } = compare(&model, &series, &reference, 1e-10);
        println!(
            "{drive:?}: state {state:.1e}, transition {transition:.1e}, dx/dZ {parameter:.1e}"
        );
        assert!(state < 1e-10, "{drive:?}: state {state:.2e}");
        assert!(transition < 1e-6, "{drive:?}: transition {transition:.2e}");
        assert!(parameter < 1e-6, "{drive:?}: dx/dZ {parameter:.2e}");
    }
}
