//! The attached meniscus's flight outside contact (MODEL.md section 9, "Capillary meniscus"):
//! under the constant force `-F_m` each mode is the free flight about a rest position shifted
//! by `-F_m / k_i`, so the model offers its exact flow there. Checked against DOP853 on the
//! same equations (the model wrapped so that it offers no acceleration: every step integrated,
//! the transition matrix by the variational equations) at tolerance 1e-13, and the steady
//! orbit found with the exact flow and the Hertz series against the DOP853 period map.

use afm::model::{ATTACHED, CONTACT};
use afm::{builtin_case, steady_orbit, OrbitStart, Separation, SteadyOrbitSettings, TappingModel};
use hybrid::{
    flow_map, Direction, ExactFlow, HybridSystem, Mode, Sensitivity, Settings, SwitchingPartials,
};
use nalgebra::DMatrix;

/// The built-in air case: the silicon lever on mica at 40 % relative humidity.
const CASE: &str = "rectangular-air-mica-humid";

fn humid_model(z: f64) -> TappingModel {
    let mut model = TappingModel::from_case(&builtin_case(CASE).unwrap()).unwrap();
    model.set_separation(Separation::Constant(z)).unwrap();
    model
}

/// The model's equations with no acceleration: DOP853 in every mode.
struct Integrated<'a>(&'a TappingModel);

impl HybridSystem for Integrated<'_> {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn surface_count(&self) -> usize {
        self.0.surface_count()
    }
    fn vector_field(&self, mode: Mode, t: f64, x: &[f64], dxdt: &mut [f64]) {
        self.0.vector_field(mode, t, x, dxdt);
    }
    fn jacobian(&self, mode: Mode, t: f64, x: &[f64], jacobian: &mut DMatrix<f64>) {
        self.0.jacobian(mode, t, x, jacobian);
    }
    fn parameter_derivative(&self, mode: Mode, t: f64, x: &[f64], dfdp: &mut [f64]) {
        self.0.parameter_derivative(mode, t, x, dfdp);
    }
    fn switching(&self, k: usize, t: f64, x: &[f64]) -> f64 {
        self.0.switching(k, t, x)
    }
    fn switching_rate(&self, k: usize, mode: Mode, t: f64, x: &[f64]) -> f64 {
        self.0.switching_rate(k, mode, t, x)
    }
    fn switching_gradient(
        &self,
        k: usize,
        t: f64,
        x: &[f64],
        gradient: &mut [f64],
    ) -> SwitchingPartials {
        self.0.switching_gradient(k, t, x, gradient)
    }
    fn mode_after_crossing(
        &self,
        k: usize,
        direction: Direction,
        mode: Mode,
        crossed: Mode,
    ) -> Mode {
        self.0.mode_after_crossing(k, direction, mode, crossed)
    }
    fn mode_of(&self, t: f64, x: &[f64]) -> Mode {
        self.0.mode_of(t, x)
    }
}

fn tight() -> Settings {
    Settings {
        relative_tolerance: 1e-13,
        absolute_tolerance: 1e-13,
        ..Settings::default()
    }
}

/// Largest entry of `a - b` relative to the largest entry of `b`.
fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

/// A state of the built-in case at `Z` = 15 nm just after the tip left the sample with the
/// meniscus attached: gap 0.3 nm (below `d_r` = 1.17 nm), rising at `rate` (nm/us), at drive
/// phase `w t0` = 1.
fn attached_start(model: &TappingModel, rate: f64) -> (f64, Vec<f64>) {
    let t0 = 1.0 / model.drive_angular_frequency();
    (t0, vec![0.3 - 15.0, rate])
}

