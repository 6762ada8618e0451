//! Tests of the model's performance overrides and accelerations against the plain definitions.

use super::*;
use crate::fixtures::builtin_case;
use hybrid::{ExactFlow, SwitchingStructure};
use nalgebra::DMatrix;

/// The fused `linearisation` is a performance override: it must give exactly (bit for bit:
/// the same expressions in the same order) what the three separate calls give, in contact
/// (at several indentations), at the surface and in free flight.
#[test]
fn linearisation_matches_the_separate_calls() {
    let case = builtin_case("biolever-mica").expect("built-in case");
    let model = TappingModel::from_case(&case).expect("model");
    let n = model.dim();
    for (mode, shift) in [
        (CONTACT, -0.3),
        (CONTACT, -1e-6),
        (CONTACT, 0.0),
        (CONTACT, 0.2),
        (FREE_FLIGHT, -0.3),
        (FREE_FLIGHT, 0.5),
    ] {
        let t = 0.37;
        let mut x: Vec<f64> = (0..n).map(|i| 0.1 * (i as f64 + 1.0)).collect();
        // Place the gap at `shift` nm.
        x[0] += shift - model.gap(t, &x);
        let (mut f1, mut f2) = (vec![0.0; n], vec![0.0; n]);
        let (mut j1, mut j2) = (DMatrix::zeros(n, n), DMatrix::from_element(n, n, 7.0));
        let (mut p1, mut p2) = (vec![0.0; n], vec![3.0; n]);
        model.vector_field(mode, t, &x, &mut f1);
        model.jacobian(mode, t, &x, &mut j1);
        model.parameter_derivative(mode, t, &x, &mut p1);
        model.linearisation(mode, t, &x, &mut f2, &mut j2, Some(&mut p2));
        assert_eq!(f1, f2, "field, mode {mode}, gap {shift}");
        assert_eq!(j1, j2, "Jacobian, mode {mode}, gap {shift}");
        assert_eq!(p1, p2, "df/dZ, mode {mode}, gap {shift}");
    }
}

/// The transitions and drive rotations kept for the standard exact step and its grid
/// spacings (every kept count) are the numbers the oscillators compute per call: the flow
/// and grids over the standard step are bit for bit those over a step computed afresh (the
/// same expressions on the same inputs).
#[test]
fn kept_standard_step_transitions_equal_fresh_ones() {
    for name in ["biolever-mica", "maclever-soft"] {
        let case = builtin_case(name).expect("built-in case");
        let model = TappingModel::from_case(&case).expect("model");
        let n = model.dim();
        let dt = model.exact_step_limit(FREE_FLIGHT);
        let x0: Vec<f64> = (0..n).map(|i| 3.0 - 0.7 * i as f64).collect();
        let t0 = 5.678;
        let mut kept = vec![0.0; n];
        let mut transition = DMatrix::zeros(n, n);
        model.exact_flow(
            FREE_FLIGHT,
            t0,
            &x0,
            dt,
            &mut kept,
            Some(&mut transition),
            None,
        );
        let w = model.drive.angular_frequency;
        for count in 1..=KEPT_GRIDS {
            let spacing = dt / count as f64;
            assert_eq!(
                model.grid_rotations[count - 1],
                phase::sin_cos(w * spacing),
                "{name}, {count} intervals"
            );
            for m in &model.modes {
                assert_eq!(
                    m.grid_transitions[count - 1],
                    m.oscillator.homogeneous_transition(spacing),
                    "{name}, {count} intervals"
                );
            }
        }
        for (i, m) in model.modes.iter().enumerate() {
            assert_eq!(m.step_transition, m.oscillator.homogeneous_transition(dt));
            let (fresh, phi) = m.oscillator.flow(t0, [x0[2 * i], x0[2 * i + 1]], dt);
            assert_eq!([kept[2 * i], kept[2 * i + 1]], fresh, "{name} mode {i}");
            assert_eq!(transition[(2 * i, 2 * i + 1)], phi[0][1], "{name} mode {i}");
        }
    }
}

