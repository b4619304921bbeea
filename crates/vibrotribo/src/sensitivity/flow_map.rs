//! The flow map with its state-transition matrix, and its derivative in a parameter.

use nalgebra::DVector;

use super::error::SensitivityError;
use super::stm::{Sensitivity, SensitivityOptions};
use crate::dynamics::{ContactStatus, Event, Observer, Simulator, StateView};
use crate::error::{ParamError, check_positive};
use crate::model::{ChainParams, ChainState, SimOptions};

/// How far a flow map runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Horizon {
    /// To this time, s (the run starts at t = 0).
    Time(f64),
    /// To this many excitation periods, `P·T`: the P-fold stroboscopic map. When a parameter
    /// changes the frequency, the end time moves with it.
    Periods(u32),
}

impl Horizon {
    /// The end time for a chain with parameters `params`, s.
    pub fn end_time(&self, params: &ChainParams) -> f64 {
        match *self {
            Horizon::Time(t) => t,
            Horizon::Periods(p) => f64::from(p) * params.period(),
        }
    }
}

/// The state as a vector `z = [x₁ … x_N, v₁ … v_N]` (m, m/s).
pub fn state_vector(state: &ChainState) -> DVector<f64> {
    DVector::from_iterator(
        state.positions.len() + state.velocities.len(),
        state.positions.iter().chain(&state.velocities).copied(),
    )
}

/// The state of a chain of `z.len() / 2` masses from `z = [x₁ … x_N, v₁ … v_N]`.
pub fn state_from_vector(z: &[f64]) -> ChainState {
    let n = z.len() / 2;
    ChainState {
        positions: z[..n].to_vec(),
        velocities: z[n..2 * n].to_vec(),
    }
}

/// The flow map from a state at t = 0 and its state-transition matrix.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowMap {
    /// The state at the end, `z(t₁)`.
    pub state: ChainState,
    /// End time t₁, s.
    pub time: f64,
    /// `Φ = ∂z(t₁)/∂z(0)`, 2N × 2N.
    pub stm: nalgebra::DMatrix<f64>,
    /// Every event on the way.
    pub events: Vec<Event>,
    /// The contacts' status at the end.
    pub contacts: Vec<ContactStatus>,
}

/// Records the events of a run.
#[derive(Debug, Clone, Default)]
pub(crate) struct EventRecorder(pub Vec<Event>);

impl Observer for EventRecorder {
    fn event(&mut self, event: &Event, _state: &StateView<'_>) {
        self.0.push(*event);
    }
}

/// Runs the chain `params` from `initial` at t = 0 to `horizon` and returns the end state with
/// its state-transition matrix.
///
/// Contacts that start closed with zero relative velocity and a compressive force start
/// stuck (as in [`Simulator::new`]); Φ then projects perturbations onto their constraint
/// subspace (its columns for gap and relative velocity are not derivatives of the map, which
/// is not defined off that subspace).
///
/// ```
/// use vibrotribo::sensitivity::{Horizon, SensitivityOptions, flow_map};
/// use vibrotribo::{ChainParams, ChainState, SimOptions};
///
/// let params = ChainParams::default();
/// let map = flow_map(&params, &ChainState::at_rest(3), Horizon::Periods(1), &SimOptions::default(), &SensitivityOptions::default())?;
/// assert_eq!(map.stm.nrows(), 6);
/// # Ok::<(), vibrotribo::sensitivity::SensitivityError>(())
/// ```
pub fn flow_map(
    params: &ChainParams,
    initial: &ChainState,
    horizon: Horizon,
    sim_options: &SimOptions,
    options: &SensitivityOptions,
) -> Result<FlowMap, SensitivityError> {
    let t_end = horizon.end_time(params);
    let mut sim = Simulator::new(params, initial, sim_options.clone())?;
    let mut stm = Sensitivity::new(params, options.clone());
    let mut events = EventRecorder::default();
    sim.run_until(t_end, &mut (&mut stm, &mut events))?;
    let phi = match stm.stm() {
        Ok(phi) => phi.clone(),
        // A zero-length run observes nothing: Φ = I.
        Err(SensitivityError::Empty) => nalgebra::DMatrix::identity(2 * params.len(), 2 * params.len()),
        Err(e) => return Err(e),
    };
    Ok(FlowMap {
        state: sim.state(),
        time: t_end,
        stm: phi,
        events: events.0,
        contacts: sim.contact_status(),
    })
}

