//! Engine throughput: events per second and simulated periods per second, for the paper's
//! default case and its chatter case (m1 = 50 g, R_m = 3, δ = 5 mm, Ω = 0.60).
//!
//! `cargo bench -p vibrotribo --bench engine`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use vibrotribo::analysis::RunStats;
use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator};

const PERIODS: u64 = 200;

fn run(params: &ChainParams) -> u64 {
    let mut sim = Simulator::new(params, &ChainState::at_rest(params.len()), SimOptions::default()).unwrap();
    let mut stats = RunStats::new(params.len() - 1, params.period(), 0);
    sim.run_until(PERIODS as f64 * params.period(), &mut stats)
        .unwrap();
    stats.events
}

fn bench(c: &mut Criterion) {
    for (name, params) in [
        ("default", ChainParams::default()),
        ("chatter", ChainParams::paper_chatter_case()),
    ] {
        let events = run(&params);
        let mut g = c.benchmark_group(format!("{name}_case"));
        g.throughput(Throughput::Elements(events));
        g.bench_function(format!("events ({events} in {PERIODS} periods)"), |b| {
            b.iter(|| black_box(run(black_box(&params))))
        });
        g.throughput(Throughput::Elements(PERIODS));
        g.bench_function(format!("periods ({PERIODS})"), |b| {
            b.iter(|| black_box(run(black_box(&params))))
        });
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(4));
    targets = bench
}
criterion_main!(benches);
