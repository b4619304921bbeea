//! Two-way electromechanical coupling: the coupled run against what is known
//! without it.

use vibrotribo::coupling::{CoupledChain, CouplingOptions, SolverOnly};
use vibrotribo::electrical::{ChargeOptions, ChargeSolver, Electrostatics, HarvesterParams, Load, VocModel};
use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator};

fn exact_harvester(load: Load) -> HarvesterParams {
    HarvesterParams {
        voc_model: VocModel::Exact,
        load,
        ..HarvesterParams::default()
    }
}

fn coupled_run(
    chain: &ChainParams,
    harvester: &HarvesterParams,
    periods: f64,
    tol: f64,
) -> (ChainState, ChargeSolver) {
    let sim = Simulator::new(chain, &ChainState::at_rest(chain.len()), SimOptions::default()).unwrap();
    let mut host = SolverOnly(ChargeSolver::for_chain(harvester, chain, ChargeOptions::default()).unwrap());
    let options = CouplingOptions {
        position_tolerance: tol,
        ..CouplingOptions::default()
    };
    let mut coupled = CoupledChain::new(sim, harvester, options).unwrap();
    coupled.run_until(periods * chain.period(), &mut host).unwrap();
    (coupled.state(), host.0)
}

/// Open circuit: the charge stays at its initial value, so the electrostatic forces are
/// constant, and the coupled run must be the closed-form flow of the chain under those
/// constant forces (`ChainParams::forces`), impacts included.
#[test]
fn open_circuit_is_the_closed_form_with_constant_forces() {
    let chain = ChainParams::default();
    for q0 in [0.0, -0.6e-7] {
        let harvester = HarvesterParams {
            initial_charge: Some(q0),
            ..exact_harvester(Load::Open)
        };
        let (coupled, solver) = coupled_run(&chain, &harvester, 12.0, 1e-11);
        assert_eq!(solver.charge(), q0);
        let statics = Electrostatics::new(&harvester.transducer()).unwrap();
        let mut forces = vec![0.0; chain.len()];
        statics.mass_forces(q0, &mut forces);
        assert!(forces.iter().any(|f| f.abs() > 0.05), "a real force: {forces:?}");
        let pushed = ChainParams {
            forces,
            ..chain.clone()
        };
        let mut sim = Simulator::new(&pushed, &ChainState::at_rest(3), SimOptions::default()).unwrap();
        sim.run_until(12.0 * chain.period(), &mut ()).unwrap();
        let reference = sim.state();
        let scale = chain.gaps[0];
        for i in 0..3 {
            let dx = (coupled.positions[i] - reference.positions[i]).abs();
            let dv = (coupled.velocities[i] - reference.velocities[i]).abs();
            assert!(dx <= 1e-10 * scale, "q0 = {q0}, mass {i}: x differs by {dx:e} m");
            assert!(
                dv <= 1e-10 * scale * chain.omega(),
                "q0 = {q0}, mass {i}: v differs by {dv:e} m/s"
            );
        }
    }
}

/// Resistor load: the coupled solution converges as the window tolerance tightens (the
/// power at 1e-11 m and at 1e-12 m agree to 1e-7), and the force changes the power
/// measurably from the one-way model (which leaves the force out).
#[test]
fn resistor_load_converges_and_differs_from_one_way() {
    let chain = ChainParams::default();
    let harvester = exact_harvester(Load::Resistor { resistance: 1e5 });
    let power = |tol: f64| {
        let (_, s) = coupled_run(&chain, &harvester, 16.0, tol);
        s.summary(8).unwrap().average_power_w
    };
    let (coarse, fine) = (power(1e-11), power(1e-12));
    assert!((coarse - fine).abs() <= 1e-7 * fine, "{coarse:e} vs {fine:e}");
    let mut sim = Simulator::new(&chain, &ChainState::at_rest(3), SimOptions::default()).unwrap();
    let mut one_way = ChargeSolver::for_chain(&harvester, &chain, ChargeOptions::default()).unwrap();
    sim.run_until(16.0 * chain.period(), &mut one_way).unwrap();
    let p1 = one_way.summary(8).unwrap().average_power_w;
    eprintln!(
        "one-way {p1:e} W, two-way {fine:e} W ({:+.3}%)",
        100.0 * (fine / p1 - 1.0)
    );
    assert!(
        (fine - p1).abs() > 1e-3 * p1,
        "coupling changes the power: {fine:e} vs {p1:e}"
    );
}

/// The paper's open-circuit voltage law has no field energy: coupling is refused, saying why.
#[test]
fn the_paper_voltage_law_is_refused() {
    let chain = ChainParams::default();
    let sim = Simulator::new(&chain, &ChainState::at_rest(3), SimOptions::default()).unwrap();
    let err = CoupledChain::new(sim, &HarvesterParams::default(), CouplingOptions::default()).unwrap_err();
    assert!(err.to_string().contains("voc_model = \"exact\""), "{err}");
}

/// The run layer's two-way mode (`harvester.coupling = "two_way"`) is the coupled chain:
/// the same power to the last bit, and complete electrical samples.
#[test]
fn the_run_layer_runs_the_coupled_chain() {
    use vibrotribo::coupling::Coupling;
    use vibrotribo::study::{Harvester, RunSpec, simulate};
    let chain = ChainParams::default();
    let harvester = HarvesterParams {
        coupling: Coupling::TwoWay,
        ..exact_harvester(Load::Resistor { resistance: 1e5 })
    };
    let mut spec = RunSpec::new(chain.clone(), 12);
    spec.transient_periods = 6;
    spec.harvester = Some(Harvester::new(harvester.clone(), ChargeOptions::default()));
    let outcome = simulate(&spec, &mut ()).unwrap();
    let via_study = outcome.electrical.unwrap().power.unwrap().average_power_w;
    let (_, solver) = coupled_run(&chain, &harvester, 12.0, harvester.coupling_tolerance);
    let direct = solver.summary(6).unwrap().average_power_w;
    assert_eq!(
        via_study.to_bits(),
        direct.to_bits(),
        "{via_study:e} vs {direct:e}"
    );
}

/// Configuration: the key reads, and two-way coupling with the paper's voltage law is
/// refused naming the key.
#[test]
fn the_coupling_key() {
    use vibrotribo::config::Config;
    let c = Config::from_toml_str("[harvester]\ncoupling = \"two_way\"\nvoc_model = \"exact\"\n").unwrap();
    assert_eq!(c.harvester().coupling, vibrotribo::coupling::Coupling::TwoWay);
    let err = Config::from_toml_str("[harvester]\ncoupling = \"two_way\"\n")
        .unwrap_err()
        .to_string();
    assert!(err.contains("coupling") && err.contains("voc_model"), "{err}");
    let err = Config::from_toml_str("[harvester]\ncoupling = \"both\"\n")
        .unwrap_err()
        .to_string();
    assert!(err.contains("coupling"), "{err}");
}
