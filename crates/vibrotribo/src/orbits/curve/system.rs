//! The defining system of a bifurcation curve and its Newton corrector.
//!
//! Unknowns `u = (ẑ, p̂₁, p̂₂)`: the section state in the units of [`Scale`] and the two
//! parameters in their units. Equations: the orbit `D⁻¹(φ(z; p₁, p₂) − z) = 0` and the
//! condition `g(z; p₁, p₂) = 0`, 2N + 1 equations in 2N + 2 unknowns, closed by the
//! pseudo-arclength plane `tᵀ(u − u_pred) = 0` (or, at the end of the range, `p̂₂` fixed).
//! The state columns of the Jacobian are the exact monodromy matrix; the parameter columns
//! and the condition's row are forward differences.

use nalgebra::{Complex, DMatrix, DVector};

use super::super::error::NewtonFailure;
use super::super::floquet::floquet_multipliers;
use super::super::gaps::gap_minima;
use super::super::map::{MapEval, Scale, evaluate, project_closed, signature};
use super::super::shooting::closed_contacts;
use super::types::{CurveKind, CurveOptions, CurvePoint};
use crate::dynamics::{EventKind, Simulator};
use crate::model::{ChainParams, StopSide};
use crate::sensitivity::{state_from_vector, state_vector};

/// A multiplier with an imaginary part below this (relative to 1 + |λ|) is real.
const REAL: f64 = 1e-9;

/// The defining system of one curve.
pub(crate) struct System<'a, F> {
    pub family: &'a F,
    pub kind: CurveKind,
    /// Grazing curves: the contact.
    pub contact: usize,
    /// Grazing curves: how much the contact's gap is widened while the orbit is computed
    /// (so that the impact-free orbit stays impact-free past the grazing), m.
    pub margin: f64,
    pub period: u32,
    pub n: usize,
    /// Section t ≡ fraction·T (mod T).
    pub phase_fraction: f64,
    pub scale: Scale,
    /// Units of the two parameters.
    pub p_scale: [f64; 2],
    pub options: &'a CurveOptions,
}

/// The system evaluated at one `u`.
#[derive(Debug, Clone)]
pub(crate) struct Eval {
    pub u: DVector<f64>,
    pub map: MapEval,
    pub multipliers: Vec<Complex<f64>>,
    /// The condition g.
    pub condition: f64,
    /// Residual `(D⁻¹(φ − z), g)`.
    pub residual: DVector<f64>,
    /// The gap minimum at the contact, m (grazing curves).
    pub gap: Option<f64>,
}

impl Eval {
    /// The larger of the orbit residual and |g|.
    pub fn error(&self) -> f64 {
        self.residual.amax()
    }
}

/// Why a corrector step failed.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Failure {
    pub reason: NewtonFailure,
    pub residuals: Vec<f64>,
    /// The condition has no critical multiplier (or gap minimum) to follow.
    pub degenerate: bool,
}

impl Failure {
    pub fn simulation() -> Self {
        fail(NewtonFailure::Simulation)
    }
}

fn fail(reason: NewtonFailure) -> Failure {
    Failure {
        reason,
        residuals: Vec::new(),
        degenerate: false,
    }
}

fn degenerate() -> Failure {
    Failure {
        degenerate: true,
        ..fail(NewtonFailure::Singular)
    }
}

/// Widens the gap of `contact` of `params` by `margin`, m.
pub(crate) fn widen(params: &mut ChainParams, contact: usize, margin: f64) {
    let n = params.len();
    if contact + 1 < n {
        params.gaps[contact] += margin;
        return;
    }
    let side = if contact + 1 == n {
        StopSide::Lower
    } else {
        StopSide::Upper
    };
    let stop = match side {
        StopSide::Lower => params.stops.lower.as_mut(),
        StopSide::Upper => params.stops.upper.as_mut(),
    };
    if let Some(stop) = stop {
        stop.gap += margin;
    }
}

