//! JSON values to Python objects, and tables of JSON records to columns: numpy arrays, in a
//! pandas DataFrame when pandas can be imported.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use pyo3::IntoPyObjectExt;
use serde_json::Value;

/// The Python object of a JSON value: `None`, `bool`, `int`, `float`, `str`, `list`, `dict`
/// (what `json.loads` gives for the same text).
pub fn json_to_py<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    match value {
        Value::Null => Ok(py.None().into_bound(py)),
        Value::Bool(b) => b.into_bound_py_any(py),
        Value::Number(n) => {
            if let Some(i) = n.as_i64() {
                i.into_bound_py_any(py)
            } else if let Some(u) = n.as_u64() {
                u.into_bound_py_any(py)
            } else {
                n.as_f64().unwrap_or(f64::NAN).into_bound_py_any(py)
            }
        }
        Value::String(s) => s.into_bound_py_any(py),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(json_to_py(py, item)?)?;
            }
            Ok(list.into_any())
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (key, item) in map {
                dict.set_item(key, json_to_py(py, item)?)?;
            }
            Ok(dict.into_any())
        }
    }
}

/// The JSON value of a Python object made of `None`, `bool`, `int`, `float`, `str`, lists,
/// tuples and dicts with string keys (a dict of a cantilever file, say); floats are kept
/// exactly (no trip through text). Anything else is a `TypeError` naming its type.
pub fn py_to_json(object: &Bound<'_, PyAny>) -> PyResult<Value> {
    if object.is_none() {
        return Ok(Value::Null);
    }
    if let Ok(b) = object.downcast::<pyo3::types::PyBool>() {
        return Ok(Value::Bool(b.is_true()));
    }
    if object.is_instance_of::<pyo3::types::PyInt>() {
        if let Ok(i) = object.extract::<i64>() {
            return Ok(Value::from(i));
        }
        return Ok(Value::from(object.extract::<u64>()?));
    }
    if let Ok(f) = object.downcast::<pyo3::types::PyFloat>() {
        return Ok(serde_json::Number::from_f64(f.value()).map_or(Value::Null, Value::Number));
    }
    if let Ok(s) = object.downcast::<pyo3::types::PyString>() {
        return Ok(Value::String(s.to_cow()?.into_owned()));
    }
    if let Ok(dict) = object.downcast::<PyDict>() {
        let mut map = serde_json::Map::new();
        for (key, item) in dict.iter() {
            let key: String = key
                .extract()
                .map_err(|_| pyo3::exceptions::PyTypeError::new_err("dict keys must be strings"))?;
            map.insert(key, py_to_json(&item)?);
        }
        return Ok(Value::Object(map));
    }
    if object.is_instance_of::<PyList>() || object.is_instance_of::<pyo3::types::PyTuple>() {
        let items: Vec<Value> = object
            .try_iter()?
            .map(|item| py_to_json(&item?))
            .collect::<PyResult<_>>()?;
        return Ok(Value::Array(items));
    }
    if let Ok(f) = object.extract::<f64>() {
        // numpy scalars and other numbers.
        return Ok(serde_json::Number::from_f64(f).map_or(Value::Null, Value::Number));
    }
    Err(pyo3::exceptions::PyTypeError::new_err(format!(
        "cannot use a {} as JSON data (allowed: None, bool, int, float, str, list, tuple, dict)",
        object.get_type().name()?
    )))
}