/// Settings of [`parameter_derivative`].
#[derive(Debug, Clone, PartialEq)]
pub struct DerivativeOptions {
    /// Step relative to |p|: `h = max(relative_step·|p|, min_step)`. Default ∛ε ≈ 6.1e-6,
    /// which balances the O(h²) truncation against the O(ε/h) rounding of central
    /// differences.
    pub relative_step: f64,
    /// Smallest step, in the parameter's unit. Default 1e-9.
    pub min_step: f64,
    /// Settings of the runs.
    pub sim: SimOptions,
}

impl Default for DerivativeOptions {
    fn default() -> Self {
        DerivativeOptions {
            relative_step: f64::EPSILON.cbrt(),
            min_step: 1e-9,
            sim: SimOptions::default(),
        }
    }
}

impl DerivativeOptions {
    /// Checks the options.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_positive("relative_step", self.relative_step)?;
        check_positive("min_step", self.min_step)?;
        self.sim.validate()
    }
}

/// `∂z(t₁)/∂p` of [`parameter_derivative`].
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterDerivative {
    /// The derivative, `[∂x₁/∂p … ∂v_N/∂p]` (m and m/s per unit of p).
    pub derivative: DVector<f64>,
    /// The step h used, in the parameter's unit.
    pub step: f64,
    /// Estimated error of `derivative` (largest component): the Richardson estimate
    /// `|D(h) − D(2h)|/3` of the central difference D(h)'s truncation error plus the rounding
    /// `ε·|z|/h`. The extrapolated derivative returned is more accurate than that.
    pub error: f64,
}

/// The derivative of the flow map `z(t₁; p)` from `initial` at t = 0 with respect to the
/// parameter `p` of the family `params_of` (any scalar that changes [`ChainParams`]), by
/// central differences of the exact flow map at `p ± h` and `p ± 2h` with Richardson
/// extrapolation (see [`ParameterDerivative::error`]).
///
/// Errors with [`SensitivityError::SequenceChange`] if the four runs do not see the same
/// events (the step crosses a grazing, sticking or other change of the event sequence).
///
/// ```
/// use vibrotribo::sensitivity::{DerivativeOptions, Horizon, parameter_derivative};
/// use vibrotribo::{ChainParams, ChainState, Frequency};
///
/// let family = |omega: f64| {
///     let mut p = ChainParams::default();
///     p.excitation.frequency = Frequency::OmegaRatio(omega);
///     p
/// };
/// let d = parameter_derivative(family, 0.7, &ChainState::at_rest(3), Horizon::Periods(1), &DerivativeOptions::default())?;
/// assert!(d.error < 1e-6 * d.derivative.amax());
/// # Ok::<(), vibrotribo::sensitivity::SensitivityError>(())
/// ```
pub fn parameter_derivative<F>(
    params_of: F,
    p: f64,
    initial: &ChainState,
    horizon: Horizon,
    options: &DerivativeOptions,
) -> Result<ParameterDerivative, SensitivityError>
where
    F: Fn(f64) -> ChainParams,
{
    options.validate().map_err(crate::error::SimError::from)?;
    let h = (options.relative_step * p.abs()).max(options.min_step);
    let run = |q: f64| -> Result<(DVector<f64>, Vec<Event>), SensitivityError> {
        let params = params_of(q);
        let mut sim = Simulator::new(&params, initial, options.sim.clone())?;
        let mut events = EventRecorder::default();
        sim.run_until(horizon.end_time(&params), &mut events)?;
        Ok((state_vector(&sim.state()), events.0))
    };
    let (zp1, ep1) = run(p + h)?;
    let (zm1, em1) = run(p - h)?;
    let (zp2, ep2) = run(p + 2.0 * h)?;
    let (zm2, em2) = run(p - 2.0 * h)?;
    let signature = |e: &[Event]| e.iter().map(|e| (e.kind, e.contact)).collect::<Vec<_>>();
    let s = signature(&ep1);
    if signature(&em1) != s || signature(&ep2) != s || signature(&em2) != s {
        return Err(SensitivityError::SequenceChange {
            low: p - 2.0 * h,
            high: p + 2.0 * h,
        });
    }
    let d1 = (&zp1 - &zm1) / (2.0 * h);
    let d2 = (&zp2 - &zm2) / (4.0 * h);
    let derivative = &d1 + (&d1 - &d2) / 3.0;
    let rounding = f64::EPSILON * zp2.amax().max(zm2.amax()) / h;
    Ok(ParameterDerivative {
        error: (&d1 - &d2).amax() / 3.0 + rounding,
        derivative,
        step: h,
    })
}
