//! The extended system of pseudo-arclength continuation and its corrector.
//!
//! Unknowns `u = (ẑ, p̂)`: the section state in the units of [`Scale`] and the parameter in
//! units of its range. Residual `G(u) = D⁻¹(φ(z; p) − z)`, Jacobian
//! `[D⁻¹(Φ − I)D, D⁻¹ ∂φ/∂p · p_s]` (the parameter column by central differences of the
//! exact map). A corrector step solves `G(u) = 0, tᵀ(u − u_pred) = 0` by Newton's method.

use nalgebra::{DMatrix, DVector};

use super::super::error::NewtonFailure;
use super::super::floquet::{TestFunctions, floquet_multipliers, is_stable};
use super::super::map::{MapEval, Scale, chatter_bounces, evaluate, project_closed, signature};
use super::super::shooting::closed_contacts;
use super::types::{BranchPoint, ContinuationOptions};
use crate::dynamics::{EventKind, Simulator};
use crate::error::SimError;
use crate::model::ChainParams;
use crate::sensitivity::{NonSmoothPoint, state_from_vector, state_vector};

/// A continuation problem: the family, the period and the units.
pub(crate) struct Problem<'a, F> {
    pub family: &'a F,
    pub period: u32,
    /// Number of masses.
    pub n: usize,
    /// Phase θ of the section t ≡ θ (mod T) the branch is represented on, s (switched away
    /// from events, see [`super::phase`]); points are reported at t ≡ 0.
    pub phase: f64,
    pub scale: Scale,
    /// Unit of the parameter in the arclength.
    pub p_scale: f64,
    pub options: &'a ContinuationOptions,
}

/// The extended system evaluated at one `u`.
#[derive(Debug, Clone)]
pub(crate) struct Evaluated {
    pub u: DVector<f64>,
    pub eval: MapEval,
    /// Scaled residual G(u).
    pub residual: DVector<f64>,
    /// Scaled Jacobian `[D⁻¹(Φ − I)D | D⁻¹ ∂φ/∂p p_s]`, 2N × (2N + 1).
    pub jacobian: DMatrix<f64>,
    /// Corrector iterations that led here.
    pub iterations: usize,
}

/// Why a corrector step failed.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Failure {
    pub reason: NewtonFailure,
    pub non_smooth: Option<NonSmoothPoint>,
    pub residuals: Vec<f64>,
}

impl Failure {
    fn new(reason: NewtonFailure, residuals: Vec<f64>) -> Self {
        Failure {
            reason,
            non_smooth: None,
            residuals,
        }
    }
}

