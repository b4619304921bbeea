//! The engine under band-limited random base motion against an exact identity
//! from outside the code: the mechanical energy balance
//!
//! ```text
//! E(t_end) − E(0) = W_base − D_damping − L_events
//! ```
//!
//! **The identity.** Every spring k_i and dashpot c_i of mass i connects it to the base
//! (docs/MODEL.md §1), and x_i is the *absolute* displacement of mass i from its static
//! position (the engine reports absolute positions: `m_i x_i'' + c_i (x_i' − y') + k_i (x_i −
//! y) = 0` away from contact). With no constant forces and no stops, the energy of the chain
//! relative to the base's springs is
//!
//! ```text
//! E = Σ ½ m_i v_i² + ½ k_i (x_i − y)².
//! ```
//!
//! Between events m_i v_i' = f_i + N_i, with f_i = −k_i (x_i − y) − c_i (v_i − y') the force
//! of mass i's connector and N_i the contact forces of a stuck (or resting, or chattering)
//! cluster, which act between masses with equal velocities and so do no work in total
//! (Σ N_i v_i = v_G Σ N_i = 0). Then
//!
//! ```text
//! dE/dt = Σ m_i v_i v_i' + k_i (x_i − y)(v_i − y')
//!       = Σ f_i v_i + Σ k_i (x_i − y)(v_i − y')
//!       = Σ f_i v_i − Σ [f_i + c_i (v_i − y')] (v_i − y')         (k_i (x_i − y) = −f_i − c_i (v_i − y'))
//!       = Σ f_i y' − Σ c_i (v_i − y')²,
//! ```
//!
//! so over the run W_base = ∫ Σ f_i y' dt is the work the base does on the chain (it moves the
//! connectors' base ends with velocity y' against the reaction −f_i), D_damping =
//! ∫ Σ c_i (v_i − y')² dt ≥ 0 what the dashpots dissipate, and at each event the energy
//! changes by a jump (positions are continuous, velocities jump) whose sum is L_events: the
//! kinetic energy that Newton's restitution law removes at an impact, the one removed by
//! merging the two sides of a chatter tail (done at the impact that starts the jump to the
//! accumulation point), and nothing (up to rounding) at a stick (zero relative velocity), a
//! release or a resting contact.
//!
//! **What is measured.** A [`RunObserver`] receives every piece of exact flow and every event
//! of `study::simulate`. W and D are Gauss–Legendre quadratures (12 nodes, exact to degree 23)
//! of the closed-form state [`Flow::state_at`] and of the base spline itself (the displacement
//! the engine is driven by, evaluated here on its own pieces): each flow piece is split at
//! every spline knot (y''' jumps there) and into sub-intervals of at most 0.5/ω_max, ω_max
//! twice the highest angular frequency of the chain and of the band (products of terms), where
//! the quadrature's relative error is below 1e-40 (each piece is exponentials × sines ×
//! polynomials of degree ≤ 6). The state before an event is the preceding flow's state at
//! its end, the one after is the event's [`StateView`]; events at one instant share that
//! state, so the first of them carries the whole jump. Any change of state between the end of
//! one piece of flow and the start of the next that no event reports (a knot, a period
//! boundary, a rounding-level touch) is accumulated separately and must be rounding noise.
//!
//! **Tolerance.** The issue asks the balance to close "to about 1e-8 of the base work"; the
//! residual is measured against Σ|terms| = |W| + D + |L| + |ΔE| (about twice |W|) and must be
//! below 1e-8 of it. Measured (`cargo test --test suite excitation_energy -- --nocapture`): 4e-15
//! to 6e-14 over 10⁴–10⁵ quadrature intervals and hundreds to thousands of events, so the
//! tolerance leaves a wide margin for rounding and none for a lost force or a wrong impact
//! law. The same runs' bookkeeping with deliberate errors misses by far more: the restitution
//! coefficient off by 1e-4 in the impact losses (≈5e-5), the c_i y' half of the base force
//! left out (≈6e-3), and, driving the simulator here, the base force of one spline interval
//! of 0.17 ms left out (≈3e-5). Not everything is visible at 1e-8: the kinetic energy merged
//! away at the start of a chatter jump is ~1e-12 of the terms (the jump is taken only once
//! the rebounds are tiny), and a force update missed at one knot (the previous cubic held
//! over the next 0.17 ms) changes the force by ~1e-11 of it, within the spline's own error.
//! What sticking and chatter contribute here is the flow of the stuck clusters (0.37 s of
//! the random chatter-chain run), whose contact forces must do no work.

