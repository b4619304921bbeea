//! Orbits with a prescribed sequence of impacts by multiple shooting in the impact times.
//!
//! The stroboscopic map has a square-root singularity at a grazing: the time of an impact
//! whose closing speed `v` is small moves like `1/v` with the state, so Newton's method on
//! the map, started from the grazing orbit, crawls towards it (its residual falls by 1/√2 an
//! iteration) instead of converging to the orbit with the new impact. Taking the impact
//! times as unknowns removes the singularity: the state at `t_i` is a smooth function of the
//! start state and of `t_i`, the gap there is a smooth function of both, and an impact of
//! closing speed zero is a regular point of the system
//!
//! ```text
//! d_{k_i}(x(t_i⁻)) = 0   (i = 1 … m),      x(t₀ + PT) − x(t₀) = 0,
//! ```
//!
//! with the free flight between the impacts and the impact law at each `t_i` (as in COCO's
//! `hspo`, whose segments are the same). Its solution is an orbit of the non-smooth system
//! only if every prescribed impact closes (speed ≥ 0) and no gap opens below zero between
//! them; the caller checks that by running the orbit's flow through the event search, which
//! this module does not replace: it only supplies the start state.
//!
//! The Jacobian is taken by forward differences of the closed-form flow (accurate to about
//! 1e-8 of the scales); Newton's method with it converges linearly at a rate far below one,
//! to the rounding of the flow.

use nalgebra::{DMatrix, DVector};

use crate::dynamics::Simulator;
use crate::model::{ChainParams, Contact, SimOptions, Stop, StopFrame, StopSide, Stops};
use crate::orbits::map::Scale;
use crate::sensitivity::{Sensitivity, state_from_vector, state_vector};

/// Converged when the scaled residual is at most this.
const TOLERANCE: f64 = 1e-12;

/// Below [`TOLERANCE`], Newton's method goes on while it still gains, down to this: a gap
/// left at an impact of closing speed `v` moves the impact by `gap/v` and the state after it
/// by about `a·gap/v` (`a` the acceleration), so the slow impacts next to a grazing need the
/// gaps far below the tolerance for the stroboscopic map to confirm the orbit.
const ROUNDING: f64 = 1e-16;

/// Newton iterations allowed.
const MAX_ITERATIONS: usize = 30;

/// Forward-difference step, in the scaled unknowns.
const DIFFERENCE: f64 = 1e-7;

/// Halvings of a Newton step in its line search.
const HALVINGS: usize = 12;

/// A prescribed impact: contact and time, s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Impact {
    pub contact: usize,
    pub time: f64,
}

/// The chain's free flight: the same masses, springs, dampers, forces and base motion with
/// every contact a million length scales open (stops kept so far off, since a single mass
/// needs one to be a valid chain).
fn free_flight(params: &ChainParams, scale: &Scale) -> ChainParams {
    let far = 1e6 * scale.length;
    let away = |s: &Option<Stop>| s.map(|s| Stop { gap: far, ..s });
    ChainParams {
        gaps: vec![far; params.gaps.len()],
        stops: Stops {
            upper: away(&params.stops.upper),
            lower: away(&params.stops.lower),
        },
        ..params.clone()
    }
}

/// The system of the module docs for `params`, over `duration` from t = `phase`.
struct Segments<'a> {
    params: &'a ChainParams,
    free: ChainParams,
    scale: Scale,
    contacts: Vec<usize>,
    phase: f64,
    duration: f64,
    sim: &'a SimOptions,
}

