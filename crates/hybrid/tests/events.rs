//! Event location: a dip through a surface far shorter than a step, events and extrema each
//! reported exactly once, and exact-flow steps against Runge-Kutta steps.
#![allow(clippy::needless_range_loop)]

mod common;

use std::f64::consts::PI;

use common::{ForcedOscillator, Rotation};
use hybrid::{flow_map, Direction, ExtremumKind, Sensitivity, Settings};

/// `h = c - cos(t - t_c)` with `c = 1 - 1e-6`: `h` dips below zero for `2 acos(c) = 2.8e-3`
/// time units around `t_c`. With the exact flow (steps of 1.5, samples every 1/6) no sample
/// falls inside the dip; the dip must be found through its negative minimum. Closed form:
/// crossings at `t_c -+ acos(c)`, minimum at `t_c` with value `c - 1`. Tolerances: the exact
/// flow is exact to rounding, the crossing rate is `sin(acos c) = 1.4e-3`, so crossing times
/// are good to ~1e-13 / 1.4e-3; asserted 1e-11. The minimum (a zero of the rate `sin(t - t_c)`,
/// slope 1) is located to 1e-13; its value to 1e-15.
#[test]
fn brief_dip_found_through_its_minimum_exact_flow() {
    let system = Rotation {
        c: 1.0 - 1e-6,
        t_c: 1.05,
        exact_flow_limit: Some(1.5),
    };
    check_dip(&system, 1e-11, 1e-15);
}

/// The same dip with DOP853 steps (no step limit): the steps are ~0.2 long, 70 times the dip.
/// The state is accurate to ~1e-12, so crossing times are good to ~1e-12 / 1.4e-3 = 7e-10
/// (asserted 1e-8) and the minimum value to ~1e-12 (asserted 1e-11).
#[test]
fn brief_dip_found_through_its_minimum_runge_kutta() {
    let system = Rotation {
        c: 1.0 - 1e-6,
        t_c: 1.05,
        exact_flow_limit: None,
    };
    check_dip(&system, 1e-8, 1e-11);
}

fn check_dip(system: &Rotation, time_tolerance: f64, value_tolerance: f64) {
    let result = flow_map(
        system,
        0.0,
        &system.initial_state(),
        3.0,
        Sensitivity::Transition,
        &Settings::default(),
    )
    .expect("integration succeeds");
    let half_width = system.c.acos();
    assert_eq!(result.events.len(), 2, "{:?}", result.events);
    let (down, up) = (&result.events[0], &result.events[1]);
    assert_eq!(down.direction, Direction::Down);
    assert_eq!(up.direction, Direction::Up);
    let e_down = (down.t - (system.t_c - half_width)).abs();
    let e_up = (up.t - (system.t_c + half_width)).abs();
    eprintln!(
        "crossing time errors {e_down:e} {e_up:e}; {:?}",
        result.statistics
    );
    assert!(e_down < time_tolerance && e_up < time_tolerance);
    // Returned states lie on the new side: h <= 0 after Down, h >= 0 after Up.
    assert!(system.c - down.state[0] <= 0.0);
    assert!(system.c - up.state[0] >= 0.0);
    let minima: Vec<_> = result
        .extrema
        .iter()
        .filter(|e| e.kind == ExtremumKind::Minimum)
        .collect();
    assert_eq!(minima.len(), 1, "{:?}", result.extrema);
    assert!((minima[0].t - system.t_c).abs() < 1e-9);
    assert!((minima[0].value - (system.c - 1.0)).abs() < value_tolerance);
    // The field is the same on both sides: the transition is the rotation by 3 time units.
    let (s, c) = 3.0f64.sin_cos();
    let expected = [[c, s], [-s, c]];
    for i in 0..2 {
        for j in 0..2 {
            assert!((result.transition[(i, j)] - expected[i][j]).abs() < 1e-10);
        }
    }
}

