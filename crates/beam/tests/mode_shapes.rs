//! Mode shapes and modal integrals against independent computations: boundary conditions, the
//! textbook (unstable) shape formula where it is still accurate, Gauss-Legendre quadrature of the
//! closed forms, orthogonality, and the static deflections of the cantilever expanded in modes.

use beam::{
    distributed_force_by_quadrature, mass_product, stiffness_product, Beam, ModeShape, MAX_MODES,
};

const RATIOS: [f64; 6] = [0.0, 0.1, 0.16, 1.0, 10.0, 1000.0];

/// Relative accuracy expected of a unit-tip-normalised mode. The eigenvalue b carries a
/// rounding error of about half an ulp, eps b / 2, and normalising by the tip deflection U(1)
/// amplifies it by d ln U(1) / d ln b ~ |phi'(1)|: large for high modes with a tip mass, whose
/// tip barely moves (|phi'(1)| ~ b + mu b^2). Measured errors are 0.2 to 0.7 eps |phi'(1)|;
/// allow 8 eps |phi'(1)| (a root up to ~10 ulps off) plus a 1e-13 floor for the arithmetic.
fn relative_accuracy(mode: &ModeShape) -> f64 {
    1e-13 + 8.0 * f64::EPSILON * mode.tip_slope().abs()
}

/// Largest |phi| on a fine grid: the scale for absolute errors of the shape.
fn sup_norm(mode: &ModeShape) -> f64 {
    (0..=1000)
        .map(|i| mode.deflection(i as f64 / 1000.0).abs())
        .fold(0.0, f64::max)
}

#[test]
fn boundary_conditions_hold_for_every_mode() {
    // phi(0) = phi'(0) = 0 (clamp), phi(1) = 1 (normalisation), phi''(1) = 0 (no moment),
    // phi'''(1) = -mu b^4 phi(1) (tip mass inertia). Each k-th derivative is compared on the
    // scale b^k sup|phi| of its own size (plus mu b^4 for the shear), to relative_accuracy.
    for mu in RATIOS {
        for mode in Beam::new(mu)
            .expect("valid")
            .modes(MAX_MODES)
            .expect("modes")
        {
            let b = mode.eigenvalue();
            let sup = sup_norm(&mode);
            let base = mode.derivatives(0.0);
            let tip = mode.derivatives(1.0);
            let accuracy = relative_accuracy(&mode);
            let tol = |k: i32| accuracy * (sup * b.powi(k) + mu * b.powi(4));
            let n = mode.index();
            assert!(
                base[0].abs() <= tol(0),
                "mu {mu} n {n}: phi(0) = {}",
                base[0]
            );
            assert!(
                base[1].abs() <= tol(1),
                "mu {mu} n {n}: phi'(0) = {}",
                base[1]
            );
            assert!(
                (tip[0] - 1.0).abs() <= 1e-14,
                "mu {mu} n {n}: phi(1) = {}",
                tip[0]
            );
            assert!(
                tip[2].abs() <= tol(2),
                "mu {mu} n {n}: phi''(1) = {}",
                tip[2]
            );
            let shear = tip[3] + mu * b.powi(4);
            assert!(
                shear.abs() <= tol(3),
                "mu {mu} n {n}: shear residual {shear}"
            );
        }
    }
}

