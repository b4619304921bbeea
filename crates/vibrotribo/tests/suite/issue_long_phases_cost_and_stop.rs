//! Long phases ran without an estimate and ignored a stop: the motion classification of a
//! chain of 2000 masses ran a Lyapunov QR of a 4000 × 4000 basis for more than ten minutes,
//! and a random signal of 89 759 harmonics was built over 106 668 intervals without a word.
//! The classification now states its cost, (2N)³ per period, skips the exponent past
//! `MAX_CLASSIFY_WORK` unless allowed, and stops on its budget's flag; a piecewise build is
//! refused past `MAX_PIECE_EVALUATIONS` unless allowed, and stops on the flag.

use std::f64::consts::TAU;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;

use vibrotribo::excitation::{Harmonic, HarmonicPieces, MAX_PIECE_EVALUATIONS, SignalError, WorkBudget};
use vibrotribo::study::{
    LyapunovSkipped, MAX_CLASSIFY_WORK, Motion, PointOptions, Window, classify, classify_cost,
};
use vibrotribo::{ChainParams, ChainState, SimOptions};

/// `count` samples of `n` values each that neither repeat nor converge (a fixed-seed
/// pseudo-random sequence, m and m/s).
fn noise(count: usize, n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed;
    (0..count * n)
        .map(|_| {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.01
        })
        .collect()
}

/// A chain of `n` equal masses (the paper's m1, its spring and damper), gaps 2 cm.
fn chain(n: usize) -> ChainParams {
    ChainParams {
        masses: vec![0.048; n],
        stiffness: vec![120.0; n],
        damping: vec![0.02; n],
        gaps: vec![0.02; n - 1],
        ..ChainParams::default()
    }
}

fn classify_noise(
    params: &ChainParams,
    options: &PointOptions,
    budget: &WorkBudget,
) -> vibrotribo::study::MotionReport {
    let n = params.len();
    let (x, v) = (noise(8, n, 1), noise(8, n, 2));
    let state = ChainState::at_rest(n);
    let window = Window {
        positions: &x,
        velocities: &v,
        periodicity: None,
        final_state: &state,
        coupled: false,
    };
    classify(
        params,
        &SimOptions::default(),
        options,
        window,
        None,
        None,
        budget,
    )
}

/// A chain of 1000 masses: its classifying Lyapunov run would cost (2·1000)³ per period,
/// over the limit for the default window; it is skipped at once, with the size named.
#[test]
fn a_large_chain_classification_is_skipped_with_its_cost() {
    let options = PointOptions::default();
    let periods = 20 + options.recorded_periods;
    let cost = 2000f64.powi(3) * periods as f64;
    assert!(cost > MAX_CLASSIFY_WORK, "{cost}");
    assert_eq!(classify_cost(1000, periods), cost);
    let report = classify_noise(&chain(1000), &options, &WorkBudget::default());
    assert_eq!(report.motion, Motion::Undetermined);
    assert_eq!(
        report.lyapunov_skipped,
        Some(LyapunovSkipped::Costly {
            dimension: 2000,
            periods
        })
    );
    assert!(report.lyapunov.is_none());
    let text = report.lyapunov_skipped.unwrap().to_string();
    assert!(
        text.contains("2000 tangent directions") && text.contains("--allow-large"),
        "{text}"
    );
}

/// A small chain's Lyapunov run stops at its first period's end once the flag is set, and
/// says so; without the flag the same window gets an exponent.
#[test]
fn the_classification_stops_on_its_flag() {
    let options = PointOptions {
        recorded_periods: 20,
        ..PointOptions::default()
    };
    let params = chain(3);
    let stop = WorkBudget {
        allow_large: false,
        stop: Some(Arc::new(AtomicBool::new(true))),
    };
    let stopped = classify_noise(&params, &options, &stop);
    assert_eq!(stopped.motion, Motion::Undetermined);
    assert_eq!(stopped.lyapunov_skipped, Some(LyapunovSkipped::Stopped));
    let full = classify_noise(&params, &options, &WorkBudget::default());
    assert_eq!(full.lyapunov_skipped, None);
    assert!(full.lyapunov.is_some(), "{full:?}");
}

