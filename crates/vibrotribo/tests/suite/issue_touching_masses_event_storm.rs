//! Touching masses with no force between them stopped a run with "event limit reached": the
//! three-ball Newton's cradle (`simulate --set 'oscillator.masses=[0.05,0.05,0.05]' --set gap=0
//! --set amplitude=0 --set restitution=1 --set oscillator.damping=0 --set
//! 'run.initial_velocities=[-1,0,0]'`) after one swing, and the same with μ = 0.6 once all three
//! masses had come together. A contact at zero gap whose closing speed was at rounding level got
//! no impulse and stayed open, so the exact flow carried that rounding into a slow penetration
//! that the gap search reported again and again (20 000 events in 1e-10 s). Touching,
//! force-free contacts now rest: one cluster, no event, watched by their force.

use std::f64::consts::PI;

use vibrotribo::{
    ChainParams, ChainState, EventKind, EventLog, Excitation, Frequency, SimOptions, Simulator, Trajectory,
};

/// Three 50 g masses on 120 N/m springs, touching (gaps 0), no base motion; the top mass
/// starts downwards at 1 m/s. The defaults elsewhere are the paper's (Ω = 0.70).
fn cradle(restitution: f64, damping: f64) -> (ChainParams, ChainState) {
    let params = ChainParams {
        masses: vec![0.05; 3],
        damping: vec![damping; 3],
        gaps: vec![0.0; 2],
        restitution,
        excitation: Excitation {
            amplitude: 0.0,
            ..Excitation::default()
        },
        ..ChainParams::default()
    };
    let initial = ChainState {
        positions: vec![0.0; 3],
        velocities: vec![-1.0, 0.0, 0.0],
    };
    (params, initial)
}

fn run(params: &ChainParams, initial: &ChainState, t_end: f64) -> (EventLog, Trajectory) {
    let mut sim = Simulator::new(params, initial, SimOptions::default()).unwrap();
    let mut log = EventLog::default();
    let mut traj = Trajectory::new(&sim);
    sim.run_until(t_end, &mut (&mut log, &mut traj))
        .unwrap_or_else(|e| panic!("run failed: {e}"));
    (log, traj)
}

/// μ = 1, equal masses and equal k: each impact exchanges the velocities exactly, so the
/// velocity passes through the two touching masses to the far one, which swings out as a free
/// harmonic oscillator for half a natural period and comes back with the same speed. Between
/// passes exactly one mass moves: the bottom one, x₃ = −sin(ω_n τ)/ω_n, after the top one was
/// struck downwards, and the top one, x₁ = +sin(ω_n τ)/ω_n, after the bottom one came back.
#[test]
fn three_ball_cradle_passes_the_velocity_through() {
    let (params, initial) = cradle(1.0, 0.0);
    let periods = 100.0;
    let (log, traj) = run(&params, &initial, periods * params.period());
    let wn = (params.stiffness[0] / params.masses[0]).sqrt();
    let half = PI / wn;
    // Every event is an impact of closing speed 1 at a pass t_j = jπ/ω_n, two per pass.
    let passes = (periods * params.period() / half).floor() as usize + 1;
    assert_eq!(log.events.len(), 2 * passes, "two impacts per pass, nothing else");
    for (i, e) in log.events.iter().enumerate() {
        let j = i / 2;
        let expected = j as f64 * half;
        assert_eq!(e.event.kind, EventKind::Impact);
        assert!(
            (e.event.time - expected).abs() < 1e-11,
            "event {i}: t = {}, expected pass {j} at {expected}",
            e.event.time
        );
        assert!(
            (e.event.velocity_before - 1.0).abs() < 1e-12,
            "event {i}: closing speed {}",
            e.event.velocity_before
        );
        let energy: f64 = e.velocities.iter().map(|v| 0.5 * params.masses[0] * v * v).sum();
        assert!(
            (energy - 0.025).abs() < 1e-13,
            "event {i}: kinetic energy {energy}"
        );
    }
    // Positions against the closed form on a fine grid.
    let (mut x, mut v) = (vec![0.0; 3], vec![0.0; 3]);
    let mut worst = 0.0f64;
    let samples = (periods * 200.0) as usize;
    for s in 0..=samples {
        let t = s as f64 * periods * params.period() / samples as f64;
        assert!(traj.state_at(t, &mut x, &mut v));
        let j = (t / half).floor();
        let swing = (wn * (t - j * half)).sin() / wn;
        let expected = if (j as u64).is_multiple_of(2) {
            [0.0, 0.0, -swing]
        } else {
            [swing, 0.0, 0.0]
        };
        for i in 0..3 {
            worst = worst.max((x[i] - expected[i]).abs());
        }
    }
    println!("largest position error {worst:e} m over {passes} passes");
    assert!(worst < 1e-12, "position error {worst:e} m");
}

