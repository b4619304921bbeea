//! The P-fold stroboscopic map `z ↦ φ(PT; z)` on the section t ≡ 0 (mod T), evaluated with
//! its state-transition matrix, and the scaling the solvers measure states in.

use nalgebra::{DMatrix, DVector};

use crate::analysis::{StroboscopicOptions, StroboscopicSection};
use crate::dynamics::{ContactStatus, Event, EventKind, Simulator};
use crate::error::{ParamError, SimError};
use crate::model::{ChainParams, SimOptions};
use crate::sensitivity::{
    NonSmoothPoint, Sensitivity, SensitivityError, SensitivityOptions, state_from_vector,
};
use crate::sensitivity::{length_scale, state_vector};

/// Units in which the solvers measure a state: positions in L = Σδ + A (m), velocities in
/// L·ω (m/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Scale {
    pub length: f64,
    pub speed: f64,
}

impl Scale {
    pub fn of(params: &ChainParams) -> Self {
        let length = length_scale(params);
        Scale {
            length,
            speed: length * params.omega(),
        }
    }

    /// Scale of component `i` of a state of `n` masses.
    pub fn of_component(&self, i: usize, n: usize) -> f64 {
        if i < n { self.length } else { self.speed }
    }

    /// `max_i |z_i| / scale_i`.
    pub fn norm(&self, z: &DVector<f64>) -> f64 {
        let n = z.len() / 2;
        z.iter()
            .enumerate()
            .map(|(i, v)| v.abs() / self.of_component(i, n))
            .fold(0.0, f64::max)
    }
}

/// One evaluation of the stroboscopic map.
#[derive(Debug, Clone)]
pub(crate) struct MapEval {
    /// The image `φ(z)`.
    pub image: DVector<f64>,
    /// `Φ = ∂φ/∂z`, or where the map is not differentiable.
    pub stm: Result<DMatrix<f64>, NonSmoothPoint>,
    /// The events on the way, t ∈ [0, PT].
    pub events: Vec<Event>,
    /// The states at the sections t = θ + kT, k = 0 … P (the first is `z`, the last the
    /// image), θ the phase of the evaluation.
    pub sections: Vec<DVector<f64>>,
    /// The state at the first t ≡ 0 (mod PT) at or after θ (`z` itself when θ = 0).
    pub at_zero: DVector<f64>,
    /// The contacts' status at the end.
    pub status: Vec<ContactStatus>,
}

impl MapEval {
    /// `φ(z) − z`.
    pub fn residual(&self, z: &DVector<f64>) -> DVector<f64> {
        &self.image - z
    }
}

/// Runs `params` from `z` at t = `phase` (s, ≥ 0) for `periods` excitation periods with a
/// [`Sensitivity`]: the P-fold stroboscopic map on the section t ≡ phase (mod T).
pub(crate) fn evaluate(
    params: &ChainParams,
    z: &DVector<f64>,
    periods: u32,
    phase: f64,
    sim: &SimOptions,
    sensitivity: &SensitivityOptions,
) -> Result<MapEval, SimError> {
    let mut simulator = Simulator::new_at(params, phase, &state_from_vector(z.as_slice()), sim.clone())?;
    let mut stm = Sensitivity::new(params, sensitivity.clone());
    let mut events = crate::sensitivity::EventRecorder::default();
    let section = |phase_time| {
        StroboscopicSection::new(
            params.len(),
            params.period(),
            StroboscopicOptions {
                phase_time,
                transient_periods: 0,
            },
        )
        .map_err(|_| ParamError::invalid("excitation period", params.period(), "must be positive"))
    };
    let mut strobe = section(phase)?;
    let duration = f64::from(periods) * params.period();
    let zero_time = duration * (phase / duration).ceil();
    let mut zero = crate::dynamics::UniformSampler::new(params.len(), zero_time, duration);
    simulator.run_until(
        phase + duration,
        &mut (&mut stm, &mut events, &mut strobe, &mut zero),
    )?;
    let sections = (0..strobe.len())
        .filter_map(|j| {
            let (x, v) = (strobe.positions_at(j)?, strobe.velocities_at(j)?);
            Some(DVector::from_iterator(2 * x.len(), x.iter().chain(v).copied()))
        })
        .collect();
    let stm = match stm.stm() {
        Ok(phi) => Ok(phi.clone()),
        Err(SensitivityError::NonSmooth(p)) => Err(p),
        Err(SensitivityError::Sim(e)) => return Err(e),
        Err(_) => Ok(DMatrix::identity(z.len(), z.len())),
    };
    let n = params.len();
    let at_zero = if zero.times.is_empty() {
        z.clone()
    } else {
        DVector::from_iterator(
            2 * n,
            zero.positions[..n].iter().chain(&zero.velocities[..n]).copied(),
        )
    };
    Ok(MapEval {
        at_zero,
        image: state_vector(&simulator.state()),
        stm,
        events: events.0,
        sections,
        status: simulator.contact_status(),
    })
}

