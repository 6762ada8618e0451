//! The hybrid-system implementation of Eq. 1: derivatives against finite differences, the exact
//! free flight against RK4 of the model's own vector field, N > 2 modes.

mod common;

use afm::model::{CONTACT, FREE_FLIGHT};
use afm::{Separation, TappingModel};
use hybrid::{ExactFlow, HybridSystem};
use nalgebra::DMatrix;

/// A three-mode cantilever (nothing may hard-wire N = 2), over-damped third mode included.
fn three_mode_model(separation: Separation) -> TappingModel {
    let cantilever = common::cantilever(&[
        (0.1, 3.5, 1.6, 1.0, 1.0),
        (10.0, 28.0, 4.3, 5.26, -1.54),
        (60.0, 80.0, 0.3, -2.0, 0.8),
    ]);
    TappingModel::new(cantilever, common::mica(), 20.0, Some(3.3), separation).expect("model")
}

fn contact_state(model: &TappingModel) -> Vec<f64> {
    // A state 1.5 nm into the sample with non-zero velocities.
    let mut x = model.free_state();
    let shift = -1.5 - model.gap(0.0, &x);
    x[0] += shift;
    for (k, v) in x.iter_mut().enumerate() {
        if k % 2 == 1 {
            *v += 0.01 * k as f64;
        }
    }
    x
}

/// A five-mode cantilever: more modes than the model's compile-time special cases.
fn five_mode_model() -> TappingModel {
    let cantilever = common::cantilever(&[
        (0.1, 3.5, 1.6, 1.0, 1.0),
        (10.0, 28.0, 4.3, 5.26, -1.54),
        (60.0, 80.0, 0.3, -2.0, 0.8),
        (150.0, 160.0, 3.0, 1.5, -0.6),
        (400.0, 300.0, 5.0, -1.2, 0.4),
    ]);
    TappingModel::new(
        cantilever,
        common::mica(),
        20.0,
        Some(3.3),
        Separation::Constant(12.0),
    )
    .expect("model")
}

/// The model's structured variational field (`J v` without forming `J`) against the dense
/// products of its own Jacobian (`linearisation` + `jacobian_products`), for 1, 2, 3 and 5
/// modes, free flight and contact, with and without the parameter column: equal to rounding.
#[test]
fn variational_field_equals_the_dense_jacobian_products() {
    let one_mode = TappingModel::new(
        common::cantilever(&[(0.1, 3.5, 1.6, 1.0, 1.0)]),
        common::mica(),
        20.0,
        Some(3.3),
        Separation::Constant(12.0),
    )
    .expect("model");
    for model in [
        one_mode,
        TappingModel::from_case(&afm::builtin_case("biolever-mica").expect("case")).expect("m"),
        three_mode_model(Separation::Constant(12.0)),
        five_mode_model(),
    ] {
        let n = model.dim();
        let x = contact_state(&model);
        let t = 0.37;
        for mode in [FREE_FLIGHT, CONTACT] {
            for parameter in [false, true] {
                let columns = if parameter { n + 1 } else { n };
                let tangents: Vec<f64> = (0..columns * n)
                    .map(|i| ((i * 7919) % 97) as f64 / 97.0 - 0.5)
                    .collect();
                let mut buffers = hybrid::LinearisationBuffers::new(n);
                let (mut field, mut rates) = (vec![0.0; n], vec![0.0; columns * n]);
                model.variational_field(
                    mode,
                    t,
                    &x,
                    &mut field,
                    &tangents,
                    &mut rates,
                    parameter,
                    &mut buffers,
                );
                let (mut dense_field, mut dense_rates) = (vec![0.0; n], vec![0.0; columns * n]);
                let mut jacobian = DMatrix::zeros(n, n);
                let mut dfdp = vec![0.0; n];
                model.linearisation(
                    mode,
                    t,
                    &x,
                    &mut dense_field,
                    &mut jacobian,
                    Some(&mut dfdp),
                );
                hybrid::sensitivity::jacobian_products(
                    &jacobian,
                    &tangents,
                    &mut dense_rates,
                    parameter.then_some(&dfdp[..]),
                );
                assert_eq!(field, dense_field, "field, {} modes", n / 2);
                // Both sum the same terms in different orders: agreement to a few roundings of
                // the largest term, |J| |v| with |v| <= 0.5.
                let scale =
                    jacobian.amax() * 0.5 * n as f64 + dfdp.iter().fold(0.0, |m, d| d.abs().max(m));
                for (r, (a, b)) in rates.iter().zip(&dense_rates).enumerate() {
                    assert!(
                        (a - b).abs() <= 1e-14 * scale,
                        "{} modes, mode {mode}, parameter {parameter}, entry {r}: {a} vs {b}",
                        n / 2
                    );
                }
            }
        }
    }
}

