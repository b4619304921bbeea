//! External forces on the masses (the constant `ChainParams::forces` and the time
//! polynomials of `Simulator::set_external_forces`) against truth from outside the engine:
//! the closed form of the damped oscillator at rest under a constant force, an independent
//! fixed-step RK4 integrator of the chain written here (impacts located by bisection on the
//! gap and resolved by Newton's law), contact forces computed by hand from Newton's second
//! law, and finite differences of the flow map for the state-transition matrix.

use crate::common;

use common::Lcg;
use common::fd::{compare_with_fd, compare_with_fd_prepared};
use vibrotribo::sensitivity::{Horizon, Sensitivity, SensitivityError, SensitivityOptions, flow_map};
use vibrotribo::{
    ChainParams, ChainState, ContactStatus, EventKind, EventLog, Excitation, ForcePolynomial, Frequency,
    SimOptions, Simulator, Stop, StopFrame, Stops, UniformSampler,
};

// ---------------------------------------------------------------------------------------
// The independent reference: every mass free, classical RK4, impacts by bisection.
// ---------------------------------------------------------------------------------------

/// Polynomial forces that hold from `.0` on (until the next entry): one per mass.
type Schedule = Vec<(f64, Vec<ForcePolynomial>)>;

/// An impact of the reference: time, contact, state just after.
#[derive(Debug, Clone)]
struct RefImpact {
    t: f64,
    contact: usize,
    x: Vec<f64>,
    v: Vec<f64>,
}

/// `m_i x_i'' = −c_i (x_i' − y') − k_i (x_i − y) + F_i + f_i(t)` for free masses, integrated
/// by classical RK4 with a fixed step (cut at the schedule's switching times); a gap that
/// turns negative within a step is located by bisection on the length of that step (each trial
/// one RK4 step from its start) and the impact resolved by Newton's law with momentum
/// conservation. Nothing here uses the closed form under test.
struct Reference<'a> {
    p: &'a ChainParams,
    schedule: &'a Schedule,
    h: f64,
    t: f64,
    /// The step grid: `t_base + j·h` (no accumulated rounding in time), restarted at every
    /// switch and impact.
    t_base: f64,
    steps: u64,
    x: Vec<f64>,
    v: Vec<f64>,
    impacts: Vec<RefImpact>,
}

impl<'a> Reference<'a> {
    fn new(p: &'a ChainParams, schedule: &'a Schedule, state: &ChainState, h: f64) -> Self {
        Reference {
            p,
            schedule,
            h,
            t: 0.0,
            t_base: 0.0,
            steps: 0,
            x: state.positions.clone(),
            v: state.velocities.clone(),
            impacts: Vec::new(),
        }
    }

    /// The schedule entry that holds from time `t` on.
    fn piece(&self, t: f64) -> Option<usize> {
        self.schedule.iter().rposition(|(s, _)| *s <= t)
    }

    fn accel(&self, piece: Option<usize>, t: f64, x: &[f64], v: &[f64], a: &mut [f64]) {
        let p = self.p;
        let w = p.omega();
        let amp = p.excitation.amplitude;
        let (y, yd) = (amp * (w * t).sin(), amp * w * (w * t).cos());
        for i in 0..x.len() {
            let mut f = -p.damping[i] * (v[i] - yd) - p.stiffness[i] * (x[i] - y) + p.force(i);
            if let Some(q) = piece.and_then(|j| self.schedule[j].1.get(i)) {
                f += q.value(t);
            }
            a[i] = f / p.masses[i];
        }
    }

