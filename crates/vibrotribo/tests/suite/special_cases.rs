//! Constructed cases with known answers: grazing, chatter accumulation, plastic impacts,
//! sticking and release of clusters (including all three masses), simultaneous impacts, and
//! the paper's symmetric R_m = 1 case.

use crate::common;

use common::grazing_pair;

use std::f64::consts::PI;

use vibrotribo::{
    ChainParams, ChainState, ContactStatus, EventKind, EventLog, Excitation, Frequency, SimOptions, Simulator,
};

fn run(params: &ChainParams, initial: &ChainState, t_end: f64) -> EventLog {
    let mut sim = Simulator::new(params, initial, SimOptions::default()).unwrap();
    let mut log = EventLog::default();
    sim.run_until(t_end, &mut log).unwrap();
    log
}

fn kinds(log: &EventLog) -> Vec<(EventKind, usize)> {
    log.events
        .iter()
        .map(|e| (e.event.kind, e.event.contact))
        .collect()
}

#[test]
fn exact_graze_is_detected() {
    let (params, initial, wn) = grazing_pair(0.0);
    let log = run(&params, &initial, 0.9 * PI / wn);
    assert_eq!(
        log.events.len(),
        1,
        "expected one grazing contact, got {:?}",
        kinds(&log)
    );
    common::assert_grazing_contact(&log.events[0].event, 0.0, 0.5 * PI / wn, 0.0);
}

#[test]
fn shallow_crossing_is_detected_and_near_miss_is_not() {
    // Overlap of 1e-9 δ = 2e-11 m lasting ~1 µs: a fixed-step integrator with any step
    // above a microsecond misses it.
    for eps in [1e-9, 1e-6, 1e-3] {
        let (params, initial, wn) = grazing_pair(eps);
        let log = run(&params, &initial, 0.9 * PI / wn);
        let first = &log
            .events
            .first()
            .unwrap_or_else(|| panic!("ε = {eps}: crossing missed"))
            .event;
        let t_expected = (1.0 / (1.0 + eps)).asin() / wn;
        let v_expected = params.gaps[0] * wn * ((1.0 + eps).powi(2) - 1.0).sqrt();
        common::assert_grazing_contact(first, eps, t_expected, v_expected);
    }
    let (params, initial, wn) = grazing_pair(-1e-9);
    let log = run(&params, &initial, 0.9 * PI / wn);
    assert!(log.events.is_empty(), "near miss reported as {:?}", kinds(&log));
}

/// Two masses with no base motion, pressed together: the stiff upper mass is pulled down onto
/// the soft lower one (closing relative acceleration a ≈ 12 m/s²) while the lower approaches
/// with a small speed. The impacts form a chatter sequence.
fn chatter_pair(v0: f64) -> (ChainParams, ChainState) {
    let delta = 0.005;
    let params = ChainParams {
        masses: vec![0.05, 0.15],
        stiffness: vec![120.0, 120.0],
        damping: vec![0.0, 0.0],
        gaps: vec![delta],
        restitution: 0.6,
        excitation: Excitation {
            amplitude: 0.0,
            frequency: Frequency::OmegaRatio(0.7),
        },
        stops: Default::default(),
        forces: Vec::new(),
    };
    let initial = ChainState {
        positions: vec![0.01, 0.01 + delta],
        velocities: vec![0.0, v0],
    };
    (params, initial)
}

/// The pair of [`chatter_pair`] integrated in gap coordinates, state [x1, v1, d, d'] with
/// d = δ − (x2 − x1): near contact d is resolved to its own relative precision, not to the
/// ulp of the positions, so tiny bounces are timed accurately.
#[derive(Clone)]
struct GapOde {
    m: [f64; 2],
    k: [f64; 2],
    delta: f64,
}

impl ode_solvers::System<f64, ode_solvers::DVector<f64>> for GapOde {
    fn system(&self, _t: f64, y: &ode_solvers::DVector<f64>, dy: &mut ode_solvers::DVector<f64>) {
        let (x1, v1, d, dd) = (y[0], y[1], y[2], y[3]);
        let x2 = x1 + self.delta - d;
        let a1 = -self.k[0] * x1 / self.m[0];
        let a2 = -self.k[1] * x2 / self.m[1];
        dy[0] = v1;
        dy[1] = a1;
        dy[2] = dd;
        dy[3] = a1 - a2;
    }
}

