//! The frequency response (`response::frequency_response`, `response::band_response`)
//! against truth from outside it: the closed-form steady state of the linear chain and its
//! harvester, brute-force runs from random starts inside a hysteresis loop, the fold that
//! continuation locates where a sweep jumps, and the mean and standard error of the seeds'
//! powers written out.

use std::ops::ControlFlow;

use vibrotribo::attractors::{StartBox, random_start};
use vibrotribo::config::Config;
use vibrotribo::orbits::BifurcationKind;
use vibrotribo::response::{
    BandOptions, BandPlan, BranchSeeding, FrequencyResponse, ResponseError, ResponseOptions, ResponseStep,
    band_response, frequency_response, response_table,
};
use vibrotribo::study::Direction;
use vibrotribo::sweep::{PointRequest, PointRunner, grid};

const EPSILON_0: f64 = 8.8541878128e-12;

fn go(_: ResponseStep) -> ControlFlow<()> {
    ControlFlow::Continue(())
}

fn runner(config: Config) -> PointRunner {
    let options = PointRequest::default().options_of_run(&config).unwrap();
    PointRunner::new(config, options, false)
}

/// The linear case: three masses that never touch (300 mm gaps, 5 mm base amplitude), the
/// outer two alike (so x₁ ≡ x₃ from rest and D₁ + D₂ stays δ₁ + δ₂), the middle one stiff,
/// the exact open-circuit voltage. Then C = ε₀S/(d₀ + δ₁ + δ₂) is constant and
/// V_oc = σ(D₂ − D₁)/ε₀ = const + 2σ(x₂ − x₁)/ε₀, and the charge R dQ/dt = V_oc − Q/C is a
/// first-order filter of a harmonic: P = ½ R ω² C² |V̂|² / (1 + (ωRC)²), with
/// V̂ = 2σA(T₂ − T₁)/ε₀ and each mass's transmissibility T = (k + icω)/(k − mω² + icω).
const LINEAR: &str = "
[oscillator]
masses = [0.048, 0.12, 0.048]
stiffness = [120.0, 1200.0, 120.0]
damping = [0.3, 0.3, 0.3]
gaps = [0.3, 0.3]
[excitation]
amplitude = 0.005
omega_ratio = 1.0
[harvester]
voc_model = \"exact\"
";

/// The closed-form average power of [`LINEAR`] at Ω, W.
fn linear_power(config: &Config, omega_ratio: f64) -> f64 {
    let chain = config.chain();
    let h = config.harvester();
    let w = omega_ratio * (chain.stiffness[0] / chain.masses[0]).sqrt();
    let t = |i: usize| {
        let (m, k, c) = (chain.masses[i], chain.stiffness[i], chain.damping[i]);
        let (nr, ni) = (k, c * w);
        let (dr, di) = (k - m * w * w, c * w);
        let d = dr * dr + di * di;
        ((nr * dr + ni * di) / d, (ni * dr - nr * di) / d)
    };
    let (t1, t2) = (t(0), t(1));
    let rel = ((t2.0 - t1.0).powi(2) + (t2.1 - t1.1).powi(2)).sqrt();
    let amplitude = chain.excitation.amplitude;
    let v = 2.0 * h.charge_density * amplitude * rel / EPSILON_0;
    let d0 = h.dielectric_thickness[0] / h.relative_permittivity[0]
        + h.dielectric_thickness[1] / h.relative_permittivity[1];
    let c = EPSILON_0 * h.area / (d0 + chain.gaps[0] + chain.gaps[1]);
    let r = h.load.resistance().unwrap();
    0.5 * r * (w * c * v).powi(2) / (1.0 + (w * r * c).powi(2))
}