    /// One RK4 step of length `h` from (`t`, `x`, `v`) with the forces of `piece`.
    fn step(&self, piece: Option<usize>, t: f64, x: &[f64], v: &[f64], h: f64) -> (Vec<f64>, Vec<f64>) {
        let n = x.len();
        let mut a1 = vec![0.0; n];
        let mut a2 = vec![0.0; n];
        let mut a3 = vec![0.0; n];
        let mut a4 = vec![0.0; n];
        self.accel(piece, t, x, v, &mut a1);
        let x2: Vec<f64> = (0..n).map(|i| x[i] + 0.5 * h * v[i]).collect();
        let v2: Vec<f64> = (0..n).map(|i| v[i] + 0.5 * h * a1[i]).collect();
        self.accel(piece, t + 0.5 * h, &x2, &v2, &mut a2);
        let x3: Vec<f64> = (0..n).map(|i| x[i] + 0.5 * h * v2[i]).collect();
        let v3: Vec<f64> = (0..n).map(|i| v[i] + 0.5 * h * a2[i]).collect();
        self.accel(piece, t + 0.5 * h, &x3, &v3, &mut a3);
        let x4: Vec<f64> = (0..n).map(|i| x[i] + h * v3[i]).collect();
        let v4: Vec<f64> = (0..n).map(|i| v[i] + h * a3[i]).collect();
        self.accel(piece, t + h, &x4, &v4, &mut a4);
        let xn = (0..n)
            .map(|i| x[i] + h / 6.0 * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]))
            .collect();
        let vn = (0..n)
            .map(|i| v[i] + h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]))
            .collect();
        (xn, vn)
    }

    /// The smallest gap and its contact.
    fn min_gap(&self, x: &[f64]) -> (f64, usize) {
        (0..x.len() - 1)
            .map(|k| (self.p.gaps[k] - (x[k + 1] - x[k]), k))
            .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a })
    }

    /// Integrates to `t_end`.
    fn advance_to(&mut self, t_end: f64) {
        while self.t < t_end {
            let piece = self.piece(self.t);
            let next_switch = self
                .schedule
                .iter()
                .map(|(s, _)| *s)
                .find(|&s| s > self.t)
                .unwrap_or(f64::INFINITY);
            let boundary = t_end.min(next_switch);
            let grid = self.t_base + (self.steps + 1) as f64 * self.h;
            let target = grid.min(boundary);
            let hs = target - self.t;
            let (xn, vn) = self.step(piece, self.t, &self.x, &self.v, hs);
            if self.min_gap(&xn).0 >= 0.0 {
                self.t = target;
                self.x = xn;
                self.v = vn;
                if target == grid {
                    self.steps += 1;
                }
                if target == next_switch {
                    (self.t_base, self.steps) = (target, 0);
                }
                continue;
            }
            // An impact within the step: bisection on the step length.
            let (mut lo, mut hi) = (0.0, hs);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                let (xm, _) = self.step(piece, self.t, &self.x, &self.v, mid);
                if self.min_gap(&xm).0 < 0.0 {
                    hi = mid
                } else {
                    lo = mid
                }
            }
            let (xi, mut vi) = self.step(piece, self.t, &self.x, &self.v, lo);
            let (xh, _) = self.step(piece, self.t, &self.x, &self.v, hi);
            let k = self.min_gap(&xh).1;
            let vc = vi[k + 1] - vi[k];
            assert!(
                vc > 0.0,
                "reference: a touch without closing speed at contact {k}"
            );
            let (m1, m2) = (self.p.masses[k], self.p.masses[k + 1]);
            let impulse = (1.0 + self.p.restitution) * vc * m1 * m2 / (m1 + m2);
            vi[k] += impulse / m1;
            vi[k + 1] -= impulse / m2;
            self.t += lo;
            (self.t_base, self.steps) = (self.t, 0);
            self.x = xi;
            self.v = vi;
            self.impacts.push(RefImpact {
                t: self.t,
                contact: k,
                x: self.x.clone(),
                v: self.v.clone(),
            });
        }
    }
}

/// The engine on the same schedule: its forces set at each switching time.
fn engine_run(p: &ChainParams, schedule: &Schedule, state: &ChainState, t_end: f64) -> (Simulator, EventLog) {
    let mut sim = Simulator::new(p, state, SimOptions::default()).unwrap();
    let mut log = EventLog::default();
    for (j, (start, forces)) in schedule.iter().enumerate() {
        if *start >= t_end {
            break;
        }
        sim.run_until(*start, &mut log).unwrap();
        sim.set_external_forces(forces).unwrap();
        let end = schedule.get(j + 1).map_or(t_end, |(s, _)| s.min(t_end));
        sim.run_until(end, &mut log).unwrap();
    }
    sim.run_until(t_end, &mut log).unwrap();
    (sim, log)
}

