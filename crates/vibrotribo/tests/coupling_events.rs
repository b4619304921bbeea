//! Two-way coupling keeps the events as reliable as one-way runs (issue 11): impacts,
//! sticking, release and chatter under the electrostatic force, with every load. The truth
//! comes from outside the coupling code:
//!
//! - **An independent integrator of the coupled equations.** From the start of every window
//!   of the coupled run (the simulator's state and the solver's charge there), Dop853
//!   (tests/common) integrates the chain under the electrostatic force written out in
//!   tests/common/electrostatics.rs together with the circuit (R dQ/dt = V for a resistor,
//!   Q constant in open circuit, Q = Q_eq(D) in short circuit), and its gaps are sampled on a
//!   fine grid: no open gap may go negative where the coupled run saw no event (nothing
//!   missed), and its state at the window's end must be the run's to the coupling's stated
//!   displacement tolerance.
//! - **A brute-force scan of the flow the run followed**, for every load (the rectifier
//!   too): every open gap of every stored piece of flow on a grid, each local minimum refined
//!   by golden-section search, never below −1e-12 of the gap (tests/events_vs_bruteforce.rs's
//!   criterion).
//! - **The contact force from the energy function.** A stuck pair must release where its
//!   contact force, mechanical plus electrostatic (the forces −∂U/∂D of
//!   tests/common/electrostatics.rs at the solver's charge), crosses zero, and stick only
//!   where it presses; it is computed here from the state at the event, not by the engine.
//! - **A closed form.** In open circuit the force is constant; two masses with equal k/m
//!   then have a relative motion r(t) = s(1 − cos ω_n t) + a sin ω_n t, whose grazing is
//!   known exactly (tests/special_cases.rs's grazing pair, with the electrostatic pull).
//! - **Conservation at events** (tests/reliability.rs): momentum kept, kinetic energy never
//!   gained.

mod common;

use std::f64::consts::PI;

use common::electrostatics::{
    VACUUM_PERMITTIVITY, electrostatic_forces, equilibrium_charge, gap_forces, terminal_voltage,
};
use common::{grazing_pair, integrate};
use ode_solvers::{DVector, System};
use vibrotribo::coupling::{ChargeHost, CoupledChain, CouplingOptions};
use vibrotribo::electrical::{
    ChargeOptions, ChargeSolver, HarvesterParams, Load, Rectifier, TransducerMode, VocModel,
};
use vibrotribo::{
    ChainParams, ChainState, Event, EventKind, EventLog, Excitation, Flow, Frequency, Observer, SimOptions,
    Simulator, StateView, Trajectory,
};

/// The coupling's displacement tolerance used here, m (the default).
const POSITION_TOLERANCE: f64 = 1e-11;

/// Records a coupled run: the stored flow, the events, the charge at every window's end and
/// the conservation figures at every event.
struct Recorder {
    solver: ChargeSolver,
    traj: Trajectory,
    log: EventLog,
    masses: Vec<f64>,
    /// (time, charge) at t = 0 and at the end of every window, s and C.
    charges: Vec<(f64, f64)>,
    /// Velocities at the end of the last piece of flow or after the last event, m/s.
    v_before: Vec<f64>,
    /// Worst momentum change at an event, relative to Σ m|v|.
    worst_momentum: f64,
    /// Worst kinetic-energy gain at an event, relative to Σ m v².
    worst_energy: f64,
}

impl Recorder {
    fn new(solver: ChargeSolver, chain: &ChainParams, q0: f64) -> Self {
        let n = chain.len();
        Recorder {
            solver,
            traj: Trajectory::for_chain(chain),
            log: EventLog::default(),
            masses: chain.masses.clone(),
            charges: vec![(0.0, q0)],
            v_before: vec![0.0; n],
            worst_momentum: 0.0,
            worst_energy: f64::NEG_INFINITY,
        }
    }

    /// The charge at `t`, C: a window ends at every event, so event times are in `charges`.
    fn charge_at(&self, t: f64) -> f64 {
        let i = self.charges.partition_point(|c| c.0 < t);
        let (tc, q) = self.charges[i.min(self.charges.len() - 1)];
        assert!((tc - t).abs() <= 1e-12 * t.max(1.0), "no window ends at {t} (nearest {tc})");
        q
    }
}

