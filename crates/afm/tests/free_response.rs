//! F_1 from A0, the free orbit's first harmonic and phase, and the first-contact separation
//! Z_G1, each against an independent computation.

mod common;

use std::f64::consts::PI;

use afm::model::trigonometric::TrigonometricPolynomial;
use afm::{Drive, FreeResponse, Separation, TappingModel};
use hybrid::{ExactFlow, HybridSystem};

fn biolever_model() -> TappingModel {
    TappingModel::new(
        common::biolever(),
        common::mica(),
        10.0,
        None,
        Separation::Constant(50.0),
    )
    .expect("valid model")
}

#[test]
fn single_mode_at_resonance_gives_the_papers_force() {
    // At w = w_1, a single mode has |H_1| = Q_1/k_1, so F_1 = k_1 A0 / Q_1 (the paper, below
    // Eq. 2); relative rounding only.
    let cantilever = common::cantilever(&[(0.036, 9.3, 1.2, 1.0, 1.0)]);
    let drive = Drive::for_free_amplitude(&cantilever, 10.0, 9.3).expect("drive");
    assert!((drive.force_nn - 0.036 * 10.0 / 1.2).abs() < 1e-14);
    let free = FreeResponse::new(&cantilever, &drive);
    assert!((free.phase_deg() - 90.0).abs() < 1e-12);
    // Single mode, single frequency: the lowest gap is at Z = A0.
    assert!((free.grazing_separation_nm() - 10.0).abs() < 1e-13);
}

#[test]
fn free_orbit_has_first_harmonic_a0_by_quadrature() {
    for (cantilever, amplitude, frequency) in [
        (common::biolever(), 10.0, None),
        (
            afm::builtin_cantilever("maclever").expect("maclever"),
            20.0,
            Some(3.3),
        ),
        (
            afm::builtin_cantilever("maclever").expect("maclever"),
            20.0,
            None,
        ),
    ] {
        let model = TappingModel::new(
            cantilever,
            common::mica(),
            amplitude,
            frequency,
            Separation::Constant(100.0),
        )
        .expect("model");
        let free = model.free_response();
        let period = model.period_us();
        // u(t) from the closed-form state at 4096 points: the rectangle rule is exact for the
        // first harmonic of a degree-1 trigonometric polynomial (to rounding, ~1e-14 relative).
        let dim = model.dim();
        let [a, b] = common::first_harmonic(
            |t| {
                let mut x = vec![0.0; dim];
                free.state_at(t, &mut x);
                model.photodiode(&x)
            },
            period,
            4096,
        );
        assert!(
            (a.hypot(b) - amplitude).abs() < 1e-12 * amplitude,
            "A = {}",
            a.hypot(b)
        );
        let phase = b.atan2(a).to_degrees();
        assert!((phase - model.free_phase_deg()).abs() < 1e-10, "{phase}");
    }
}

#[test]
fn free_orbit_solves_eq1_and_is_periodic() {
    let model = biolever_model();
    let free = model.free_response();
    let mut x = vec![0.0; 4];
    let mut xp = vec![0.0; 4];
    let mut xm = vec![0.0; 4];
    let mut dx = vec![0.0; 4];
    for t in [0.0, 17.0, 60.0] {
        free.state_at(t, &mut x);
        model.vector_field(0, t, &x, &mut dx);
        // Central difference in time, h = 1e-3 us: truncation ~ w^3 h^2 |q| / 6 ~ 1e-8 for the
        // second mode (w_2 = 0.45 rad/us).
        let h = 1e-3;
        free.state_at(t + h, &mut xp);
        free.state_at(t - h, &mut xm);
        for k in 0..4 {
            let numeric = (xp[k] - xm[k]) / (2.0 * h);
            assert!(
                (numeric - dx[k]).abs() < 1e-7,
                "t = {t}, {k}: {numeric} vs {}",
                dx[k]
            );
        }
    }
    // One period of the exact flow maps the free state at t = 0 to itself.
    let x0 = model.free_state();
    let mut x1 = vec![0.0; 4];
    let mut t = 0.0;
    let mut state = x0.clone();
    let steps = 16;
    let dt = model.period_us() / steps as f64;
    for _ in 0..steps {
        model.exact_flow(0, t, &state, dt, &mut x1, None, None);
        state.copy_from_slice(&x1);
        t += dt;
    }
    for k in 0..4 {
        assert!((state[k] - x0[k]).abs() < 1e-12 * (1.0 + x0[k].abs()));
    }
}

