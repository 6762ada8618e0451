//! The Gauss-Legendre rule against exact integrals.

use beam::{BeamError, GaussLegendre};

#[test]
fn exact_for_polynomials_up_to_degree_2n_minus_1() {
    // int_{-1}^{1} x^k dx = 2 / (k + 1) for even k, 0 for odd k; an n-point rule is exact up to
    // k = 2n - 1 (to rounding, 1e-14), and not for k = 2n (checked for n <= 10, where the
    // x^{2n} error 2^{2n+1} (n!)^4 / ((2n+1) ((2n)!)^3) (2n)! stays above 1e-9).
    for order in [1, 2, 3, 5, 8, 10, 16, 32, 64] {
        let rule = GaussLegendre::new(order).expect("valid order");
        let sum: f64 = rule.weights().iter().sum();
        assert!(
            (sum - 2.0).abs() <= 1e-14,
            "order {order}: weights sum {sum}"
        );
        for k in 0..(2 * order) {
            let exact = if k % 2 == 0 {
                2.0 / (k as f64 + 1.0)
            } else {
                0.0
            };
            let got = rule
                .integrate(|x| x.powi(k as i32), -1.0, 1.0, 1)
                .expect("valid");
            assert!((got - exact).abs() <= 1e-14, "order {order}, x^{k}: {got}");
        }
        if order <= 10 {
            let k = 2 * order;
            let got = rule
                .integrate(|x| x.powi(k as i32), -1.0, 1.0, 1)
                .expect("valid");
            assert!(
                (got - 2.0 / (k as f64 + 1.0)).abs() > 1e-9,
                "order {order}, x^{k}"
            );
        }
    }
}

#[test]
fn composite_rule_integrates_oscillatory_and_exponential_functions() {
    // int_0^1 e^{-40 x} dx = (1 - e^{-40}) / 40 and int_0^1 cos(100 x) dx = sin(100) / 100:
    // the boundary layer and the oscillation of a high mode, to 1e-14.
    let rule = GaussLegendre::new(16).expect("valid");
    let layer = rule
        .integrate(|x| (-40.0 * x).exp(), 0.0, 1.0, 80)
        .expect("valid");
    assert!((layer - (1.0 - (-40.0f64).exp()) / 40.0).abs() <= 1e-14);
    let wave = rule
        .integrate(|x| (100.0 * x).cos(), 0.0, 1.0, 200)
        .expect("valid");
    assert!((wave - 100.0f64.sin() / 100.0).abs() <= 1e-14);
}

#[test]
fn rejects_unusable_sizes() {
    assert!(matches!(
        GaussLegendre::new(0),
        Err(BeamError::QuadratureOutOfRange { field: "order", .. })
    ));
    assert!(matches!(
        GaussLegendre::new(65),
        Err(BeamError::QuadratureOutOfRange { field: "order", .. })
    ));
    let rule = GaussLegendre::new(4).expect("valid");
    assert!(matches!(
        rule.integrate(|x| x, 0.0, 1.0, 0),
        Err(BeamError::QuadratureOutOfRange {
            field: "panels",
            ..
        })
    ));
}
