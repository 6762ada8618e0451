//! The solver's Taylor-series steps in Hertz contact against DOP853 everywhere
//! (`Settings::taylor_series = false`): the same flow map, events and transition matrix over
//! three drive periods of the Biolever on mica at the paper's Fig. 1 point A/A0 = 0.5 (three
//! impacts per period), from the free orbit (so the first period's contacts are a transient).
//! Measured: 94 series steps for the 9 contacts where DOP853 takes 418 steps in all; event
//! times within 6e-11 us, the state within 1.1e-12, the transition matrix within 4.9e-9
//! (coupled: tangents at the state's order) and 4.2e-6 (decoupled: order 12), relative to
//! their largest entries.

mod common;
mod series_reference;

use afm::{builtin_case, Separation, TappingModel};
use hybrid::{
    Clock, Direction, FlowMap, Sensitivity, SensitivityMethod, Settings, Solver, StepOutcome,
};
use series_reference::{compare, periods, relative_difference, tight, FlowDifference};

/// The separation of the Fig. 1 point A/A0 = 0.5 on the approach branch (nm).
const Z_HALF_AMPLITUDE: f64 = 2.733_156_827_672_611;

fn model() -> TappingModel {
    let case = builtin_case("biolever-mica").expect("built-in case");
    let mut model = TappingModel::from_case(&case).expect("model");
    model
        .set_separation(Separation::Constant(Z_HALF_AMPLITUDE))
        .expect("finite");
    model
}

/// Three drive periods from the free orbit with the transition matrix.
fn three_periods(model: &TappingModel, settings: &Settings) -> FlowMap {
    periods(
        model,
        &model.free_state(),
        3.0,
        Sensitivity::Transition,
        settings,
    )
}

#[test]
fn series_steps_reproduce_the_runge_kutta_flow_events_and_transition() {
    let model = model();
    let reference = three_periods(&model, &tight(false));
    assert_eq!(reference.statistics.series_steps, 0);
    for (method, transition_tolerance) in [
        (SensitivityMethod::Coupled, 5e-8),
        (SensitivityMethod::Decoupled, 2e-5),
    ] {
        let series = three_periods(
            &model,
            &Settings {
                sensitivity_method: method,
                ..tight(true)
            },
        );
        // Every contact stepped by series (several steps per contact), none by DOP853.
        let contacts = series
            .events
            .iter()
            .filter(|e| e.direction == Direction::Down)
            .count();
        assert!(contacts >= 9, "{contacts} contacts in three periods");
        assert!(series.statistics.series_steps >= 2 * contacts);
        let FlowDifference {
            state, transition, ..
        } = compare(&model, &series, &reference, 1e-12);
        assert!(state < 2e-11, "{method:?}: state {state:.2e}");
        assert!(
            transition < transition_tolerance,
            "{method:?}: transition {transition:.2e}"
        );
    }
}

/// One, three and four modes (the recurrences' other unrolled mode counts and the tangent
/// recurrence's column blocks: 3, 7 and 9 tangent columns with `dx/dZ`, the last a block of 8
/// and a single column), 1.5 nm into mica: two periods with the transition matrix and
/// `dx/dZ`, series against DOP853 alone. Measured: 22 and 57 series steps for one and three
/// modes; the state within 7.3e-14, 2.2e-13 and 6.0e-13, the transition matrix within 2.1e-9,
/// 2.3e-8 and 1.7e-8, `dx/dZ` within 1.9e-9, 1.4e-8 and 6.1e-8 (the four-mode bar on the
/// sensitivities 1e-7, the others 5e-8).
#[test]
fn series_steps_match_runge_kutta_for_one_three_and_four_modes() {
    let third = (12.0, 210.0, 3.0, 5.9, 0.35);
    let fourth = (46.0, 410.0, 4.0, 8.4, -0.2);
    let biolever = [(0.036, 9.3, 1.2, 1.0, 1.0), (1.4, 72.0, 2.0, 3.47, -0.554)];
    for (modes, sensitivity_bar) in [
        (&biolever[..1], 5e-8),
        (&[biolever[0], biolever[1], third][..], 5e-8),
        (&[biolever[0], biolever[1], third, fourth][..], 1e-7),
    ] {
        let mut model = TappingModel::new(
            common::cantilever(modes),
            common::mica(),
            10.0,
            None,
            Separation::Constant(0.0),
        )
        .expect("model");
        let z = model.grazing_separation_nm() - 1.5;
        model
            .set_separation(Separation::Constant(z))
            .expect("finite");
        let sensitivity = Sensitivity::TransitionAndParameter;
        let x0 = model.free_state();
        let reference = periods(&model, &x0, 2.0, sensitivity, &tight(false));
        let series = periods(&model, &x0, 2.0, sensitivity, &tight(true));
        // At least two series steps per contact (two events each).
        assert!(series.statistics.series_steps >= series.events.len());
        assert!(series.events.len() >= 4, "{} events", series.events.len());
        let n = modes.len();
        let FlowDifference {
            state,
            transition,
            parameter,
        } = compare(&model, &series, &reference, 1e-12);
        eprintln!(
            "{n} modes: state {state:.3e} transition {transition:.3e} parameter {parameter:.3e}"
        );
        assert!(state < 2e-11, "{n} modes: state {state:.2e}");
        assert!(
            transition < sensitivity_bar,
            "{n} modes: transition {transition:.2e}"
        );
        assert!(
            parameter < sensitivity_bar,
            "{n} modes: dx/dZ {parameter:.2e}"
        );
    }
}

/// `Solver::interpolate_clock` (the quadratures' nodes, on a Taylor step evaluated together)
/// gives the states `Solver::interpolate` gives at the same instants, over one period at
/// A/A0 = 0.5 (series steps on the square-root clocks, exact flow, the DOP853 landing): within
/// the rounding of the round trip through time (measured 2.6e-15 relative; asserted 1e-13).
#[test]
fn clock_interpolation_equals_time_interpolation() {
    let model = model();
    let x0 = model.free_state();
    let mut solver =
        Solver::new(&model, 0.0, &x0, Sensitivity::None, Settings::default()).expect("valid start");
    let n = x0.len();
    let (mut series_steps, mut worst) = (0, 0.0f64);
    loop {
        let outcome = solver
            .step(model.period_us())
            .expect("integration succeeds");
        let clock = solver.last_step_clock();
        let (a, b) = solver.last_step();
        let (sigma_a, sigma_b) = (clock.sigma(a), clock.sigma(b));
        let sigma: Vec<f64> = (1..=7)
            .map(|j| sigma_a + (sigma_b - sigma_a) * j as f64 / 8.0)
            .collect();
        let mut together = vec![0.0; sigma.len() * n];
        solver.interpolate_clock(&sigma, &mut together);
        let mut alone = vec![0.0; n];
        for (&reading, state) in sigma.iter().zip(together.chunks_exact(n)) {
            solver.interpolate(clock.time(reading), &mut alone);
            worst = worst.max(relative_difference(state, &alone));
        }
        if matches!(clock, Clock::SquareRoot { .. }) {
            series_steps += 1;
        }
        if outcome == StepOutcome::EndTime {
            break;
        }
    }
    assert!(
        series_steps >= 10,
        "{series_steps} steps on a square-root clock"
    );
    assert!(worst < 1e-13, "worst relative difference {worst:.2e}");
}