use std::f64::consts::TAU;

use vibrotribo::config::Config;
use vibrotribo::dynamics::driven_chain;
use vibrotribo::excitation::PiecewiseCubic;
use vibrotribo::study::{RunObserver, RunSpec, simulate};
use vibrotribo::{
    ChainParams, Event, EventKind, Flow, ForcePolynomial, Observer, RunEnd, Simulator, StateView,
};

use crate::common;
use common::base_motion::Base;
use common::quadrature::{Sum, gauss_legendre};

/// Relative tolerance of the balance (of Σ|terms|), as the issue states it.
const TOLERANCE: f64 = 1e-8;

/// Gauss–Legendre nodes per quadrature interval.
const NODES: usize = 12;

/// A state of the chain at one time.
#[derive(Debug, Clone)]
struct State {
    t: f64,
    x: Vec<f64>,
    v: Vec<f64>,
}

/// The terms of the balance, accumulated over a run.
struct Balance<'a> {
    base: Base<'a>,
    m: Vec<f64>,
    k: Vec<f64>,
    c: Vec<f64>,
    /// Longest quadrature interval, s.
    h_max: f64,
    nodes: (Vec<f64>, Vec<f64>),
    e0: f64,
    /// W_base, J.
    work: Sum,
    /// D_damping, J.
    damping: Sum,
    /// L by event kind (impact, stick, release, chatter), J.
    lost: [Sum; 4],
    /// Energy changes between pieces of flow that no event reports, J.
    unreported: Sum,
    /// Largest |Δx| (m) and |Δv| (m/s) across such a junction.
    junction: (f64, f64),
    /// Largest |t_event − end of the preceding flow|, s.
    event_time: f64,
    /// Largest |potential energy change| at an event (positions are continuous), J.
    event_potential: f64,
    /// Events by kind (impact, stick, release, chatter).
    count: [usize; 4],
    /// Impacts after which the state shows the contact's two sides merged (the start of a
    /// chatter jump) although the event reports an opening speed, and the energy they took.
    merged_impacts: (usize, Sum),
    quadrature_intervals: usize,
    /// Time spent with at least two masses moving as one cluster (stuck, chattering or
    /// resting), s.
    clustered: f64,
    last: State,
    scratch: State,
    // Sensitivity: the same run's bookkeeping with a deliberate error.
    /// μ, and μ(1 + 1e-4).
    restitution: f64,
    perturbed_mu: f64,
    /// L with the impacts' impulses scaled by (1 + μ(1 + 1e-4))/(1 + μ), J.
    lost_perturbed: Sum,
    /// ∫ dE/dt of a drive that left out the c_i y' part of the base force,
    /// Σ −k_i (x_i − y) y' − c_i v_i², in place of W − D, J.
    work_no_cy: Sum,
}

fn kind_index(k: EventKind) -> usize {
    match k {
        EventKind::Impact => 0,
        EventKind::Stick => 1,
        EventKind::Release => 2,
        EventKind::Chatter => 3,
        _ => unreachable!("{k:?}"),
    }
}

