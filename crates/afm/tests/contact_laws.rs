//! Each contact law's force (MODEL.md section 9) against its closed form written out here at
//! several gaps, its slopes against central differences, its continuity on its contact surface
//! where the law is continuous, the Hertz limits (H = 0, eta = 0, h -> infinity), and the
//! sample file's `contact` / `electrostatic` objects: parsed, defaulted and range-checked.

use std::f64::consts::PI;

use afm::contact::{
    ContactLaw, DmtContact, DoubleLayer, FilmContact, FilmCorrection, HertzShape, HertzTip,
    KelvinVoigtContact, TipSampleForce,
};
use afm::fixtures::parse_sample;

/// E* = 1 GPa, R = 10 nm.
const E: f64 = 1.0;
const R: f64 = 10.0;

fn sphere() -> HertzShape {
    HertzShape {
        effective_modulus_gpa: E,
        tip: HertzTip::Sphere { radius_nm: R },
    }
}

fn alone(law: ContactLaw) -> TipSampleForce {
    TipSampleForce {
        law,
        double_layer: None,
        hydration: None,
    }
}

/// Relative agreement `|a - b| <= tol max(|a|, |b|, 1e-300)`.
fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(1e-300)
}

/// The slopes of `force(d, rate)` against central differences (step 1e-6 nm, nm/us;
/// truncation ~1e-12 relative, so 1e-6 leaves room for the rounding).
fn check_slopes(force: &TipSampleForce, inside: bool, clipped: bool, d: f64, rate: f64) {
    let h = 1e-6;
    let at = |d: f64, r: f64| force.in_region(inside, clipped, d, r).force;
    let slopes = force.in_region(inside, clipped, d, rate);
    let gap = (at(d + h, rate) - at(d - h, rate)) / (2.0 * h);
    let rate_slope = (at(d, rate + h) - at(d, rate - h)) / (2.0 * h);
    assert!(
        (gap - slopes.gap_slope).abs() <= 1e-6 * gap.abs().max(1.0),
        "dF/dd at d = {d}: {gap} vs {}",
        slopes.gap_slope
    );
    assert!(
        (rate_slope - slopes.rate_slope).abs() <= 1e-6 * rate_slope.abs().max(1.0),
        "dF/dd' at d = {d}: {rate_slope} vs {}",
        slopes.rate_slope
    );
}

#[test]
fn hertz_shapes_match_their_closed_forms() {
    // (4/3) E* sqrt(R) delta^{3/2} at delta = 1 nm: 4.2164 nN (the issue's number).
    let law = alone(ContactLaw::Hertz(sphere()));
    assert!((law.force(-1.0, 0.0) - 4.2164).abs() < 5e-5);
    for d in [-3.0f64, -1.0, -0.2, -1e-3] {
        let exact = 4.0 / 3.0 * E * R.sqrt() * (-d).powf(1.5);
        assert!(close(law.force(d, 0.0), exact, 1e-14), "sphere at {d}");
        check_slopes(&law, true, false, d, 0.0);
    }
    assert_eq!(law.force(0.5, 0.0), 0.0);
    let cone = alone(ContactLaw::Hertz(HertzShape {
        effective_modulus_gpa: E,
        tip: HertzTip::Cone {
            half_angle_deg: 20.0,
        },
    }));
    let punch = alone(ContactLaw::Hertz(HertzShape {
        effective_modulus_gpa: E,
        tip: HertzTip::FlatPunch { radius_nm: 5.0 },
    }));
    for d in [-2.0, -0.7, -0.01] {
        let s: f64 = -d;
        let cone_exact = 2.0 / PI * E * 20f64.to_radians().tan() * s * s;
        assert!(close(cone.force(d, 0.0), cone_exact, 1e-14), "cone at {d}");
        assert!(
            close(punch.force(d, 0.0), 2.0 * E * 5.0 * s, 1e-14),
            "punch at {d}"
        );
        check_slopes(&cone, true, false, d, 0.0);
        check_slopes(&punch, true, false, d, 0.0);
    }
    // Continuous at d = 0 from inside.
    for law in [&cone, &punch, &law] {
        assert!(law.in_region(true, false, -1e-12, 0.0).force.abs() < 1e-10);
    }
}

fn dmt(hamaker_j: f64) -> DmtContact {
    DmtContact {
        effective_modulus_gpa: E,
        tip_radius_nm: R,
        hamaker_constant_j: hamaker_j,
        intermolecular_distance_nm: 0.165,
    }
}

