//! `Case.map` and `drumroll.RegimeMap`: the impact-regime map of `drumroll map`: the grazing
//! `G_n`, fold and period-doubling points of the approach diagram continued over a second
//! parameter (MODEL.md section 5), each curve a table.

use afm::ParameterAxis;
use drumroll::map::{compute_map_until, map_json, map_settings, MapArgs, CSV_COLUMNS};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use serde_json::Value;
use std::sync::Arc;

use crate::convert::{json_to_py, py_to_json, records_to_table, reduce_by_from_dict};
use crate::errors::to_py_err;
use crate::interrupt::without_gil_on_workers;
use crate::resolved::{resolved_model_args, Resolved};

/// The options of `Case.map`, as `drumroll map`'s.
pub struct MapOptions {
    /// The parameter varied: `a0` (nm), `drive-frequency` (kHz), `sample-modulus` (GPa),
    /// `tip-radius` (nm), `quality-factor-N`, `stiffness-N` (N/m).
    pub vary: String,
    /// One end of the parameter's range (its unit).
    pub start: f64,
    /// The other end.
    pub stop: f64,
    /// Parameter values where every curve spanning them gets a point exactly.
    pub at: Vec<f64>,
    /// The curves to compute (labels as `continue` names them); empty: all.
    pub labels: Vec<String>,
    /// Points per curve over the whole range, at least.
    pub points: usize,
    /// Lowest separation of the seed approach and the curves, nm.
    pub floor: Option<f64>,
    /// The seed approach stops below this A/A0.
    pub min_amplitude_ratio: f64,
    /// Largest arclength step of the seed approach, nm.
    pub max_step: Option<f64>,
    /// The harmonics `1..=N` of `u` at every curve point.
    pub harmonics: i64,
}

/// An impact-regime map: for each special point of the case's approach diagram (`G2`, `G3`,
/// `fold`, `period-doubling`, ...) its curve over a second parameter, as `drumroll map
/// --json`.
///
/// `curves`: a dict from label to a table (pandas DataFrame, else a dict of numpy arrays), one
/// row per curve point: `parameter` (the parameter's unit, `parameter_info["unit"]`), `z_nm`
/// (nm), `amplitude_ratio`, `phase_deg` (deg), `impacts_before`, `impacts_after`, `stable`,
/// `spectral_radius`, `residual`, `at_fixed_parameter` (a point at one of `at`),
/// `dissipated_ev` and `virial_ev` (eV), `max_indentation_nm`, `mean_indentation_nm`,
/// `energy_balance_residual`, `harmonic_<n>_amplitude_nm` and `harmonic_<n>_phase_deg` for
/// `n = 1..N`, `floquet_multipliers`, `state` (the columns of `map --csv`, then the rest). `ends`: why and where each curve ended.
/// `codim2_points`: the codimension-two points met on the curves. `to_dict()`: the whole
/// JSON object.
#[pyclass(module = "drumroll", frozen)]
pub struct RegimeMap {
    json: Value,
}

#[pymethods]
impl RegimeMap {
    /// Each curve's points as a table, by label.
    #[getter]
    fn curves<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let curves = PyDict::new(py);
        for curve in self.json["curves"].as_array().into_iter().flatten() {
            let points = curve["points"].as_array().map(Vec::as_slice).unwrap_or(&[]);
            curves.set_item(
                curve["label"].as_str().unwrap_or_default(),
                records_to_table(py, points, &CSV_COLUMNS)?,
            )?;
        }
        Ok(curves)
    }

    /// Each curve's ends, by label: lists of dicts (`reason`, `parameter`, `z_nm`, `error`).
    #[getter]
    fn ends<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let ends = PyDict::new(py);
        for curve in self.json["curves"].as_array().into_iter().flatten() {
            ends.set_item(
                curve["label"].as_str().unwrap_or_default(),
                json_to_py(py, &curve["ends"])?,
            )?;
        }
        Ok(ends)
    }

    /// The codimension-two points on the curves: a list of dicts.
    #[getter]
    fn codim2_points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.json["codim2_points"])
    }

    /// The parameter: `name`, `unit`, `from`, `to` and the case's own value `case_value`.
    #[getter]
    fn parameter_info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.json["parameter"])
    }

    /// The whole `drumroll map --json` object as a dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.json)
    }

    /// A map from its `to_dict()` (or a saved `drumroll map --json` file's content).
    #[classmethod]
    fn from_dict(_cls: &Bound<'_, pyo3::types::PyType>, data: &Bound<'_, PyAny>) -> PyResult<Self> {
        let json = py_to_json(data)?;
        if !json["curves"].is_array() {
            return Err(PyValueError::new_err(
                "a regime map's dict has a `curves` array (the output of `drumroll map --json`)",
            ));
        }
        Ok(Self { json })
    }

    /// Pickling: the map travels as its dict.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let state = slf.get().to_dict(slf.py())?;
        reduce_by_from_dict::<Self>(slf.py(), state)
    }

    fn __repr__(&self) -> String {
        let labels: Vec<&str> = self.json["curves"]
            .as_array()
            .map(|c| c.iter().filter_map(|c| c["label"].as_str()).collect())
            .unwrap_or_default();
        format!(
            "<drumroll.RegimeMap '{}' over {}: curves [{}]>",
            self.json["case"].as_str().unwrap_or_default(),
            self.json["parameter"]["name"].as_str().unwrap_or_default(),
            labels.join(", ")
        )
    }
}

/// The regime map of the case `resolved` with `options` (checked as `drumroll map` checks its
/// options), computed without the GIL.
pub fn compute_regime_map(
    py: Python<'_>,
    resolved: &Arc<Resolved>,
    options: MapOptions,
) -> PyResult<RegimeMap> {
    let args = MapArgs {
        model: resolved_model_args(),
        vary: options.vary,
        from: options.start,
        to: options.stop,
        at: options.at,
        labels: options.labels,
        points: options.points,
        floor: options.floor,
        min_amplitude_ratio: options.min_amplitude_ratio,
        max_step: options.max_step,
        harmonics: options.harmonics,
        json: true,
        csv: None,
        codim2_csv: None,
        plot: None,
        grid_file: None,
    };
    // The curves run on rayon's threads, each asking between its steps whether Ctrl-C came.
    let json = without_gil_on_workers(py, |interrupted| -> anyhow::Result<Value> {
        let (case, model) = (&resolved.case, &resolved.model);
        let axis = ParameterAxis::parse(&args.vary, case.cantilever.modes.len())?;
        let settings = map_settings(&args, model)?;
        let map = compute_map_until(case, axis, &settings, interrupted)?;
        Ok(map_json(&args, case, model, axis, &settings, &map))
    })?
    .map_err(to_py_err)?;
    Ok(RegimeMap { json })
}
