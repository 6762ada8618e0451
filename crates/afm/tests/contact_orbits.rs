//! Steady orbits and grazing points of the non-Hertz contact laws (MODEL.md section 9) against
//! a brute force written here: fixed-step RK4 on the model's vector field, with each crossing
//! of a switching surface located by bisection of the step and the step split there, a step 64
//! times finer in contact, and the lock-in integrals by the trapezoidal rule on the uniform
//! grid. It shares with drumroll only the field `f_m(t, x)` and the switching functions, not
//! the solver, its event location, Newton or continuation.

use afm::{
    approach_diagram, builtin_cantilever, steady_orbit, DiagramSettings, OrbitStart, Sample,
    Separation, SteadyOrbitSettings, TappingModel,
};
use hybrid::{HybridSystem, Mode};

/// Grid steps per drive period outside contact.
const STEPS_PER_PERIOD: usize = 40_000;

fn model_with(contact: &str, z: f64) -> TappingModel {
    let text = format!(
        r#"{{"name": "test", "youngs_modulus_gpa": 1.0, "poisson_ratio": 0.3, "contact": {contact}}}"#
    );
    let sample: Sample = afm::fixtures::parse_sample("test.json", &text).unwrap();
    let cantilever = builtin_cantilever("biolever").unwrap();
    TappingModel::new(cantilever, sample, 10.0, None, Separation::Constant(z)).unwrap()
}

fn rk4_step(model: &TappingModel, mode: Mode, t: f64, x: &[f64], h: f64, out: &mut [f64]) {
    let n = x.len();
    let (mut k1, mut k2, mut k3, mut k4) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut y = vec![0.0; n];
    model.vector_field(mode, t, x, &mut k1);
    for i in 0..n {
        y[i] = x[i] + 0.5 * h * k1[i];
    }
    model.vector_field(mode, t + 0.5 * h, &y, &mut k2);
    for i in 0..n {
        y[i] = x[i] + 0.5 * h * k2[i];
    }
    model.vector_field(mode, t + 0.5 * h, &y, &mut k3);
    for i in 0..n {
        y[i] = x[i] + h * k3[i];
    }
    model.vector_field(mode, t + h, &y, &mut k4);
    for i in 0..n {
        out[i] = x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

/// Advance `(t, x, mode)` by `h` in RK4 substeps (64 of them in contact), splitting a substep
/// at every switching-surface crossing found by bisection on its length (to 1e-15 periods).
fn advance(model: &TappingModel, mode: &mut Mode, t: &mut f64, x: &mut [f64], h: f64, period: f64) {
    let end = *t + h;
    let mut next = vec![0.0; x.len()];
    while *t < end - 1e-12 * period {
        let sub = if *mode & 1 != 0 { h / 64.0 } else { h };
        let step = sub.min(end - *t);
        rk4_step(model, *mode, *t, x, step, &mut next);
        let landed = model.mode_of(*t + step, &next);
        if landed == *mode {
            x.copy_from_slice(&next);
            *t += step;
            continue;
        }
        // Bisect for the first time the mode changes.
        let (mut lo, mut hi) = (0.0, step);
        while hi - lo > 1e-15 * period {
            let mid = 0.5 * (lo + hi);
            rk4_step(model, *mode, *t, x, mid, &mut next);
            if model.mode_of(*t + mid, &next) == *mode {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        rk4_step(model, *mode, *t, x, hi, &mut next);
        x.copy_from_slice(&next);
        *t += hi;
        *mode = model.mode_of(*t, x);
    }
    *t = end;
}

/// Integrate `periods` drive periods from `x0` at t = 0; return the last period's A/A0 and
/// phase (deg) of u, and the local minima of `h_0 = d - d_c` over it (parabola through the
/// three grid points around each).
fn brute_force(model: &TappingModel, x0: &[f64], periods: usize) -> (f64, f64, Vec<f64>) {
    let period = model.period_us();
    let w = model.drive_angular_frequency();
    let h = period / STEPS_PER_PERIOD as f64;
    let mut x = x0.to_vec();
    let mut t = 0.0;
    let mut mode = model.mode_of(0.0, &x);
    let (mut a, mut b) = (0.0, 0.0);
    let mut heights = Vec::with_capacity(STEPS_PER_PERIOD + 1);
    for p in 0..periods {
        let last = p + 1 == periods;
        for i in 0..STEPS_PER_PERIOD {
            if last {
                let u = model.photodiode(&x);
                let tk = i as f64 * h;
                a += u * (w * tk).cos();
                b += u * (w * tk).sin();
                heights.push(model.switching(0, t, &x));
            }
            advance(model, &mut mode, &mut t, &mut x, h, period);
        }
    }
    heights.push(model.switching(0, t, &x));
    let scale = 2.0 / STEPS_PER_PERIOD as f64;
    let ratio = scale * a.hypot(b) / model.free_amplitude_nm();
    let phase = b.atan2(a).to_degrees();
    let minima = heights
        .windows(3)
        .filter(|w| w[1] < w[0] && w[1] <= w[2])
        .map(|w| w[1] - (w[2] - w[0]).powi(2) / (8.0 * (w[0] - 2.0 * w[1] + w[2])))
        .collect();
    (ratio, phase, minima)
}

fn check_orbit(contact: &str, z: f64) {
    let model = model_with(contact, z);
    let settings = SteadyOrbitSettings::default();
    let orbit = steady_orbit(&model, z, OrbitStart::Approach, &settings).unwrap();
    assert!(orbit.converged && orbit.multiplicity == 1, "{contact}");
    let observables = orbit.observables();
    let (ratio, phase, _) = brute_force(&model, &orbit.state, 3);
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
    let nearest = |z: f64| {
        let mut at = model.clone();
        at.set_separation(Separation::Constant(z)).unwrap();
        let (_, _, minima) = brute_force(&at, &g2.state, 12);
        minima
            .into_iter()
            .min_by(|a, b| a.abs().total_cmp(&b.abs()))
            .unwrap()
    };
    let (mut below, mut above) = (g2.z_nm - 2e-3, g2.z_nm + 2e-3);
    assert!(nearest(below) < 0.0 && nearest(above) > 0.0);
    while above - below > 2e-8 {
        let mid = 0.5 * (below + above);
        if nearest(mid) < 0.0 {
            below = mid;
        } else {
            above = mid;
        }
    }
    let z = 0.5 * (below + above);
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