impl<'a> Balance<'a> {
    fn new(chain: &ChainParams, base: Base<'a>, omega_max: f64, x0: &[f64], v0: &[f64]) -> Self {
        assert!(
            chain.forces.iter().all(|&f| f == 0.0),
            "constant forces are not in E"
        );
        assert!(chain.stops.upper.is_none() && chain.stops.lower.is_none());
        let n = chain.len();
        let last = State {
            t: 0.0,
            x: x0.to_vec(),
            v: v0.to_vec(),
        };
        let mut b = Balance {
            base,
            m: chain.masses.clone(),
            k: chain.stiffness.clone(),
            c: chain.damping.clone(),
            h_max: 0.5 / omega_max,
            nodes: gauss_legendre(NODES),
            e0: 0.0,
            work: Sum::default(),
            damping: Sum::default(),
            lost: [Sum::default(); 4],
            unreported: Sum::default(),
            junction: (0.0, 0.0),
            event_time: 0.0,
            event_potential: 0.0,
            count: [0; 4],
            merged_impacts: (0, Sum::default()),
            quadrature_intervals: 0,
            clustered: 0.0,
            scratch: State {
                t: 0.0,
                x: vec![0.0; n],
                v: vec![0.0; n],
            },
            last,
            restitution: chain.restitution,
            perturbed_mu: chain.restitution * (1.0 + 1e-4),
            lost_perturbed: Sum::default(),
            work_no_cy: Sum::default(),
        };
        b.e0 = b.energy(0.0, x0, v0).0;
        b
    }

    /// Total energy and its potential part at time `t`, J.
    fn energy(&self, t: f64, x: &[f64], v: &[f64]) -> (f64, f64) {
        let (y, _) = self.base.value(t);
        let (mut kinetic, mut potential) = (0.0, 0.0);
        for i in 0..self.m.len() {
            kinetic += 0.5 * self.m[i] * v[i] * v[i];
            potential += 0.5 * self.k[i] * (x[i] - y) * (x[i] - y);
        }
        (kinetic + potential, potential)
    }

    fn kinetic(&self, v: &[f64]) -> f64 {
        (0..self.m.len()).map(|i| 0.5 * self.m[i] * v[i] * v[i]).sum()
    }

    /// (W, D, W without c y', D without y') integrands at `t`.
    fn integrands(&mut self, flow: &Flow<'_>, t: f64, piece: usize) -> [f64; 3] {
        flow.state_at(t, &mut self.scratch.x, &mut self.scratch.v);
        let (y, yd) = self.base.at(t, piece);
        let (mut p, mut d, mut q) = (0.0, 0.0, 0.0);
        for i in 0..self.m.len() {
            let (x, v) = (self.scratch.x[i], self.scratch.v[i]);
            let f = -self.k[i] * (x - y) - self.c[i] * (v - yd);
            p += f * yd;
            d += self.c[i] * (v - yd) * (v - yd);
            // dE/dt of a chain driven by k_i y alone (m v' = −k (x − y) − c v):
            // Σ −k_i (x_i − y) y' − c_i v_i², the balance a drive without c_i y' would obey.
            q += -self.k[i] * (x - y) * yd - self.c[i] * v * v;
        }
        [p, d, q]
    }
}

