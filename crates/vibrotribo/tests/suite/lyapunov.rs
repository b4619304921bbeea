//! Lyapunov spectra against truth from outside the QR averaging: the closed form of a chain
//! that never touches, the Floquet multipliers of periodic orbits (eigenvalues of the
//! monodromy matrix), the phase-space contraction rate (trace of the linear flow plus the
//! saltation determinants μ² of the impacts), and a two-trajectory (Benettin) estimate from
//! the exact flow alone.

use crate::common;

use common::Lcg;
use vibrotribo::lyapunov::{LyapunovError, LyapunovOptions, LyapunovSpectrum};
use vibrotribo::orbits::{ShootingOptions, periodic_orbit_from_transient};
use vibrotribo::sensitivity::{SensitivityOptions, length_scale, state_from_vector, state_vector};
use vibrotribo::study::{RunSpec, lyapunov_spectrum};
use vibrotribo::{ChainParams, ChainState, Excitation, Frequency, SimOptions, Simulator};

/// The paper's chain with masses `m` and gaps `gaps`, Ω = `omega` (A = 80 mm, μ = 0.6).
fn three(m: [f64; 3], gaps: [f64; 2], omega: f64) -> ChainParams {
    ChainParams {
        masses: m.to_vec(),
        gaps: gaps.to_vec(),
        excitation: Excitation {
            amplitude: 0.08,
            frequency: Frequency::OmegaRatio(omega),
        },
        ..ChainParams::default()
    }
}

/// Fig. 14's chain at R_m = 6.54, Ω = 0.72 (the report's optimal mass ratio): chaotic.
fn hyperchaotic() -> ChainParams {
    three([0.05, 0.05 * 6.54, 0.05], [0.02, 0.02], 0.72)
}

/// Fig. 10's chain at R_δ = 1.423 (m = 90, 120, 90 g, Ω = 0.70): weakly chaotic.
fn weakly_chaotic() -> ChainParams {
    three([0.09, 0.12, 0.09], [0.02, 0.02 * 1.423], 0.70)
}

fn spectrum_of(spec: &RunSpec, options: &LyapunovOptions) -> LyapunovSpectrum {
    let run = lyapunov_spectrum(spec, options, &mut ()).unwrap();
    assert_eq!(run.outcome.periods, spec.periods);
    run.spectrum.unwrap()
}

fn run_spec(params: ChainParams, initial: ChainState, transient: u64, measured: u64) -> RunSpec {
    let mut spec = RunSpec::new(params, transient + measured);
    spec.initial = initial;
    spec.transient_periods = transient;
    spec
}

fn show(name: &str, s: &LyapunovSpectrum) {
    println!(
        "{name}: exponents {:?}\n  spread {:?}, collapsed {}, periods {}, skipped {}",
        s.exponents, s.spread, s.collapsed, s.periods, s.skipped_periods
    );
}

/// Real parts of the eigenvalues of m ẍ + c ẋ + k x = 0, 1/s.
fn oscillator_rates(m: f64, c: f64, k: f64) -> [f64; 2] {
    let a = c / (2.0 * m);
    let disc = a * a - k / m;
    if disc > 0.0 {
        [-a + disc.sqrt(), -a - disc.sqrt()]
    } else {
        [-a, -a]
    }
}

#[test]
fn impact_free_chains_match_the_closed_form() {
    let mut rng = Lcg(2024);
    for n in 2..=4 {
        // Light, moderate and (for the last mass) over-critical damping.
        let masses: Vec<f64> = (0..n).map(|_| rng.range(0.03, 0.2)).collect();
        let stiffness: Vec<f64> = (0..n).map(|_| rng.range(80.0, 200.0)).collect();
        let mut damping: Vec<f64> = (0..n).map(|_| rng.range(0.005, 0.5)).collect();
        damping[n - 1] = 3.0 * (masses[n - 1] * stiffness[n - 1]).sqrt();
        let params = ChainParams {
            masses: masses.clone(),
            stiffness: stiffness.clone(),
            damping: damping.clone(),
            gaps: vec![10.0; n - 1],
            restitution: 0.6,
            excitation: Excitation {
                amplitude: 0.03,
                frequency: Frequency::OmegaRatio(rng.range(0.4, 1.4)),
            },
            stops: Default::default(),
            forces: Vec::new(),
        };
        let mut expected: Vec<f64> = (0..n)
            .flat_map(|i| oscillator_rates(masses[i], damping[i], stiffness[i]))
            .collect();
        expected.sort_by(|a, b| b.total_cmp(a));
        let s = spectrum_of(
            &run_spec(params, ChainState::at_rest(n), 50, 3000),
            &LyapunovOptions::default(),
        );
        show(&format!("N = {n}"), &s);
        println!("  closed form {expected:?}");
        assert_eq!(s.collapsed, 0);
        for (i, (got, want)) in s.exponents.iter().zip(&expected).enumerate() {
            // The finite-time average of a damped rotation carries an O(1/t) wobble.
            let tol = 3.0 * s.spread[i] + 2e-3 * want.abs().max(0.1);
            assert!(
                (got - want).abs() < tol,
                "N = {n}, exponent {i}: {got} vs closed form {want} (tolerance {tol})"
            );
        }
    }
}