#[test]
fn jacobian_and_parameter_derivative_match_finite_differences() {
    for model in [
        three_mode_model(Separation::Constant(12.0)),
        TappingModel::from_case(&afm::builtin_case("biolever-mica").expect("case")).expect("m"),
    ] {
        let n = model.dim();
        let x = contact_state(&model);
        let t = 0.37;
        for mode in [FREE_FLIGHT, CONTACT] {
            let mut jacobian = DMatrix::zeros(n, n);
            model.jacobian(mode, t, &x, &mut jacobian);
            let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
            for c in 0..n {
                let h = 1e-6;
                let (mut xp, mut xm) = (x.clone(), x.clone());
                xp[c] += h;
                xm[c] -= h;
                model.vector_field(mode, t, &xp, &mut fp);
                model.vector_field(mode, t, &xm, &mut fm);
                for r in 0..n {
                    // Central difference: truncation ~ F''' h^2 w^2/k ~ 1e-9 relative to the
                    // largest entry (w_3^2 ~ 0.25); rounding ~ eps |f| / h ~ 1e-9.
                    let numeric = (fp[r] - fm[r]) / (2.0 * h);
                    let scale = jacobian.amax();
                    assert!(
                        (numeric - jacobian[(r, c)]).abs() < 1e-7 * scale,
                        "mode {mode} ({r},{c}): {numeric} vs {}",
                        jacobian[(r, c)]
                    );
                }
            }
            // df/dZ by changing the separation.
            let z = model.separation().at(t);
            let h = 1e-6;
            let mut plus = model.clone();
            plus.set_separation(Separation::Constant(z + h))
                .expect("finite");
            let mut minus = model.clone();
            minus
                .set_separation(Separation::Constant(z - h))
                .expect("finite");
            plus.vector_field(mode, t, &x, &mut fp);
            minus.vector_field(mode, t, &x, &mut fm);
            let mut dfdp = vec![0.0; n];
            model.parameter_derivative(mode, t, &x, &mut dfdp);
            for r in 0..n {
                let numeric = (fp[r] - fm[r]) / (2.0 * h);
                assert!(
                    (numeric - dfdp[r]).abs() < 1e-7 * (1.0 + dfdp[r].abs()),
                    "mode {mode} df/dZ[{r}]: {numeric} vs {}",
                    dfdp[r]
                );
                if mode == FREE_FLIGHT {
                    assert_eq!(dfdp[r], 0.0);
                }
            }
        }
    }
}

#[test]
fn contact_field_is_eq1_with_hertz_force_and_continuous_at_the_surface() {
    let model = three_mode_model(Separation::Constant(12.0));
    let x = contact_state(&model);
    let n = model.dim();
    let (mut free, mut contact) = (vec![0.0; n], vec![0.0; n]);
    let t = 0.37;
    model.vector_field(FREE_FLIGHT, t, &x, &mut free);
    model.vector_field(CONTACT, t, &x, &mut contact);
    // Eq. 1: the contact adds w_i^2 F_ts / k_i to each acceleration, F_ts = c (1.5)^{3/2}.
    let force = model.hertz().coefficient * 1.5f64.powf(1.5);
    assert!((model.tip_sample_force(t, &x) - force).abs() < 1e-12 * force);
    for (i, mode) in model.cantilever().modes.iter().enumerate() {
        let w = mode.angular_frequency();
        let added = w * w * force / mode.stiffness_n_per_m;
        assert!((contact[2 * i + 1] - free[2 * i + 1] - added).abs() < 1e-12 * added.abs());
        assert_eq!(contact[2 * i], free[2 * i]);
    }
    // On the surface d = 0 both fields agree (continuous force).
    let mut y = x.clone();
    y[0] -= model.gap(t, &y);
    model.vector_field(FREE_FLIGHT, t, &y, &mut free);
    model.vector_field(CONTACT, t, &y, &mut contact);
    for k in 0..n {
        assert!((free[k] - contact[k]).abs() < 1e-9 * (1.0 + free[k].abs()));
    }
}

