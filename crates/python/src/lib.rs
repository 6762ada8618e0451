//! The Python module `drumroll`: steady orbits, bifurcation diagrams and approach sweeps of
//! AFM cantilevers tapping a sample (Melcher, Xu, Raman, APL 93, 093111 (2008)), computed by
//! the `afm` crate and given as Python objects, numpy arrays and pandas DataFrames whose keys
//! and numbers are those of the `drumroll` CLI's JSON (docs/output-schema.md). Long
//! computations release the GIL; `Case`, `Orbit` and `Diagram` pickle.
#![warn(missing_docs)]

pub mod approach;
pub mod case;
pub mod convert;
pub mod diagram;
pub mod errors;
pub mod interrupt;
pub mod measurement;
pub mod orbit;
pub mod regime_map;
pub mod resolved;
pub mod scan;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::Value;

use crate::convert::json_to_py;
use crate::errors::afm_to_py_err;

/// The built-in fixtures: `{"cases": {name: case dict}, "cantilevers": {name: cantilever
/// dict}, "samples": {name: sample dict}}`, each dict in its file's format (a case with its
/// cantilever and sample inline, as `Case.to_dict()`).
#[pyfunction]
fn cases(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let result = PyDict::new(py);
    let table = PyDict::new(py);
    for name in afm::case_names() {
        let case = afm::builtin_case(name).map_err(afm_to_py_err)?;
        let value = serde_json::json!({
            "name": case.name,
            "description": case.description,
            "cantilever": case.cantilever,
            "sample": case.sample,
            "free_amplitude_nm": case.free_amplitude_nm,
            "drive_frequency_khz": case.drive_frequency_khz,
            "drive": case.drive,
        });
        table.set_item(name, json_to_py(py, &value)?)?;
    }
    result.set_item("cases", table)?;
    let table = PyDict::new(py);
    for name in afm::cantilever_names() {
        let cantilever = afm::builtin_cantilever(name).map_err(afm_to_py_err)?;
        table.set_item(name, json_to_py(py, &to_json(&cantilever)?)?)?;
    }
    result.set_item("cantilevers", table)?;
    let table = PyDict::new(py);
    for name in afm::sample_names() {
        let sample = afm::builtin_sample(name).map_err(afm_to_py_err)?;
        table.set_item(name, json_to_py(py, &to_json(&sample)?)?)?;
    }
    result.set_item("samples", table)?;
    Ok(result)
}

fn to_json(value: &impl serde::Serialize) -> PyResult<Value> {
    serde_json::to_value(value).map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))
}

/// The `drumroll` module.
#[pymodule]
#[pyo3(name = "drumroll")]
fn drumroll_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<case::Case>()?;
    m.add_class::<orbit::Orbit>()?;
    m.add_class::<diagram::Diagram>()?;
    m.add_class::<regime_map::RegimeMap>()?;
    m.add_class::<measurement::Measurement>()?;
    m.add_class::<measurement::FitResult>()?;
    m.add_function(wrap_pyfunction!(cases, m)?)?;
    m.add_function(wrap_pyfunction!(orbit::_restore_orbit, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