impl RunObserver for Balance<'_> {
    fn flow(&mut self, flow: &Flow<'_>) {
        let (a, b) = (flow.t_start, flow.t_end);
        // The junction with what came before.
        let n = self.m.len();
        let mut start = State {
            t: a,
            x: vec![0.0; n],
            v: vec![0.0; n],
        };
        flow.state_at(a, &mut start.x, &mut start.v);
        let gain = self.energy(a, &start.x, &start.v).0 - self.energy(a, &self.last.x, &self.last.v).0;
        self.unreported.add(gain);
        for i in 0..n {
            self.junction.0 = self.junction.0.max((start.x[i] - self.last.x[i]).abs());
            self.junction.1 = self.junction.1.max((start.v[i] - self.last.v[i]).abs());
        }
        assert!(
            (a - self.last.t).abs() <= 1e-12 * a.abs().max(1.0),
            "flow starts at {a}, the last known state is at {}",
            self.last.t
        );
        if flow.clusters().iter().any(|c| c.last > c.first) {
            self.clustered += b - a;
        }
        // W and D over [a, b].
        let (xs, ws) = std::mem::take(&mut self.nodes);
        for (p0, p1, piece) in self.base.parts(a, b) {
            let len = p1 - p0;
            if len <= 0.0 {
                continue;
            }
            let m = (len / self.h_max).ceil().max(1.0) as usize;
            let h = len / m as f64;
            for j in 0..m {
                let (lo, hi) = (
                    p0 + j as f64 * h,
                    if j + 1 == m { p1 } else { p0 + (j + 1) as f64 * h },
                );
                let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
                let mut acc = [0.0; 3];
                for (z, w) in xs.iter().zip(&ws) {
                    let vals = self.integrands(flow, mid + half * z, piece);
                    for (s, v) in acc.iter_mut().zip(vals) {
                        *s += w * v;
                    }
                }
                self.work.add(half * acc[0]);
                self.damping.add(half * acc[1]);
                self.work_no_cy.add(half * acc[2]);
                self.quadrature_intervals += 1;
            }
        }
        self.nodes = (xs, ws);
        let mut end = State {
            t: b,
            x: vec![0.0; n],
            v: vec![0.0; n],
        };
        flow.state_at(b, &mut end.x, &mut end.v);
        self.last = end;
    }

    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        let t = event.time;
        self.event_time = self.event_time.max((t - self.last.t).abs());
        let (before, pb) = self.energy(t, &self.last.x, &self.last.v);
        let (after, pa) = self.energy(t, state.positions, state.velocities);
        let kind = kind_index(event.kind);
        self.count[kind] += 1;
        self.lost[kind].add(before - after);
        let k = event.contact;
        if event.kind == EventKind::Impact && k + 1 < self.m.len() && event.velocity_after > 0.0 {
            let opening = state.velocities[k] - state.velocities[k + 1];
            if opening.abs() < 1e-9 * event.velocity_after {
                self.merged_impacts.0 += 1;
                self.merged_impacts.1.add(before - after);
            }
        }
        self.event_potential = self.event_potential.max((pb - pa).abs());
        // The same jump with μ(1 + δμ): the impulse scales by (1 + μ')/(1 + μ).
        let mut lost = before - after;
        if event.kind == EventKind::Impact {
            let s = (1.0 + self.perturbed_mu) / (1.0 + self.restitution);
            let v: Vec<f64> = (0..self.m.len())
                .map(|i| self.last.v[i] + s * (state.velocities[i] - self.last.v[i]))
                .collect();
            lost = self.kinetic(&self.last.v) - self.kinetic(&v) + (pb - pa);
        }
        self.lost_perturbed.add(lost);
        self.last = State {
            t,
            x: state.positions.to_vec(),
            v: state.velocities.to_vec(),
        };
    }
}

/// The same bookkeeping for a [`Simulator`] driven directly (the tampered drives below).
impl Observer for Balance<'_> {
    fn flow(&mut self, flow: &Flow<'_>) {
        RunObserver::flow(self, flow)
    }
    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        RunObserver::event(self, event, state)
    }
}

/// What one run's balance came to.
#[derive(Debug)]
struct Report {
    /// ΔE − (W − D − L), relative to Σ|terms|.
    residual: f64,
    /// Energy changed between pieces of flow without an event, relative to Σ|terms|.
    unreported: f64,
    counts: [usize; 4],
    /// Residuals with the deliberate errors: (restitution off by 1e-4, no c y').
    perturbed: (f64, f64),
}

/// Runs `spec` with the balance observed; prints and returns the terms.
fn balance(name: &str, spec: &RunSpec, base: Base<'_>, omega_max: f64) -> Report {
    assert!(spec.harvester.is_none(), "mechanics only");
    let mut obs = Balance::new(
        &spec.chain,
        base,
        omega_max,
        &spec.initial.positions,
        &spec.initial.velocities,
    );
    let started = std::time::Instant::now();
    let outcome = simulate(spec, &mut obs).unwrap();
    assert!(outcome.failure().is_none(), "{:?}", outcome.ending);
    let elapsed = started.elapsed().as_secs_f64();
    // The observer's last state is the run's final state.
    assert_eq!(obs.last.t, outcome.final_time);
    for i in 0..obs.m.len() {
        assert!((obs.last.x[i] - outcome.final_state.positions[i]).abs() < 1e-15);
        assert!((obs.last.v[i] - outcome.final_state.velocities[i]).abs() < 1e-14);
    }
    report(name, &obs, elapsed)
}

