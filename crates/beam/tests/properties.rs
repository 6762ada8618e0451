//! Property tests over random tip mass ratios and modes.

use beam::{characteristic_function, eigenvalue_bracket, mass_product, Beam, MAX_MODES};
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn eigenvalue_is_a_bracketed_root(mu in 0.0f64..=1000.0, n in 1usize..=MAX_MODES) {
        let b = Beam::new(mu).unwrap().eigenvalue(n).unwrap();
        let (lower, upper) = eigenvalue_bracket(n);
        prop_assert!(b > lower && b < upper);
        // Residual at the level one can reach in doubles: g's terms and slope are O(1 + mu b),
        // so rounding (eps (2 + mu b)) plus half an ulp of b times the slope
        // (eps b (2 + mu b)); 8 times that allowed.
        let g = characteristic_function(b, mu);
        prop_assert!(g.abs() <= 8.0 * f64::EPSILON * (2.0 + mu * b) * (1.0 + b), "g = {g:e}");
        // The sign of g changes across b: 1e-12 b is ~5000 ulps each side, far beyond the
        // root's error and the rounding noise of g.
        let h = 1e-12 * b;
        prop_assert!(characteristic_function(b - h, mu) * characteristic_function(b + h, mu) < 0.0);
    }

    #[test]
    fn more_tip_mass_lowers_every_eigenvalue(mu in 0.0f64..=500.0, n in 1usize..=20) {
        let lighter = Beam::new(mu).unwrap().eigenvalue(n).unwrap();
        let heavier = Beam::new(mu * 1.5 + 0.01).unwrap().eigenvalue(n).unwrap();
        prop_assert!(heavier < lighter);
    }

    #[test]
    fn closed_form_modal_mass_matches_quadrature(mu in 0.0f64..=100.0, n in 1usize..=20) {
        // Tolerance: see relative_accuracy in tests/mode_shapes.rs.
        let mode = Beam::new(mu).unwrap().mode(n).unwrap();
        let quadrature = mass_product(&mode, &mode).unwrap();
        let accuracy = 1e-13 + 8.0 * f64::EPSILON * mode.tip_slope().abs();
        prop_assert!((quadrature / mode.modal_mass() - 1.0).abs() <= accuracy * (1.0 + mu));
    }
}
