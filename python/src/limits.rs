//! The command line's size limits ([`vibrotribo::study::limits`]) as Python exceptions: a
//! grid above the limit is a `ValueError` naming the argument, a run whose estimated memory
//! is above the limit a `MemoryError` naming what needs it and `allow_large=True` — raised
//! before anything is allocated, so that a mistyped size never kills the kernel.

use pyo3::exceptions::{PyMemoryError, PyValueError};
use pyo3::prelude::*;
use vibrotribo::study::limits::{self, SizeError};

fn size_error(e: SizeError) -> PyErr {
    match e {
        SizeError::Memory { .. } => PyMemoryError::new_err(format!(
            "{e}; use fewer periods or samples, or pass allow_large=True"
        )),
        other => PyValueError::new_err(format!("{other}; split the job or use a coarser grid")),
    }
}

/// Refuses a grid of `points` points set by the argument `what`.
pub fn check_grid(what: &str, points: f64) -> PyResult<()> {
    limits::check_grid(what, points).map_err(size_error)
}

/// Refuses an estimated `bytes` of memory (for `what`) unless `allow`.
pub fn check_memory(what: &str, bytes: f64, allow: bool) -> PyResult<()> {
    limits::check_memory(what, bytes, allow).map_err(size_error)
}