/// The balance of a finished run, printed.
fn report(name: &str, obs: &Balance<'_>, elapsed: f64) -> Report {
    let e1 = obs.energy(obs.last.t, &obs.last.x, &obs.last.v).0;
    let de = e1 - obs.e0;
    let (w, d) = (obs.work.get(), obs.damping.get());
    let lost: Vec<f64> = obs.lost.iter().map(|s| s.get()).collect();
    let l: f64 = lost.iter().sum();
    let residual = de - (w - d - l);
    let scale = w.abs() + d + l.abs() + de.abs();
    let unreported = obs.unreported.get();
    let perturbed = (
        de - (w - d - obs.lost_perturbed.get()),
        de - (obs.work_no_cy.get() - l),
    );
    println!(
        "{name}: t = {:.3} s, {} quadrature intervals, run + balance {elapsed:.2} s\n  \
         events: {} impacts, {} sticks, {} releases, {} chatter; {:.3} s with masses moving as one cluster\n  \
         E(0) = {:.6e} J, E(end) = {e1:.6e} J, ΔE = {de:.6e} J\n  \
         W_base = {w:.9e} J, D_damping = {d:.9e} J, L = {l:.9e} J \
         (impacts {:.3e}, sticks {:.3e}, releases {:.3e}, chatter {:.3e}); \
         {} impacts started a chatter jump (merged at once, their loss {:.3e} J)\n  \
         residual ΔE − (W − D − L) = {residual:.3e} J = {:.3e} of Σ|terms| ({scale:.4e} J), {:.3e} of |W|\n  \
         energy changed between flows without an event: {unreported:.3e} J (largest jump |Δx| {:.1e} m, \
         |Δv| {:.1e} m/s); event times vs flow ends {:.1e} s; largest potential-energy jump at an event {:.1e} J\n  \
         sensitivity: μ off by 1e-4 in L → residual {:.3e} of Σ|terms|; c·y' left out of the base force → {:.3e}",
        obs.last.t,
        obs.quadrature_intervals,
        obs.count[0],
        obs.count[1],
        obs.count[2],
        obs.count[3],
        obs.clustered,
        obs.e0,
        lost[0],
        lost[1],
        lost[2],
        lost[3],
        obs.merged_impacts.0,
        obs.merged_impacts.1.get(),
        residual / scale,
        residual / w.abs(),
        obs.junction.0,
        obs.junction.1,
        obs.event_time,
        obs.event_potential,
        perturbed.0 / scale,
        perturbed.1 / scale,
    );
    Report {
        residual: residual / scale,
        unreported: unreported / scale,
        counts: obs.count,
        perturbed: (perturbed.0 / scale, perturbed.1 / scale),
    }
}

/// The highest angular frequency in the integrands of a chain under base motion up to
/// `f_high` Hz: twice the largest of the masses' natural frequencies and the band's edge.
fn omega_max(chain: &ChainParams, f_high_hz: f64) -> f64 {
    let wn = chain
        .masses
        .iter()
        .zip(&chain.stiffness)
        .map(|(m, k)| (k / m).sqrt())
        .fold(0.0, f64::max);
    2.0 * wn.max(TAU * f_high_hz)
}

fn random_case(name: &str, text: &str, f_high_hz: f64) -> Report {
    let config = Config::from_toml_str(text).unwrap();
    config.check_runnable().unwrap();
    let spec = config.run_spec(true);
    // What the engine is driven by: a random signal's harmonics as piecewise polynomials.
    // Their displacement is continuous across a knot only to its interpolation bound (each
    // interval interpolates on its own), so the spring energy ½k(x − y)² jumps there by up
    // to k|x − y|·2e_y without work: with e_y ~ 1e-11 m that adds ~1e-12 of the terms,
    // still far inside the tolerance.
    let end = spec.periods as f64 * spec.chain.period();
    let sim = Simulator::driven(
        &spec.chain,
        &spec.initial,
        spec.options.clone(),
        spec.base_motion.as_ref(),
        end,
    )
    .unwrap();
    let pieces = sim
        .base_displacement()
        .and_then(|b| b.pieces())
        .expect("a random signal runs on piecewise polynomials");
    let intervals = pieces.knots().len() - 1;
    let [y0, v0] = pieces.evaluate(0.0);
    let r = balance(
        name,
        &spec,
        Base::Pieces(pieces),
        omega_max(&spec.chain, f_high_hz),
    );
    println!("  (pieces: {intervals} intervals; base at t = 0: y = {y0:.4e} m, y' = {v0:.4e} m/s)");
    r
}

