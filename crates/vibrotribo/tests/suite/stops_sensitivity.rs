//! The state-transition matrix with rigid stops against central finite differences of the
//! exact flow map: random chains N = 1..3 with an upper stop, a lower stop or both, fixed in
//! space or moving with the base, over 1–2 periods with impacts against the stops, sticking
//! to them, releases and chatter jumps in the interval.

use crate::common;

use common::fd::{FdComparison, compare_with_fd};
use common::{Lcg, random_chain};
use vibrotribo::sensitivity::{Horizon, SensitivityError, SensitivityOptions, flow_map};
use vibrotribo::{ChainParams, ChainState, EventKind, SimOptions, Stop, StopFrame, Stops};

/// A random chain of 1–3 masses with random stops (gaps 0–10 mm, restitution 0–0.9, either
/// frame) and a random state that leaves them open.
fn random_chain_with_stops(rng: &mut Lcg, s: usize) -> (ChainParams, ChainState) {
    let n = 1 + s % 3;
    let mu = rng.range(0.3, 0.9);
    let (mut params, mut state) = if n == 1 {
        let (mut p, mut st) = random_chain(rng, 2, mu);
        p.masses.truncate(1);
        p.stiffness.truncate(1);
        p.damping.truncate(1);
        p.gaps.clear();
        st.positions.truncate(1);
        st.velocities.truncate(1);
        (p, st)
    } else {
        random_chain(rng, n, mu)
    };
    params.excitation.amplitude = rng.range(0.005, 0.03);
    let stop = |rng: &mut Lcg| Stop {
        gap: rng.range(0.0, 0.01),
        restitution: if s.is_multiple_of(5) {
            0.0
        } else {
            rng.range(0.3, 0.9)
        },
        frame: if rng.next() < 0.5 {
            StopFrame::Fixed
        } else {
            StopFrame::Base
        },
    };
    params.stops = match s % 3 {
        0 => Stops {
            upper: Some(stop(rng)),
            lower: None,
        },
        1 => Stops {
            upper: None,
            lower: Some(stop(rng)),
        },
        _ => Stops {
            upper: Some(stop(rng)),
            lower: Some(stop(rng)),
        },
    };
    // Shift the state into the room between the stops (at t = 0 the base is at rest).
    let top = state.positions[0];
    let bottom = state.positions[n - 1];
    let shift = match (params.stops.upper, params.stops.lower) {
        (Some(u), _) if top > u.gap => u.gap - top - 0.3 * u.gap,
        (_, Some(l)) if bottom < -l.gap => -l.gap - bottom + 0.3 * l.gap,
        _ => 0.0,
    };
    for x in &mut state.positions {
        *x += shift;
    }
    (params, state)
}

#[derive(Debug, Default)]
struct Tally {
    compared: usize,
    skipped: usize,
    stop_impacts: usize,
    stop_sticks: usize,
    stop_releases: usize,
    stop_chatter: usize,
    errors: Vec<f64>,
}

fn sweep(samples: usize, seed: u64) -> Tally {
    let mut rng = Lcg(seed);
    let mut tally = Tally::default();
    for s in 0..samples {
        let (params, state) = random_chain_with_stops(&mut rng, s);
        if params.validate().is_err() || params.validate_state(&state).is_err() {
            tally.skipped += 1;
            continue;
        }
        let horizon = Horizon::Periods(1 + (s % 2) as u32);
        let map = match flow_map(
            &params,
            &state,
            horizon,
            &SimOptions::default(),
            &SensitivityOptions::default(),
        ) {
            Ok(map) => map,
            Err(SensitivityError::NonSmooth(p)) => {
                println!("sample {s}: {p}");
                tally.skipped += 1;
                continue;
            }
            Err(e) => panic!("sample {s}: {e}\n{params:?}\n{state:?}"),
        };
        let Some(FdComparison {
            error,
            fd_uncertainty: uncertainty,
        }) = compare_with_fd(&params, &state, horizon, &map.stm, &map.events, 1e-6)
        else {
            tally.skipped += 1;
            continue;
        };
        let at_stop = |k: EventKind| {
            map.events
                .iter()
                .filter(|e| e.kind == k && params.is_stop(e.contact))
                .count()
        };
        tally.stop_impacts += at_stop(EventKind::Impact);
        tally.stop_sticks += at_stop(EventKind::Stick);
        tally.stop_releases += at_stop(EventKind::Release);
        tally.stop_chatter += at_stop(EventKind::Chatter);
        tally.compared += 1;
        tally.errors.push(error);
        assert!(
            error <= 2e-7 + 3.0 * uncertainty,
            "sample {s}: Φ differs from finite differences by {error:.3e} (their own uncertainty \
             {uncertainty:.3e})\n{params:?}\n{state:?}\n{:?}",
            map.events
        );
    }
    tally.errors.sort_by(f64::total_cmp);
    let q = |p: f64| {
        tally
            .errors
            .get(((tally.errors.len() as f64 - 1.0) * p) as usize)
            .copied()
            .unwrap_or(0.0)
    };
    println!(
        "{} compared ({} impacts, {} sticks, {} releases, {} chatter jumps at stops): relative error \
         median {:.2e}, 90 % {:.2e}, largest {:.2e}; {} skipped (not differentiable or sequence changed)",
        tally.compared,
        tally.stop_impacts,
        tally.stop_sticks,
        tally.stop_releases,
        tally.stop_chatter,
        q(0.5),
        q(0.9),
        q(1.0),
        tally.skipped
    );
    tally
}

fn assert_coverage(t: &Tally, samples: usize) {
    assert!(t.compared * 10 >= samples * 6, "too few samples compared: {t:?}");
    assert!(
        t.stop_impacts > 0 && t.stop_sticks > 0 && t.stop_releases > 0,
        "the sweep must cover impacts, sticking and releases at stops: {t:?}"
    );
}

#[test]
fn random_chains_with_stops_match_finite_differences() {
    let samples = 60;
    let t = sweep(samples, 2024);
    assert_coverage(&t, samples);
}

#[test]
#[ignore = "full randomized suite: cargo test --release -- --ignored"]
fn random_chains_with_stops_match_finite_differences_full() {
    let samples = 1000;
    let t = sweep(samples, 77);
    assert_coverage(&t, samples);
}
