//! The state-transition matrix Φ of the non-smooth flow against truth from outside it:
//! central finite differences of the exact flow map (random chains N = 2..5 with impacts,
//! sticking, releases and chatter jumps), the matrix exponential of the linear system when
//! nothing touches, and finite differences of event times.

use crate::common;

use common::fd::{compare_with_fd, run_with, signature};
use common::{Lcg, random_chain};
use nalgebra::DMatrix;
use vibrotribo::sensitivity::{
    Horizon, SensitivityError, SensitivityOptions, flow_map, length_scale, speed_scale, state_vector,
};
use vibrotribo::{ChainParams, ChainState, EventKind, Excitation, Frequency, SimOptions, Simulator};

/// What a randomized sweep saw.
#[derive(Debug, Default)]
struct Tally {
    compared: usize,
    non_smooth: usize,
    sequence_changed: usize,
    errors: Vec<f64>,
    impacts: usize,
    sticks: usize,
    releases: usize,
    chatter: usize,
    chatter_release: usize,
}

/// Random chains N = 2..5 from `seed`, each over 1–3 periods from a random state; μ = 0
/// (plastic) every 7th sample, μ = 1 every 11th, otherwise μ ∈ [0.3, 0.9].
fn sweep(samples: usize, seed: u64) -> Tally {
    let mut rng = Lcg(seed);
    let mut tally = Tally::default();
    for s in 0..samples {
        let n = 2 + s % 4;
        let mu = if s % 7 == 0 {
            0.0
        } else if s % 11 == 0 {
            1.0
        } else {
            rng.range(0.3, 0.9)
        };
        let (params, state) = random_chain(&mut rng, n, mu);
        let horizon = Horizon::Periods(1 + (s % 3) as u32);
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
                tally.non_smooth += 1;
                continue;
            }
            Err(e) => panic!("sample {s}: {e}"),
        };
        let Some(cmp) = compare_with_fd(&params, &state, horizon, &map.stm, &map.events, 1e-6) else {
            tally.sequence_changed += 1;
            continue;
        };
        let count = |k: EventKind| map.events.iter().filter(|e| e.kind == k).count();
        tally.impacts += count(EventKind::Impact);
        tally.sticks += count(EventKind::Stick);
        tally.releases += count(EventKind::Release);
        tally.chatter += count(EventKind::Chatter);
        tally.chatter_release += map
            .events
            .windows(2)
            .filter(|w| w[0].kind == EventKind::Chatter && w[1].kind == EventKind::Release)
            .count();
        tally.compared += 1;
        tally.errors.push(cmp.error);
        assert!(
            cmp.error <= 2e-7 + 3.0 * cmp.fd_uncertainty,
            "sample {s} (N = {n}, μ = {mu}, {} events): Φ differs from finite differences by {:.3e} \
             (their own uncertainty {:.3e})\n{params:?}\n{state:?}",
            map.events.len(),
            cmp.error,
            cmp.fd_uncertainty
        );
    }
    tally.errors.sort_by(f64::total_cmp);
    let quantile = |q: f64| {
        tally
            .errors
            .get(((tally.errors.len() as f64 - 1.0) * q) as usize)
            .copied()
            .unwrap_or(0.0)
    };
    println!(
        "{} compared ({} impacts, {} sticks, {} releases, {} chatter jumps): relative error median {:.2e}, \
         90 % {:.2e}, 99 % {:.2e}, largest {:.2e} ({} above 1e-7, all within the differences' own uncertainty); \
         {} not differentiable, {} with a change of event sequence within the step",
        tally.compared,
        tally.impacts,
        tally.sticks,
        tally.releases,
        tally.chatter,
        quantile(0.5),
        quantile(0.9),
        quantile(0.99),
        quantile(1.0),
        tally.errors.iter().filter(|e| **e > 1e-7).count(),
        tally.non_smooth,
        tally.sequence_changed
    );
    tally
}

fn assert_coverage(t: &Tally, samples: usize) {
    assert!(t.compared * 10 >= samples * 8, "too few samples compared: {t:?}");
    assert!(
        t.impacts > 0 && t.sticks > 0 && t.releases > 0 && t.chatter > 0,
        "the sweep must cover impacts, sticking, releases and chatter jumps: {t:?}"
    );
}

#[test]
fn random_chains_match_finite_differences() {
    let samples = 120;
    let t = sweep(samples, 12345);
    assert_coverage(&t, samples);
}

#[test]
#[ignore = "full randomized suite: cargo test --release -- --ignored"]
fn random_chains_match_finite_differences_full() {
    let samples = 2000;
    let t = sweep(samples, 987654321);
    assert_coverage(&t, samples);
}

