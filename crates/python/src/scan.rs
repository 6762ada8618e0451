//! `Case.scan`: an image line with amplitude feedback, as `drumroll scan` (MODEL.md section
//! 12), as a table of pixels whose columns are the CLI's CSV columns.

use afm::scan::line::ScanLine;
use drumroll::scan::{
    line_json, pixel_json, scan_pixels, Direction, Feedback, ScanArgs, CSV_COLUMNS,
};
use pyo3::prelude::*;
use serde_json::Value;
use std::sync::Arc;

use crate::convert::{json_to_py, py_to_json, records_to_table};
use crate::errors::to_py_err;
use crate::interrupt::without_gil;
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
    let line_name = line
        .extract::<String>()
        .unwrap_or_else(|_| String::from("(dict)"));
    let line = line_of(line)?;
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
    let args = ScanArgs {
        line: line_name,
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
    };
    let mut case = resolved.case.clone();
    case.sample = line.materials[0].clone();
    let (pixels, inputs) = without_gil(py, |interrupted| -> anyhow::Result<(Vec<Value>, Value)> {
        let settings = args.settings()?;
        let (pixels, inputs) = scan_pixels(&args, &case, &line, &settings, &mut |_| interrupted())?;
        Ok((pixels.iter().map(pixel_json).collect(), inputs))
    })?
    .map_err(to_py_err)?;
    let mut columns = vec!["direction"];
    columns.extend(CSV_COLUMNS);
    let table = records_to_table(py, &pixels, &columns)?;
    if let Ok(attrs) = table.getattr("attrs") {
        attrs.set_item("inputs", json_to_py(py, &inputs)?)?;
        attrs.set_item("line", json_to_py(py, &line_json(&line))?)?;
    }
    Ok(table)
}
