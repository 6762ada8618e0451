//! The JSON objects as `serde_json::json!` built them before the commands wrote them from
//! derived structs (the reference of the byte-for-byte tests `orbit_json_bytes.rs` and
//! `diagram_json_bytes.rs`): `serde_json::Value` trees, whose objects are sorted maps.
// Each test binary uses its own subset of these helpers.
#![allow(dead_code)]

use afm::{fixtures, Case, SteadyOrbitSettings, TappingModel};
use drumroll::inputs::drive_json;
use serde_json::{json, Value};

/// The built-in case `name` and its model.
pub fn case_and_model(name: &str) -> (Case, TappingModel) {
    let case = fixtures::find_case(name).expect("built-in case");
    let model = TappingModel::from_case(&case).expect("valid case");
    (case, model)
}

/// The `inputs` object as `json!` builds it, with Newton's and the orbit search's settings
/// when `settings` is given.
pub fn reference_inputs(
    command: &str,
    options: Value,
    case: &Case,
    model: &TappingModel,
    integration: &hybrid::Settings,
    settings: Option<&SteadyOrbitSettings>,
) -> Value {
    let mut inputs = json!({
        "drumroll_version": env!("CARGO_PKG_VERSION"),
        "command": command,
        "options": options,
        "case": case.name,
        "cantilever": case.cantilever,
        "sample": case.sample,
        "free_amplitude_nm": model.free_amplitude_nm(),
        "drive_frequency_khz": model.drive_frequency_khz(),
        "drive": drive_json(model),
        "solver": {
            "relative_tolerance": integration.relative_tolerance,
            "absolute_tolerance": integration.absolute_tolerance,
            "event_time_tolerance": integration.event_time_tolerance,
            "event_value_tolerance": integration.event_value_tolerance,
            "samples_per_step": integration.samples_per_step,
            "taylor_series": integration.taylor_series,
        },
    });
    if let Some(settings) = settings {
        inputs["newton"] = json!({
            "tolerance": settings.newton.tolerance,
            "max_iterations": settings.newton.max_iterations,
        });
        inputs["steady_orbit"] = json!({
            "transient_periods": settings.transient_periods,
            "recurrence_periods": settings.recurrence_periods,
            "max_multiplicity": settings.max_multiplicity,
        });
    }
    inputs
}
