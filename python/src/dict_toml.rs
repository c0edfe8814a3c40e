//! Python dictionaries and lists ↔ TOML: a scene given as a dictionary is written out as TOML
//! text, which glint's own parser then reads, so it is checked exactly as a file is, with the
//! same messages; a scene's TOML is read back as dictionaries for editing.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use pyo3::IntoPyObjectExt;
use toml::{Table, Value};

/// Deeper nesting than any scene has: a self-referencing list would otherwise recurse forever.
const MAX_DEPTH: usize = 32;

/// The TOML text of `scene`, a dictionary of the scene file's tables.
pub fn to_toml_text(scene: &Bound<'_, PyAny>) -> PyResult<String> {
    let Value::Table(table) = to_value(scene, "scene", 0)? else {
        return Err(PyValueError::new_err(
            "load_dict: the scene must be a dict (the TOML file's tables)",
        ));
    };
    toml::to_string(&table).map_err(|e| PyValueError::new_err(format!("load_dict: {e}")))
}

fn to_value(obj: &Bound<'_, PyAny>, at: &str, depth: usize) -> PyResult<Value> {
    if depth > MAX_DEPTH {
        return Err(PyValueError::new_err(format!(
            "load_dict: {at}: nested more than {MAX_DEPTH} levels deep"
        )));
    }
    // bool before int: Python's bool is an int.
    if obj.is_instance_of::<PyBool>() {
        return Ok(Value::Boolean(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        let v: i64 = obj.extract().map_err(|_| {
            PyValueError::new_err(format!(
                "load_dict: {at}: {obj} does not fit a 64-bit integer"
            ))
        })?;
        return Ok(Value::Integer(v));
    }
    if obj.is_instance_of::<PyFloat>() {
        return Ok(Value::Float(obj.extract()?));
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(Value::String(obj.extract()?));
    }
    if obj.is_instance_of::<PyDict>() {
        let mut table = Table::new();
        for (key, value) in obj.extract::<Bound<'_, PyDict>>()?.iter() {
            let key: String = key.extract().map_err(|_| {
                PyValueError::new_err(format!("load_dict: {at}: key {key} is not a string"))
            })?;
            let value = to_value(&value, &format!("{at}.{key}"), depth + 1)?;
            table.insert(key, value);
        }
        return Ok(Value::Table(table));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        let mut items = Vec::new();
        for (i, item) in obj.try_iter()?.enumerate() {
            items.push(to_value(&item?, &format!("{at}[{i}]"), depth + 1)?);
        }
        return Ok(Value::Array(items));
    }
    // NumPy arrays and scalars (vertices, a colour): their Python equivalents.
    if obj.hasattr("tolist")? {
        let plain = obj.call_method0("tolist")?;
        if !plain.is(obj) {
            return to_value(&plain, at, depth + 1);
        }
    }
    Err(PyValueError::new_err(format!(
        "load_dict: {at}: a {} cannot be written in TOML (use dict, list, str, int, float or bool)",
        obj.get_type().name()?
    )))
}

/// TOML text as Python values: tables as dicts, arrays as lists, date-times as strings.
pub fn from_toml_text<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    let table: Table = toml::from_str(text)
        .map_err(|e| PyValueError::new_err(format!("TOML error: {}", e.message().trim_end())))?;
    from_value(py, &Value::Table(table))
}

fn from_value<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    match value {
        Value::String(s) => s.into_bound_py_any(py),
        Value::Integer(i) => i.into_bound_py_any(py),
        Value::Float(f) => f.into_bound_py_any(py),
        Value::Boolean(b) => b.into_bound_py_any(py),
        Value::Datetime(d) => d.to_string().into_bound_py_any(py),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(from_value(py, item)?)?;
            }
            Ok(list.into_any())
        }
        Value::Table(table) => {
            let dict = PyDict::new(py);
            for (key, item) in table {
                dict.set_item(key, from_value(py, item)?)?;
            }
            Ok(dict.into_any())
        }
    }
}