#[test]
fn stable_shape_matches_the_textbook_formula_for_low_modes() {
    // U = cosh b xi - cos b xi - sigma (sinh b xi - sin b xi), sigma = (cosh b + cos b) /
    // (sinh b + sin b), evaluated directly: cosh b xi and sigma sinh b xi cancel, so its rounding
    // error is ~ eps (cosh b xi + |sigma| sinh b xi) / |U(1)| (8 eps allowed), the same at xi = 1
    // for the normalisation by U(1), plus the stable
    // form's own relative_accuracy. Checked for the first 6 modes (b < 20).
    for mu in RATIOS {
        for mode in Beam::new(mu).expect("valid").modes(6).expect("modes") {
            let b = mode.eigenvalue();
            let sigma = (b.cosh() + b.cos()) / (b.sinh() + b.sin());
            let textbook = |xi: f64| {
                (b * xi).cosh() - (b * xi).cos() - sigma * ((b * xi).sinh() - (b * xi).sin())
            };
            let tip = textbook(1.0);
            for i in 0..=20 {
                let xi = i as f64 / 20.0;
                let direct = textbook(xi) / tip;
                let stable = mode.deflection(xi);
                // Error of U(xi), and of the normalisation by U(1), in relative terms.
                let cancellation =
                    |x: f64| 8.0 * f64::EPSILON * ((b * x).cosh() + sigma.abs() * (b * x).sinh());
                let rounding = (cancellation(xi) + cancellation(1.0) * direct.abs()) / tip.abs();
                assert!(
                    (direct - stable).abs()
                        <= rounding + relative_accuracy(&mode) * sup_norm(&mode),
                    "mu {mu} n {} xi {xi}: {direct} vs {stable}",
                    mode.index()
                );
            }
        }
    }
}

#[test]
fn closed_form_integrals_match_quadrature() {
    // Modal mass, stiffness (= int phi''^2, the Rayleigh quotient) and int phi against 16-point
    // Gauss-Legendre on 2 b panels. Quadrature error is far below rounding (see panels_for); the
    // closed forms assume the tip boundary condition holds exactly, which it does to
    // relative_accuracy, and cancel O(mu) terms: tolerance relative_accuracy times (1 + mu)
    // times the size of the integrand, sup|phi|^2 (times b^4 for the stiffness).
    for mu in RATIOS {
        for mode in Beam::new(mu)
            .expect("valid")
            .modes(MAX_MODES)
            .expect("modes")
        {
            let n = mode.index();
            let sup = sup_norm(&mode);
            let b4 = mode.eigenvalue().powi(4);
            let mass = mass_product(&mode, &mode).expect("quadrature");
            let accuracy = relative_accuracy(&mode);
            let scale = (1.0 + mu) * sup * sup;
            assert!(
                (mass - mode.modal_mass()).abs() <= accuracy * scale,
                "mu {mu} n {n}: mass {mass} vs {}",
                mode.modal_mass()
            );
            let beam_part = mass - mu;
            assert!((beam_part - mode.beam_mass_integral()).abs() <= accuracy * scale);
            let stiffness = stiffness_product(&mode, &mode).expect("quadrature");
            assert!(
                (stiffness - mode.stiffness()).abs() <= accuracy * scale * b4,
                "mu {mu} n {n}: stiffness {stiffness} vs {}",
                mode.stiffness()
            );
            let load = distributed_force_by_quadrature(&mode).expect("quadrature");
            assert!(
                (load - mode.distributed_force_integral()).abs() <= accuracy * (1.0 + mu) * sup,
                "mu {mu} n {n}: int phi {load} vs {}",
                mode.distributed_force_integral()
            );
        }
    }
}

#[test]
fn free_cantilever_modal_mass_is_a_quarter() {
    // For mu = 0 and unit tip deflection, int phi^2 = 1/4 for every mode (a classical result:
    // the boundary identity reduces to phi(1)^2 / 4). Checked by quadrature, to 1e-13.
    for mode in Beam::new(0.0)
        .expect("valid")
        .modes(MAX_MODES)
        .expect("modes")
    {
        let mass = mass_product(&mode, &mode).expect("quadrature");
        assert!(
            (mass - 0.25).abs() <= 1e-13 * sup_norm(&mode).powi(2),
            "n {}",
            mode.index()
        );
    }
}