impl Observer for Recorder {
    fn flow(&mut self, flow: &Flow<'_>) {
        self.traj.flow(flow);
        let mut x = vec![0.0; self.masses.len()];
        flow.state_at(flow.t_end, &mut x, &mut self.v_before);
    }

    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        self.log.event(event, state);
        let m = &self.masses;
        let momentum = |v: &[f64]| m.iter().zip(v).map(|(m, v)| m * v).sum::<f64>();
        let energy = |v: &[f64]| m.iter().zip(v).map(|(m, v)| 0.5 * m * v * v).sum::<f64>();
        let size = |v: &[f64]| m.iter().zip(v).map(|(m, v)| (m * v).abs()).sum::<f64>();
        let p_scale = size(&self.v_before).max(size(state.velocities)) + f64::MIN_POSITIVE;
        let dp = (momentum(state.velocities) - momentum(&self.v_before)).abs() / p_scale;
        self.worst_momentum = self.worst_momentum.max(dp);
        let e0 = energy(&self.v_before);
        let de = (energy(state.velocities) - e0) / (2.0 * e0 + f64::MIN_POSITIVE);
        self.worst_energy = self.worst_energy.max(de);
        self.v_before.copy_from_slice(state.velocities);
    }

    fn proceed(&mut self) -> vibrotribo::dynamics::Verdict {
        // Called once per accepted window, with the solver at the window's end.
        self.charges.push((self.solver.time(), self.solver.charge()));
        Ok(std::ops::ControlFlow::Continue(()))
    }
}

impl ChargeHost for Recorder {
    fn charge_solver(&mut self) -> &mut ChargeSolver {
        &mut self.solver
    }
}

/// The harvester of these tests: exact V_oc, the given load and initial charge.
fn harvester(mode: TransducerMode, load: Load, q0: f64) -> HarvesterParams {
    HarvesterParams {
        mode,
        voc_model: VocModel::Exact,
        load,
        initial_charge: Some(q0),
        ..HarvesterParams::default()
    }
}

/// The four loads: a resistor of `resistance` Ω, the default rectifier, open and short.
fn loads(resistance: f64) -> [(&'static str, Load); 4] {
    [
        ("resistor", Load::Resistor { resistance }),
        ("rectifier", Load::Rectifier(Rectifier::default())),
        ("open", Load::Open),
        ("short", Load::Short),
    ]
}

/// Runs `chain` two-way from `initial` for `periods` periods (electrical rtol 1e-10).
fn coupled_run(chain: &ChainParams, initial: &ChainState, h: &HarvesterParams, periods: f64) -> Recorder {
    let sim = Simulator::new(chain, initial, SimOptions::default()).unwrap();
    let options = ChargeOptions {
        rtol: 1e-10,
        ..ChargeOptions::default()
    };
    let solver = ChargeSolver::for_chain(h, chain, options).unwrap();
    let mut rec = Recorder::new(solver, chain, h.initial_charge.unwrap());
    let options = CouplingOptions {
        position_tolerance: POSITION_TOLERANCE,
        ..CouplingOptions::default()
    };
    let mut coupled = CoupledChain::new(sim, h, options).unwrap();
    coupled
        .run_until(periods * chain.period(), &mut rec)
        .unwrap_or_else(|e| panic!("coupled run failed: {e}"));
    rec.solver.status().unwrap();
    rec
}

/// Contacts open during a piece of flow (the last mass of a cluster above another cluster).
fn open_contacts(flow: &Flow<'_>) -> Vec<usize> {
    let n = flow.len();
    flow.clusters()
        .iter()
        .map(|c| c.last)
        .filter(|&l| l + 1 < n)
        .collect()
}

/// The stored piece of flow `i` of `traj` (`None` for a piece so short that no time lies
/// inside it: an ulp or two between events).
fn segment(traj: &Trajectory, i: usize) -> Option<Flow<'_>> {
    let s = &traj.segments()[i];
    traj.flow_at(0.5 * (s.t_start + s.t_end))
        .filter(|f| f.t_start == s.t_start)
}