/// Degree-6 polynomials (as two-way coupling makes: the square of a cubic) on every mass,
/// one set per piece of length `piece` from 0 to `t_end`, with terms of about `size` N over
/// a piece.
fn random_schedule(rng: &mut Lcg, n: usize, piece: f64, t_end: f64, size: f64) -> Schedule {
    let mut out = Vec::new();
    let mut t = 0.0;
    while t < t_end {
        let forces = (0..n)
            .map(|_| {
                let c = (0..7).map(|j| rng.range(-size, size) / piece.powi(j)).collect();
                ForcePolynomial::new(t, c)
            })
            .collect();
        out.push((t, forces));
        t += piece;
    }
    out
}

fn default_with(f: impl FnOnce(&mut ChainParams)) -> ChainParams {
    let mut p = ChainParams::default();
    f(&mut p);
    p
}

// ---------------------------------------------------------------------------------------
// Static equilibrium under constant forces.
// ---------------------------------------------------------------------------------------

/// No excitation, constant forces, gaps too wide to close: a chain started at `x_i = F_i/k_i`
/// stays there, and one started at rest at 0 follows the closed form of the damped
/// oscillator, `x(t) = X [1 − e^{−αt}(cos ω_d t + (α/ω_d) sin ω_d t)]`, X = F/k, to
/// rounding.
#[test]
fn constant_forces_static_equilibrium_and_damped_approach() {
    let p = default_with(|p| {
        p.excitation.amplitude = 0.0;
        p.gaps = vec![0.1, 0.1];
        p.damping = vec![0.05, 0.3, 0.1];
        p.forces = vec![0.6, -0.4, 0.9];
    });
    let eq: Vec<f64> = (0..3).map(|i| p.forces[i] / p.stiffness[i]).collect();
    let t_end = 30.0 * p.period();
    // At equilibrium: stays to 1e-12 m.
    let start = ChainState {
        positions: eq.clone(),
        velocities: vec![0.0; 3],
    };
    let mut sim = Simulator::new(&p, &start, SimOptions::default()).unwrap();
    let mut sampler = UniformSampler::new(3, 0.0, p.period() / 7.0);
    let mut log = EventLog::default();
    sim.run_until(t_end, &mut (&mut sampler, &mut log)).unwrap();
    assert!(log.events.is_empty());
    for (j, x) in sampler.positions.chunks(3).enumerate() {
        for i in 0..3 {
            assert!(
                (x[i] - eq[i]).abs() <= 1e-12,
                "sample {j}, mass {i}: {} vs {}",
                x[i],
                eq[i]
            );
        }
    }
    // From rest at 0: the damped approach, each mass on its own.
    let mut sim = Simulator::new(&p, &ChainState::at_rest(3), SimOptions::default()).unwrap();
    let mut sampler = UniformSampler::new(3, 0.0, p.period() / 7.0);
    sim.run_until(t_end, &mut sampler).unwrap();
    for (j, (&t, x)) in sampler.times.iter().zip(sampler.positions.chunks(3)).enumerate() {
        for i in 0..3 {
            let alpha = p.damping[i] / (2.0 * p.masses[i]);
            let wd = (p.stiffness[i] / p.masses[i] - alpha * alpha).sqrt();
            let truth = eq[i] * (1.0 - (-alpha * t).exp() * ((wd * t).cos() + alpha / wd * (wd * t).sin()));
            assert!(
                (x[i] - truth).abs() <= 1e-12 * eq[i].abs(),
                "sample {j} (t = {t}), mass {i}: {} vs {truth}",
                x[i]
            );
        }
    }
    // ... and it converges: after 30 periods the most damped mass is within its envelope.
    let end = sim.state();
    let alpha = p.damping[1] / (2.0 * p.masses[1]);
    assert!((end.positions[1] - eq[1]).abs() < 2.0 * (-alpha * t_end).exp() * eq[1].abs());
    assert!((-alpha * t_end).exp() < 2e-3);
}

// ---------------------------------------------------------------------------------------
// Polynomial forcing against the independent integrator.
// ---------------------------------------------------------------------------------------

/// RK4 step of the reference, s: with ω_max = 50 rad/s its global error over a run is about
/// `(ω_max h)⁴ ω_max t ≈ 1e-14` relative, far below the tolerances asserted.
const H: f64 = 2e-6;

