//! The cost of a base motion other than one sine, against the goal that a recorded-input run
//! cost at most 3× the harmonic run per simulated second. Four runs of the paper's default case
//! over 1000 excitation periods (179.5 s), mechanics only and with the 100 kΩ harvester:
//!
//! - `harmonic`: `y = A sin ωt`, the engine's own closed form;
//! - `harmonic as a record`: the same A sin ωt sampled 200 times a period into a displacement
//!   record (a not-a-knot spline, within ~1e-8 A of the sine): the same motion, so the ratio
//!   to `harmonic` is the cost of the spline drive alone (a knot every T/200, where the
//!   forces are reset);
//! - `multisine`: two harmonics (0.06 m at ω, 0.015 m at 2.3 ω), as degree-7 Chebyshev pieces
//!   within 1e-10 of Σ|A| (a different motion: its cost per simulated second is shown, not
//!   compared);
//! - over 160 periods (28.7 s), the real record `configs/record_default.toml` (BW.RJOB, 100
//!   samples/s, scaled to the sine's peak acceleration A ω² = 98 m/s²) beside the sine over the
//!   same 160 periods: the "cost per simulated second" of a recorded input (a different
//!   motion, with fewer impacts: both the knots and the events count), and band-limited
//!   noise of the sine's RMS acceleration (4–24 Hz: its harmonics as degree-7 pieces, built
//!   when the configuration is read, so not timed here).
//!
//! `cargo bench -p vibrotribo --bench excitation`

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use vibrotribo::config::Config;
use vibrotribo::study::simulate;

const PERIODS: u64 = 1000;

fn configs() -> Vec<(&'static str, Config)> {
    let harmonic =
        Config::from_toml_str(&format!("[run]\nperiods = {PERIODS}\ntransient_periods = 0\n")).unwrap();
    let chain = harmonic.chain();
    let (a, w, period) = (chain.excitation.amplitude, chain.omega(), chain.period());
    let per = 200;
    let body: String = (0..=(PERIODS + 1) * per)
        .map(|k| {
            let t = period * k as f64 / per as f64;
            format!("{t:e},{:e}\n", a * (w * t).sin())
        })
        .collect();
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bench_excitation");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("sine.csv"), format!("time_s,displacement_m\n{body}")).unwrap();
    std::fs::write(
        dir.join("record.toml"),
        format!(
            "[excitation]\nkind = \"record\"\nfile = \"sine.csv\"\nquantity = \"displacement\"\n\
             [run]\nperiods = {PERIODS}\ntransient_periods = 0\n"
        ),
    )
    .unwrap();
    let record = Config::from_path(&dir.join("record.toml")).unwrap();
    let multisine = Config::from_toml_str(&format!(
        "[excitation]\nkind = \"multisine\"\nharmonics = [{{amplitude = 0.06, ratio = 1.0}}, \
         {{amplitude = 0.015, ratio = 2.3, phase = 0.4}}]\n[run]\nperiods = {PERIODS}\ntransient_periods = 0\n"
    ))
    .unwrap();
    let real = Config::from_path(
        &PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../configs/record_default.toml"),
    )
    .unwrap()
    .with("excitation.peak_acceleration", 98.0.into())
    .unwrap()
    .with("run.periods", 160.into())
    .unwrap();
    let sine_160 = Config::from_toml_str("[run]\nperiods = 160\n").unwrap();
    let random = Config::from_toml_str(
        "[excitation]\nkind = \"random\"\nrms_acceleration = 69.3\nf_low_hz = 4\nf_high_hz = 24\n[run]\nperiods = 160\n",
    )
    .unwrap();
    vec![
        ("harmonic, 1000 periods", harmonic),
        (
            "harmonic as a record (200 knots per period), 1000 periods",
            record,
        ),
        ("multisine, 2 harmonics, 1000 periods", multisine),
        ("harmonic, 160 periods", sine_160),
        ("BW.RJOB record at 98 m/s² peak, 160 periods", real),
        ("random 4–24 Hz at 69.3 m/s² RMS, 160 periods", random),
    ]
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("excitation");
    g.sample_size(10);
    for (name, config) in configs() {
        for (what, mechanics_only) in [("mechanics", true), ("100 kΩ harvester", false)] {
            let spec = config.run_spec(mechanics_only);
            g.bench_function(format!("{name}, {what}"), |b| {
                b.iter(|| black_box(simulate(black_box(&spec), &mut ()).unwrap()))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