/// The smallest open gap over every stored piece of flow, relative to its δ_k: a grid of
/// `grid` intervals per piece, every local minimum refined by golden-section search.
fn scan_stored_flow(traj: &Trajectory, deltas: &[f64], grid: usize) -> (f64, f64) {
    let mut worst = (f64::INFINITY, 0.0);
    let mut gaps = vec![0.0; deltas.len()];
    let mut rates = vec![0.0; deltas.len()];
    for i in 0..traj.segments().len() {
        let Some(flow) = segment(traj, i) else {
            continue;
        };
        let open = open_contacts(&flow);
        let (a, b) = (flow.t_start, flow.t_end);
        let mut gap = |t: f64, k: usize| {
            flow.gaps_at(t, &mut gaps, &mut rates);
            gaps[k] / deltas[k]
        };
        for &k in &open {
            let ts: Vec<f64> = (0..=grid)
                .map(|j| if j == grid { b } else { a + (b - a) * j as f64 / grid as f64 })
                .collect();
            let gs: Vec<f64> = ts.iter().map(|&t| gap(t, k)).collect();
            for j in 0..=grid {
                let left = if j == 0 { f64::INFINITY } else { gs[j - 1] };
                let right = if j == grid { f64::INFINITY } else { gs[j + 1] };
                let mut low = (gs[j], ts[j]);
                if gs[j] <= left && gs[j] <= right && 0 < j && j < grid {
                    // Golden-section search for the minimum on [t_{j−1}, t_{j+1}].
                    let (mut lo, mut hi) = (ts[j - 1], ts[j + 1]);
                    let r = 0.5 * (5f64.sqrt() - 1.0);
                    for _ in 0..80 {
                        let (c, d) = (hi - r * (hi - lo), lo + r * (hi - lo));
                        if gap(c, k) < gap(d, k) { hi = d } else { lo = c }
                    }
                    let t = 0.5 * (lo + hi);
                    let g = gap(t, k);
                    if g < low.0 {
                        low = (g, t);
                    }
                }
                if low.0 < worst.0 {
                    worst = low;
                }
            }
        }
    }
    worst
}

/// The coupled equations of motion, written here: per cluster (top position s, m; velocity,
/// m/s), then for a resistor q = Q/σS; time last (the autonomous form of tests/common).
#[derive(Clone)]
struct CoupledOde {
    chain: ChainParams,
    h: HarvesterParams,
    clusters: Vec<(usize, usize)>,
    /// Offsets of the masses in a stuck cluster, m (Σ of the closed gaps above).
    offsets: Vec<f64>,
    /// The charge in open circuit, C.
    q_open: f64,
}

impl CoupledOde {
    fn new(chain: &ChainParams, h: &HarvesterParams, clusters: &[(usize, usize)], q_open: f64) -> Self {
        let mut offsets = vec![0.0; chain.len()];
        for i in 1..chain.len() {
            offsets[i] = offsets[i - 1] + chain.gaps[i - 1];
        }
        CoupledOde {
            chain: chain.clone(),
            h: h.clone(),
            clusters: clusters.to_vec(),
            offsets,
            q_open,
        }
    }

    fn sigma_s(&self) -> f64 {
        self.h.charge_density * self.h.area
    }

    /// Positions of all masses, m, from the state.
    fn positions(&self, y: &[f64]) -> Vec<f64> {
        let mut x = vec![0.0; self.chain.len()];
        for (c, &(first, last)) in self.clusters.iter().enumerate() {
            for i in first..=last {
                x[i] = y[2 * c] + self.offsets[i] - self.offsets[first];
            }
        }
        x
    }

    fn gaps(&self, x: &[f64]) -> Vec<f64> {
        (0..x.len() - 1)
            .map(|k| self.chain.gaps[k] - (x[k + 1] - x[k]))
            .collect()
    }

