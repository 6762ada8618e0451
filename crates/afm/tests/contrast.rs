//! The observables of contrast (MODEL.md section 10): the energy dissipated in the sample, the
//! virial, the indentation, the energy balance of every mode, and the higher harmonics of `u`.
//!
//! The references are independent of the observer's quadrature: the energy balance itself
//! (the drive's work, the damping loss and the dissipation are three separate integrals), the
//! conservative laws' zero dissipation, the single-mode identity between phase, amplitude and
//! dissipation (its drive work from the first harmonic alone), and a discrete Fourier transform
//! and rectangle rules written here on a trajectory sampled at 2^16 points per period.

use afm::{
    builtin_cantilever, builtin_case, case_names, sample_trajectory, steady_orbit, OrbitStart,
    Sample, Separation, SteadyOrbit, SteadyOrbitSettings, TappingModel,
};
use hybrid::Settings;

/// The Biolever (both modes, or only the first) on a 1 GPa sample with the `contact` object
/// `contact`, at separation `z` (nm).
fn model_with(contact: &str, z: f64, modes: usize) -> TappingModel {
    let text = format!(
        r#"{{"name": "test", "youngs_modulus_gpa": 1.0, "poisson_ratio": 0.3, "contact": {contact}}}"#
    );
    let sample: Sample = afm::fixtures::parse_sample("test.json", &text).expect("sample");
    let mut cantilever = builtin_cantilever("biolever").expect("cantilever");
    cantilever.modes.truncate(modes);
    TappingModel::new(cantilever, sample, 10.0, None, Separation::Constant(z)).expect("model")
}

