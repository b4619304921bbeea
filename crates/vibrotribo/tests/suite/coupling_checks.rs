//! Two-way electromechanical coupling: the checks against truth from outside the
//! coupling code.
//!
//! **Static equilibrium.** With the base at rest the coupled chain settles where every spring
//! balances the electrostatic forces on its mass. The test computes that point on its own,
//! from the field energy of the parallel-plate stack written out in
//! tests/suite/common/electrostatics.rs (docs/MODEL.md §2):
//!
//! ```text
//! freestanding:        U = [Q² d₀ + (Q + σS)² D₁ + (σS − Q)² D₂] / (2ε₀S)
//! contact-separation:  U = [Q² d₀ + (σS − Q)² D] / (2ε₀S)
//! ```
//!
//! A resistor carries no current at rest, so the terminal voltage −∂U/∂Q vanishes:
//!
//! ```text
//! freestanding:        Q* = σS (D₂ − D₁)/(d₀ + D₁ + D₂)
//! contact-separation:  Q* = σS D/(d₀ + D)
//! ```
//!
//! (in open circuit Q keeps its initial value). The force on gap k at constant charge is
//! G_k = −∂U/∂D_k, −(Q + σS)²/(2ε₀S) and −(σS − Q)²/(2ε₀S) for the freestanding gaps,
//! −(σS − Q)²/(2ε₀S) for the contact-separation gap; it pulls mass k (above the gap) down
//! with G_k and mass k + 1 up with −G_k. With y = 0 the equilibrium is k_i x_i = F_i(Q), the
//! gaps D_k = δ_k − (x_{k+1} − x_k) fix Q*, and Q* fixes the forces: a small nonlinear system,
//! solved here by fixed-point iteration (the forces change by ~σ²S/(ε₀(d₀ + D₁ + D₂)) ≈ 6 N/m
//! per metre of gap against springs of 100 N/m and more: a contraction), to rounding.

use vibrotribo::config::Config;
use vibrotribo::coupling::{CoupledChain, CouplingOptions, SolverOnly};
use vibrotribo::electrical::{
    ChargeOptions, ChargeSolver, EPSILON_0, HarvesterParams, Load, TransducerMode, VocModel,
};
use vibrotribo::study::{RunObserver, Sample, Sampling, simulate};
use vibrotribo::{ChainParams, ChainState, Event, Flow, SimOptions, Simulator, StateView};

use crate::common;
use common::balance::Balance;
use common::base_motion::Base;
use common::electrostatics::{VACUUM_PERMITTIVITY, electrostatic_forces, equilibrium_charge, field_energy};

/// The charge at rest: the initial charge in open circuit, otherwise where −∂U/∂Q = 0.
fn charge_at_rest(h: &HarvesterParams, gaps: &[f64]) -> f64 {
    if h.load == Load::Open {
        return h.initial_charge.expect("open circuit: a given charge");
    }
    equilibrium_charge(h, gaps)
}

/// The static equilibrium (positions, m, and charge, C) of `chain` (base at rest) under the
/// electrostatic forces, by fixed-point iteration on k_i x_i = F_i(Q*(D(x))).
fn static_equilibrium(chain: &ChainParams, h: &HarvesterParams) -> (Vec<f64>, f64) {
    let n = chain.len();
    let mut x = vec![0.0; n];
    let mut q = 0.0;
    for iteration in 0..200 {
        let gaps: Vec<f64> = (0..n - 1).map(|k| chain.gaps[k] - (x[k + 1] - x[k])).collect();
        q = charge_at_rest(h, &gaps);
        let f = electrostatic_forces(h, n, q);
        let next: Vec<f64> = (0..n).map(|i| f[i] / chain.stiffness[i]).collect();
        let change = x
            .iter()
            .zip(&next)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        x = next;
        if change == 0.0 || (iteration > 50 && change < 1e-18) {
            break;
        }
    }
    (x, q)
}

/// Runs the coupled chain from rest (base at rest) for `periods` periods; the final state
/// and the final charge.
fn settle(chain: &ChainParams, h: &HarvesterParams, periods: f64) -> (ChainState, f64) {
    let sim = Simulator::new(chain, &ChainState::at_rest(chain.len()), SimOptions::default()).unwrap();
    let mut host = SolverOnly(ChargeSolver::for_chain(h, chain, ChargeOptions::default()).unwrap());
    let mut coupled = CoupledChain::new(sim, h, CouplingOptions::default()).unwrap();
    coupled.run_until(periods * chain.period(), &mut host).unwrap();
    (coupled.state(), host.0.charge())
}