#[test]
fn modes_are_orthogonal_with_the_tip_mass() {
    // Eigenmodes of a self-adjoint problem are orthogonal in the mass inner product that includes
    // the tip mass (int phi_m phi_n + mu phi_m(1) phi_n(1)) and in the stiffness inner product
    // (int phi_m'' phi_n''). Normalised off-diagonal entries must vanish to ~1e-12.
    for mu in RATIOS {
        let modes = Beam::new(mu).expect("valid").modes(20).expect("modes");
        for (i, a) in modes.iter().enumerate() {
            for b in &modes[..i] {
                let mass = mass_product(a, b).expect("quadrature");
                let norm = (a.modal_mass() * b.modal_mass()).sqrt();
                assert!(
                    (mass / norm).abs() <= 1e-12 * (1.0 + mu),
                    "mu {mu}: M[{}, {}] = {:e}",
                    a.index(),
                    b.index(),
                    mass / norm
                );
                let stiffness = stiffness_product(a, b).expect("quadrature");
                let norm = (a.stiffness() * b.stiffness()).sqrt();
                assert!(
                    (stiffness / norm).abs() <= 1e-12 * (1.0 + mu),
                    "mu {mu}: K[{}, {}] = {:e}",
                    a.index(),
                    b.index(),
                    stiffness / norm
                );
            }
        }
    }
}

#[test]
fn without_tip_mass_the_modes_are_not_orthogonal_to_tip_loaded_ones() {
    // The mass inner product must include the tip mass: dropping the mu phi_m(1) phi_n(1) term
    // leaves an O(mu) off-diagonal entry. This shows the orthogonality test above can fail.
    let modes = Beam::new(0.16).expect("valid").modes(2).expect("modes");
    let with_tip = mass_product(&modes[0], &modes[1]).expect("quadrature");
    let beam_only = with_tip - 0.16 * modes[0].deflection(1.0) * modes[1].deflection(1.0);
    assert!(beam_only.abs() > 0.1, "beam-only product {beam_only}");
}

/// Sums `terms` and checks the sum against `exact`, allowing for the truncated tail: terms
/// decay like a power n^-p with p >= 3, so the tail after N terms is below N |last term|.
fn assert_modal_sum(terms: &[f64], exact: f64, what: &str) {
    let sum: f64 = terms.iter().sum();
    let last = terms.last().copied().unwrap_or(0.0).abs();
    let tail_bound = terms.len() as f64 * last + 1e-13;
    assert!(
        (sum - exact).abs() <= tail_bound,
        "{what}: modal sum {sum} vs exact {exact} (tail bound {tail_bound:e})"
    );
}

#[test]
fn modal_expansion_reproduces_static_deflections() {
    // A static load is expanded in modes: the response is sum_n (F_n / k_n) phi_n. The tip mass
    // plays no role in statics, so for every mu the sums must give the textbook cantilever
    // results (units of EI = L = 1): tip force -> tip deflection 1/3, tip slope 1/2; uniform load
    // -> tip deflection 1/8, tip slope 1/6. This ties together k_n (stiffness), the tip slope
    // (chi) and both generalised forces, independently of the paper.
    for mu in [0.0, 0.16, 10.0] {
        let modes = Beam::new(mu)
            .expect("valid")
            .modes(MAX_MODES)
            .expect("modes");
        let terms = |f: &dyn Fn(&ModeShape) -> f64| -> Vec<f64> { modes.iter().map(f).collect() };
        let tip_force_deflection = terms(&|m| m.tip_force_integral() / m.stiffness());
        let tip_force_slope = terms(&|m| m.tip_force_integral() * m.tip_slope() / m.stiffness());
        let load_deflection = terms(&|m| m.distributed_force_integral() / m.stiffness());
        let load_slope = terms(&|m| m.distributed_force_integral() * m.tip_slope() / m.stiffness());
        assert_modal_sum(
            &tip_force_deflection,
            1.0 / 3.0,
            &format!("mu {mu} tip force, w(L)"),
        );
        assert_modal_sum(&tip_force_slope, 0.5, &format!("mu {mu} tip force, w'(L)"));
        assert_modal_sum(
            &load_deflection,
            1.0 / 8.0,
            &format!("mu {mu} uniform load, w(L)"),
        );
        assert_modal_sum(
            &load_slope,
            1.0 / 6.0,
            &format!("mu {mu} uniform load, w'(L)"),
        );
    }
}

