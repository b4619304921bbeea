//! Lyapunov spectra over 10,000 excitation periods (after a 300-period transient): the
//! paper's default case (a stable period-1 orbit, 6 impacts per period) and Fig. 14's chain
//! at R_m = 6.54, Ω = 0.72 (chaotic), each beside the plain simulation of the same run.
//!
//! `cargo bench -p vibrotribo --bench lyapunov`

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use vibrotribo::lyapunov::LyapunovOptions;
use vibrotribo::study::{RunSpec, lyapunov_spectrum, simulate};
use vibrotribo::{ChainParams, Excitation, Frequency};

fn bench(c: &mut Criterion) {
    let chaotic = ChainParams {
        masses: vec![0.05, 0.05 * 6.54, 0.05],
        excitation: Excitation {
            amplitude: 0.08,
            frequency: Frequency::OmegaRatio(0.72),
        },
        ..ChainParams::default()
    };
    let mut g = c.benchmark_group("lyapunov");
    g.sample_size(10);
    for (name, params) in [
        ("default case", ChainParams::default()),
        ("chaotic R_m = 6.54", chaotic),
    ] {
        let mut spec = RunSpec::new(params, 10_300);
        spec.transient_periods = 300;
        let options = LyapunovOptions::default();
        g.bench_function(format!("spectrum, {name}, 10000 periods"), |b| {
            b.iter(|| black_box(lyapunov_spectrum(black_box(&spec), &options, &mut ()).unwrap()))
        });
        g.bench_function(format!("simulation alone, {name}, 10300 periods"), |b| {
            b.iter(|| black_box(simulate(black_box(&spec), &mut ()).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