fn gap_ode_to(ode: &GapOde, t0: f64, t1: f64, y0: &[f64]) -> Vec<f64> {
    use ode_solvers::{DVector, Dop853, OutputType};
    // Autonomous system: ode_solvers' DOP853 stage-time issue does not arise. The absolute
    // tolerance is far below the smallest flight apex resolved here (~1e-17 m).
    let mut stepper = Dop853::from_param(
        ode.clone(),
        t0,
        t1,
        0.0,
        DVector::from_column_slice(y0),
        1e-14,
        1e-24,
        0.9,
        0.0,
        0.333,
        6.0,
        t1 - t0,
        0.0,
        10_000_000,
        u32::MAX,
        OutputType::Sparse,
    );
    stepper.integrate().expect("Dop853 failed");
    stepper.y_out().last().unwrap().iter().copied().collect()
}

/// The accumulation time computed independently: every bounce is integrated in gap
/// coordinates with Dop853 and its impact found by bisection, until the rebound speed is
/// 1e-5 of the first; the remaining tail (~4e-9 s) is the Budd–Dux limit, whose
/// neglected-jerk error is ~1e-17 s.
fn bruteforce_accumulation(params: &ChainParams, initial: &ChainState) -> f64 {
    let mu = params.restitution;
    let (m1, m2) = (params.masses[0], params.masses[1]);
    let ode = GapOde {
        m: [m1, m2],
        k: [params.stiffness[0], params.stiffness[1]],
        delta: params.gaps[0],
    };
    let x1 = initial.positions[0];
    let d0 = params.gaps[0] - (initial.positions[1] - x1);
    let mut y = vec![
        x1,
        initial.velocities[0],
        d0,
        initial.velocities[0] - initial.velocities[1],
    ];
    let mut t = 0.0;
    let v_first = -y[3];
    loop {
        // Impact at t: Newton's law with momentum conservation; closing speed vc = −d'.
        let vc = -y[3];
        let v2 = y[1] + vc;
        let vcm = (m1 * y[1] + m2 * v2) / (m1 + m2);
        y[1] = vcm + m2 / (m1 + m2) * mu * vc;
        y[3] = mu * vc;
        y[2] = 0.0;
        let u = mu * vc;
        let x2 = y[0] + params.gaps[0];
        let a = (-params.stiffness[1] * x2 / m2) - (-params.stiffness[0] * y[0] / m1);
        if u < 1e-5 * v_first {
            return t + 2.0 * u / ((1.0 - mu) * a);
        }
        let guess = 2.0 * u / a;
        let (mut lo, mut hi) = (t + 0.5 * guess, t + 1.5 * guess);
        assert!(gap_ode_to(&ode, t, lo, &y)[2] > 0.0);
        assert!(gap_ode_to(&ode, t, hi, &y)[2] < 0.0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if gap_ode_to(&ode, t, mid, &y)[2] > 0.0 {
                lo = mid
            } else {
                hi = mid
            }
        }
        y = gap_ode_to(&ode, t, lo, &y);
        t = lo;
    }
}

#[test]
fn chatter_ends_at_the_accumulation_point_then_sticks_and_releases() {
    let (params, initial) = chatter_pair(1e-3);
    let log = run(&params, &initial, 0.05);
    let events = kinds(&log);
    let chatter = log
        .events
        .iter()
        .position(|e| e.event.kind == EventKind::Chatter)
        .expect("no chatter jump");
    assert!(events[..chatter].iter().all(|&(k, _)| k == EventKind::Impact));
    assert_eq!(events[chatter + 1], (EventKind::Stick, 0), "events: {events:?}");
    let t_acc = log.events[chatter].event.time;
    let expected = bruteforce_accumulation(&params, &initial);
    println!("accumulation at {t_acc:.15e} s, brute force {expected:.15e} s");
    // The documented accuracy of the jump: chatter_tolerance × T, or the rounding with which
    // the next bounce could be timed (about two ulps of the positions over the last rebound
    // speed), whichever is larger.
    let last = &log.events[chatter - 1];
    let scale = last.positions.iter().fold(0.0f64, |a, x| a.max(x.abs())) + params.gaps[0];
    let rounding = 2.0 * f64::EPSILON * scale / last.event.velocity_after;
    let tol = (SimOptions::default().chatter_tolerance * params.period()).max(rounding);
    println!(
        "jump after rebound speed {:e} m/s: tolerance {tol:e} s",
        last.event.velocity_after
    );
    assert!(
        (t_acc - expected).abs() < tol,
        "chatter ends at {t_acc}, expected {expected} (tolerance {tol:e})"
    );
    // Impact speeds fall geometrically with ratio μ.
    for w in log.events[..chatter].windows(2) {
        let ratio = w[1].event.velocity_before / w[0].event.velocity_before;
        assert!((ratio - params.restitution).abs() < 1e-3, "ratio {ratio}");
    }
    // After sticking the pair moves as one body until the contact force
    // N = m1 m2/(m1+m2) (a2 − a1) vanishes, i.e. (with a_i = −k_i x_i/m_i and x2 = x1 + δ)
    // when x1 falls to x* = k2 δ m1 / (k1 m2 − k2 m1)... computed from the cluster's harmonic
    // motion about its equilibrium s_eq = −k2 δ/(k1 + k2).
    let release = log
        .events
        .iter()
        .find(|e| e.event.kind == EventKind::Release)
        .expect("no release");
    let stuck = &log.events[chatter + 1];
    let (m1, m2, k1, k2, d) = (
        params.masses[0],
        params.masses[1],
        params.stiffness[0],
        params.stiffness[1],
        params.gaps[0],
    );
    let x_star = k2 * d * m1 / (k1 * m2 - k2 * m1);
    let wc = ((k1 + k2) / (m1 + m2)).sqrt();
    let s_eq = -k2 * d / (k1 + k2);
    let (s0, v0) = (stuck.positions[0] - s_eq, stuck.velocities[0]);
    // s(τ) − s_eq = s0 cos wc τ + v0/wc sin wc τ = R cos(wc τ − φ); first τ > 0 with s = x*.
    let r = s0.hypot(v0 / wc);
    let phi = (v0 / wc).atan2(s0);
    let target = ((x_star - s_eq) / r).acos();
    let mut tau = (target + phi) / wc;
    if tau <= 0.0 {
        tau += 2.0 * PI / wc;
    }
    let expected_release = stuck.event.time + tau;
    println!(
        "release at {:.15e}, analytic {expected_release:.15e}",
        release.event.time
    );
    assert!((release.event.time - expected_release).abs() < 1e-12);
}