/// `ln|μ_i| / (P·T)` of a periodic orbit's multipliers, largest first (−∞ for zero ones).
fn floquet_exponents(orbit: &vibrotribo::orbits::PeriodicOrbit) -> Vec<f64> {
    let mut e: Vec<f64> = orbit
        .multipliers
        .iter()
        .map(|m| {
            if m.norm() < 1e-12 {
                f64::NEG_INFINITY
            } else {
                m.norm().ln() / orbit.duration()
            }
        })
        .collect();
    e.sort_by(|a, b| b.total_cmp(a));
    e
}

fn check_against_floquet(name: &str, params: ChainParams, period: Option<u32>) {
    let n = params.len();
    let orbit = periodic_orbit_from_transient(
        &params,
        &ChainState::at_rest(n),
        200,
        period,
        &ShootingOptions::default(),
    )
    .unwrap();
    let expected = floquet_exponents(&orbit);
    // Started on the orbit: the tangent vectors align during 300 periods, 3000 averaged.
    let s = spectrum_of(
        &run_spec(params, orbit.state.clone(), 300, 3000),
        &LyapunovOptions::default(),
    );
    show(name, &s);
    println!("  Floquet ln|μ|/PT {expected:?} (period {})", orbit.period);
    let zeros = expected.iter().filter(|e| e.is_infinite()).count();
    assert_eq!(s.collapsed, zeros, "{name}: −∞ exponents vs zero multipliers");
    for (i, (got, want)) in s.exponents.iter().zip(&expected).enumerate() {
        if want.is_infinite() {
            assert_eq!(*got, f64::NEG_INFINITY, "{name}, exponent {i}");
            continue;
        }
        let tol = 3.0 * s.spread[i] + 2e-3 * want.abs().max(0.1);
        assert!(
            (got - want).abs() < tol,
            "{name}, exponent {i}: {got} vs Floquet {want} (tolerance {tol})"
        );
    }
}

#[test]
fn stable_orbits_give_the_logarithms_of_their_multipliers() {
    check_against_floquet("default case, period 1", ChainParams::default(), None);
    // Fig. 10's R_δ = 1.430: period 8.
    check_against_floquet(
        "R_δ = 1.430",
        three([0.09, 0.12, 0.09], [0.02, 0.02 * 1.430], 0.70),
        None,
    );
}

/// The stated error bar (one spread, the ± printed) covers the difference to ln|μ|/T on the
/// default case's period-1 orbit, whose leading multipliers are a complex pair (two equal
/// exponents the QR averaging splits), for short and long windows and several seeds.
#[test]
fn error_bars_on_a_periodic_orbit_cover_the_floquet_exponents() {
    let params = ChainParams::default();
    let orbit = periodic_orbit_from_transient(
        &params,
        &ChainState::at_rest(3),
        200,
        Some(1),
        &ShootingOptions::default(),
    )
    .unwrap();
    let expected = floquet_exponents(&orbit);
    for (seed, periods) in [(1, 200), (2, 200), (1, 1000), (2, 1000), (3, 1000), (4, 1000)] {
        let options = LyapunovOptions {
            seed,
            ..LyapunovOptions::default()
        };
        let s = spectrum_of(
            &run_spec(params.clone(), orbit.state.clone(), 300, periods),
            &options,
        );
        for (i, (got, want)) in s.exponents.iter().zip(&expected).enumerate() {
            assert!(
                (got - want).abs() <= s.spread[i],
                "seed {seed}, {periods} periods, exponent {i}: {got} ± {} vs Floquet {want}",
                s.spread[i]
            );
        }
    }
}

#[test]
fn a_chatter_orbit_has_minus_infinity_exponents_for_its_stuck_directions() {
    // Every period a chatter sequence ends in sticking: two zero multipliers.
    check_against_floquet("chatter case", ChainParams::paper_chatter_case(), Some(1));
}

