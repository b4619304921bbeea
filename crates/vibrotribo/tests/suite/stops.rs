//! Rigid stops against truth from outside the engine: the closed-form (1,1) orbits of the
//! harmonically forced impact oscillator (Shaw & Holmes 1983), their Floquet multipliers and
//! period doubling; energy conservation of elastic impacts against a stop and the closed-form
//! time between them; sticking to a stop moving with the base with its closed-form release
//! time; no mass ever beyond a stop.

use crate::common::impact_oscillator;

use impact_oscillator::{ImpactOscillator, OneOne};
use vibrotribo::orbits::{
    BifurcationKind, BranchEnd, ContinuationOptions, ShootingOptions, continue_orbit, find_periodic_orbit,
};
use vibrotribo::{
    ChainParams, ChainState, ContactStatus, EventKind, EventLog, Excitation, Frequency, SimOptions,
    Simulator, Stop, StopFrame, Stops,
};

const M: f64 = 0.05;
const K: f64 = 120.0;
/// Damping ratio 2 %.
const ZETA: f64 = 0.02;
const A: f64 = 0.01;
const R: f64 = 0.8;

fn wn() -> f64 {
    (K / M).sqrt()
}

fn damping() -> f64 {
    2.0 * ZETA * (M * K).sqrt()
}

/// One mass on a spring and dashpot to the base, below an upper stop fixed in space at `gap`.
fn single(omega_ratio: f64, gap: f64) -> ChainParams {
    ChainParams {
        masses: vec![M],
        stiffness: vec![K],
        damping: vec![damping()],
        gaps: vec![],
        restitution: 0.5,
        excitation: Excitation {
            amplitude: A,
            frequency: Frequency::OmegaRatio(omega_ratio),
        },
        stops: Stops {
            upper: Some(Stop {
                gap,
                restitution: R,
                frame: StopFrame::Fixed,
            }),
            lower: None,
        },
        forces: Vec::new(),
    }
}

fn textbook(omega_ratio: f64, gap: f64) -> ImpactOscillator {
    textbook_in(omega_ratio, gap, false)
}

fn textbook_in(omega_ratio: f64, gap: f64, moving: bool) -> ImpactOscillator {
    ImpactOscillator {
        m: M,
        k: K,
        c: damping(),
        amplitude: A,
        omega: omega_ratio * wn(),
        gap,
        r: R,
        moving,
    }
}

/// The closed-form (1,1) orbit, found from a scan of impact phases.
fn closed_form(io: &ImpactOscillator, speed_guess: f64) -> OneOne {
    for j in 0..64 {
        if let Some(o) = io.one_one((io.period() * f64::from(j) / 64.0, speed_guess)) {
            return o;
        }
    }
    panic!("no (1,1) orbit of {io:?}");
}

/// The state of the closed-form orbit at the section t = T (≡ 0).
fn section_state(io: &ImpactOscillator, o: &OneOne) -> ChainState {
    let (p, pd) = io.xp(o.t0);
    let (h0, h1) = (io.gap - p, -io.r * o.speed - pd);
    let f = io.propagator(io.period() - o.t0);
    let (xp, vp) = io.xp(io.period());
    // With a moving stop the closed form is relative to the base, which is at y = 0,
    // y' = Aω at the section.
    let base_speed = if io.moving { io.amplitude * io.omega } else { 0.0 };
    ChainState {
        positions: vec![xp + f[0][0] * h0 + f[0][1] * h1],
        velocities: vec![vp + f[1][0] * h0 + f[1][1] * h1 + base_speed],
    }
}

/// The closed-form orbit never reaches the stop between its impacts.
fn admissible(io: &ImpactOscillator, o: &OneOne) -> bool {
    let (p, pd) = io.xp(o.t0);
    let (h0, h1) = (io.gap - p, -io.r * o.speed - pd);
    (1..1000).all(|i| {
        let tau = io.period() * f64::from(i) / 1000.0;
        let f = io.propagator(tau);
        io.xp(o.t0 + tau).0 + f[0][0] * h0 + f[0][1] * h1 < io.gap
    })
}

fn sorted(mut m: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    m.sort_by(|a, b| (b.0.hypot(b.1), b.1).partial_cmp(&(a.0.hypot(a.1), a.1)).unwrap());
    m
}