impl<F: Fn(f64) -> ChainParams> Problem<'_, F> {
    /// The same problem on the section t ≡ `phase` (mod T).
    pub fn with_phase(&self, phase: f64) -> Self {
        Problem {
            family: self.family,
            period: self.period,
            n: self.n,
            phase,
            scale: self.scale,
            p_scale: self.p_scale,
            options: self.options,
        }
    }

    /// The problem's period `P·T` for the chain `params`, s.
    pub fn duration(&self, params: &ChainParams) -> f64 {
        f64::from(self.period) * params.period()
    }

    /// The end of that period from the section, `θ + P·T`, s.
    pub fn end(&self, params: &ChainParams) -> f64 {
        self.phase + self.duration(params)
    }

    pub fn dim(&self) -> usize {
        2 * self.n()
    }

    fn n(&self) -> usize {
        self.n
    }

    /// The state `z` of `u`, m and m/s.
    pub fn state(&self, u: &DVector<f64>) -> DVector<f64> {
        let n = self.n();
        DVector::from_fn(2 * n, |i, _| u[i] * self.scale.of_component(i, n))
    }

    /// The parameter of `u`.
    pub fn parameter(&self, u: &DVector<f64>) -> f64 {
        u[self.dim()] * self.p_scale
    }

    /// `u` of a state and a parameter.
    pub fn point(&self, z: &DVector<f64>, p: f64) -> DVector<f64> {
        let n = self.n();
        DVector::from_fn(2 * n + 1, |i, _| {
            if i < 2 * n {
                z[i] / self.scale.of_component(i, n)
            } else {
                p / self.p_scale
            }
        })
    }

    /// The map and its derivatives at `u`.
    pub fn evaluate(&self, u: &DVector<f64>) -> Result<Evaluated, Failure> {
        let (z, p) = (self.state(u), self.parameter(u));
        let params = (self.family)(p);
        let opts = &self.options.shooting;
        let eval = evaluate(&params, &z, self.period, self.phase, &opts.sim, &opts.sensitivity)
            .map_err(|_| Failure::new(NewtonFailure::Simulation, Vec::new()))?;
        let phi = match &eval.stm {
            Ok(phi) => phi,
            Err(point) => {
                return Err(Failure {
                    reason: NewtonFailure::NonSmooth,
                    non_smooth: Some(point.clone()),
                    residuals: Vec::new(),
                });
            }
        };
        let h = self.options.parameter_step * p.abs().max(self.p_scale);
        let plus = end_state(&(self.family)(p + h), &z, self.period, self.phase, &opts.sim);
        let minus = end_state(&(self.family)(p - h), &z, self.period, self.phase, &opts.sim);
        let (Ok(plus), Ok(minus)) = (plus, minus) else {
            return Err(Failure::new(NewtonFailure::Simulation, Vec::new()));
        };
        let dim = self.dim();
        let n = self.n();
        let s = |i: usize| self.scale.of_component(i, n);
        let mut jacobian = DMatrix::zeros(dim, dim + 1);
        for i in 0..dim {
            for j in 0..dim {
                let identity = if i == j { 1.0 } else { 0.0 };
                jacobian[(i, j)] = (phi[(i, j)] - identity) * s(j) / s(i);
            }
            jacobian[(i, dim)] = (plus[i] - minus[i]) / (2.0 * h) * self.p_scale / s(i);
        }
        let residual = DVector::from_fn(dim, |i, _| (eval.image[i] - z[i]) / s(i));
        Ok(Evaluated {
            u: u.clone(),
            eval,
            residual,
            jacobian,
            iterations: 0,
        })
    }

    /// Newton's method on `G(u) = 0, tᵀ(u − u_pred) = 0` from `u_pred`.
    pub fn correct(&self, u_pred: &DVector<f64>, t: &DVector<f64>) -> Result<Evaluated, Failure> {
        let dim = self.dim();
        let mut u = u_pred.clone();
        let mut residuals = Vec::new();
        for _ in 0..self.options.corrector_iterations {
            let mut ev = self.evaluate(&u).map_err(|mut f| {
                f.residuals = residuals.clone();
                f
            })?;
            let r = ev.residual.amax();
            residuals.push(r);
            if r <= self.options.corrector_tolerance.max(rounding_floor(&ev.jacobian)) {
                ev.iterations = residuals.len() - 1;
                return Ok(ev);
            }
            // Newton must contract: a residual that does not halve after the first iteration
            // means the predictor is too far (or the orbit is gone).
            if residuals.len() >= 3 && r > 0.5 * residuals[residuals.len() - 2] {
                return Err(Failure::new(NewtonFailure::LineSearch, residuals));
            }
            let mut a = ev.jacobian.clone().insert_row(dim, 0.0);
            let mut rhs = -ev.residual.clone().insert_row(dim, 0.0);
            for j in 0..=dim {
                a[(dim, j)] = t[j];
            }
            rhs[dim] = -t.dot(&(&u - u_pred));
            let Some(step) = a.lu().solve(&rhs).filter(|s| s.iter().all(|v| v.is_finite())) else {
                return Err(Failure::new(NewtonFailure::Singular, residuals));
            };
            u += step;
            let mut z = self.state(&u);
            project_closed(
                &(self.family)(self.parameter(&u)),
                &closed_contacts(&ev.eval),
                &self.scale,
                1e-6,
                &mut z,
            );
            for i in 0..dim {
                u[i] = z[i] / self.scale.of_component(i, self.n());
            }
        }
        Err(Failure::new(NewtonFailure::Iterations, residuals))
    }

    /// The unit tangent of the branch at `ev`, oriented along `previous` (`tᵀ previous > 0`).
    pub fn tangent(&self, ev: &Evaluated, previous: &DVector<f64>) -> Option<DVector<f64>> {
        let dim = self.dim();
        let mut a = ev.jacobian.clone().insert_row(dim, 0.0);
        for j in 0..=dim {
            a[(dim, j)] = previous[j];
        }
        let mut rhs = DVector::zeros(dim + 1);
        rhs[dim] = 1.0;
        let t = a.lu().solve(&rhs)?;
        if t.iter().any(|v| !v.is_finite()) {
            return None;
        }
        let t = t.normalize();
        Some(if t.dot(previous) < 0.0 { -t } else { t })
    }

    /// The orbit at a converged point, with its test functions and event signature.
    pub fn describe(&self, ev: &Evaluated, arclength: f64) -> Option<Described> {
        let phi = ev.eval.stm.as_ref().ok()?;
        let multipliers = floquet_multipliers(phi).ok()?;
        let params = (self.family)(self.parameter(&ev.u));
        let end = self.end(&params);
        let events: Vec<_> = ev.eval.events.iter().filter(|e| e.time < end).copied().collect();
        let mut impacts = vec![0.0; params.contact_count()];
        for e in events.iter().filter(|e| e.kind == EventKind::Impact) {
            impacts[e.contact] += 1.0 / f64::from(self.period);
        }
        let bounces = chatter_bounces(&events);
        let min_closing_speed = events
            .iter()
            .zip(&bounces)
            .filter(|(e, b)| e.kind == EventKind::Impact && !**b)
            .map(|(e, _)| (e.contact, e.velocity_before))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let z = &ev.eval.at_zero;
        Some(Described {
            tests: TestFunctions::of(&multipliers),
            signature: signature(&events),
            point: BranchPoint {
                parameter: self.parameter(&ev.u),
                state: state_from_vector(z.as_slice()),
                stable: is_stable(&multipliers),
                multipliers,
                impacts_per_period: impacts,
                min_closing_speed,
                sticks: events.iter().any(|e| e.kind == EventKind::Stick),
                arclength,
            },
        })
    }
}