/// One free mass (its neighbour beyond a gap it never closes) under harmonic base motion and
/// polynomial forces that switch every 0.05 s: positions and velocities against RK4 at
/// every sample, to 1e-11 of the motion's scale (its largest displacement and speed): the
/// reference's own error is below 1e-13 of it (its end state moves by less than that between
/// steps of 8, 4, 2 and 1 µs), the closed form's rounding ~1e-15.
#[test]
fn polynomial_forcing_of_a_free_mass_matches_rk4() {
    let p = default_with(|p| {
        p.masses = vec![0.05, 0.1];
        p.stiffness = vec![120.0, 90.0];
        p.damping = vec![0.03, 0.01];
        p.gaps = vec![10.0];
        p.forces = vec![0.2, -0.1];
    });
    let mut rng = Lcg(17);
    let t_end = 0.6;
    let schedule = random_schedule(&mut rng, 2, 0.05, t_end, 0.8);
    let state = ChainState {
        positions: vec![0.003, -0.002],
        velocities: vec![0.1, 0.0],
    };
    let mut sim = Simulator::new(&p, &state, SimOptions::default()).unwrap();
    let mut reference = Reference::new(&p, &schedule, &state, H);
    let dt = 0.0137;
    let mut sampler = UniformSampler::new(2, 0.0, dt);
    for (j, (start, forces)) in schedule.iter().enumerate() {
        sim.run_until(*start, &mut sampler).unwrap();
        sim.set_external_forces(forces).unwrap();
        let end = schedule.get(j + 1).map_or(t_end, |(s, _)| *s);
        sim.run_until(end, &mut sampler).unwrap();
    }
    // Scales: the largest displacement and speed of the run.
    let scale_x = sampler.positions.iter().fold(0.0f64, |a, x| a.max(x.abs()));
    let scale_v = sampler.velocities.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let mut worst = (0.0f64, 0.0f64);
    for (j, &t) in sampler.times.iter().enumerate() {
        reference.advance_to(t);
        for i in 0..2 {
            let ex = (sampler.positions[2 * j + i] - reference.x[i]).abs() / scale_x;
            let ev = (sampler.velocities[2 * j + i] - reference.v[i]).abs() / scale_v;
            worst = (worst.0.max(ex), worst.1.max(ev));
            assert!(
                ex <= 1e-11 && ev <= 1e-11,
                "t = {t}, mass {i}: position error {ex:e}, velocity error {ev:e} (scaled)"
            );
        }
    }
    assert!(reference.impacts.is_empty());
    println!(
        "worst scaled errors: position {:.2e}, velocity {:.2e}",
        worst.0, worst.1
    );
}

/// The paper's three-mass chain with degree-6 polynomial forces on every mass, switched every
/// 0.04 s, and impacts: every impact (time, contact, state just after) against the reference.
/// Times to 1e-11 s (5e-11 of a period) and states to 1e-10 of their scales (20 mm, 1 m/s):
/// the reference's step error is ~1e-14 and its impact times are bisected to an ulp, but each
/// impact multiplies a difference by the ratio of accelerations to closing speeds, up to a
/// few hundred over the run, and the tolerance keeps that margin.
#[test]
fn polynomial_forcing_with_impacts_matches_rk4() {
    let p = ChainParams::default();
    let mut rng = Lcg(5);
    let t_end = 0.8;
    let schedule = random_schedule(&mut rng, 3, 0.04, t_end, 0.5);
    let state = ChainState {
        positions: vec![0.0, 0.01, 0.015],
        velocities: vec![-0.4, 0.3, 0.5],
    };
    let (_, log) = engine_run(&p, &schedule, &state, t_end);
    let mut reference = Reference::new(&p, &schedule, &state, H);
    reference.advance_to(t_end);
    let impacts: Vec<_> = log
        .events
        .iter()
        .take_while(|e| e.event.kind == EventKind::Impact)
        .collect();
    assert!(
        impacts.len() == log.events.len(),
        "the run should have impacts only: {:?}",
        log.events.iter().map(|e| e.event.kind).collect::<Vec<_>>()
    );
    assert!(impacts.len() >= 8, "only {} impacts", impacts.len());
    assert_eq!(impacts.len(), reference.impacts.len(), "impact counts differ");
    let (scale_x, scale_v) = (0.02, 1.0);
    let mut worst = (0.0f64, 0.0f64);
    for (e, r) in impacts.iter().zip(&reference.impacts) {
        assert_eq!(e.event.contact, r.contact, "contact of the impact at {}", r.t);
        let dt = (e.event.time - r.t).abs();
        let mut ds = 0.0f64;
        for i in 0..3 {
            ds = ds.max((e.positions[i] - r.x[i]).abs() / scale_x);
            ds = ds.max((e.velocities[i] - r.v[i]).abs() / scale_v);
        }
        worst = (worst.0.max(dt), worst.1.max(ds));
        assert!(dt <= 1e-11, "impact at {}: time differs by {dt:e} s", r.t);
        assert!(ds <= 1e-10, "impact at {}: state differs by {ds:e} (scaled)", r.t);
    }
    println!(
        "{} impacts; worst time difference {:.2e} s, worst scaled state difference {:.2e}",
        impacts.len(),
        worst.0,
        worst.1
    );
}

