//! The `inputs` object that every JSON result carries (docs/output-schema.md): the drumroll
//! version, the command and its options, the cantilever and sample as resolved (in the case
//! files' own format, so that they can be saved and loaded again), the drive, and the
//! solver's and Newton's settings, so that a saved result says how to reproduce it.

use afm::{Case, SteadyOrbitSettings, TappingModel};
use serde_json::{json, Value};

/// The `inputs` object of a result of `command` (e.g. `approach`) on `case` (resolved into
/// `model`), with the command's own options in `options` (keys with units, as the options'
/// names say) and the solver settings `integration` the computation used.
pub fn inputs_json(
    command: &str,
    options: Value,
    case: &Case,
    model: &TappingModel,
    integration: &hybrid::Settings,
) -> Value {
    json!({
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
    })
}

/// [`inputs_json`] for a computation of steady orbits with `settings`: its solver settings,
/// and Newton's and the orbit search's settings besides.
pub fn orbit_inputs_json(
    command: &str,
    options: Value,
    case: &Case,
    model: &TappingModel,
    settings: &SteadyOrbitSettings,
) -> Value {
    let mut inputs = inputs_json(command, options, case, model, &settings.integration);
    inputs["newton"] = json!({
        "tolerance": settings.newton.tolerance,
        "max_iterations": settings.newton.max_iterations,
    });
    inputs["steady_orbit"] = json!({
        "transient_periods": settings.transient_periods,
        "recurrence_periods": settings.recurrence_periods,
        "max_multiplicity": settings.max_multiplicity,
    });
    inputs
}

/// The `drive` object of [`inputs_json`] (docs/output-schema.md; MODEL.md section 14): the
/// case's drive object as written (`kind` and its fields) with what the model solved from it:
/// the acoustic base amplitude `Y` and participation factors, or the bimodal second drive's
/// force, ratio and the common period.
pub fn drive_json(model: &TappingModel) -> Value {
    let mut drive = json!(model.drive_spec());
    drive["force_nn"] = json!(model.drive_force_nn());
    if let Some(base) = model.base_motion() {
        drive["base_amplitude_nm"] = json!(base.amplitude_nm);
        drive["base_participation"] = json!(base.participation);
    }
    if let Some(second) = model.second_drive() {
        drive["second_force_nn"] = json!(second.force_nn);
        drive["frequency_ratio"] = json!([second.ratio.numerator, second.ratio.denominator]);
        drive["common_period_us"] = json!(model.period_us());
    }
    drive
}
