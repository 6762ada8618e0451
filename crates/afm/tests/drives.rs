//! Acoustic (base) and bimodal drives (MODEL.md section 14).
//!
//! The references are written here, independently of the model's code: the base participation
//! factors of the Euler-Bernoulli cantilever from its characteristic equation, the free steady
//! state from the modes' complex transfer functions, and a classical fixed-step RK4 of the
//! equations of section 14 (inertial forcing in the base's frame, base motion in the gap, Hertz
//! contact with the reduced modulus typed in) over one (common) period, sampled for the lock-in
//! at both frequencies.

mod common;

use std::f64::consts::PI;

use afm::model::drive_spec::DriveSpec;
use afm::{
    approach_diagram, builtin_case, steady_orbit, DiagramSettings, OrbitStart, Separation,
    SteadyOrbit, SteadyOrbitSettings, TappingModel,
};
use nalgebra::Complex;

/// `w = 2 pi f / 1000`, rad/us, for `f` in kHz.
fn angular(frequency_khz: f64) -> f64 {
    2.0 * PI * frequency_khz / 1000.0
}

/// The Biolever's modes `(k, f, Q, chi, r)`, typed in (MODEL.md section 6).
const BIOLEVER: [(f64, f64, f64, f64, f64); 2] =
    [(0.036, 9.3, 1.2, 1.0, 1.0), (1.4, 72.0, 2.0, 3.47, -0.554)];

/// `H_i(w) = (1/k_i) / (1 - (w/w_i)^2 + i (w/w_i)/Q_i)`, nm/nN.
fn transfer(mode: (f64, f64, f64, f64, f64), w: f64) -> Complex<f64> {
    let r = w / angular(mode.1);
    Complex::new(1.0 - r * r, r / mode.2).inv() / mode.0
}

/// The clamped-free beam's `gamma_n = 4 sigma_n / beta_n (-1)^{n+1}` (modes normalised to unit
/// tip deflection, no tip mass), `beta_n` the n-th root of `1 + cos b cosh b = 0` by bisection
/// and `sigma_n = (sinh b - sin b) / (cosh b + cos b)`.
fn beam_gamma(n: usize) -> f64 {
    let f = |b: f64| 1.0 + b.cos() * b.cosh();
    let centre = (n as f64 - 0.5) * PI;
    let (mut lo, mut hi) = (centre - 0.6, centre + 0.6);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(lo) * f(mid) <= 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let b = 0.5 * (lo + hi);
    let sigma = (b.sinh() - b.sin()) / (b.cosh() + b.cos());
    let sign = if n % 2 == 1 { 1.0 } else { -1.0 };
    4.0 * sigma / b * sign
}

/// Hertz's coefficient `(4/3) E* sqrt(R)` of the Biolever's tip (130 GPa, R = 30 nm) on mica
/// (60 GPa), every Poisson ratio 0.3 (MODEL.md section 1).
fn hertz_coefficient() -> f64 {
    let reduced = 1.0 / ((1.0 - 0.09) / 60.0 + (1.0 - 0.09) / 130.0);
    4.0 / 3.0 * reduced * 30f64.sqrt()
}

/// The drive of the reference equations: mode `i` is forced by `sum_j f[j][i] cos(w_j t)` (nN)
/// and the gap holds `Y cos(w_0 t)`.
struct Reference {
    /// `(w_j, force on each mode)` per drive frequency.
    drives: Vec<(f64, Vec<f64>)>,
    /// The base amplitude `Y` (at the first drive's frequency), nm.
    base: f64,
    z: f64,
}

impl Reference {
    /// Eq. 1 of MODEL.md section 14 in the base's frame, with Hertz contact.
    fn field(&self, t: f64, x: &[f64], dxdt: &mut [f64]) {
        let w0 = self.drives[0].0;
        let gap = self.z + self.base * (w0 * t).cos() + x[0] + x[2];
        let force = if gap < 0.0 {
            hertz_coefficient() * (-gap).powf(1.5)
        } else {
            0.0
        };
        for (i, mode) in BIOLEVER.iter().enumerate() {
            let wi = angular(mode.1);
            let drive: f64 = self.drives.iter().map(|(w, f)| f[i] * (w * t).cos()).sum();
            dxdt[2 * i] = x[2 * i + 1];
            dxdt[2 * i + 1] =
                wi * wi * ((drive + force) / mode.0 - x[2 * i]) - wi / mode.2 * x[2 * i + 1];
        }
    }