    /// The charge, C.
    fn charge(&self, y: &[f64], gaps: &[f64]) -> f64 {
        match self.h.load {
            Load::Resistor { .. } => y[2 * self.clusters.len()] * self.sigma_s(),
            Load::Open => self.q_open,
            Load::Short => equilibrium_charge(&self.h, gaps),
            Load::Rectifier(_) => unreachable!("the bridge is not written out here"),
        }
    }
}

impl System<f64, DVector<f64>> for CoupledOde {
    fn system(&self, _t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) {
        let len = y.len();
        let t = y[len - 1];
        dy[len - 1] = 1.0;
        let (a, w) = (self.chain.excitation.amplitude, self.chain.omega());
        let (yb, ybd) = (a * (w * t).sin(), a * w * (w * t).cos());
        let x = self.positions(y.as_slice());
        let gaps = self.gaps(&x);
        let q = self.charge(y.as_slice(), &gaps);
        let f = electrostatic_forces(&self.h, x.len(), q);
        for (c, &(first, last)) in self.clusters.iter().enumerate() {
            let v = y[2 * c + 1];
            let (mut m, mut force) = (0.0, 0.0);
            for i in first..=last {
                m += self.chain.masses[i];
                force += -self.chain.stiffness[i] * (x[i] - yb) - self.chain.damping[i] * (v - ybd) + f[i];
            }
            dy[2 * c] = v;
            dy[2 * c + 1] = force / m;
        }
        if let Load::Resistor { resistance } = self.h.load {
            dy[2 * self.clusters.len()] = terminal_voltage(&self.h, q, &gaps) / resistance / self.sigma_s();
        }
    }
}

/// What the independent integrator found over all windows.
#[derive(Debug, Default)]
struct WindowCheck {
    windows: usize,
    /// Smallest open gap on the integrator's grid, relative to δ_k, and its time.
    worst_gap: (f64, f64),
    /// Largest |x_run − x_ode| at a window's end, m.
    worst_dx: f64,
    /// Largest |Q_run − Q_ode| at a window's end, relative to σS.
    worst_dq: f64,
    /// Windows shorter than [`SHORTEST_WINDOW`] periods, not integrated.
    skipped: usize,
}

/// Windows shorter than this many periods are not integrated (Dop853 cannot step across a
/// few ulps of time).
const SHORTEST_WINDOW: f64 = 1e-12;

/// Integrates every window of `rec` independently (see the module docs), `grid` samples per
/// window.
fn check_windows(rec: &Recorder, chain: &ChainParams, h: &HarvesterParams, grid: usize) -> WindowCheck {
    let n = chain.len();
    let segs = rec.traj.segments();
    let mut out = WindowCheck {
        worst_gap: (f64::INFINITY, 0.0),
        ..WindowCheck::default()
    };
    let (mut x, mut v) = (vec![0.0; n], vec![0.0; n]);
    for pair in rec.charges.windows(2) {
        let ((ta, qa), (tb, qb)) = (pair[0], pair[1]);
        if tb - ta < SHORTEST_WINDOW * chain.period() {
            // Nothing to integrate (zero-length windows at events, a few ulps before them).
            out.skipped += usize::from(tb > ta);
            continue;
        }
        let first = segs.partition_point(|s| s.t_end <= ta);
        let last = segs.partition_point(|s| s.t_end < tb);
        assert!(segs[first].t_start == ta && segs[last].t_end == tb, "window [{ta}, {tb}]");
        let flow = (first..=last)
            .find_map(|i| segment(&rec.traj, i))
            .expect("a piece of flow inside the window");
        let clusters: Vec<(usize, usize)> = flow.clusters().iter().map(|c| (c.first, c.last)).collect();
        for i in first..=last {
            let other: Vec<(usize, usize)> = segs[i].clusters.iter().map(|c| (c.first, c.last)).collect();
            assert_eq!(other, clusters, "no event inside a window");
        }
        let open = open_contacts(&flow);
        flow.state_at(ta, &mut x, &mut v);
        let mut y0: Vec<f64> = clusters.iter().flat_map(|&(f, _)| [x[f], v[f]]).collect();
        let ode = CoupledOde::new(chain, h, &clusters, qa);
        if matches!(h.load, Load::Resistor { .. }) {
            y0.push(qa / ode.sigma_s());
        }
        let (ts, ys) = integrate(ode.clone(), ta, tb, (tb - ta) / grid as f64, &y0);
        for (t, y) in ts.iter().zip(&ys) {
            let gaps = ode.gaps(&ode.positions(y));
            for &k in &open {
                let g = gaps[k] / chain.gaps[k];
                if g < out.worst_gap.0 {
                    out.worst_gap = (g, *t);
                }
            }
        }
        let end = ys.last().unwrap();
        (first..=last)
            .rev()
            .find_map(|i| segment(&rec.traj, i))
            .unwrap()
            .state_at(tb, &mut x, &mut v);
        let xo = ode.positions(end);
        for i in 0..n {
            out.worst_dx = out.worst_dx.max((x[i] - xo[i]).abs());
        }
        let qo = ode.charge(end, &ode.gaps(&xo));
        out.worst_dq = out.worst_dq.max((qb - qo).abs() / ode.sigma_s());
        out.windows += 1;
    }
    out
}

