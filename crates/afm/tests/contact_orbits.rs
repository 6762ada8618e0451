//! Steady orbits and grazing points of the non-Hertz contact laws (MODEL.md section 9) against
//! the shared brute force of `brute_force/`: fixed-step RK4 on the model's vector field, with
//! each crossing of a switching surface located by bisection of the step and the step split
//! there, a step 64 times finer in contact, and the lock-in integrals by the trapezoidal rule
//! on the uniform grid. It shares with drumroll only the field `f_m(t, x)` and the switching
//! functions, not the solver, its event location, Newton or continuation.

mod brute_force;
use brute_force::{brute_force, grazing_by_bisection_within};

use afm::{
    approach_diagram, builtin_cantilever, steady_orbit, DiagramSettings, OrbitStart, Sample,
    Separation, SteadyOrbitSettings, TappingModel,
};

fn model_with(contact: &str, z: f64) -> TappingModel {
    let text = format!(
        r#"{{"name": "test", "youngs_modulus_gpa": 1.0, "poisson_ratio": 0.3, "contact": {contact}}}"#
    );
    let sample: Sample = afm::fixtures::parse_sample("test.json", &text).unwrap();
    let cantilever = builtin_cantilever("biolever").unwrap();
    TappingModel::new(cantilever, sample, 10.0, None, Separation::Constant(z)).unwrap()
}

fn check_orbit(contact: &str, z: f64) {
    let model = model_with(contact, z);
    let settings = SteadyOrbitSettings::default();
    let orbit = steady_orbit(&model, z, OrbitStart::Approach, &settings).unwrap();
    assert!(orbit.converged && orbit.multiplicity == 1, "{contact}");
    let observables = orbit.observables();
    let last = brute_force(&model, &orbit.state, 3);
    let (ratio, phase) = (last.amplitude_ratio, last.phase_deg);
    assert!(
        (ratio - observables.amplitude_ratio).abs() < 1e-6,
        "{contact}: A/A0 {ratio} vs {}",
        observables.amplitude_ratio
    );
    assert!(
        (phase - observables.phase_deg).abs() < 1e-6,
        "{contact}: phase {phase} vs {}",
        observables.phase_deg
    );
}

#[test]
fn dmt_orbit_matches_the_brute_force() {
    check_orbit(
        r#"{"law": "dmt", "hamaker_constant_j": 5e-22, "intermolecular_distance_nm": 0.165}"#,
        8.5,
    );
}

#[test]
fn clipped_kelvin_voigt_orbit_matches_the_brute_force() {
    check_orbit(r#"{"law": "kelvin-voigt", "viscosity_pa_s": 100}"#, 8.5);
}

#[test]
fn film_orbit_matches_the_brute_force() {
    check_orbit(r#"{"law": "film", "thickness_nm": 6}"#, 8.5);
}

/// The grazing `label` of `contact` from `drumroll continue`'s diagram against a bisection in
/// Z on the brute-force orbit's gap minimum nearest the surface (each orbit 12 periods from
/// the diagram's state at the grazing: the Biolever's transients decay by over 1e-13 in that
/// time).
fn check_grazing(contact: &str, label: &str) {
    let model = model_with(contact, 9.0);
    let diagram = approach_diagram(&model, &DiagramSettings::approach(&model)).unwrap();
    let g2 = diagram
        .special_points
        .iter()
        .find(|p| p.label == label)
        .expect("the grazing on the approach");
    assert!(g2.converged);
    let z = grazing_by_bisection_within(&model, &g2.state, g2.z_nm, 2e-3, 12);
    assert!(
        (z - g2.z_nm).abs() < 1e-7,
        "{contact}: G2 {} vs brute force {z}",
        g2.z_nm
    );
}

#[test]
fn dmt_grazing_matches_the_brute_force_bisection() {
    check_grazing(
        r#"{"law": "dmt", "hamaker_constant_j": 5e-22, "intermolecular_distance_nm": 0.165}"#,
        "G2",
    );
}

/// DMT's first contact, moved from the force-free estimate `Z_G1 + a0` by the van der Waals
/// attraction of the free flight.
#[test]
fn dmt_first_contact_matches_the_brute_force_bisection() {
    check_grazing(
        r#"{"law": "dmt", "hamaker_constant_j": 5e-22, "intermolecular_distance_nm": 0.165}"#,
        "G1",
    );
}

#[test]
fn clipped_kelvin_voigt_grazing_matches_the_brute_force_bisection() {
    check_grazing(r#"{"law": "kelvin-voigt", "viscosity_pa_s": 100}"#, "G2");
}

/// The Hertz limits at orbit level: DMT with H = 0 is Hertz shifted to `d = a0` (its orbit at
/// `Z + a0` is Hertz's at `Z`) and Kelvin-Voigt with eta = 0 is Hertz: A/A0 and phase agree
/// with the Hertz sphere's to 1e-9 (the solver's tolerance is 1e-12). A film's correction is
/// `a_1 sqrt(R s) / h` to first order: its orbit's distance from Hertz's falls like `1/h`
/// (by 10 +- 2 from h = 1e4 to 1e5 nm, the top of the thickness range).
#[test]
fn limits_reproduce_the_hertz_orbit() {
    let z = 8.5;
    let settings = SteadyOrbitSettings::default();
    let observe = |contact: &str, z: f64| {
        let model = model_with(contact, z);
        let orbit = steady_orbit(&model, z, OrbitStart::Approach, &settings).unwrap();
        assert!(orbit.converged, "{contact}");
        let o = orbit.observables();
        (o.amplitude_ratio, o.phase_deg)
    };
    let hertz = observe(r#"{"law": "hertz"}"#, z);
    let exact = [
        (
            r#"{"law": "dmt", "hamaker_constant_j": 0, "intermolecular_distance_nm": 0.165}"#,
            z + 0.165,
        ),
        (r#"{"law": "kelvin-voigt", "viscosity_pa_s": 0}"#, z),
    ];
    for (contact, at) in exact {
        let (ratio, phase) = observe(contact, at);
        assert!(
            (ratio - hertz.0).abs() < 1e-9 && (phase - hertz.1).abs() < 1e-9,
            "{contact}: ({ratio}, {phase}) vs Hertz {hertz:?}"
        );
    }
    let film_phase_offset = |thickness: f64| {
        let contact = format!(r#"{{"law": "film", "thickness_nm": {thickness}}}"#);
        observe(&contact, z).1 - hertz.1
    };
    let (thick, thicker) = (film_phase_offset(1e4), film_phase_offset(1e5));
    let ratio = thick / thicker;
    assert!(
        (8.0..12.0).contains(&ratio),
        "{thick:e} then {thicker:e}: ratio {ratio}"
    );
}

/// The clipped law's first contact, a double grazing (`d = 0`, `d' = 0` also puts the state on
/// the release surface `h_1 = -d - tau d' = 0`): located, converged, and at the brute force's Z.
#[test]
fn clipped_kelvin_voigt_first_contact_matches_the_brute_force_bisection() {
    check_grazing(r#"{"law": "kelvin-voigt", "viscosity_pa_s": 100}"#, "G1");
}