#[test]
fn the_sum_is_the_phase_space_contraction_rate() {
    for (name, params) in [
        ("hyperchaotic", hyperchaotic()),
        ("weakly chaotic", weakly_chaotic()),
        ("default", ChainParams::default()),
    ] {
        let (transient, measured) = (100, 1000);
        let run = lyapunov_spectrum(
            &run_spec(params.clone(), ChainState::at_rest(3), transient, measured),
            &LyapunovOptions::default(),
            &mut (),
        )
        .unwrap();
        let s = run.spectrum.unwrap();
        let stats = &run.outcome.stats;
        assert_eq!(stats.sticks + stats.chatter_sequences, 0, "{name}: no sticking");
        // Trace of the free flow, −Σ c_i/m_i, and ln det S = 2 ln μ per impact.
        let trace: f64 = -params
            .masses
            .iter()
            .zip(&params.damping)
            .map(|(m, c)| c / m)
            .sum::<f64>();
        let impacts: f64 = stats.impacts_per_period(transient + measured).iter().sum();
        let rate = impacts / params.period();
        let expected = trace + 2.0 * params.restitution.ln() * rate;
        println!(
            "{name}: Σλ = {}, trace {trace} + 2 ln μ × {rate} impacts/s = {expected}",
            s.sum()
        );
        assert!(
            (s.sum() - expected).abs() < 1e-9 * expected.abs(),
            "{name}: Σλ = {} vs contraction rate {expected}",
            s.sum()
        );
    }
}

/// The largest exponent from two trajectories of the exact flow `d0` apart (scaled units:
/// positions in L, velocities in L·ω), the second brought back to distance `d0` along their
/// separation at every period's end (Benettin et al. 1976). Returns the estimate and its
/// batch-means standard error over 10 batches, 1/s.
fn two_trajectory_estimate(params: &ChainParams, start: &ChainState, periods: u64) -> (f64, f64) {
    let (l, w) = (length_scale(params), params.omega());
    let n = params.len();
    let scale = |i: usize| if i < n { l } else { l * w };
    let d0 = 1e-8;
    let mut rng = Lcg(5);
    let a = state_vector(start);
    let dir: Vec<f64> = (0..2 * n).map(|_| rng.range(-1.0, 1.0)).collect();
    let norm = dir.iter().map(|d| d * d).sum::<f64>().sqrt();
    let b: Vec<f64> = (0..2 * n).map(|i| a[i] + d0 * dir[i] / norm * scale(i)).collect();
    let mut sim_a = Simulator::new(params, start, SimOptions::default()).unwrap();
    let mut state_b = state_from_vector(&b);
    let mut logs = Vec::new();
    for p in 1..=periods {
        let t0 = (p - 1) as f64 * params.period();
        let t1 = p as f64 * params.period();
        sim_a.run_until(t1, &mut ()).unwrap();
        let mut sim_b = Simulator::new_at(params, t0, &state_b, SimOptions::default()).unwrap();
        sim_b.run_until(t1, &mut ()).unwrap();
        let za = state_vector(&sim_a.state());
        let zb = state_vector(&sim_b.state());
        let d: Vec<f64> = (0..2 * n).map(|i| (zb[i] - za[i]) / scale(i)).collect();
        let dist = d.iter().map(|x| x * x).sum::<f64>().sqrt();
        logs.push(dist.ln() - d0.ln());
        let renormalised: Vec<f64> = (0..2 * n).map(|i| za[i] + d0 * d[i] / dist * scale(i)).collect();
        state_b = state_from_vector(&renormalised);
    }
    let t = params.period();
    // The first 10 % realign the separation with the most expanding direction.
    let logs = &logs[logs.len() / 10..];
    let mean = logs.iter().sum::<f64>() / logs.len() as f64 / t;
    let b = 10;
    let per = logs.len() / b;
    let batches: Vec<f64> = (0..b)
        .map(|k| logs[k * per..(k + 1) * per].iter().sum::<f64>() / (per as f64 * t))
        .collect();
    let bm = batches.iter().sum::<f64>() / b as f64;
    let sd = (batches.iter().map(|x| (x - bm).powi(2)).sum::<f64>() / (b - 1) as f64).sqrt();
    (mean, sd / (b as f64).sqrt())
}