/// Shooting on the engine reproduces the closed-form orbit: impact phase, impact speed, both
/// multipliers (a stable complex pair at Ω = 2.5, an unstable real pair at Ω = 2.8), and
/// det = r² e^{−2ζω_nT}.
#[test]
fn shooting_reproduces_the_closed_form_one_one_orbits() {
    for (omega, stable) in [(2.5, true), (2.8, false), (1.6, true)] {
        let io = textbook(omega, 0.0);
        let o = closed_form(&io, 0.2);
        assert!(
            admissible(&io, &o),
            "Ω = {omega}: the textbook orbit is not admissible"
        );
        let params = single(omega, 0.0);
        let mut guess = section_state(&io, &o);
        guess.velocities[0] *= 1.01;
        guess.positions[0] -= 1e-4;
        let orbit = find_periodic_orbit(&params, &guess, 1, &ShootingOptions::default()).unwrap();
        let impacts: Vec<_> = orbit
            .events
            .iter()
            .filter(|e| e.kind == EventKind::Impact)
            .collect();
        assert_eq!(impacts.len(), 1, "Ω = {omega}: {:?}", orbit.events);
        let t = impacts[0].time.rem_euclid(io.period());
        let speed = impacts[0].velocity_before;
        println!(
            "Ω = {omega}: impact phase {:.12} (closed form {:.12}), speed {:.12} ({:.12}) m/s",
            t / io.period(),
            o.t0 / io.period(),
            speed,
            o.speed
        );
        assert!(
            (t - o.t0).abs() < 1e-10 * io.period(),
            "Ω = {omega}: impact time {t} vs {}",
            o.t0
        );
        assert!(
            (speed - o.speed).abs() < 1e-9 * o.speed,
            "Ω = {omega}: speed {speed} vs {}",
            o.speed
        );
        let got = sorted(orbit.multipliers.iter().map(|c| (c.re, c.im)).collect());
        let want = sorted(o.multipliers.to_vec());
        println!("  multipliers {got:?}, closed form {want:?}");
        for (g, w) in got.iter().zip(&want) {
            assert!(
                (g.0 - w.0).abs() < 1e-8 && (g.1.abs() - w.1.abs()).abs() < 1e-8,
                "Ω = {omega}: multipliers {got:?} vs {want:?}"
            );
        }
        let det = got[0].0 * got[1].0 - got[0].1 * got[1].1;
        let want_det = R * R * (-2.0 * ZETA * wn() * io.period()).exp();
        assert!(
            (det - want_det).abs() < 1e-9,
            "det {det} vs r² e^(−2ζω_nT) = {want_det}"
        );
        assert_eq!(orbit.stable, stable, "Ω = {omega}");
    }
}

/// The same with the stop moving with the base (relative coordinates): impact phase, speed
/// and multipliers of the (1,1) orbit.
#[test]
fn shooting_reproduces_the_one_one_orbits_against_a_moving_stop() {
    let mut found = 0;
    for omega in [0.8, 1.6, 2.5, 2.8] {
        let io = textbook_in(omega, 0.002, true);
        let Some(o) = (0..64).find_map(|j| io.one_one((io.period() * f64::from(j) / 64.0, 0.2))) else {
            continue;
        };
        if !admissible(&io, &o) {
            continue;
        }
        found += 1;
        let mut params = single(omega, 0.002);
        params.stops.upper.as_mut().unwrap().frame = StopFrame::Base;
        let mut guess = section_state(&io, &o);
        guess.velocities[0] *= 1.01;
        let orbit = find_periodic_orbit(&params, &guess, 1, &ShootingOptions::default()).unwrap();
        let impacts: Vec<_> = orbit
            .events
            .iter()
            .filter(|e| e.kind == EventKind::Impact)
            .collect();
        assert_eq!(impacts.len(), 1, "Ω = {omega}: {:?}", orbit.events);
        let t = impacts[0].time.rem_euclid(io.period());
        let speed = impacts[0].velocity_before;
        let got = sorted(orbit.multipliers.iter().map(|c| (c.re, c.im)).collect());
        let want = sorted(o.multipliers.to_vec());
        println!(
            "moving stop, Ω = {omega}: phase {:.12} ({:.12}), speed {speed:.12} ({:.12}), multipliers \
             {got:?} ({want:?})",
            t / io.period(),
            o.t0 / io.period(),
            o.speed
        );
        assert!(
            (t - o.t0).abs() < 1e-10 * io.period(),
            "Ω = {omega}: impact time {t} vs {}",
            o.t0
        );
        assert!(
            (speed - o.speed).abs() < 1e-9 * o.speed,
            "Ω = {omega}: speed {speed} vs {}",
            o.speed
        );
        for (g, w) in got.iter().zip(&want) {
            assert!(
                (g.0 - w.0).abs() < 1e-8 && (g.1.abs() - w.1.abs()).abs() < 1e-8,
                "Ω = {omega}: multipliers {got:?} vs {want:?}"
            );
        }
    }
    assert!(found >= 2, "only {found} admissible textbook orbits");
}

