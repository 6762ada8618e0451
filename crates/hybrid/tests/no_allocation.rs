//! `Solver::step` allocates nothing on the heap except `Event::state`: counted with a global
//! allocator wrapper over a run with many steps and events (RK and exact flow, with and
//! without sensitivities).

mod common;

use common::{HertzOscillator, ImpactOscillator, Rotation};
use hybrid::{HybridSystem, Sensitivity, Settings, Solver, StepOutcome};

mod allocation_counter;

use allocation_counter::{allocations, count_this_thread};

/// Allocations during the steps of a run, minus one per event (its `state` vector). The run
/// is made three times: after `Solver::restart`, and by a solver built by
/// `Solver::with_workspace` on the buffers of the first (neither may allocate), and every run
/// must give the same final state and statistics.
fn allocations_beyond_events<S: HybridSystem>(system: &S, x0: &[f64], s: Sensitivity) -> usize {
    let mut solver = Solver::new(system, 0.0, x0, s, Settings::default()).expect("valid");
    let first = run_counting(&mut solver);
    let final_state = solver.state().to_vec();
    let statistics = *solver.statistics();
    let before = allocations();
    solver.restart(0.0, x0).expect("valid");
    let restart = allocations() - before;
    let second = run_counting(&mut solver);
    assert_eq!(solver.state(), &final_state[..]);
    assert_eq!(*solver.statistics(), statistics);
    // A new solver on the first one's buffers: no allocation, and the same run again.
    let workspace = solver.into_workspace();
    let before = allocations();
    let mut solver =
        Solver::with_workspace(system, 0.0, x0, s, Settings::default(), workspace).expect("valid");
    let reuse = allocations() - before;
    let third = run_counting(&mut solver);
    assert_eq!(solver.state(), &final_state[..]);
    assert_eq!(*solver.statistics(), statistics);
    first + restart + second + reuse + third
}

fn run_counting<S: HybridSystem>(solver: &mut Solver<S>) -> usize {
    let mut events = 0;
    let mut steps = 0;
    let before = allocations();
    loop {
        match solver.step(30.0).expect("integration succeeds") {
            StepOutcome::Event(_) => events += 1,
            StepOutcome::Internal => {}
            StepOutcome::EndTime => break,
        }
        steps += 1;
    }
    let after = allocations();
    assert!(
        events > 3 && steps > 50,
        "a run with events: {events}, {steps}"
    );
    after - before - events
}

#[test]
fn steps_do_not_allocate() {
    count_this_thread();
    for s in [
        Sensitivity::None,
        Sensitivity::Transition,
        Sensitivity::TransitionAndParameter,
    ] {
        assert_eq!(
            allocations_beyond_events(&HertzOscillator::reference(), &[0.0, 0.0], s),
            0
        );
        assert_eq!(
            allocations_beyond_events(&ImpactOscillator::reference(), &[0.0, 0.0], s),
            0
        );
        let rotation = Rotation {
            c: 0.3,
            t_c: 0.0,
            exact_flow_limit: Some(0.5),
            curvature_bound: false,
            affine: false,
        };
        assert_eq!(
            allocations_beyond_events(&rotation, &rotation.initial_state(), s),
            0
        );
    }
}

/// Buffers of another shape (here sized for sensitivities) are replaced, not misused: the run
/// on them equals a run from `Solver::new`.
#[test]
fn a_workspace_of_another_shape_is_replaced() {
    let system = HertzOscillator::reference();
    let x0 = [0.0, 0.0];
    let mut reference =
        Solver::new(&system, 0.0, &x0, Sensitivity::None, Settings::default()).expect("valid");
    run_counting(&mut reference);
    let sized_for_sensitivities = Solver::new(
        &system,
        0.0,
        &x0,
        Sensitivity::TransitionAndParameter,
        Settings::default(),
    )
    .expect("valid")
    .into_workspace();
    let mut solver = Solver::with_workspace(
        &system,
        0.0,
        &x0,
        Sensitivity::None,
        Settings::default(),
        sized_for_sensitivities,
    )
    .expect("valid");
    run_counting(&mut solver);
    assert_eq!(solver.state(), reference.state());
    assert_eq!(solver.statistics(), reference.statistics());
}
