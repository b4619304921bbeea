//! Random initial states, reproducible from a seed and independent of who draws them.

use crate::error::{ParamError, check_non_negative};
use crate::model::{ChainParams, ChainState};
use crate::random::SplitMix64;

/// Draws before [`random_start`] gives up on finding a state without interpenetration.
const MAX_DRAWS: usize = 100_000;

/// The box random starts are drawn from: every position uniform in `[−positions, positions]`,
/// every velocity in `[−velocities, velocities]`, states whose neighbours would overlap
/// (a gap below zero) drawn again.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StartBox {
    /// Half-width for the positions x_i, m.
    pub positions: f64,
    /// Half-width for the velocities, m/s.
    pub velocities: f64,
}

impl StartBox {
    /// The default box of a chain: positions within the base amplitude A, velocities within
    /// the base's peak speed A·ω.
    pub fn of(params: &ChainParams) -> Self {
        let a = params.excitation.amplitude;
        StartBox {
            positions: a,
            velocities: a * params.omega(),
        }
    }

    /// Checks the box.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_non_negative("positions", self.positions)?;
        check_non_negative("velocities", self.velocities)
    }
}

/// Random start number `sample` of the stream `seed`: a state of the chain `params` drawn
/// uniformly from `bounds` (SplitMix64 on `(seed, sample)`, so the same for any thread
/// count, order or parameter value, except that a draw that overlaps on this chain is
/// drawn again).
///
/// ```
/// use vibrotribo::attractors::{StartBox, random_start};
/// use vibrotribo::ChainParams;
///
/// let params = ChainParams::default();
/// let a = random_start(&params, &StartBox::of(&params), 7, 3)?;
/// assert_eq!(a, random_start(&params, &StartBox::of(&params), 7, 3)?);
/// assert!(params.validate_state(&a).is_ok());
/// # Ok::<(), vibrotribo::ParamError>(())
/// ```
pub fn random_start(
    params: &ChainParams,
    bounds: &StartBox,
    seed: u64,
    sample: u64,
) -> Result<ChainState, ParamError> {
    bounds.validate()?;
    let n = params.len();
    let mut rng = SplitMix64::stream(seed, &[sample]);
    for _ in 0..MAX_DRAWS {
        let positions: Vec<f64> = (0..n)
            .map(|_| bounds.positions * (2.0 * rng.uniform() - 1.0))
            .collect();
        let velocities: Vec<f64> = (0..n)
            .map(|_| bounds.velocities * (2.0 * rng.uniform() - 1.0))
            .collect();
        let state = ChainState {
            positions,
            velocities,
        };
        if params.validate_state(&state).is_ok() {
            return Ok(state);
        }
    }
    Err(ParamError::Conflict {
        name: "start box".into(),
        message: format!(
            "no state without overlapping masses in {MAX_DRAWS} draws from ±{} m: shrink the position range",
            bounds.positions
        ),
    })
}
