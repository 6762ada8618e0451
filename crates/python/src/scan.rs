//! `Case.scan`: an image line with amplitude feedback, as `drumroll scan` (MODEL.md section
//! 12), as a table of pixels whose columns are the CLI's CSV columns.

use afm::scan::line::ScanLine;
use afm::scan::raster::ScanRaster;
use drumroll::scan::{
    line_json, pixel_json, raster_json, raster_pixel_json, scan_pixels, scan_raster, Direction,
    Feedback, ScanArgs, CSV_COLUMNS,
};
use pyo3::prelude::*;
use serde_json::Value;
use std::path::Path;
use std::sync::Arc;

use crate::convert::{json_to_py, py_to_json, records_to_table};
use crate::errors::to_py_err;
use crate::interrupt::{without_gil, without_gil_on_workers};
use crate::resolved::Resolved;

/// The options of `Case.scan`, named as in Python (units in the names).
pub struct ScanOptions {
    /// The setpoint A/A0.
    pub setpoint: f64,
    /// Pixels along the line.
    pub pixels: i64,
    /// `"ideal"` or `"pi"`.
    pub feedback: String,
    /// `"trace"`, `"retrace"` or `"both"`.
    pub direction: String,
    /// PI: proportional gain, nm/nm.
    pub gain_p: f64,
    /// PI: integral gain, 1/ms.
    pub gain_i_per_ms: f64,
    /// PI: scan rate, nm/s.
    pub scan_rate_nm_per_s: f64,
    /// PI: lock-in time constant, ms.
    pub lockin_time_constant_ms: f64,
    /// Harmonics per pixel.
    pub harmonics: i64,
}

/// The scan line of a Python argument: a built-in name or a file path (`str`), or a dict in
/// the line files' format (sample names in it are built-in names; sample objects inline).
pub fn line_of(line: &Bound<'_, PyAny>) -> PyResult<ScanLine> {
    if let Ok(name) = line.extract::<String>() {
        return ScanLine::find(&name).map_err(crate::errors::afm_to_py_err);
    }
    let value = py_to_json(line)?;
    ScanLine::parse("the line dict", &value.to_string(), None).map_err(crate::errors::afm_to_py_err)
}

/// The raster of a Python argument: a raster file path (`str`; its rows' relative paths
/// resolved beside it), or a dict in the raster files' format (rows as line dicts or built-in
/// line names).
pub fn raster_of(raster: &Bound<'_, PyAny>) -> PyResult<ScanRaster> {
    if let Ok(path) = raster.extract::<String>() {
        return ScanRaster::load(Path::new(&path)).map_err(crate::errors::afm_to_py_err);
    }
    let value = py_to_json(raster)?;
    ScanRaster::parse("the raster dict", &value.to_string(), None)
        .map_err(crate::errors::afm_to_py_err)
}

/// `drumroll scan`'s arguments for `options` over the line or raster named `name` (a path or
/// built-in name, or `(dict)`).
fn scan_args(name: String, options: &ScanOptions) -> PyResult<ScanArgs> {
    let feedback = match options.feedback.as_str() {
        "ideal" => Feedback::Ideal,
        "pi" => Feedback::Pi,
        other => {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "feedback {other:?}: allowed: \"ideal\" or \"pi\""
            )))
        }
    };
    let direction = match options.direction.as_str() {
        "trace" => Direction::Trace,
        "retrace" => Direction::Retrace,
        "both" => Direction::Both,
        other => {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "direction {other:?}: allowed: \"trace\", \"retrace\" or \"both\""
            )))
        }
    };
    Ok(ScanArgs {
        line: name,
        raster: None,
        case: None,
        cantilever: None,
        a0: None,
        drive_frequency: None,
        setpoint: options.setpoint,
        pixels: options.pixels,
        feedback,
        direction,
        gain_p: options.gain_p,
        gain_i: options.gain_i_per_ms,
        scan_rate: options.scan_rate_nm_per_s,
        lockin_time_constant: options.lockin_time_constant_ms,
        harmonics: options.harmonics,
        json: true,
        out: None,
        plot: None,
    })
}

/// The name of a line or raster argument in the outputs: its path or built-in name, or
/// `(dict)`.
fn argument_name(argument: &Bound<'_, PyAny>) -> String {
    argument
        .extract::<String>()
        .unwrap_or_else(|_| String::from("(dict)"))
}