/// With μ < 1 and equal k/m and c/m, the centre of mass X obeys M X'' + C X' + K X = 0 through
/// every impact (impulses are internal), so X(t) = e^{−αt} (V₀/ω_d) sin ω_d t with V₀ = −1/3
/// m/s. The relative motion dies out at every impact, so the masses end up together: one
/// cluster that follows X exactly, with no event after the last impact.
#[test]
fn three_ball_cradle_with_restitution_ends_as_one_cluster() {
    for damping in [0.02, 0.0] {
        let (params, initial) = cradle(0.6, damping);
        let periods = 100.0;
        let t_end = periods * params.period();
        let (log, traj) = run(&params, &initial, t_end);
        let (m, k) = (params.masses[0], params.stiffness[0]);
        let alpha = damping / (2.0 * m);
        let wd = (k / m - alpha * alpha).sqrt();
        let com = |t: f64| (-alpha * t).exp() * (-1.0 / 3.0) / wd * (wd * t).sin();
        let last = log.events.last().unwrap().event.time;
        println!(
            "c = {damping}: {} events, the last at t = {last:.4} s ({:.1} periods)",
            log.events.len(),
            last / params.period()
        );
        assert!(last < 20.0 * params.period(), "impacts go on until {last} s");
        // One cluster of all three masses from the last event to the end.
        let segment = traj.segments().last().unwrap();
        assert_eq!(segment.clusters.len(), 1, "not one cluster at the end");
        let (mut x, mut v) = (vec![0.0; 3], vec![0.0; 3]);
        let (mut worst_com, mut worst_merged) = (0.0f64, 0.0f64);
        let samples = (periods * 200.0) as usize;
        for s in 0..=samples {
            let t = s as f64 * t_end / samples as f64;
            assert!(traj.state_at(t, &mut x, &mut v));
            let big_x = x.iter().sum::<f64>() / 3.0;
            worst_com = worst_com.max((big_x - com(t)).abs());
            if t > last {
                for xi in &x {
                    worst_merged = worst_merged.max((xi - com(t)).abs());
                }
            }
        }
        println!("centre of mass error {worst_com:e} m, merged masses error {worst_merged:e} m");
        assert!(worst_com < 1e-13, "centre of mass off by {worst_com:e} m");
        assert!(worst_merged < 1e-13, "merged masses off by {worst_merged:e} m");
        // Kinetic energy is never gained at an event.
        for w in log.events.windows(2) {
            let energy = |e: &vibrotribo::dynamics::LoggedEvent| -> f64 {
                e.velocities.iter().map(|v| 0.5 * m * v * v).sum()
            };
            if w[0].event.time == w[1].event.time {
                assert!(energy(&w[1]) <= energy(&w[0]) * (1.0 + 1e-14));
            }
        }
    }
}

