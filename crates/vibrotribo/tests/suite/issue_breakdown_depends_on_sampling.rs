//! The air-breakdown ratio of `simulate` depended on `samples_per_period` (0.875 at 1, 0.938
//! at 200 in the default case) and was missing without `--out`: it was the largest ratio over
//! the output samples. The charge solver now tracks it over its own stage points and refines
//! the maximum on its dense output; this checks that against a dense independent sampling.

use vibrotribo::electrical::breakdown::{BreakdownMargin, PaschenParams};
use vibrotribo::electrical::{ChargeOptions, ChargeSolver, HarvesterParams, Load};
use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator, Trajectory};

fn check(chain: &ChainParams, h: &HarvesterParams, periods: u64, from_period: u64) {
    let period = chain.period();
    let mut sim = Simulator::new(chain, &ChainState::at_rest(chain.len()), SimOptions::default()).unwrap();
    let mut traj = Trajectory::new(&sim);
    sim.run_until(periods as f64 * period, &mut traj).unwrap();
    let from = from_period as f64 * period;
    let mut watched = ChargeSolver::for_chain(h, chain, ChargeOptions::default())
        .unwrap()
        .with_breakdown_check(from);
    watched.run_trajectory(&traj).unwrap();
    let got = *watched.breakdown_margin().unwrap();
    // Independent: the same solution sampled 20 000 times per period, each sample checked
    // with the gaps of the exact trajectory.
    let per = 20_000;
    let mut sampled = ChargeSolver::for_chain(h, chain, ChargeOptions::default())
        .unwrap()
        .with_periodic_sampling(per)
        .unwrap();
    sampled.run_trajectory(&traj).unwrap();
    let s = sampled.samples().unwrap();
    let mut dense = BreakdownMargin::default();
    let n = chain.len() - 1;
    let (mut d, mut r) = (vec![0.0; n], vec![0.0; n]);
    for (&t, &q) in s.times.iter().zip(&s.charge_c) {
        if t < from {
            continue;
        }
        traj.flow_at(t).unwrap().gaps_at(t, &mut d, &mut r);
        let d2 = d.get(h.contact + 1).copied().unwrap_or(0.0);
        dense.add(h, &PaschenParams::default(), t, q, d[h.contact], d2);
    }
    assert!(got.worst_ratio > 0.1, "no ratio found: {got:?}");
    // The refined maximum is at least every sample (to the solver's tolerance) and beats a
    // 20 000-per-period sampling by no more than that sampling can miss.
    assert!(
        got.worst_ratio >= dense.worst_ratio * (1.0 - 1e-6),
        "refined {} below sampled {}",
        got.worst_ratio,
        dense.worst_ratio
    );
    assert!(
        got.worst_ratio <= dense.worst_ratio * (1.0 + 1e-5),
        "refined {} far above sampled {}",
        got.worst_ratio,
        dense.worst_ratio
    );
    assert!(
        (got.time_s - dense.time_s).abs() < 2.0 * period / per as f64,
        "{got:?} vs {dense:?}"
    );
}

#[test]
fn default_case_resistor() {
    check(&ChainParams::default(), &HarvesterParams::default(), 12, 6);
}

#[test]
fn chatter_case_resistor_and_open_circuit() {
    let chain = ChainParams::paper_chatter_case();
    check(&chain, &HarvesterParams::default(), 10, 5);
    let open = HarvesterParams {
        load: Load::Open,
        ..HarvesterParams::default()
    };
    check(&chain, &open, 6, 3);
}