fn harvester(mode: TransducerMode, load: Load, initial_charge: Option<f64>) -> HarvesterParams {
    HarvesterParams {
        mode,
        voc_model: VocModel::Exact,
        load,
        initial_charge,
        ..HarvesterParams::default()
    }
}

/// The chain at rest (amplitude 0) with enough damping (c = 2 N·s/m, decay rate c/2m ≥ 8 s⁻¹)
/// that the transient from rest dies below 1e-12 m within the run.
fn at_rest(chain: ChainParams) -> ChainParams {
    let n = chain.len();
    let mut c = chain;
    c.excitation.amplitude = 0.0;
    c.damping = vec![2.0; n];
    c
}

/// `[a, b, …]` in scientific notation with `digits` decimals.
fn list(v: &[f64], digits: usize) -> String {
    let items: Vec<String> = v.iter().map(|x| format!("{x:.digits$e}")).collect();
    format!("[{}]", items.join(", "))
}

/// Position tolerance, m (the issue's).
const TOLERANCE_M: f64 = 1e-9;

/// Settles each case and compares with the equilibrium computed above; returns the shifts.
fn check_equilibrium(name: &str, chain: &ChainParams, h: &HarvesterParams, periods: f64) -> Vec<f64> {
    assert_eq!(VACUUM_PERMITTIVITY, EPSILON_0, "the same ε₀");
    let (expected, q_expected) = static_equilibrium(chain, h);
    let started = std::time::Instant::now();
    let (state, q) = settle(chain, h, periods);
    let elapsed = started.elapsed().as_secs_f64();
    let dx: Vec<f64> = (0..chain.len())
        .map(|i| state.positions[i] - expected[i])
        .collect();
    let v_max = state.velocities.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    println!(
        "{name}: {periods} periods in {elapsed:.2} s; equilibrium x = {} m, Q* = {q_expected:.6e} C; \
         run: Q = {q:.6e} C, x − x* = {} m, |v| ≤ {v_max:.1e} m/s",
        list(&expected, 6),
        list(&dx, 2),
    );
    for (i, d) in dx.iter().enumerate() {
        assert!(d.abs() <= TOLERANCE_M, "{name}: mass {i} off by {d:e} m");
    }
    let sigma_s = h.charge_density * h.area;
    assert!(
        (q - q_expected).abs() <= 1e-9 * sigma_s,
        "{name}: Q = {q:e} C, expected {q_expected:e} C"
    );
    assert!(
        v_max <= TOLERANCE_M * chain.omega(),
        "{name}: not at rest, |v| = {v_max:e}"
    );
    expected
}

/// The paper's chain and harvester (σ = 15 µC/m², S = 0.01 m², 100 kΩ, exact V_oc) with the
/// base at rest: by symmetry Q* = 0, so each outer mass moves toward the middle one by
/// σ²S/(2ε₀)/k = 0.127 N / 120 N/m ≈ 1.06 mm (the issue's estimate) and the middle one stays.
#[test]
fn static_equilibrium_paper_harvester_resistor() {
    let chain = at_rest(ChainParams::default());
    let h = harvester(
        TransducerMode::Freestanding,
        Load::Resistor { resistance: 1e5 },
        None,
    );
    let x = check_equilibrium("paper chain, 100 kΩ", &chain, &h, 30.0);
    let shift = h.charge_density.powi(2) * h.area / (2.0 * VACUUM_PERMITTIVITY) / chain.stiffness[0];
    println!("  σ²S/(2ε₀k) = {shift:.6e} m");
    assert!((0.9e-3..1.2e-3).contains(&shift), "of order 1 mm: {shift:e}");
    assert!(
        (x[0] + shift).abs() < 1e-15 && (x[2] - shift).abs() < 1e-15 && x[1] == 0.0,
        "{x:?}"
    );
}