/// Masses with equal k/m and c/m (but unequal masses: the ratios agree only to rounding) that
/// touch at rest with no force between them, under base motion: they move together as one
/// forced oscillator, with no event at all.
#[test]
fn touching_masses_with_equal_natural_frequency_move_together() {
    let masses = [0.03, 0.05, 0.07];
    let params = ChainParams {
        masses: masses.to_vec(),
        stiffness: masses.iter().map(|m| 2400.0 * m).collect(),
        damping: masses.iter().map(|m| 0.4 * m).collect(),
        gaps: vec![0.0; 2],
        restitution: 0.6,
        excitation: Excitation {
            amplitude: 0.05,
            frequency: Frequency::OmegaRatio(0.7),
        },
        stops: Default::default(),
        forces: Vec::new(),
    };
    let periods = 50.0;
    let t_end = periods * params.period();
    let (log, traj) = run(&params, &ChainState::at_rest(3), t_end);
    assert!(log.events.is_empty(), "{} events", log.events.len());
    // x'' + 2αx' + ω_n²x = 2αy' + ω_n²y from rest, y = A sin ωt.
    let (wn2, two_alpha) = (2400.0f64, 0.4f64);
    let (a, w) = (params.excitation.amplitude, params.omega());
    // Steady response A·Im(H e^{iωt}), H = (ω_n² + 2iαω)/(ω_n² − ω² + 2iαω).
    let (nr, ni, dr, di) = (wn2, two_alpha * w, wn2 - w * w, two_alpha * w);
    let den = dr * dr + di * di;
    let (hr, hi) = ((nr * dr + ni * di) / den, (ni * dr - nr * di) / den);
    let alpha = 0.5 * two_alpha;
    let wd = (wn2 - alpha * alpha).sqrt();
    let c1 = -a * hi;
    let c2 = (-a * w * hr + alpha * c1) / wd;
    let exact = |t: f64| {
        a * (hr * (w * t).sin() + hi * (w * t).cos())
            + (-alpha * t).exp() * (c1 * (wd * t).cos() + c2 * (wd * t).sin())
    };
    let (mut x, mut v) = (vec![0.0; 3], vec![0.0; 3]);
    let mut worst = 0.0f64;
    for s in 0..=(periods as usize * 200) {
        let t = s as f64 * t_end / (periods * 200.0);
        assert!(traj.state_at(t, &mut x, &mut v));
        for xi in &x {
            worst = worst.max((xi - exact(t)).abs());
        }
    }
    println!("largest error {worst:e} m");
    assert!(
        worst < 1e-13,
        "positions off the forced oscillator by {worst:e} m"
    );
}

/// Two masses that touch at t = 0 (zero gap, zero overlap) at rest, with springs that pull them
/// apart: they separate at once with no event, each on its own free oscillation, until the gap
/// d(t) = δ + x₁(t) − x₂(t) closes again; that impact is found by bisection on the closed form.
#[test]
fn touching_pair_released_apart_separates_without_an_event() {
    let (m, k, delta) = ([0.05, 0.1], [120.0, 100.0], 0.005);
    let params = two_masses(m, k, delta);
    let (x1, x2) = (-0.01, -0.01 + delta);
    let initial = ChainState {
        positions: vec![x1, x2],
        velocities: vec![0.0, 0.0],
    };
    let (w1, w2) = ((k[0] / m[0]).sqrt(), (k[1] / m[1]).sqrt());
    let gap = |t: f64| delta + x1 * (w1 * t).cos() - x2 * (w2 * t).cos();
    let rate = |t: f64| -x1 * w1 * (w1 * t).sin() + x2 * w2 * (w2 * t).sin();
    let t_hit = first_zero_after(gap, 1e-6, 1.0);
    let (log, _) = run(&params, &initial, t_hit * 1.001);
    assert_eq!(log.events.len(), 1, "{:?}", kinds(&log));
    let e = &log.events[0].event;
    println!("impact at {:.15e} s, closed form {t_hit:.15e} s", e.time);
    assert_eq!(e.kind, EventKind::Impact);
    assert!((e.time - t_hit).abs() < 1e-12, "impact at {} vs {t_hit}", e.time);
    assert!((e.velocity_before + rate(t_hit)).abs() < 1e-9 * rate(t_hit).abs());
}