impl<F: Fn(f64, f64) -> ChainParams> System<'_, F> {
    pub fn dim(&self) -> usize {
        2 * self.n
    }

    /// The chain at `u` (widened at the grazing contact).
    pub fn params(&self, u: &DVector<f64>) -> ChainParams {
        let (p1, p2) = self.parameters(u);
        let mut params = (self.family)(p1, p2);
        if self.kind == CurveKind::Grazing && self.margin > 0.0 {
            widen(&mut params, self.contact, self.margin);
        }
        params
    }

    pub fn parameters(&self, u: &DVector<f64>) -> (f64, f64) {
        let d = self.dim();
        (u[d] * self.p_scale[0], u[d + 1] * self.p_scale[1])
    }

    /// The state `z` of `u`, m and m/s.
    pub fn state(&self, u: &DVector<f64>) -> DVector<f64> {
        DVector::from_fn(self.dim(), |i, _| u[i] * self.scale.of_component(i, self.n))
    }

    /// `u` of a state and the parameters.
    pub fn point(&self, z: &DVector<f64>, p1: f64, p2: f64) -> DVector<f64> {
        let d = self.dim();
        DVector::from_fn(d + 2, |i, _| match i {
            i if i < d => z[i] / self.scale.of_component(i, self.n),
            i if i == d => p1 / self.p_scale[0],
            _ => p2 / self.p_scale[1],
        })
    }

    fn phase(&self, params: &ChainParams) -> f64 {
        self.phase_fraction * params.period()
    }

    /// The condition of a real or complex multiplier, or of the gap minimum (in L).
    fn condition(&self, multipliers: &[Complex<f64>], gap: Option<f64>) -> Option<f64> {
        let real = |l: &&Complex<f64>| l.im.abs() <= REAL * (1.0 + l.norm());
        match self.kind {
            CurveKind::Fold => multipliers
                .iter()
                .filter(real)
                .map(|l| l.re - 1.0)
                .min_by(|a, b| a.abs().total_cmp(&b.abs())),
            CurveKind::PeriodDoubling => multipliers
                .iter()
                .filter(real)
                .map(|l| l.re + 1.0)
                .min_by(|a, b| a.abs().total_cmp(&b.abs())),
            CurveKind::NeimarkSacker => multipliers
                .iter()
                .filter(|l| l.im > REAL * (1.0 + l.norm()))
                .map(|l| l.norm() - 1.0)
                .min_by(|a, b| a.abs().total_cmp(&b.abs())),
            CurveKind::Grazing => gap.map(|g| (g - self.margin) / self.scale.length),
        }
    }

    /// The gap minimum at the contact over the orbit from `z`, m.
    fn gap(&self, params: &ChainParams, z: &DVector<f64>) -> Option<f64> {
        let sim = &self.options.shooting.sim;
        gap_minima(params, z, self.period, self.phase(params), sim)
            .into_iter()
            .filter(|m| m.contact == self.contact)
            .map(|m| m.gap)
            .min_by(f64::total_cmp)
    }

    /// The map, its multipliers and the condition at `u`.
    pub fn evaluate(&self, u: &DVector<f64>) -> Result<Eval, Failure> {
        let params = self.params(u);
        let z = self.state(u);
        let opts = &self.options.shooting;
        let map = evaluate(
            &params,
            &z,
            self.period,
            self.phase(&params),
            &opts.sim,
            &opts.sensitivity,
        )
        .map_err(|_| fail(NewtonFailure::Simulation))?;
        let phi = map.stm.as_ref().map_err(|_| fail(NewtonFailure::NonSmooth))?;
        let multipliers = floquet_multipliers(phi).map_err(|_| fail(NewtonFailure::Singular))?;
        let gap = (self.kind == CurveKind::Grazing)
            .then(|| self.gap(&params, &z))
            .flatten();
        let condition = self.condition(&multipliers, gap).ok_or_else(degenerate)?;
        let d = self.dim();
        let mut residual = DVector::zeros(d + 1);
        for i in 0..d {
            residual[i] = (map.image[i] - z[i]) / self.scale.of_component(i, self.n);
        }
        residual[d] = condition;
        Ok(Eval {
            u: u.clone(),
            map,
            multipliers,
            condition,
            residual,
            gap,
        })
    }

    /// The condition alone at `u` (the gap minimum needs no sensitivities).
    fn condition_at(&self, u: &DVector<f64>) -> Result<f64, Failure> {
        if self.kind == CurveKind::Grazing {
            let params = self.params(u);
            let gap = self.gap(&params, &self.state(u));
            return self.condition(&[], gap).ok_or_else(degenerate);
        }
        Ok(self.evaluate(u)?.condition)
    }

    /// The image of `u`'s state under the map, without sensitivities.
    fn image(&self, u: &DVector<f64>) -> Result<DVector<f64>, Failure> {
        let params = self.params(u);
        let phase = self.phase(&params);
        let z = self.state(u);
        let mut s = Simulator::new_at(
            &params,
            phase,
            &state_from_vector(z.as_slice()),
            self.options.shooting.sim.clone(),
        )
        .map_err(|_| fail(NewtonFailure::Simulation))?;
        s.run_until(phase + f64::from(self.period) * params.period(), &mut ())
            .map_err(|_| fail(NewtonFailure::Simulation))?;
        Ok(state_vector(&s.state()))
    }

    /// The Jacobian of the residual at `ev`, (2N + 1) × (2N + 2).
    pub fn jacobian(&self, ev: &Eval) -> Result<DMatrix<f64>, Failure> {
        let d = self.dim();
        let phi = ev.map.stm.as_ref().map_err(|_| fail(NewtonFailure::NonSmooth))?;
        let s = |i: usize| self.scale.of_component(i, self.n);
        let mut j = DMatrix::zeros(d + 1, d + 2);
        for r in 0..d {
            for c in 0..d {
                let identity = if r == c { 1.0 } else { 0.0 };
                j[(r, c)] = (phi[(r, c)] - identity) * s(c) / s(r);
            }
        }
        for c in 0..d + 2 {
            let h = self.options.difference_step * ev.u[c].abs().max(1.0);
            let mut u = ev.u.clone();
            u[c] += h;
            j[(d, c)] = (self.condition_at(&u)? - ev.condition) / h;
            if c >= d {
                let image = self.image(&u)?;
                for r in 0..d {
                    j[(r, c)] = (image[r] - ev.map.image[r]) / h / s(r);
                }
            }
        }
        Ok(j)
    }

    /// Newton's method on the residual and `aᵀu = c`, from `u`.
    pub fn correct(&self, u: &DVector<f64>, a: &DVector<f64>, c: f64) -> Result<(Eval, usize), Failure> {
        let d = self.dim();
        let mut u = u.clone();
        let mut residuals = Vec::new();
        let with = |mut f: Failure, r: &Vec<f64>| {
            f.residuals = r.clone();
            f
        };
        for iteration in 0..self.options.corrector_iterations {
            let ev = self.evaluate(&u).map_err(|f| with(f, &residuals))?;
            let r = ev.error();
            residuals.push(r);
            let floor = ev
                .map
                .stm
                .as_ref()
                .map_or(0.0, |phi| (4.0 * f64::EPSILON * phi.amax()).min(1e-10));
            if r <= self.options.tolerance.max(floor) && (a.dot(&u) - c).abs() <= 1e-12 * (1.0 + c.abs()) {
                return Ok((ev, iteration));
            }
            if residuals.len() >= 3 && r > 0.5 * residuals[residuals.len() - 2] {
                return Err(with(fail(NewtonFailure::LineSearch), &residuals));
            }
            let jac = self.jacobian(&ev).map_err(|f| with(f, &residuals))?;
            let mut m = jac.insert_row(d + 1, 0.0);
            for k in 0..d + 2 {
                m[(d + 1, k)] = a[k];
            }
            let mut rhs = -ev.residual.clone().insert_row(d + 1, 0.0);
            rhs[d + 1] = c - a.dot(&u);
            let Some(step) = m.lu().solve(&rhs).filter(|s| s.iter().all(|v| v.is_finite())) else {
                return Err(with(fail(NewtonFailure::Singular), &residuals));
            };
            u += step;
            let mut z = self.state(&u);
            project_closed(
                &self.params(&u),
                &closed_contacts(&ev.map),
                &self.scale,
                1e-6,
                &mut z,
            );
            for i in 0..d {
                u[i] = z[i] / self.scale.of_component(i, self.n);
            }
        }
        Err(with(fail(NewtonFailure::Iterations), &residuals))
    }

    /// The unit tangent of the curve at `ev`, oriented along `previous`.
    pub fn tangent(&self, ev: &Eval, previous: &DVector<f64>) -> Result<DVector<f64>, Failure> {
        let d = self.dim();
        let mut m = self.jacobian(ev)?.insert_row(d + 1, 0.0);
        for k in 0..d + 2 {
            m[(d + 1, k)] = previous[k];
        }
        let mut rhs = DVector::zeros(d + 2);
        rhs[d + 1] = 1.0;
        let t = m
            .lu()
            .solve(&rhs)
            .filter(|t| t.iter().all(|v| v.is_finite()) && t.norm() > 0.0)
            .ok_or_else(|| fail(NewtonFailure::Singular))?
            .normalize();
        Ok(if t.dot(previous) < 0.0 { -t } else { t })
    }

    /// The event sequence of the orbit at `ev` (one period of the orbit).
    pub fn signature(&self, ev: &Eval) -> Vec<(EventKind, usize)> {
        signature(&self.events(ev))
    }

    fn events(&self, ev: &Eval) -> Vec<crate::dynamics::Event> {
        let params = self.params(&ev.u);
        let end = self.phase(&params) + f64::from(self.period) * params.period();
        ev.map.events.iter().filter(|e| e.time < end).copied().collect()
    }

    /// The curve point at `ev`.
    pub fn describe(&self, ev: &Eval, arclength: f64) -> CurvePoint {
        let (parameter, parameter2) = self.parameters(&ev.u);
        let params = self.params(&ev.u);
        let mut impacts = vec![0.0; params.contact_count().max(self.contact + 1)];
        for e in self.events(ev).iter().filter(|e| e.kind == EventKind::Impact) {
            if let Some(slot) = impacts.get_mut(e.contact) {
                *slot += 1.0 / f64::from(self.period);
            }
        }
        impacts.truncate(params.contact_count());
        CurvePoint {
            parameter,
            parameter2,
            state: state_from_vector(ev.map.at_zero.as_slice()),
            multipliers: ev.multipliers.clone(),
            condition: ev.condition,
            gap_minimum: ev.gap.map(|g| g - self.margin),
            impacts_per_period: impacts,
            arclength,
        }
    }
}
