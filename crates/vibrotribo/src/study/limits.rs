//! Sane sizes: a job whose grid or memory would be unreasonably large is refused before it
//! starts, with the estimate and the limit, by every door (the command line's
//! `--allow-large`, Python's `allow_large=True`).
//!
//! The estimates are deliberately rough (a CSV number is taken as 22 bytes, a number held in
//! memory as 8); they exist to catch a mistyped `1e11`, not to budget a job to the byte.

use thiserror::Error;

use crate::study::{PointOptions, RunSpec, SettleMode};

/// Bytes in a GiB.
pub const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// Most points of one sweep, map or basin grid (their values are held in memory): 10⁷.
pub const MAX_GRID_POINTS: f64 = 1e7;

/// Largest estimated output written without being allowed: 20 GiB.
pub const MAX_OUTPUT_BYTES: f64 = 20.0 * GIB;

/// Largest estimated memory used without being allowed: 4 GiB.
pub const MAX_MEMORY_BYTES: f64 = 4.0 * GIB;

/// Bytes of one number written to a CSV file (estimate).
pub const CSV_NUMBER_BYTES: f64 = 22.0;

/// A job refused for its size.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SizeError {
    /// More grid points than [`MAX_GRID_POINTS`] (a limit that holds even when large jobs
    /// are allowed).
    #[error("{what} asks for {points:.3e} grid points, more than the limit of {MAX_GRID_POINTS:.0e}")]
    Grid {
        /// What sets the grid (an option's name).
        what: String,
        /// The points asked for.
        points: f64,
    },
    /// More estimated memory than [`MAX_MEMORY_BYTES`].
    #[error("{what} would need about {:.1} GiB of memory (limit {:.0} GiB)", bytes / GIB, MAX_MEMORY_BYTES / GIB)]
    Memory {
        /// What needs the memory.
        what: String,
        /// The estimate, bytes.
        bytes: f64,
    },
}

/// Refuses a grid of `points` points (named `what`) above [`MAX_GRID_POINTS`].
pub fn check_grid(what: &str, points: f64) -> Result<(), SizeError> {
    if points > MAX_GRID_POINTS {
        return Err(SizeError::Grid {
            what: what.to_string(),
            points,
        });
    }
    Ok(())
}

/// Refuses an estimated `bytes` of memory (for `what`) above [`MAX_MEMORY_BYTES`] unless
/// `allow`.
pub fn check_memory(what: &str, bytes: f64, allow: bool) -> Result<(), SizeError> {
    if bytes > MAX_MEMORY_BYTES && !allow {
        return Err(SizeError::Memory {
            what: what.to_string(),
            bytes,
        });
    }
    Ok(())
}

/// Bytes a run keeps per excitation period whatever it records: impact counts per contact,
/// the charge solver's period record and the per-period arrays of its summary.
pub fn per_period_bytes(masses: usize, electrical: bool) -> f64 {
    48.0 + 4.0 * masses as f64
        + if electrical {
            80.0 + 2.0 * CSV_NUMBER_BYTES
        } else {
            0.0
        }
}

/// Numbers in one sample of a run held in memory: time, positions, velocities, base, gaps,
/// and with a harvester charge, current, voltage, capacitance, open-circuit and storage
/// voltage.
pub fn numbers_per_sample(masses: usize, electrical: bool) -> f64 {
    let n = masses as f64;
    1.0 + 2.0 * n + 1.0 + (n - 1.0) + if electrical { 6.0 } else { 0.0 }
}

/// Estimated memory of a run of `spec` whose samples (`samples_per_period` per period, if
/// `samples`) are held in memory, bytes.
pub fn run_memory_bytes(spec: &RunSpec, samples_per_period: u64, samples: bool) -> f64 {
    let n = spec.chain.len();
    let electrical = spec.harvester.is_some();
    let periods = spec.periods as f64;
    let mut bytes = periods * per_period_bytes(n, electrical);
    if samples {
        let rows = periods * samples_per_period as f64 + 1.0;
        bytes += rows * numbers_per_sample(n, electrical) * 8.0;
    }
    bytes
}

/// Estimated memory of one point of a sweep, map or basin grid with `options` on a chain of
/// `masses` masses (its periods before and in the recorded window), bytes.
pub fn point_memory_bytes(options: &PointOptions, masses: usize) -> f64 {
    let before = match &options.settle {
        SettleMode::Auto(a) => a.cap_periods.max(options.transient_periods),
        SettleMode::Fixed => options.transient_periods,
    };
    (before + options.recorded_periods) as f64 * (8.0 * masses as f64 + 96.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_name_the_problem() {
        assert!(check_grid("steps", 1e6).is_ok());
        let e = check_grid("steps", 1e11).unwrap_err().to_string();
        assert!(e.contains("steps") && e.contains("1.000e11"), "{e}");
        assert!(check_memory("x", 1e12, true).is_ok());
        let e = check_memory("200000 periods", 5.0 * GIB, false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("200000 periods") && e.contains("5.0 GiB"), "{e}");
    }
}