impl Segments<'_> {
    fn n(&self) -> usize {
        self.params.len()
    }

    /// The state at `t1` from `z` at `t0` by the free flight (`t1 ≥ t0`).
    fn fly(&self, z: &DVector<f64>, t0: f64, t1: f64) -> Option<DVector<f64>> {
        if t1 <= t0 {
            return (t1 == t0).then(|| z.clone());
        }
        let mut run =
            Simulator::new_at(&self.free, t0, &state_from_vector(z.as_slice()), self.sim.clone()).ok()?;
        run.run_until(t1, &mut None::<Sensitivity>).ok()?;
        Some(state_vector(&run.state()))
    }

    /// Position and velocity of a stop's frame at `t`, m and m/s.
    fn frame(&self, frame: StopFrame, t: f64) -> (f64, f64) {
        let w = self.params.omega();
        let a = self.params.excitation.amplitude;
        let (s, c) = (w * t.rem_euclid(self.params.period())).sin_cos();
        let [y, yd, ..] = ChainParams::frame_motion(frame, a * s, a * w * c, w);
        (y, yd)
    }

    /// The gap of `contact` in state `z` at `t`, m, and its rate, m/s.
    fn gap(&self, contact: usize, z: &DVector<f64>, t: f64) -> Option<(f64, f64)> {
        let n = self.n();
        match self.params.contact(contact) {
            Contact::Masses(k) => Some((self.params.gaps[k] - (z[k + 1] - z[k]), z[n + k] - z[n + k + 1])),
            Contact::Stop(side) => {
                let stop = self.params.stops.get(side)?;
                let (y, yd) = self.frame(stop.frame, t);
                Some(match side {
                    StopSide::Upper => (stop.gap - (z[0] - y), yd - z[n]),
                    StopSide::Lower => (stop.gap - (y - z[n - 1]), z[2 * n - 1] - yd),
                })
            }
        }
    }

    /// The state just after an impact at `contact` from `z` just before it, at `t`: the
    /// closing velocity reversed times the restitution, momentum kept between two masses.
    fn strike(&self, contact: usize, z: &DVector<f64>, t: f64) -> Option<DVector<f64>> {
        let n = self.n();
        let r = self.params.contact_restitution(contact);
        let mut after = z.clone();
        match self.params.contact(contact) {
            Contact::Masses(k) => {
                let (m1, m2) = (self.params.masses[k], self.params.masses[k + 1]);
                let (v1, v2) = (z[n + k], z[n + k + 1]);
                let p = m1 * v1 + m2 * v2;
                let w = -r * (v2 - v1);
                after[n + k] = (p - m2 * w) / (m1 + m2);
                after[n + k + 1] = after[n + k] + w;
            }
            Contact::Stop(side) => {
                let stop = self.params.stops.get(side)?;
                let (_, yd) = self.frame(stop.frame, t);
                let i = match side {
                    StopSide::Upper => n,
                    StopSide::Lower => 2 * n - 1,
                };
                after[i] = yd - r * (z[i] - yd);
            }
        }
        Some(after)
    }

    /// The unknowns in scaled form: the start state, then the impact times in periods.
    fn pack(&self, z: &DVector<f64>, times: &[f64]) -> DVector<f64> {
        let n = self.n();
        let period = self.params.period();
        DVector::from_iterator(
            2 * n + times.len(),
            (0..2 * n)
                .map(|i| z[i] / self.scale.of_component(i, n))
                .chain(times.iter().map(|t| (t - self.phase) / period)),
        )
    }

    fn unpack(&self, u: &DVector<f64>) -> (DVector<f64>, Vec<f64>) {
        let n = self.n();
        let period = self.params.period();
        let z = DVector::from_fn(2 * n, |i, _| u[i] * self.scale.of_component(i, n));
        let times = u.iter().skip(2 * n).map(|s| self.phase + s * period).collect();
        (z, times)
    }

    /// The scaled residual at `u`, and the closing speed of each impact (m/s); `None` if the
    /// times are out of order or outside the period.
    fn residual(&self, u: &DVector<f64>) -> Option<(DVector<f64>, Vec<f64>)> {
        let n = self.n();
        let (z, times) = self.unpack(u);
        let end = self.phase + self.duration;
        if times.windows(2).any(|w| w[1] < w[0]) || times.iter().any(|&t| t <= self.phase || t >= end) {
            return None;
        }
        let mut r = DVector::zeros(u.len());
        let mut speeds = Vec::with_capacity(times.len());
        let (mut state, mut t) = (z.clone(), self.phase);
        for (i, (&contact, &ti)) in self.contacts.iter().zip(&times).enumerate() {
            state = self.fly(&state, t, ti)?;
            let (gap, rate) = self.gap(contact, &state, ti)?;
            r[2 * n + i] = gap / self.scale.length;
            speeds.push(-rate);
            state = self.strike(contact, &state, ti)?;
            t = ti;
        }
        state = self.fly(&state, t, end)?;
        for i in 0..2 * n {
            r[i] = (state[i] - z[i]) / self.scale.of_component(i, n);
        }
        Some((r, speeds))
    }
}