// ---------------------------------------------------------------------------------------
// Sticking and rigid stops under pressing forces.
// ---------------------------------------------------------------------------------------

/// Two masses touching (gap 0 at x = (0, δ)), pressed together by opposite constant forces
/// (down on the top one, up on the bottom one), with a common downward velocity and no
/// excitation: they start stuck, and the cluster swings down until the contact force
/// `N = m₁ (a_G − a₁)` falls to zero. With the cluster coordinate s (top mass) on its closed
/// form `M s'' + C s' + K s = F₁ + F₂ − k₂δ`,
///
/// `N(t) = (m₁/M)(F₁ + F₂ − C s' − K s − k₂δ) − (F₁ − c₁ s' − k₁ s)`,
///
/// and the release is its first zero, found here by bisection.
#[test]
fn pressing_forces_stick_and_release_at_the_hand_computed_time() {
    let (m1, m2, k1, k2, c1, c2, delta) = (0.1, 0.2, 100.0, 100.0, 0.02, 0.01, 0.01);
    let (f1, f2) = (-1.0, 1.0);
    let p = ChainParams {
        masses: vec![m1, m2],
        stiffness: vec![k1, k2],
        damping: vec![c1, c2],
        gaps: vec![delta],
        excitation: Excitation {
            amplitude: 0.0,
            frequency: Frequency::Hertz(3.0),
        },
        forces: vec![f1, f2],
        ..ChainParams::default()
    };
    let v0 = -0.5;
    let state = ChainState {
        positions: vec![0.0, delta],
        velocities: vec![v0, v0],
    };
    let mut sim = Simulator::new(&p, &state, SimOptions::default()).unwrap();
    assert_eq!(sim.contact_status(), vec![ContactStatus::Stuck]);
    let mut log = EventLog::default();
    sim.run_until(1.0, &mut log).unwrap();
    let first = &log.events[0].event;
    assert_eq!(first.kind, EventKind::Release);
    // The closed form of the damped cluster.
    let (m, c, k) = (m1 + m2, c1 + c2, k1 + k2);
    let s_eq = (f1 + f2 - k2 * delta) / k;
    let alpha = c / (2.0 * m);
    let wd = (k / m - alpha * alpha).sqrt();
    let (a0, b0) = (0.0 - s_eq, (v0 + alpha * (0.0 - s_eq)) / wd);
    let motion = |t: f64| {
        let e = (-alpha * t).exp();
        let (sn, cs) = (wd * t).sin_cos();
        let s = s_eq + e * (a0 * cs + b0 * sn);
        let v = e * ((-alpha * a0 + wd * b0) * cs + (-alpha * b0 - wd * a0) * sn);
        (s, v)
    };
    let force = |t: f64| {
        let (s, v) = motion(t);
        m1 / m * (f1 + f2 - c * v - k * s - k2 * delta) - (f1 - c1 * v - k1 * s)
    };
    let truth = first_zero(force, 0.0, 1.0);
    assert!(
        (first.time - truth).abs() <= 1e-12,
        "release at {} s, by hand {truth} s",
        first.time
    );
}