/// Puts the masses joined by a closed contact (`closed[k]`) back on their constraint
/// manifold, `x_{k+1} = x_k + δ_k`, `v_{k+1} = v_k`, about their centre of mass, where they
/// are already within `tolerance` (relative to `scale`) of it. A Newton step from a state on
/// the manifold stays on it up to rounding (Φ maps into the constrained subspace); this
/// removes the rounding so that the simulator sees the contact closed again.
pub(crate) fn project_closed(
    params: &ChainParams,
    closed: &[bool],
    scale: &Scale,
    tolerance: f64,
    z: &mut DVector<f64>,
) {
    let n = params.len();
    let mut first = 0;
    while first < n {
        let mut last = first;
        while last + 1 < n && closed[last] {
            let gap = params.gaps[last] - (z[last + 1] - z[last]);
            let dv = z[n + last + 1] - z[n + last];
            if gap.abs() > tolerance * scale.length || dv.abs() > tolerance * scale.speed {
                break;
            }
            last += 1;
        }
        if last > first {
            let (mut m, mut p, mut q) = (0.0, 0.0, 0.0);
            let mut offset = 0.0;
            for i in first..=last {
                if i > first {
                    offset += params.gaps[i - 1];
                }
                let mi = params.masses[i];
                m += mi;
                p += mi * z[n + i];
                q += mi * (z[i] - offset);
            }
            let mut offset = 0.0;
            for i in first..=last {
                if i > first {
                    offset += params.gaps[i - 1];
                }
                z[i] = q / m + offset;
                z[n + i] = p / m;
            }
        }
        first = last + 1;
    }
}

/// Marks the impacts that belong to a chatter sequence (the impacts at one contact resolved
/// one by one before an accumulation-point jump, the first included): how many there are
/// depends on a tolerance, not on the dynamics.
pub(crate) fn chatter_bounces(events: &[Event]) -> Vec<bool> {
    let mut mask = vec![false; events.len()];
    for (j, e) in events.iter().enumerate() {
        if e.kind != EventKind::Chatter {
            continue;
        }
        let mut left = e.sequence_impacts as usize;
        for i in (0..j).rev() {
            if left == 0 {
                break;
            }
            if events[i].kind == EventKind::Impact && events[i].contact == e.contact && !mask[i] {
                mask[i] = true;
                left -= 1;
            }
        }
    }
    mask
}

/// The orbit's event sequence as `(kind, contact)`, each chatter sequence reduced to its
/// `Chatter` entry (see [`chatter_bounces`]), as a cycle: rotated to its lexicographically
/// smallest form, so that it does not depend on where the period starts.
pub(crate) fn signature(events: &[Event]) -> Vec<(EventKind, usize)> {
    let mask = chatter_bounces(events);
    let seq: Vec<(EventKind, usize)> = events
        .iter()
        .zip(mask)
        .filter(|(_, bounce)| !bounce)
        .map(|(e, _)| (e.kind, e.contact))
        .collect();
    let key = |e: &(EventKind, usize)| (e.0 as u8, e.1);
    let n = seq.len();
    let best = (0..n)
        .min_by(|&a, &b| {
            (0..n)
                .map(|i| key(&seq[(a + i) % n]))
                .cmp((0..n).map(|i| key(&seq[(b + i) % n])))
        })
        .unwrap_or(0);
    (0..n).map(|i| seq[(best + i) % n]).collect()
}