    /// RK4 over `[0, period]` in `steps` steps from `x0`: the end state, and the first harmonic
    /// `[a, b]` of `u` at each drive frequency (rectangle rule on the steps' starts, exact for
    /// trigonometric polynomials; the kinks of contact make it converge as the step), and
    /// `int F_ts y_base' dt` (nN nm).
    fn period(&self, x0: &[f64], period: f64, steps: usize) -> (Vec<f64>, Vec<[f64; 2]>, f64) {
        let h = period / steps as f64;
        let mut x = x0.to_vec();
        let mut harmonics = vec![[0.0, 0.0]; self.drives.len()];
        let mut base_work = 0.0;
        let w0 = self.drives[0].0;
        for step in 0..steps {
            let t = step as f64 * h;
            let u = x[0] + BIOLEVER[1].3 * x[2];
            for ((w, _), harmonic) in self.drives.iter().zip(harmonics.iter_mut()) {
                harmonic[0] += 2.0 / steps as f64 * u * (w * t).cos();
                harmonic[1] += 2.0 / steps as f64 * u * (w * t).sin();
            }
            let gap = self.z + self.base * (w0 * t).cos() + x[0] + x[2];
            if gap < 0.0 {
                base_work +=
                    h * hertz_coefficient() * (-gap).powf(1.5) * (-w0 * self.base * (w0 * t).sin());
            }
            x = common::rk4(|t, x, dx| self.field(t, x, dx), t, &x, h, 1);
        }
        (x, harmonics, base_work)
    }
}

/// The model of built-in case `name` with its drive made acoustic (the beam's participation
/// factors).
fn driven_acoustically(name: &str) -> TappingModel {
    let mut case = builtin_case(name).expect("case");
    case.drive = DriveSpec::Acoustic {
        base_participation: None,
    };
    TappingModel::from_case(&case).expect("model")
}

fn converged_orbit(model: &TappingModel, z: f64) -> SteadyOrbit {
    let orbit = steady_orbit(
        model,
        z,
        OrbitStart::Approach,
        &SteadyOrbitSettings::default(),
    )
    .expect("orbit");
    assert!(orbit.converged, "orbit at Z = {z} did not converge");
    orbit
}

fn at(model: &TappingModel, z: f64) -> TappingModel {
    let mut model = model.clone();
    model
        .set_separation(Separation::Constant(z))
        .expect("separation");
    model
}

