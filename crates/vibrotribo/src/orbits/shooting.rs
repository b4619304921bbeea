//! Periodic orbits by shooting: Newton's method on the P-fold stroboscopic map.

use nalgebra::{Complex, DMatrix, DVector};

use super::cancel::{Cancel, Polled};
use super::error::{NewtonFailure, OrbitError};
use super::floquet::{floquet_multipliers, is_stable};
use super::map::{MapEval, Scale, chatter_bounces, evaluate, project_closed};
use crate::analysis::{PeriodOptions, Periodicity, StroboscopicOptions, StroboscopicSection, detect_period};
use crate::dynamics::{ContactStatus, Event, EventKind, Observer, RunEnd, Simulator};
use crate::error::{ParamError, SimError, check, check_positive};
use crate::model::{ChainParams, ChainState, SimOptions};
use crate::sensitivity::{SensitivityOptions, state_from_vector, state_vector};

/// Settings of [`find_periodic_orbit`].
#[derive(Debug, Clone, PartialEq)]
pub struct ShootingOptions {
    /// Converged when the scaled residual `max_i |φ(z) − z|_i / scale_i` is at most this
    /// (positions scaled by L = Σδ_k + A, velocities by L·ω). Default 1e-12.
    pub tolerance: f64,
    /// Newton iterations allowed. Default 40.
    pub max_iterations: usize,
    /// Smallest damping factor of the backtracking line search (the step is halved from 1
    /// until the residual decreases). Default 1/1024.
    pub min_damping: f64,
    /// Settings of the simulations.
    pub sim: SimOptions,
    /// Settings of the sensitivities (grazing and simultaneity thresholds).
    pub sensitivity: SensitivityOptions,
    /// Polled at every Newton iteration and through the transient of
    /// [`periodic_orbit_from_transient`]: when it asks, the search stops with
    /// [`OrbitError::Cancelled`]. Default: never.
    pub cancel: Cancel,
}

impl Default for ShootingOptions {
    fn default() -> Self {
        ShootingOptions {
            tolerance: 1e-12,
            max_iterations: 40,
            min_damping: 1.0 / 1024.0,
            sim: SimOptions::default(),
            sensitivity: SensitivityOptions::default(),
            cancel: Cancel::never(),
        }
    }
}

impl ShootingOptions {
    /// Checks the options.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_positive("tolerance", self.tolerance)?;
        check(
            "max_iterations",
            self.max_iterations as f64,
            self.max_iterations > 0,
            "must be positive",
        )?;
        check_positive("min_damping", self.min_damping)?;
        check(
            "min_damping",
            self.min_damping,
            self.min_damping <= 1.0,
            "must be at most 1",
        )?;
        self.sim.validate()
    }
}

/// A periodic orbit of the P-fold stroboscopic map (section t ≡ 0 mod T) with its Floquet
/// multipliers.
///
/// A contact stuck at the section and through the whole period makes Φ a projection in its
/// gap and relative-velocity directions (see [`sensitivity`](crate::sensitivity)): two
/// multipliers are exactly 0 there.
#[derive(Debug, Clone, PartialEq)]
pub struct PeriodicOrbit {
    /// The chain.
    pub params: ChainParams,
    /// Period P, in excitation periods.
    pub period: u32,
    /// The state at the section t ≡ 0 (mod T): positions, m, and velocities, m/s.
    pub state: ChainState,
    /// Monodromy matrix `Φ(PT) = ∂φ/∂z` at the orbit, 2N × 2N.
    pub monodromy: DMatrix<f64>,
    /// Floquet multipliers (eigenvalues of the monodromy matrix), largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
    /// Whether every multiplier lies inside the unit circle.
    pub stable: bool,
    /// The events over one period of the orbit, t ∈ [0, PT).
    pub events: Vec<Event>,
    /// Scaled residual at the orbit.
    pub residual: f64,
    /// Scaled residual at every accepted Newton iterate, the first at the initial state.
    pub residuals: Vec<f64>,
}