/// The same pair at rest and pressed, pulled apart by a polynomial force on the bottom mass,
/// `f₂(t) = −b t − e t²`: the release where `N` (as above, with `f₂` in the cluster's force)
/// falls to zero, the cluster's motion from the test's RK4 (step 1e-6 s; the root bisected on
/// single steps) — the time to 1e-10 s.
#[test]
fn polynomial_pull_releases_a_stuck_pair_at_the_hand_computed_time() {
    let (m1, m2, k1, k2, c1, c2, delta) = (0.1, 0.2, 100.0, 100.0, 0.02, 0.01, 0.01);
    let (f1, f2) = (-1.0, 1.0);
    let (b, e) = (3.0, 4.0);
    let p = ChainParams {
        masses: vec![m1, m2],
        stiffness: vec![k1, k2],
        damping: vec![c1, c2],
        gaps: vec![delta],
        excitation: Excitation {
            amplitude: 0.0,
            frequency: Frequency::Hertz(3.0),
        },
        forces: vec![f1, f2],
        ..ChainParams::default()
    };
    let state = ChainState {
        positions: vec![0.0, delta],
        velocities: vec![0.0, 0.0],
    };
    let mut sim = Simulator::new(&p, &state, SimOptions::default()).unwrap();
    assert_eq!(sim.contact_status(), vec![ContactStatus::Stuck]);
    sim.set_external_forces(&[
        ForcePolynomial::zero(),
        ForcePolynomial::new(0.0, vec![0.0, -b, -e]),
    ])
    .unwrap();
    let mut log = EventLog::default();
    sim.run_until(2.0, &mut log).unwrap();
    let first = &log.events[0].event;
    assert_eq!(first.kind, EventKind::Release);
    // The stuck pair as one body, integrated by RK4.
    let (m, c, k) = (m1 + m2, c1 + c2, k1 + k2);
    let g = |t: f64| -b * t - e * t * t;
    let acc = |t: f64, s: f64, v: f64| (f1 + f2 + g(t) - c * v - k * s - k2 * delta) / m;
    let step = |t: f64, s: f64, v: f64, h: f64| {
        let (k1s, k1v) = (v, acc(t, s, v));
        let (k2s, k2v) = (
            v + 0.5 * h * k1v,
            acc(t + 0.5 * h, s + 0.5 * h * k1s, v + 0.5 * h * k1v),
        );
        let (k3s, k3v) = (
            v + 0.5 * h * k2v,
            acc(t + 0.5 * h, s + 0.5 * h * k2s, v + 0.5 * h * k2v),
        );
        let (k4s, k4v) = (v + h * k3v, acc(t + h, s + h * k3s, v + h * k3v));
        (
            s + h / 6.0 * (k1s + 2.0 * k2s + 2.0 * k3s + k4s),
            v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v),
        )
    };
    let force = |t: f64, s: f64, v: f64| {
        m1 / m * (f1 + f2 + g(t) - c * v - k * s - k2 * delta) - (f1 - c1 * v - k1 * s)
    };
    let h = 1e-6;
    let (mut t, mut s, mut v) = (0.0, 0.0, 0.0);
    assert!(force(0.0, 0.0, 0.0) > 0.0);
    let truth = loop {
        let (s1, v1) = step(t, s, v, h);
        if force(t + h, s1, v1) <= 0.0 {
            let root = first_zero(
                |tau| {
                    let (sx, vx) = step(t, s, v, tau);
                    force(t + tau, sx, vx)
                },
                0.0,
                h,
            );
            break t + root;
        }
        (t, s, v) = (t + h, s1, v1);
        assert!(t < 2.0, "no release by hand");
    };
    assert!(
        (first.time - truth).abs() <= 1e-10,
        "release at {} s, by hand {truth} s",
        first.time
    );
}