/// The orbit of the quasi-static approach at `model`'s separation, converged.
fn orbit(model: &TappingModel) -> SteadyOrbit {
    let z = model.separation().at(0.0);
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

/// Every law of MODEL.md section 9 (and a double layer), each at a separation where it taps.
const LAWS: [(&str, &str, f64); 8] = [
    ("hertz sphere", r#"{"law": "hertz"}"#, 8.5),
    (
        "hertz cone",
        r#"{"law": "hertz", "tip_shape": "cone", "cone_half_angle_deg": 20}"#,
        8.5,
    ),
    (
        "hertz flat punch",
        r#"{"law": "hertz", "tip_shape": "flat-punch", "punch_radius_nm": 5}"#,
        8.5,
    ),
    (
        "dmt",
        r#"{"law": "dmt", "hamaker_constant_j": 5e-22, "intermolecular_distance_nm": 0.165}"#,
        8.5,
    ),
    (
        "kelvin-voigt clipped",
        r#"{"law": "kelvin-voigt", "viscosity_pa_s": 100}"#,
        8.5,
    ),
    (
        "kelvin-voigt unclipped",
        r#"{"law": "kelvin-voigt", "viscosity_pa_s": 100, "clip": false}"#,
        8.5,
    ),
    ("film", r#"{"law": "film", "thickness_nm": 6}"#, 8.5),
    (
        "hertz with a double layer",
        r#"{"law": "hertz"}, "electrostatic": {"tip_charge_c_per_m2": 0.02, "sample_charge_c_per_m2": 0.02, "debye_length_nm": 1.0, "relative_permittivity": 80}"#,
        8.5,
    ),
];

/// The energy balance closes to 1e-9 of the damping loss on the orbit of every built-in case
/// (at 0.7 `Z_G1`, tapping) and of every contact law, and on every period of each.
#[test]
fn energy_balance_closes_on_every_case_and_law() {
    let mut checked = Vec::new();
    for name in case_names() {
        let case = builtin_case(name).expect("case");
        let mut model = TappingModel::from_case(&case).expect("model");
        let z = 0.7 * model.grazing_separation_nm();
        model
            .set_separation(Separation::Constant(z))
            .expect("separation");
        checked.push((name.to_string(), model.mode_count(), orbit(&model)));
    }
    for (name, contact, z) in LAWS {
        checked.push((name.to_string(), 2, orbit(&model_with(contact, z, 2))));
    }
    for (name, modes, orbit) in &checked {
        let whole = orbit.observables();
        assert!(!whole.impacts.is_empty(), "{name}: no contact");
        assert!(
            whole.energy_balance_residual < 1e-9,
            "{name}: residual {:e} ({:?})",
            whole.energy_balance_residual,
            whole.mode_energy
        );
        for period in &orbit.periods {
            assert!(period.energy_balance_residual < 1e-9, "{name}");
        }
        assert_eq!(whole.mode_energy.len(), *modes, "{name}");
        // The shares add up to the dissipation (and, under an acoustic drive, the contact
        // force's work on the moving base, MODEL.md section 14).
        let shares: f64 = whole
            .mode_energy
            .iter()
            .map(|m| m.dissipated_share_ev)
            .sum();
        // A conservative law's `dissipated_ev` is its energy's change, the shares quadratures:
        // they agree to the quadrature's accuracy, 1e-12 of the drive's work (the balance's
        // scale, as for the residual).
        let total = whole.dissipated_ev + whole.base_work_ev;
        let scale: f64 = whole
            .mode_energy
            .iter()
            .map(|m| m.drive_work_ev.abs())
            .sum();
        assert!(
            (shares - total).abs() <= 1e-12 * scale + 1e-14 * shares.abs().max(1.0),
            "{name}: shares {shares:e} eV against {total:e} eV (scale {scale:e} eV)"
        );
    }
}

/// A period-2 orbit (the Biolever driven at 40 kHz, where its tapping orbits are
/// subharmonic: one impact every two periods) closes its energy balance over its two periods
/// and over each, on mica (Hertz) and on a Kelvin-Voigt sample; the dissipation per period is
/// the mean of its two periods' (the per-period breakdown), all of it in the period with the
/// impact.
#[test]
fn energy_balance_closes_on_a_period_2_orbit() {
    let sample = afm::fixtures::parse_sample(
        "kv.json",
        r#"{"name": "kv", "youngs_modulus_gpa": 1.0, "poisson_ratio": 0.3,
            "contact": {"law": "kelvin-voigt", "viscosity_pa_s": 100}}"#,
    )
    .expect("sample");
    for sample in [afm::builtin_sample("mica").expect("mica"), sample] {
        let cantilever = builtin_cantilever("biolever").expect("cantilever");
        let model = TappingModel::new(
            cantilever,
            sample,
            10.0,
            Some(PERIOD_2_DRIVE_KHZ),
            Separation::Constant(PERIOD_2_Z_NM),
        )
        .expect("model");
        let orbit = steady_orbit(
            &model,
            PERIOD_2_Z_NM,
            OrbitStart::Transient,
            &SteadyOrbitSettings::default(),
        )
        .expect("orbit");
        assert!(orbit.converged);
        assert_eq!(orbit.multiplicity, 2);
        let whole = orbit.observables();
        assert_eq!(whole.impacts.len(), 1);
        assert!(
            whole.energy_balance_residual < 1e-9,
            "{:e}",
            whole.energy_balance_residual
        );
        for period in &orbit.periods {
            assert!(period.energy_balance_residual < 1e-9);
        }
        let mean: f64 = orbit.periods.iter().map(|p| p.dissipated_ev).sum::<f64>() / 2.0;
        assert!(
            (mean - whole.dissipated_ev).abs() < 1e-12 + 1e-9 * mean.abs(),
            "{mean} vs {}",
            whole.dissipated_ev
        );
        let breakdown = orbit.period_breakdown(model.free_amplitude_nm());
        for (period, observables) in breakdown.iter().zip(&orbit.periods) {
            assert_eq!(period.dissipated_ev, observables.dissipated_ev);
            assert_eq!(period.max_indentation_nm, observables.max_indentation_nm);
        }
    }
}

/// The drive frequency (kHz) and separation (nm) of the period-2 orbit of the Biolever.
const PERIOD_2_DRIVE_KHZ: f64 = 40.0;
const PERIOD_2_Z_NM: f64 = 2.0;

/// Hertz (sphere, cone, punch) and DMT are conservative: the dissipation per period is a
/// potential's change over a closed orbit, zero. Each gives 0 to 1e-12 eV on the Biolever,
/// and so do the paper's four cases at half of `Z_G1` (the energy's change between the
/// window's ends, which lie in free flight; [`conservative_energies_are_the_forces_integrals`]
/// checks the energies themselves).
#[test]
fn conservative_laws_dissipate_nothing() {
    let mut orbits = Vec::new();
    for (name, contact, z) in &LAWS[..4] {
        orbits.push((
            name.to_string(),
            orbit(&model_with(contact, *z, 2)).whole_orbit,
        ));
    }
    for name in [
        "biolever-mica",
        "biolever-soft",
        "maclever-mica",
        "maclever-soft",
    ] {
        let mut model = TappingModel::from_case(&builtin_case(name).expect("case")).expect("model");
        let z = 0.5 * model.grazing_separation_nm();
        model
            .set_separation(Separation::Constant(z))
            .expect("separation");
        orbits.push((name.to_string(), orbit(&model).whole_orbit));
    }
    for (name, whole) in orbits {
        assert!(!whole.impacts.is_empty());
        assert!(
            whole.dissipated_ev.abs() < 1e-12,
            "{name}: {:e} eV",
            whole.dissipated_ev
        );
    }
}

/// The energies `U(d)` that conservative laws' `dissipated_ev` is computed from (MODEL.md
/// section 10) are their forces' integrals: `-dU/dd = F_ts` by central differences (step 1e-5
/// nm, error about 1e-10 of the force's scale: tolerance 1e-7 of it) at gaps from -3 to 5 nm
/// on both sides of the contact surface, and `U` continuous across it (to 1e-9 of the
/// scale), for every conservative law (Hertz's three shapes, DMT, the film), a double layer,
/// and the built-in cases with a potential (the hydration force among them).
#[test]
fn conservative_energies_are_the_forces_integrals() {
    let mut forces = Vec::new();
    for (name, contact, z) in LAWS {
        forces.push((name.to_string(), *model_with(contact, z, 1).contact_force()));
    }
    for name in case_names() {
        let model = TappingModel::from_case(&builtin_case(name).expect("case")).expect("model");
        forces.push((name.to_string(), *model.contact_force()));
    }
    let mut checked = 0;
    for (name, force) in forces {
        let Some(_) = force.potential_nn_nm(0.0) else {
            continue;
        };
        checked += 1;
        let energy = |d: f64| force.potential_nn_nm(d).expect("a conservative force");
        let contact = force.contact_gap_nm();
        let gaps: Vec<f64> = (0..=160).map(|i| -3.0 + 0.05 * i as f64 + 1e-3).collect();
        let scale = gaps
            .iter()
            .map(|&d| force.force(d, 0.0).abs())
            .fold(0.0, f64::max);
        assert!(scale > 0.0, "{name}: no force");
        for d in gaps {
            if (d - contact).abs() < 1e-3 {
                continue;
            }
            let h = 1e-5;
            let slope = (energy(d - h) - energy(d + h)) / (2.0 * h);
            let f = force.force(d, 0.0);
            assert!(
                (slope - f).abs() < 1e-7 * scale,
                "{name} at d = {d} nm: -dU/dd = {slope} nN, F = {f} nN"
            );
        }
        let jump = energy(contact - 1e-12) - energy(contact + 1e-12);
        assert!(
            jump.abs() < 1e-9 * scale,
            "{name}: U jumps by {jump} at d_c"
        );
    }
    // The six conservative laws and forces above, and the built-in Hertz and DMT cases.
    assert!(checked >= 10, "{checked} conservative forces checked");
}

/// Clipped Kelvin-Voigt dissipates: positive, growing with the viscosity at a fixed separation.
#[test]
fn kelvin_voigt_dissipation_grows_with_viscosity() {
    let mut previous = 0.0;
    for viscosity in [1.0, 10.0, 30.0, 100.0] {
        let contact = format!(r#"{{"law": "kelvin-voigt", "viscosity_pa_s": {viscosity}}}"#);
        let whole = orbit(&model_with(&contact, 8.5, 2)).whole_orbit;
        assert!(
            whole.dissipated_ev > previous,
            "eta = {viscosity} Pa s: {} eV after {previous} eV",
            whole.dissipated_ev
        );
        previous = whole.dissipated_ev;
    }
}

/// The single-mode identity (MODEL.md section 10): for one mode driven by `F_1 cos(w t)` on a
/// periodic orbit, the drive's work is `pi F_1 A sin(Phi)` (the first harmonic alone), so
/// `pi F_1 A sin(Phi) = D + E_ts` with the damping loss `D = (k/(w_1 Q)) int q'^2 dt`. Checked to
/// 1e-9 relative with clipped Kelvin-Voigt, where `E_ts` is a sizeable part of the balance.
#[test]
fn single_mode_identity_between_phase_amplitude_and_dissipation() {
    for (viscosity, z) in [(100.0, 8.0), (1000.0, 6.0)] {
        let contact = format!(r#"{{"law": "kelvin-voigt", "viscosity_pa_s": {viscosity}}}"#);
        let model = model_with(&contact, z, 1);
        let whole = orbit(&model).whole_orbit;
        assert!(whole.dissipated_ev > 0.0);
        let drive = std::f64::consts::PI
            * model.drive_force_nn()
            * whole.amplitude_nm
            * whole.phase_deg.to_radians().sin()
            * afm::NN_NM_IN_EV;
        let loss = whole.mode_energy[0].damping_loss_ev + whole.dissipated_ev;
        assert!(
            (drive - loss).abs() < 1e-9 * drive,
            "eta = {viscosity}: {drive} eV vs {loss} eV"
        );
        assert!(
            whole.dissipated_ev > 0.01 * drive,
            "the dissipation is a visible part of the balance"
        );
    }
}

/// A plain discrete Fourier transform of `n` uniform samples of one period (rectangle rule, the
/// last sample, equal to the first, left out): `[a_k, b_k]` for `k = 1..=count`.
fn dft(samples: &[f64], count: usize) -> Vec<[f64; 2]> {
    let n = samples.len();
    (1..=count)
        .map(|k| {
            let (mut a, mut b) = (0.0, 0.0);
            for (j, u) in samples.iter().enumerate() {
                let angle = std::f64::consts::TAU * (k * j % n) as f64 / n as f64;
                a += u * angle.cos();
                b += u * angle.sin();
            }
            [2.0 * a / n as f64, 2.0 * b / n as f64]
        })
        .collect()
}

/// Harmonics 1..=20 of `u` on tapping orbits (Hertz, two and three impacts, and clipped
/// Kelvin-Voigt) against a DFT of 2^16 samples per period: the rectangle rule on the periodic
/// `u`, whose fourth derivative is the first to jump, errs by about `N^-4` (1e-19 relative), so
/// the samples' own accuracy (the solver's dense output, about 1e-11 nm) sets the tolerance:
/// 1e-9 nm.
#[test]
fn harmonics_match_a_dft_of_the_sampled_orbit() {
    let count = 20;
    let samples_per_period = 1 << 16;
    let settings = SteadyOrbitSettings {
        harmonics: count,
        ..SteadyOrbitSettings::default()
    };
    let models = [
        {
            let mut model = TappingModel::from_case(&builtin_case("biolever-mica").expect("case"))
                .expect("model");
            model
                .set_separation(Separation::Constant(5.0))
                .expect("separation");
            model
        },
        model_with(r#"{"law": "kelvin-voigt", "viscosity_pa_s": 100}"#, 8.5, 2),
    ];
    for model in &models {
        let z = model.separation().at(0.0);
        let orbit = steady_orbit(model, z, OrbitStart::Approach, &settings).expect("orbit");
        assert!(orbit.converged);
        let harmonics = &orbit.whole_orbit.harmonics;
        assert_eq!(harmonics.len(), count);
        let trajectory = sample_trajectory(
            model,
            &orbit.state,
            1,
            samples_per_period,
            &Settings::default(),
        )
        .expect("samples");
        let u: Vec<f64> = trajectory[..samples_per_period]
            .iter()
            .map(|s| s.u_nm)
            .collect();
        for (harmonic, [a, b]) in harmonics.iter().zip(dft(&u, count)) {
            let (phase_sin, phase_cos) = harmonic.phase_deg.to_radians().sin_cos();
            let (a_observed, b_observed) = (
                harmonic.amplitude_nm * phase_cos,
                harmonic.amplitude_nm * phase_sin,
            );
            assert!(
                (a_observed - a).abs() < 1e-9 && (b_observed - b).abs() < 1e-9,
                "Z = {z}, n = {}: ({a_observed:e}, {b_observed:e}) vs DFT ({a:e}, {b:e})",
                harmonic.n
            );
        }
        // Higher harmonics are there at all (the test would pass on zeros otherwise).
        assert!(harmonics[1].amplitude_nm > 1e-3 && harmonics[9].amplitude_nm > 1e-7);
    }
}

/// On the free orbit `u` is a pure first harmonic: harmonics 2..=20 vanish (below 1e-12 A0)
/// and the first is the closed form's `A0` and phase.
#[test]
fn the_free_orbit_has_only_the_first_harmonic() {
    let model =
        TappingModel::from_case(&builtin_case("maclever-mica").expect("case")).expect("model");
    let (_, observables) = afm::observe_period(
        &model,
        0.0,
        &model.free_state(),
        hybrid::Sensitivity::None,
        &Settings::default(),
        20,
    )
    .expect("observables");
    let a0 = model.free_amplitude_nm();
    assert!((observables.harmonics[0].amplitude_nm - a0).abs() < 1e-12 * a0);
    assert!((observables.harmonics[0].phase_deg - model.free_phase_deg()).abs() < 1e-9);
    for harmonic in &observables.harmonics[1..] {
        assert!(harmonic.amplitude_nm < 1e-12 * a0, "{harmonic:?}");
    }
    assert_eq!(observables.dissipated_ev, 0.0);
    assert_eq!(observables.max_indentation_nm, 0.0);
    assert!(observables.energy_balance_residual < 1e-12);
}

/// Indentation, virial and dissipation against rectangle rules on 2^16 samples per period
/// (Kelvin-Voigt, whose force starts as `(t - t_c)^{1/2}`: the samples' sums err by about
/// `h^{3/2}`, 1e-7 relative) and the deepest sample.
#[test]
fn indentation_virial_and_dissipation_match_sampled_sums() {
    let samples_per_period = 1 << 16;
    for contact in [
        r#"{"law": "kelvin-voigt", "viscosity_pa_s": 100}"#,
        r#"{"law": "dmt", "hamaker_constant_j": 5e-22, "intermolecular_distance_nm": 0.165}"#,
    ] {
        let model = model_with(contact, 8.5, 2);
        let o = orbit(&model);
        let whole = &o.whole_orbit;
        let samples = sample_trajectory(
            &model,
            &o.state,
            1,
            samples_per_period,
            &Settings::default(),
        )
        .expect("samples");
        let contact_gap = model.contact_gap_nm();
        let period = model.period_us();
        let h = period / samples_per_period as f64;
        let body = &samples[..samples_per_period];
        let deepest = body
            .iter()
            .map(|s| contact_gap - s.gap_nm)
            .fold(f64::NEG_INFINITY, f64::max);
        assert!(deepest <= whole.max_indentation_nm + 1e-12);
        assert!(
            whole.max_indentation_nm - deepest < 1e-6 * whole.max_indentation_nm,
            "{} vs deepest sample {deepest}",
            whole.max_indentation_nm
        );
        let (mut indented, mut in_contact, mut virial, mut dissipated) = (0.0, 0.0, 0.0, 0.0);
        for (j, s) in body.iter().enumerate() {
            let w: f64 = s.q_nm.iter().sum();
            let next: f64 = samples[j + 1].q_nm.iter().sum();
            let previous: f64 = samples[(j + samples_per_period - 1) % samples_per_period]
                .q_nm
                .iter()
                .sum();
            if s.gap_nm < contact_gap {
                indented += (contact_gap - s.gap_nm) * h;
                in_contact += h;
            }
            virial += s.force_nn * w * h;
            // int F w' dt with the central difference of w.
            dissipated -= s.force_nn * (next - previous) / 2.0;
        }
        let mean = indented / in_contact;
        assert!(
            (mean - whole.mean_indentation_nm).abs() < 1e-4 * mean,
            "{mean} vs {}",
            whole.mean_indentation_nm
        );
        let virial = virial / period * afm::NN_NM_IN_EV;
        assert!(
            (virial - whole.virial_ev).abs() < 1e-5 * virial.abs(),
            "{virial} vs {}",
            whole.virial_ev
        );
        let dissipated = dissipated * afm::NN_NM_IN_EV;
        let scale = whole.dissipated_ev.abs().max(1e-3 * virial.abs() * period);
        assert!(
            (dissipated - whole.dissipated_ev).abs() < 1e-4 * scale,
            "{dissipated} vs {}",
            whole.dissipated_ev
        );
    }
}

/// Every point of a diagram reports a closed energy balance (below 1e-9) and harmonics
/// `1..=4`; the dissipation of the paper's Hertz case vanishes all along the branch.
#[test]
fn every_diagram_point_closes_its_energy_balance() {
    let model =
        TappingModel::from_case(&builtin_case("biolever-mica").expect("case")).expect("model");
    let settings = afm::DiagramSettings::approach(&model);
    let diagram = afm::approach_diagram(&model, &settings).expect("diagram");
    assert!(diagram.points.len() > 100);
    for point in &diagram.points {
        assert!(
            point.energy_balance_residual < 1e-9,
            "Z = {}: {:e}",
            point.z_nm,
            point.energy_balance_residual
        );
        assert_eq!(point.harmonics.len(), 4);
        let scale = point.peak_force_nn * point.max_indentation_nm * afm::NN_NM_IN_EV;
        assert!(point.dissipated_ev.abs() <= 1e-11 * scale.max(1e-3));
    }
    for special in &diagram.special_points {
        assert_eq!(special.harmonics.len(), 4);
    }
}
