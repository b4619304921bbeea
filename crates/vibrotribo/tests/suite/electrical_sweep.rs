//! The load sweep on one recorded trajectory: the refined optimum is a maximum of the average
//! power (checked by independent solver runs either side of it), and bad input is refused.

use vibrotribo::electrical::{ChargeOptions, ChargeSolver, HarvesterParams, Load, load_sweep, log_spaced};
use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator, Trajectory};

fn setup() -> (ChainParams, Trajectory) {
    let chain = ChainParams::default();
    let mut sim = Simulator::new(&chain, &ChainState::at_rest(3), SimOptions::default()).unwrap();
    let mut t = Trajectory::new(&sim);
    sim.run_until(8.0 * chain.period(), &mut t).unwrap();
    (chain, t)
}

fn power(chain: &ChainParams, traj: &Trajectory, r: f64) -> f64 {
    let p = HarvesterParams {
        load: Load::Resistor { resistance: r },
        ..HarvesterParams::default()
    };
    let mut s = ChargeSolver::for_chain(&p, chain, ChargeOptions::default()).unwrap();
    s.run_trajectory(traj).unwrap();
    s.summary(2).unwrap().average_power_w
}

#[test]
fn sweep_finds_the_power_maximum() {
    let (chain, traj) = setup();
    let grid = log_spaced(1e7, 1e13, 13);
    assert_eq!(grid.len(), 13);
    assert!((grid[0] / 1e7 - 1.0).abs() < 1e-12 && (grid[12] / 1e13 - 1.0).abs() < 1e-12);
    let sweep = load_sweep(
        &traj,
        &HarvesterParams::default(),
        chain.period(),
        &grid,
        2,
        &ChargeOptions::default(),
    )
    .unwrap();
    for p in &sweep.points {
        println!(
            "R = {:.3e} Ω: P_a = {:.6e} W",
            p.resistance_ohm, p.average_power_w
        );
    }
    let opt = sweep.optimum;
    println!(
        "optimum R = {:.4e} Ω, P_a = {:.6e} W",
        opt.resistance_ohm, opt.average_power_w
    );
    assert!(!sweep.optimum_at_edge);
    // Grid points are what an independent run gives.
    let mid = sweep.points[6];
    assert_eq!(mid.average_power_w, power(&chain, &traj, mid.resistance_ohm));
    // The optimum beats the best grid point and its neighbours 3 % away on either side.
    let best_grid = sweep.points.iter().map(|p| p.average_power_w).fold(0.0, f64::max);
    assert!(opt.average_power_w >= best_grid);
    for f in [1.03, 1.0 / 1.03] {
        let p = power(&chain, &traj, opt.resistance_ohm * f);
        assert!(
            p <= opt.average_power_w,
            "P({:.4e}) = {p:e} exceeds the reported optimum {:e}",
            opt.resistance_ohm * f,
            opt.average_power_w
        );
    }
}

#[test]
fn sweep_rejects_bad_input() {
    let (chain, traj) = setup();
    let opts = ChargeOptions::default();
    let params = HarvesterParams::default();
    let msg = load_sweep(&traj, &params, chain.period(), &[], 2, &opts)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("sweep.resistances"), "{msg}");
    let msg = load_sweep(&traj, &params, chain.period(), &[1e5, -1.0], 2, &opts)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("sweep.resistances[1]"), "{msg}");
    let msg = load_sweep(&traj, &params, chain.period(), &[1e5], 20, &opts)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("sweep.transient_periods"), "{msg}");
}
