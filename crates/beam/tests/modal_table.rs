//! The modal table against quadrature and closed forms computed independently of it, plus
//! input validation and serialisation.

use beam::{
    distributed_force_by_quadrature, mass_product, modal_table, stiffness_product, Beam, BeamError,
    MAX_MODES, MAX_TIP_MASS_RATIO,
};

#[test]
fn first_row_is_the_reference() {
    for mu in [0.0, 0.16, 10.0] {
        let table = modal_table(mu, 3).expect("valid");
        let first = &table[0];
        assert_eq!(first.index, 1);
        for ratio in [
            first.frequency_ratio,
            first.stiffness_ratio,
            first.chi,
            first.force_ratio_distributed,
            first.force_ratio_tip,
        ] {
            assert!((ratio - 1.0).abs() <= 1e-15, "mu {mu}: {ratio}");
        }
        assert_eq!(table.iter().map(|r| r.index).collect::<Vec<_>>(), [1, 2, 3]);
    }
}

#[test]
fn ratios_match_quadrature_rayleigh_quotients() {
    // w_n^2 = K_nn / M_nn (stiffness and mass by quadrature) gives the frequency ratio
    // independently of (b_n / b_1)^2; K_nn / K_11 the stiffness ratio; int phi_n / int phi_1 the
    // distributed force ratio. Tolerance 1e-11: quadrature and closed forms agree to ~1e-13 for
    // modes up to 10 and mu <= 10 (relative_accuracy in tests/mode_shapes.rs).
    for mu in [0.0, 0.1, 0.16, 2.0, 10.0] {
        let table = modal_table(mu, 10).expect("valid");
        let modes = Beam::new(mu).expect("valid").modes(10).expect("modes");
        let rayleigh = |n: usize| {
            let m = &modes[n];
            stiffness_product(m, m).expect("quadrature") / mass_product(m, m).expect("quadrature")
        };
        let k = |n: usize| stiffness_product(&modes[n], &modes[n]).expect("quadrature");
        let load = |n: usize| distributed_force_by_quadrature(&modes[n]).expect("quadrature");
        for (n, row) in table.iter().enumerate() {
            let frequency = (rayleigh(n) / rayleigh(0)).sqrt();
            assert!(
                (row.frequency_ratio / frequency - 1.0).abs() <= 1e-11,
                "mu {mu} n {n}"
            );
            assert!(
                (row.stiffness_ratio / (k(n) / k(0)) - 1.0).abs() <= 1e-11,
                "mu {mu} n {n}"
            );
            let force = load(n) / load(0);
            assert!(
                (row.force_ratio_distributed / force - 1.0).abs() <= 1e-11,
                "mu {mu} n {n}"
            );
            assert!((row.force_ratio_tip - 1.0).abs() <= 1e-15);
        }
    }
}

#[test]
fn chi_matches_the_textbook_tip_slope_for_low_modes() {
    // phi'(1) = b (sinh b + sin b - sigma (cosh b - cos b)) / U(1) with the textbook (directly
    // evaluated) shape, accurate to ~eps e^{b} < 1e-13 relative for modes 1-3 (b < 8).
    for mu in [0.0, 0.1, 0.16, 1.0] {
        let table = modal_table(mu, 3).expect("valid");
        let slope = |b: f64| {
            let sigma = (b.cosh() + b.cos()) / (b.sinh() + b.sin());
            let tip = b.cosh() - b.cos() - sigma * (b.sinh() - b.sin());
            b * (b.sinh() + b.sin() - sigma * (b.cosh() - b.cos())) / tip
        };
        let reference = slope(table[0].eigenvalue);
        for row in &table {
            let chi = slope(row.eigenvalue) / reference;
            assert!(
                (row.chi / chi - 1.0).abs() <= 1e-12,
                "mu {mu} n {}: {}",
                row.index,
                row.chi
            );
        }
    }
}

#[test]
fn frequency_ratio_is_the_square_of_the_eigenvalue_ratio() {
    // w_n / w_1 = (b_n / b_1)^2 (w = b^2 sqrt(EI / (rho A L^4))), in vacuum.
    let table = modal_table(0.16, 5).expect("valid");
    for row in &table {
        let expected = (row.eigenvalue / table[0].eigenvalue).powi(2);
        assert!((row.frequency_ratio - expected).abs() <= 1e-14 * expected);
    }
}

#[test]
fn rejects_invalid_tip_mass_ratios() {
    for bad in [
        -1e-9,
        -1.0,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        1_000.000_001,
    ] {
        match modal_table(bad, 2) {
            Err(BeamError::TipMassRatioOutOfRange { value, max }) => {
                assert!(value.is_nan() && bad.is_nan() || value == bad);
                assert_eq!(max, MAX_TIP_MASS_RATIO);
            }
            other => panic!("tip mass ratio {bad} accepted: {other:?}"),
        }
        let message = Beam::new(bad).expect_err("invalid").to_string();
        assert!(message.contains("tip_mass_ratio"), "{message}");
    }
    assert!(modal_table(0.0, 1).is_ok());
    assert!(modal_table(MAX_TIP_MASS_RATIO, 1).is_ok());
}

#[test]
fn rejects_invalid_mode_counts() {
    for bad in [0, MAX_MODES + 1, usize::MAX] {
        match modal_table(0.16, bad) {
            Err(BeamError::ModeOutOfRange { field, value, max }) => {
                assert_eq!((field, value, max), ("modes", bad, MAX_MODES));
            }
            other => panic!("mode count {bad} accepted: {other:?}"),
        }
    }
    let beam = Beam::new(0.16).expect("valid");
    assert!(matches!(
        beam.mode(0),
        Err(BeamError::ModeOutOfRange { field: "index", .. })
    ));
    assert_eq!(
        modal_table(0.16, MAX_MODES).expect("valid").len(),
        MAX_MODES
    );
}

#[test]
fn serialises_with_the_documented_field_names() {
    let table = modal_table(0.16, 2).expect("valid");
    let json = serde_json::to_value(table[1]).expect("serialise");
    for field in [
        "index",
        "eigenvalue",
        "frequency_ratio",
        "stiffness_ratio",
        "chi",
        "force_ratio_distributed",
        "force_ratio_tip",
    ] {
        assert!(json.get(field).is_some(), "missing {field} in {json}");
    }
    assert_eq!(json["index"], 2);
}
