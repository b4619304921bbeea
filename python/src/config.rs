//! `vibrotribo.Config`: a configuration read by the library ([`vibrotribo::config::Config`])
//! from a TOML file, a dict shaped like one, and keyword overrides; Python values to TOML
//! values and back; the library's errors as Python exceptions.

use std::path::PathBuf;

use pyo3::exceptions::{PyFileNotFoundError, PyKeyError, PyOSError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use toml::{Table, Value};
use vibrotribo::config::{Config, ConfigError, DERIVED_KEYS, did_you_mean, known_keys};
use vibrotribo::excitation::WorkBudget;

use crate::convert::json_to_py;
use crate::interrupt::interruptibly;

/// The exception for a configuration error: `KeyError` for an unknown key, `OSError` for an
/// unreadable file, `ValueError` for anything else (a bad value, bad TOML). The message
/// names the key (or the file).
pub fn config_error(e: ConfigError) -> PyErr {
    fn innermost(e: &ConfigError) -> &ConfigError {
        match e {
            ConfigError::Setting { error, .. } => innermost(error),
            other => other,
        }
    }
    let message = e.to_string();
    match innermost(&e) {
        ConfigError::UnknownKey { key, .. } => PyKeyError::new_err(unknown_key_message(key)),
        ConfigError::Io { path, .. } if !std::path::Path::new(path).exists() => {
            PyFileNotFoundError::new_err(message)
        }
        ConfigError::Io { .. } => PyOSError::new_err(message),
        _ => PyValueError::new_err(message),
    }
}

/// "unknown parameter `key`", with the closest keys ("did you mean …?", the library's
/// [`did_you_mean`], as the command line says it).
pub fn unknown_key_message(key: &str) -> String {
    format!(
        "unknown parameter `{key}`{} (Config.keys() lists every key)",
        did_you_mean(key)
    )
}

/// `v` without its `null` entries (tables emptied by that dropped too).
fn without_nulls(v: &serde_json::Value) -> Option<serde_json::Value> {
    match v {
        serde_json::Value::Null => None,
        serde_json::Value::Object(o) => {
            let kept: serde_json::Map<String, serde_json::Value> = o
                .iter()
                .filter_map(|(k, x)| without_nulls(x).map(|x| (k.clone(), x)))
                .collect();
            (!kept.is_empty()).then_some(serde_json::Value::Object(kept))
        }
        other => Some(other.clone()),
    }
}

/// A keyword argument's name as a configuration key: `__` stands for `.`
/// (`excitation__omega_ratio` is `excitation.omega_ratio`); names holding a `.` or `[`
/// (passed as `**{"oscillator.gaps[1]": 0.03}`) and derived keys (`mass_ratio`) are used as
/// they are.
pub fn key_of(name: &str) -> String {
    name.replace("__", ".")
}

/// A Python value as a TOML value: bool, int, float, str, a list or tuple (or a numpy array)
/// of values, a dict of values; numpy scalars as their Python values. `key` names the value
/// in errors.
pub fn to_toml(v: &Bound<'_, PyAny>, key: &str) -> PyResult<Value> {
    if v.is_none() {
        return Err(PyValueError::new_err(format!(
            "`{key}` = None: a configuration value cannot be None (leave the key out for its default)"
        )));
    }
    if v.is_instance_of::<PyBool>() {
        return Ok(Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        let i: i64 = v
            .extract()
            .map_err(|_| PyValueError::new_err(format!("`{key}` = {v}: the integer is too large")))?;
        return Ok(Value::Integer(i));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(Value::String(v.extract()?));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        return Ok(Value::Table(to_table(d, Some(key))?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut out = Vec::new();
        for (i, item) in v.try_iter()?.enumerate() {
            out.push(to_toml(&item?, &format!("{key}[{i}]"))?);
        }
        return Ok(Value::Array(out));
    }
    // numpy arrays and scalars: their Python equivalent.
    if v.hasattr("tolist")? {
        return to_toml(&v.call_method0("tolist")?, key);
    }
    Err(PyValueError::new_err(format!(
        "`{key}`: a {} cannot be a configuration value (use a number, a string, a bool, a list or a dict)",
        v.get_type().name()?
    )))
}

/// A dict shaped like a configuration file (`{"oscillator": {"masses": [...]}}`) as a TOML
/// table; `prefix` is the key of the dict itself (`None` at the top).
pub fn to_table(d: &Bound<'_, PyDict>, prefix: Option<&str>) -> PyResult<Table> {
    let mut table = Table::new();
    for (k, v) in d.iter() {
        let name: String = k
            .extract()
            .map_err(|_| PyTypeError::new_err(format!("configuration keys must be strings, got {k}")))?;
        let key = match prefix {
            Some(p) => format!("{p}.{name}"),
            None => name.clone(),
        };
        table.insert(name, to_toml(&v, &key)?);
    }
    Ok(table)
}

/// A TOML value as a Python value (tables as dicts, arrays as lists, dates as strings).
pub fn from_toml<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Boolean(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Integer(i) => i.into_pyobject(py)?.into_any(),
        Value::Float(x) => PyFloat::new(py, *x).into_any(),
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Datetime(d) => PyString::new(py, &d.to_string()).into_any(),
        Value::Array(a) => {
            let items = a.iter().map(|x| from_toml(py, x)).collect::<PyResult<Vec<_>>>()?;
            PyList::new(py, items)?.into_any()
        }
        Value::Table(t) => table_to_dict(py, t)?.into_any(),
    })
}

/// A TOML table as a dict.
pub fn table_to_dict<'py>(py: Python<'py>, t: &Table) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in t {
        d.set_item(k, from_toml(py, v)?)?;
    }
    Ok(d)
}