fn check(r: &Report) {
    assert!(r.residual.abs() < TOLERANCE, "{r:?}");
    assert!(r.unreported.abs() < TOLERANCE, "{r:?}");
    // The deliberate errors are far outside the tolerance: the check can fail.
    assert!(r.perturbed.0.abs() > 100.0 * TOLERANCE, "{r:?}");
    assert!(r.perturbed.1.abs() > 100.0 * TOLERANCE, "{r:?}");
}

/// The default chain under flat random base acceleration, 2–20 Hz, 40 m/s² RMS, over 60
/// reference periods (10.8 s).
const DEFAULT_RANDOM: &str = "[excitation]\nkind = \"random\"\nrms_acceleration = 40\nf_low_hz = 2\nf_high_hz = 20\nseed = 14\n[run]\nperiods = 60\n";

/// The paper's default chain (m = 48, 120, 48 g, δ = 20 mm) under band-limited random base
/// acceleration.
#[test]
fn energy_balance_default_chain_random() {
    let r = random_case("default chain, random 2–20 Hz, 40 m/s² rms", DEFAULT_RANDOM, 20.0);
    assert!(r.counts[0] > 100, "{r:?}");
    check(&r);
}

/// The chatter-prone chain (m = 50, 150, 50 g, δ = 5 mm) under random base acceleration.
#[test]
fn energy_balance_chatter_chain_random() {
    let r = random_case(
        "chatter chain, random 2–8 Hz, 40 m/s² rms",
        "[oscillator]\nmasses = [0.05, 0.15, 0.05]\ngaps = [0.005, 0.005]\n[excitation]\nkind = \"random\"\nrms_acceleration = 40\nf_low_hz = 2\nf_high_hz = 8\nseed = 3\n[run]\nperiods = 60\n",
        8.0,
    );
    assert!(r.counts[0] > 100, "{r:?}");
    // Sticking and chatter are in the run.
    assert!(r.counts[1] > 0 && r.counts[3] > 0, "{r:?}");
    check(&r);
}

/// Controls under the chain's own harmonic: the default case, and the paper's chatter case
/// at Ω = 0.60 (sticking and chatter every period).
#[test]
fn energy_balance_harmonic_controls() {
    for (name, text) in [
        ("default case, harmonic", "[run]\nperiods = 40\n"),
        (
            "chatter case, harmonic",
            "[oscillator]\nmasses = [0.05, 0.15, 0.05]\ngaps = [0.005, 0.005]\n[excitation]\nomega_ratio = 0.60\n[run]\nperiods = 40\n",
        ),
    ] {
        let config = Config::from_toml_str(text).unwrap();
        let spec = config.run_spec(true);
        assert!(spec.base_motion.is_none());
        let chain = &spec.chain;
        let r = balance(
            name,
            &spec,
            Base::Sine {
                amplitude: chain.excitation.amplitude,
                omega: chain.omega(),
            },
            omega_max(chain, chain.omega() / TAU),
        );
        assert!(r.counts[0] > 40, "{r:?}");
        check(&r);
    }
}

// ---------------------------------------------------------------------------------------
// Sensitivity to the knot forces: the same chain driven here, interval by interval, once
// faithfully and once with one interval's base force wrong.
// ---------------------------------------------------------------------------------------