/// The half-power edges of the closed form around its peak, by bisection on a fine scan.
fn linear_band(config: &Config, lo: f64, hi: f64) -> (f64, f64, f64) {
    let n = 20_000;
    let scan: Vec<(f64, f64)> = (0..=n)
        .map(|i| {
            let o = lo + (hi - lo) * i as f64 / n as f64;
            (o, linear_power(config, o))
        })
        .collect();
    let (k, &(peak_at, peak)) = scan
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.1.total_cmp(&b.1.1))
        .unwrap();
    let edge = |mut a: f64, mut b: f64| {
        for _ in 0..80 {
            let m = 0.5 * (a + b);
            if (linear_power(config, m) - 0.5 * peak) * (linear_power(config, a) - 0.5 * peak) > 0.0 {
                a = m;
            } else {
                b = m;
            }
        }
        0.5 * (a + b)
    };
    let below = (0..k).rev().find(|&i| scan[i].1 < 0.5 * peak).unwrap();
    let above = (k..scan.len()).find(|&i| scan[i].1 < 0.5 * peak).unwrap();
    (
        peak_at,
        edge(scan[below].0, peak_at),
        edge(peak_at, scan[above].0),
    )
}

/// Without impacts both sweeps give the closed-form power at every value (to 1e-4), and the
/// response's peak and half-power edges are the closed form's: on a grid of step h the
/// edges, interpolated linearly, lie within 0.05·h of the exact ones.
#[test]
fn linear_chain_has_the_closed_form_bandwidth() {
    let config = Config::from_toml_str(LINEAR).unwrap();
    let values = grid(0.8, 1.2, 41);
    let step = values[1] - values[0];
    let r = frequency_response(
        &runner(config.clone()),
        "excitation.omega_ratio",
        &values,
        &ResponseOptions::default(),
        &go,
    )
    .unwrap();
    assert!(r.complete);
    for d in [Direction::Up, Direction::Down] {
        let got = r.sweep(d).power(&values);
        assert_eq!(got.len(), values.len(), "{d:?}: every value has a power");
        for &(o, p) in &got {
            let want = linear_power(&config, o);
            assert!(
                (p - want).abs() < 1e-4 * want,
                "{d:?} Ω = {o}: {p:e} W, closed form {want:e} W"
            );
        }
        let impacts = r.sweep(d).results.iter().flatten().flatten();
        assert!(impacts.clone().all(|p| p.impacts.is_empty()), "nothing impacts");
    }
    let (peak_at, lower, upper) = linear_band(&config, 0.8, 1.2);
    let b = r.bandwidth().unwrap();
    println!(
        "closed form: peak at {peak_at:.5}, band {lower:.5}..{upper:.5}; response: peak at {}, band {:?}..{:?}",
        b.peak_frequency, b.lower, b.upper
    );
    assert!((b.peak_frequency - peak_at).abs() <= 0.5 * step);
    assert!((b.peak_power - linear_power(&config, b.peak_frequency)).abs() < 1e-4 * b.peak_power);
    let (l, u) = (b.lower.unwrap(), b.upper.unwrap());
    assert!((l - lower).abs() < 0.05 * step, "lower edge {l} vs {lower}");
    assert!((u - upper).abs() < 0.05 * step, "upper edge {u} vs {upper}");
    // One row per value, the up and down columns side by side.
    let t = response_table(&r).table();
    assert_eq!(t.rows(), values.len());
    assert_eq!(
        &t.names()[..5],
        [
            "param",
            "power_up_w",
            "power_down_w",
            "power_se_up_w",
            "power_se_down_w"
        ]
    );
}