/// A configuration: the paper's default case, a TOML file, or a dict shaped like one, with
/// keys overridden by keyword arguments.
///
///     Config()                                          # the paper's default case
///     Config("configs/chatter.toml")                    # a TOML file (str or path)
///     Config({"oscillator": {"masses": [0.05, 0.15, 0.05]}, "run": {"periods": 200}})
///     Config("configs/chatter.toml", excitation__omega_ratio=0.6)
///     Config(mass_ratio=3, **{"oscillator.gaps[1]": 0.03})
///
/// Keys are those of the TOML file, `section.name` (`excitation.omega_ratio`,
/// `harvester.load_resistance`, one element as `oscillator.gaps[1]`), and the derived keys
/// (`mass_ratio`, `gap_ratio`, `gap`, `omega_ratio`, `frequency_hz`, `amplitude`,
/// `restitution`; see `Config.keys()`). As keyword arguments a `.` is written `__`
/// (`excitation__omega_ratio=0.6`), or the key is passed as it is with `**{...}`. Overrides
/// are applied in order and the whole is validated once. Units are SI (kg, m, s, N/m, Ω, F).
///
/// An unknown key raises `KeyError` (with the closest keys: "did you mean …?"), a bad value
/// `ValueError`, a missing file `FileNotFoundError`; each message names the key or the file.
///
/// A `Config` is an immutable, hashable, read-only mapping of its effective values:
/// `cfg["excitation.amplitude"]` (the default where the file leaves a key out),
/// `cfg["oscillator.gaps[1]"]`, derived keys (`cfg["mass_ratio"]`), None for an optional
/// key left absent; its keys are `Config.keys()`; `to_dict()` the values nested like the
/// file. Two configurations are equal when
/// their effective values are. `with_(**changes)` (or `replace`) returns a changed copy,
/// `without(*keys)` a copy with keys back at their defaults.
///
/// A random excitation costlier to build than 10⁹ harmonic evaluations is refused
/// (`ValueError` with its harmonics and intervals) unless `allow_large=True`, the command
/// line's `--allow-large`; the configurations derived from this one (and a pickled copy)
/// keep the setting, which is not a key and leaves equality alone. Ctrl-C stops a build with
/// `KeyboardInterrupt`.
#[pyclass(module = "vibrotribo", name = "Config", frozen)]
#[derive(Clone)]
pub struct PyConfig {
    /// The library's configuration.
    pub inner: Config,
}