/// An asymmetric chain (gaps 15 and 25 mm, stiffnesses 100, 150, 200 N/m) with a 10 MΩ
/// resistor: Q* ≠ 0 and depends on the gaps, which depend on the forces it sets.
#[test]
fn static_equilibrium_asymmetric_resistor() {
    let chain = at_rest(ChainParams {
        gaps: vec![0.015, 0.025],
        stiffness: vec![100.0, 150.0, 200.0],
        ..ChainParams::default()
    });
    let h = harvester(
        TransducerMode::Freestanding,
        Load::Resistor { resistance: 1e7 },
        None,
    );
    let x = check_equilibrium("asymmetric chain, 10 MΩ", &chain, &h, 30.0);
    // The middle mass moves: the two gap forces differ.
    assert!(x[1].abs() > 1e-5, "{x:?}");
}

/// Open circuit with a given charge: the forces are constant, the equilibrium linear.
#[test]
fn static_equilibrium_open_circuit() {
    let chain = at_rest(ChainParams::default());
    let h = harvester(TransducerMode::Freestanding, Load::Open, Some(-0.6e-7));
    check_equilibrium("paper chain, open, Q = −0.6e-7 C", &chain, &h, 30.0);
}

/// Two masses, contact-separation mode: with a resistor the equilibrium charge nearly
/// cancels the tribo-charge facing the gap (Q* = σS D/(d₀ + D)) and the force is small
/// (~(d₀/D)² of σ²S/2ε₀); in open circuit at Q = 0.3σS it is 0.49 σ²S/2ε₀.
#[test]
fn static_equilibrium_contact_separation() {
    let two = at_rest(ChainParams {
        masses: vec![0.05, 0.1],
        stiffness: vec![120.0, 150.0],
        gaps: vec![0.01],
        ..ChainParams::default()
    });
    let h = harvester(
        TransducerMode::ContactSeparation,
        Load::Resistor { resistance: 1e9 },
        None,
    );
    let x = check_equilibrium("two masses, contact-separation, 1 GΩ", &two, &h, 30.0);
    assert!(x[0].abs() > 1e-9, "{x:?}");
    let q0 = 0.3 * h.charge_density * h.area;
    let h = harvester(TransducerMode::ContactSeparation, Load::Open, Some(q0));
    let x = check_equilibrium("two masses, contact-separation, open", &two, &h, 30.0);
    assert!(x[0].abs() > 1e-4, "{x:?}");
}

// ---------------------------------------------------------------------------------------
// Energy balance over a coupled run.
// ---------------------------------------------------------------------------------------
//
// **The identity.** With E = Σ ½ m_i v_i² + ½ k_i (x_i − y)² as in tests/suite/excitation_energy.rs
// (whose derivation this extends), the electrostatic force F_i on mass i adds Σ F_i v_i to
// dE/dt. The gap force G_k acts as +G_k on mass k and −G_k on mass k + 1, and
// D_k = δ_k − (x_{k+1} − x_k), so Σ F_i v_i = Σ G_k (v_k − v_{k+1}) = Σ G_k dD_k/dt. Along
// any motion dU/dt = ∂U/∂Q dQ/dt + Σ ∂U/∂D_k dD_k/dt = −V I − Σ G_k dD_k/dt (the voltage
// is −∂U/∂Q, the gap force −∂U/∂D_k). So Σ F_i v_i = −dU/dt − V I, and over the run
//
//     W_base = ΔE + D_damping + L_events + E_load + ΔU,
//
// with E_load = ∫ V I dt the energy that left the transducer's terminals (V the generator's
// voltage, I = dQ/dt; `ElectricalOutcome::terminal_energy_j`, the charge solver's
// collocation quadrature of V·I) and ΔU = U(Q, D₁, D₂)(end) − U(start) (U written out in
// tests/suite/common/electrostatics.rs, the charge taken from the run's samples at t = 0 and at the
// end). For a resistor E_load is ∫ V²/R dt, what the solver books per period as the load's
// energy; for the rectifier it is the storage side's energy ∫ V_s I_out dt (what the periods
// book) plus the bridge's losses, which the periods leave out.
// W_base, D_damping and L_events are measured as in tests/suite/excitation_energy.rs: Gauss–Legendre
// quadrature of the closed-form flow, kinetic-energy jumps at events.
//
// In one-way mode the masses feel no force, so W_base = ΔE + D + L alone; the load's energy
// and ΔU are then energy the model creates: the full identity misses by E_load + ΔU.

