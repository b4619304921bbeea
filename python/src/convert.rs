//! Results as Python objects: JSON values as dicts and lists, columns as numpy arrays.

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyList, PyString};
use vibrotribo::sweep::{Column, Table};

/// A JSON value as a Python value (objects as dicts in their order, numbers as int or float
/// with the same bits).
pub fn json_to_py<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    use serde_json::Value;
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => match (n.as_u64(), n.as_i64(), n.as_f64()) {
            (Some(u), _, _) => u.into_pyobject(py)?.into_any(),
            (None, Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, None, Some(x)) => PyFloat::new(py, x).into_any(),
            _ => return Err(PyValueError::new_err(format!("unrepresentable number {n}"))),
        },
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(a) => {
            let items = a
                .iter()
                .map(|x| json_to_py(py, x))
                .collect::<PyResult<Vec<_>>>()?;
            PyList::new(py, items)?.into_any()
        }
        Value::Object(o) => {
            let d = PyDict::new(py);
            for (k, x) in o {
                d.set_item(k, json_to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// A result as the Python value of its JSON form ([`json_to_py`]): what the command line
/// writes to a file, as dicts and lists.
pub fn serde_to_py<'py, T: serde::Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    let v = serde_json::to_value(value).map_err(|e| PyValueError::new_err(e.to_string()))?;
    json_to_py(py, &v)
}

/// A 1-D float array.
pub fn array1<'py>(py: Python<'py>, v: Vec<f64>) -> Bound<'py, PyAny> {
    PyArray1::from_vec(py, v).into_any()
}

/// A row-major `(rows, cols)` float array from a flat vector of `rows·cols` numbers.
pub fn array2<'py>(py: Python<'py>, v: Vec<f64>, cols: usize) -> PyResult<Bound<'py, PyAny>> {
    let rows = v.len().checked_div(cols).unwrap_or(0);
    let a = Array2::from_shape_vec((rows, cols), v).map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(a.into_pyarray(py).into_any())
}

/// A table as a dict of its columns in order: numbers, integers and flags as numpy arrays
/// (float64, int64, bool), text as a list of str.
pub fn table_to_py<'py>(py: Python<'py>, t: &Table) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, column) in &t.columns {
        let value = match column {
            Column::Float(v) => PyArray1::from_slice(py, v).into_any(),
            Column::Int(v) => PyArray1::from_slice(py, v).into_any(),
            Column::Bool(v) => PyArray1::from_slice(py, v).into_any(),
            Column::Text(v) => PyList::new(py, v)?.into_any(),
        };
        d.set_item(name, value)?;
    }
    Ok(d)
}