/// How the drive of [`own_drive`] departs from the exact interval forces.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Tamper {
    /// None: the forces k_i y + c_i y' of every interval (what `Simulator::driven` does).
    Faithful,
    /// Interval j gets no base force at all.
    Dropped(usize),
    /// The forces are not updated at the knot starting interval j: interval j − 1's cubic
    /// goes on over interval j.
    Held(usize),
}

/// Drives a [`Simulator`] on the chain of `spec` (harmonic amplitude 0) with the forces
/// k_i y + c_i y' of each interval of `spline`, set at its knots, tampered as `tamper` says.
fn own_drive(spec: &RunSpec, spline: &PiecewiseCubic, tamper: Tamper, obs: &mut Balance<'_>) {
    let chain = driven_chain(&spec.chain, spec.base_motion.as_deref()).into_owned();
    assert_eq!(chain.excitation.amplitude, 0.0);
    let mut sim = Simulator::new(&chain, &spec.initial, spec.options.clone()).unwrap();
    let t_end = spec.periods as f64 * chain.period();
    let knots = spline.knots();
    let mut i = 0;
    while sim.time() < t_end {
        let source = if tamper == Tamper::Held(i) { i - 1 } else { i };
        let (t0, [c0, c1, c2, c3]) = spline.piece(source);
        let forces: Vec<ForcePolynomial> = (0..chain.len())
            .map(|m| {
                let (k, c) = (chain.stiffness[m], chain.damping[m]);
                if tamper == Tamper::Dropped(i) {
                    ForcePolynomial::zero()
                } else {
                    ForcePolynomial::new(
                        t0,
                        vec![
                            k * c0 + c * c1,
                            k * c1 + 2.0 * c * c2,
                            k * c2 + 3.0 * c * c3,
                            k * c3,
                        ],
                    )
                }
            })
            .collect();
        sim.set_external_forces(&forces).unwrap();
        let end = sim.run_until(knots[i + 1].min(t_end), obs).unwrap();
        assert!(matches!(end, RunEnd::Reached), "{end:?}");
        i += 1;
    }
}

/// The default chain under the random input of [`energy_balance_default_chain_random`] as
/// its clamped cubic spline (`RandomSpec::to_spline`; the run layer drives random signals on
/// piecewise polynomials, records on such splines), driven here interval by interval with
/// the spline's forces: faithfully, the balance closes; with the base
/// force of the one interval at t = 5 s (0.17 ms of a 10.8 s run) left out, it misses by
/// far more than the tolerance. A force update missed at one knot (the previous interval's
/// cubic held over the next) changes the force by about y⁗ h⁴ ≈ 1e-11 of it, below the
/// spline's own accuracy: that residual is printed, not asserted.
#[test]
fn a_wrong_force_on_one_spline_interval_breaks_the_balance() {
    let config = Config::from_toml_str(DEFAULT_RANDOM).unwrap();
    let spec = config.run_spec(true);
    let vibrotribo::excitation::ExcitationSpec::Random {
        spec: random,
        relative_tolerance,
    } = config.excitation()
    else {
        panic!("{:?}", config.excitation())
    };
    let (spline, _, _) = random.to_spline(*relative_tolerance).unwrap();
    let spline = &spline;
    let j = spline.interval(5.0);
    let mut residuals = Vec::new();
    for tamper in [Tamper::Faithful, Tamper::Dropped(j), Tamper::Held(j)] {
        let mut obs = Balance::new(
            &spec.chain,
            Base::Spline(spline),
            omega_max(&spec.chain, 20.0),
            &spec.initial.positions,
            &spec.initial.velocities,
        );
        let started = std::time::Instant::now();
        own_drive(&spec, spline, tamper, &mut obs);
        let r = report(
            &format!("default chain, random, driven here: {tamper:?}"),
            &obs,
            started.elapsed().as_secs_f64(),
        );
        assert!(r.unreported.abs() < TOLERANCE, "{r:?}");
        residuals.push(r.residual);
    }
    assert!(residuals[0].abs() < TOLERANCE, "{residuals:?}");
    assert!(residuals[1].abs() > 100.0 * TOLERANCE, "{residuals:?}");
}