/// What the balance of one run came to.
#[derive(Debug, Clone, Copy)]
struct Closure {
    /// W − (ΔE + D + L + E_load + ΔU), relative to |W|.
    full: f64,
    /// The same, J.
    full_j: f64,
    /// |ΔU| + E_load, J: the scale of the electrical terms.
    electrical_j: f64,
    /// W − (ΔE + D + L), relative to |W|.
    mechanical: f64,
    /// E_load = ∫V·I dt at the transducer's terminals, J.
    load: f64,
    /// The load's energy as the periods book it (for the rectifier ∫V_s I_out dt), J.
    booked: f64,
    /// Average power after the transient, W.
    power: f64,
}

/// Runs `text` (a configuration) with the balance observed; prints and returns the terms.
fn coupled_balance(name: &str, text: &str) -> Closure {
    let config = Config::from_toml_str(text).unwrap();
    let mut spec = config.run_spec(false);
    spec.sampling = Some(Sampling::PerPeriod(1));
    let h = spec.harvester.as_ref().unwrap().params.clone();
    let chain = &spec.chain;
    // Integrands are products of terms up to the natural frequencies: 12 nodes over
    // 0.5/(2ω_max) leave a relative error far below rounding.
    let wn = (0..chain.len())
        .map(|i| (chain.stiffness[i] / chain.masses[i]).sqrt())
        .fold(chain.omega(), f64::max);
    let base = Base::Sine {
        amplitude: chain.excitation.amplitude,
        omega: chain.omega(),
    };
    let mut obs = Balance::new(&spec, base, 2.0 * wn);
    let started = std::time::Instant::now();
    let outcome = simulate(&spec, &mut obs).unwrap();
    let elapsed = started.elapsed().as_secs_f64();
    assert!(outcome.failure().is_none(), "{:?}", outcome.ending);
    assert_eq!(obs.last.0, outcome.final_time);
    let electrical = outcome.electrical.as_ref().unwrap();
    // What the periods book as the load's energy, and what left the terminals (∫V·I dt).
    let booked: f64 = electrical.periods.iter().map(|p| p.energy_j).sum();
    let e_load = electrical.terminal_energy_j;
    if h.load.resistance().is_some() {
        assert!(
            (e_load - booked).abs() <= 1e-12 * booked,
            "a resistor's ∫V·I is its ∫V²/R: {e_load:e} against {booked:e} J"
        );
    }
    let power = electrical.power.as_ref().unwrap().average_power_w;
    // The charge at the start and at the end, from the samples at t = 0 and t = t_end.
    assert_eq!(
        obs.samples.len() as u64,
        outcome.periods + 1,
        "a sample per boundary"
    );
    let (t0, q0, ref g0) = obs.samples[0];
    let (t1, q1, ref g1) = *obs.samples.last().unwrap();
    assert_eq!(t0, 0.0);
    assert!((t1 - outcome.final_time).abs() <= 1e-12 * t1);
    let n = spec.chain.len();
    let (x_end, v_end) = (&outcome.final_state.positions, &outcome.final_state.velocities);
    // The samples at the ends are the run's initial and final states (to rounding).
    let near = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(p, q)| (p - q).abs() <= 1e-14);
    assert!(near(g1, &obs.gaps(x_end)), "{g1:?}");
    assert!(near(g0, &obs.gaps(&spec.initial.positions)), "{g0:?}");
    let du = field_energy(&h, q1, g1) - field_energy(&h, q0, g0);
    let de =
        obs.energy(t1, x_end, v_end) - obs.energy(0.0, &spec.initial.positions, &spec.initial.velocities);
    let (w, d, l) = (obs.work.get(), obs.damping.get(), obs.lost.get());
    let mechanical = w - (de + d + l);
    let full = mechanical - (e_load + du);
    println!(
        "{name} ({} masses, {} periods, {:.3} s): run + balance {elapsed:.2} s, {} events, {} quadrature intervals\n  \
         W_base = {w:.12e} J, ΔE = {de:.6e} J, D = {d:.6e} J, L = {l:.6e} J, E_load = ∫V·I = {e_load:.6e} J \
         (booked as the load's {booked:.6e} J), ΔU = {du:.6e} J (Q: {q0:.6e} → {q1:.6e} C)\n  \
         W − (ΔE + D + L) = {mechanical:.3e} J = {:.3e} of |W|\n  \
         W − (ΔE + D + L + E_load + ΔU) = {full:.3e} J = {:.3e} of |W|; unreported between flows {:.1e} J; \
         power after the transient {power:.6e} W",
        n,
        outcome.periods,
        t1,
        obs.events,
        obs.quadrature_intervals,
        mechanical / w.abs(),
        full / w.abs(),
        obs.unreported.get(),
    );
    assert!(
        obs.unreported.get().abs() <= 1e-12 * w.abs(),
        "{}",
        obs.unreported.get()
    );
    Closure {
        full: full / w.abs(),
        full_j: full,
        electrical_j: du.abs() + e_load,
        mechanical: mechanical / w.abs(),
        load: e_load,
        booked,
        power,
    }
}