/// The paper's chain at a 2 mm base amplitude: between Ω ≈ 0.70 and 0.79 an impacting
/// period-1 motion coexists with one that never impacts. The up sweep rides the impacting
/// one, the down sweep the other; brute-force runs from random starts at Ω = 0.74 end on
/// both, with the sweeps' powers (to 1e-6). Continuation from the up sweep's motion finds
/// the fold where it ends between the last impacting value of the up sweep and the next.
#[test]
fn hysteresis_is_two_attractors_and_a_fold() {
    let config = Config::default()
        .with("excitation.amplitude", 0.002.into())
        .unwrap();
    let values = grid(0.66, 0.84, 10);
    let options = ResponseOptions {
        branches: Some(BranchSeeding::default()),
    };
    let run = runner(config.clone());
    let r = frequency_response(&run, "excitation.omega_ratio", &values, &options, &go).unwrap();
    assert!(r.complete, "{:?}", r.branch_failures);
    let at = |r: &FrequencyResponse, d: Direction, o: f64| {
        let j = values.iter().position(|v| (v - o).abs() < 1e-9).unwrap();
        r.sweep(d).results[j].clone().unwrap().unwrap()
    };
    let (up, down) = (at(&r, Direction::Up, 0.74), at(&r, Direction::Down, 0.74));
    let (pu, pd) = (up.average_power_w.unwrap(), down.average_power_w.unwrap());
    println!(
        "Ω = 0.74: up {pu:e} W ({} impacts/period), down {pd:e} W",
        up.total_impacts_per_period()
    );
    assert!(up.total_impacts_per_period() > 0.0 && down.impacts.is_empty());
    assert!(pu > 2.0 * pd, "hysteresis: {pu} vs {pd}");
    // Brute force: random starts at Ω = 0.74, half in a wide box around rest, half in a
    // narrow one around the base's own state at t = 0 (at rest relative to it).
    let fixed = config.with("excitation.omega_ratio", 0.74.into()).unwrap();
    let chain = fixed.chain();
    let base_speed = chain.excitation.amplitude * chain.omega();
    let boxes = [(0.02, 0.5, 0.0), (0.001, 0.02, base_speed)];
    let powers: Vec<f64> = (0..16)
        .filter_map(|k| {
            let (positions, velocities, offset) = boxes[k as usize % 2];
            let bounds = StartBox {
                positions,
                velocities,
            };
            let mut start = random_start(chain, &bounds, 7, k).ok()?;
            start.velocities.iter_mut().for_each(|v| *v += offset);
            run.run(&[("excitation.omega_ratio", 0.74)], Some(&start))
                .ok()?
                .average_power_w
        })
        .collect();
    for want in [pu, pd] {
        assert!(
            powers.iter().any(|p| (p - want).abs() < 1e-6 * want),
            "{want:e} W not among the random starts' {powers:?}"
        );
    }
    // The up sweep's last impacting value before it drops, and the fold that continuation
    // locates on the branch of its motion.
    let j = (1..values.len())
        .find(|&j| at(&r, Direction::Up, values[j]).impacts.is_empty())
        .unwrap()
        - 1;
    let folds: Vec<f64> = r
        .branches
        .iter()
        .flat_map(|b| &b.bifurcations)
        .filter(|b| b.kind == BifurcationKind::Fold)
        .map(|b| b.parameter)
        .collect();
    println!("up sweep impacts up to Ω = {}, folds at {folds:?}", values[j]);
    assert!(
        folds.iter().any(|&f| values[j] < f && f < values[j + 1]),
        "a fold between {} and {}: {folds:?}",
        values[j],
        values[j + 1]
    );
    // The envelope's peak is at least the up sweep's power there.
    assert!(r.bandwidth().unwrap().peak_power >= pu);
}

/// A stop request ends the sweeps at their next value, with the values done kept.
#[test]
fn a_stop_keeps_what_was_done() {
    let config = Config::from_toml_str(LINEAR).unwrap();
    let values = grid(0.8, 1.2, 9);
    let count = std::sync::atomic::AtomicUsize::new(0);
    let stop = |_: ResponseStep| {
        if count.fetch_add(1, std::sync::atomic::Ordering::SeqCst) >= 2 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    };
    let r = frequency_response(
        &runner(config),
        "excitation.omega_ratio",
        &values,
        &ResponseOptions::default(),
        &stop,
    )
    .unwrap();
    assert!(!r.complete);
    let done = r.up.done() + r.down.done();
    assert!((3..=4).contains(&done), "{done} values done");
    // Each sweep's values are a run from its start: the up sweep's the first, the down
    // sweep's the last.
    let up: Vec<bool> = r.up.results.iter().map(Option::is_some).collect();
    let down: Vec<bool> = r.down.results.iter().rev().map(Option::is_some).collect();
    for done in [up, down] {
        let k = done.iter().take_while(|d| **d).count();
        assert!(done[k..].iter().all(|d| !d), "{done:?}");
    }
}

