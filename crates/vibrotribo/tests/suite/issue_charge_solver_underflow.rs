//! The charge solver's step size underflowed (or it exceeded 10⁷ steps in a period) on many
//! points of the paper's Fig. 14 sweep with R_m > 5 (Ω = 0.72, m1 = m3 = 50 g, δ = 20 mm),
//! e.g. at R_m = 6.2667 about 1 µs before a 15 m/s impact at m2–m3 with D1 ≈ 1.35 mm: a
//! smooth stretch with R·C ≈ 6 µs. Found by `vibrotribo reproduce`.

use vibrotribo::electrical::{ChargeOptions, ChargeSolver, HarvesterParams};
use vibrotribo::{ChainParams, ChainState, Excitation, Frequency, SimOptions, Simulator, Trajectory};

fn chain(rm: f64) -> ChainParams {
    ChainParams {
        masses: vec![0.05, 0.05 * rm, 0.05],
        excitation: Excitation {
            amplitude: 0.08,
            frequency: Frequency::OmegaRatio(0.72),
        },
        ..ChainParams::default()
    }
}

fn energy(trajectory: &Trajectory, chain: &ChainParams, rtol: f64) -> f64 {
    let options = ChargeOptions {
        rtol,
        ..ChargeOptions::default()
    };
    let mut solver = ChargeSolver::for_chain(&HarvesterParams::default(), chain, options).unwrap();
    solver
        .run_trajectory(trajectory)
        .unwrap_or_else(|e| panic!("charge solver failed at rtol {rtol}: {e}"));
    solver.total_energy()
}

#[test]
fn no_underflow_on_the_high_mass_ratio_points() {
    for (rm, from) in [(6.266666666666667, 255.0), (5.075, 430.0), (5.205, 440.0)] {
        let chain = chain(rm);
        let period = chain.period();
        let mut sim = Simulator::new(&chain, &ChainState::at_rest(3), SimOptions::default()).unwrap();
        sim.run_until(from * period, &mut ()).unwrap();
        let mut trajectory = Trajectory::new(&sim);
        sim.run_until((from + 8.0) * period, &mut trajectory).unwrap();
        let e = energy(&trajectory, &chain, 1e-5);
        let reference = energy(&trajectory, &chain, 1e-9);
        let rel = (e - reference) / reference;
        println!("R_m = {rm}: energy {e:e} J, tight {reference:e} J ({rel:.1e})");
        assert!(rel.abs() < 1e-6, "R_m = {rm}: energy off by {rel:e}");
    }
}