/// The paper's default case with the exact V_oc and its 100 kΩ, over `periods` from rest.
fn default_case(coupling: &str, periods: u32, rtol: f64, tolerance: f64) -> String {
    format!(
        "[harvester]\nvoc_model = \"exact\"\ncoupling = \"{coupling}\"\ncoupling_tolerance = {tolerance:e}\n\
         [electrical]\nrtol = {rtol:e}\n[run]\nperiods = {periods}\ntransient_periods = {}\n",
        periods / 2
    )
}

/// Energy balance of a two-way run (the paper's default case, 100 kΩ, 20 periods from rest):
/// W_base = ΔE + D + L + E_load + ΔU to 1e-8 of W_base; the one-way run of the same case
/// misses the full identity by E_load + ΔU (what the one-way model leaves out).
#[test]
fn energy_balance_two_way_resistor() {
    let two = coupled_balance(
        "two-way, default case, 100 kΩ",
        &default_case("two_way", 20, 1e-10, 1e-11),
    );
    let one = coupled_balance(
        "one-way, default case, 100 kΩ",
        &default_case("one_way", 20, 1e-10, 1e-11),
    );
    println!(
        "two-way {:.6e} W, one-way {:.6e} W; the full identity: two-way {:.2e}, one-way {:.2e} of |W|",
        two.power, one.power, two.full, one.full
    );
    assert!(two.full.abs() < 1e-8, "{two:?}");
    // One-way: the mechanics alone closes, the electrical terms are unaccounted for.
    assert!(one.mechanical.abs() < 1e-8, "{one:?}");
    assert!(one.full.abs() > 100.0 * 1e-8, "{one:?}");
    assert!(two.load > 0.0 && one.load > 0.0);
}

/// Energy balance of the chatter case in its sticking regime (masses 0.05/0.15/0.05 kg, gaps
/// 5 mm, Ω = 0.4, 100 kΩ, 5 periods from rest: impacts, chatter, sticks and releases), where
/// a two-way run can loop at a release (tests/suite/issue_coupled_stick_release_loop.rs): the
/// work of the base is ΔE + D + L + E_load + ΔU to 1e-8 of it and to 1e-5 of the electrical
/// terms.
#[test]
fn energy_balance_two_way_chatter_case_sticking() {
    let two = coupled_balance(
        "two-way, chatter case, Ω = 0.4",
        "[oscillator]\nmasses = [0.05, 0.15, 0.05]\ngaps = [0.005, 0.005]\n\
         [excitation]\nomega_ratio = 0.4\n\
         [harvester]\nvoc_model = \"exact\"\ncoupling = \"two_way\"\n\
         [electrical]\nrtol = 1e-10\n[run]\nperiods = 5\ntransient_periods = 2\n",
    );
    println!(
        "full identity {:.3e} of |W|, {:.3e} of the electrical terms",
        two.full,
        two.full_j / two.electrical_j
    );
    assert!(two.full.abs() < 1e-8, "{two:?}");
    assert!(two.full_j.abs() < 1e-5 * two.electrical_j, "{two:?}");
}

/// The default case as [`default_case`] with the full-wave bridge into its 1 µF storage
/// capacitor (1N4148 diodes, no load resistor) instead of the resistor.
fn rectifier_case(periods: u32, rtol: f64, tolerance: f64) -> String {
    default_case("two_way", periods, rtol, tolerance)
        .replace("[harvester]\n", "[harvester]\nload = \"rectifier\"\n")
}