/// The scan of `line` with the case `resolved`'s cantilever, drive and A0: a table
/// (DataFrame, or dict of numpy arrays) with one row per pixel in scan order, the columns
/// `direction` and those of `drumroll scan`'s CSV; a DataFrame's `attrs["inputs"]` and
/// `attrs["line"]` hold the JSON output's `inputs` and `line`.
pub fn compute_scan<'py>(
    py: Python<'py>,
    resolved: &Arc<Resolved>,
    line: &Bound<'py, PyAny>,
    options: &ScanOptions,
) -> PyResult<Bound<'py, PyAny>> {
    let args = scan_args(argument_name(line), options)?;
    let line = line_of(line)?;
    let mut case = resolved.case.clone();
    case.sample = line.materials[0].clone();
    let (pixels, inputs) = without_gil(py, |interrupted| -> anyhow::Result<(Vec<Value>, Value)> {
        let settings = args.settings()?;
        let (pixels, inputs) = scan_pixels(&args, &case, &line, &settings, &mut |_| interrupted())?;
        Ok((pixels.iter().map(pixel_json).collect(), inputs))
    })?
    .map_err(to_py_err)?;
    pixel_table(py, &pixels, &[], &inputs, ("line", &line_json(&line)))
}

/// The scan of every row of `raster` (a raster file path or dict) as a line, as `drumroll scan
/// --raster` (the rows in parallel): a table with one row per pixel, rows in order, the
/// columns `direction`, `row`, `y_nm` (nm) and those of `drumroll scan`'s CSV; a DataFrame's
/// `attrs["inputs"]` and `attrs["raster"]` hold the JSON output's `inputs` and `raster`.
pub fn compute_raster_scan<'py>(
    py: Python<'py>,
    resolved: &Arc<Resolved>,
    raster: &Bound<'py, PyAny>,
    options: &ScanOptions,
) -> PyResult<Bound<'py, PyAny>> {
    let name = argument_name(raster);
    let args = scan_args(name.clone(), options)?;
    let raster = raster_of(raster)?;
    let mut case = resolved.case.clone();
    case.sample = raster.rows[0].materials[0].clone();
    // The rows run on rayon's threads, which cannot see a Ctrl-C themselves: this thread
    // looks for one while they run.
    let work = |interrupted: &(dyn Fn() -> bool + Sync)| -> anyhow::Result<(Vec<Value>, Value)> {
        let settings = args.settings()?;
        let asked = |_| interrupted();
        let source = format!("raster {name}");
        let (rows, mut inputs) = scan_raster(&args, &case, &raster, &source, &settings, &asked)?;
        inputs["options"]["raster"] = Value::String(name.clone());
        let pixels = rows
            .iter()
            .enumerate()
            .flat_map(|(j, row)| row.iter().map(move |pixel| (j, pixel)))
            .map(|(j, pixel)| raster_pixel_json(&raster, j, pixel))
            .collect();
        Ok((pixels, inputs))
    };
    let (pixels, inputs) = without_gil_on_workers(py, work)?.map_err(to_py_err)?;
    let sample = raster_json(&raster);
    pixel_table(py, &pixels, &["row", "y_nm"], &inputs, ("raster", &sample))
}

/// The table of a scan's JSON `pixels`: the columns `direction`, then `leading`, then those of
/// `drumroll scan`'s CSV; a DataFrame's `attrs["inputs"]` holds `inputs` and
/// `attrs[sample.0]` the JSON output's line or raster object `sample.1`.
fn pixel_table<'py>(
    py: Python<'py>,
    pixels: &[Value],
    leading: &[&'static str],
    inputs: &Value,
    sample: (&str, &Value),
) -> PyResult<Bound<'py, PyAny>> {
    let mut columns = vec!["direction"];
    columns.extend(leading);
    columns.extend(CSV_COLUMNS);
    let table = records_to_table(py, pixels, &columns)?;
    if let Ok(attrs) = table.getattr("attrs") {
        attrs.set_item("inputs", json_to_py(py, inputs)?)?;
        attrs.set_item(sample.0, json_to_py(py, sample.1)?)?;
    }
    Ok(table)
}
