//! `drumroll.Measurement` and `drumroll.FitResult`: a measured approach curve, its transitions
//! (`drumroll detect`) and a fit of the model to it (`drumroll fit`), whose dicts are the CLI's
//! JSON built by the cli crate's own functions (MODEL.md section 13).

use afm::fit::least_squares::{FitParameter, FitSettings};
use afm::fit::measurement::Measurement as AfmMeasurement;
use afm::fit::transitions::{detect_transitions, DetectionSettings};
use drumroll::detect::detect_json;
use drumroll::fit::{fit_and_detect, fit_json};
use drumroll::measurement_args::MeasurementArgs;
use pyo3::prelude::*;
use serde_json::Value;

use crate::convert::{json_to_py, records_to_table};
use crate::errors::{afm_to_py_err, to_py_err};
use crate::interrupt::without_gil_on_workers;
use crate::resolved::Resolved;

/// A measured approach curve read from a CSV or TSV file with a header, as `drumroll detect
/// --data` reads it: `Measurement.from_csv(path, columns="z=NAME,amplitude=NAME,phase=NAME",
/// z_unit="nm", amplitude_unit="nm" (or "V" with invols=NM_PER_V), phase_radians=False,
/// a0=None)`. `a0` (nm) is the free amplitude; `approach` the rows as a table (`line`,
/// `z_nm`, `amplitude_nm`, `phase_deg`); `bad_rows` the rows left out with their line
/// numbers; `detect()` the transitions.
#[pyclass(module = "drumroll", frozen)]
pub struct Measurement {
    /// The curve as read.
    pub measurement: AfmMeasurement,
}

#[pymethods]
impl Measurement {
    /// Read a measurement file (see the class docstring); ValueError names the file, line and
    /// column of a bad file.
    #[staticmethod]
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (path, *, columns=None, z_unit="nm", amplitude_unit="nm", invols=None, phase_radians=false, a0=None))]
    fn from_csv(
        py: Python<'_>,
        path: String,
        columns: Option<String>,
        z_unit: &str,
        amplitude_unit: &str,
        invols: Option<f64>,
        phase_radians: bool,
        a0: Option<f64>,
    ) -> PyResult<Self> {
        let args = MeasurementArgs {
            data: path,
            columns,
            z_unit: z_unit.to_string(),
            amplitude_unit: amplitude_unit.to_string(),
            invols,
            phase_radians,
        };
        let options = args.options(a0).map_err(to_py_err)?;
        let measurement = py
            .allow_threads(|| AfmMeasurement::from_file(&args.data, &options))
            .map_err(afm_to_py_err)?;
        Ok(Self { measurement })
    }

    /// The free amplitude, nm (the mean of the free rows, or the given `a0`).
    #[getter]
    fn a0(&self) -> f64 {
        self.measurement.a0_nm
    }

    /// The approach rows (Z decreasing): a pandas DataFrame (dict of numpy arrays without
    /// pandas) with `line`, `z_nm`, `amplitude_nm`, `phase_deg`.
    #[getter]
    fn approach<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows: Vec<Value> = self
            .measurement
            .approach
            .iter()
            .map(|p| serde_json::to_value(p).unwrap_or(Value::Null))
            .collect();
        records_to_table(py, &rows, &["line", "z_nm", "amplitude_nm", "phase_deg"])
    }

    /// The rows left out: a list of dicts `line`, `column`, `reason`.
    #[getter]
    fn bad_rows<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(
            py,
            &serde_json::to_value(&self.measurement.bad_rows).unwrap_or(Value::Null),
        )
    }

    /// The transitions (kinks and jumps) with their Z, 1-sigma uncertainty, A/A0, phase and
    /// significance: the dict of `drumroll detect --json` (MODEL.md section 13.2).
    #[pyo3(signature = (*, significance=0.01, window=0))]
    fn detect<'py>(
        &self,
        py: Python<'py>,
        significance: f64,
        window: usize,
    ) -> PyResult<Bound<'py, PyAny>> {
        let settings = DetectionSettings {
            significance,
            half_window: window,
        };
        let detection = py
            .allow_threads(|| {
                settings.validate("detect")?;
                detect_transitions(
                    &self.measurement.approach,
                    self.measurement.a0_nm,
                    &settings,
                )
            })
            .map_err(afm_to_py_err)?;
        json_to_py(
            py,
            &detect_json(&self.measurement, &detection, significance),
        )
    }
}

/// The result of `Case.fit(measurement, fit=[...])`: `parameters` (a dict name ->
/// `{"value", "stderr", "initial"}`), `points` (a DataFrame: the measured rows with the fitted
/// model and its contrast observables), `to_dict()` (the `drumroll fit --json` object).
#[pyclass(module = "drumroll", frozen)]
pub struct FitResult {
    json: Value,
}

#[pymethods]
impl FitResult {
    /// The fitted parameters: name -> dict of `value`, `stderr` (None: undetermined),
    /// `initial`.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.json["parameters"])
    }

    /// The measured points with the fitted model, one row each (docs/output-schema.md).
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows = self.json["points"]
            .as_array()
            .map(Vec::as_slice)
            .unwrap_or(&[]);
        records_to_table(py, rows, &["line", "z_nm", "amplitude_nm", "phase_deg"])
    }

    /// The whole `drumroll fit --json` object as a dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.json)
    }
}

/// Fit `resolved`'s case to `measurement` over the parameters named in `fit` (the names of
/// `drumroll fit --fit`), without the GIL.
pub fn fit_case(
    py: Python<'_>,
    resolved: &Resolved,
    measurement: &Measurement,
    fit: Vec<String>,
    max_evaluations: usize,
) -> PyResult<FitResult> {
    let modes = resolved.case.cantilever.mode_count();
    let parameters = fit
        .iter()
        .map(|name| FitParameter::parse(name, modes))
        .collect::<Result<Vec<_>, _>>()
        .map_err(afm_to_py_err)?;
    let mut settings = FitSettings::new(parameters);
    settings.max_evaluations = max_evaluations.clamp(1, 10_000);
    let measured = &measurement.measurement;
    // The fit runs on rayon's threads (its Jacobian's columns), each asking between branch
    // points whether Ctrl-C came.
    let json = without_gil_on_workers(py, |interrupted| {
        let (result, detection) = fit_and_detect(&resolved.case, measured, &settings, interrupted)?;
        Ok::<Value, afm::AfmError>(fit_json(&resolved.case.name, measured, &result, &detection))
    })?
    .map_err(afm_to_py_err)?;
    Ok(FitResult { json })
}