#[test]
fn dmt_matches_its_closed_form_and_is_continuous_at_a0() {
    let (h_j, a0) = (5e-20, 0.165);
    let law = alone(ContactLaw::Dmt(dmt(h_j)));
    // H R / 6 in nN nm: H (J) * 1e18.
    let scale = h_j * 1e18 * R / 6.0;
    for d in [0.165, 0.3, 1.0, 5.0] {
        assert!(
            close(law.force(d, 0.0), -scale / (d * d), 1e-14),
            "outside at {d}"
        );
        check_slopes(&law, false, false, d, 0.0);
    }
    for d in [0.1f64, -0.5, -2.0] {
        let exact = 4.0 / 3.0 * E * R.sqrt() * (a0 - d).powf(1.5) - scale / (a0 * a0);
        assert!(close(law.force(d, 0.0), exact, 1e-14), "inside at {d}");
        check_slopes(&law, true, false, d, 0.0);
    }
    let below = law.in_region(true, false, a0, 0.0).force;
    let above = law.in_region(false, false, a0, 0.0).force;
    assert!(close(below, above, 1e-14), "{below} vs {above}");
    // H = 0: Hertz shifted to d = a0.
    let hertz = alone(ContactLaw::Hertz(sphere()));
    let plain = alone(ContactLaw::Dmt(dmt(0.0)));
    for d in [-1.0, 0.0, 0.1] {
        assert!(close(plain.force(d, 0.0), hertz.force(d - a0, 0.0), 1e-14));
    }
    assert_eq!(plain.force(0.5, 0.0), 0.0);
    assert!(!plain.acts_outside_contact() && law.acts_outside_contact());
}

fn kelvin_voigt(viscosity_pa_s: f64, clip: bool) -> KelvinVoigtContact {
    KelvinVoigtContact {
        effective_modulus_gpa: E,
        tip_radius_nm: R,
        effective_viscosity_pa_s: viscosity_pa_s,
        clip,
    }
}

#[test]
fn kelvin_voigt_matches_its_closed_form_clips_and_reduces_to_hertz() {
    let eta = 100.0; // Pa s = 0.1 nN us / nm^2
    let unclipped = alone(ContactLaw::KelvinVoigt(kelvin_voigt(eta, false)));
    let clipped = alone(ContactLaw::KelvinVoigt(kelvin_voigt(eta, true)));
    for (d, rate) in [(-1.0, -0.3), (-0.5, 0.2), (-2.0, 1.5), (-0.1, -2.0)] {
        let s: f64 = -d;
        let s_rate = -rate;
        // (4/3) sqrt(R) [E* s^{3/2} + eta* (3/2) s^{1/2} s'], eta* in nN us/nm^2.
        let exact = 4.0 / 3.0 * R.sqrt() * (E * s.powf(1.5) + eta * 1e-3 * 1.5 * s.sqrt() * s_rate);
        assert!(
            close(unclipped.force(d, rate), exact, 1e-13),
            "at ({d}, {rate})"
        );
        assert!(close(clipped.force(d, rate), exact.max(0.0), 1e-13));
        check_slopes(&unclipped, true, false, d, rate);
    }
    // (-2, 1.5): s + tau s' = 2 - 0.15 * 1.5 > 0; (-0.1, ...) fine; a fast retreat clips:
    assert!(unclipped.force(-0.1, 2.0) < 0.0);
    assert_eq!(clipped.force(-0.1, 2.0), 0.0);
    assert_eq!(clipped.in_region(true, true, -0.1, 2.0).force, 0.0);
    // tau = 1.5 eta* / E*: 1.5 * 0.1 / 1 = 0.15 us.
    assert!(close(
        ContactLaw::KelvinVoigt(kelvin_voigt(eta, true))
            .release_time_us()
            .unwrap(),
        0.15,
        1e-14
    ));
    // Continuous at d = 0 (the force vanishes as s^{1/2}) and on the release surface.
    assert!(unclipped.force(-1e-14, -1.0).abs() < 1e-6);
    let d = -0.5;
    let release_rate = -d / 0.15; // -d - tau d' = 0
    assert!(
        unclipped
            .in_region(true, false, d, release_rate)
            .force
            .abs()
            < 1e-12
    );
    // eta = 0: Hertz.
    let elastic = alone(ContactLaw::KelvinVoigt(kelvin_voigt(0.0, true)));
    let hertz = alone(ContactLaw::Hertz(sphere()));
    for (d, rate) in [(-1.0, 3.0), (-0.3, -1.0)] {
        assert!(close(elastic.force(d, rate), hertz.force(d, rate), 1e-14));
    }
}

#[test]
fn film_matches_its_closed_form_and_tends_to_hertz_for_thick_films() {
    let hertz = alone(ContactLaw::Hertz(sphere()));
    for correction in [
        FilmCorrection::Garcia2018,
        FilmCorrection::Dimitriadis2002Bonded,
        FilmCorrection::Dimitriadis2002NonBonded,
    ] {
        let film = |h: f64| {
            alone(ContactLaw::Film(FilmContact {
                effective_modulus_gpa: E,
                tip_radius_nm: R,
                thickness_nm: h,
                correction,
            }))
        };
        let a = correction.coefficients();
        for d in [-0.05, -0.5, -2.0] {
            let s: f64 = -d;
            let chi = (R * s).sqrt() / 6.0;
            let p =
                a[0] + a[1] * chi + a[2] * chi.powi(2) + a[3] * chi.powi(3) + a[4] * chi.powi(4);
            let exact = 4.0 / 3.0 * E * R.sqrt() * s.powf(1.5) * p;
            assert!(
                close(film(6.0).force(d, 0.0), exact, 1e-13),
                "{correction:?} at {d}"
            );
            check_slopes(&film(6.0), true, false, d, 0.0);
            // h -> infinity: the correction's first term, a_1 chi, vanishes like 1/h.
            for h in [1e3, 1e6, 1e9] {
                let relative = film(h).force(d, 0.0) / hertz.force(d, 0.0) - 1.0;
                let first_order = a[1] * (R * s).sqrt() / h;
                assert!((relative - first_order).abs() <= 2.0 * first_order * first_order + 1e-15);
            }
        }
        assert!(film(6.0).force(-1e-12, 0.0).abs() < 1e-15);
        assert_eq!(film(6.0).force(0.1, 0.0), 0.0);
    }
}

