//! Event location: a dip through a surface far shorter than a step, events and extrema each
//! reported exactly once, and exact-flow steps against Runge-Kutta steps.
#![allow(clippy::needless_range_loop)]

mod common;

use std::f64::consts::PI;

use common::{ForcedOscillator, HertzOscillator, Rotation};
use hybrid::{flow_map, Direction, ExtremumKind, Sensitivity, Settings, Solver, StepOutcome};

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
        curvature_bound: false,
        affine: false,
    };
    check_dip(&system, 1e-11, 1e-15);
}

/// The same dip with DOP853 steps (no step limit): the steps are ~0.2 long, 70 times the dip.
/// The state is accurate to ~1e-12, so crossing times are good to ~1e-12 / 1.4e-3 = 7e-10
/// (asserted 1e-8) and the minimum value to ~1e-12 (asserted 1e-11).
///
/// Declared affine, `h`'s interpolant is bounded on each step instead of sampled where its
/// Bernstein coefficients prove it monotone: the step holding the dip is not, so it is found
/// all the same.
#[test]
fn brief_dip_found_through_its_minimum_runge_kutta() {
    for affine in [false, true] {
        let system = Rotation {
            c: 1.0 - 1e-6,
            t_c: 1.05,
            exact_flow_limit: None,
            curvature_bound: false,
            affine,
        };
        check_dip(&system, 1e-8, 1e-11);
    }
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
    // (exact-flow step limit, curvature bound, affine): the last three let the solver skip
    // sampling steps it proves monotone (by the curvature bound, or the interpolant's
    // Bernstein bound).
    for (limit, curvature_bound, affine) in [
        (Some(PI / 4.0), false, false),
        (Some(1.0), false, false),
        (None, false, false),
        (Some(PI / 4.0), true, false),
        (Some(1.0), true, false),
        (None, false, true),
    ] {
        let system = Rotation {
            c: 0.3,
            t_c: 0.0,
            exact_flow_limit: limit,
            curvature_bound,
            affine,
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
        if curvature_bound || affine {
            assert!(
                2 * result.statistics.sampled_steps < result.statistics.steps,
                "{:?}",
                result.statistics
            );
        } else {
            assert_eq!(result.statistics.sampled_steps, result.statistics.steps);
        }
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

/// Step boundaries placed on the extrema themselves: `h = 2 - cos t` (never crossed) has extrema at
/// `k pi`. (a) exact-flow steps of `pi/4` from t = 0 end on every extremum (to rounding); (b)
/// DOP853 steps driven with `step(t_end)` for `t_end = pi, 2 pi, ...` end exactly there (then on to
/// `20 pi + 0.5`), with `h` declared affine or not. Either way each of the 20 extrema in
/// `(0, 20 pi + 0.5]` is reported exactly once, at `k pi` to 1e-9.
#[test]
fn extrema_on_step_boundaries_are_reported_once() {
    let exact = Rotation {
        c: 2.0,
        t_c: 0.0,
        exact_flow_limit: Some(PI / 4.0),
        curvature_bound: false,
        affine: false,
    };
    let result = flow_map(
        &exact,
        0.0,
        &exact.initial_state(),
        20.0 * PI + 0.5,
        Sensitivity::None,
        &Settings::default(),
    )
    .expect("integration succeeds");
    assert!(result.events.is_empty());
    check_extrema_at_multiples_of_pi(&result.extrema, 20);

    // (b) with h sampled in every step, and declared affine (steps on which its interpolant
    // is proven monotone are not sampled inside: an extremum at a step's end must still be
    // reported once).
    for affine in [false, true] {
        let rk = Rotation {
            exact_flow_limit: None,
            curvature_bound: false,
            affine,
            ..exact
        };
        let mut solver = Solver::new(
            &rk,
            0.0,
            &rk.initial_state(),
            Sensitivity::None,
            Settings::default(),
        )
        .expect("valid");
        let mut extrema = Vec::new();
        for k in 1..=21 {
            // The numerical phase error (~1e-12) may put an extremum just after a t_end, so
            // the run goes on past the 20th extremum.
            let t_end = if k == 21 {
                20.0 * PI + 0.5
            } else {
                PI * k as f64
            };
            loop {
                let outcome = solver.step(t_end).expect("integration succeeds");
                extrema.extend_from_slice(solver.step_extrema());
                if outcome == StepOutcome::EndTime {
                    break;
                }
            }
        }
        check_extrema_at_multiples_of_pi(&extrema, 20);
    }
}

fn check_extrema_at_multiples_of_pi(extrema: &[hybrid::Extremum], count: usize) {
    assert_eq!(extrema.len(), count, "{extrema:?}");
    for (i, extremum) in extrema.iter().enumerate() {
        // h = 2 - cos t: maxima at odd multiples of pi, minima at even ones.
        let kind = if i % 2 == 0 {
            ExtremumKind::Maximum
        } else {
            ExtremumKind::Minimum
        };
        assert_eq!(extremum.kind, kind);
        assert!(
            (extremum.t - PI * (i + 1) as f64).abs() < 1e-9,
            "{extremum:?}"
        );
    }
}

/// Exact grazing: `h = 1 - cos(t - t_c)` touches zero with `dh/dt = 0` at `t_c + 2 pi k`.
/// The rule (see `hybrid::solver`): a touch that does not go strictly negative fires nothing
/// and is reported as a minimum of value ~0; one that rounding pushes strictly below zero
/// fires a Down and an Up event (grazing ones: a dip of depth `delta` is crossed at rate
/// `sqrt(2 delta)`). Either way: at most two events per touch, alternating Down/Up, each with
/// |rate| < sqrt(2e-11), exactly one minimum per touch with |value| < 1e-11 (the
/// exact flow is within rounding; the RK global error after two periods is ~1e-12, measured
/// 1.4e-12 at the second touch), and the run terminates.
#[test]
fn exact_grazing_never_loops() {
    for (t_c, limit) in [(1.0, Some(0.5)), (1.0, None), (0.5, Some(0.5)), (0.3, None)] {
        let system = Rotation {
            c: 1.0,
            t_c,
            exact_flow_limit: limit,
            curvature_bound: false,
            affine: false,
        };
        let result = flow_map(
            &system,
            0.0,
            &system.initial_state(),
            4.0 * PI,
            Sensitivity::Transition,
            &Settings::default(),
        )
        .expect("integration succeeds");
        let minima: Vec<_> = result
            .extrema
            .iter()
            .filter(|e| e.kind == ExtremumKind::Minimum)
            .collect();
        assert_eq!(
            minima.len(),
            2,
            "t_c {t_c}, {limit:?}: {:?}",
            result.extrema
        );
        for (k, m) in minima.iter().enumerate() {
            assert!((m.t - (t_c + 2.0 * PI * k as f64)).abs() < 1e-6);
            assert!(m.value.abs() < 1e-11, "{m:?}");
        }
        assert!(result.events.len() <= 4, "{:?}", result.events);
        for (i, event) in result.events.iter().enumerate() {
            let direction = if i % 2 == 0 {
                Direction::Down
            } else {
                Direction::Up
            };
            assert_eq!(event.direction, direction);
            assert!(event.rate.abs() < 2e-11f64.sqrt(), "{event:?}");
        }
        eprintln!(
            "t_c {t_c}, {limit:?}: {} events, minima {:?}",
            result.events.len(),
            minima.iter().map(|m| m.value).collect::<Vec<_>>()
        );
    }
}

/// `step(t_end)` with `t_end == t` takes no step: it returns `EndTime` and reports no extrema
/// (so a driver collecting `step_extrema` after every call never counts one twice).
#[test]
fn step_to_current_time_reports_nothing() {
    // h = -0.3 - cos t: up at acos(-0.3) = 1.88, maximum at pi, down at 4.41. Exact steps of
    // 3 make the step that ends at the down event contain the maximum.
    let system = Rotation {
        c: -0.3,
        t_c: 0.0,
        exact_flow_limit: Some(3.0),
        curvature_bound: false,
        affine: false,
    };
    let mut solver = Solver::new(
        &system,
        0.0,
        &system.initial_state(),
        Sensitivity::None,
        Settings::default(),
    )
    .expect("valid");
    let event_time = loop {
        let outcome = solver.step(10.0).expect("integration succeeds");
        if let StepOutcome::Event(event) = outcome {
            if event.direction == Direction::Down {
                break event.t;
            }
        }
    };
    assert_eq!(
        solver.step_extrema().len(),
        1,
        "the event step holds the maximum"
    );
    assert_eq!(solver.step(event_time), Ok(StepOutcome::EndTime));
    assert!(solver.step_extrema().is_empty());
}

/// Three surfaces, two of them crossed at the same instants (`h2 = -h0`). From `(1, 0)` over
/// `2 pi + 0.5`: `h0` up and `h2` down at `pi/3`, `h1` up at `pi + asin 0.2`, `h0` down and
/// `h2` up at `5 pi / 3`, `h1` down at `2 pi - asin 0.2` (closed form). Every event fires
/// exactly once, in time order, and the final mode matches the side of every surface.
#[test]
fn several_surfaces_and_simultaneous_crossings() {
    use common::ThreeSurfaces;
    use hybrid::HybridSystem;
    let x0 = [1.0, 0.0];
    let result = flow_map(
        &ThreeSurfaces,
        0.0,
        &x0,
        2.0 * PI + 0.5,
        Sensitivity::Transition,
        &Settings::default(),
    )
    .expect("integration succeeds");
    let s = 0.2f64.asin();
    let mut expected = [
        (PI / 3.0, 0, Direction::Up),
        (PI / 3.0, 2, Direction::Down),
        (PI + s, 1, Direction::Up),
        (5.0 * PI / 3.0, 0, Direction::Down),
        (5.0 * PI / 3.0, 2, Direction::Up),
        (2.0 * PI - s, 1, Direction::Down),
    ];
    assert_eq!(result.events.len(), expected.len(), "{:?}", result.events);
    let mut found: Vec<_> = result
        .events
        .iter()
        .map(|e| (e.t, e.surface, e.direction))
        .collect();
    assert!(found.windows(2).all(|w| w[0].0 <= w[1].0), "time order");
    // Simultaneous events may come in either surface order: compare sorted by (time bucket,
    // surface).
    found.sort_by(|a, b| {
        (a.0 * 1e6)
            .round()
            .total_cmp(&(b.0 * 1e6).round())
            .then(a.1.cmp(&b.1))
    });
    expected.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    for (f, e) in found.iter().zip(&expected) {
        // Crossing rates are >= 0.5 and the state is accurate to ~1e-12: times to 1e-9.
        assert!(
            (f.0 - e.0).abs() < 1e-9 && f.1 == e.1 && f.2 == e.2,
            "{f:?} vs {e:?}"
        );
    }
    // The mode after the run is the side of every surface at the final state.
    let t_end = 2.0 * PI + 0.5;
    let mut solver = Solver::new(
        &ThreeSurfaces,
        0.0,
        &x0,
        Sensitivity::None,
        Settings::default(),
    )
    .expect("valid");
    while solver.step(t_end).expect("integration succeeds") != StepOutcome::EndTime {}
    assert_eq!(solver.mode(), ThreeSurfaces.mode_of(t_end, solver.state()));
    assert_eq!(solver.mode(), 0b011, "h0 < 0, h1 < 0, h2 > 0 at 2 pi + 0.5");
    // Saltation is the identity (same field everywhere): the transition is the rotation.
    let (sn, cs) = t_end.sin_cos();
    assert!((result.transition[(0, 0)] - cs).abs() < 1e-10);
    assert!((result.transition[(0, 1)] - sn).abs() < 1e-10);
}

/// Steps proven clear of the surface (`extremum_height = 0` and a curvature bound) go
/// unsampled (and exact-flow steps are stretched across them), yet every crossing is found as
/// with full sampling: `h = c - cos(t - t_c)` with `c = 1 - 1e-6` dips below zero for 2.8e-3
/// time units once per period, six periods, exact-flow steps of at most 0.5 where not proven
/// clear, and Runge-Kutta steps. The events must match those of the fully sampled run to
/// rounding (the exact flow composed of other steps: crossing times to 1e-11, as in the
/// brief-dip tests, states to 1e-11 as `|dx/dt| = 1` moves them; the final state to 1e-13);
/// the dips' minima (value `c - 1`) are still reported, the
/// maxima of `h` (value `c + 1`, farther than any bound allows) no longer are.
#[test]
fn steps_clear_of_the_surface_skip_sampling_but_no_crossing() {
    for limit in [Some(0.5), None] {
        let system = Rotation {
            c: 1.0 - 1e-6,
            t_c: 1.05,
            exact_flow_limit: limit,
            curvature_bound: true,
            affine: false,
        };
        let run = |height: f64| {
            let settings = Settings {
                extremum_height: height,
                ..Settings::default()
            };
            flow_map(
                &system,
                0.0,
                &system.initial_state(),
                12.0 * PI,
                Sensitivity::None,
                &settings,
            )
            .expect("integration succeeds")
        };
        let full = run(f64::INFINITY);
        let skipping = run(0.0);
        assert_eq!(full.events.len(), 12, "{:?}", full.events);
        assert_eq!(skipping.events.len(), full.events.len());
        for (a, b) in full.events.iter().zip(&skipping.events) {
            assert!((a.t - b.t).abs() < 1e-11, "{a:?} {b:?}");
            assert_eq!(a.direction, b.direction);
            for (x, y) in a.state.iter().zip(&b.state) {
                assert!((x - y).abs() < 1e-11, "{a:?} {b:?}");
            }
        }
        for (x, y) in skipping.state.iter().zip(&full.state) {
            assert!((x - y).abs() < 1e-13);
        }
        let count = |result: &hybrid::FlowMap, kind: ExtremumKind| {
            result.extrema.iter().filter(|e| e.kind == kind).count()
        };
        assert_eq!(count(&full, ExtremumKind::Minimum), 6);
        assert_eq!(count(&full, ExtremumKind::Maximum), 6);
        assert_eq!(count(&skipping, ExtremumKind::Minimum), 6);
        assert_eq!(count(&skipping, ExtremumKind::Maximum), 0);
        for minimum in skipping.extrema.iter() {
            assert!((minimum.value - (system.c - 1.0)).abs() < 1e-11);
        }
        // A height above the maxima's value reports them again.
        let high = run(2.5);
        assert_eq!(count(&high, ExtremumKind::Maximum), 6);
    }
}

/// Hertz contact from rest over 3 drive periods (5 crossings, contact minima inside the
/// obstacle, maxima and minima in free flight), with every extremum wanted (the default
/// height): declaring the affine gap lets the solver skip the interior sampling of the steps on
/// which the Bernstein bound proves the gap monotone, and changes nothing else. The events and
/// extrema are those of the fully sampled run, times within 1e-12 (both locate the same roots
/// of the same interpolants, to the event tolerance) and values within 1e-14; the state at the
/// end is the same to rounding (the steps are the same).
#[test]
fn steps_settled_on_their_interpolant_skip_sampling_and_nothing_else() {
    let duration = 3.0 * 2.0 * std::f64::consts::PI / 1.2;
    let run = |affine: bool| {
        let system = HertzOscillator {
            affine,
            ..HertzOscillator::reference()
        };
        flow_map(
            &system,
            0.0,
            &[0.0, 0.0],
            duration,
            Sensitivity::None,
            &Settings::default(),
        )
        .expect("integration succeeds")
    };
    let (sampled, settled) = (run(false), run(true));
    eprintln!(
        "sampled {:?}\nsettled {:?}",
        sampled.statistics, settled.statistics
    );
    assert_eq!(sampled.statistics.steps, settled.statistics.steps);
    assert_eq!(sampled.statistics.sampled_steps, sampled.statistics.steps);
    // Most steps, in contact and in free flight, hold no extremum.
    assert!(2 * settled.statistics.sampled_steps < settled.statistics.steps);
    assert_eq!(sampled.events.len(), 5);
    assert_eq!(sampled.events.len(), settled.events.len());
    for (a, b) in sampled.events.iter().zip(&settled.events) {
        assert_eq!(a.direction, b.direction);
        assert!((a.t - b.t).abs() < 1e-12, "{a:?} vs {b:?}");
    }
    assert_eq!(sampled.extrema.len(), settled.extrema.len());
    assert!(
        sampled.extrema.iter().any(|e| e.value < 0.0),
        "a minimum inside contact"
    );
    for (a, b) in sampled.extrema.iter().zip(&settled.extrema) {
        assert_eq!(a.kind, b.kind);
        assert!((a.t - b.t).abs() < 1e-12, "{a:?} vs {b:?}");
        assert!((a.value - b.value).abs() < 1e-14, "{a:?} vs {b:?}");
    }
    for (a, b) in sampled.state.iter().zip(&settled.state) {
        assert!((a - b).abs() < 1e-13);
    }
}
