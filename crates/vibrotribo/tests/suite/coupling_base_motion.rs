//! Two-way coupling under base motion other than the sine (band-limited random acceleration, a
//! recorded ground acceleration) against the energy identity of a coupled run:
//!
//! ```text
//! W_base = ΔE + D_damping + L_events + E_load + ΔU
//! ```
//!
//! derived in tests/suite/coupling_checks.rs (the electrostatic force does −dU/dt − V·I of work on
//! the masses) from tests/suite/excitation_energy.rs's mechanical balance, which holds for any base
//! displacement y(t): E = Σ ½ m_i v_i² + ½ k_i (x_i − y)², W_base = ∫ Σ f_i y' dt with
//! f_i = −k_i (x_i − y) − c_i (v_i − y'), D = ∫ Σ c_i (v_i − y')² dt, L the energy jumps at
//! events. Nothing here comes from the coupling code: W and D are Gauss–Legendre
//! quadratures of the closed-form flow against the base displacement evaluated on its own
//! pieces (tests/suite/common/base_motion.rs; each flow piece split at the knots), E_load is the
//! charge solver's ∫V·I dt, ΔU the field energy of the plates written out in
//! tests/suite/common/electrostatics.rs at the charges and gaps of the first and last samples.
//!
//! The one-way run of the same case closes the mechanical balance alone and misses the full
//! identity by E_load + ΔU, far outside the tolerance: the check can fail.

use vibrotribo::Simulator;
use vibrotribo::config::{Config, apply_overrides};
use vibrotribo::study::{Sampling, simulate};

use crate::common;
use common::balance::Balance;
use common::base_motion::Base;
use common::electrostatics::field_energy;

/// Relative tolerance of the full identity, of |W_base| (tests/suite/coupling_checks.rs's, under
/// the sine, at the default coupling tolerance 1e-11 m).
const TOLERANCE: f64 = 1e-8;

/// What the balance of one run came to.
#[derive(Debug, Clone, Copy)]
struct Closure {
    /// W − (ΔE + D + L + E_load + ΔU), relative to |W|.
    full: f64,
    /// W − (ΔE + D + L), relative to |W|.
    mechanical: f64,
    /// Energy changes no event reports, relative to |W|.
    unreported: f64,
    /// E_load = ∫V·I dt, J.
    load: f64,
    events: usize,
}

/// Runs `config` (a harvester with the exact V_oc) with the balance observed; `omega_max`
/// (rad/s) bounds the frequencies of the integrands' factors.
fn coupled_balance(name: &str, config: &Config, omega_max: f64) -> Closure {
    config.check_runnable().unwrap();
    let mut spec = config.run_spec(false);
    spec.sampling = Some(Sampling::PerPeriod(1));
    let end = spec.periods as f64 * spec.chain.period();
    // What the engine is driven by: the base displacement's pieces (the signal itself).
    let sim = Simulator::driven(
        &spec.chain,
        &spec.initial,
        spec.options.clone(),
        spec.base_motion.as_ref(),
        end,
    )
    .unwrap();
    let displacement = sim
        .base_displacement()
        .expect("a base motion other than the sine");
    let base = match (displacement.cubic(), displacement.pieces()) {
        (Some(c), _) => Base::Spline(c),
        (None, Some(p)) => Base::Pieces(p),
        (None, None) => unreachable!("a displacement is a cubic or pieces"),
    };
    let h = spec.harvester.as_ref().unwrap().params.clone();
    let mut obs = Balance::new(&spec, base, omega_max);
    let outcome = simulate(&spec, &mut obs).unwrap();
    assert!(outcome.failure().is_none(), "{name}: {:?}", outcome.ending);
    let electrical = outcome.electrical.as_ref().unwrap();
    let e_load = electrical.terminal_energy_j;
    assert_eq!(
        obs.samples.len() as u64,
        outcome.periods + 1,
        "a sample per boundary"
    );
    let (t0, q0, ref g0) = obs.samples[0];
    let (t1, q1, ref g1) = *obs.samples.last().unwrap();
    assert_eq!(t0, 0.0);
    let (x_end, v_end) = (&outcome.final_state.positions, &outcome.final_state.velocities);
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
        "{name}: {} periods, {} events\n  W_base = {w:.12e} J, ΔE = {de:.6e} J, D = {d:.6e} J, L = {l:.6e} J, \
         E_load = {e_load:.6e} J, ΔU = {du:.6e} J\n  W − (ΔE + D + L) = {:.3e} of |W|; \
         W − (ΔE + D + L + E_load + ΔU) = {full:.3e} J = {:.3e} of |W|; unreported {:.1e} J",
        outcome.periods,
        obs.events,
        mechanical / w.abs(),
        full / w.abs(),
        obs.unreported.get(),
    );
    Closure {
        full: full / w.abs(),
        mechanical: mechanical / w.abs(),
        unreported: obs.unreported.get() / w.abs(),
        load: e_load,
        events: obs.events,
    }
}