/// The force of contact k (between masses k and k + 1) inside the stuck cluster
/// `[first, last]`, N, positive when it presses: the cluster accelerates as one body under
/// the forces F_i on its masses, and the contact carries N = (m_U F_L − m_L F_U)/(m_U + m_L)
/// (U the masses first..=k, L the masses k+1..=last). F_i = −k_i(x_i − y) − c_i(v_i − y')
/// plus, given a charge, the electrostatic force −∂U/∂D at it.
#[allow(clippy::too_many_arguments)]
fn contact_force(
    chain: &ChainParams,
    h: &HarvesterParams,
    (first, last): (usize, usize),
    k: usize,
    t: f64,
    x: &[f64],
    v: &[f64],
    charge: Option<f64>,
) -> f64 {
    let (a, w) = (chain.excitation.amplitude, chain.omega());
    let (yb, ybd) = (a * (w * t).sin(), a * w * (w * t).cos());
    let es = charge.map_or(vec![0.0; x.len()], |q| electrostatic_forces(h, x.len(), q));
    let force = |i: usize| -chain.stiffness[i] * (x[i] - yb) - chain.damping[i] * (v[i] - ybd) + es[i];
    let (mu, fu): (f64, f64) = (first..=k).map(|i| (chain.masses[i], force(i))).fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
    let (ml, fl): (f64, f64) = (k + 1..=last).map(|i| (chain.masses[i], force(i))).fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
    (mu * fl - ml * fu) / (mu + ml)
}

/// Contact forces at the sticks and releases of a run.
#[derive(Debug, Default)]
struct ContactForces {
    releases: usize,
    sticks: usize,
    /// Largest |N| at a release, mechanical + electrostatic, N.
    release_total: f64,
    /// Largest |N| at a release with the mechanical forces only, N.
    release_mechanical: f64,
    /// Most negative N at a stick (a stick that pulls), N.
    stick_total: f64,
    /// Releases at the instant of their stick (no flow in between: not checked).
    instant_releases: usize,
    /// Chatter sequences that ended in a stick later released.
    chatter_stick_release: usize,
    chatters: usize,
}

/// The cluster containing contact k in the piece of flow ending at `t` (`None` if it was
/// open there: stuck at the same instant).
fn cluster_before(traj: &Trajectory, t: f64, k: usize) -> Option<(usize, usize)> {
    let segs = traj.segments();
    let i = segs.partition_point(|s| s.t_end <= t);
    let s = &segs[i.checked_sub(1)?];
    assert_eq!(s.t_end, t, "a piece of flow ends at every event");
    s.clusters
        .iter()
        .find(|c| c.first <= k && k < c.last)
        .map(|c| (c.first, c.last))
}