/// Two masses at the one touching position where their free accelerations agree (ω₁²x₁ = ω₂²x₂,
/// so the contact force is zero), moving together at v₀. Stuck, they form one oscillator
/// s(t) = s_eq + (s₀ − s_eq) cos ω_c t + (v₀/ω_c) sin ω_c t, and the contact force
/// N = m₁(a_G − a₁) = (k₁ − m₁K/M)(s − s₀) is linear in s. Moving up (N rising) the pair sticks
/// at once and releases when s comes back to s₀, at ω_c t = 2 atan(v₀/(ω_c (s₀ − s_eq))); moving
/// down (N falling) it parts at once, with no event, and meets again where the free gap closes.
#[test]
fn force_free_touching_pair_sticks_or_parts_by_its_force() {
    let (m, k, delta) = ([0.05, 0.1], [120.0, 50.0], 0.005);
    let params = two_masses(m, k, delta);
    let (w1s, w2s) = (k[0] / m[0], k[1] / m[1]);
    let s0 = w2s * delta / (w1s - w2s);
    let (mt, kt) = (m[0] + m[1], k[0] + k[1]);
    let s_eq = -k[1] * delta / kt;
    let wc = (kt / mt).sqrt();
    assert!(k[0] - m[0] * kt / mt > 0.0, "N rises with s");

    // Upwards: stick at once, release at the analytic time.
    let v0 = 0.1;
    let initial = ChainState {
        positions: vec![s0, s0 + delta],
        velocities: vec![v0, v0],
    };
    let t_release = 2.0 * (v0 / (wc * (s0 - s_eq))).atan() / wc;
    let (log, _) = run(&params, &initial, t_release * 1.001);
    let events: Vec<_> = log.events.iter().map(|e| (e.event.kind, e.event.time)).collect();
    println!("moving up: {events:?}, analytic release at {t_release:.15e} s");
    assert_eq!(kinds(&log), vec![EventKind::Stick, EventKind::Release]);
    assert!(events[0].1 < 1e-9, "stick at {}", events[0].1);
    assert!(
        (events[1].1 - t_release).abs() < 1e-12,
        "release at {}",
        events[1].1
    );

    // Downwards: part at once (no event), then free flight until the gap closes.
    let initial = ChainState {
        positions: vec![s0, s0 + delta],
        velocities: vec![-v0, -v0],
    };
    let (w1, w2) = (w1s.sqrt(), w2s.sqrt());
    let x1 = |t: f64| s0 * (w1 * t).cos() - v0 / w1 * (w1 * t).sin();
    let x2 = |t: f64| (s0 + delta) * (w2 * t).cos() - v0 / w2 * (w2 * t).sin();
    let t_hit = first_zero_after(|t| delta - (x2(t) - x1(t)), 1e-4, 1.0);
    let (log, traj) = run(&params, &initial, t_hit * 1.001);
    println!(
        "moving down: {:?}, analytic impact at {t_hit:.15e} s",
        kinds(&log)
    );
    assert_eq!(kinds(&log), vec![EventKind::Impact]);
    assert!((log.events[0].event.time - t_hit).abs() < 1e-12);
    let (mut x, mut v) = (vec![0.0; 2], vec![0.0; 2]);
    for s in 0..=100 {
        let t = s as f64 * t_hit / 100.0;
        assert!(traj.state_at(t, &mut x, &mut v));
        assert!(
            (x[0] - x1(t)).abs() < 1e-14 && (x[1] - x2(t)).abs() < 1e-14,
            "t = {t}: {x:?} vs [{}, {}]",
            x1(t),
            x2(t)
        );
    }
}

fn two_masses(m: [f64; 2], k: [f64; 2], delta: f64) -> ChainParams {
    ChainParams {
        masses: m.to_vec(),
        stiffness: k.to_vec(),
        damping: vec![0.0; 2],
        gaps: vec![delta],
        restitution: 0.6,
        excitation: Excitation {
            amplitude: 0.0,
            frequency: Frequency::OmegaRatio(0.7),
        },
        stops: Default::default(),
        forces: Vec::new(),
    }
}

fn kinds(log: &EventLog) -> Vec<EventKind> {
    log.events.iter().map(|e| e.event.kind).collect()
}

/// The first zero of `f` after `t0` (where `f > 0`), by a scan of step `dt` and bisection.
fn first_zero_after(f: impl Fn(f64) -> f64, t0: f64, t_max: f64) -> f64 {
    let dt = 1e-5;
    let mut t = t0;
    assert!(f(t) > 0.0);
    while f(t + dt) > 0.0 {
        t += dt;
        assert!(t < t_max, "no zero before {t_max}");
    }
    let (mut lo, mut hi) = (t, t + dt);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if f(mid) > 0.0 { lo = mid } else { hi = mid }
    }
    lo
}