impl PyConfig {
    /// The configuration `source` stands for (see [`config_of`]), its base motion built
    /// within the documented limit unless `allow_large` (or the source is a `Config` made
    /// with `allow_large=True`), the build stopped by Ctrl-C ([`read_within`]).
    fn read(py: Python<'_>, source: Option<&Bound<'_, PyAny>>, allow_large: bool) -> PyResult<Config> {
        let Some(s) = source.filter(|s| !s.is_none()) else {
            return Ok(keeping(Config::default(), allow_large));
        };
        if let Ok(c) = s.cast::<PyConfig>() {
            let c = c.get().inner.clone();
            let large = allow_large || c.budget().allow_large;
            return Ok(keeping(c, large));
        }
        if let Ok(d) = s.cast::<PyDict>() {
            let table = to_table(d, None)?;
            return read_within(py, allow_large, move |b| Config::from_table_within(table, b));
        }
        if let Ok(path) = s.extract::<PathBuf>() {
            return read_within(py, allow_large, move |b| Config::from_path_within(&path, b));
        }
        Err(PyTypeError::new_err(format!(
            "Config takes a path to a TOML file, a dict or a Config, not a {}",
            s.get_type().name()?
        )))
    }

    /// `config` with the keyword overrides applied (in order, validated as a whole), within
    /// `config`'s budget.
    pub fn overridden(
        py: Python<'_>,
        config: Config,
        overrides: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Config> {
        let Some(o) = overrides else { return Ok(config) };
        let mut pairs = Vec::new();
        for (k, v) in o.iter() {
            let key = key_of(&k.extract::<String>()?);
            let value = to_toml(&v, &key)?;
            pairs.push((key, value));
        }
        let large = config.budget().allow_large;
        read_within(py, large, move |budget| {
            let mut config = config;
            config.set_budget(budget.clone());
            config.set_all(pairs.iter().map(|(k, v)| (k.as_str(), v.clone())))?;
            Ok(config)
        })
    }
}

/// `config` whose later base-motion builds (of the configurations derived from it) allow
/// large ones if `allow_large`.
fn keeping(mut config: Config, allow_large: bool) -> Config {
    config.set_budget(WorkBudget {
        allow_large,
        stop: None,
    });
    config
}

/// `read` (a configuration's read or change, which may build a random base motion) run with
/// a budget that allows large builds if `allow_large`, on a worker thread stopped by Ctrl-C
/// (`KeyboardInterrupt`, [`interruptibly`]); the configuration keeps the budget's limit for
/// the configurations derived from it.
fn read_within<F>(py: Python<'_>, allow_large: bool, read: F) -> PyResult<Config>
where
    F: FnOnce(&WorkBudget) -> Result<Config, ConfigError> + Send,
{
    let read = interruptibly(py, move |flag| {
        read(&WorkBudget {
            allow_large,
            stop: Some(std::sync::Arc::clone(flag)),
        })
    })?;
    Ok(keeping(read.map_err(config_error)?, allow_large))
}

impl PyConfig {
    /// Whether `key` names a key of the schema (with or without an element) or a derived one.
    fn known(&self, key: &str) -> bool {
        let base = key.split('[').next().unwrap_or(key);
        known_keys().iter().any(|k| k == base) || DERIVED_KEYS.iter().any(|(k, _)| *k == base)
    }

    /// The effective value of `key`: a key of the file, an element `name[i]`, or a derived
    /// key (`mass_ratio` m₂/m₁, `mass_ratio_m2_fixed` the same, `gap_ratio` δ₂/δ₁, `gap`
    /// the common gap if all are equal, `omega_ratio`, `frequency_hz`, `amplitude`,
    /// `restitution`).
    fn value(&self, key: &str) -> Option<serde_json::Value> {
        use serde_json::json;
        let chain = self.inner.chain();
        let derived = match key {
            "mass_ratio" | "mass_ratio_m2_fixed" if chain.masses.len() > 1 => {
                Some(json!(chain.masses[1] / chain.masses[0]))
            }
            "gap_ratio" if chain.gaps.len() > 1 => Some(json!(chain.gaps[1] / chain.gaps[0])),
            "gap" => chain
                .gaps
                .first()
                .filter(|g| chain.gaps.iter().all(|x| x == *g))
                .map(|g| json!(g)),
            "omega_ratio" => Some(json!(chain.omega_ratio())),
            "frequency_hz" => Some(json!(chain.omega() / std::f64::consts::TAU)),
            "amplitude" => return self.value("excitation.amplitude"),
            "restitution" => return self.value("oscillator.restitution"),
            _ => None,
        };
        if derived.is_some() {
            return derived;
        }
        let (base, index) = match key.split_once('[') {
            Some((b, rest)) => (b, Some(rest.strip_suffix(']')?.parse::<usize>().ok()?)),
            None => (key, None),
        };
        let mut v = self.inner.effective();
        for part in base.split('.') {
            v = v.get(part)?.clone();
        }
        let v = match index {
            Some(i) => v.get(i)?.clone(),
            None => v,
        };
        (!v.is_null()).then_some(v)
    }
}

/// The configuration `obj` stands for (a `Config`, a dict, a path, or `None`: the defaults),
/// to be run: refused, naming the reason, if its base motion cannot drive its chain
/// (`Config::check_runnable`, as the command line refuses it).
pub fn config_of(obj: &Bound<'_, PyAny>) -> PyResult<Config> {
    let config = PyConfig::read(obj.py(), Some(obj), false)?;
    config.check_runnable().map_err(config_error)?;
    Ok(config)
}

/// What pickling a [`PyConfig`] stores: `Config._restore` and its arguments (the table as a
/// dict, and `allow_large`).
type Reduced<'py> = (Bound<'py, PyAny>, (Bound<'py, PyDict>, bool));

#[pymethods]
impl PyConfig {
    #[new]
    #[pyo3(signature = (source=None, /, *, allow_large=false, **overrides))]
    fn new(
        py: Python<'_>,
        source: Option<&Bound<'_, PyAny>>,
        allow_large: bool,
        overrides: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        Ok(PyConfig {
            inner: Self::overridden(py, Self::read(py, source, allow_large)?, overrides)?,
        })
    }

    /// A configuration from TOML text (`allow_large` as for the constructor).
    #[staticmethod]
    #[pyo3(signature = (text, *, allow_large=false))]
    fn from_toml(py: Python<'_>, text: String, allow_large: bool) -> PyResult<Self> {
        Ok(PyConfig {
            inner: read_within(py, allow_large, move |b| Config::from_toml_str_within(&text, b))?,
        })
    }

    /// Whether this configuration's base motion, and those of the configurations derived from
    /// it, may be built past the documented limit of 10⁹ harmonic evaluations (a random
    /// excitation's build): `Config(..., allow_large=True)`, the command line's `--allow-large`.
    #[getter]
    fn allow_large(&self) -> bool {
        self.inner.budget().allow_large
    }

    /// Rebuilds a pickled configuration: its settings and `allow_large`.
    #[staticmethod]
    fn _restore(py: Python<'_>, settings: &Bound<'_, PyDict>, allow_large: bool) -> PyResult<Self> {
        let table = to_table(settings, None)?;
        Ok(PyConfig {
            inner: read_within(py, allow_large, move |b| Config::from_table_within(table, b))?,
        })
    }

    /// A copy with the keyword overrides applied (same keys as the constructor).
    #[pyo3(signature = (**overrides))]
    fn replace(&self, py: Python<'_>, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        Ok(PyConfig {
            inner: Self::overridden(py, self.inner.clone(), overrides)?,
        })
    }

    /// A copy with the keyword overrides applied (the same as `replace`).
    #[pyo3(signature = (**changes))]
    fn with_(&self, py: Python<'_>, changes: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        self.replace(py, changes)
    }

    /// A copy with `keys` (`section.name`, or a whole `section`) removed from the settings:
    /// back at their defaults. A key that is not set is refused (`KeyError`).
    #[pyo3(signature = (*keys))]
    fn without(&self, py: Python<'_>, keys: Vec<String>) -> PyResult<Self> {
        let mut table = self.inner.table().clone();
        for key in &keys {
            let key = key_of(key);
            let parts: Vec<&str> = key.split('.').collect();
            let (last, path) = parts
                .split_last()
                .ok_or_else(|| PyKeyError::new_err("empty key"))?;
            let mut t = &mut table;
            for p in path {
                t = match t.get_mut(*p) {
                    Some(Value::Table(inner)) => inner,
                    _ => {
                        return Err(PyKeyError::new_err(format!(
                            "`{key}` is not set in this configuration"
                        )));
                    }
                };
            }
            if t.remove(*last).is_none() {
                let message = if self.known(&key) {
                    format!("`{key}` is not set in this configuration (it has its default)")
                } else {
                    unknown_key_message(&key)
                };
                return Err(PyKeyError::new_err(message));
            }
        }
        let large = self.inner.budget().allow_large;
        Ok(PyConfig {
            inner: read_within(py, large, move |b| Config::from_table_within(table, b))?,
        })
    }

    /// The effective settings as a dict shaped like the TOML file: every key with its value,
    /// the defaults filled in (optional keys left absent are left out).
    /// `Config(c.to_dict()) == c`.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let v = without_nulls(&self.inner.effective()).unwrap_or(serde_json::json!({}));
        json_to_py(py, &v)
    }