/// The smallest scaled residual the map can be evaluated to near `jacobian` (scaled, either
/// `Φ` or `Φ − I` and its parameter column): rounding in the state is amplified by the map's
/// largest derivative, which grows like the inverse of the impact speed just past a grazing.
/// At most [`ROUNDING_CAP`], and below every tolerance away from grazing.
pub(crate) fn rounding_floor(jacobian: &DMatrix<f64>) -> f64 {
    (4.0 * f64::EPSILON * jacobian.amax()).min(ROUNDING_CAP)
}

/// The largest residual (scaled) taken as converged where the map amplifies rounding.
const ROUNDING_CAP: f64 = 1e-10;

/// A converged point with what the detection needs.
#[derive(Debug, Clone)]
pub(crate) struct Described {
    pub point: BranchPoint,
    pub tests: TestFunctions,
    pub signature: Vec<(EventKind, usize)>,
}

/// The state after `periods` excitation periods from `z` at t = `phase`, without
/// sensitivities.
fn end_state(
    params: &ChainParams,
    z: &DVector<f64>,
    periods: u32,
    phase: f64,
    sim: &crate::SimOptions,
) -> Result<DVector<f64>, SimError> {
    let mut s = Simulator::new_at(params, phase, &state_from_vector(z.as_slice()), sim.clone())?;
    s.run_until(phase + f64::from(periods) * params.period(), &mut ())?;
    Ok(state_vector(&s.state()))
}
