//! The hydration (solvation) force (MODEL.md section 9, "Hydration force"): its closed form
//! against the Derjaguin integral of the pressure done numerically here, its steady orbit
//! against the brute force of `brute_force/mod.rs`, its zero-pressure limit against Hertz, and
//! the built-in case's diagram and energy balance.

mod brute_force;

use std::f64::consts::PI;

use afm::contact::HydrationForce;
use afm::{
    approach_diagram, builtin_case, steady_orbit, DiagramSettings, OrbitStart, Separation,
    SteadyOrbitSettings, TappingModel,
};
use brute_force::brute_force;

/// `F(d) = 2 pi R int_d^inf P(D) dD` with `P = P_0 cos(2 pi D / sigma) exp(-D / lambda)`, by
/// composite Simpson on [d, d + 60 lambda] in 600000 intervals (truncation `exp(-60)`,
/// quadrature error ~1e-16 relative): the closed form agrees to 1e-10 relative to its
/// amplitude, and its slope with `-2 pi R P(d)` to 1e-12.
#[test]
fn closed_form_matches_the_derjaguin_integral() {
    let (radius, pressure, spacing, decay) = (30.0, 10.0, 0.25, 0.3);
    let force = HydrationForce::new(radius, pressure, spacing, decay);
    let p = |d: f64| pressure * 1e-3 * (2.0 * PI * d / spacing).cos() * (-d / decay).exp();
    for d in [-0.1, 0.0, 0.07, 0.2, 0.5, 1.3] {
        let (length, n) = (60.0 * decay, 600_000);
        let h = length / n as f64;
        let mut sum = p(d) + p(d + length);
        for i in 1..n {
            sum += if i % 2 == 1 { 4.0 } else { 2.0 } * p(d + i as f64 * h);
        }
        let reference = 2.0 * PI * radius * sum * h / 3.0;
        let slopes = force.force_slopes(d);
        assert!(
            (slopes.force - reference).abs() < 1e-10 * force.amplitude_nn.abs(),
            "{d}: {} vs {reference}",
            slopes.force
        );
        let slope = -2.0 * PI * radius * p(d);
        assert!((slopes.gap_slope - slope).abs() < 1e-12 * slope.abs().max(1e-3));
    }
}

/// The built-in `biolever-mica-hydration` case at Z = 8.5 nm: A/A0 and phase agree with the
/// brute force's last of 3 periods from the orbit's state to 1e-6 (RK4's error at 40000 steps
/// a period is below 1e-8), the force is conservative (`dissipated_ev` below 1e-9 eV) and the
/// energy balance closes to 1e-9.
#[test]
fn orbit_matches_the_brute_force() {
    let case = builtin_case("biolever-mica-hydration").unwrap();
    let mut model = TappingModel::from_case(&case).unwrap();
    let z = 8.5;
    model.set_separation(Separation::Constant(z)).unwrap();
    let orbit = steady_orbit(
        &model,
        z,
        OrbitStart::Approach,
        &SteadyOrbitSettings::default(),
    )
    .unwrap();
    assert!(orbit.converged && orbit.multiplicity == 1);
    let o = orbit.observables();
    let last = brute_force(&model, &orbit.state, 3);
    assert!(
        (last.amplitude_ratio - o.amplitude_ratio).abs() < 1e-6,
        "A/A0 {} vs {}",
        last.amplitude_ratio,
        o.amplitude_ratio
    );
    assert!(
        (last.phase_deg - o.phase_deg).abs() < 1e-6,
        "phase {} vs {}",
        last.phase_deg,
        o.phase_deg
    );
    assert!(o.dissipated_ev.abs() < 1e-9, "{}", o.dissipated_ev);
    assert!(
        o.energy_balance_residual < 1e-9,
        "{:e}",
        o.energy_balance_residual
    );
}

/// With `P_0 = 0` the force is Hertz's: the diagram's grazing points agree with the plain
/// mica case's to 1e-9 nm; with the built-in 10 MPa the first contact moves (the hydration
/// force acts before contact) and the continuation still passes every grazing.
#[test]
fn zero_pressure_reproduces_hertz_and_the_case_continues() {
    let grazings = |model: &TappingModel| {
        let diagram = approach_diagram(model, &DiagramSettings::approach(model)).unwrap();
        diagram
            .special_points
            .iter()
            .filter(|p| p.label.starts_with('G'))
            .map(|p| (p.label.clone(), p.z_nm, p.converged))
            .collect::<Vec<_>>()
    };
    let hertz =
        grazings(&TappingModel::from_case(&builtin_case("biolever-mica").unwrap()).unwrap());
    let mut case = builtin_case("biolever-mica-hydration").unwrap();
    let hydrated = grazings(&TappingModel::from_case(&case).unwrap());
    case.sample.hydration.as_mut().unwrap().pressure_mpa = 0.0;
    let limit = grazings(&TappingModel::from_case(&case).unwrap());
    assert!(hertz.len() >= 2, "{hertz:?}");
    assert_eq!(hertz.len(), limit.len(), "{hertz:?} vs {limit:?}");
    for ((label, z, _), (limit_label, limit_z, converged)) in hertz.iter().zip(&limit) {
        assert_eq!(label, limit_label);
        assert!(converged);
        assert!(
            (z - limit_z).abs() < 1e-9,
            "{label}: Hertz {z} vs P0 = 0 {limit_z}"
        );
    }
    assert!(
        hydrated.iter().all(|(_, _, converged)| *converged),
        "{hydrated:?}"
    );
    let g1 = |points: &[(String, f64, bool)]| points.iter().find(|p| p.0 == "G1").unwrap().1;
    assert!((g1(&hydrated) - g1(&hertz)).abs() > 1e-6, "{hydrated:?}");
}

/// Out-of-range parameters are refused naming the file and the field.
#[test]
fn sample_file_checks_the_hydration_object() {
    let text = r#"{"name": "t", "youngs_modulus_gpa": 60, "hydration": {"pressure_mpa": 10, "layer_spacing_nm": 0, "decay_length_nm": 0.3}}"#;
    let error = afm::fixtures::parse_sample("t.json", text)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("t.json") && error.contains("hydration.layer_spacing_nm"),
        "{error}"
    );
}
