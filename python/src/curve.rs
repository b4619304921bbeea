//! `vibrotribo.curve`: a bifurcation followed in two configuration keys
//! ([`vibrotribo::curve::curve_config`]), as `vibrotribo curve` computes it.

use numpy::{Complex64, PyArray1, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use vibrotribo::curve::{CurveConfigError, CurveConfigOptions, CurveRequest, curve_config, curve_powers};
use vibrotribo::orbits::OrbitError;
use vibrotribo::orbits::curve::{Codim2Kind, CurveEnd, CurveError, CurveKind, CurveOptions, CurvePoint};

use crate::config::{config_error, config_of};
use crate::convert::{array1, array2};
use crate::orbits::OrbitNotFound;

fn error(e: CurveConfigError) -> PyErr {
    match e {
        CurveConfigError::Value { source, .. } => config_error(source),
        CurveConfigError::SameKey(_) | CurveConfigError::Window(_) => PyValueError::new_err(e.to_string()),
        CurveConfigError::Curve(CurveError::Param(_) | CurveError::UnknownKind(_)) => {
            PyValueError::new_err(e.to_string())
        }
        CurveConfigError::FirstOrbit {
            source: OrbitError::Param(_) | OrbitError::ZeroPeriod,
            ..
        } => PyValueError::new_err(e.to_string()),
        other => OrbitNotFound::new_err(other.to_string()),
    }
}

/// The points of a curve as arrays.
fn points_to_py<'py>(py: Python<'py>, points: &[CurvePoint], n: usize) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let column = |f: &dyn Fn(&CurvePoint) -> f64| array1(py, points.iter().map(f).collect());
    let flat = |f: &dyn Fn(&CurvePoint) -> &[f64]| -> Vec<f64> {
        points.iter().flat_map(|p| f(p).to_vec()).collect()
    };
    d.set_item("parameter", column(&|p| p.parameter))?;
    d.set_item("parameter2", column(&|p| p.parameter2))?;
    d.set_item("x", array2(py, flat(&|p| &p.state.positions), n)?)?;
    d.set_item("v", array2(py, flat(&|p| &p.state.velocities), n)?)?;
    let m: Vec<Complex64> = points
        .iter()
        .flat_map(|p| p.multipliers.iter().map(|c| Complex64::new(c.re, c.im)))
        .collect();
    let rows = points.len();
    d.set_item(
        "multipliers",
        PyArray1::from_vec(py, m).reshape([rows, if rows == 0 { 0 } else { 2 * n }])?,
    )?;
    d.set_item("condition", column(&|p| p.condition))?;
    d.set_item("gap_minimum_m", column(&|p| p.gap_minimum.unwrap_or(f64::NAN)))?;
    d.set_item(
        "impacts_per_period",
        array2(
            py,
            flat(&|p| &p.impacts_per_period),
            points.first().map_or(n - 1, |p| p.impacts_per_period.len()),
        )?,
    )?;
    d.set_item("arclength", column(&|p| p.arclength))?;
    Ok(d)
}

fn end_to_py<'py>(py: Python<'py>, end: &CurveEnd) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    match end {
        CurveEnd::RangeEnd { parameter2 } => {
            d.set_item("reason", "range_end")?;
            d.set_item("parameter2", parameter2)?;
        }
        CurveEnd::MaxPoints => d.set_item("reason", "max_points")?,
        CurveEnd::StepFloor {
            parameter,
            parameter2,
            reason,
        } => {
            d.set_item("reason", "step_floor")?;
            d.set_item("parameter", parameter)?;
            d.set_item("parameter2", parameter2)?;
            d.set_item("failure", reason.to_string())?;
        }
        CurveEnd::SequenceChange => d.set_item("reason", "sequence_change")?,
        CurveEnd::Degenerate {
            parameter,
            parameter2,
        } => {
            d.set_item("reason", "degenerate")?;
            d.set_item("parameter", parameter)?;
            d.set_item("parameter2", parameter2)?;
        }
        other => d.set_item("reason", format!("{other:?}"))?,
    }
    Ok(d)
}

/// Follows a bifurcation in two configuration keys (see the Python `vibrotribo.curve`).
#[pyfunction]
#[pyo3(signature = (config, kind, param, near, param2, from2, to2, *, period = None, window = None, transient = None, max_points = None, mechanics_only = false))]
#[allow(clippy::too_many_arguments)]
pub fn curve<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    kind: String,
    param: String,
    near: f64,
    param2: String,
    from2: f64,
    to2: f64,
    period: Option<u32>,
    window: Option<f64>,
    transient: Option<u32>,
    max_points: Option<usize>,
    mechanics_only: bool,
) -> PyResult<Bound<'py, PyDict>> {
    if period == Some(0) {
        return Err(PyValueError::new_err("period: must be at least 1"));
    }
    if !(near.is_finite() && from2.is_finite() && to2.is_finite()) || from2 == to2 {
        return Err(PyValueError::new_err(format!(
            "near, from2 and to2 must be finite, from2 and to2 different (got {near}, {from2}, {to2})"
        )));
    }
    let kind: CurveKind = kind
        .parse()
        .map_err(|e: CurveError| PyValueError::new_err(e.to_string()))?;
    let base = config_of(config)?;
    base.check_uncoupled("curve").map_err(config_error)?;
    base.check_periodic("continuation of bifurcation curves")
        .map_err(config_error)?;
    let d = CurveConfigOptions::default();
    let options = CurveConfigOptions {
        transient: transient.unwrap_or(d.transient),
        window: window.unwrap_or(d.window),
        curve: CurveOptions {
            max_points: max_points.unwrap_or(d.curve.max_points),
            ..d.curve
        },
    };
    let request = CurveRequest {
        kind,
        key: param,
        near,
        key2: param2,
        from2,
        to2,
        period,
    };
    let r = py.detach(|| curve_config(&base, &request, &options));
    py.check_signals()?;
    let r = r.map_err(error)?;
    let n = base.chain().len();
    let out = PyDict::new(py);
    out.set_item("kind", r.curve.kind.name())?;
    out.set_item("param", r.key.as_str())?;
    out.set_item("param2", r.key2.as_str())?;
    out.set_item("period", r.curve.period)?;
    out.set_item("contact", r.curve.contact.map(|k| k + 1))?;
    out.set_item("located", r.located.parameter)?;
    out.set_item("located_precision", r.located.precision)?;
    let points = points_to_py(py, &r.curve.points, n)?;
    let power = if mechanics_only {
        vec![f64::NAN; r.curve.points.len()]
    } else {
        py.detach(|| curve_powers(&base, &r.key, &r.key2, &r.curve))
    };
    points.set_item("average_power_w", array1(py, power))?;
    out.set_item("points", points)?;
    let codim2 = PyList::empty(py);
    for p in &r.curve.codim2 {
        let e = PyDict::new(py);
        e.set_item("kind", p.kind.name())?;
        e.set_item(
            "contact",
            match p.kind {
                Codim2Kind::Grazing { contact } => Some(contact + 1),
                _ => None,
            },
        )?;
        e.set_item("parameter", p.point.parameter)?;
        e.set_item("parameter2", p.point.parameter2)?;
        e.set_item("precision", p.precision)?;
        let m: Vec<Complex64> = p
            .point
            .multipliers
            .iter()
            .map(|c| Complex64::new(c.re, c.im))
            .collect();
        e.set_item("multipliers", PyArray1::from_vec(py, m))?;
        codim2.append(e)?;
    }
    out.set_item("codim2", codim2)?;
    out.set_item("end", end_to_py(py, &r.curve.end)?)?;
    Ok(out)
}