#[test]
fn double_layer_matches_its_closed_form_and_is_held_inside_contact() {
    let (lambda, sigma, eps_r) = (1.5, 0.02, 80.0);
    let layer = DoubleLayer::new(R, sigma, sigma, eps_r, lambda);
    // 4 pi R sigma_t sigma_s lambda_D / (eps_r eps_0) in SI (m, C/m^2), then N -> nN.
    let amplitude = 4.0 * PI * (R * 1e-9) * sigma * sigma * (lambda * 1e-9)
        / (eps_r * 8.854_187_812_8e-12)
        * 1e9;
    let force = TipSampleForce {
        law: ContactLaw::Hertz(sphere()),
        double_layer: Some(layer),
        hydration: None,
    };
    for d in [0.0, 0.5, 3.0] {
        let exact = amplitude * (-d / lambda).exp();
        assert!(close(force.force(d, 0.0), exact, 1e-13), "at {d}");
        check_slopes(&force, false, false, d, 0.0);
    }
    // Inside contact: Hertz plus the double layer's value at d = 0.
    let hertz = alone(ContactLaw::Hertz(sphere()));
    assert!(close(
        force.force(-1.0, 0.0),
        hertz.force(-1.0, 0.0) + amplitude,
        1e-13
    ));
    assert!(force.acts_outside_contact());
}

#[test]
fn sample_files_parse_default_and_check_the_contact_object() {
    let plain = parse_sample("s.json", r#"{"name": "s", "youngs_modulus_gpa": 1}"#).unwrap();
    assert_eq!(plain.contact, None);
    let kv = parse_sample(
        "s.json",
        r#"{"name": "s", "youngs_modulus_gpa": 1,
            "contact": {"law": "kelvin-voigt", "viscosity_pa_s": 100}}"#,
    )
    .unwrap();
    assert!(format!("{:?}", kv.contact).contains("clip: true"));
    let cases = [
        (
            r#"{"law": "dmt", "hamaker_constant_j": -1e-20, "intermolecular_distance_nm": 0.165}"#,
            "contact.hamaker_constant_j",
        ),
        (
            r#"{"law": "dmt", "hamaker_constant_j": 1e-20, "intermolecular_distance_nm": 0}"#,
            "contact.intermolecular_distance_nm",
        ),
        (
            r#"{"law": "kelvin-voigt", "viscosity_pa_s": -1}"#,
            "contact.viscosity_pa_s",
        ),
        (
            r#"{"law": "film", "thickness_nm": 0}"#,
            "contact.thickness_nm",
        ),
        (
            r#"{"law": "hertz", "tip_shape": "cone"}"#,
            "contact.cone_half_angle_deg",
        ),
        (
            r#"{"law": "hertz", "tip_shape": "flat-punch", "punch_radius_nm": 1e9}"#,
            "contact.punch_radius_nm",
        ),
        (
            r#"{"law": "hertz", "cone_half_angle_deg": 20}"#,
            "contact.cone_half_angle_deg",
        ),
    ];
    for (contact, field) in cases {
        let text = format!(r#"{{"name": "s", "youngs_modulus_gpa": 1, "contact": {contact}}}"#);
        let error = parse_sample("bad.json", &text).unwrap_err().to_string();
        assert!(
            error.contains("bad.json") && error.contains(field),
            "{error}"
        );
    }
    for text in [
        r#"{"law": "magic"}"#,
        r#"{"law": "film", "thickness_nm": 6, "correction": "none"}"#,
        r#"{"law": "dmt", "hamaker_constant_j": 1e-20, "intermolecular_distance_nm": 0.2, "extra": 1}"#,
    ] {
        let text = format!(r#"{{"name": "s", "youngs_modulus_gpa": 1, "contact": {text}}}"#);
        assert!(parse_sample("bad.json", &text).is_err(), "{text}");
    }
    let electrostatic = r#"{"name": "s", "youngs_modulus_gpa": 1, "electrostatic":
        {"debye_length_nm": 1, "tip_charge_c_per_m2": 2, "sample_charge_c_per_m2": 0.01,
         "relative_permittivity": 80}}"#;
    let error = parse_sample("bad.json", electrostatic)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("electrostatic.tip_charge_c_per_m2"),
        "{error}"
    );
}