#[test]
fn static_tip_compliance_sum_converges_from_below() {
    // Every term 1 / k_n is positive, so the partial sums approach 1/3 from below: a sign error
    // in a stiffness would show here even if it happened to cancel in a tolerance.
    for mu in [0.0, 0.16, 10.0] {
        let modes = Beam::new(mu)
            .expect("valid")
            .modes(MAX_MODES)
            .expect("modes");
        let mut sum = 0.0;
        for mode in &modes {
            assert!(mode.stiffness() > 0.0);
            sum += 1.0 / mode.stiffness();
            assert!(
                sum < 1.0 / 3.0,
                "mu {mu}: partial sum {sum} at mode {}",
                mode.index()
            );
        }
    }
}

#[test]
fn derivatives_match_finite_differences() {
    // Each derivative against a fourth-order central difference of the one below (step h):
    // truncation ~ h^4 b^5 / 30, rounding ~ eps / h, both below 1e-6 of the scale b^k sup|phi|
    // for h = 1e-3 and b <= 50 (mode 16).
    let h = 1e-3;
    for mu in [0.0, 0.16, 10.0] {
        for mode in Beam::new(mu).expect("valid").modes(16).expect("modes") {
            let b = mode.eigenvalue();
            let sup = sup_norm(&mode);
            for i in 1..10 {
                let xi = i as f64 / 10.0;
                let d = |x: f64| mode.derivatives(x);
                let exact = d(xi);
                for k in 0..3 {
                    let fd = (d(xi - 2.0 * h)[k] - 8.0 * d(xi - h)[k] + 8.0 * d(xi + h)[k]
                        - d(xi + 2.0 * h)[k])
                        / (12.0 * h);
                    let scale = sup * b.powi(k as i32 + 1);
                    assert!(
                        (fd - exact[k + 1]).abs() <= 1e-6 * scale,
                        "mu {mu} n {} xi {xi} k {k}: {fd} vs {}",
                        mode.index(),
                        exact[k + 1]
                    );
                }
                // And the differential equation phi'''' = b^4 phi, from the third derivative.
                let fourth = (d(xi - 2.0 * h)[3] - 8.0 * d(xi - h)[3] + 8.0 * d(xi + h)[3]
                    - d(xi + 2.0 * h)[3])
                    / (12.0 * h);
                assert!((fourth - b.powi(4) * exact[0]).abs() <= 1e-6 * sup * b.powi(4));
            }
        }
    }
}

#[test]
fn textbook_shape_loses_all_digits_at_high_modes() {
    // Why the overflow-free form exists: at mu = 0, mode 14 (b = 42.4), the textbook formula's
    // cancellation error eps e^{b} / 2 ~ 300 swamps a shape of order one, while the stable form
    // still meets its boundary conditions (tested above for all 50 modes). The textbook shape is
    // off by far more than 1e-3 somewhere on the beam.
    let mode = Beam::new(0.0).expect("valid").mode(14).expect("mode");
    let b = mode.eigenvalue();
    let sigma = (b.cosh() + b.cos()) / (b.sinh() + b.sin());
    let textbook =
        |xi: f64| (b * xi).cosh() - (b * xi).cos() - sigma * ((b * xi).sinh() - (b * xi).sin());
    let tip = textbook(1.0);
    let worst = (0..=100)
        .map(|i| {
            let xi = i as f64 / 100.0;
            (textbook(xi) / tip - mode.deflection(xi)).abs()
        })
        .fold(0.0, f64::max);
    assert!(
        worst > 1e-3,
        "textbook form unexpectedly accurate: {worst:e}"
    );
}
