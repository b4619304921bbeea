//! Periodic orbits: one Newton-converged period-1 orbit of the paper's default case (from
//! the state after a 3-period transient, five Newton iterations), and a pseudo-arclength
//! continuation of 500 points along Ω in the default case (from the period-1 orbit at
//! Ω = 1.0 towards 0.3, stopped at 500 points).
//!
//! `cargo bench -p vibrotribo --bench orbits`

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use vibrotribo::orbits::{ContinuationOptions, ShootingOptions, continue_orbit, find_periodic_orbit};
use vibrotribo::{ChainParams, ChainState, Frequency, SimOptions, Simulator};

fn family(omega: f64) -> ChainParams {
    let mut p = ChainParams::default();
    p.excitation.frequency = Frequency::OmegaRatio(omega);
    p
}

fn bench(c: &mut Criterion) {
    let params = ChainParams::default();
    let mut sim = Simulator::new(&params, &ChainState::at_rest(3), SimOptions::default()).unwrap();
    sim.run_until(3.0 * params.period(), &mut ()).unwrap();
    let guess = sim.state();
    let options = ShootingOptions::default();
    let orbit = find_periodic_orbit(&params, &guess, 1, &options).unwrap();
    let mut g = c.benchmark_group("orbits");
    g.bench_function(
        format!("newton default case ({} iterations)", orbit.residuals.len() - 1),
        |b| b.iter(|| black_box(find_periodic_orbit(&params, black_box(&guess), 1, &options).unwrap())),
    );
    let continuation = ContinuationOptions {
        max_points: 500,
        ..ContinuationOptions::default()
    };
    let mut sim = Simulator::new(&family(1.0), &ChainState::at_rest(3), SimOptions::default()).unwrap();
    sim.run_until(300.0 * family(1.0).period(), &mut ()).unwrap();
    let start = find_periodic_orbit(&family(1.0), &sim.state(), 1, &options).unwrap();
    let run = || continue_orbit("omega_ratio", family, 1.0, 0.3, &start.state, 1, &continuation).unwrap();
    let points: usize = run().branches.iter().map(|b| b.points.len()).sum();
    g.sample_size(10);
    g.bench_function(format!("continuation along omega ({points} points)"), |b| {
        b.iter(|| black_box(run()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