#[test]
fn biolever_free_phase_is_a_few_degrees_past_90() {
    let model = biolever_model();
    // Independent: the phase of u by quadrature of the closed-form orbit (rectangle rule,
    // exact for degree 1).
    let free = model.free_response();
    let [a, b] = common::first_harmonic(
        |t| {
            let mut x = [0.0; 4];
            free.state_at(t, &mut x);
            model.photodiode(&x)
        },
        model.period_us(),
        1024,
    );
    let quadrature_phase = b.atan2(a).to_degrees();
    // Hand estimate (MODEL.md section 4): at w = w_1, q_1 lags by exactly 90 deg with
    // amplitude F_1 Q_1/k_1 = 33.33 F_1 nm/nN, and chi_2 q_2 ~ chi_2 r_2 F_1 / k_2 /
    // (1 - (9.3/72)^2) = -1.3966 F_1 (in phase with the drive, negative, nearly no lag), so
    // Phi ~ 90 + atan(1.3966/33.33) = 92.40 deg (ignoring q_2's small lag: ~0.01 deg).
    let estimate = 90.0
        + (3.47 * 0.554 / 1.4 / (1.0 - (9.3f64 / 72.0).powi(2)) / (1.2 / 0.036))
            .atan()
            .to_degrees();
    assert!((quadrature_phase - model.free_phase_deg()).abs() < 1e-10);
    assert!(
        (quadrature_phase - estimate).abs() < 0.05,
        "{quadrature_phase} vs {estimate}"
    );
    assert!(quadrature_phase > 92.0 && quadrature_phase < 93.0);
    println!("Biolever free phase of u: {quadrature_phase:.6} deg");
}

/// Brute-force minimum of `f` over `[0, period)` with `m` samples, refined by golden-section
/// search in the bracket around the best sample.
fn brute_force_minimum<F: Fn(f64) -> f64>(f: F, period: f64, m: usize) -> f64 {
    let step = period / m as f64;
    let best = (0..m)
        .map(|j| j as f64 * step)
        .min_by(|x, y| f(*x).total_cmp(&f(*y)))
        .unwrap_or(0.0);
    let (mut lo, mut hi) = (best - step, best + step);
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..200 {
        let c = hi - ratio * (hi - lo);
        let d = lo + ratio * (hi - lo);
        if f(c) < f(d) {
            hi = d;
        } else {
            lo = c;
        }
    }
    f(0.5 * (lo + hi))
}

#[test]
fn first_contact_separation_matches_brute_force_sampling() {
    for name in afm::case_names() {
        let case = afm::builtin_case(name).expect("case");
        let model = TappingModel::from_case(&case).expect("model");
        let free = model.free_response();
        let dim = model.dim();
        let lowest = brute_force_minimum(
            |t| {
                let mut y = vec![0.0; dim];
                free.state_at(t, &mut y);
                // The gap minus Z: `sum_i q_i`, plus an acoustic drive's base motion
                // (MODEL.md section 14).
                (0..model.mode_count()).map(|i| y[2 * i]).sum::<f64>() + model.base_displacement(t)
            },
            model.period_us(),
            20_000,
        );
        let mut x = vec![0.0; dim];
        let z_g1 = model.grazing_separation_nm();
        // First contact is where the lowest gap reaches the contact surface `d_c` (0 but for
        // DMT's `a0`). The golden-section refinement converges to ~sqrt(eps) in t, i.e. ~eps
        // in value.
        let contact_gap = model.contact_gap_nm();
        assert!(
            (z_g1 - contact_gap + lowest).abs() < 1e-9 * z_g1,
            "{name}: {z_g1} vs {}",
            contact_gap - lowest
        );
        // At Z = Z_G1 the free gap's minimum is `d_c`, i.e. the model's gap touches it there.
        let t_low = free.lowest_gap_time_us();
        free.state_at(t_low, &mut x);
        assert!((model.gap(t_low, &x) - contact_gap).abs() < 1e-12 * z_g1);
        // First contact is not at Z = A0 (MODEL.md section 5).
        println!(
            "{name}: Z_G1 = {z_g1:.9} nm, A0 = {} nm",
            model.free_amplitude_nm()
        );
    }
}

#[test]
fn trigonometric_minimum_with_several_harmonics_matches_brute_force() {
    let polynomial = TrigonometricPolynomial {
        constant: 0.3,
        harmonics: vec![[1.0, -0.4], [0.0, 0.0], [0.35, 0.2], [-0.1, 0.05]],
    };
    let (theta, value) = polynomial.minimum();
    let reference = brute_force_minimum(|t| polynomial.evaluate(t)[0], 2.0 * PI, 100_000);
    assert!((value - reference).abs() < 1e-12, "{value} vs {reference}");
    assert!(polynomial.evaluate(theta)[1].abs() < 1e-10);
}