/// The start state at t = `phase` of an orbit of `params` over `duration` (s) with the
/// impacts `impacts` (in time order, within the period), from `z` and the impacts' times as
/// guesses: multiple shooting in the impact times (module docs), with the impacts at the
/// times found. `None` if Newton's method does not converge or an impact it finds does not
/// close.
pub(super) fn shoot(
    params: &ChainParams,
    z: &DVector<f64>,
    impacts: &[Impact],
    (phase, duration): (f64, f64),
    scale: &Scale,
    sim: &SimOptions,
) -> Option<(DVector<f64>, Vec<Impact>)> {
    let system = Segments {
        params,
        free: free_flight(params, scale),
        scale: *scale,
        contacts: impacts.iter().map(|i| i.contact).collect(),
        phase,
        duration,
        sim,
    };
    let times: Vec<f64> = impacts.iter().map(|i| i.time).collect();
    let mut u = system.pack(z, &times);
    let (mut r, mut speeds) = system.residual(&u)?;
    for _ in 0..MAX_ITERATIONS {
        let norm = r.amax();
        if norm <= ROUNDING {
            break;
        }
        let mut jacobian = DMatrix::zeros(u.len(), u.len());
        for j in 0..u.len() {
            let mut moved = u.clone();
            moved[j] += DIFFERENCE;
            let (rj, _) = system.residual(&moved)?;
            jacobian.set_column(j, &((rj - &r) / DIFFERENCE));
        }
        let step = jacobian.lu().solve(&(-&r))?;
        let mut damping = 1.0;
        let mut accepted = None;
        for _ in 0..HALVINGS {
            let trial = &u + &step * damping;
            if let Some((rt, st)) = system.residual(&trial)
                && rt.amax() < norm
            {
                accepted = Some((trial, rt, st));
                break;
            }
            damping *= 0.5;
        }
        match accepted {
            Some(next) => (u, r, speeds) = next,
            None if norm <= TOLERANCE => break,
            None => return None,
        }
    }
    if r.amax() > TOLERANCE || speeds.iter().any(|&v| v < 0.0) {
        return None;
    }
    let (z, times) = system.unpack(&u);
    let found = impacts
        .iter()
        .zip(times)
        .map(|(i, time)| Impact {
            contact: i.contact,
            time,
        })
        .collect();
    Some((z, found))
}

#[cfg(test)]
mod tests {
    //! The impact oscillator's (1,1) orbit by [`shoot`] from a guess a thousandth of the
    //! scales and of the period off, against the orbit the engine's own event search and
    //! shooting find (a single mass: its free flight keeps its stop, far off).

    use super::{Impact, shoot};
    use crate::dynamics::{EventKind, EventLog, Simulator};
    use crate::model::{ChainParams, ChainState, Excitation, Frequency, SimOptions, Stop, StopFrame, Stops};
    use crate::orbits::map::Scale;
    use crate::orbits::{ShootingOptions, periodic_orbit_from_transient};
    use crate::sensitivity::state_vector;

    /// 50 g on 120 N/m, c = 0.02 N·s/m, base amplitude 10 mm at `omega_ratio`, a stop fixed
    /// 1 mm above, r = 0.8.
    fn oscillator(omega_ratio: f64) -> ChainParams {
        ChainParams {
            masses: vec![0.05],
            stiffness: vec![120.0],
            damping: vec![0.02],
            gaps: vec![],
            restitution: 0.5,
            excitation: Excitation {
                amplitude: 0.01,
                frequency: Frequency::OmegaRatio(omega_ratio),
            },
            stops: Stops {
                upper: Some(Stop {
                    gap: 0.001,
                    restitution: 0.8,
                    frame: StopFrame::Fixed,
                }),
                lower: None,
            },
            forces: Vec::new(),
        }
    }

    #[test]
    fn the_impact_oscillators_one_one_orbit_is_the_engines() {
        let params = oscillator(2.7);
        let orbit = periodic_orbit_from_transient(
            &params,
            &ChainState::at_rest(1),
            300,
            Some(1),
            &ShootingOptions::default(),
        )
        .expect("the (1,1) orbit");
        let mut log = EventLog::default();
        let mut run = Simulator::new(&params, &orbit.state, SimOptions::default()).unwrap();
        run.run_until(params.period(), &mut log).unwrap();
        let impacts: Vec<Impact> = log
            .events
            .iter()
            .filter(|e| e.event.kind == EventKind::Impact)
            .map(|e| Impact {
                contact: e.event.contact,
                time: e.event.time,
            })
            .collect();
        assert_eq!(impacts.len(), 1, "one impact a period: {impacts:?}");
        let scale = Scale::of(&params);
        let z = state_vector(&orbit.state);
        let guess = &z + nalgebra::DVector::from_vec(vec![1e-3 * scale.length, -1e-3 * scale.speed]);
        let late = [Impact {
            time: impacts[0].time + 1e-3 * params.period(),
            ..impacts[0]
        }];
        let sim = SimOptions::default();
        let (shot, found) =
            shoot(&params, &guess, &late, (0.0, params.period()), &scale, &sim).expect("converges");
        assert!(scale.norm(&(&shot - &z)) < 1e-9, "{shot} against {z}");
        assert!((found[0].time - impacts[0].time).abs() < 1e-9 * params.period());
    }
}