/// The two-way run closes the full identity; the one-way run of the same case closes only
/// the mechanical part and misses the full one by the electrical terms.
fn check_two_way_against_one_way(name: &str, two_way: &Config, omega_max: f64) {
    let two = coupled_balance(&format!("two-way, {name}"), two_way, omega_max);
    let mut one_way = two_way.clone();
    apply_overrides(&mut one_way, &["harvester.coupling=one_way"]).unwrap();
    let one = coupled_balance(&format!("one-way, {name}"), &one_way, omega_max);
    // Impacts in both runs: the events' energy jumps are in the balance.
    assert!(two.events > 0 && one.events > 0, "{two:?} {one:?}");
    assert!(two.full.abs() < TOLERANCE, "{two:?}");
    assert!(two.unreported.abs() < TOLERANCE, "{two:?}");
    assert!(one.mechanical.abs() < TOLERANCE, "{one:?}");
    assert!(one.full.abs() > 100.0 * TOLERANCE, "{one:?}");
    assert!(two.load > 0.0 && one.load > 0.0);
}

/// The harvester of the paper's default case with the exact V_oc, two-way.
const TWO_WAY: &str =
    "[harvester]\nvoc_model = \"exact\"\ncoupling = \"two_way\"\n[electrical]\nrtol = 1e-10\n";

/// The paper's default chain under flat random base acceleration, 2–20 Hz, 40 m/s² RMS,
/// 8 reference periods (1.4 s), 100 kΩ.
#[test]
fn energy_balance_two_way_random() {
    let text = format!(
        "[excitation]\nkind = \"random\"\nrms_acceleration = 40\nf_low_hz = 2\nf_high_hz = 20\nseed = 14\n\
         [run]\nperiods = 8\ntransient_periods = 4\n{TWO_WAY}"
    );
    let config = Config::from_toml_str(&text).unwrap();
    let wn = omega_n_max(&config);
    check_two_way_against_one_way(
        "default chain, random 2–20 Hz",
        &config,
        2.0 * wn.max(std::f64::consts::TAU * 20.0),
    );
}

/// The paper's default chain under the recorded ground acceleration of
/// configs/record_default.toml (1 g peak) over its first 40 reference periods (7.2 s, a few
/// impacts), 100 kΩ.
#[test]
fn energy_balance_two_way_record() {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../configs/record_default.toml");
    let mut config = Config::from_path(&path).unwrap();
    apply_overrides(
        &mut config,
        &[
            "run.periods=40",
            "run.transient_periods=20",
            "harvester.voc_model=exact",
            "harvester.coupling=two_way",
            "electrical.rtol=1e-10",
        ],
    )
    .unwrap();
    let wn = omega_n_max(&config);
    check_two_way_against_one_way("default chain, record RJOB at 1 g", &config, 2.0 * wn);
}

/// The largest natural frequency of a single mass of the chain, rad/s (at least ω).
fn omega_n_max(config: &Config) -> f64 {
    let chain = config.chain();
    chain
        .masses
        .iter()
        .zip(&chain.stiffness)
        .map(|(m, k)| (k / m).sqrt())
        .fold(chain.omega(), f64::max)
}