#[test]
fn plastic_impacts_stick() {
    let params = ChainParams {
        restitution: 0.0,
        ..ChainParams::default()
    };
    let log = run(&params, &ChainState::at_rest(3), 20.0 * params.period());
    let impacts: Vec<_> = log
        .events
        .iter()
        .filter(|e| e.event.kind == EventKind::Impact)
        .collect();
    assert!(!impacts.is_empty());
    for e in &impacts {
        // No struck contact is left approaching.
        assert!(
            e.event.velocity_after > -1e-12,
            "still closing after a plastic impact"
        );
        // An isolated plastic impact (no other impact at that instant) leaves the pair with
        // one velocity. In a simultaneous impact the pairwise rule may open the first contact
        // again while resolving the second.
        let simultaneous = impacts.iter().filter(|o| o.event.time == e.event.time).count() > 1;
        if !simultaneous {
            assert!(
                e.event.velocity_after.abs() < 1e-12,
                "μ = 0 rebound {}",
                e.event.velocity_after
            );
            let k = e.event.contact;
            assert!((e.velocities[k] - e.velocities[k + 1]).abs() < 1e-12);
        }
    }
    let sticks = log
        .events
        .iter()
        .filter(|e| e.event.kind == EventKind::Stick)
        .count();
    let releases = log
        .events
        .iter()
        .filter(|e| e.event.kind == EventKind::Release)
        .count();
    assert!(sticks > 0 && sticks >= releases && sticks - releases <= 2);
}

/// All three masses pressed together with no base motion: a stiff top, medium middle and soft
/// bottom spring push the stack together. The cluster moves harmonically; the contact forces
/// N_1 = m1 (a_G − a1), N_2 = (m1 + m2) a_G − m1 a1 − m2 a2 (docs/MODEL.md §1) are linear in the
/// cluster position, so the first release time is analytic.
#[test]
fn all_three_stuck_release_at_the_analytic_time() {
    let (m, k, d) = ([0.05, 0.1, 0.08], [300.0, 100.0, 20.0], [0.004, 0.006]);
    let params = ChainParams {
        masses: m.to_vec(),
        stiffness: k.to_vec(),
        damping: vec![0.0; 3],
        gaps: d.to_vec(),
        restitution: 0.5,
        excitation: Excitation {
            amplitude: 0.0,
            frequency: Frequency::OmegaRatio(1.0),
        },
        stops: Default::default(),
        forces: Vec::new(),
    };
    let s0 = 0.02;
    let offsets = [0.0, d[0], d[0] + d[1]];
    let initial = ChainState {
        positions: offsets.iter().map(|o| s0 + o).collect(),
        velocities: vec![0.0; 3],
    };
    let mut sim = Simulator::new(&params, &initial, SimOptions::default()).unwrap();
    assert_eq!(
        sim.contact_status(),
        vec![ContactStatus::Stuck, ContactStatus::Stuck]
    );
    let mut log = EventLog::default();
    sim.run_until(0.2, &mut log).unwrap();
    let first = &log.events[0].event;
    assert_eq!(first.kind, EventKind::Release);
    // Analytic: s(t) = s_eq + (s0 − s_eq) cos(ω t), forces linear in s.
    let (mt, kt) = (m.iter().sum::<f64>(), k.iter().sum::<f64>());
    let f0: f64 = -(0..3).map(|i| k[i] * offsets[i]).sum::<f64>();
    let s_eq = f0 / kt;
    let w = (kt / mt).sqrt();
    let force = |j: usize, s: f64| {
        let a_g = (-kt * s + f0) / mt;
        (0..=j).map(|i| m[i] * a_g + k[i] * (s + offsets[i])).sum::<f64>()
    };
    // N_j(s) = α_j s + β_j: zero at s_j; the first reached as s falls from s0 towards s_eq.
    let mut best = f64::INFINITY;
    let mut which = 0;
    for j in 0..2 {
        let beta = force(j, 0.0);
        let alpha = force(j, 1.0) - beta;
        let s_zero = -beta / alpha;
        assert!(force(j, s0) > 0.0, "contact {j} not compressive at start");
        let c = (s_zero - s_eq) / (s0 - s_eq);
        if c.abs() <= 1.0 {
            let t = c.acos() / w;
            if t < best {
                best = t;
                which = j;
            }
        }
    }
    println!(
        "release of contact {} at {:.15e}, analytic {best:.15e}",
        first.contact + 1,
        first.time
    );
    assert_eq!(first.contact, which);
    assert!((first.time - best).abs() < 1e-12);
}