#[test]
fn exact_free_flight_matches_rk4_of_the_vector_field() {
    for model in [
        three_mode_model(Separation::Constant(30.0)),
        TappingModel::from_case(&afm::builtin_case("biolever-soft").expect("case")).expect("m"),
    ] {
        let n = model.dim();
        let mut x0 = model.free_state();
        x0[0] += 2.0;
        x0[3] -= 0.05;
        let t0 = 5.0;
        let dt = model.exact_step_limit(FREE_FLIGHT);
        assert!(dt <= 0.25 * model.period_us());
        let mut exact = vec![0.0; n];
        let mut transition = DMatrix::zeros(n, n);
        let mut dxdp = vec![1.0; n];
        model.exact_flow(
            FREE_FLIGHT,
            t0,
            &x0,
            dt,
            &mut exact,
            Some(&mut transition),
            Some(&mut dxdp),
        );
        assert!(dxdp.iter().all(|&v| v == 0.0));
        // RK4, 20000 steps over at most a quarter of the shortest period: error < 1e-12 nm.
        let reference = common::rk4(
            |t, x, dx| model.vector_field(FREE_FLIGHT, t, x, dx),
            t0,
            &x0,
            dt,
            20_000,
        );
        for k in 0..n {
            assert!((exact[k] - reference[k]).abs() < 1e-10, "{k}");
        }
        // Transition matrix against finite differences of the flow (affine: exact to rounding).
        let mut plus = vec![0.0; n];
        let mut minus = vec![0.0; n];
        for c in 0..n {
            let h = 1e-4;
            let (mut xp, mut xm) = (x0.clone(), x0.clone());
            xp[c] += h;
            xm[c] -= h;
            model.exact_flow(FREE_FLIGHT, t0, &xp, dt, &mut plus, None, None);
            model.exact_flow(FREE_FLIGHT, t0, &xm, dt, &mut minus, None, None);
            for r in 0..n {
                let numeric = (plus[r] - minus[r]) / (2.0 * h);
                assert!((numeric - transition[(r, c)]).abs() < 1e-8, "({r},{c})");
            }
        }
    }
}

#[test]
fn switching_function_rate_and_gradient_with_a_ramp() {
    let model = three_mode_model(Separation::Ramp {
        z0_nm: 25.0,
        rate_nm_per_us: 0.002,
    });
    let n = model.dim();
    let x = contact_state(&model);
    let t = 40.0;
    let mut dx = vec![0.0; n];
    for mode in [FREE_FLIGHT, CONTACT] {
        model.vector_field(mode, t, &x, &mut dx);
        // dh/dt along the flow by a first-order step of the field (h linear in t and x:
        // the difference quotient is exact up to rounding).
        let h = 1e-3;
        let moved: Vec<f64> = x.iter().zip(&dx).map(|(a, b)| a + h * b).collect();
        let numeric = (model.switching(0, t + h, &moved) - model.switching(0, t, &x)) / h;
        let rate = model.switching_rate(0, mode, t, &x);
        assert!((numeric - rate).abs() < 1e-9, "{numeric} vs {rate}");
    }
    let mut gradient = vec![0.0; n];
    let partials = model.switching_gradient(0, t, &x, &mut gradient);
    assert_eq!(partials.t, -0.002);
    assert_eq!(partials.p, 1.0);
    for (k, g) in gradient.iter().enumerate() {
        assert_eq!(*g, if k % 2 == 0 { 1.0 } else { 0.0 });
    }
    assert!(
        (model.gap(t, &x) - (25.0 - 0.08 + (0..3).map(|i| x[2 * i]).sum::<f64>())).abs() < 1e-12
    );
    assert_eq!(model.mode_of(t, &x), CONTACT);
}

#[test]
fn from_case_starts_at_first_contact_and_accessors_agree() {
    let case = afm::builtin_case("maclever-mica-experiment").expect("case");
    let model = TappingModel::from_case(&case).expect("model");
    assert_eq!(model.dim(), 4);
    assert_eq!(model.drive_frequency_khz(), 3.3);
    let w = 2.0 * std::f64::consts::PI * 3.3 / 1000.0;
    assert!((model.drive_angular_frequency() - w).abs() < 1e-16);
    assert!((model.period_us() - 1000.0 / 3.3).abs() < 1e-10);
    assert_eq!(
        model.separation(),
        Separation::Constant(model.grazing_separation_nm())
    );
    let x = model.free_state();
    // u = q_1 + chi_2 q_2 with chi_2 = 5.26.
    assert!((model.photodiode(&x) - (x[0] + 5.26 * x[2])).abs() < 1e-14);
    assert!(model.drive_force_nn() > 0.0);
    let mut bad = model.clone();
    assert!(bad.set_separation(Separation::Constant(f64::NAN)).is_err());
}
