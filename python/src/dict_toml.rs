//! Python dictionaries and lists → TOML text, which glint's own parser then reads: a scene
//! given as a dictionary is checked exactly as a file is, with the same messages.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
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