/// One mass on a lower stop fixed in space (gap g), pressed onto it by a constant force F and
/// pulled off by a polynomial force f(t) (or by the base motion alone): the stop's force
/// `λ = −(c y' + k (g + y) + F + f(t))` (Newton's second law of the mass at rest on the stop,
/// `x = −g`) falls to zero at the release, found here by bisection.
#[test]
fn a_mass_stuck_to_a_stop_releases_at_the_hand_computed_time() {
    let (m, k, c, g, amp) = (0.1, 100.0, 0.05, 0.01, 0.005);
    for (force, ramp) in [(-1.3, 0.0), (-2.0, 4.0)] {
        let p = ChainParams {
            masses: vec![m],
            stiffness: vec![k],
            damping: vec![c],
            gaps: vec![],
            excitation: Excitation {
                amplitude: amp,
                frequency: Frequency::Hertz(5.0),
            },
            stops: Stops {
                upper: None,
                lower: Some(Stop {
                    gap: g,
                    restitution: 0.5,
                    frame: StopFrame::Fixed,
                }),
            },
            forces: vec![force],
            ..ChainParams::default()
        };
        let state = ChainState {
            positions: vec![-g],
            velocities: vec![0.0],
        };
        let mut sim = Simulator::new(&p, &state, SimOptions::default()).unwrap();
        assert_eq!(sim.contact_status()[0], ContactStatus::Stuck, "F = {force}");
        if ramp != 0.0 {
            sim.set_external_forces(&[ForcePolynomial::new(0.0, vec![0.0, ramp])])
                .unwrap();
        }
        let mut log = EventLog::default();
        sim.run_until(1.0, &mut log).unwrap();
        let first = &log.events[0].event;
        assert_eq!(
            (first.kind, first.contact),
            (EventKind::Release, 0),
            "F = {force}"
        );
        let w = p.omega();
        let lambda = |t: f64| {
            let (y, yd) = (amp * (w * t).sin(), amp * w * (w * t).cos());
            -(c * yd + k * (g + y) + force + ramp * t)
        };
        let truth = first_zero(lambda, 0.0, 1.0);
        assert!(
            (first.time - truth).abs() <= 1e-12,
            "F = {force}, ramp {ramp}: release at {} s, by hand {truth} s",
            first.time
        );
    }
}

/// The first zero of `f` (positive at `a`) in `[a, b]`: a scan on 10⁵ points, then bisection
/// to the last ulp.
fn first_zero(f: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let n = 100_000;
    let mut lo = a;
    for i in 1..=n {
        let t = a + (b - a) * i as f64 / n as f64;
        if f(t) <= 0.0 {
            let mut hi = t;
            while hi - lo > 0.0 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if f(mid) > 0.0 { lo = mid } else { hi = mid }
            }
            return 0.5 * (lo + hi);
        }
        lo = t;
    }
    panic!("no zero in [{a}, {b}]");
}

// ---------------------------------------------------------------------------------------
// State-transition matrix.
// ---------------------------------------------------------------------------------------

/// Φ of runs with constant forces (through `flow_map`) and with polynomial forces set before
/// the run (through the `Sensitivity` observer) against Richardson-extrapolated central
/// differences of the flow map (tests/suite/common/fd.rs), on random chains with impacts, sticking
/// and chatter; the same acceptance as the tests without forces.
#[test]
fn stm_with_external_forces_matches_finite_differences() {
    let mut rng = Lcg(2024);
    let (mut compared_const, mut compared_poly, mut events) = (0, 0, 0);
    for s in 0..24 {
        let n = 2 + s % 3;
        let mu = rng.range(0.3, 0.9);
        let (mut params, state) = common::random_chain(&mut rng, n, mu);
        params.forces = (0..n).map(|_| rng.range(-0.5, 0.5)).collect();
        let horizon = Horizon::Periods(1 + (s % 2) as u32);
        // Constant forces.
        match flow_map(
            &params,
            &state,
            horizon,
            &SimOptions::default(),
            &SensitivityOptions::default(),
        ) {
            Ok(map) => {
                if let Some(cmp) = compare_with_fd(&params, &state, horizon, &map.stm, &map.events, 1e-6) {
                    assert!(
                        cmp.error <= 2e-7 + 3.0 * cmp.fd_uncertainty,
                        "sample {s} (constant forces): Φ differs from finite differences by {:.3e} \
                         (their uncertainty {:.3e})\n{params:?}\n{state:?}",
                        cmp.error,
                        cmp.fd_uncertainty
                    );
                    compared_const += 1;
                    events += map.events.len();
                }
            }
            Err(SensitivityError::NonSmooth(_)) => {}
            Err(e) => panic!("sample {s}: {e}"),
        }
        // Polynomial forces from t = 0 (degree 6, terms of about 0.5 N over a period).
        let period = params.period();
        let polys: Vec<ForcePolynomial> = (0..n)
            .map(|_| {
                ForcePolynomial::new(
                    0.0,
                    (0..7).map(|j| rng.range(-0.5, 0.5) / period.powi(j)).collect(),
                )
            })
            .collect();
        let prepare = |sim: &mut Simulator| sim.set_external_forces(&polys).ok();
        let mut sim = Simulator::new(&params, &state, SimOptions::default()).unwrap();
        prepare(&mut sim).unwrap();
        let options = SensitivityOptions {
            record_events: true,
            ..SensitivityOptions::default()
        };
        let mut sens = Sensitivity::for_simulator(&sim, options);
        sim.run_until(horizon.end_time(&params), &mut sens).unwrap();
        let Ok(phi) = sens.stm() else { continue };
        let run_events: Vec<_> = sens.events().iter().map(|e| e.event).collect();
        if let Some(cmp) =
            compare_with_fd_prepared(&params, &state, horizon, phi, &run_events, 1e-6, &prepare)
        {
            assert!(
                cmp.error <= 2e-7 + 3.0 * cmp.fd_uncertainty,
                "sample {s} (polynomial forces): Φ differs from finite differences by {:.3e} \
                 (their uncertainty {:.3e})\n{params:?}\n{state:?}\n{polys:?}",
                cmp.error,
                cmp.fd_uncertainty
            );
            compared_poly += 1;
            events += run_events.len();
        }
    }
    println!("compared {compared_const} (constant) + {compared_poly} (polynomial) runs, {events} events");
    assert!(
        compared_const >= 12 && compared_poly >= 12,
        "{compared_const} / {compared_poly} compared"
    );
    assert!(events >= 50, "only {events} events");
}