fn contact_forces(rec: &Recorder, chain: &ChainParams, h: &HarvesterParams, charged: bool) -> ContactForces {
    let mut out = ContactForces::default();
    let events = &rec.log.events;
    for (j, e) in events.iter().enumerate() {
        let (t, k) = (e.event.time, e.event.contact);
        match e.event.kind {
            EventKind::Release => {
                let Some(cluster) = cluster_before(&rec.traj, t, k) else {
                    out.instant_releases += 1;
                    continue;
                };
                let q = charged.then(|| rec.charge_at(t));
                let total = contact_force(chain, h, cluster, k, t, &e.positions, &e.velocities, q);
                let mech = contact_force(chain, h, cluster, k, t, &e.positions, &e.velocities, None);
                out.releases += 1;
                out.release_total = out.release_total.max(total.abs());
                out.release_mechanical = out.release_mechanical.max(mech.abs());
            }
            EventKind::Stick => {
                // The cluster after the stick: the piece of flow starting at t.
                let flow = rec.traj.flow_at(t);
                let Some(c) = flow
                    .as_ref()
                    .and_then(|f| f.clusters().iter().find(|c| c.first <= k && k < c.last))
                else {
                    continue; // released at the same instant, or the run's end
                };
                let q = charged.then(|| rec.charge_at(t));
                let total = contact_force(chain, h, (c.first, c.last), k, t, &e.positions, &e.velocities, q);
                out.sticks += 1;
                out.stick_total = out.stick_total.min(total);
            }
            EventKind::Chatter => {
                out.chatters += 1;
                let stuck = events[j + 1..]
                    .iter()
                    .take_while(|f| f.event.time == t)
                    .any(|f| f.event.kind == EventKind::Stick && f.event.contact == k);
                let released = events[j + 1..]
                    .iter()
                    .any(|f| f.event.kind == EventKind::Release && f.event.contact == k);
                if stuck && released {
                    out.chatter_stick_release += 1;
                }
            }
            _ => {}
        }
    }
    out
}

// ---------------------------------------------------------------------------------------
// Scenarios.
// ---------------------------------------------------------------------------------------

/// The paper's chatter case (masses 0.05/0.15/0.05 kg, gaps 5 mm) at `omega_ratio`.
fn chatter_case(omega_ratio: f64) -> ChainParams {
    let mut c = ChainParams::paper_chatter_case();
    c.excitation.frequency = Frequency::OmegaRatio(omega_ratio);
    c
}

/// The scenarios of tests/events_vs_bruteforce.rs and the chatter case's sticking regime.
fn scenarios() -> Vec<(&'static str, ChainParams, f64)> {
    vec![
        ("default case", ChainParams::default(), 8.0),
        ("chatter case, Ω = 0.6", chatter_case(0.6), 6.0),
        ("chatter case, Ω = 0.4 (sticking)", chatter_case(0.4), 5.0),
        ("four masses, sticking", common::four_mass_stack(), 6.0),
    ]
}

/// A charge that is not the equilibrium one, C (−0.2 σS), for the runs to start with.
fn start_charge(h: &HarvesterParams) -> f64 {
    -0.2 * h.charge_density * h.area
}

#[test]
fn probe_windows() {
    for (name, chain, periods) in scenarios() {
        for (load_name, load) in loads(1e9) {
            if matches!(load, Load::Rectifier(_)) {
                continue;
            }
            let mut h = harvester(TransducerMode::Freestanding, load, 0.0);
            h.initial_charge = Some(start_charge(&h));
            let started = std::time::Instant::now();
            let rec = coupled_run(&chain, &ChainState::at_rest(chain.len()), &h, periods);
            let run = started.elapsed().as_secs_f64();
            let w = check_windows(&rec, &chain, &h, 16);
            let scan = scan_stored_flow(&rec.traj, &chain.gaps, 64);
            println!(
                "{name}, {load_name}: run {run:.2} s, check {:.2} s; {} events, {} windows; ODE: min gap/δ {:.2e} at {:.6}, \
                 max |Δx| {:.2e} m, max |ΔQ|/σS {:.2e}; stored flow min gap/δ {:.2e} at {:.6}",
                started.elapsed().as_secs_f64() - run,
                rec.log.events.len(),
                w.windows,
                w.worst_gap.0,
                w.worst_gap.1,
                w.worst_dx,
                w.worst_dq,
                scan.0,
                scan.1
            );
        }
    }
}

