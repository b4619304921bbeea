//! Accuracy of the charge solver on real mechanical trajectories: energy per period at the
//! default tolerance against a reference computed with a 1e5 times tighter one, for loads
//! from 1 kΩ (stiff) to 10 GΩ (not stiff), and convergence under halving the tolerance.

use crate::common;
use common::period_stats;
use vibrotribo::electrical::{ChargeOptions, HarvesterParams, Load, PeriodStats, Rectifier};
use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator, Trajectory};

fn trajectory(chain: &ChainParams, periods: f64) -> Trajectory {
    let mut sim = Simulator::new(chain, &ChainState::at_rest(chain.len()), SimOptions::default()).unwrap();
    let mut t = Trajectory::new(&sim);
    sim.run_until(periods * chain.period(), &mut t).unwrap();
    t
}

/// Largest relative difference of the energy per period, over all periods.
fn worst(a: &[PeriodStats], b: &[PeriodStats]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| ((x.energy_j - y.energy_j) / y.energy_j).abs())
        .fold(0.0, f64::max)
}

fn check_case(name: &str, chain: &ChainParams, n_periods: f64, loads: &[f64]) {
    let traj = trajectory(chain, n_periods);
    let default = ChargeOptions::default().rtol;
    for &r in loads {
        let params = HarvesterParams {
            load: Load::Resistor { resistance: r },
            ..HarvesterParams::default()
        };
        let reference = period_stats(chain, &traj, &params, default * 1e-5);
        let got = period_stats(chain, &traj, &params, default);
        let halved = period_stats(chain, &traj, &params, default / 2.0);
        let (err, change) = (worst(&got, &reference), worst(&got, &halved));
        println!(
            "{name}, R = {r:e} Ω: energy per period {:.6e} J; worst relative error vs reference {err:.2e}, \
             change on halving rtol {change:.2e}",
            reference[reference.len() - 1].energy_j
        );
        assert!(
            err <= 1e-6,
            "{name}, R = {r:e}: energy per period off by {err:e} (> 1e-6)"
        );
        assert!(
            change <= default,
            "{name}, R = {r:e}: halving rtol changed energy by {change:e} (> {default:e})"
        );
    }
}

#[test]
fn default_case_energy_per_period_within_1e_6() {
    check_case(
        "default case",
        &ChainParams::default(),
        10.0,
        &[1e3, 1e5, 1e8, 1e10],
    );
}

#[test]
fn chatter_case_energy_per_period_within_1e_6() {
    // Periods 4–6 of this run hold chatter sequences and triple closures (capacitance spikes).
    check_case(
        "chatter case",
        &ChainParams::paper_chatter_case(),
        6.0,
        &[1e3, 1e5, 1e8, 1e10],
    );
}

#[test]
fn rectifier_energy_per_period_within_1e_6() {
    let chain = ChainParams::paper_chatter_case();
    let traj = trajectory(&chain, 6.0);
    let params = HarvesterParams {
        load: Load::Rectifier(Rectifier::default()),
        ..HarvesterParams::default()
    };
    let default = ChargeOptions::default().rtol;
    let reference = period_stats(&chain, &traj, &params, default * 1e-4);
    let got = period_stats(&chain, &traj, &params, default);
    let err = worst(&got, &reference);
    let vs = |p: &[PeriodStats]| p.last().unwrap().storage_voltage_v.unwrap();
    println!(
        "rectifier, chatter case: worst energy error per period {err:.2e}; storage voltage {:.9} V vs reference {:.9} V",
        vs(&got),
        vs(&reference)
    );
    assert!(err <= 1e-6, "rectifier: energy per period off by {err:e}");
    assert!((vs(&got) - vs(&reference)).abs() <= 1e-6 * vs(&reference));
}