impl PeriodicOrbit {
    /// Duration of one period of the orbit, P·T, s.
    pub fn duration(&self) -> f64 {
        f64::from(self.period) * self.params.period()
    }

    /// Largest multiplier modulus.
    pub fn spectral_radius(&self) -> f64 {
        self.multipliers.first().map_or(0.0, |l| l.norm())
    }

    /// Multipliers outside the unit circle.
    pub fn unstable_dimension(&self) -> usize {
        self.multipliers.iter().filter(|l| l.norm() > 1.0).count()
    }

    /// Impacts per excitation period at each contact (chatter bounces included, as
    /// [`RunStats`](crate::analysis::RunStats) counts them).
    pub fn impacts_per_period(&self) -> Vec<f64> {
        let mut counts = vec![0.0; self.params.contact_count()];
        for e in self.events.iter().filter(|e| e.kind == EventKind::Impact) {
            counts[e.contact] += 1.0;
        }
        counts.iter().map(|c| c / f64::from(self.period)).collect()
    }

    /// The slowest impact that is not a bounce of a chatter sequence: `(contact, closing speed
    /// in m/s)`. It tends to zero at a grazing bifurcation.
    pub fn min_closing_speed(&self) -> Option<(usize, f64)> {
        let bounces = chatter_bounces(&self.events);
        self.events
            .iter()
            .zip(bounces)
            .filter(|(e, bounce)| e.kind == EventKind::Impact && !bounce)
            .map(|(e, _)| (e.contact, e.velocity_before))
            .min_by(|a, b| a.1.total_cmp(&b.1))
    }

    /// Whether a contact sticks somewhere on the orbit (a `Stick` event, or stuck at the
    /// section).
    pub fn sticks(&self) -> bool {
        self.events.iter().any(|e| e.kind == EventKind::Stick)
    }

    /// Runs one period of the orbit again from its section state with `observer` attached:
    /// the hook for anything computed along the orbit (the average power of a harvester with
    /// [`ChargeSolver`](crate::electrical::ChargeSolver), …).
    pub fn replay<O: Observer + ?Sized>(
        &self,
        sim_options: &SimOptions,
        observer: &mut O,
    ) -> Result<RunEnd, SimError> {
        let mut sim = Simulator::new(&self.params, &self.state, sim_options.clone())?;
        sim.run_until(self.duration(), observer)
    }
}

/// Newton's method converged at `z`; `eval` is the map there.
pub(crate) struct Converged {
    pub z: DVector<f64>,
    pub eval: MapEval,
    pub residuals: Vec<f64>,
}

/// Which contacts are closed (stuck or in a chatter jump) at the end of an evaluation.
pub(crate) fn closed_contacts(eval: &MapEval) -> Vec<bool> {
    eval.status.iter().map(|s| *s != ContactStatus::Open).collect()
}

/// Solves `A x = b` in the units of `scale`: `(D⁻¹ A D) x̂ = D⁻¹ b`, `x = D x̂`.
pub(crate) fn solve_scaled(a: &DMatrix<f64>, b: &DVector<f64>, scale: &Scale) -> Option<DVector<f64>> {
    let n = b.len() / 2;
    let s = |i: usize| scale.of_component(i, n);
    let a_hat = DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)] * s(j) / s(i));
    let b_hat = DVector::from_fn(b.len(), |i, _| b[i] / s(i));
    let x_hat = a_hat.lu().solve(&b_hat)?;
    if x_hat.iter().any(|v| !v.is_finite()) {
        return None;
    }
    Some(DVector::from_fn(b.len(), |i, _| x_hat[i] * s(i)))
}

/// Damped Newton iteration for `φ(z) = z` from `z0` (module docs of [`super`]).
/// On the section t ≡ `phase` (mod T), s.
pub(crate) fn newton(
    params: &ChainParams,
    z0: DVector<f64>,
    period: u32,
    phase: f64,
    options: &ShootingOptions,
) -> Result<Converged, OrbitError> {
    newton_within(params, z0, period, phase, options, |_| true)
}