/// Block-diagonal linear system of free masses: ż = A z + b(t), A = [[0, I], [−K/M, −C/M]].
fn free_system(params: &ChainParams) -> DMatrix<f64> {
    let n = params.len();
    let mut a = DMatrix::zeros(2 * n, 2 * n);
    for i in 0..n {
        a[(i, n + i)] = 1.0;
        a[(n + i, i)] = -params.stiffness[i] / params.masses[i];
        a[(n + i, n + i)] = -params.damping[i] / params.masses[i];
    }
    a
}

fn assert_close(got: &DMatrix<f64>, want: &DMatrix<f64>, tol: f64, what: &str) {
    let err = (got - want).amax() / want.amax().max(1.0);
    assert!(
        err < tol,
        "{what}: relative error {err:.3e}\ngot {got}\nwant {want}"
    );
}

#[test]
fn impact_free_chain_matches_the_matrix_exponential() {
    // Gaps far wider than the motion: no contact. All damping regimes: under-, critically and
    // over-damped masses.
    let mut rng = Lcg(7);
    for n in 2..=5 {
        let m: Vec<f64> = (0..n).map(|_| rng.range(0.03, 0.2)).collect();
        let k: Vec<f64> = (0..n).map(|_| rng.range(80.0, 200.0)).collect();
        let c: Vec<f64> = (0..n)
            .map(|i| match i % 3 {
                0 => rng.range(0.0, 0.1),
                1 => 2.0 * (m[i] * k[i]).sqrt(),
                _ => 3.0 * (m[i] * k[i]).sqrt(),
            })
            .collect();
        let params = ChainParams {
            masses: m,
            stiffness: k,
            damping: c,
            gaps: vec![10.0; n - 1],
            restitution: 0.6,
            excitation: Excitation {
                amplitude: 0.05,
                frequency: Frequency::OmegaRatio(rng.range(0.3, 1.5)),
            },
            stops: Default::default(),
            forces: Vec::new(),
        };
        let state = ChainState {
            positions: (0..n).map(|_| rng.range(-0.02, 0.02)).collect(),
            velocities: (0..n).map(|_| rng.range(-0.5, 0.5)).collect(),
        };
        let t1 = rng.range(0.05, 0.6);
        let map = flow_map(
            &params,
            &state,
            Horizon::Time(t1),
            &SimOptions::default(),
            &SensitivityOptions::default(),
        )
        .unwrap();
        assert!(map.events.is_empty());
        let want = (free_system(&params) * t1).exp();
        assert_close(&map.stm, &want, 1e-12, &format!("N = {n}, t = {t1}"));
    }
}

#[test]
fn stuck_cluster_matches_the_matrix_exponential_of_its_oscillator() {
    // Two masses pressed together, no base motion: m1 (stiff) held above its rest position
    // pulls down harder than m2 (soft) pulls down, so the contact presses (gap acceleration
    // a1 − a2 < 0) and sticks from the start; over 50 ms the cluster (M, C, K) swings down
    // without the force reaching zero.
    let (m1, m2, k1, k2, c1, c2, delta) = (0.05, 0.15, 120.0, 20.0, 0.02, 0.03, 0.01);
    let params = ChainParams {
        masses: vec![m1, m2],
        stiffness: vec![k1, k2],
        damping: vec![c1, c2],
        gaps: vec![delta],
        restitution: 0.6,
        excitation: Excitation {
            amplitude: 0.0,
            frequency: Frequency::OmegaRatio(0.7),
        },
        stops: Default::default(),
        forces: Vec::new(),
    };
    let state = ChainState {
        positions: vec![0.02, 0.02 + delta],
        velocities: vec![0.0, 0.0],
    };
    let t1 = 0.05;
    let map = flow_map(
        &params,
        &state,
        Horizon::Time(t1),
        &SimOptions::default(),
        &SensitivityOptions::default(),
    )
    .unwrap();
    assert!(map.events.is_empty(), "{:?}", map.events);
    let (mm, kk, cc) = (m1 + m2, k1 + k2, c1 + c2);
    let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -kk / mm, -cc / mm]);
    let e = (a * t1).exp();
    // Full Φ: every member follows the cluster coordinate, read as the mass-weighted mean.
    let w = [m1 / mm, m2 / mm];
    let mut want = DMatrix::zeros(4, 4);
    for row in 0..2 {
        for col in 0..2 {
            for (i, j) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
                want[(2 * row + i, 2 * col + j)] = e[(row, col)] * w[j];
            }
        }
    }
    // want is in [x1, x2, v1, v2] order already: rows 2·row + i are (x or v) of mass i.
    assert_close(&map.stm, &want, 1e-12, "stuck pair");
    // Rank 2: the gap and the relative velocity do not move.
    let sv = map.stm.singular_values();
    assert!(sv[2] < 1e-12 * sv[0] && sv[3] < 1e-12 * sv[0], "{sv}");
}

