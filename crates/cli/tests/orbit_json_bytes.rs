//! `simulate --json`'s object written from derived structs ([`drumroll::orbit_json::OrbitJson`],
//! [`drumroll::inputs::InputsJson`]) is byte for byte the object built as a
//! `serde_json::Value` with `json!` (the form it replaced, written out here as the reference):
//! the same keys, in the same (sorted) order, with the same numbers.

use afm::{steady_orbit, Case, OrbitStart, SteadyOrbit, SteadyOrbitSettings, TappingModel};
use drumroll::inputs::inputs_json;
use drumroll::simulate::{coexisting_orbit, orbit_at, simulate_json, simulate_object, Start};
use serde_json::{json, Value};

mod json_reference;
use json_reference::{case_and_model, reference_inputs};

/// The orbit object as `json!` builds it.
fn reference_orbit(case: &str, model: &TappingModel, orbit: &SteadyOrbit) -> Value {
    let observables = orbit.observables();
    let (amplitude_ratio, phase_deg) = orbit.lockin(model.free_amplitude_nm());
    let min_gap = observables.min_gap_nm();
    json!({
        "case": case,
        "z_nm": orbit.z_nm,
        "first_contact_z_nm": model.grazing_separation_nm(),
        "free_amplitude_nm": model.free_amplitude_nm(),
        "drive_frequency_khz": model.drive_frequency_khz(),
        "period_us": model.period_us(),
        "amplitude_ratio": amplitude_ratio,
        "phase_deg": phase_deg,
        "free_phase_deg": model.free_phase_deg(),
        "multiplicity": orbit.multiplicity,
        "impacts_per_period": orbit.impacts_per_period(),
        "impacts_per_orbit": orbit.impacts_per_orbit(),
        "converged": orbit.converged,
        "newton_iterations": orbit.iterations,
        "residual": orbit.residual,
        "stable": orbit.stable,
        "floquet_multipliers": orbit.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>(),
        "spectral_radius": continuation::spectral_radius(&orbit.multipliers),
        "gap_minima": observables.gap_minima,
        "min_gap_nm": min_gap.is_finite().then_some(min_gap),
        "impacts": observables.impacts,
        "peak_force_nn": observables.peak_force_nn,
        "mean_force_nn": observables.mean_force_nn,
        "contact_time_periods": observables.contact_time_periods,
        "impulse_nn_us": observables.impulse_nn_us,
        "dissipated_ev": observables.dissipated_ev,
        "virial_ev": observables.virial_ev,
        "max_indentation_nm": observables.max_indentation_nm,
        "mean_indentation_nm": observables.mean_indentation_nm,
        "energy_balance_residual": observables.energy_balance_residual,
        "harmonics": observables.harmonics,
        "second_drive": observables.second_drive.map(|response| json!({
            "frequency_khz": model.second_drive().map(|second| second.frequency_khz),
            "free_amplitude_nm": model.second_drive().map(|second| second.free_amplitude_nm),
            "amplitude_nm": response.amplitude_nm,
            "phase_deg": response.phase_deg,
            "free_phase_deg": model
                .free_response()
                .second_photodiode_harmonic()
                .map(|[a, b]| b.atan2(a).to_degrees()),
        })),
        "state": orbit.state,
        "periods": orbit.period_breakdown(model.free_amplitude_nm()),
    })
}

/// The settings of `simulate --harmonics 3`.
fn settings() -> SteadyOrbitSettings {
    SteadyOrbitSettings {
        harmonics: 3,
        ..SteadyOrbitSettings::default()
    }
}