/// Over 0.05 us (the gap stays in the band: it reaches 0.49 nm) the attached flight is
/// the mode the model gives an exact flow, and it agrees with DOP853 at 1e-13 to 1e-12 of
/// the state and of the transition matrix (both relative to their largest entries; DOP853's
/// own error at that tolerance over a fiftieth of a period; measured 1.2e-16 and 1.4e-16).
/// The grid of nine states agrees with nine direct flows to 1e-14 (rounding of the phase
/// rotation; measured 1.5e-15).
#[test]
fn attached_flight_is_exact() {
    let model = humid_model(15.0);
    let (t0, x0) = attached_start(&model, 2.0);
    let mode = model.mode_of(t0, &x0);
    assert!(mode & ATTACHED != 0 && mode & CONTACT == 0, "mode {mode}");
    assert!(model.accelerations().has_exact_flow(mode));
    let dt = 0.05;
    let mut x = vec![0.0; 2];
    let mut transition = DMatrix::zeros(2, 2);
    model.exact_flow(mode, t0, &x0, dt, &mut x, Some(&mut transition), None);
    let reference = flow_map(
        &Integrated(&model),
        t0,
        &x0,
        dt,
        Sensitivity::Transition,
        &tight(),
    )
    .unwrap();
    assert!(reference.events.is_empty() && reference.mode == mode);
    let gap = model.gap(t0 + dt, &reference.state);
    assert!(
        gap > 0.3 && gap < model.release_gap_nm().unwrap(),
        "gap {gap}"
    );
    let state = relative_difference(&x, &reference.state);
    let matrix = relative_difference(transition.as_slice(), reference.transition.as_slice());
    assert!(state < 1e-12 && matrix < 1e-12, "{state:e} {matrix:e}");

    let mut grid = vec![0.0; 2 * 9];
    model.exact_flow_grid(mode, t0, &x0, dt, 9, &mut grid);
    for (j, point) in grid.chunks_exact(2).enumerate() {
        let mut direct = vec![0.0; 2];
        let step = dt * (j + 1) as f64 / 9.0;
        model.exact_flow(mode, t0, &x0, step, &mut direct, None, None);
        let difference = relative_difference(point, &direct);
        assert!(difference < 1e-14, "grid point {j}: {difference:e}");
    }
}

/// Through the meniscus's rupture, a flight, a contact and a return to the band, over a whole
/// drive period (exact steps while attached and in free flight, the Hertz series minus `F_m`
/// in contact) the solver's flow meets DOP853's: the same events (surface, direction, time
/// within 1e-11 periods; measured 1.5e-13 us), the state within 1e-11 (measured 1.6e-13) and
/// the transition matrix within 5e-8 (measured 1.4e-8: in contact DOP853's variational
/// equations and the Hertz series differ by up to 2.3e-8, `taylor_steps.rs`).
#[test]
fn rupture_and_period_match_dop853() {
    let model = humid_model(15.0);
    // Rising at 20 nm/us the tip's amplitude is about 17 nm: it ruptures the meniscus and
    // comes back into contact within the period.
    let (t0, x0) = attached_start(&model, 20.0);
    let duration = model.period_us();
    let accelerated =
        flow_map(&model, t0, &x0, duration, Sensitivity::Transition, &tight()).unwrap();
    let reference = flow_map(
        &Integrated(&model),
        t0,
        &x0,
        duration,
        Sensitivity::Transition,
        &tight(),
    )
    .unwrap();
    assert!(accelerated.statistics.exact_steps > 0 && accelerated.statistics.series_steps > 0);
    assert_eq!(accelerated.events.len(), reference.events.len());
    assert!(accelerated.events.len() >= 2, "{:?}", accelerated.events);
    for (a, b) in accelerated.events.iter().zip(&reference.events) {
        assert_eq!((a.surface, a.direction), (b.surface, b.direction));
        assert!((a.t - b.t).abs() < 1e-11 * duration, "{} vs {}", a.t, b.t);
    }
    let state = relative_difference(&accelerated.state, &reference.state);
    let matrix = relative_difference(
        accelerated.transition.as_slice(),
        reference.transition.as_slice(),
    );
    assert!(state < 1e-11 && matrix < 5e-8, "{state:e} {matrix:e}");
}

/// The stable period-1 orbit at `Z` = 16.56 nm (where the approach lands past the band of
/// intermittent taps), found with the exact attached flight and the contact series, is a
/// fixed point of DOP853's period map: `|P(x) - x|` below 1e-9 (Newton's tolerance 1e-10 plus
/// DOP853's error over a period at 1e-13; measured 3.5e-12), and DOP853's monodromy's spectral
/// radius within 1e-6 of the orbit's (measured 1.2e-8).
#[test]
fn steady_orbit_is_a_fixed_point_of_dop853() {
    let model = humid_model(16.56);
    let settings = SteadyOrbitSettings::default();
    let orbit = steady_orbit(&model, 16.56, OrbitStart::Approach, &settings).unwrap();
    assert!(orbit.converged && orbit.stable && orbit.multiplicity == 1);
    let reference = flow_map(
        &Integrated(&model),
        0.0,
        &orbit.state,
        model.period_us(),
        Sensitivity::Transition,
        &tight(),
    )
    .unwrap();
    let residual = reference
        .state
        .iter()
        .zip(&orbit.state)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        .sqrt();
    assert!(residual < 1e-9, "{residual:e}");
    let radius = |m: &DMatrix<f64>| {
        m.complex_eigenvalues()
            .iter()
            .fold(0.0_f64, |r, v| r.max(v.norm()))
    };
    let orbit_radius = orbit
        .multipliers
        .iter()
        .fold(0.0_f64, |r, v| r.max(v.norm()));
    let difference = (radius(&reference.transition) - orbit_radius).abs();
    assert!(difference < 1e-6, "{difference:e}");
}