/// Energy balance of a two-way run with the rectifier (the default case, 20 periods from
/// rest): W_base = ΔE + D + L + ∫V·I dt + ΔU, the electrical term the energy that left the
/// transducer's terminals, which is the storage side's ∫V_s I_out dt plus the bridge's losses.
/// It closes to 1e-8 of W and to 1e-6 of the electrical terms; booking the storage side's
/// energy alone (as the periods do) would miss by the bridge's losses, far more.
#[test]
fn energy_balance_two_way_rectifier() {
    let two = coupled_balance(
        "two-way, default case, rectifier",
        &rectifier_case(20, 1e-10, 1e-11),
    );
    let losses = two.load - two.booked;
    println!(
        "full identity {:.3e} of |W|, {:.3e} of the electrical terms; bridge losses {losses:.6e} J \
         ({:.3e} of ∫V·I)",
        two.full,
        two.full_j / two.electrical_j,
        losses / two.load
    );
    assert!(two.full.abs() < 1e-8, "{two:?}");
    assert!(two.full_j.abs() < 1e-6 * two.electrical_j, "{two:?}");
    // The losses are real and far above the residual: the storage side's energy alone would
    // not close the identity.
    assert!(losses > 0.0 && losses > 1000.0 * two.full_j.abs(), "{two:?}");
}

/// The rectifier's balance residual against `coupling_tolerance` (the default case, 20
/// periods), as [`energy_balance_against_the_coupling_tolerance`] for the resistor. Measured:
/// +4.1e-10, −1.4e-9, −4.8e-10, −1.7e-10 J at 1e-10, 1e-11, 1e-12, 1e-13 m (the electrical
/// terms are 2.9 mJ; the last step is near the charge solver's rtol of 1e-10). The residual at
/// the loosest tolerance is erratic (it moves between −1.85e-8 and +4.1e-10 J when event times
/// change by rounding: the coupling error of 1e-10 m windows, whose edges follow the event
/// times), so the residual is not monotone decade by decade here; what holds is the envelope:
/// the tightest tolerance gives the smallest residual, and from 1e-11 m on it is within 1e-6
/// of the electrical terms.
#[test]
fn energy_balance_rectifier_against_the_coupling_tolerance() {
    balance_against_the_coupling_tolerance("two-way rectifier", Shrinks::ToTheTightest, |tolerance| {
        rectifier_case(20, 1e-10, tolerance)
    });
}

/// Diagnosis of the two-way residual: at every time of a fine grid, the force the accepted
/// motion was actually driven by, F_eff,i = m_i x_i'' + c_i (x_i' − y') + k_i (x_i − y) (x''
/// by a central difference of the closed-form velocity over ±0.2 µs), against the force of
/// the solver's charge at that time, F_i(Q) from [`electrostatic_forces`]. Σ (F_eff − F(Q))·v
/// summed over the grid is the work the coupling's force representation adds; it should
/// account for the balance's residual.
#[derive(Default)]
struct ForceProbe {
    step: f64,
    m: Vec<f64>,
    k: Vec<f64>,
    c: Vec<f64>,
    amplitude: f64,
    omega: f64,
    h: Option<HarvesterParams>,
    /// Grid index → (F_eff per mass, v per mass), waiting for the sample's charge.
    eff: std::collections::HashMap<u64, (Vec<f64>, Vec<f64>)>,
    last_event: f64,
    /// Grid index → time since the last event, s.
    since: std::collections::HashMap<u64, f64>,
    /// Σ (F_eff − F(Q))·v·step, J.
    work: f64,
    /// Largest |F_eff − F(Q)| (N), its time and the time since the last event (s).
    worst: (f64, f64, f64),
    /// `work` by time since the last event: < 0.1 ms, < 1 ms, < 10 ms, < 30 ms, < 100 ms, more.
    by_since: [f64; 6],
}