/// `simulate --json`'s object of `orbit` (found from `start`, with `coexisting` beside it)
/// written from the structs and from the reference `json!` tree: the same bytes, and the
/// `Value` form (`simulate_json`) equal to the reference. Returns the reference.
fn same_bytes(
    case: &Case,
    model: &TappingModel,
    orbit: &SteadyOrbit,
    start: &str,
    coexisting: Option<(&SteadyOrbit, &str)>,
) -> Value {
    let settings = settings();
    let options =
        json!({"z_nm": orbit.z_nm, "amplitude_ratio": null, "start": start, "harmonics": 3});
    let mut reference = reference_orbit(&case.name, model, orbit);
    reference["start"] = json!(start);
    reference["coexisting_orbit"] = coexisting.map_or(Value::Null, |(other, other_start)| {
        let mut other = reference_orbit(&case.name, model, other);
        other["start"] = json!(other_start);
        other
    });
    reference["inputs"] = reference_inputs(
        "simulate",
        options.clone(),
        case,
        model,
        &settings.integration,
        Some(&settings),
    );
    let object = simulate_object(
        case,
        model,
        &settings,
        orbit,
        start,
        coexisting,
        options.clone(),
    );
    let written = serde_json::to_string_pretty(&object).expect("JSON");
    let expected = serde_json::to_string_pretty(&reference).expect("JSON");
    assert_eq!(written, expected, "{} at Z = {} nm", case.name, orbit.z_nm);
    let value = simulate_json(case, model, &settings, orbit, start, coexisting, options);
    assert_eq!(
        value, reference,
        "{} at Z = {} nm as a Value",
        case.name, orbit.z_nm
    );
    reference
}

/// [`same_bytes`] of `simulate --case NAME --z Z --json` (start `approach`).
fn same_bytes_at(name: &str, z: f64) -> Value {
    let (case, model) = case_and_model(name);
    let settings = settings();
    let (orbit, start) =
        orbit_at(&model, Some(z), None, Start::Approach, &settings).expect("orbit");
    let other = coexisting_orbit(&model, &orbit, start, &settings);
    let coexisting = other.as_ref().map(|o| (o, start.other().name()));
    same_bytes(&case, &model, &orbit, start.name(), coexisting)
}

#[test]
fn a_double_impact_orbit_is_written_as_the_value_tree_was() {
    let reference = same_bytes_at("biolever-mica", 8.518336);
    assert_eq!(reference["impacts_per_orbit"], 2);
    assert_eq!(reference["coexisting_orbit"], Value::Null);
}

#[test]
fn a_coexisting_orbit_is_written_as_the_value_tree_was() {
    // In the MAClever-on-mica bistable window, the retract branch's orbit (followed up from
    // 19.995 nm) has the approach branch's beside it, which the transient start reaches
    // (crates/afm/tests/coexistence.rs).
    let (case, model) = case_and_model("maclever-mica");
    let settings = settings();
    let below = steady_orbit(&model, 19.995, OrbitStart::Approach, &settings).expect("below");
    let mut retract = below;
    for z in [19.996, 19.997] {
        retract = steady_orbit(&model, z, OrbitStart::Near(&retract.state), &settings)
            .expect("retract orbit");
    }
    let other = coexisting_orbit(&model, &retract, Start::Approach, &settings)
        .expect("the transient start's orbit");
    let reference = same_bytes(&case, &model, &retract, "near", Some((&other, "transient")));
    assert!(reference["coexisting_orbit"].is_object());
}

#[test]
fn bimodal_and_acoustic_drives_are_written_as_the_value_tree_was() {
    let bimodal = same_bytes_at("biolever-mica-bimodal", 8.5);
    assert!(bimodal["second_drive"].is_object());
    assert!(bimodal["inputs"]["drive"]["frequency_ratio"].is_array());
    let acoustic = same_bytes_at("biolever-mica-acoustic", 8.5);
    assert!(acoustic["inputs"]["drive"]["base_participation"].is_array());
}

#[test]
fn other_contact_laws_are_written_as_the_value_tree_was() {
    for name in [
        "biolever-adhesive",
        "biolever-soft-viscoelastic",
        "biolever-mica-hydration",
    ] {
        let reference = same_bytes_at(name, 8.5);
        assert!(reference["inputs"]["sample"].is_object(), "{name}");
    }
}

#[test]
fn inputs_without_orbit_settings_are_the_value_tree() {
    let (case, model) = case_and_model("biolever-soft");
    let integration = hybrid::Settings::default();
    let options = json!({"from_nm": 9.0, "to_nm": 8.0});
    let reference = reference_inputs(
        "approach",
        options.clone(),
        &case,
        &model,
        &integration,
        None,
    );
    let value = inputs_json("approach", options, &case, &model, &integration);
    assert_eq!(value, reference);
    assert!(value.get("newton").is_none());
}