// ---------------------------------------------------------------------------------------
// Validation and configuration.
// ---------------------------------------------------------------------------------------

#[test]
fn bad_forces_are_refused_with_their_names() {
    let p = default_with(|p| p.forces = vec![0.1, 0.2]);
    assert!(p.validate().unwrap_err().to_string().contains("forces"));
    let p = default_with(|p| p.forces = vec![0.1, f64::NAN, 0.0]);
    assert!(p.validate().unwrap_err().to_string().contains("forces[1]"));
    let p = ChainParams::default();
    let mut sim = Simulator::new(&p, &ChainState::at_rest(3), SimOptions::default()).unwrap();
    let z = ForcePolynomial::zero();
    let err = sim.set_external_forces(&[z.clone(), z.clone()]).unwrap_err();
    assert!(err.to_string().contains("forces"), "{err}");
    let high = ForcePolynomial::new(0.0, vec![1.0; vibrotribo::model::MAX_FORCE_DEGREE + 2]);
    let err = sim
        .set_external_forces(&[z.clone(), high, z.clone()])
        .unwrap_err();
    assert!(err.to_string().contains("forces[1].coefficients"), "{err}");
    let nan = ForcePolynomial::new(0.0, vec![1.0, 0.0, f64::INFINITY]);
    let err = sim.set_external_forces(&[z.clone(), z.clone(), nan]).unwrap_err();
    assert!(err.to_string().contains("forces[2].coefficients[2]"), "{err}");
    // A refused call leaves the simulator as it was, and a clear is always possible.
    assert_eq!(sim.external_force(1, 0.3), 0.0);
    sim.set_external_forces(&[z.clone(), ForcePolynomial::new(0.0, vec![1.0, 2.0]), z])
        .unwrap();
    assert_eq!(sim.external_force(1, 0.5), 2.0);
    sim.clear_external_forces().unwrap();
    assert_eq!(sim.external_force(1, 0.5), 0.0);
}

#[test]
fn config_key_oscillator_forces() {
    use vibrotribo::config::Config;
    let c = Config::from_toml_str("[oscillator]\nforces = [-0.47, -1.18, -0.47]\n").unwrap();
    assert_eq!(c.chain().forces, vec![-0.47, -1.18, -0.47]);
    let c = Config::from_toml_str("[oscillator]\nforces = -0.5\n").unwrap();
    assert_eq!(c.chain().forces, vec![-0.5; 3]);
    let mut c = Config::default();
    c.set("oscillator.forces[1]", 0.25.into()).unwrap();
    assert_eq!(c.chain().forces, vec![0.0, 0.25, 0.0]);
    let err = Config::from_toml_str("[oscillator]\nforces = [1.0, 2.0]\n").unwrap_err();
    assert!(err.to_string().contains("oscillator.forces"), "{err}");
    assert!(Config::default().chain().forces.is_empty());
}
