//! The standard linear solid (MODEL.md section 9, "Standard linear solid") against the
//! brute force of `brute_force/mod.rs` (fixed-step RK4 with bisected crossings): its steady
//! orbit, its grazing, its dissipation in the dashpot and its energy balance; `E_0 = E_inf`
//! against Hertz; a regime map through it; the sample file's checks.

mod brute_force;
mod hertz_limit;

use afm::{
    approach_diagram, builtin_cantilever, builtin_case, regime_map, steady_orbit, DiagramSettings,
    OrbitStart, ParameterAxis, RegimeMapSettings, Sample, Separation, SteadyOrbitSettings,
    TappingModel,
};
use brute_force::{brute_force, grazing_by_bisection};

fn model_with(contact: &str, z: f64) -> TappingModel {
    let text = format!(
        r#"{{"name": "test", "youngs_modulus_gpa": 1.0, "poisson_ratio": 0.3, "contact": {contact}}}"#
    );
    let sample: Sample = afm::fixtures::parse_sample("test.json", &text).unwrap();
    let cantilever = builtin_cantilever("biolever").unwrap();
    TappingModel::new(cantilever, sample, 10.0, None, Separation::Constant(z)).unwrap()
}

/// The built-in sample's law: 1 GPa instantly, 0.4 GPa relaxed, tau = 5 us.
const SLS: &str = r#"{"law": "standard-linear-solid", "instant_modulus_gpa": 1.0, "relaxed_modulus_gpa": 0.4, "relaxation_time_us": 5.0}"#;

/// The dashpot's dissipation rate written from MODEL.md section 9 (not the crate's):
/// `D = c_0 (S - (rho/beta)^{2/3}) (beta S^{3/2} - rho) / tau`, `S = max(-d, rho^{2/3})`,
/// with the reduced moduli of the Biolever's tip (`1/E* = (1 - nu_s^2)/E_s + (1 - nu_t^2)/E_t`).
fn dashpot_rate(model: &TappingModel, gap: f64, rho: f64) -> f64 {
    let cantilever = model.cantilever();
    let reduced = |e: f64| {
        1.0 / ((1.0 - 0.09) / e
            + (1.0 - cantilever.tip_poisson_ratio.powi(2)) / cantilever.tip_youngs_modulus_gpa)
    };
    let (e0, einf) = (reduced(1.0), reduced(0.4));
    let c0 = 4.0 / 3.0 * e0 * cantilever.tip_radius_nm.sqrt();
    let beta = 1.0 - einf / e0;
    let s = (-gap).max(rho.powf(2.0 / 3.0));
    c0 * (s - (rho / beta).powf(2.0 / 3.0)) * (beta * s.powf(1.5) - rho) / 5.0
}