/// `h = 0.3 - cos t` over 10 periods plus 0.5: exactly 20 crossings (up at `acos(0.3) + 2 pi k`,
/// down at `2 pi - acos(0.3) + 2 pi k`, k = 0..9) and 20 extrema (maxima of h at
/// `pi + 2 pi k`, minima at `2 pi k`, k >= 1; the zero of the rate at t = 0 is the start and is
/// not reported). Exact-flow steps of pi/4 end on (or a rounding error from) every extremum,
/// so step boundaries land on extrema: each must still be reported exactly once.
#[test]
fn events_and_extrema_fire_exactly_once() {
    for limit in [Some(PI / 4.0), Some(1.0), None] {
        let system = Rotation {
            c: 0.3,
            t_c: 0.0,
            exact_flow_limit: limit,
        };
        let result = flow_map(
            &system,
            0.0,
            &system.initial_state(),
            20.0 * PI + 0.5,
            Sensitivity::None,
            &Settings::default(),
        )
        .expect("integration succeeds");
        assert_eq!(result.events.len(), 20, "limit {limit:?}");
        let a = 0.3f64.acos();
        for (i, event) in result.events.iter().enumerate() {
            let k = (i / 2) as f64;
            let (expected, direction) = if i % 2 == 0 {
                (a + 2.0 * PI * k, Direction::Up)
            } else {
                (2.0 * PI - a + 2.0 * PI * k, Direction::Down)
            };
            assert_eq!(event.direction, direction);
            // Crossing rate sin(acos 0.3) = 0.95: times good to the state accuracy, ~1e-11.
            assert!(
                (event.t - expected).abs() < 1e-9,
                "{limit:?} event {i}: {event:?}"
            );
        }
        assert_eq!(
            result.extrema.len(),
            20,
            "limit {limit:?}: {:?}",
            result.extrema
        );
        for (i, extremum) in result.extrema.iter().enumerate() {
            let expected = PI * (i + 1) as f64;
            let kind = if i % 2 == 0 {
                ExtremumKind::Maximum
            } else {
                ExtremumKind::Minimum
            };
            assert_eq!(extremum.kind, kind);
            assert!(
                (extremum.t - expected).abs() < 1e-9,
                "{limit:?}: {extremum:?}"
            );
        }
        eprintln!("limit {limit:?}: {:?}", result.statistics);
    }
}

/// A linear mode integrated by its exact flow (steps <= 0.5) and by DOP853: state, transition
/// and parameter sensitivity agree to 1e-10 over 20 time units (both are within ~3e-12 of the
/// closed form, which the exact flow evaluates).
#[test]
fn exact_flow_matches_runge_kutta() {
    let x0 = [0.4, -0.3];
    let rk = ForcedOscillator::reference();
    let exact = ForcedOscillator {
        exact_flow_limit: Some(0.5),
        ..rk
    };
    let settings = Settings::default();
    let a = flow_map(
        &rk,
        0.0,
        &x0,
        20.0,
        Sensitivity::TransitionAndParameter,
        &settings,
    )
    .expect("RK integration");
    let b = flow_map(
        &exact,
        0.0,
        &x0,
        20.0,
        Sensitivity::TransitionAndParameter,
        &settings,
    )
    .expect("exact-flow integration");
    assert_eq!(b.statistics.exact_steps, 40);
    assert_eq!(b.statistics.rhs_evaluations, 0);
    for i in 0..2 {
        assert!((a.state[i] - b.state[i]).abs() < 1e-10);
        assert!((a.parameter_sensitivity[i] - b.parameter_sensitivity[i]).abs() < 1e-10);
        for j in 0..2 {
            assert!((a.transition[(i, j)] - b.transition[(i, j)]).abs() < 1e-10);
        }
    }
    // The composed exact steps reproduce the single closed-form evaluation to rounding.
    let (x, phi, dxda) = rk.exact(0.0, x0, 20.0);
    for i in 0..2 {
        assert!((b.state[i] - x[i]).abs() < 1e-13);
        assert!((b.parameter_sensitivity[i] - dxda[i]).abs() < 1e-13);
        for j in 0..2 {
            assert!((b.transition[(i, j)] - phi[i][j]).abs() < 1e-13);
        }
    }
}
