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
