//! The electrical solve against the mechanical simulation it rides on, on the paper's default
//! case (10 periods from rest; 100 kΩ, 100 MΩ and 10 GΩ loads, and the rectifier).
//!
//! `cargo bench -p vibrotribo --bench electrical`. Criterion prints the medians; the ratio
//! electrical / mechanics is what to read off.
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use vibrotribo::electrical::{ChargeOptions, ChargeSolver, HarvesterParams, Load, Rectifier};
use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator, Trajectory};

const PERIODS: f64 = 10.0;

fn mechanics(chain: &ChainParams) {
    let mut sim = Simulator::new(chain, &ChainState::at_rest(chain.len()), SimOptions::default()).unwrap();
    sim.run_until(PERIODS * chain.period(), &mut ()).unwrap();
    black_box(sim.state());
}

fn live(chain: &ChainParams, params: &HarvesterParams) -> f64 {
    let mut sim = Simulator::new(chain, &ChainState::at_rest(chain.len()), SimOptions::default()).unwrap();
    let mut solver = ChargeSolver::for_chain(params, chain, ChargeOptions::default()).unwrap();
    sim.run_until(PERIODS * chain.period(), &mut solver).unwrap();
    solver.status().unwrap();
    solver.total_energy()
}

fn replay(chain: &ChainParams, trajectory: &Trajectory, params: &HarvesterParams) -> f64 {
    let mut solver = ChargeSolver::for_chain(params, chain, ChargeOptions::default()).unwrap();
    solver.run_trajectory(trajectory).unwrap();
    solver.total_energy()
}

fn bench(c: &mut Criterion) {
    let chain = ChainParams::default();
    let mut sim = Simulator::new(&chain, &ChainState::at_rest(3), SimOptions::default()).unwrap();
    let mut trajectory = Trajectory::new(&sim);
    sim.run_until(PERIODS * chain.period(), &mut trajectory).unwrap();
    let resistor = |r: f64| HarvesterParams {
        load: Load::Resistor { resistance: r },
        ..HarvesterParams::default()
    };
    let rectifier = HarvesterParams {
        load: Load::Rectifier(Rectifier::default()),
        ..HarvesterParams::default()
    };

    let mut g = c.benchmark_group("default_case_10_periods");
    g.bench_function("mechanics", |b| b.iter(|| mechanics(black_box(&chain))));
    g.bench_function("mechanics+electrical_100k_live", |b| {
        b.iter(|| live(black_box(&chain), &resistor(1e5)))
    });
    g.bench_function("electrical_100k_replay", |b| {
        b.iter(|| replay(&chain, black_box(&trajectory), &resistor(1e5)))
    });
    g.bench_function("electrical_100M_replay", |b| {
        b.iter(|| replay(&chain, black_box(&trajectory), &resistor(1e8)))
    });
    g.bench_function("electrical_10G_replay", |b| {
        b.iter(|| replay(&chain, black_box(&trajectory), &resistor(1e10)))
    });
    g.bench_function("electrical_rectifier_replay", |b| {
        b.iter(|| replay(&chain, black_box(&trajectory), &rectifier))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