#[test]
fn probe_contacts() {
    for (name, chain, periods) in scenarios() {
        for (load_name, load) in loads(1e5) {
            let mut h = harvester(TransducerMode::Freestanding, load, 0.0);
            h.initial_charge = Some(start_charge(&h));
            let started = std::time::Instant::now();
            let rec = coupled_run(&chain, &ChainState::at_rest(chain.len()), &h, periods);
            let run = started.elapsed().as_secs_f64();
            let scan = scan_stored_flow(&rec.traj, &chain.gaps, 64);
            let cf = contact_forces(&rec, &chain, &h, true);
            println!(
                "{name}, {load_name}: run {run:.2} s; {} events; stored flow min gap/δ {:.2e}; momentum {:.1e}, energy {:.1e}; {cf:?}",
                rec.log.events.len(),
                scan.0,
                rec.worst_momentum,
                rec.worst_energy,
            );
        }
        // One-way: the contact force of the mechanics alone vanishes at releases.
        let h = harvester(TransducerMode::Freestanding, Load::Open, 0.0);
        let solver = ChargeSolver::for_chain(&h, &chain, ChargeOptions::default()).unwrap();
        let mut rec = Recorder::new(solver, &chain, 0.0);
        let mut sim = Simulator::new(&chain, &ChainState::at_rest(chain.len()), SimOptions::default()).unwrap();
        sim.run_until(periods * chain.period(), &mut rec).unwrap();
        let cf = contact_forces(&rec, &chain, &h, false);
        println!("{name}, one-way: {cf:?}");
    }
}

#[test]
fn probe_grazing() {
    for eps in [0.0, 1e-9, 1e-6, 1e-3, -1e-9] {
        let (chain, _, wn) = grazing_pair(eps);
        let h = harvester(TransducerMode::ContactSeparation, Load::Open, 0.0);
        let q0 = start_charge(&h);
        let h = HarvesterParams { initial_charge: Some(q0), ..h };
        let g: f64 = gap_forces(&h, q0)[0].1;
        let (ma, mb) = (chain.masses[0], chain.masses[1]);
        let s = -g * (1.0 / ma + 1.0 / mb) / (wn * wn);
        let delta = chain.gaps[0];
        let a = ((delta * (1.0 + eps) - s).powi(2) - s * s).sqrt();
        let initial = ChainState { positions: vec![0.0, 0.0], velocities: vec![0.0, a * wn] };
        let rho = s.hypot(a);
        let phi = a.atan2(s);
        let theta = ((s - delta) / rho).clamp(-1.0, 1.0).acos() - phi;
        let t_expected = theta / wn;
        let v_expected = wn * (s * theta.sin() + a * theta.cos());
        let t_end = (PI - phi + 0.5) / wn;
        let rec = coupled_run(&chain, &initial, &h, t_end / chain.period());
        let first = rec.log.events.first().map(|e| e.event);
        println!("ε = {eps:e}: s = {s:.6e} m, expected t = {t_expected:.15e} s, v = {v_expected:.3e}; first {first:?}; {} events; dt = {:?}", rec.log.events.len(), first.map(|e| e.time - t_expected));
        let _ = VACUUM_PERMITTIVITY;
        let _ = (Excitation::default(), Frequency::OmegaRatio(1.0));
    }
}

