//! `Case.approach`: the time-domain approach (and retract) sweep of `drumroll approach`, read
//! by a lock-in once per block of drive cycles, as a table of records.

use drumroll::approach::{approach_inputs_json, ApproachArgs, CSV_HEADER};
use pyo3::prelude::*;
use serde_json::Value;

use crate::convert::{json_to_py, records_to_table};
use crate::errors::to_py_err;
use crate::interrupt::without_gil_on_workers;
use crate::resolved::{resolved_model_args, Resolved};
use std::sync::Arc;

/// The options of `Case.approach`, named as in Python (units in the names).
pub struct ApproachOptions {
    /// Start separation, nm (default 0.2 nm above first contact).
    pub from_nm: Option<f64>,
    /// Floor, nm.
    pub to_nm: f64,
    /// Sweep speed, nm/s.
    pub rate_nm_per_s: f64,
    /// Retract back up after the approach.
    pub retract: bool,
    /// Drive cycles per lock-in reading.
    pub lockin_cycles: i64,
    /// Keep every N-th reading.
    pub every: i64,
    /// Cycles integrated at the start before the sweep.
    pub settle_cycles: i64,
    /// Contact integration tolerance.
    pub tolerance: f64,
    /// The harmonics `1..=N` of `u` of every reading.
    pub harmonics: i64,
}

/// The sweep of the case `resolved` with `options`: a table (DataFrame, or dict of numpy arrays) with one
/// row per record and the columns of `drumroll approach`'s CSV; a DataFrame's
/// `attrs["inputs"]` holds the `inputs` object of `--jsonl`'s first line.
pub fn compute_approach<'py>(
    py: Python<'py>,
    resolved: &Arc<Resolved>,
    options: &ApproachOptions,
) -> PyResult<Bound<'py, PyAny>> {
    let args = ApproachArgs {
        model: resolved_model_args(),
        from: options.from_nm,
        to: options.to_nm,
        rate: options.rate_nm_per_s,
        retract: options.retract,
        lockin_cycles: options.lockin_cycles,
        every: options.every,
        settle_cycles: options.settle_cycles,
        tolerance: options.tolerance,
        harmonics: options.harmonics,
        jsonl: true,
        out: None,
        plot: None,
    };
    // The sweep may integrate its cycles ahead on rayon's threads: the work runs on a thread
    // of its own while this one looks for Ctrl-C, and every thread of the sweep asks between
    // cycles whether one came.
    let (records, inputs) =
        without_gil_on_workers(py, |interrupted| -> anyhow::Result<(Vec<Value>, Value)> {
            let model = &resolved.model;
            let settings = args.settings(model)?;
            let inputs = approach_inputs_json(&resolved.case, model, &settings);
            let mut sweep = afm::Sweep::new(model, settings).map_err(anyhow::Error::new)?;
            let mut records = Vec::new();
            while let Some(record) = sweep.next_record_until(interrupted).map_err(|error| {
                anyhow::Error::new(error).context(format!(
                    "the sweep of case `{}` failed at Z = {} nm after {} cycles",
                    resolved.case.name,
                    sweep.z_nm(),
                    sweep.cycles_done()
                ))
            })? {
                records.push(serde_json::to_value(record)?);
            }
            Ok((records, inputs))
        })?
        .map_err(to_py_err)?;
    let columns: Vec<&str> = CSV_HEADER.split(',').collect();
    let table = records_to_table(py, &records, &columns)?;
    if let Ok(attrs) = table.getattr("attrs") {
        attrs.set_item("inputs", json_to_py(py, &inputs)?)?;
    }
    Ok(table)
}