impl RunObserver for ForceProbe {
    fn flow(&mut self, flow: &Flow<'_>) {
        let n = self.m.len();
        let (mut x, mut v, mut vp, mut vm) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let j0 = (flow.t_start / self.step).ceil() as u64;
        let mut j = j0;
        loop {
            let t = j as f64 * self.step;
            if t > flow.t_end {
                break;
            }
            let d = 2e-7;
            flow.state_at(t, &mut x, &mut v);
            flow.state_at(t + d, &mut vec![0.0; n], &mut vp);
            flow.state_at(t - d, &mut vec![0.0; n], &mut vm);
            let (s, co) = (self.omega * t).sin_cos();
            let (y, yd) = (self.amplitude * s, self.amplitude * self.omega * co);
            let f: Vec<f64> = (0..n)
                .map(|i| {
                    self.m[i] * (vp[i] - vm[i]) / (2.0 * d) + self.c[i] * (v[i] - yd) + self.k[i] * (x[i] - y)
                })
                .collect();
            self.eff.insert(j, (f, v.clone()));
            self.since.insert(j, t - self.last_event);
            j += 1;
        }
    }
    fn event(&mut self, event: &Event, _state: &StateView<'_>) {
        self.last_event = event.time;
    }
    fn wants_samples(&self) -> bool {
        true
    }
    fn sample(&mut self, sample: &Sample<'_>) {
        let Some(e) = sample.electrical else { return };
        let Some((f, v)) = self.eff.remove(&sample.index) else {
            return;
        };
        let since = self.since.remove(&sample.index).unwrap();
        let n = self.m.len();
        let g = electrostatic_forces(self.h.as_ref().unwrap(), n, e.charge_c);
        let mut p = 0.0;
        for i in 0..n {
            let df = f[i] - g[i];
            p += df * v[i];
            if df.abs() > self.worst.0 {
                self.worst = (df.abs(), sample.time, since);
            }
        }
        self.work += p * self.step;
        let bucket = match since {
            s if s < 1e-4 => 0,
            s if s < 1e-3 => 1,
            s if s < 1e-2 => 2,
            s if s < 3e-2 => 3,
            s if s < 1e-1 => 4,
            _ => 5,
        };
        self.by_since[bucket] += p * self.step;
    }
}

/// The same balance measured against the electrical terms it is about (|ΔU| + E_load, 2.6 mJ
/// here, against W = 111 J): the force of the charge and the charge's own energy books agree
/// to 1e-6 of them (2.9e-7 at the default tolerance, −7.5e-10 J over 20 periods). Before the
/// coupling matched each window's force impulse and first moment to the solver's charge
/// (the `vibrotribo::coupling` module docs) it was 2·10⁻⁴ (5.8e-7 J, 1.2 % of E_load) and did not shrink
/// with `coupling_tolerance`; see [`energy_balance_against_the_coupling_tolerance`].
#[test]
fn energy_balance_two_way_against_the_electrical_terms() {
    let two = coupled_balance(
        "two-way, default case, 100 kΩ",
        &default_case("two_way", 20, 1e-10, 1e-11),
    );
    assert!(
        two.full_j.abs() < 1e-6 * two.electrical_j,
        "{:.3e} of the electrical terms",
        two.full_j / two.electrical_j
    );
}

/// The coupling's force error, probed pointwise: Σ (F_eff − F(Q))·v on a 1 µs grid, and when
/// it accrues. Before the fix the probe reproduced the balance's residual (−5.6e-7 J against
/// 5.8e-7 J, 71 % of it within 0.1 ms after impacts: the charge's R·C boundary layer, which the
/// window's polynomial missed). Now the residual (~1e-9 J) is below the probe's own resolution
/// (a Riemann sum on a 1 µs grid of a force error that, inside the ~1 µs layer, is still there
/// pointwise: only its impulse and first moment per window are matched), so the probe checks
/// that what it sees is at most that resolution, 2e-8 J (30× below the old error). A
/// diagnostic (about 10 s): `cargo test --test suite coupling_checks -- --ignored --nocapture
/// force_error`.
#[test]
#[ignore = "diagnostic, ~10 s"]
fn force_error_accounts_for_the_residual() {
    let text = default_case("two_way", 20, 1e-10, 1e-11);
    let residual = coupled_balance("two-way, default case, 100 kΩ", &text).full_j;
    let config = Config::from_toml_str(&text).unwrap();
    let mut spec = config.run_spec(false);
    let step = 1e-6;
    spec.sampling = Some(Sampling::Uniform { start: 0.0, step });
    let ch = spec.chain.clone();
    let mut probe = ForceProbe {
        step,
        m: ch.masses.clone(),
        k: ch.stiffness.clone(),
        c: ch.damping.clone(),
        amplitude: ch.excitation.amplitude,
        omega: ch.omega(),
        h: Some(spec.harvester.as_ref().unwrap().params.clone()),
        ..Default::default()
    };
    simulate(&spec, &mut probe).unwrap();
    println!(
        "Σ (F_eff − F(Q))·v dt = {:.3e} J against the residual {residual:.3e} J; largest |F_eff − F(Q)| = {:.2e} N \
         at t = {:.6} s, {:.2e} s after an event; by time since the last event (<0.1 ms, <1 ms, <10 ms, <30 ms, \
         <100 ms, more): {} J",
        probe.work,
        probe.worst.0,
        probe.worst.1,
        probe.worst.2,
        list(&probe.by_since, 2)
    );
    assert!(residual.abs() < 2e-8, "{residual}");
    assert!(probe.work.abs() < 2e-8, "{} vs {residual}", probe.work);
}