#[test]
fn newtons_cradle_with_elastic_impacts() {
    // Equal masses, μ = 1, negligible springs: m3 strikes m2, which touches m1 at rest.
    let params = ChainParams {
        masses: vec![0.1; 3],
        stiffness: vec![1e-9; 3],
        damping: vec![0.0; 3],
        gaps: vec![0.0, 0.01],
        restitution: 1.0,
        excitation: Excitation {
            amplitude: 0.0,
            frequency: Frequency::OmegaRatio(1.0),
        },
        stops: Default::default(),
        forces: Vec::new(),
    };
    let initial = ChainState {
        positions: vec![0.0, 0.0, 0.0],
        velocities: vec![0.0, 0.0, 1.0],
    };
    let log = run(&params, &initial, 0.011);
    let hit = &log.events.last().unwrap();
    assert!(
        (hit.event.time - 0.01).abs() < 1e-12,
        "impact at {}",
        hit.event.time
    );
    let v = &hit.velocities;
    assert!(
        (v[0] - 1.0).abs() < 1e-12 && v[1].abs() < 1e-12 && v[2].abs() < 1e-12,
        "{v:?}"
    );
}

#[test]
fn symmetric_simultaneous_impact() {
    // m2 at rest in the middle, m1 and m3 close on it with equal speeds and equal gaps: both
    // contacts close at the same instant. Pairwise resolution (μ = 1, equal masses) sends m1
    // up and m3 down with the incoming speed and leaves m2 at rest.
    let params = ChainParams {
        masses: vec![0.1; 3],
        stiffness: vec![1e-9; 3],
        damping: vec![0.0; 3],
        gaps: vec![0.01, 0.01],
        restitution: 1.0,
        excitation: Excitation {
            amplitude: 0.0,
            frequency: Frequency::OmegaRatio(1.0),
        },
        stops: Default::default(),
        forces: Vec::new(),
    };
    let initial = ChainState {
        positions: vec![0.0; 3],
        velocities: vec![-1.0, 0.0, 1.0],
    };
    let log = run(&params, &initial, 0.0101);
    let times: Vec<f64> = log.events.iter().map(|e| e.event.time).collect();
    assert_eq!(log.events.len(), 2, "{:?}", kinds(&log));
    assert!(times.iter().all(|t| (t - 0.01).abs() < 1e-12));
    let v = &log.events[1].velocities;
    assert!(
        (v[0] - 1.0).abs() < 1e-12 && v[1].abs() < 1e-12 && (v[2] + 1.0).abs() < 1e-12,
        "{v:?}"
    );
}

#[test]
fn equal_masses_stop_impacting() {
    // Paper Sect. 4.3: R_m = 1 with symmetric parameters → no impacts at steady state. Start
    // from a perturbed state that does impact, and check the impacts die out.
    let params = ChainParams {
        masses: vec![0.12; 3],
        ..ChainParams::default()
    };
    let initial = ChainState {
        positions: vec![0.0, 0.0, 0.0],
        velocities: vec![-1.0, 0.5, 1.5],
    };
    let t = params.period();
    let log = run(&params, &initial, 400.0 * t);
    let impacts: Vec<f64> = log
        .events
        .iter()
        .filter(|e| e.event.kind == EventKind::Impact)
        .map(|e| e.event.time)
        .collect();
    assert!(impacts.len() > 5, "the transient should impact");
    let last = impacts.last().unwrap();
    println!("{} impacts, the last at period {:.1}", impacts.len(), last / t);
    assert!(
        *last < 300.0 * t,
        "impacts continue at steady state (last at {last})"
    );
}