/// The gradients of event times the observer reports (impacts: `δτ = ∇d·δz / v_c` carried
/// back to the initial state; chatter accumulation points: the derivative of `t_acc`)
/// against central differences of the event times, in the paper's chatter case with the
/// default chatter tolerance (24 bounces resolved before the jump) and a coarse one (the jump
/// comes after a few bounces, whose larger rebound speeds time the accumulation point with
/// less rounding noise).
#[test]
fn event_time_gradients_match_finite_differences() {
    for tolerance in [1e-12, 1e-3] {
        let sim_options = SimOptions {
            chatter_tolerance: tolerance,
            ..SimOptions::default()
        };
        event_time_gradients(&sim_options);
    }
}

fn event_time_gradients(sim_options: &SimOptions) {
    let params = ChainParams::paper_chatter_case();
    let n = params.len();
    let state = ChainState::at_rest(n);
    let horizon = Horizon::Periods(2);
    let options = SensitivityOptions {
        record_events: true,
        ..SensitivityOptions::default()
    };
    let mut sim = Simulator::new(&params, &state, sim_options.clone()).unwrap();
    let mut stm = vibrotribo::sensitivity::Sensitivity::new(&params, options);
    sim.run_until(horizon.end_time(&params), &mut stm).unwrap();
    let recorded = stm.events();
    let chatter = recorded
        .iter()
        .filter(|e| e.event.kind == EventKind::Chatter)
        .count();
    assert!(chatter >= 1, "the chatter case must jump: {chatter}");
    let (l, v) = (length_scale(&params), speed_scale(&params));
    let z0 = state_vector(&state);
    let reference: Vec<_> = recorded.iter().map(|e| (e.event.kind, e.event.contact)).collect();
    let mut checked = (0, 0);
    let mut worst_acc = 0.0f64;
    for j in 0..2 * n {
        let h = 1e-6 * if j < n { l } else { v };
        let mut times = Vec::new();
        for step in [h, -h, 2.0 * h, -2.0 * h] {
            let mut z = z0.clone();
            z[j] += step;
            let (_, ev) = run_with(&params, &z, horizon, sim_options).unwrap();
            assert_eq!(signature(&ev), reference, "sequence changed for a step in z[{j}]");
            times.push(ev.iter().map(|e| e.time).collect::<Vec<_>>());
        }
        for (e, rec) in recorded.iter().enumerate() {
            let Some(gradient) = &rec.time_gradient else {
                continue;
            };
            let d1 = (times[0][e] - times[1][e]) / (2.0 * h);
            let d2 = (times[2][e] - times[3][e]) / (4.0 * h);
            let fd = d1 + (d1 - d2) / 3.0;
            // An event time is located no better than the rounding of the gap (~64 ulp of the
            // motion's size) over the speed at which the gap closes: the last rebound speed
            // for an accumulation point.
            let speed = match rec.event.kind {
                EventKind::Chatter => recorded[e - 1].event.velocity_after,
                _ => rec.event.velocity_before,
            };
            let noise = 64.0 * f64::EPSILON * l / speed / h;
            // Scaled to periods per state scale.
            let unit = if j < n { l } else { v } / params.period();
            let err = (fd - gradient[j]).abs() * unit;
            let tol = 1e-7 + (3.0 * (d1 - d2).abs() + 4.0 * noise) * unit;
            assert!(
                err <= tol,
                "{:?} at t = {:.9} s, ∂t/∂z[{j}]: recorded {:e}, differences {fd:e} (tolerance {tol:e})",
                rec.event.kind,
                rec.event.time,
                gradient[j]
            );
            match rec.event.kind {
                EventKind::Chatter => {
                    checked.1 += 1;
                    worst_acc = worst_acc.max((fd - gradient[j]).abs() / gradient[j].abs());
                }
                _ => checked.0 += 1,
            }
        }
    }
    println!(
        "chatter tolerance {:e}: {} impact-time and {} accumulation-time derivatives checked; accumulation time: \
         largest relative error {worst_acc:.2e}",
        sim_options.chatter_tolerance, checked.0, checked.1
    );
}
