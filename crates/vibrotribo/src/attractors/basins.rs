//! The axes of a basin picture: two initial conditions of the chain
//! (`run.initial_positions[i]`, m, or `run.initial_velocities[i]`, m/s, i 0-based), every
//! node of their grid a start ([`StartRunner`](super::StartRunner)), y outer and x inner.

use thiserror::Error;

/// Transient and recorded periods of a start unless the caller says otherwise.
pub const DEFAULT_START_PERIODS: (u64, u64) = (500, 100);

/// A basin axis that is not an initial condition of the chain.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[non_exhaustive]
pub enum BasinKeyError {
    /// The index is past the chain's last mass.
    #[error("{key}: index {index} out of range (the chain has {masses} masses, 0-based)")]
    OutOfRange {
        /// The key.
        key: String,
        /// Its index.
        index: usize,
        /// Masses of the chain.
        masses: usize,
    },
    /// The key is not an initial condition.
    #[error(
        "{key}: basins vary initial conditions, run.initial_positions[i] or run.initial_velocities[i] (i 0-based); for parameters use a map or an attractor census"
    )]
    NotInitial {
        /// The key.
        key: String,
    },
}

/// The mass index of `key` if it is an initial condition of a chain of `masses` masses.
pub fn initial_condition_index(key: &str, masses: usize) -> Result<usize, BasinKeyError> {
    let index = ["run.initial_positions[", "run.initial_velocities["]
        .iter()
        .find_map(|p| key.strip_prefix(p))
        .and_then(|rest| rest.strip_suffix(']'))
        .and_then(|i| i.parse::<usize>().ok());
    match index {
        Some(index) if index < masses => Ok(index),
        Some(index) => Err(BasinKeyError::OutOfRange {
            key: key.to_string(),
            index,
            masses,
        }),
        None => Err(BasinKeyError::NotInitial { key: key.to_string() }),
    }
}

/// The nodes of the grid `xs` × `ys` in grid order: y outer, x inner.
pub fn basin_points(xs: &[f64], ys: &[f64]) -> Vec<(f64, f64)> {
    ys.iter().flat_map(|&y| xs.iter().map(move |&x| (x, y))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axes_are_initial_conditions_of_the_chain() {
        assert_eq!(initial_condition_index("run.initial_velocities[2]", 3), Ok(2));
        assert!(matches!(
            initial_condition_index("run.initial_positions[3]", 3),
            Err(BasinKeyError::OutOfRange { index: 3, .. })
        ));
        assert!(initial_condition_index("omega_ratio", 3).is_err());
        assert_eq!(basin_points(&[1.0, 2.0], &[5.0]), vec![(1.0, 5.0), (2.0, 5.0)]);
    }
}
