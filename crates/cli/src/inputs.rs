//! The `inputs` object that every JSON result carries (docs/output-schema.md): the drumroll
//! version, the command and its options, the cantilever and sample as resolved (in the case
//! files' own format, so that they can be saved and loaded again), the drive, and the
//! solver's and Newton's settings, so that a saved result says how to reproduce it.

use afm::{Cantilever, Case, Sample, SteadyOrbitSettings, TappingModel};
use serde::Serialize;
use serde_json::{json, Value};

use crate::json_value::{plain_value, sorted_keys};

/// The `inputs` object (docs/output-schema.md) as a derived `Serialize` of borrowed fields,
/// declared in alphabetical order of their keys: the bytes of the same object as a
/// `serde_json::Value` (whose objects are sorted maps).
#[derive(Debug, Serialize)]
pub struct InputsJson<'a> {
    /// The cantilever as resolved, in the case files' format.
    #[serde(serialize_with = "sorted_keys")]
    cantilever: &'a Cantilever,
    /// The case's name.
    case: &'a str,
    /// The command (e.g. `simulate`).
    command: &'a str,
    /// [`drive_json`].
    drive: Value,
    /// The drive frequency, kHz.
    drive_frequency_khz: f64,
    /// The drumroll version.
    drumroll_version: &'static str,
    /// The free amplitude `A0`, nm.
    free_amplitude_nm: f64,
    /// Newton's settings, for steady orbits.
    #[serde(skip_serializing_if = "Option::is_none")]
    newton: Option<NewtonJson>,
    /// The command's own options.
    options: Value,
    /// The sample as resolved, in the case files' format.
    #[serde(serialize_with = "sorted_keys")]
    sample: &'a Sample,
    /// The solver's settings.
    solver: SolverJson,
    /// The orbit search's settings, for steady orbits.
    #[serde(skip_serializing_if = "Option::is_none")]
    steady_orbit: Option<SteadyOrbitJson>,
}

/// The `solver` object of [`InputsJson`]: the integration settings a result used.
#[derive(Debug, Serialize)]
struct SolverJson {
    absolute_tolerance: f64,
    event_time_tolerance: f64,
    event_value_tolerance: f64,
    relative_tolerance: f64,
    samples_per_step: usize,
    taylor_series: bool,
}

/// The `newton` object of [`InputsJson`]: the steady orbits' Newton settings.
#[derive(Debug, Serialize)]
struct NewtonJson {
    max_iterations: usize,
    tolerance: f64,
}

/// The `steady_orbit` object of [`InputsJson`]: the orbit search's settings.
#[derive(Debug, Serialize)]
struct SteadyOrbitJson {
    max_multiplicity: usize,
    recurrence_periods: usize,
    transient_periods: usize,
}

impl<'a> InputsJson<'a> {
    /// The `inputs` object of a result of `command` (e.g. `approach`) on `case` (resolved into
    /// `model`), with the command's own options in `options` (keys with units, as the options'
    /// names say) and the solver settings `integration` the computation used.
    pub fn new(
        command: &'a str,
        options: Value,
        case: &'a Case,
        model: &TappingModel,
        integration: &hybrid::Settings,
    ) -> Self {
        Self {
            cantilever: &case.cantilever,
            case: &case.name,
            command,
            drive: drive_json(model),
            drive_frequency_khz: model.drive_frequency_khz(),
            drumroll_version: env!("CARGO_PKG_VERSION"),
            free_amplitude_nm: model.free_amplitude_nm(),
            newton: None,
            options,
            sample: &case.sample,
            solver: SolverJson {
                absolute_tolerance: integration.absolute_tolerance,
                event_time_tolerance: integration.event_time_tolerance,
                event_value_tolerance: integration.event_value_tolerance,
                relative_tolerance: integration.relative_tolerance,
                samples_per_step: integration.samples_per_step,
                taylor_series: integration.taylor_series,
            },
            steady_orbit: None,
        }
    }

    /// [`InputsJson::new`] for a computation of steady orbits with `settings`: its solver
    /// settings, and Newton's and the orbit search's settings besides.
    pub fn orbit(
        command: &'a str,
        options: Value,
        case: &'a Case,
        model: &TappingModel,
        settings: &SteadyOrbitSettings,
    ) -> Self {
        Self {
            newton: Some(NewtonJson {
                max_iterations: settings.newton.max_iterations,
                tolerance: settings.newton.tolerance,
            }),
            steady_orbit: Some(SteadyOrbitJson {
                max_multiplicity: settings.max_multiplicity,
                recurrence_periods: settings.recurrence_periods,
                transient_periods: settings.transient_periods,
            }),
            ..Self::new(command, options, case, model, &settings.integration)
        }
    }
}

/// [`InputsJson::new`] as a `serde_json::Value`.
pub fn inputs_json(
    command: &str,
    options: Value,
    case: &Case,
    model: &TappingModel,
    integration: &hybrid::Settings,
) -> Value {
    plain_value(&InputsJson::new(command, options, case, model, integration))
}

/// [`InputsJson::orbit`] as a `serde_json::Value`.
pub fn orbit_inputs_json(
    command: &str,
    options: Value,
    case: &Case,
    model: &TappingModel,
    settings: &SteadyOrbitSettings,
) -> Value {
    plain_value(&InputsJson::orbit(command, options, case, model, settings))
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