/// At Z = 8.5 nm (two impacts a period, the second on a surface not yet recovered): A/A0 and
/// phase agree with the brute force's last of 3 periods from the orbit's state to 1e-6 (RK4's
/// error at 40000 steps a period, with 64 times finer contact steps, is below 1e-8; the
/// trapezoidal lock-in's below 1e-9). The energy the tip puts into the sample per period,
/// `-int F_ts w' dt`, and the dashpot's loss `int D dt`, both by the trapezoidal rule on the
/// brute-force grid, agree with `dissipated_ev` to 1e-5 relative (the grid's second-order error
/// at the contacts' kinks of `D'`); the energy balance closes to 1e-9; the largest and the mean
/// indentation below the unrecovered surface agree with the grid's.
#[test]
fn orbit_and_dissipation_match_the_brute_force() {
    let z = 8.5;
    let model = model_with(SLS, z);
    let orbit = steady_orbit(
        &model,
        z,
        OrbitStart::Approach,
        &SteadyOrbitSettings::default(),
    )
    .unwrap();
    assert!(orbit.converged && orbit.multiplicity == 1);
    let o = orbit.observables();
    assert_eq!(o.impacts_per_period, 2.0);
    // The sample is still deformed when the period starts (rho > 0 between the impacts).
    assert!(orbit.state[4] > 1e-4, "rho = {}", orbit.state[4]);
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
    let ev = 6.241_509_074;
    let h = last.step;
    let period = model.period_us();
    let (mut work, mut loss) = (0.0, 0.0);
    let velocity = |x: &[f64]| x[1] + x[3];
    for (i, pair) in last.states.windows(2).enumerate() {
        let (t0, t1) = (i as f64 * h, (i + 1) as f64 * h);
        let power = |t: f64, x: &[f64]| -model.tip_sample_force(t + 2.0 * period, x) * velocity(x);
        work += 0.5 * h * (power(t0, &pair[0]) + power(t1, &pair[1]));
        let rate = |x: &[f64]| dashpot_rate(&model, model.gap(0.0, x), x[4]);
        loss += 0.5 * h * (rate(&pair[0]) + rate(&pair[1]));
    }
    let (work, loss) = (work * ev, loss * ev);
    assert!(o.dissipated_ev > 0.0);
    assert!(
        (work - o.dissipated_ev).abs() < 1e-5 * o.dissipated_ev,
        "tip work {work} vs dissipated_ev {}",
        o.dissipated_ev
    );
    assert!(
        (loss - o.dissipated_ev).abs() < 1e-5 * o.dissipated_ev,
        "dashpot loss {loss} vs dissipated_ev {}",
        o.dissipated_ev
    );
    assert!(
        o.energy_balance_residual < 1e-9,
        "residual {:e}",
        o.energy_balance_residual
    );
    // The indentation below the unrecovered surface, `s = -h_0 = -(d + rho^{2/3})` (MODEL.md
    // section 10), on the brute-force grid: its largest value (the grid's error about
    // `s'' h^2 / 8`, 1e-6 nm) and its mean over the time in contact (trapezoidal), to 1e-5 and
    // 1e-4 relative.
    let depth = |x: &[f64]| -(model.gap(0.0, x) + x[4].powf(2.0 / 3.0));
    let depths: Vec<f64> = last.states.iter().map(|x| depth(x)).collect();
    let deepest = depths.iter().copied().fold(0.0, f64::max);
    assert!(
        (deepest - o.max_indentation_nm).abs() < 1e-5 * o.max_indentation_nm,
        "deepest {deepest} vs max_indentation_nm {}",
        o.max_indentation_nm
    );
    let (mut indented, mut in_contact) = (0.0, 0.0);
    for pair in depths.windows(2) {
        indented += 0.5 * h * (pair[0].max(0.0) + pair[1].max(0.0));
        in_contact += match (pair[0] > 0.0, pair[1] > 0.0) {
            (true, true) => h,
            (false, false) => 0.0,
            // The crossing by linear interpolation.
            _ => h * pair[0].max(pair[1]) / (pair[0] - pair[1]).abs(),
        };
    }
    let mean = indented / in_contact;
    assert!(
        (mean - o.mean_indentation_nm).abs() < 1e-4 * mean,
        "mean {mean} vs mean_indentation_nm {}",
        o.mean_indentation_nm
    );
    assert!(o.mean_indentation_nm < o.max_indentation_nm);
}

/// G2 (the second impact's onset, on the unrecovered surface) from the diagram against the
/// brute force's bisection in Z: within 1e-7 nm (the bisection's bracket 2e-8 nm plus the
/// brute force's error in the minimum).
#[test]
fn second_impact_grazing_matches_the_brute_force_bisection() {
    let model = model_with(SLS, 9.0);
    let diagram = approach_diagram(&model, &DiagramSettings::approach(&model)).unwrap();
    let g2 = diagram
        .special_points
        .iter()
        .find(|p| p.label == "G2")
        .expect("G2 on the approach");
    assert!(g2.converged);
    let z = grazing_by_bisection(&model, &g2.state, g2.z_nm);
    assert!(
        (z - g2.z_nm).abs() < 1e-7,
        "G2 {} vs brute force {z}",
        g2.z_nm
    );
}