    /// The settings as given: what was read and overridden, shaped like the TOML file (keys
    /// left out are absent; they take their defaults).
    fn settings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        table_to_dict(py, self.inner.table())
    }

    /// The effective value of `key` (a key of the file, an element `name[i]`, or a derived
    /// key; None for an optional key left absent); `KeyError` with the closest keys for an
    /// unknown one.
    fn __getitem__<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyAny>> {
        match self.value(key) {
            Some(v) => json_to_py(py, &v),
            None if key.contains('[') && self.known(key) => Err(PyKeyError::new_err(format!(
                "`{key}`: no such element in this configuration (index out of range)"
            ))),
            None if self.known(key) => Ok(py.None().into_bound(py)),
            None => Err(PyKeyError::new_err(unknown_key_message(key))),
        }
    }

    /// The effective value of `key`, or `default` if it has none or is unknown.
    #[pyo3(signature = (key, default = None))]
    fn get<'py>(
        &self,
        py: Python<'py>,
        key: &str,
        default: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        match self.value(key) {
            Some(v) => json_to_py(py, &v),
            None => Ok(default.unwrap_or_else(|| py.None().into_bound(py))),
        }
    }

    /// Whether `key` is a key of the configuration (of the file, an element of an array
    /// key within its length, or derived).
    fn __contains__(&self, key: &str) -> bool {
        self.known(key) && (!key.contains('[') || self.value(key).is_some())
    }

    /// Every key, as `Config.keys()`: those of the file (`section.name`), then the derived
    /// ones.
    fn __iter__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        PyList::new(py, Self::keys())?
            .into_any()
            .try_iter()
            .map(|i| i.into_any())
    }

    fn __len__(&self) -> usize {
        Self::keys().len()
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<PyConfig>()
            .is_ok_and(|o| o.get().inner.effective() == self.inner.effective())
    }

    fn __hash__(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        self.inner.effective().to_string().hash(&mut h);
        h.finish()
    }

    /// The settings as TOML text.
    fn to_toml(&self) -> PyResult<String> {
        toml::to_string(self.inner.table()).map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// Every key: those of the TOML file (`section.name`), then the derived ones.
    #[staticmethod]
    fn keys() -> Vec<String> {
        let mut k = known_keys();
        k.extend(DERIVED_KEYS.iter().map(|(name, _)| name.to_string()));
        k
    }

    /// Masses m_i, kg (top to bottom).
    #[getter]
    fn masses(&self) -> Vec<f64> {
        self.inner.chain().masses.clone()
    }

    /// Gaps δ_k at rest, m.
    #[getter]
    fn gaps(&self) -> Vec<f64> {
        self.inner.chain().gaps.clone()
    }

    /// Excitation period T, s.
    #[getter]
    fn period_s(&self) -> f64 {
        self.inner.chain().period()
    }

    /// Ω = ω/√(k1/m1).
    #[getter]
    fn omega_ratio(&self) -> f64 {
        self.inner.chain().omega_ratio()
    }

    /// Excitation periods simulated (`run.periods`).
    #[getter]
    fn periods(&self) -> u64 {
        self.inner.run().periods
    }

    /// Periods excluded from statistics (`run.transient_periods`).
    #[getter]
    fn transient_periods(&self) -> u64 {
        self.inner.run().transient()
    }

    fn __repr__(&self) -> String {
        let text = toml::to_string(self.inner.table()).unwrap_or_default();
        if text.trim().is_empty() {
            "Config()  # the paper's default case".into()
        } else {
            format!("Config.from_toml('''\n{}''')", text)
        }
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Reduced<'py>> {
        let py = slf.py();
        Ok((
            slf.get_type().getattr("_restore")?,
            (
                table_to_dict(py, slf.get().inner.table())?,
                slf.get().inner.budget().allow_large,
            ),
        ))
    }
}