/// [`newton`] whose line search accepts only iterates whose evaluation satisfies `keep` (an
/// event sequence held fixed, so that the iteration stays on one side of a grazing).
pub(crate) fn newton_within(
    params: &ChainParams,
    z0: DVector<f64>,
    period: u32,
    phase: f64,
    options: &ShootingOptions,
    keep: impl Fn(&MapEval) -> bool,
) -> Result<Converged, OrbitError> {
    options.validate()?;
    if period == 0 {
        return Err(OrbitError::ZeroPeriod);
    }
    let scale = Scale::of(params);
    let eval_at = |z: &DVector<f64>| evaluate(params, z, period, phase, &options.sim, &options.sensitivity);
    let mut z = z0;
    let mut eval = eval_at(&z)?;
    let mut residual = scale.norm(&eval.residual(&z));
    let mut residuals = vec![residual];
    let fail = |reason, residuals: Vec<f64>| OrbitError::NoConvergence {
        period,
        reason,
        residuals,
    };
    for _ in 0..options.max_iterations {
        if residual <= options.tolerance {
            return Ok(Converged { z, eval, residuals });
        }
        if options.cancel.requested() {
            return Err(OrbitError::Cancelled);
        }
        let Ok(phi) = &eval.stm else {
            return Err(fail(NewtonFailure::NonSmooth, residuals));
        };
        let n = z.len();
        let a = phi - DMatrix::identity(n, n);
        let Some(step) = solve_scaled(&a, &(-eval.residual(&z)), &scale) else {
            return Err(fail(NewtonFailure::Singular, residuals));
        };
        let closed = closed_contacts(&eval);
        let mut damping = 1.0;
        let accepted = loop {
            if damping < options.min_damping {
                break None;
            }
            let mut trial = &z + &step * damping;
            project_closed(params, &closed, &scale, 1e-6, &mut trial);
            if let Ok(e) = eval_at(&trial)
                .map_err(|_| ())
                .and_then(|e| if keep(&e) { Ok(e) } else { Err(()) })
            {
                let r = scale.norm(&e.residual(&trial));
                if r <= (1.0 - 1e-4 * damping) * residual || r <= options.tolerance {
                    break Some((trial, e, r));
                }
            }
            damping *= 0.5;
        };
        let Some((trial, e, r)) = accepted else {
            return Err(fail(NewtonFailure::LineSearch, residuals));
        };
        z = trial;
        eval = e;
        residual = r;
        residuals.push(r);
    }
    if residual <= options.tolerance {
        return Ok(Converged { z, eval, residuals });
    }
    Err(fail(NewtonFailure::Iterations, residuals))
}

/// Builds the orbit from a converged Newton iteration.
pub(crate) fn orbit_from(
    params: &ChainParams,
    period: u32,
    c: Converged,
) -> Result<PeriodicOrbit, OrbitError> {
    let monodromy = c.eval.stm?;
    let multipliers = floquet_multipliers(&monodromy)?;
    let end = f64::from(period) * params.period();
    Ok(PeriodicOrbit {
        params: params.clone(),
        period,
        state: state_from_vector(c.z.as_slice()),
        stable: is_stable(&multipliers),
        multipliers,
        monodromy,
        events: c.eval.events.into_iter().filter(|e| e.time < end).collect(),
        residual: *c.residuals.last().unwrap_or(&f64::NAN),
        residuals: c.residuals,
    })
}

