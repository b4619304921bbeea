//! Sane sizes: a job whose grid, memory or output would be unreasonably large is refused
//! before it starts, with the estimate and the flag that allows it (`--allow-large`).
//!
//! The estimates are deliberately rough (a CSV number is taken as 22 bytes); they exist to
//! catch a mistyped `1e11`, not to budget a job to the byte.

use anyhow::{Result, bail};
use vibrotribo::study::limits::{self, SizeError};

/// Largest estimated output written without `--allow-large`: 20 GiB.
pub const MAX_OUTPUT_BYTES: f64 = vibrotribo::study::limits::MAX_OUTPUT_BYTES;

/// Largest estimated memory used without `--allow-large`: 4 GiB.
pub const MAX_MEMORY_BYTES: f64 = vibrotribo::study::limits::MAX_MEMORY_BYTES;

/// Bytes in a GiB.
pub const GIB: f64 = vibrotribo::study::limits::GIB;

/// Bytes of one number written to a CSV file (estimate).
pub const CSV_NUMBER_BYTES: f64 = vibrotribo::study::limits::CSV_NUMBER_BYTES;

/// Refuses a grid of `points` points (named `what`, e.g. "--steps") above [`limits::MAX_GRID_POINTS`] (10⁷);
/// this limit holds even with `--allow-large`.
pub fn check_grid(what: &str, points: f64) -> Result<()> {
    if let Err(e) = limits::check_grid(what, points) {
        bail!("{e}; split the job into several (e.g. --shard) or use a coarser grid");
    }
    Ok(())
}

/// Refuses an estimated `bytes` of output (what, e.g. "trajectory.csv") above
/// [`MAX_OUTPUT_BYTES`] unless `allow`.
pub fn check_output(what: &str, bytes: f64, allow: bool) -> Result<()> {
    if bytes > MAX_OUTPUT_BYTES && !allow {
        bail!(
            "{what} would be about {:.1} GiB (limit {:.0} GiB without --allow-large); \
             lower run.samples_per_period or the number of periods, or pass --allow-large",
            bytes / GIB,
            MAX_OUTPUT_BYTES / GIB
        );
    }
    Ok(())
}

/// Refuses an estimated `bytes` of memory (for `what`) above [`MAX_MEMORY_BYTES`] unless
/// `allow` (the library's check, in the command line's words).
pub fn check_memory(what: &str, bytes: f64, allow: bool) -> Result<()> {
    match limits::check_memory(what, bytes, allow) {
        Ok(()) => Ok(()),
        Err(SizeError::Memory { what, bytes }) => bail!(
            "{what} would need about {:.1} GiB of memory (limit {:.0} GiB without --allow-large); \
             ask for less (fewer periods or points), or pass --allow-large",
            bytes / GIB,
            MAX_MEMORY_BYTES / GIB
        ),
        Err(other) => bail!("{other}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_name_the_problem() {
        assert!(check_grid("--steps", 1e6).is_ok());
        let e = check_grid("--steps", 1e11).unwrap_err().to_string();
        assert!(e.contains("--steps") && e.contains("1.000e11"), "{e}");
        assert!(check_output("trajectory.csv", 1e12, true).is_ok());
        let e = check_output("trajectory.csv", 1e12, false)
            .unwrap_err()
            .to_string();
        assert!(e.contains("trajectory.csv") && e.contains("--allow-large"), "{e}");
        assert!(check_memory("x", 1e12, false).is_err());
    }
}