/// The acoustic Biolever's free orbit is the analytic steady state of the base-driven modes:
/// the participation factors are the beam's (1e-9), `Y` solves `A0` (1e-12), the free phase
/// (1e-9 deg), the first-contact separation `Z_G1 = -min(Y cos + sum q)` (1e-9 nm), and a
/// steady orbit far above the sample reads `A / A0 = 1` (1e-9) at that phase (1e-6 deg).
#[test]
fn acoustic_free_orbit_is_the_analytic_base_driven_steady_state() {
    let model = TappingModel::from_case(&builtin_case("biolever-mica-acoustic").expect("case"))
        .expect("model");
    let base = model.base_motion().expect("acoustic drive");
    for (n, gamma) in base.participation.iter().enumerate() {
        assert!(
            (gamma - beam_gamma(n + 1)).abs() < 1e-9,
            "gamma_{}: {gamma} vs {}",
            n + 1,
            beam_gamma(n + 1)
        );
    }
    let w = angular(9.3);
    // The inertial force per nm of base motion on mode i: k_i gamma_i (w / w_i)^2.
    let per_nm: Vec<f64> = BIOLEVER
        .iter()
        .enumerate()
        .map(|(i, m)| m.0 * beam_gamma(i + 1) * (w / angular(m.1)).powi(2))
        .collect();
    let gain: Complex<f64> = BIOLEVER
        .iter()
        .zip(&per_nm)
        .map(|(m, f)| transfer(*m, w) * (m.3 * f))
        .sum();
    let y = 10.0 / gain.norm();
    assert!(
        (base.amplitude_nm - y).abs() < 1e-12 * y,
        "Y = {} vs {y}",
        base.amplitude_nm
    );
    let phase = (-gain.arg()).to_degrees();
    assert!((model.free_phase_deg() - phase).abs() < 1e-9);

    // The lowest free gap: golden-section refinement of the densest sample.
    let q: Vec<Complex<f64>> = BIOLEVER
        .iter()
        .zip(&per_nm)
        .map(|(m, f)| transfer(*m, w) * f * y)
        .collect();
    let gap = |t: f64| {
        let e = Complex::new(0.0, w * t).exp();
        y * (w * t).cos() + q.iter().map(|qi| (qi * e).re).sum::<f64>()
    };
    let period = 2.0 * PI / w;
    let samples = 4096;
    let best = (0..samples)
        .map(|j| period * j as f64 / samples as f64)
        .min_by(|a, b| gap(*a).total_cmp(&gap(*b)))
        .expect("samples");
    let (mut lo, mut hi) = (
        best - period / samples as f64,
        best + period / samples as f64,
    );
    for _ in 0..200 {
        let (m1, m2) = (lo + (hi - lo) * 0.382, lo + (hi - lo) * 0.618);
        if gap(m1) < gap(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    let z_g1 = -gap(0.5 * (lo + hi));
    assert!(
        (model.grazing_separation_nm() - z_g1).abs() < 1e-9,
        "Z_G1 {} vs {z_g1}",
        model.grazing_separation_nm()
    );

    let far = z_g1 + 5.0;
    let orbit = converged_orbit(&at(&model, far), far);
    let (ratio, orbit_phase) = orbit.lockin(10.0);
    assert!((ratio - 1.0).abs() < 1e-9, "A/A0 {ratio}");
    assert!(
        (orbit_phase - phase).abs() < 1e-6,
        "{orbit_phase} vs {phase}"
    );
}

/// The acoustic Biolever tapping mica at 0.7 `Z_G1` (base motion in the gap): the steady
/// orbit is a fixed point of the RK4 reference's period map (1e-6 nm, 1e-6 nm/us at 2^17
/// steps), with its amplitude (1e-6 of `A0`) and phase (1e-4 deg); on this conservative law the
/// dissipated energy, which holds the base's work `int F_ts y_base' dt` (4.4 eV per period
/// here, so that leaving it out would fail), vanishes to 1e-9 eV; the energy balance closes to
/// 1e-9.
#[test]
fn acoustic_tapping_orbit_matches_brute_force() {
    let model = TappingModel::from_case(&builtin_case("biolever-mica-acoustic").expect("case"))
        .expect("model");
    let z = 0.7 * model.grazing_separation_nm();
    let model = at(&model, z);
    let orbit = converged_orbit(&model, z);
    assert_eq!(orbit.multiplicity, 1);
    let base = model.base_motion().expect("acoustic drive").amplitude_nm;
    let w = angular(9.3);
    let forces: Vec<f64> = BIOLEVER
        .iter()
        .enumerate()
        .map(|(i, m)| m.0 * beam_gamma(i + 1) * (w / angular(m.1)).powi(2) * base)
        .collect();
    let reference = Reference {
        drives: vec![(w, forces)],
        base,
        z,
    };
    let (end, harmonics, base_work) = reference.period(&orbit.state, 2.0 * PI / w, 1 << 17);
    for (i, (a, b)) in end.iter().zip(&orbit.state).enumerate() {
        assert!((a - b).abs() < 1e-6, "state[{i}]: {a} vs {b}");
    }
    let [a, b] = harmonics[0];
    let observables = orbit.observables();
    assert!(observables.impacts_per_period >= 1.0);
    assert!((a.hypot(b) - observables.amplitude_nm).abs() < 1e-5);
    assert!((b.atan2(a).to_degrees() - observables.phase_deg).abs() < 1e-4);
    let base_work_ev = base_work * afm::NN_NM_IN_EV;
    assert!(base_work_ev.abs() > 1.0, "base work {base_work_ev} eV");
    assert!(
        observables.dissipated_ev.abs() < 1e-9,
        "E_ts {}",
        observables.dissipated_ev
    );
    assert!(observables.energy_balance_residual < 1e-9);
}

/// Under an acoustic drive the standard linear solid's balance closes: the work done on the
/// sample along the whole gap (the modes' shares, less the base's work and `Z' int F`) is the
/// dashpot's loss plus the change of the stored energy, both functions of the gap with the base
/// motion in it (MODEL.md sections 10 and 14). At 0.7 `Z_G1` of the Biolever on the
/// `soft-viscoelastic` sample the base does several eV a period, so leaving its work out of the
/// balance shows as a residual of order 0.1 of the damping; closed, it is the quadrature's,
/// below 1e-9 (as on every orbit); the sample dissipates (`dissipated_ev` > 0.01 eV).
#[test]
fn acoustic_drive_over_a_standard_linear_solid_closes_the_sample_balance() {
    let model = driven_acoustically("biolever-soft-viscoelastic");
    let z = 0.7 * model.grazing_separation_nm();
    let model = at(&model, z);
    let orbit = converged_orbit(&model, z);
    let observables = orbit.observables();
    assert!(observables.impacts_per_period >= 1.0);
    assert!(
        observables.base_work_ev.abs() > 1.0,
        "base work {} eV",
        observables.base_work_ev
    );
    assert!(
        observables.energy_balance_residual < 1e-9,
        "residual {:e}",
        observables.energy_balance_residual
    );
    assert!(
        observables.dissipated_ev > 0.01,
        "E_ts {}",
        observables.dissipated_ev
    );
}

/// The acoustic contact is stepped by Taylor series (the gap affine in the state with the base
/// motion's series, MODEL.md section 14), and the monodromy they carry over one period of the
/// steady orbit at 0.9 `Z_G1` agrees with central differences (step 1e-5 nm, nm/us) of the
/// state-only period map integrated by DOP853 alone at tolerance 1e-14, to 1e-7 (measured:
/// 3e-9; the differences' own error is about 1e-9).
#[test]
fn acoustic_contact_by_series_matches_finite_difference_monodromy() {
    use hybrid::{Sensitivity, Solver};
    let model = TappingModel::from_case(&builtin_case("biolever-mica-acoustic").expect("case"))
        .expect("model");
    let z = 0.9 * model.grazing_separation_nm();
    let model = at(&model, z);
    let orbit = converged_orbit(&model, z);
    let settings = SteadyOrbitSettings::default().integration;
    let period = model.period_us();
    let run = |x0: &[f64], sensitivity: Sensitivity, settings: &hybrid::Settings| {
        let mut solver =
            Solver::new(&model, 0.0, x0, sensitivity, settings.clone()).expect("solver");
        while solver.t() < period {
            solver.step(period).expect("step");
        }
        let transition = match sensitivity {
            Sensitivity::None => Vec::new(),
            _ => solver.transition().as_slice().to_vec(),
        };
        (
            solver.state().to_vec(),
            transition,
            solver.statistics().series_steps,
        )
    };
    let (_, monodromy, series_steps) = run(&orbit.state, Sensitivity::Transition, &settings);
    assert!(orbit.observables().impacts_per_period >= 1.0);
    assert!(series_steps > 0, "no Taylor-series step in contact");
    let mut tight = settings.clone();
    tight.taylor_series = false;
    tight.relative_tolerance = 1e-14;
    tight.absolute_tolerance = 1e-14;
    let n = orbit.state.len();
    let h = 1e-5;
    for j in 0..n {
        let (mut above, mut below) = (orbit.state.clone(), orbit.state.clone());
        above[j] += h;
        below[j] -= h;
        let (end_above, ..) = run(&above, Sensitivity::None, &tight);
        let (end_below, ..) = run(&below, Sensitivity::None, &tight);
        for i in 0..n {
            let difference = (end_above[i] - end_below[i]) / (2.0 * h);
            let series = monodromy[i + n * j];
            assert!(
                (series - difference).abs() < 1e-7,
                "M[{i}][{j}]: {series} vs {difference}"
            );
        }
    }
}

/// An acoustic drive over a force acting outside contact (the hydration force of
/// `mica-hydration`): the diagram down to `A/A0 = 0.7` locates G1 and G2 (converged, bracketed
/// to 1e-9 nm) and every point closes its energy balance to 1e-9. (Before the gap's time part
/// had its series, G1 and G2 stayed unlocated, bracketed to 1.7e-4 and 1.9e-6 nm, and the whole
/// diagram took 29 times as long.)
#[test]
fn acoustic_drive_over_the_hydration_force_locates_its_grazings() {
    let model = driven_acoustically("biolever-mica-hydration");
    let mut settings = DiagramSettings::approach(&model);
    settings.min_amplitude_ratio = 0.7;
    let diagram = approach_diagram(&model, &settings).expect("diagram");
    assert!(diagram.completed, "{}", diagram.stop);
    for label in ["G1", "G2"] {
        let point = diagram
            .special_points
            .iter()
            .find(|p| p.label == label)
            .unwrap_or_else(|| panic!("no {label}"));
        assert!(
            point.converged && point.precision_nm < 1e-9,
            "{label} at {}: converged {}, bracket {} nm",
            point.z_nm,
            point.converged,
            point.precision_nm
        );
    }
    for point in &diagram.points {
        assert!(
            point.energy_balance_residual < 1e-9,
            "residual {} at Z = {}",
            point.energy_balance_residual,
            point.z_nm
        );
    }
}

/// A bimodal drive with `A0_b = 0` is the single drive: at ratio 15/2 the model's period is two
/// drive periods, `Z_G1` is the same (1e-12 nm), and the steady orbit at 0.7 `Z_G1` has the
/// single drive's state, `A / A0`, phase, impacts and peak force per period (1e-9).
#[test]
fn bimodal_with_zero_second_amplitude_is_the_single_drive() {
    let single =
        TappingModel::from_case(&builtin_case("biolever-mica").expect("case")).expect("model");
    let mut case = builtin_case("biolever-mica").expect("case");
    case.drive = DriveSpec::Bimodal {
        second_frequency_khz: 9.3 * 7.5,
        second_free_amplitude_nm: 0.0,
    };
    let bimodal = TappingModel::from_case(&case).expect("model");
    assert!((bimodal.period_us() - 2.0 * single.period_us()).abs() < 1e-12);
    assert!((bimodal.grazing_separation_nm() - single.grazing_separation_nm()).abs() < 1e-12);
    let z = 0.7 * single.grazing_separation_nm();
    let one = converged_orbit(&at(&single, z), z);
    let two = converged_orbit(&at(&bimodal, z), z);
    for (a, b) in one.state.iter().zip(&two.state) {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }
    let (o1, o2) = (one.observables(), two.observables());
    assert!((o1.amplitude_ratio - o2.amplitude_ratio).abs() < 1e-9);
    assert!((o1.phase_deg - o2.phase_deg).abs() < 1e-9);
    assert_eq!(o1.impacts_per_period * 2.0, o2.impacts_per_period);
    assert!((o1.peak_force_nn - o2.peak_force_nn).abs() < 1e-9 * o1.peak_force_nn);
    assert!(o2.second_drive.expect("bimodal").amplitude_nm < 1e-9);
}

/// A bimodal Biolever (a second drive at 15/2 `f_1` = 69.75 kHz, `A0_b` = 2 nm) tapping mica
/// at 0.8 `Z_G1`: the steady orbit of the common period `2 T` is a fixed point of the RK4
/// reference (1e-6), which gives the amplitude and phase of `u` at both frequencies (1e-5 nm,
/// 1e-4 deg); far from the sample the second reading is `A0_b` (1e-9); the energy balance,
/// whose drive work holds both drives, closes to 1e-9.
#[test]
fn bimodal_tapping_orbit_matches_brute_force() {
    let mut case = builtin_case("biolever-mica").expect("case");
    let fb = 9.3 * 7.5;
    case.drive = DriveSpec::Bimodal {
        second_frequency_khz: fb,
        second_free_amplitude_nm: 2.0,
    };
    let model = TappingModel::from_case(&case).expect("model");
    let (w, wb) = (angular(9.3), angular(fb));
    let gain = |w: f64| -> f64 {
        BIOLEVER
            .iter()
            .map(|m| transfer(*m, w) * (m.3 * m.4))
            .sum::<Complex<f64>>()
            .norm()
    };
    let (f1, f1b) = (10.0 / gain(w), 2.0 / gain(wb));
    let far = model.grazing_separation_nm() + 5.0;
    let free = converged_orbit(&at(&model, far), far);
    let second = free.observables().second_drive.expect("bimodal");
    assert!((second.amplitude_nm - 2.0).abs() < 1e-9, "{second:?}");
    assert!((free.observables().amplitude_ratio - 1.0).abs() < 1e-9);

    let z = 0.8 * model.grazing_separation_nm();
    let orbit = converged_orbit(&at(&model, z), z);
    let reference = Reference {
        drives: vec![
            (w, BIOLEVER.iter().map(|m| m.4 * f1).collect()),
            (wb, BIOLEVER.iter().map(|m| m.4 * f1b).collect()),
        ],
        base: 0.0,
        z,
    };
    let period = model.period_us();
    assert!((period - 4.0 * PI / w).abs() < 1e-12);
    let (end, harmonics, _) = reference.period(&orbit.state, period, 1 << 18);
    for (i, (a, b)) in end.iter().zip(&orbit.state).enumerate() {
        assert!((a - b).abs() < 1e-6, "state[{i}]: {a} vs {b}");
    }
    let observables = orbit.observables();
    assert!(observables.impacts_per_period >= 1.0);
    let second = observables.second_drive.expect("bimodal");
    for ([a, b], (amplitude, phase)) in harmonics.iter().zip([
        (observables.amplitude_nm, observables.phase_deg),
        (second.amplitude_nm, second.phase_deg),
    ]) {
        assert!((a.hypot(*b) - amplitude).abs() < 1e-5, "{amplitude}");
        assert!((b.atan2(*a).to_degrees() - phase).abs() < 1e-4, "{phase}");
    }
    assert!(observables.energy_balance_residual < 1e-9);
}

/// A diagram through each drive: the approach branch of the acoustic and of the bimodal
/// built-in case starts at first contact, locates its `G1` at the free orbit's `Z_G1` (1e-9
/// nm: the located grazing against the closed form with the base motion or both drives), finds
/// the double-impact onset `G2` below it, and closes the energy balance at every point (1e-9).
#[test]
fn diagrams_through_acoustic_and_bimodal_drives() {
    for name in ["biolever-mica-acoustic", "biolever-mica-bimodal"] {
        let model = TappingModel::from_case(&builtin_case(name).expect("case")).expect("model");
        let mut settings = DiagramSettings::approach(&model);
        settings.min_amplitude_ratio = 0.7;
        let diagram = approach_diagram(&model, &settings).expect("diagram");
        assert!(diagram.completed, "{name}: {}", diagram.stop);
        let g1 = diagram
            .special_points
            .iter()
            .find(|p| p.label == "G1")
            .unwrap_or_else(|| panic!("{name}: no G1"));
        assert!(
            (g1.z_nm - model.grazing_separation_nm()).abs() < 1e-9,
            "{name}: G1 at {} vs Z_G1 {}",
            g1.z_nm,
            model.grazing_separation_nm()
        );
        assert!(
            diagram
                .special_points
                .iter()
                .any(|p| p.label == "G2" && p.z_nm < g1.z_nm),
            "{name}: no G2"
        );
        for point in &diagram.points {
            assert!(
                point.energy_balance_residual < 1e-9,
                "{name}: residual {} at Z = {}",
                point.energy_balance_residual,
                point.z_nm
            );
        }
    }
}

/// An incommensurate second frequency is refused, the error naming the file, the field and the
/// nearest commensurate frequencies, and so is the first drive's own frequency; a wrong number of participation factors and an unknown
/// drive kind name the field.
#[test]
fn bad_drives_are_refused_with_the_field_and_the_choices() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let load = |drive: &str| {
        let path = directory.path().join("case.json");
        let text = format!(
            r#"{{"name": "x", "cantilever": "biolever", "sample": "mica",
                "free_amplitude_nm": 10, "drive": {drive}}}"#
        );
        std::fs::write(&path, text).expect("case file");
        afm::load_case(&path).map(|_| ()).map_err(|e| e.to_string())
    };
    let error = load(
        r#"{"kind": "bimodal", "second_frequency_khz": 72.0436, "second_free_amplitude_nm": 1}"#,
    )
    .expect_err("incommensurate");
    assert!(error.contains("drive.second_frequency_khz"), "{error}");
    assert!(error.contains("case.json"), "{error}");
    // 72.0436 / 9.3 = 7.7466...: the nearest p/q with q <= 16 is 31/4 (72.075 kHz).
    assert!(error.contains("72.075 kHz (ratio 31/4)"), "{error}");
    // The first drive's own frequency (ratio 1/1) is refused, saying why.
    let error =
        load(r#"{"kind": "bimodal", "second_frequency_khz": 9.3, "second_free_amplitude_nm": 1}"#)
            .expect_err("the same frequency");
    assert!(error.contains("drive.second_frequency_khz"), "{error}");
    assert!(error.contains("other than the drive's 9.3 kHz"), "{error}");
    let error = load(r#"{"kind": "acoustic", "base_participation": [1.5]}"#)
        .expect_err("one factor for two modes");
    assert!(error.contains("drive.base_participation"), "{error}");
    let error = load(r#"{"kind": "magnetic"}"#).expect_err("unknown kind");
    assert!(error.contains("drive"), "{error}");
    assert!(load(r#"{"kind": "acoustic", "base_participation": [1.5, -0.9]}"#).is_ok());
    assert!(load(
        r#"{"kind": "bimodal", "second_frequency_khz": 74.4, "second_free_amplitude_nm": 1}"#
    )
    .is_ok());
}