/// Harmonics 1..=k Hz of 1 mm: the cost is harmonics × intervals, refused above the limit
/// unless allowed; a set flag stops the build before its first interval.
#[test]
fn a_piecewise_build_has_a_cost_and_a_stop() {
    let harmonics: Vec<Harmonic> = (1..=2000)
        .map(|k| Harmonic {
            amplitude: 1e-3,
            omega: TAU * k as f64,
            phase: 0.0,
        })
        .collect();
    let (end, tolerance) = (100.0, 1e-12);
    let accuracy = vibrotribo::excitation::piece_accuracy(&harmonics, end, tolerance).unwrap();
    let cost = harmonics.len() as f64 * accuracy.intervals as f64;
    assert!(cost > MAX_PIECE_EVALUATIONS, "{cost}");
    match HarmonicPieces::new_within(&harmonics, end, tolerance, &WorkBudget::default()) {
        Err(SignalError::Costly {
            harmonics: h,
            intervals,
        }) => {
            assert_eq!((h, intervals), (2000, accuracy.intervals));
        }
        other => panic!("expected a refusal, got {:?}", other.map(|p| p.accuracy())),
    }
    let stop = WorkBudget {
        allow_large: true,
        stop: Some(Arc::new(AtomicBool::new(true))),
    };
    match HarmonicPieces::new_within(&harmonics, end, tolerance, &stop) {
        Err(SignalError::Stopped { done, intervals }) => {
            assert_eq!((done, intervals), (0, accuracy.intervals));
        }
        other => panic!("expected a stop, got {:?}", other.map(|p| p.accuracy())),
    }
}

/// A cancel hook that counts its calls and asks to stop from call `from` on.
fn hook_from(from: u64) -> (vibrotribo::orbits::Cancel, Arc<std::sync::atomic::AtomicU64>) {
    use std::sync::atomic::{AtomicU64, Ordering};
    let calls = Arc::new(AtomicU64::new(0));
    let seen = Arc::clone(&calls);
    let cancel = vibrotribo::orbits::Cancel::new(move || seen.fetch_add(1, Ordering::Relaxed) + 1 >= from);
    (cancel, calls)
}

/// Settling, the recorded window, the Lyapunov spectrum, the classification and the Floquet
/// shots of a sweep point ran to their end whatever was asked: `simulate --settle auto` and a
/// sweep's long points ignored SIGINT. A point polls its cancel hook throughout and,
/// stopped anywhere, gives no result but [`PointError::Stopped`]; never stopped, the same
/// result as without a hook.
#[test]
fn a_sweep_point_stops_in_every_phase_when_its_cancel_hook_asks() {
    use vibrotribo::lyapunov::LyapunovOptions;
    use vibrotribo::study::{AutoSettle, PointError, SettleMode, run_point};
    let cases = [
        // The chatter case: settled and shot onto its period-1 orbit.
        (ChainParams::paper_chatter_case(), ChainState::at_rest(3)),
        // Fig. 19's non-periodic window: irregular settling, a Lyapunov classification, the
        // Floquet search at close returns.
        (
            ChainParams {
                masses: vec![0.05, 0.2105, 0.05],
                excitation: vibrotribo::Excitation {
                    frequency: vibrotribo::Frequency::OmegaRatio(0.3),
                    ..ChainParams::default().excitation
                },
                ..ChainParams::default()
            },
            ChainState::at_rest(3),
        ),
    ];
    for (params, start) in cases {
        let options = PointOptions {
            transient_periods: 100,
            recorded_periods: 60,
            floquet: true,
            lyapunov: Some(LyapunovOptions::default()),
            settle: SettleMode::Auto(AutoSettle::default()),
            classify: true,
            ..PointOptions::default()
        };
        let free = run_point(&params, &start, &SimOptions::default(), None, &options).unwrap();
        let (cancel, calls) = hook_from(u64::MAX);
        let counted = PointOptions {
            cancel,
            ..options.clone()
        };
        let same = run_point(&params, &start, &SimOptions::default(), None, &counted).unwrap();
        assert_eq!(same, free);
        let total = calls.load(std::sync::atomic::Ordering::Relaxed);
        let last = free.strobe_periods.last().copied().unwrap();
        println!(
            "{total} polls over {last} periods, motion {:?}",
            free.motion.as_ref().map(|m| m.motion)
        );
        assert!(total > last, "{total} polls, {last} periods");
        for k in 0..=16 {
            let from = (1 + total * k / 16).min(total);
            let (cancel, _) = hook_from(from);
            let stopped = PointOptions {
                cancel,
                ..options.clone()
            };
            match run_point(&params, &start, &SimOptions::default(), None, &stopped) {
                Err(PointError::Stopped { periods }) => assert!(periods <= last, "{periods} > {last}"),
                other => panic!("stopped at poll {from} of {total}: {other:?}"),
            }
        }
    }
}

/// The chirp's settling at its start frequency is stopped by the chirp's cancel hook.
#[test]
fn a_chirps_settling_stops_when_its_cancel_hook_asks() {
    use vibrotribo::study::{ChirpError, ChirpOptions, Direction, PointError, run_chirp};
    let (cancel, _) = hook_from(1);
    let options = ChirpOptions {
        cancel,
        mechanics_only: true,
        ..ChirpOptions::new(0.6, 0.8, 20.0)
    };
    let spec = vibrotribo::config::Config::default().run_spec(true);
    match run_chirp(&spec, &options, Direction::Up, &mut ()) {
        Err(ChirpError::Settle { source, .. }) => {
            assert!(matches!(*source, PointError::Stopped { .. }), "{source}")
        }
        other => panic!("{:?}", other.map(|r| r.cycles.len())),
    }
}
