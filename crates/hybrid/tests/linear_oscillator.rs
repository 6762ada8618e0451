//! The forced damped linear oscillator against its closed-form solution: state, dense output,
//! transition matrix and parameter sensitivity; accuracy against tolerance.
#![allow(clippy::needless_range_loop)]

mod common;

use common::ForcedOscillator;
use hybrid::{
    flow_map, flow_map_observed, Sensitivity, SensitivityMethod, Settings, Solver, StepOutcome,
};

const X0: [f64; 2] = [0.4, -0.3];
const DURATION: f64 = 20.0;

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// At the default tolerances (1e-12), the state after 20 time units (about 4 periods) matches
/// the closed form to 1e-10 (global error accumulates over ~60 steps; the solution is O(1)).
/// The transition matrix and `dx/dA`, integrated as variational equations in the same RK
/// system, match the closed form to 1e-9 (they are not under error control).
#[test]
fn state_transition_and_parameter_sensitivity_match_exact_solution() {
    let system = ForcedOscillator::reference();
    let result = flow_map(
        &system,
        0.0,
        &X0,
        DURATION,
        Sensitivity::TransitionAndParameter,
        &Settings::default(),
    )
    .expect("integration succeeds");
    let (x, phi, dxda) = system.exact(0.0, X0, DURATION);
    let state_error = max_abs_diff(&result.state, &x);
    eprintln!(
        "state error {state_error:e}, statistics {:?}",
        result.statistics
    );
    assert!(state_error < 1e-10, "state error {state_error:e}");
    for i in 0..2 {
        for j in 0..2 {
            let e = (result.transition[(i, j)] - phi[i][j]).abs();
            assert!(e < 1e-9, "Phi[{i}{j}] error {e:e}");
        }
    }
    let s_error = max_abs_diff(&result.parameter_sensitivity, &dxda);
    eprintln!(
        "Phi {} vs {phi:?}; dx/dA error {s_error:e}",
        result.transition
    );
    assert!(s_error < 1e-9, "dx/dA error {s_error:e}");
    assert!(result.events.is_empty());
}

/// The dense output between steps (7th order) matches the closed form at 50 points per step
/// to 1e-10 at the default tolerances (its error is of the order of the local error).
#[test]
fn dense_output_matches_exact_solution() {
    let system = ForcedOscillator::reference();
    let mut worst: f64 = 0.0;
    let mut x = [0.0; 2];
    let mut observer = |solver: &Solver<ForcedOscillator>, _: &StepOutcome| {
        let (a, b) = solver.last_step();
        for i in 1..50 {
            let t = a + (b - a) * i as f64 / 50.0;
            solver.interpolate(t, &mut x);
            let (exact, _, _) = system.exact(0.0, X0, t);
            worst = worst.max(max_abs_diff(&x, &exact));
        }
    };
    flow_map_observed(
        &system,
        0.0,
        &X0,
        DURATION,
        Sensitivity::None,
        &Settings::default(),
        &mut observer,
    )
    .expect("integration succeeds");
    eprintln!("dense output error {worst:e}");
    assert!(worst < 1e-10, "dense output error {worst:e}");
}

/// Tolerance sweep: the global error falls with the tolerance (it stays within 1000 x rtol
/// over four periods for rtol = atol from 1e-6 to 1e-12) and the step count grows roughly
/// like tol^(-1/8) (between tolerances 1e-6 and 1e-12 the ratio is 10^(6/8) = 5.6; asserted
/// between 3 and 10), so error against mean step size has slope ~8.
#[test]
fn tolerance_sweep() {
    let system = ForcedOscillator::reference();
    let (exact, _, _) = system.exact(0.0, X0, DURATION);
    let mut steps = Vec::new();
    let mut errors = Vec::new();
    for exponent in [6, 8, 10, 12] {
        let tol = 10f64.powi(-exponent);
        let settings = Settings {
            relative_tolerance: tol,
            absolute_tolerance: tol,
            ..Settings::default()
        };
        let result = flow_map(&system, 0.0, &X0, DURATION, Sensitivity::None, &settings)
            .expect("integration succeeds");
        let error = max_abs_diff(&result.state, &exact);
        eprintln!("tol {tol:e}: error {error:e}, {:?}", result.statistics);
        assert!(error < 1e3 * tol, "tol {tol:e}: error {error:e}");
        steps.push(result.statistics.steps as f64);
        errors.push(error);
    }
    let ratio = steps[3] / steps[0];
    assert!((3.0..=10.0).contains(&ratio), "steps {steps:?}");
    // Empirical order: error ~ (mean step)^q, q = ln(e_6 / e_12) / ln(N_12 / N_6). Measured
    // 8.4 (errors 3.6e-6 .. 2.9e-12 over 24 .. 128 steps); DOP853 is 8th order.
    let order = (errors[0] / errors[3]).ln() / ratio.ln();
    eprintln!("empirical order {order:.2}");
    assert!((7.0..=9.5).contains(&order), "order {order}");
}