#[test]
fn probe_scan_detail() {
    for (name, chain, periods) in scenarios() {
        // One-way
        let h = harvester(TransducerMode::Freestanding, Load::Open, 0.0);
        let solver = ChargeSolver::for_chain(&h, &chain, ChargeOptions::default()).unwrap();
        let mut rec = Recorder::new(solver, &chain, 0.0);
        let mut sim = Simulator::new(&chain, &ChainState::at_rest(chain.len()), SimOptions::default()).unwrap();
        sim.run_until(periods * chain.period(), &mut rec).unwrap();
        let scan = scan_stored_flow(&rec.traj, &chain.gaps, 64);
        let segs = rec.traj.segments();
        let i = segs.partition_point(|s| s.t_end < scan.1);
        let s = &segs[i.min(segs.len() - 1)];
        let ev: Vec<_> = rec.log.events.iter().filter(|e| (e.event.time - s.t_end).abs() < 1e-12).map(|e| e.event).collect();
        println!("{name}, one-way: min gap/δ {:.2e} at {:.15}, segment [{:.15}, {:.15}] (t_end − t = {:.2e}); events at its end {ev:?}", scan.0, scan.1, s.t_start, s.t_end, s.t_end - scan.1);
        let h = harvester(TransducerMode::Freestanding, Load::Open, start_charge(&h));
        let rec = coupled_run(&chain, &ChainState::at_rest(chain.len()), &h, periods);
        let scan = scan_stored_flow(&rec.traj, &chain.gaps, 64);
        let segs = rec.traj.segments();
        let i = segs.partition_point(|s| s.t_end < scan.1);
        let s = &segs[i.min(segs.len() - 1)];
        let ev: Vec<_> = rec.log.events.iter().filter(|e| (e.event.time - s.t_end).abs() < 1e-12).map(|e| e.event).collect();
        println!("{name}, two-way open: min gap/δ {:.2e} at {:.15}, segment [{:.15}, {:.15}] (t_end − t = {:.2e}); events at its end {ev:?}", scan.0, scan.1, s.t_start, s.t_end, s.t_end - scan.1);
    }
}

#[test]
fn probe_four_mass_release() {
    let chain = common::four_mass_stack();
    let h0 = harvester(TransducerMode::Freestanding, Load::Open, 0.0);
    let h = harvester(TransducerMode::Freestanding, Load::Open, start_charge(&h0));
    let q = start_charge(&h0);
    let rec = coupled_run(&chain, &ChainState::at_rest(4), &h, 6.0);
    let show = |rec: &Recorder, label: &str| {
        let scan = scan_stored_flow(&rec.traj, &chain.gaps, 64);
        println!("{label}: min gap/δ {:.3e} at {:.17}", scan.0, scan.1);
        for e in rec.log.events.iter().filter(|e| (e.event.time - scan.1).abs() < 1e-9) {
            let g: Vec<f64> = (0..3).map(|k| chain.gaps[k] - (e.positions[k + 1] - e.positions[k])).collect();
            println!("  event {:?} at {:.17}: gaps {g:?} v {:?}", e.event.kind, e.event.time, e.velocities);
        }
        for s in rec.traj.segments().iter().filter(|s| (s.t_start - scan.1).abs() < 1e-9 || (s.t_end - scan.1).abs() < 1e-9) {
            let cl: Vec<_> = s.clusters.iter().map(|c| (c.first, c.last)).collect();
            let f = rec.traj.flow_at(0.5 * (s.t_start + s.t_end)).unwrap();
            let mut gs = vec![0.0; 3];
            let mut rs = vec![0.0; 3];
            f.gaps_at(s.t_start, &mut gs, &mut rs);
            let mut ge = vec![0.0; 3];
            f.gaps_at(s.t_end, &mut ge, &mut rs);
            println!("  segment [{:.17}, {:.17}] clusters {cl:?}: gaps at start {gs:?}, at end {ge:?}", s.t_start, s.t_end);
        }
    };
    show(&rec, "two-way open");
    // One-way with the same constant forces.
    let statics = vibrotribo::electrical::Electrostatics::new(&h.transducer()).unwrap();
    let mut forces = vec![0.0; 4];
    statics.mass_forces(q, &mut forces);
    let pushed = ChainParams { forces, ..chain.clone() };
    let solver = ChargeSolver::for_chain(&h, &chain, ChargeOptions::default()).unwrap();
    let mut rec1 = Recorder::new(solver, &pushed, q);
    let mut sim = Simulator::new(&pushed, &ChainState::at_rest(4), SimOptions::default()).unwrap();
    sim.run_until(6.0 * chain.period(), &mut rec1).unwrap();
    show(&rec1, "one-way, constant forces");
}
