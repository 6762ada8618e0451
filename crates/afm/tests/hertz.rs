//! Hertz contact: E* and the force law against hand computations (MODEL.md section 1).

mod common;

use afm::{effective_modulus_gpa, HertzContact, Sample};

#[test]
fn effective_modulus_of_mica_and_soft_sample_by_hand() {
    // E* = [0.91/E_s + 0.91/130]^{-1} = 130 E_s / (0.91 (130 + E_s)).
    // Mica: 7800 / (0.91 * 190) = 7800 / 172.9; soft: 130 / (0.91 * 131) = 130 / 119.21.
    let mica = effective_modulus_gpa(60.0, 0.3, 130.0, 0.3);
    let soft = effective_modulus_gpa(1.0, 0.3, 130.0, 0.3);
    // Two roundings apart at most: a few ulps.
    assert!((mica - 7800.0 / 172.9).abs() < 1e-13 * mica, "{mica}");
    assert!((soft - 130.0 / 119.21).abs() < 1e-13 * soft, "{soft}");
    assert!((mica - 45.112_781_954_887_2).abs() < 1e-12);
    assert!((soft - 1.090_512_540_894_22).abs() < 1e-12, "{soft}");
}

#[test]
fn hertz_force_in_nanonewtons_and_its_derivative() {
    let cantilever = common::biolever();
    let sample = common::mica();
    let contact = HertzContact::new(&cantilever, &sample);
    // F = (4/3) E* sqrt(R) (-d)^{3/2} with E* = 7800/172.9 GPa, R = 30 nm, d = -0.5 nm.
    let expected = 4.0 / 3.0 * (7800.0 / 172.9) * 30f64.sqrt() * 0.5f64.powf(1.5);
    assert!((contact.force(-0.5) - expected).abs() < 1e-13 * expected);
    assert_eq!(contact.force(0.0), 0.0);
    assert_eq!(contact.force(0.3), 0.0);
    assert_eq!(contact.force_derivative(0.3), 0.0);
    // Central difference, step 1e-5 nm: truncation ~ F''' h^2 ~ 1e-10 relative; rounding
    // ~ eps F / h ~ 1e-11 relative.
    for d in [-0.01, -0.5, -3.0] {
        let h = 1e-5;
        let numeric = (contact.force(d + h) - contact.force(d - h)) / (2.0 * h);
        let analytic = contact.force_derivative(d);
        assert!(
            (numeric - analytic).abs() < 1e-7 * analytic.abs(),
            "{d}: {numeric} vs {analytic}"
        );
    }
    let soft = Sample {
        youngs_modulus_gpa: 1.0,
        ..sample
    };
    let soft_contact = HertzContact::new(&cantilever, &soft);
    let ratio = soft_contact.coefficient / contact.coefficient;
    assert!((ratio - (130.0 / 119.21) / (7800.0 / 172.9)).abs() < 1e-14);
}
