//! The AFM model's steps allocate nothing on the heap except `Event::state`, from the first
//! step of a new solver on: two drive periods of the Biolever on mica at the Fig. 1 point
//! A/A0 = 0.5 (three impacts per period: Taylor-series steps in contact with their tangent
//! series, exact flow with its grid samples in free flight, onsets and releases), with every
//! sensitivity and both sensitivity methods, counted by a global allocator wrapper. The
//! solver's own construction allocates; a restart and a solver on the first one's workspace do
//! not, and repeat the run exactly.

use afm::{builtin_case, Separation, TappingModel};
use hybrid::{Sensitivity, SensitivityMethod, Settings, Solver, StepOutcome};

#[path = "../../hybrid/tests/allocation_counter/mod.rs"]
mod allocation_counter;

use allocation_counter::{allocations, count_this_thread};

/// The separation of the Fig. 1 point A/A0 = 0.5 on the approach branch (nm).
const Z_HALF_AMPLITUDE: f64 = 2.733_156_827_672_611;

/// Allocations during the steps of two periods from `x0`, minus one per event (its `state`),
/// and the number of Taylor-series steps taken.
fn run_counting(solver: &mut Solver<TappingModel>, t_end: f64) -> (usize, u64) {
    let mut events = 0;
    let before = allocations();
    loop {
        match solver.step(t_end).expect("integration succeeds") {
            StepOutcome::Event(_) => events += 1,
            StepOutcome::Internal => {}
            StepOutcome::EndTime => break,
        }
    }
    let after = allocations();
    assert!(
        events >= 12,
        "two periods of three impacts: {events} events"
    );
    (
        after - before - events,
        solver.statistics().series_steps as u64,
    )
}

#[test]
fn contact_and_free_flight_steps_do_not_allocate() {
    let case = builtin_case("biolever-mica").expect("built-in case");
    let mut model = TappingModel::from_case(&case).expect("model");
    model
        .set_separation(Separation::Constant(Z_HALF_AMPLITUDE))
        .expect("finite");
    let x0 = model.free_state();
    let t_end = 2.0 * model.period_us();
    count_this_thread();
    for (sensitivity, method) in [
        (Sensitivity::None, SensitivityMethod::Coupled),
        (Sensitivity::Transition, SensitivityMethod::Coupled),
        (Sensitivity::Transition, SensitivityMethod::Decoupled),
        (
            Sensitivity::TransitionAndParameter,
            SensitivityMethod::Coupled,
        ),
        (
            Sensitivity::TransitionAndParameter,
            SensitivityMethod::Decoupled,
        ),
    ] {
        let settings = Settings {
            sensitivity_method: method,
            ..Settings::default()
        };
        let label = format!("{sensitivity:?}, {method:?}");
        let mut solver =
            Solver::new(&model, 0.0, &x0, sensitivity, settings.clone()).expect("valid");
        let (first, series_steps) = run_counting(&mut solver, t_end);
        assert!(series_steps >= 12, "{label}: {series_steps} series steps");
        assert_eq!(first, 0, "{label}: the first run");
        let final_state = solver.state().to_vec();
        let before = allocations();
        solver.restart(0.0, &x0).expect("valid");
        let restart = allocations() - before;
        let (second, _) = run_counting(&mut solver, t_end);
        assert_eq!(restart + second, 0, "{label}: after a restart");
        assert_eq!(solver.state(), &final_state[..]);
        let workspace = solver.into_workspace();
        let before = allocations();
        let mut solver = Solver::with_workspace(&model, 0.0, &x0, sensitivity, settings, workspace)
            .expect("valid");
        let construction = allocations() - before;
        let (third, _) = run_counting(&mut solver, t_end);
        assert_eq!(
            construction + third,
            0,
            "{label}: on the first one's workspace"
        );
        assert_eq!(solver.state(), &final_state[..]);
    }
}