/// The numpy array of `(0..n).map(value)`: `int64` when every value is an integer, `float64`
/// when every value is a number or `null` (`null` as NaN), `bool` when every value is a
/// boolean, else an array of Python objects (strings, lists, dicts).
fn column<'py>(
    py: Python<'py>,
    numpy: &Bound<'py, PyModule>,
    values: &[&Value],
) -> PyResult<Bound<'py, PyAny>> {
    let all = |test: fn(&Value) -> bool| values.iter().all(|v| test(v));
    if !values.is_empty() && all(|v| v.is_i64() || v.is_u64()) {
        let items: Vec<i64> = values.iter().filter_map(|v| v.as_i64()).collect();
        return numpy.call_method1("array", (items, "int64"));
    }
    if !values.is_empty() && all(|v| v.is_number() || v.is_null()) {
        let items: Vec<f64> = values
            .iter()
            .map(|v| v.as_f64().unwrap_or(f64::NAN))
            .collect();
        return numpy.call_method1("array", (items, "float64"));
    }
    if !values.is_empty() && all(Value::is_boolean) {
        let items: Vec<bool> = values.iter().filter_map(|v| v.as_bool()).collect();
        return numpy.call_method1("array", (items, "bool"));
    }
    let array = numpy.call_method1("empty", (values.len(), "object"))?;
    for (i, value) in values.iter().enumerate() {
        array.set_item(i, json_to_py(py, value)?)?;
    }
    Ok(array)
}

/// The records (JSON objects with the same keys) as columns: a pandas DataFrame if pandas can
/// be imported, else a dict of numpy arrays; one column per key, the keys of `order` first in
/// that order, then a record's `harmonics` list as the columns `harmonic_<n>_amplitude_nm` and
/// `harmonic_<n>_phase_deg` for `n = 1..N` (as the CLI's CSV writes them; NaN where a record
/// has fewer), then the other keys alphabetically.
pub fn records_to_table<'py>(
    py: Python<'py>,
    records: &[Value],
    order: &[&str],
) -> PyResult<Bound<'py, PyAny>> {
    let numpy = py.import("numpy")?;
    let mut keys: Vec<String> = order.iter().map(|k| k.to_string()).collect();
    let harmonic_count = records
        .first()
        .and_then(|r| r["harmonics"].as_array())
        .map_or(0, Vec::len);
    if let Some(Value::Object(first)) = records.first() {
        let mut rest: Vec<String> = first
            .keys()
            .filter(|k| !order.contains(&k.as_str()) && k.as_str() != "harmonics")
            .cloned()
            .collect();
        rest.sort();
        keys.extend(rest);
    }
    let columns = PyDict::new(py);
    for key in &keys[..order.len()] {
        let values: Vec<&Value> = records.iter().map(|r| &r[key.as_str()]).collect();
        columns.set_item(key, column(py, &numpy, &values)?)?;
    }
    for n in 1..=harmonic_count {
        for (name, field) in [
            (format!("harmonic_{n}_amplitude_nm"), "amplitude_nm"),
            (format!("harmonic_{n}_phase_deg"), "phase_deg"),
        ] {
            let values: Vec<f64> = records
                .iter()
                .map(|r| r["harmonics"][n - 1][field].as_f64().unwrap_or(f64::NAN))
                .collect();
            columns.set_item(name, float_array(py, values)?)?;
        }
    }
    for key in &keys[order.len()..] {
        let values: Vec<&Value> = records.iter().map(|r| &r[key.as_str()]).collect();
        columns.set_item(key, column(py, &numpy, &values)?)?;
    }
    match py.import("pandas") {
        Ok(pandas) => pandas.call_method1("DataFrame", (columns,)),
        Err(_) => Ok(columns.into_any()),
    }
}

/// A numpy `float64` array of `values`.
pub fn float_array<'py>(py: Python<'py>, values: Vec<f64>) -> PyResult<Bound<'py, PyAny>> {
    py.import("numpy")?
        .call_method1("array", (values, "float64"))
}

/// The `__reduce__` value of a class that rebuilds itself from its dict: `(T.from_dict,
/// (state,))`, so that pickling carries the object as `state` (its `to_dict()`).
pub fn reduce_by_from_dict<'py, T: pyo3::PyTypeInfo>(
    py: Python<'py>,
    state: Bound<'py, PyAny>,
) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
    let rebuild = py.get_type::<T>().getattr("from_dict")?;
    pyo3::types::PyTuple::new(
        py,
        [rebuild, pyo3::types::PyTuple::new(py, [state])?.into_any()],
    )
}
