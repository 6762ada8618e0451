//! `drumroll.Diagram`: the bifurcation diagram in Z (the paper's Fig. 2; MODEL.md section 5)
//! as `drumroll continue --json` gives it, with the branch points as a table.

use drumroll::continue_diagram::{continue_case_until, continue_json, ContinueArgs, CSV_COLUMNS};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use serde_json::Value;

use crate::convert::{json_to_py, py_to_json, records_to_table, reduce_by_from_dict};
use crate::errors::{to_py_err, warn};
use crate::interrupt::without_gil;
use crate::resolved::{resolved_model_args, Resolved};
use std::sync::Arc;

/// A bifurcation diagram: the branch of periodic orbits continued in the separation Z from
/// above first contact down to a floor, every special point (grazing G_n, fold, ...) located
/// to |dZ| < 1e-9 nm, and optionally the retract branch back up.
///
/// `points`: one row per branch point, the columns those of `continue --csv` (the keys of a
/// `continue --json` point: `z_nm` in nm, `amplitude_ratio`, `phase_deg` in degrees,
/// `impacts_per_period`, `peak_force_nn` in nN, `dissipated_ev` and `virial_ev` in eV,
/// `max_indentation_nm`, `energy_balance_residual`, `stable`, ..., then
/// `harmonic_<n>_amplitude_nm` and `harmonic_<n>_phase_deg`; docs/output-schema.md); a pandas
/// DataFrame, or a dict of numpy arrays without pandas (a `null` `min_gap_nm` is NaN there).
/// `special_points`: a list of dicts (`label`, `z_nm`, `amplitude_ratio`, `phase_deg`,
/// `impacts_before`, `impacts_after`, `bracket_nm`, `precision_nm`, `converged`, `state`).
/// `to_dict()`: the whole `continue --json` object.
#[pyclass(module = "drumroll", frozen)]
pub struct Diagram {
    json: Value,
}

fn branch_table<'py>(py: Python<'py>, branch: &Value) -> PyResult<Bound<'py, PyAny>> {
    let points = branch["points"]
        .as_array()
        .map(Vec::as_slice)
        .unwrap_or(&[]);
    records_to_table(py, points, &CSV_COLUMNS)
}

#[pymethods]
impl Diagram {
    /// The approach's branch points, one row each (see the class docstring).
    #[getter]
    fn points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        branch_table(py, &self.json)
    }

    /// The approach's special points: a list of dicts with the keys of `continue --json`.
    #[getter]
    fn special_points<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.json["special_points"])
    }

    /// Why the approach stopped, in words.
    #[getter]
    fn stop(&self) -> String {
        self.json["stop"].as_str().unwrap_or_default().to_string()
    }

    /// Whether the approach reached its requested end (False: it stopped at `max_points` or on
    /// an error; the CLI exits with status 3 then).
    #[getter]
    fn completed(&self) -> bool {
        self.json["completed"].as_bool().unwrap_or(false)
    }

    /// The error that ended the approach early, if any.
    #[getter]
    fn error(&self) -> Option<String> {
        self.json["error"].as_str().map(String::from)
    }

    /// The retract's branch points (Z increasing from the approach's lowest point), or None
    /// when the diagram was computed without `retract=True`.
    #[getter]
    fn retract_points<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match self.json.get("retract") {
            Some(retract) => Ok(Some(branch_table(py, retract)?)),
            None => Ok(None),
        }
    }

    /// The retract's special points (a list of dicts), or None without a retract.
    #[getter]
    fn retract_special_points<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match self.json.get("retract") {
            Some(retract) => Ok(Some(json_to_py(py, &retract["special_points"])?)),
            None => Ok(None),
        }
    }

    /// With a retract: the `[Z_low, Z_high]` ranges (nm) where two stable orbits coexist (the
    /// hysteresis of approach and retract); None without a retract.
    #[getter]
    fn bistable_ranges_nm<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match self.json.get("bistable_ranges_nm") {
            Some(ranges) => Ok(Some(json_to_py(py, ranges)?)),
            None => Ok(None),
        }
    }

    /// The whole `drumroll continue --json` object as a dict.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.json)
    }

    /// A diagram from its `to_dict()` (or a saved `drumroll continue --json` file's content).
    #[classmethod]
    fn from_dict(_cls: &Bound<'_, pyo3::types::PyType>, data: &Bound<'_, PyAny>) -> PyResult<Self> {
        let json = py_to_json(data)?;
        if !json["points"].is_array() || !json["special_points"].is_array() {
            return Err(PyValueError::new_err(
                "a diagram's dict has `points` and `special_points` arrays (the output of `drumroll continue --json`)",
            ));
        }
        Ok(Self { json })
    }

    /// Pickling: the diagram travels as its dict.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let state = slf.get().to_dict(slf.py())?;
        reduce_by_from_dict::<Self>(slf.py(), state)
    }

    fn __repr__(&self) -> String {
        let labels: Vec<&str> = self.json["special_points"]
            .as_array()
            .map(|s| s.iter().filter_map(|p| p["label"].as_str()).collect())
            .unwrap_or_default();
        format!(
            "<drumroll.Diagram '{}': {} points, special points [{}]>",
            self.json["case"].as_str().unwrap_or_default(),
            self.json["points"].as_array().map_or(0, Vec::len),
            labels.join(", ")
        )
    }
}

/// The options of `Case.diagram`, as `drumroll continue`'s.
pub struct DiagramOptions {
    /// Lowest separation, nm.
    pub floor: Option<f64>,
    /// The approach stops below this A/A0.
    pub min_amplitude_ratio: f64,
    /// Largest arclength step, nm.
    pub max_step: Option<f64>,
    /// Largest number of points per branch.
    pub max_points: i64,
    /// Continue back up after the approach.
    pub retract: bool,
    /// The harmonics `1..=N` of `u` at every point.
    pub harmonics: i64,
}

/// The diagram of the case `resolved` (options as `drumroll continue`'s), computed without the GIL and
/// interruptible by Ctrl-C between branch points.
pub fn compute_diagram(
    py: Python<'_>,
    resolved: &Arc<Resolved>,
    options: &DiagramOptions,
) -> PyResult<Diagram> {
    let args = ContinueArgs {
        model: resolved_model_args(),
        floor: options.floor,
        min_amplitude_ratio: options.min_amplitude_ratio,
        max_step: options.max_step,
        max_points: options.max_points,
        retract: options.retract,
        json: true,
        csv: None,
        plot: None,
        overlay: false,
        panels: None,
        harmonics: options.harmonics,
        threads: None,
    };
    let (json, warning) = without_gil(
        py,
        |interrupted| -> anyhow::Result<(Value, Option<String>)> {
            let continued =
                continue_case_until(&args, &resolved.case, &resolved.model, interrupted)?;
            let json = continue_json(&args, &resolved.case, &resolved.model, &continued);
            let warning = continued.warning;
            Ok((json, warning))
        },
    )?
    .map_err(to_py_err)?;
    if let Some(warning) = warning {
        warn(py, &warning)?;
    }
    Ok(Diagram { json })
}