/// Regression guard: the statistics of this reference run (forced oscillator, 20 time units,
/// default settings, no sensitivity) were recorded from the current implementation, so that a
/// silent change of the algorithm shows. The accuracy of the same run is checked by
/// `state_transition_and_parameter_sensitivity_match_exact_solution`.
#[test]
fn statistics_are_pinned() {
    let system = ForcedOscillator::reference();
    let result = flow_map(
        &system,
        0.0,
        &X0,
        DURATION,
        Sensitivity::None,
        &Settings::default(),
    )
    .expect("integration succeeds");
    let s = result.statistics;
    eprintln!("{s:?}");
    assert_eq!(s.steps, PINNED_STEPS);
    assert_eq!(s.rejected_steps, PINNED_REJECTED);
    assert_eq!(s.rhs_evaluations, PINNED_RHS);
    assert_eq!(s.events, 0);
    assert_eq!(s.exact_steps, 0);
}

/// 128 accepted steps (about 0.16 time units each), none rejected.
const PINNED_STEPS: usize = 128;
const PINNED_REJECTED: usize = 0;
/// 15 evaluations per step (11 new stages, the end derivative, 3 dense-output stages) plus 2
/// for the starting-step heuristic.
const PINNED_RHS: usize = 1922;

/// With [`SensitivityMethod::Decoupled`] the transition matrix and `dx/dA` come from a
/// sixth-order method over the state's steps: against the closed form their error falls like
/// the sixth power of the step (the state's tolerance sets the steps), and the state is that
/// of a run without sensitivities to the last bit (its steps do not depend on them).
#[test]
fn decoupled_sensitivities_converge_at_sixth_order() {
    let system = ForcedOscillator::reference();
    let (_, phi, dxda) = system.exact(0.0, X0, DURATION);
    let error = |tolerance: f64| {
        let settings = Settings {
            relative_tolerance: tolerance,
            absolute_tolerance: tolerance,
            sensitivity_method: SensitivityMethod::Decoupled,
            ..Settings::default()
        };
        let decoupled = flow_map(
            &system,
            0.0,
            &X0,
            DURATION,
            Sensitivity::TransitionAndParameter,
            &settings,
        )
        .expect("integration succeeds");
        let state_only = flow_map(&system, 0.0, &X0, DURATION, Sensitivity::None, &settings)
            .expect("integration succeeds");
        assert_eq!(decoupled.state, state_only.state);
        let mut worst: f64 = max_abs_diff(&decoupled.parameter_sensitivity, &dxda);
        for i in 0..2 {
            for j in 0..2 {
                worst = worst.max((decoupled.transition[(i, j)] - phi[i][j]).abs());
            }
        }
        (worst, decoupled.statistics.steps)
    };
    let (coarse, coarse_steps) = error(1e-8);
    let (fine, fine_steps) = error(1e-12);
    eprintln!("decoupled: error {coarse:e} in {coarse_steps} steps, {fine:e} in {fine_steps}");
    let order = (coarse / fine).ln() / (fine_steps as f64 / coarse_steps as f64).ln();
    assert!((5.5..7.0).contains(&order), "observed order {order}");
    assert!(fine < 1e-5, "error at tolerance 1e-12: {fine:e}");
}