/// Bad values and options are errors that name them.
#[test]
fn bad_input_is_named() {
    let run = runner(Config::default());
    let e = frequency_response(
        &run,
        "excitation.omega_ratio",
        &[],
        &ResponseOptions::default(),
        &go,
    )
    .unwrap_err();
    assert!(matches!(e, ResponseError::NoValues), "{e}");
    let e = frequency_response(
        &run,
        "excitation.omega_ratio",
        &[0.7, 0.6],
        &ResponseOptions::default(),
        &go,
    )
    .unwrap_err();
    assert!(matches!(e, ResponseError::BadValues { index: 1, .. }), "{e}");
    let e = frequency_response(
        &run,
        "excitation.omega_ratio",
        &[-0.5],
        &ResponseOptions::default(),
        &go,
    )
    .unwrap_err();
    assert!(e.to_string().contains("excitation.omega_ratio"), "{e}");
    let e = frequency_response(&run, "no.such_key", &[0.5], &ResponseOptions::default(), &go).unwrap_err();
    assert!(e.to_string().contains("no.such_key"), "{e}");
    // The random-band response needs flat-spectrum noise, and bands above 0 Hz.
    let options = BandOptions {
        centres_hz: vec![5.0, 10.0],
        width_hz: None,
        seeds: 2,
    };
    let e = BandPlan::new(&Config::default(), &options).unwrap_err();
    assert!(matches!(e, ResponseError::NotFlatNoise { .. }), "{e}");
    let noise = noise_config();
    let e = BandPlan::new(
        &noise,
        &BandOptions {
            width_hz: Some(12.0),
            ..options.clone()
        },
    )
    .unwrap_err();
    assert!(matches!(e, ResponseError::BandBelowZero { .. }), "{e}");
    let e = BandPlan::new(&noise, &BandOptions { seeds: 0, ..options }).unwrap_err();
    assert!(e.to_string().contains("seeds"), "{e}");
}

fn noise_config() -> Config {
    Config::from_toml_str(
        "[excitation]\nkind = \"random\"\nrms_acceleration = 20.0\nf_low_hz = 4.0\nf_high_hz = 8.0\nseed = 3\nomega_ratio = 0.7\n\
         [run]\nperiods = 24\ntransient_periods = 8\nstart_relative_to_base = true\n",
    )
    .unwrap()
}

/// The random-band response: each centre's band is [f_c − B/2, f_c + B/2] at the configured
/// RMS acceleration, each seed a run of its own (the same as a run of the configuration with
/// those keys set), and the power the mean of the seeds' with the standard error s/√n.
#[test]
fn band_response_is_the_mean_over_seeds() {
    let config = noise_config();
    let run = runner(config.clone());
    let plan = BandPlan::new(
        &config,
        &BandOptions {
            centres_hz: vec![5.0, 9.0],
            width_hz: Some(4.0),
            seeds: 3,
        },
    )
    .unwrap();
    assert_eq!(plan.seeds, vec![3, 4, 5]);
    assert_eq!(plan.band(5.0), (3.0, 7.0));
    let r = band_response(&run, &plan, None, || ControlFlow::Continue(())).unwrap();
    assert!(r.complete);
    let points = r.points();
    assert_eq!(points.len(), 2);
    for (i, p) in points.iter().enumerate() {
        let powers: Vec<f64> = (0..3)
            .map(|k| {
                let c = config
                    .with("excitation.f_low_hz", (plan.centres_hz[i] - 2.0).into())
                    .and_then(|c| c.with("excitation.f_high_hz", (plan.centres_hz[i] + 2.0).into()))
                    .and_then(|c| c.with("excitation.seed", toml::Value::Integer(3 + k)))
                    .unwrap();
                run.run_config(&c, None).unwrap().average_power_w.unwrap()
            })
            .collect();
        let mean = powers.iter().sum::<f64>() / 3.0;
        let sd = (powers.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 2.0).sqrt();
        println!("centre {} Hz: {powers:?}", p.centre_hz);
        assert_eq!(p.runs, 3);
        assert!((p.power_w.unwrap() - mean).abs() <= 1e-12 * mean);
        assert!((p.power_se_w.unwrap() - sd / 3f64.sqrt()).abs() <= 1e-9 * sd);
        assert!(p.power_min_w.unwrap() <= mean && mean <= p.power_max_w.unwrap());
    }
    // Different seeds are different realisations.
    assert!(points[0].power_se_w.unwrap() > 0.0);
    let b = r.bandwidth().unwrap();
    assert!(b.peak_frequency == 5.0 || b.peak_frequency == 9.0);
}