/// The residual of the full identity against `coupling_tolerance` (the default case, 100 kΩ,
/// 20 periods): it shrinks with the tolerance, and from the default tolerance on it is within
/// 1e-6 of the electrical terms. Measured: +2.8e-9, +1.1e-9, +3.7e-11, −9.6e-12 J at 1e-10,
/// 1e-11, 1e-12, 1e-13 m (at 1e-11 m 4.1e-7 of the electrical terms, 9.5e-12 of the work); the
/// four runs take 0.2 s. Windows whose inner charge nodes are taken from the solver's dense
/// output instead of solved do not pass (the 1e-12 m row no smaller than the 1e-11 m one).
#[test]
fn energy_balance_against_the_coupling_tolerance() {
    balance_against_the_coupling_tolerance("two-way", Shrinks::DecadeByDecade, |tolerance| {
        default_case("two_way", 20, 1e-10, tolerance)
    });
}

/// How a balance residual is asserted to shrink with the coupling tolerance.
#[derive(Clone, Copy, PartialEq)]
enum Shrinks {
    /// With each tighter tolerance.
    DecadeByDecade,
    /// The tightest tolerance's residual is below every looser one's.
    ToTheTightest,
}

/// The coupled balance of `case(tolerance)` at coupling tolerances 1e-10 … 1e-13 m, printed as a
/// table: the residual shrinks with the tolerance as `shrinks` says, and from 1e-11 m on it is
/// within 1e-6 of the electrical terms.
fn balance_against_the_coupling_tolerance(name: &str, shrinks: Shrinks, case: impl Fn(f64) -> String) {
    let mut rows = Vec::new();
    for tolerance in [1e-10, 1e-11, 1e-12, 1e-13] {
        let started = std::time::Instant::now();
        let two = coupled_balance(
            &format!("{name}, coupling_tolerance {tolerance:e} m"),
            &case(tolerance),
        );
        rows.push((tolerance, two, started.elapsed().as_secs_f64()));
    }
    for (tolerance, two, secs) in &rows {
        println!(
            "tolerance {tolerance:.0e} m: residual {:+.3e} J = {:+.3e} of the electrical terms ({:.3e} J), \
             {:+.3e} of W; {secs:.2} s",
            two.full_j,
            two.full_j / two.electrical_j,
            two.electrical_j,
            two.full
        );
    }
    let (tightest, looser) = rows.split_last().expect("four tolerances");
    for (i, looser_row) in looser.iter().enumerate() {
        let tighter = match shrinks {
            Shrinks::DecadeByDecade => &rows[i + 1],
            Shrinks::ToTheTightest => tightest,
        };
        assert!(
            tighter.1.full_j.abs() < looser_row.1.full_j.abs(),
            "no smaller at {:e} m than at {:e} m",
            tighter.0,
            looser_row.0
        );
    }
    for (tolerance, two, _) in &rows[1..] {
        assert!(
            two.full_j.abs() < 1e-6 * two.electrical_j,
            "{tolerance:e}: {:.3e} of the electrical terms",
            two.full_j / two.electrical_j
        );
    }
}