/// The periodic orbit of period `period` (in excitation periods) nearest, for Newton's method,
/// to the section state `guess` (at t ≡ 0 mod T). Stable and unstable orbits alike.
///
/// ```
/// use vibrotribo::orbits::{ShootingOptions, find_periodic_orbit};
/// use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator};
///
/// // The paper's default case settles to a period-1 orbit: start Newton after 20 periods.
/// let params = ChainParams::default();
/// let mut sim = Simulator::new(&params, &ChainState::at_rest(3), SimOptions::default())?;
/// sim.run_until(20.0 * params.period(), &mut ())?;
/// let orbit = find_periodic_orbit(&params, &sim.state(), 1, &ShootingOptions::default())?;
/// assert!(orbit.residual <= 1e-12 && orbit.stable);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn find_periodic_orbit(
    params: &ChainParams,
    guess: &ChainState,
    period: u32,
    options: &ShootingOptions,
) -> Result<PeriodicOrbit, OrbitError> {
    if period == 0 {
        return Err(OrbitError::ZeroPeriod);
    }
    params.validate()?;
    params.validate_state(guess)?;
    let converged = newton(params, state_vector(guess), period, 0.0, options)?;
    orbit_from(params, period, converged)
}

/// Simulates `transient_periods` excitation periods from `initial`, then finds the periodic
/// orbit of period `period` from the state reached (at t = transient·T, a section time). With
/// `period = None` the period is read off 128 further stroboscopic samples
/// ([`detect_period`], periods up to 64, relative tolerance 1e-4).
///
/// ```
/// use vibrotribo::orbits::{ShootingOptions, periodic_orbit_from_transient};
/// use vibrotribo::{ChainParams, ChainState};
///
/// let params = ChainParams::default();
/// let orbit = periodic_orbit_from_transient(&params, &ChainState::at_rest(3), 100, None, &ShootingOptions::default())?;
/// assert_eq!(orbit.period, 1);
/// assert!(orbit.stable && orbit.residual <= 1e-12);
/// # Ok::<(), vibrotribo::orbits::OrbitError>(())
/// ```
pub fn periodic_orbit_from_transient(
    params: &ChainParams,
    initial: &ChainState,
    transient_periods: u32,
    period: Option<u32>,
    options: &ShootingOptions,
) -> Result<PeriodicOrbit, OrbitError> {
    if period == Some(0) {
        return Err(OrbitError::ZeroPeriod);
    }
    options.validate()?;
    let n = params.len();
    let mut sim = Simulator::new(params, initial, options.sim.clone())?;
    let t_transient = f64::from(transient_periods) * params.period();
    let cancel = &options.cancel;
    sim.run_until(t_transient, &mut Polled { inner: (), cancel })?;
    if cancel.requested() {
        return Err(OrbitError::Cancelled);
    }
    let (guess, period) = match period {
        Some(p) => (sim.state(), p),
        None => {
            let popts = PeriodOptions {
                max_period: 64,
                tolerance: 1e-4,
                repeats: 1,
                scale: None,
            };
            let samples = popts.samples_needed() as u64;
            let mut strobe = StroboscopicSection::new(
                n,
                params.period(),
                StroboscopicOptions {
                    phase_time: 0.0,
                    transient_periods: u64::from(transient_periods),
                },
            )
            .map_err(|_| ParamError::invalid("excitation period", params.period(), "must be positive"))?;
            let mut polled = Polled {
                inner: &mut strobe,
                cancel,
            };
            sim.run_until(t_transient + samples as f64 * params.period(), &mut polled)?;
            if cancel.requested() {
                return Err(OrbitError::Cancelled);
            }
            let verdict =
                detect_period(&strobe.positions, n, &popts).map_err(|_| OrbitError::NotPeriodic {
                    max_period: popts.max_period,
                    closest_period: 0,
                    mismatch: f64::NAN,
                })?;
            match verdict {
                Periodicity::Periodic { period, .. } => (sim.state(), period as u32),
                Periodicity::NonPeriodic {
                    closest_period,
                    mismatch,
                } => {
                    return Err(OrbitError::NotPeriodic {
                        max_period: popts.max_period,
                        closest_period,
                        mismatch,
                    });
                }
            }
        }
    };
    find_periodic_orbit(params, &guess, period, options)
}