/// The closed-form period-doubling point: where a multiplier of the (1,1) orbit is −1
/// (bisection in Ω on the closed form).
fn closed_form_doubling(lo: f64, hi: f64) -> f64 {
    let f = |w: f64| {
        let io = textbook(w, 0.0);
        let o = closed_form(&io, 0.2);
        io.doubling_function(&o)
    };
    let (mut lo, mut hi) = (lo, hi);
    let f_lo = f(lo);
    assert!(
        f_lo * f(hi) < 0.0,
        "no sign change of (1 + λ₁)(1 + λ₂) in [{lo}, {hi}]"
    );
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if f(mid) * f_lo > 0.0 { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

/// Continuation in Ω locates the period doubling of the (1,1) orbit where the closed form has
/// a multiplier −1, and a direct simulation just past it settles on a period-2 orbit.
#[test]
fn continuation_finds_the_closed_form_period_doubling() {
    let pd = closed_form_doubling(2.6, 2.7);
    let io = textbook(2.6, 0.0);
    let o = closed_form(&io, 0.2);
    let start = section_state(&io, &o);
    let options = ContinuationOptions {
        doubling_depth: 0,
        ..ContinuationOptions::default()
    };
    let result = continue_orbit("omega_ratio", |w| single(w, 0.0), 2.6, 2.7, &start, 1, &options).unwrap();
    let main = &result.branches[0];
    let found: Vec<_> = main
        .bifurcations
        .iter()
        .filter(|b| b.kind == BifurcationKind::PeriodDoubling)
        .collect();
    println!(
        "closed-form period doubling at Ω = {pd:.12}; continuation: {:?}",
        found
            .iter()
            .map(|b| (b.parameter, b.precision))
            .collect::<Vec<_>>()
    );
    assert_eq!(found.len(), 1, "bifurcations: {:?}", main.bifurcations);
    assert!(
        (found[0].parameter - pd).abs() < 1e-7,
        "PD at {} vs {pd}",
        found[0].parameter
    );

    // Past the doubling: the stroboscopic samples alternate between two states.
    let beyond = pd + 0.01;
    let params = single(beyond, 0.0);
    let io = textbook(beyond, 0.0);
    let o = closed_form(&io, 0.2);
    let mut state = section_state(&io, &o);
    state.velocities[0] *= 1.001;
    let mut sim = Simulator::new(&params, &state, SimOptions::default()).unwrap();
    let t = params.period();
    sim.run_until(600.0 * t, &mut ()).unwrap();
    let mut x = Vec::new();
    for p in 1..=6 {
        sim.run_until((600.0 + f64::from(p)) * t, &mut ()).unwrap();
        x.push(sim.state().positions[0]);
    }
    println!("sections past the doubling (Ω = {beyond:.6}): {x:?}");
    for p in 2..6 {
        assert!((x[p] - x[p - 2]).abs() < 1e-9, "not period 2: {x:?}");
    }
    assert!((x[1] - x[0]).abs() > 1e-5, "still period 1: {x:?}");
}

/// Elastic impacts (r = 1) of an undamped, unforced mass against a fixed stop conserve
/// ½mv² + ½kx², and the time between them is the closed form (π + 2 asin(g/a))/ω_n with
/// a = v₀/ω_n the free amplitude.
#[test]
fn elastic_impacts_against_a_stop_conserve_energy() {
    let (g, v0) = (0.004, 0.5);
    for side in [true, false] {
        let stop = Some(Stop {
            gap: g,
            restitution: 1.0,
            frame: StopFrame::Fixed,
        });
        let params = ChainParams {
            damping: vec![0.0],
            excitation: Excitation {
                amplitude: 0.0,
                frequency: Frequency::OmegaRatio(0.7),
            },
            stops: if side {
                Stops {
                    upper: stop,
                    lower: None,
                }
            } else {
                Stops {
                    upper: None,
                    lower: stop,
                }
            },
            ..single(0.7, g)
        };
        let state = ChainState {
            positions: vec![0.0],
            velocities: vec![if side { v0 } else { -v0 }],
        };
        let mut sim = Simulator::new(&params, &state, SimOptions::default()).unwrap();
        let mut log = EventLog::default();
        sim.run_until(2.0, &mut log).unwrap();
        let times: Vec<f64> = log.events.iter().map(|e| e.event.time).collect();
        assert!(times.len() > 20, "{} impacts", times.len());
        assert!(log.events.iter().all(|e| e.event.kind == EventKind::Impact));
        let a = v0 / wn();
        let spacing = (std::f64::consts::PI + 2.0 * (g / a).asin()) / wn();
        for w in times.windows(2) {
            assert!(
                (w[1] - w[0] - spacing).abs() < 1e-12,
                "spacing {} vs {spacing}",
                w[1] - w[0]
            );
        }
        let s = sim.state();
        let energy = 0.5 * M * s.velocities[0].powi(2) + 0.5 * K * s.positions[0].powi(2);
        let e0 = 0.5 * M * v0 * v0;
        assert!((energy - e0).abs() < 1e-12 * e0, "energy {energy} vs {e0}");
    }
}

/// A mass stuck to a lower stop that moves with the base, with the spring stretched by the
/// gap g, feels the stop's force λ = −mω²A sin ωt − kg; it releases where λ falls to zero,
/// at ωt = 2π − asin(kg/(mω²A)).
#[test]
fn sticking_to_a_moving_stop_releases_at_the_closed_form_time() {
    let (g, omega_ratio) = (0.002, 1.5);
    let params = ChainParams {
        stops: Stops {
            upper: None,
            lower: Some(Stop {
                gap: g,
                restitution: 0.5,
                frame: StopFrame::Base,
            }),
        },
        ..single(omega_ratio, g)
    };
    let w = params.omega();
    let t0 = 1.5 * std::f64::consts::PI / w;
    let y = A * (w * t0).sin();
    let yd = A * w * (w * t0).cos();
    let state = ChainState {
        positions: vec![-g + y],
        velocities: vec![yd],
    };
    assert!(M * w * w * A > K * g, "the stop must press at t0");
    let mut sim = Simulator::new_at(&params, t0, &state, SimOptions::default()).unwrap();
    assert_eq!(
        sim.contact_status()[0],
        ContactStatus::Stuck,
        "stuck to the stop at the start"
    );
    let mut log = EventLog::default();
    sim.run_until(t0 + 0.5 * params.period(), &mut log).unwrap();
    let kinds: Vec<_> = log
        .events
        .iter()
        .map(|e| (e.event.kind, e.event.contact))
        .collect();
    assert_eq!(kinds.first(), Some(&(EventKind::Release, 0)), "{kinds:?}");
    let release = log
        .events
        .iter()
        .find(|e| e.event.kind == EventKind::Release)
        .expect("a release")
        .event
        .time;
    let want = (2.0 * std::f64::consts::PI - (K * g / (M * w * w * A)).asin()) / w;
    println!("release at {release:.15} s, closed form {want:.15} s");
    assert!(
        (release - want).abs() < 1e-12 * params.period(),
        "release {release} vs {want}"
    );
}

/// Chatter against a stop fixed at the mass's static position, which the base's motion
/// presses the mass against for half of each period: sticks, releases, impacts and chatter
/// jumps at the stop; the mass is never beyond it.
#[test]
fn chatter_against_a_stop_never_penetrates() {
    let params = ChainParams {
        stops: Stops {
            upper: Some(Stop {
                gap: 0.0,
                restitution: 0.5,
                frame: StopFrame::Fixed,
            }),
            lower: None,
        },
        ..single(0.5, 0.0)
    };
    let mut sim = Simulator::new(&params, &ChainState::at_rest(1), SimOptions::default()).unwrap();
    let mut log = EventLog::default();
    sim.run_until(40.0 * params.period(), &mut log).unwrap();
    let count = |k: EventKind| log.events.iter().filter(|e| e.event.kind == k).count();
    println!(
        "{} impacts, {} chatter jumps, {} sticks, {} releases",
        count(EventKind::Impact),
        count(EventKind::Chatter),
        count(EventKind::Stick),
        count(EventKind::Release)
    );
    assert!(count(EventKind::Chatter) > 0 && count(EventKind::Stick) > 0 && count(EventKind::Release) > 0);
    for e in &log.events {
        assert_eq!(
            e.event.contact, 1,
            "the only contact is the upper stop (contact 1 for N = 1)"
        );
        let gap = -e.positions[0];
        assert!(gap > -1e-12, "beyond the stop by {gap:e} at {}", e.event.time);
    }
}

/// Continuation of the orbit that never reaches the stop, towards lower Ω, meets the stop where
/// the steady amplitude `A √(k² + c²ω²) / √((k − mω²)² + c²ω²)` equals the gap: a grazing of
/// the stop's contact, located where the closed form puts it.
#[test]
fn continuation_meets_the_stop_at_the_closed_form_grazing() {
    let gap = 0.002;
    let steady = |w: f64| {
        let (c, om) = (damping(), w * wn());
        A * (K * K + c * c * om * om).sqrt() / ((K - M * om * om).powi(2) + c * c * om * om).sqrt()
    };
    let (mut lo, mut hi) = (2.3, 3.0);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if steady(mid) > gap { lo = mid } else { hi = mid }
    }
    let grazing = 0.5 * (lo + hi);
    let io = textbook(3.0, gap);
    let (x, v) = io.xp(0.0);
    let start = ChainState {
        positions: vec![x],
        velocities: vec![v],
    };
    let options = ContinuationOptions {
        doubling_depth: 0,
        ..ContinuationOptions::default()
    };
    let result = continue_orbit("omega_ratio", |w| single(w, gap), 3.0, 2.3, &start, 1, &options).unwrap();
    let main = &result.branches[0];
    let located: Vec<f64> = main
        .bifurcations
        .iter()
        .filter(|b| matches!(b.kind, BifurcationKind::Grazing { contact: 1, .. }))
        .map(|b| b.parameter)
        .chain(match main.end {
            BranchEnd::Grazing {
                parameter,
                contact: 1,
                ..
            } => Some(parameter),
            _ => None,
        })
        .collect();
    println!(
        "closed-form grazing at Ω = {grazing:.12}; continuation: {located:?}, bifurcations {:?}, end {:?}",
        main.bifurcations
            .iter()
            .map(|b| (b.kind, b.parameter))
            .collect::<Vec<_>>(),
        main.end
    );
    assert!(!located.is_empty(), "no grazing of the stop found");
    assert!(
        (located[0] - grazing).abs() < 1e-6,
        "grazing at {} vs {grazing}",
        located[0]
    );
    // A branch that ends at the grazing stops just short of it: its last gap minimum is the
    // closed-form distance of the steady motion from the stop there.
    if let BranchEnd::Grazing {
        parameter, gap: left, ..
    } = main.end
    {
        let want = gap - steady(parameter);
        println!("gap minimum at the end {left:e} m, closed form {want:e} m");
        assert!(
            (left - want).abs() < 1e-12,
            "gap minimum {left:e} vs closed form {want:e}"
        );
    }
}

/// Two masses between two fixed stops, all impacts elastic (r = μ = 1), no damping and no
/// forcing: ½Σm v² + ½Σk x² is conserved through hundreds of impacts between the masses and
/// against both stops, and no mass ever passes a stop or its neighbour.
#[test]
fn elastic_chain_between_two_stops_conserves_energy() {
    let stop = |gap| {
        Some(Stop {
            gap,
            restitution: 1.0,
            frame: StopFrame::Fixed,
        })
    };
    let params = ChainParams {
        masses: vec![0.05, 0.08],
        stiffness: vec![120.0, 90.0],
        damping: vec![0.0, 0.0],
        gaps: vec![0.004],
        restitution: 1.0,
        excitation: Excitation {
            amplitude: 0.0,
            frequency: Frequency::OmegaRatio(0.7),
        },
        stops: Stops {
            upper: stop(0.003),
            lower: stop(0.005),
        },
        forces: Vec::new(),
    };
    let state = ChainState {
        positions: vec![0.0, 0.0],
        velocities: vec![0.4, -0.3],
    };
    let energy = |x: &[f64], v: &[f64]| {
        (0..2)
            .map(|i| 0.5 * params.masses[i] * v[i] * v[i] + 0.5 * params.stiffness[i] * x[i] * x[i])
            .sum::<f64>()
    };
    let e0 = energy(&state.positions, &state.velocities);
    let mut sim = Simulator::new(&params, &state, SimOptions::default()).unwrap();
    let mut log = EventLog::default();
    sim.run_until(3.0, &mut log).unwrap();
    let at = |k: usize| log.events.iter().filter(|e| e.event.contact == k).count();
    println!(
        "impacts: masses {}, lower stop {}, upper stop {}",
        at(0),
        at(1),
        at(2)
    );
    assert!(
        at(0) > 20 && at(1) > 20 && at(2) > 20,
        "{} {} {}",
        at(0),
        at(1),
        at(2)
    );
    for e in &log.events {
        assert_eq!(e.event.kind, EventKind::Impact);
        let (x, v) = (&e.positions, &e.velocities);
        assert!(
            (energy(x, v) - e0).abs() < 1e-12 * e0,
            "energy {} vs {e0}",
            energy(x, v)
        );
        let tol = 1e-15;
        assert!(x[0] <= 0.003 + tol && x[1] >= -0.005 - tol && x[1] - x[0] <= 0.004 + tol);
    }
}