/// `E_0 = E_inf` keeps `rho = 0`: the diagram's grazing points are Hertz's (1 GPa) to 1e-9 nm.
#[test]
fn equal_moduli_reproduce_the_hertz_grazing_points() {
    let sls = model_with(
        r#"{"law": "standard-linear-solid", "instant_modulus_gpa": 1.0, "relaxed_modulus_gpa": 1.0, "relaxation_time_us": 5.0}"#,
        9.0,
    );
    let hertz = model_with(r#"{"law": "hertz"}"#, 9.0);
    hertz_limit::assert_hertz_grazing(&sls, &hertz, 3, 1e-9);
}

/// A regime map of the built-in case over A0 = 9.5 .. 10.5 nm: its G2 curve (the second
/// impact on the unrecovered surface) at the case's own A0 = 10 nm lies at the diagram's point
/// (to 1e-9 nm plus the diagram's bracket), and at A0 = 9.5 nm at that of an independent
/// diagram of the case rebuilt there (1.3 s since contact is stepped by Taylor series; it
/// took 90 s by DOP853 and was ignored by default). The G1 curve stops
/// at the case's value: at first contact the sample is recovered (`rho = 0`), where
/// `h_0 = d + rho^{2/3}` is not differentiable in `rho` (MODEL.md section 9).
#[test]
fn regime_map_follows_the_grazing_points() {
    let case = builtin_case("biolever-soft-viscoelastic").unwrap();
    let model = TappingModel::from_case(&case).unwrap();
    let settings = RegimeMapSettings {
        at: vec![9.5],
        points_per_range: 4,
        ..RegimeMapSettings::new(&model, 9.5, 10.5)
    };
    let map = regime_map(&case, ParameterAxis::FreeAmplitude, &settings).unwrap();
    for a0 in [9.5, 10.0] {
        let rebuilt = ParameterAxis::FreeAmplitude
            .apply(&case, a0, "test")
            .unwrap();
        let at = TappingModel::from_case(&rebuilt).unwrap();
        let diagram = approach_diagram(&at, &DiagramSettings::approach(&at)).unwrap();
        let curve = map.curves.iter().find(|c| c.label == "G2").expect("G2");
        let point = curve
            .points
            .iter()
            .find(|p| p.parameter == a0)
            .unwrap_or_else(|| panic!("G2 at A0 = {a0}"));
        let special = diagram
            .special_points
            .iter()
            .find(|s| s.label == "G2")
            .unwrap();
        assert!(
            (point.z_nm - special.z_nm).abs() <= 1e-9 + special.precision_nm,
            "G2 at A0 = {a0}: map {} vs diagram {}",
            point.z_nm,
            special.z_nm
        );
    }
}

/// Out-of-range and inconsistent moduli are refused naming the file, the field and the range.
#[test]
fn sample_file_checks_the_moduli_and_the_time() {
    let error = |contact: &str| {
        let text =
            format!(r#"{{"name": "test", "youngs_modulus_gpa": 1.0, "contact": {contact}}}"#);
        afm::fixtures::parse_sample("test.json", &text)
            .unwrap_err()
            .to_string()
    };
    let relaxed_above = error(
        r#"{"law": "standard-linear-solid", "instant_modulus_gpa": 1.0, "relaxed_modulus_gpa": 2.0, "relaxation_time_us": 5.0}"#,
    );
    assert!(
        relaxed_above.contains("test.json")
            && relaxed_above.contains("contact.relaxed_modulus_gpa")
            && relaxed_above.contains('1'),
        "{relaxed_above}"
    );
    let time = error(
        r#"{"law": "standard-linear-solid", "instant_modulus_gpa": 1.0, "relaxed_modulus_gpa": 0.5, "relaxation_time_us": 0}"#,
    );
    assert!(time.contains("contact.relaxation_time_us"), "{time}");
    let missing = error(r#"{"law": "standard-linear-solid", "instant_modulus_gpa": 1.0}"#);
    assert!(missing.contains("relaxed_modulus_gpa"), "{missing}");
}