#[test]
fn the_largest_exponent_agrees_with_two_nearby_trajectories() {
    for (name, params, periods) in [
        ("hyperchaotic", hyperchaotic(), 3000),
        ("weakly chaotic", weakly_chaotic(), 4000),
        ("default (stable)", ChainParams::default(), 1000),
    ] {
        // Both start from the state after a 200-period transient from rest.
        let mut sim = Simulator::new(&params, &ChainState::at_rest(3), SimOptions::default()).unwrap();
        sim.run_until(200.0 * params.period(), &mut ()).unwrap();
        let start = sim.state();
        let (benettin, se) = two_trajectory_estimate(&params, &start, periods);
        let s = spectrum_of(
            &run_spec(params.clone(), start, periods / 10, periods - periods / 10),
            &LyapunovOptions::default(),
        );
        let tol = 3.0 * (s.largest_spread().powi(2) + se * se).sqrt() + 1e-3 * benettin.abs();
        println!(
            "{name}: λ1 = {} ± {}, two trajectories {benettin} ± {se}",
            s.largest(),
            s.largest_spread()
        );
        assert!(
            (s.largest() - benettin).abs() < tol,
            "{name}: λ1 = {} vs two-trajectory {benettin} (tolerance {tol})",
            s.largest()
        );
    }
}

#[test]
fn seed_and_run_length_change_the_exponents_within_their_spread() {
    let params = weakly_chaotic();
    let base = run_spec(params, ChainState::at_rest(3), 200, 3000);
    let a = spectrum_of(&base, &LyapunovOptions::default());
    let b = spectrum_of(
        &base,
        &LyapunovOptions {
            seed: 77,
            ..LyapunovOptions::default()
        },
    );
    let mut longer = base.clone();
    longer.periods = 200 + 6000;
    let c = spectrum_of(&longer, &LyapunovOptions::default());
    for (x, y, what) in [(&a, &b, "seed"), (&a, &c, "run length")] {
        for i in 0..6 {
            let tol = 3.0 * (x.spread[i].powi(2) + y.spread[i].powi(2)).sqrt();
            println!(
                "{what}, exponent {i}: {} ± {} vs {} ± {}",
                x.exponents[i], x.spread[i], y.exponents[i], y.spread[i]
            );
            assert!(
                (x.exponents[i] - y.exponents[i]).abs() < tol,
                "{what}, exponent {i}: {} vs {} (tolerance {tol})",
                x.exponents[i],
                y.exponents[i]
            );
        }
    }
    assert!(a.largest() > 3.0 * a.largest_spread(), "chaotic: {}", a.largest());
}

#[test]
fn non_differentiable_periods_are_skipped_and_counted() {
    // Every impact of the default case slower than this "grazing" threshold: nothing left.
    let everything = LyapunovOptions {
        sensitivity: SensitivityOptions {
            grazing_speed: 10.0,
            ..SensitivityOptions::default()
        },
        ..LyapunovOptions::default()
    };
    let spec = run_spec(ChainParams::default(), ChainState::at_rest(3), 20, 40);
    let run = lyapunov_spectrum(&spec, &everything, &mut ()).unwrap();
    match run.spectrum {
        Err(LyapunovError::NoPeriods { skipped, first }) => {
            assert_eq!(skipped, 40);
            assert!(first.is_some());
        }
        other => panic!("expected no periods, got {other:?}"),
    }
    // The weakly chaotic run with its slowest impacts declared grazing: the periods that
    // hold one (and the next) are left out, and the rest give the same spectrum.
    let spec = run_spec(weakly_chaotic(), ChainState::at_rest(3), 200, 3000);
    let some = LyapunovOptions {
        sensitivity: SensitivityOptions {
            grazing_speed: 2e-3,
            ..SensitivityOptions::default()
        },
        ..LyapunovOptions::default()
    };
    let all = spectrum_of(&spec, &LyapunovOptions::default());
    let part = spectrum_of(&spec, &some);
    show("all periods", &all);
    show("without the slowest impacts", &part);
    assert_eq!(all.skipped_periods, 0);
    assert!(part.skipped_periods > 0 && part.periods + part.skipped_periods == 3000);
    let tol = 3.0 * (all.largest_spread().powi(2) + part.largest_spread().powi(2)).sqrt();
    assert!((all.largest() - part.largest()).abs() < tol);
}

#[test]
fn an_interrupted_run_reports_the_periods_done() {
    use vibrotribo::study::{Checkpoint, Ending};
    let spec = run_spec(ChainParams::default(), ChainState::at_rest(3), 20, 100);
    let mut stop = Checkpoint {
        stop: |p: u64| p >= 50,
    };
    let run = lyapunov_spectrum(&spec, &LyapunovOptions::default(), &mut stop).unwrap();
    assert_eq!(run.outcome.ending, Ending::Stopped);
    assert_eq!(run.spectrum.unwrap().periods, 30);
}