/// The grid of free-flight states by recurrence agrees with the direct closed-form flow
/// at every point: to 1e-13 relative to the largest component (rounding of ~10 products per
/// point accumulated over at most 16 points is ~1e-14; the trigonometric and exponential
/// functions of the direct flow are each within an ulp; measured 2e-16..5e-16), over a quarter of the shortest
/// period (the solver's exact step) and over a whole drive period.
#[test]
fn exact_flow_grid_matches_the_direct_flow() {
    for name in ["biolever-mica", "maclever-soft"] {
        let case = builtin_case(name).expect("built-in case");
        let model = TappingModel::from_case(&case).expect("model");
        let n = model.dim();
        let x0: Vec<f64> = (0..n).map(|i| 3.0 - 0.7 * i as f64).collect();
        for (dt, count) in [
            (model.exact_step_limit(FREE_FLIGHT), 9),
            (model.period_us(), 16),
        ] {
            let t0 = 1.234;
            let mut grid = vec![0.0; count * n];
            model.exact_flow_grid(FREE_FLIGHT, t0, &x0, dt, count, &mut grid);
            let mut direct = vec![0.0; count * n];
            for j in 1..=count {
                let tau = dt * (j as f64 / count as f64);
                let out = &mut direct[(j - 1) * n..j * n];
                model.exact_flow(FREE_FLIGHT, t0, &x0, tau, out, None, None);
            }
            // The scale: the largest state component on the grid.
            let scale = direct.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            let mut worst = 0.0f64;
            for j in 1..=count {
                for c in 0..n {
                    let e = (grid[(j - 1) * n + c] - direct[(j - 1) * n + c]).abs();
                    worst = worst.max(e / scale);
                }
            }
            eprintln!("{name}: {count} points over {dt} us: worst relative error {worst:e}");
            assert!(worst < 1e-13, "{name}: {worst:e}");
        }
    }
}

/// The free flight's curvature bound holds: the largest `|d''|` seen on a fine sampling of
/// the exact flow (`d'' = sum_i q_i''` from the vector field with `F_ts = 0`) never exceeds
/// it, for the free steady state, a state with the second mode ringing (as after an impact),
/// a state at rest, and states with large velocities, over one exact step and over a whole
/// period, with a constant and a moving separation; and it is tight (within a factor 1.5 of
/// the maximum over a period of the free orbit, `w^2 |sum_i P_i e^{i phi_i}|`). In contact
/// there is no bound.
#[test]
fn free_flight_curvature_bound_holds() {
    for name in ["biolever-mica", "maclever-soft"] {
        let case = builtin_case(name).expect("built-in case");
        let mut model = TappingModel::from_case(&case).expect("model");
        let n = model.dim();
        let free = model.free_state();
        let mut ringing = free.clone();
        ringing[2] += 2.0;
        ringing[3] -= 1.5;
        let rest = vec![0.0; n];
        let fast: Vec<f64> = (0..n).map(|i| 5.0 * (-1.0f64).powi(i as i32)).collect();
        for separation in [
            Separation::Constant(3.0),
            Separation::Ramp {
                z0_nm: 3.0,
                rate_nm_per_us: 1e-3,
            },
        ] {
            model.set_separation(separation).expect("finite");
            for (label, x0) in [
                ("free", &free),
                ("ringing", &ringing),
                ("rest", &rest),
                ("fast", &fast),
            ] {
                for dt in [model.exact_step_limit(FREE_FLIGHT), model.period_us()] {
                    let t0 = 0.37;
                    let bound = model
                        .switching_curvature_bound(GAP_SURFACE, FREE_FLIGHT, t0, x0, dt)
                        .expect("a bound in free flight");
                    let (mut x, mut f) = (vec![0.0; n], vec![0.0; n]);
                    let mut seen = 0.0f64;
                    for j in 0..=2000 {
                        let tau = dt * j as f64 / 2000.0;
                        model.exact_flow(FREE_FLIGHT, t0, x0, tau, &mut x, None, None);
                        model.vector_field(FREE_FLIGHT, t0 + tau, &x, &mut f);
                        let curvature: f64 = (0..n / 2).map(|i| f[2 * i + 1]).sum();
                        seen = seen.max(curvature.abs());
                    }
                    assert!(seen <= bound, "{name} {label} dt {dt}: {seen} > {bound}");
                    if label == "free" && dt == model.period_us() {
                        assert!(bound < 1.5 * seen, "{name}: {bound} vs {seen}");
                    }
                }
            }
        }
        assert!(model
            .switching_curvature_bound(GAP_SURFACE, CONTACT, 0.0, &free, 1.0)
            .is_none());
    }
}
