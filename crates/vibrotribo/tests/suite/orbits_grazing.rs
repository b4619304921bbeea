//! Branches continued through grazing against truth from outside the continuation: the
//! closed-form impact oscillator (its impact-free orbit's grazing, its (1,1) orbit and that
//! orbit's period doubling, computed here from the closed-form flow and impact law), the
//! square-root law of the impact speed in the penetration, the one-dimensional square-root
//! map's own dynamics, and every point of branches on random chains re-simulated by the
//! engine: it returns to itself after its period and never closes a gap below zero.

use crate::common::impact_oscillator;

use impact_oscillator::ImpactOscillator;
use vibrotribo::orbits::{
    Bifurcation, BifurcationKind, Branch, BranchEnd, ContinuationOptions, CrossingKind, NordmarkScenario,
    ShootingOptions, continue_orbit, periodic_orbit_from_transient,
};
use vibrotribo::sensitivity::state_vector;
use vibrotribo::{
    ChainParams, ChainState, EventKind, EventLog, Excitation, Frequency, SimOptions, Simulator, Stop,
    StopFrame, Stops, UniformSampler,
};

/// The impact oscillator: 50 g on 120 N/m, c = 0.02 N s/m, base amplitude 10 mm, a stop fixed
/// 1 mm above the static position, r = 0.8.
const M: f64 = 0.05;
const K: f64 = 120.0;
const C: f64 = 0.02;
const A: f64 = 0.01;
const GAP: f64 = 0.001;
const R: f64 = 0.8;

fn wn() -> f64 {
    (K / M).sqrt()
}

fn oscillator(omega_ratio: f64, gap: f64) -> ChainParams {
    ChainParams {
        masses: vec![M],
        stiffness: vec![K],
        damping: vec![C],
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

fn textbook(omega_ratio: f64) -> ImpactOscillator {
    ImpactOscillator {
        m: M,
        k: K,
        c: C,
        amplitude: A,
        omega: omega_ratio * wn(),
        gap: GAP,
        r: R,
        moving: false,
    }
}

/// The closed-form Ω where the impact-free steady motion's amplitude
/// `A √(k² + c²ω²) / √((k − mω²)² + c²ω²)` equals the gap (bisection above resonance).
fn closed_form_grazing() -> f64 {
    let steady = |w: f64| {
        let om = w * wn();
        A * (K * K + C * C * om * om).sqrt() / ((K - M * om * om).powi(2) + C * C * om * om).sqrt()
    };
    let (mut lo, mut hi) = (2.0, 5.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if steady(mid) > GAP { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

/// The closed-form (1,1) orbit at Ω, continued in Ω from the one nearest `guess` (t₀, v).
fn closed_form_speed(omega_ratio: f64, guess: (f64, f64)) -> Option<(f64, f64)> {
    let io = textbook(omega_ratio);
    io.one_one(guess).map(|o| (o.t0, o.speed))
}

/// The first bifurcation of `kind` on `branch`.
fn first(branch: &Branch, f: impl Fn(&BifurcationKind) -> bool) -> Option<&Bifurcation> {
    branch.bifurcations.iter().find(|b| f(&b.kind))
}

/// `det(Φ − I)` from the multipliers.
fn fold_test(multipliers: &[vibrotribo::nalgebra::Complex<f64>]) -> f64 {
    let one = vibrotribo::nalgebra::Complex::new(1.0, 0.0);
    multipliers.iter().fold(one, |p, l| p * (l - one)).re
}

/// The impact-free orbit of the impact oscillator followed down in Ω: it grazes the stop where
/// the closed form puts it, the branch goes on through the grazing onto the (1,1) orbit (the
/// same side: a persistence, with `det(Φ − I)` of one sign on both sides as Feigin's rule
/// says), whose impact speed is the closed form's and vanishes linearly at the grazing (the
/// fixed point of the square-root map), and whose period doubling is where the closed-form
/// (1,1) orbit has a multiplier −1.
#[test]
fn the_impact_oscillator_grazing_is_located_and_crossed() {
    let grazing = closed_form_grazing();
    let io = textbook(3.6);
    let (x, v) = io.xp(0.0);
    let start = ChainState {
        positions: vec![x],
        velocities: vec![v],
    };
    let options = ContinuationOptions {
        doubling_depth: 0,
        ..ContinuationOptions::default()
    };
    let result = continue_orbit(
        "omega_ratio",
        |w| oscillator(w, GAP),
        3.6,
        2.4,
        &start,
        1,
        &options,
    )
    .unwrap();
    let main = &result.branches[0];
    println!(
        "closed-form grazing at Ω = {grazing:.12}; bifurcations {:?}; end {:?}",
        main.bifurcations
            .iter()
            .map(|b| (b.kind, b.parameter, b.crossing))
            .collect::<Vec<_>>(),
        main.end
    );
    let g = first(main, |k| {
        matches!(
            k,
            BifurcationKind::Grazing {
                contact: 1,
                appears: true
            }
        )
    })
    .expect("the grazing of the stop");
    assert!(
        (g.parameter - grazing).abs() < 1e-7,
        "grazing at {} vs {grazing}",
        g.parameter
    );
    let crossing = g.crossing.expect("crossed");
    assert_eq!(crossing.kind, CrossingKind::Persistence);
    let after = g.after.as_ref().expect("the orbit beyond");
    assert!(
        fold_test(&g.point.multipliers) * fold_test(&after.multipliers) > 0.0,
        "Feigin: det(Φ − I) {} before, {} after",
        fold_test(&g.point.multipliers),
        fold_test(&after.multipliers)
    );
    // The impact-free orbit's multipliers are the free oscillator's e^{(−ζ ± i√(1−ζ²))ω_nT}:
    // a complex pair, for which the one-dimensional map says nothing.
    assert_eq!(crossing.nordmark, Some(NordmarkScenario::Undetermined));

    // The first orbit beyond strikes the stop once per period, slowly.
    assert_eq!(after.impacts_per_period, vec![0.0, 1.0]);
    assert!(after.parameter < grazing);
}

/// The same branch followed on down towards Ω = 2.4 through the grazing (where the orbit's
/// multiplier grows like the inverse of its impact speed): the impact speeds against the
/// closed form, their linear vanishing at the grazing, and the (1,1) orbit's period doubling,
/// where the branch ends (no doubled branch asked for).
#[test]
fn the_impact_oscillator_branch_goes_on_to_its_period_doubling() {
    let grazing = closed_form_grazing();
    let io = textbook(3.6);
    let (x, v) = io.xp(0.0);
    let start = ChainState {
        positions: vec![x],
        velocities: vec![v],
    };
    let options = ContinuationOptions {
        doubling_depth: 0,
        ..ContinuationOptions::default()
    };
    let result = continue_orbit(
        "omega_ratio",
        |w| oscillator(w, GAP),
        3.6,
        2.4,
        &start,
        1,
        &options,
    )
    .unwrap();
    let main = &result.branches[0];
    println!(
        "closed-form grazing at Ω = {grazing:.12}; bifurcations {:?}; end {:?}",
        main.bifurcations
            .iter()
            .map(|b| (b.kind, b.parameter, b.crossing))
            .collect::<Vec<_>>(),
        main.end
    );
    let pd_at = first(main, |k| *k == BifurcationKind::PeriodDoubling).map(|b| b.parameter);
    assert!(
        matches!(main.end, BranchEnd::CascadeDepth { parameter } if Some(parameter) == pd_at),
        "{:?}",
        main.end
    );
    let g = first(main, |k| {
        matches!(
            k,
            BifurcationKind::Grazing {
                contact: 1,
                appears: true
            }
        )
    })
    .expect("the grazing of the stop");
    assert!(
        (g.parameter - grazing).abs() < 1e-7,
        "grazing at {} vs {grazing}",
        g.parameter
    );
    let crossing = g.crossing.expect("crossed");
    assert_eq!(crossing.kind, CrossingKind::Persistence);
    let after = g.after.as_ref().expect("the orbit beyond");
    assert!(
        fold_test(&g.point.multipliers) * fold_test(&after.multipliers) > 0.0,
        "Feigin: det(Φ − I) {} before, {} after",
        fold_test(&g.point.multipliers),
        fold_test(&after.multipliers)
    );
    // The impact-free orbit's multipliers are the free oscillator's e^{(−ζ ± i√(1−ζ²))ω_nT}:
    // a complex pair, for which the one-dimensional map says nothing.
    assert_eq!(crossing.nordmark, Some(NordmarkScenario::Undetermined));

    // Beyond the grazing: one impact per period at the closed-form speed.
    let mut guess = (0.0, 0.0);
    let mut near = Vec::new();
    let mut compared = 0;
    for p in main
        .points
        .iter()
        .filter(|p| p.parameter < grazing - 1e-9 && p.parameter > 2.6)
    {
        assert_eq!(p.impacts_per_period, vec![0.0, 1.0], "at Ω = {}", p.parameter);
        let speed = p.min_closing_speed.expect("an impact").1;
        if grazing - p.parameter < 0.02 {
            near.push(((grazing - p.parameter).ln(), speed.ln()));
        }
        // The closed form's own Newton iteration resolves speeds above 1 mm/s.
        if speed < 1e-3 {
            continue;
        }
        if guess.1 == 0.0 {
            guess = (0.0, speed);
            let io = textbook(p.parameter);
            for j in 0..64 {
                if let Some(o) = io.one_one((io.period() * f64::from(j) / 64.0, speed)) {
                    guess = (o.t0, o.speed);
                    break;
                }
            }
        }
        let (t0, want) = closed_form_speed(p.parameter, guess).expect("the closed-form (1,1) orbit");
        guess = (t0, want);
        assert!(
            (speed - want).abs() <= 1e-7 * want.max(1e-3),
            "Ω = {}: impact speed {speed} vs closed form {want}",
            p.parameter
        );
        compared += 1;
    }
    assert!(compared >= 5, "{compared} points compared with the closed form");
    // The fixed point of the square-root map: speed ∝ (Ω_g − Ω)¹.
    assert!(near.len() >= 3, "{} points near the grazing", near.len());
    let slope = fit_slope(&near);
    println!("impact speed ∝ (Ω_g − Ω)^{slope:.4} over {} points", near.len());
    assert!((slope - 1.0).abs() < 0.05, "exponent {slope}");

    // The period doubling of the (1,1) orbit.
    let pd = first(main, |k| *k == BifurcationKind::PeriodDoubling).expect("a period doubling");
    let speed = pd.point.min_closing_speed.expect("an impact").1;
    let f = |w: f64| {
        let io = textbook(w);
        let o = (0..64)
            .find_map(|j| io.one_one((io.period() * f64::from(j) / 64.0, speed)))
            .expect("the closed-form (1,1) orbit");
        io.doubling_function(&o)
    };
    let (mut lo, mut hi) = (pd.parameter - 1e-3, pd.parameter + 1e-3);
    assert!(
        f(lo) * f(hi) < 0.0,
        "no closed-form doubling near {}",
        pd.parameter
    );
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if f(mid) * f(lo) > 0.0 { lo = mid } else { hi = mid }
    }
    let want = 0.5 * (lo + hi);
    println!("period doubling at {} vs closed form {want}", pd.parameter);
    assert!((pd.parameter - want).abs() < 1e-7);
}

/// Least-squares slope of `(x, y)`.
fn fit_slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (sx, sy) = points.iter().fold((0.0, 0.0), |(a, b), p| (a + p.0, b + p.1));
    let (mx, my) = (sx / n, sy / n);
    let (num, den) = points.iter().fold((0.0, 0.0), |(a, b), p| {
        (a + (p.0 - mx) * (p.1 - my), b + (p.0 - mx).powi(2))
    });
    num / den
}

/// The square-root singularity itself: from the grazing orbit, a stop lowered by η is struck
/// at the speed `√(2aη)` of the free motion's turning point (a = Xω² its deceleration there),
/// so the speed grows like η^½.
#[test]
fn near_grazing_the_impact_speed_grows_like_the_square_root_of_the_penetration() {
    let grazing = closed_form_grazing();
    let io = textbook(grazing);
    let (x, v) = io.xp(0.0);
    let start = ChainState {
        positions: vec![x],
        velocities: vec![v],
    };
    let amplitude = io.xp(0.0).0.hypot(io.xp(0.0).1 / io.omega);
    let decel = amplitude * io.omega * io.omega;
    let mut points = Vec::new();
    for eta in [1e-10, 1e-9, 1e-8, 1e-7] {
        let params = oscillator(grazing, GAP - eta);
        let mut sim = Simulator::new(&params, &start, SimOptions::default()).unwrap();
        let mut log = EventLog::default();
        sim.run_until(params.period(), &mut log).unwrap();
        let e = log
            .events
            .iter()
            .find(|e| e.event.kind == EventKind::Impact)
            .expect("an impact");
        let speed = e.event.velocity_before;
        let want = (2.0 * decel * eta).sqrt();
        println!("η = {eta:e} m: impact speed {speed:e} m/s, √(2aη) = {want:e}");
        assert!((speed - want).abs() < 1e-3 * want, "{speed} vs {want}");
        points.push((eta.ln(), speed.ln()));
    }
    let slope = fit_slope(&points);
    assert!((slope - 0.5).abs() < 1e-3, "exponent {slope}");
}

/// The scenarios [`NordmarkScenario::of`] assigns agree with the dynamics of the
/// one-dimensional square-root map `x ↦ μ + λx (x ≤ 0), μ − √x (x > 0)` just past grazing:
/// period 2 for λ < 0, period adding (periods growing as μ → 0, no chaos) for small λ > 0,
/// chaos for λ near 1, and both periodic windows and chaos between.
#[test]
fn the_nordmark_scenarios_are_those_of_the_square_root_map() {
    use vibrotribo::nalgebra::Complex;
    let period = |lambda: f64, mu: f64| -> Option<usize> {
        let f = |x: f64| if x <= 0.0 { mu + lambda * x } else { mu - x.sqrt() };
        let mut x = -0.1 * mu;
        for _ in 0..20_000 {
            x = f(x);
        }
        let mut orbit = vec![x];
        for _ in 0..600 {
            x = f(x);
            orbit.push(x);
        }
        (1..200).find(|&p| (0..orbit.len() - p).all(|i| (orbit[i] - orbit[i + p]).abs() <= 1e-9 * mu))
    };
    let mus: Vec<f64> = (0..60)
        .map(|j| 1e-4 * 10f64.powf(-4.0 * f64::from(j) / 59.0))
        .collect();
    for lambda in [-0.6, -0.2, 0.1, 0.2, 0.4, 0.55, 0.75, 0.9] {
        let scenario = NordmarkScenario::of(&[Complex::new(lambda, 0.0), Complex::new(0.01, 0.0)]);
        let periods: Vec<Option<usize>> = mus.iter().map(|&mu| period(lambda, mu)).collect();
        let chaotic = periods.iter().filter(|p| p.is_none()).count();
        println!("λ = {lambda}: {scenario:?}, {chaotic} of {} aperiodic", mus.len());
        match scenario {
            NordmarkScenario::PeriodTwo => assert!(periods.iter().all(|p| *p == Some(2))),
            NordmarkScenario::PeriodAdding => {
                assert_eq!(chaotic, 0);
                let first = periods.first().unwrap().unwrap();
                let last = periods.last().unwrap().unwrap();
                assert!(last > first + 1, "periods {first} → {last}");
            }
            NordmarkScenario::PeriodAddingWithChaos => assert!(chaotic > 0 && chaotic < mus.len()),
            NordmarkScenario::Chaos => assert_eq!(chaotic, mus.len()),
            other => panic!("λ = {lambda}: {other:?}"),
        }
    }
    // A complex dominant pair, or one outside the unit circle: no prediction.
    let pair = [Complex::new(0.3, 0.4), Complex::new(0.3, -0.4)];
    assert_eq!(NordmarkScenario::of(&pair), NordmarkScenario::Undetermined);
    assert_eq!(
        NordmarkScenario::of(&[Complex::new(1.5, 0.0), Complex::new(0.2, 0.0)]),
        NordmarkScenario::Undetermined
    );
}

/// A small deterministic generator (xorshift).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}

/// A random chain of `n` masses, with stops or not.
fn random_chain(rng: &mut Rng, n: usize, stops: bool) -> ChainParams {
    let mut p = ChainParams {
        masses: (0..n).map(|_| rng.range(0.02, 0.1)).collect(),
        stiffness: (0..n).map(|_| rng.range(40.0, 200.0)).collect(),
        damping: (0..n).map(|_| rng.range(0.02, 0.1)).collect(),
        gaps: (0..n.saturating_sub(1))
            .map(|_| rng.range(0.005, 0.015))
            .collect(),
        restitution: rng.range(0.5, 0.9),
        excitation: Excitation {
            amplitude: rng.range(0.01, 0.05),
            frequency: Frequency::OmegaRatio(1.0),
        },
        stops: Stops::default(),
        forces: Vec::new(),
    };
    if stops {
        p.stops.upper = Some(Stop {
            gap: rng.range(0.002, 0.01),
            restitution: rng.range(0.5, 0.9),
            frame: StopFrame::Fixed,
        });
        if n > 1 {
            p.stops.lower = Some(Stop {
                gap: rng.range(0.01, 0.03),
                restitution: rng.range(0.5, 0.9),
                frame: StopFrame::Base,
            });
        }
    }
    p
}

/// The gaps of `params` at the state `(x, v)` at time `t`: between masses, then the stops.
fn gaps(params: &ChainParams, x: &[f64], t: f64) -> Vec<f64> {
    let n = x.len();
    let mut out: Vec<f64> = (0..n - 1).map(|k| params.gaps[k] - (x[k + 1] - x[k])).collect();
    let y = params.excitation.amplitude * (params.omega() * t).sin();
    if let Some(s) = &params.stops.upper {
        let base = if s.frame == StopFrame::Base { y } else { 0.0 };
        out.push(s.gap - (x[0] - base));
    }
    if let Some(s) = &params.stops.lower {
        let base = if s.frame == StopFrame::Base { y } else { 0.0 };
        out.push(s.gap - (base - x[n - 1]));
    }
    out
}

/// Every point of every branch on random chains of one to four masses, with and without
/// stops: the engine run from its state for its period returns to it (to 1e-9 of the length
/// and speed units), and no gap is negative anywhere on the way.
#[test]
fn every_point_of_a_branch_is_a_true_orbit() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut checked = 0;
    let mut crossings = 0;
    for n in 1..=4 {
        for stops in [false, true] {
            if n == 1 && !stops {
                continue; // a free linear oscillator has no events
            }
            let mut done = false;
            for _attempt in 0..6 {
                let chain = random_chain(&mut rng, n, stops);
                let omega = rng.range(0.5, 1.5);
                let family = |w: f64| {
                    let mut p = chain.clone();
                    p.excitation.frequency = Frequency::OmegaRatio(w);
                    p
                };
                let Ok(start) = periodic_orbit_from_transient(
                    &family(omega),
                    &ChainState::at_rest(n),
                    200,
                    None,
                    &ShootingOptions::default(),
                ) else {
                    continue;
                };
                if start.period > 4 {
                    continue;
                }
                let options = ContinuationOptions {
                    max_points: 60,
                    max_branches: 3,
                    doubling_depth: 1,
                    ..ContinuationOptions::default()
                };
                let to = omega + if rng.next() < 0.5 { -0.2 } else { 0.2 };
                let Ok(result) = continue_orbit(
                    "omega_ratio",
                    family,
                    omega,
                    to,
                    &start.state,
                    start.period,
                    &options,
                ) else {
                    continue;
                };
                for b in &result.branches {
                    crossings += b.bifurcations.iter().filter(|f| f.crossing.is_some()).count();
                    for p in &b.points {
                        check_orbit(&family(p.parameter), &p.state, b.period);
                        checked += 1;
                    }
                }
                println!(
                    "N = {n}, stops {stops}: Ω {omega:.3} → {to:.3}, branches {:?}",
                    result
                        .branches
                        .iter()
                        .map(|b| (b.period, b.points.len(), b.bifurcations.len(), &b.end))
                        .collect::<Vec<_>>()
                );
                done = true;
                break;
            }
            assert!(
                done,
                "no periodic chain of {n} masses (stops {stops}) in six draws"
            );
        }
    }
    println!("{checked} points checked, {crossings} sequence changes crossed");
    assert!(checked > 100);
}

/// The orbit through `state` returns to it after `period` excitation periods, and no gap is
/// negative on the way (sampled 4000 times per period, and at every event).
pub(crate) fn check_orbit(params: &ChainParams, state: &ChainState, period: u32) {
    check_orbit_to(params, state, period, 1e-9);
}

/// [`check_orbit`] for a branch point, to the bound a plain run from it can meet: 1e-9 of
/// the units, and more for an unstable orbit, whose state the corrector converges to 1e-11
/// on its own section and whose run from it amplifies what is left by its largest
/// multiplier (up to ~1e5 next to a grazing): 1e-9 + 1e-10·|λ|max.
pub(crate) fn check_branch_point(params: &ChainParams, p: &vibrotribo::orbits::BranchPoint, period: u32) {
    check_orbit_to(params, &p.state, period, 1e-9 + 1e-10 * p.spectral_radius());
}

/// [`check_orbit`], returning to `state` within `tolerance` of the length and speed units.
fn check_orbit_to(params: &ChainParams, state: &ChainState, period: u32, tolerance: f64) {
    let n = params.len();
    let duration = f64::from(period) * params.period();
    let mut sim = Simulator::new(params, state, SimOptions::default()).unwrap();
    let mut samples = UniformSampler::new(n, 0.0, params.period() / 4000.0);
    sim.run_until(duration, &mut samples).unwrap();
    let (z0, z1) = (state_vector(state), state_vector(&sim.state()));
    let length: f64 = params.gaps.iter().sum::<f64>()
        + params.excitation.amplitude
        + params.stops.upper.as_ref().map_or(0.0, |s| s.gap)
        + params.stops.lower.as_ref().map_or(0.0, |s| s.gap);
    let speed = length * params.omega();
    for i in 0..2 * n {
        let unit = if i < n { length } else { speed };
        assert!(
            (z1[i] - z0[i]).abs() <= tolerance * unit,
            "not periodic: component {i} {} → {} (unit {unit})",
            z0[i],
            z1[i]
        );
    }
    for (j, t) in samples.times.iter().enumerate() {
        for g in gaps(params, &samples.positions[j * n..(j + 1) * n], *t) {
            assert!(g >= -1e-12, "gap {g:e} m at t = {t}");
        }
    }
}

/// The stroboscopic period (1, 2, 4, … 64) the impact oscillator settles to at Ω from `state`
/// after a long transient, by direct simulation; `None` if none repeats to 1e-9 m.
fn brute_force_period(omega_ratio: f64, state: &ChainState) -> Option<usize> {
    let params = oscillator(omega_ratio, GAP);
    let mut sim = Simulator::new(&params, state, SimOptions::default()).unwrap();
    let t = params.period();
    sim.run_until(6000.0 * t, &mut ()).unwrap();
    let mut x = Vec::new();
    for k in 1..=256 {
        sim.run_until((6000.0 + f64::from(k)) * t, &mut ()).unwrap();
        x.push(sim.state().positions[0]);
    }
    [1, 2, 4, 8, 16, 32, 64]
        .into_iter()
        .find(|&p| (0..x.len() - p).all(|i| (x[i] - x[i + p]).abs() < 1e-9))
}

/// The impact oscillator's cascade followed from its impact-free orbit through the grazing:
/// period 1 → 2 → 4 → 8 → 16, each doubled branch switched onto and followed. Every located
/// doubling is where the brute-force period (direct simulation from the branch's orbit, after a
/// long transient) doubles: on the side before it the period is that of the branch, on the
/// side after it twice that. The Feigenbaum ratios of the located points shrink the intervals
/// geometrically (they approach 4.669 only asymptotically).
#[test]
fn the_impact_oscillators_cascade_is_followed_and_each_doubling_is_where_the_brute_force_period_doubles() {
    let io = textbook(3.6);
    let (x, v) = io.xp(0.0);
    let start = ChainState {
        positions: vec![x],
        velocities: vec![v],
    };
    let options = ContinuationOptions {
        doubling_depth: 4,
        max_points: 400,
        ..ContinuationOptions::default()
    };
    let result = continue_orbit(
        "omega_ratio",
        |w| oscillator(w, GAP),
        3.6,
        2.4,
        &start,
        1,
        &options,
    )
    .unwrap();
    let chain = vibrotribo::orbits::cascade(&result);
    let points: Vec<f64> = chain.iter().map(|b| b.parameter).collect();
    let ratios = vibrotribo::orbits::feigenbaum_ratios(&points);
    println!("cascade at {points:?}, Feigenbaum ratios {ratios:?}");
    assert!(points.len() >= 4, "{points:?}");
    assert!((points[0] - 2.4551988).abs() < 1e-6 && (points[1] - 2.4861677).abs() < 1e-6);
    for r in &ratios {
        assert!(*r > 2.0 && r.is_finite(), "ratios {ratios:?}");
    }
    // Brute force on each side of each located doubling, a fifth of the way to its
    // neighbours, from the orbit at the point.
    for (k, b) in chain.iter().enumerate() {
        let p = b.parameter;
        let below = if k == 0 {
            0.2 * (points[1] - p)
        } else {
            0.2 * (p - points[k - 1])
        };
        let above = match points.get(k + 1) {
            Some(q) => 0.2 * (q - p),
            None => 0.2 * (p - points[k - 1]) / 4.669,
        };
        let period = 1usize << k;
        let sign = (points[1] - points[0]).signum();
        let before = brute_force_period(p - sign * below, &b.point.state);
        let after = brute_force_period(p + sign * above, &b.point.state);
        println!("doubling {k} at {p}: brute-force period {before:?} before, {after:?} after");
        assert_eq!(before, Some(period), "before the doubling at {p}");
        assert_eq!(after, Some(2 * period), "after the doubling at {p}");
    }
}

/// The impact oscillator of the tests above followed as `vibrotribo continue` follows it from
/// the orbit a transient from rest settles on at Ω = 3.6 (period 2) down to 2.4, four
/// doublings deep: no branch ends at a grazing, and every orbit beyond a grazing crossed, and
/// every point of a branch within 1e-3 of the range of one, is a true orbit by the engine run
/// from it for its period, with no gap below zero (to 1e-9 of the units, and 1e-10 times its
/// largest multiplier, which a run from an unstable orbit amplifies its state's rounding by).
/// The period-2 branch crosses a grazing onto a short stretch of orbits with one more impact,
/// whose impact vanishes again, and is then back on its own orbits going the other way: it
/// ends `retraced`, and its last orbit is the one shooting finds from its earlier points.
#[test]
fn the_impact_oscillators_branches_from_period_two_cross_every_grazing() {
    let text = format!(
        "[oscillator]\nmasses = [{M}]\nstiffness = {K}\ndamping = {C}\n\
         [oscillator.stops.upper]\ngap = {GAP}\nrestitution = {R}\nframe = \"fixed\"\n\
         [excitation]\namplitude = {A}\nomega_ratio = 3.6\n"
    );
    let config = vibrotribo::config::Config::from_toml_str(&text).unwrap();
    let key = "excitation.omega_ratio";
    let options = vibrotribo::branch::BranchOptions {
        continuation: ContinuationOptions {
            doubling_depth: 4,
            ..ContinuationOptions::default()
        },
        ..vibrotribo::branch::BranchOptions::default()
    };
    let result = vibrotribo::branch::continue_config(&config, key, 3.6, 2.4, None, &options).unwrap();
    let at = |p: f64| config.with(key, toml::Value::Float(p)).unwrap().chain().clone();
    let mut crossed = 0;
    for (i, b) in result.branches.iter().enumerate() {
        println!(
            "branch {i} (period {}): {} points, {:?}",
            b.period,
            b.points.len(),
            b.end
        );
        assert!(
            !matches!(b.end, BranchEnd::Grazing { .. }),
            "branch {i} ends at a grazing: {:?}",
            b.end
        );
        for f in &b.bifurcations {
            let (BifurcationKind::Grazing { .. }, Some(after)) = (&f.kind, &f.after) else {
                continue;
            };
            crossed += 1;
            check_branch_point(&at(after.parameter), after, b.period);
            for p in b
                .points
                .iter()
                .filter(|p| (p.parameter - f.parameter).abs() < 1.2e-3)
            {
                check_branch_point(&at(p.parameter), p, b.period);
            }
        }
    }
    println!("{crossed} grazings crossed");
    assert!(crossed >= 3, "grazings crossed: {crossed}");
    // A branch that ends `retraced` is back on its own orbits going the other way: shooting
    // from the chord of two of its earlier points around its last parameter (same impacts)
    // finds its last orbit, and along that chord the parameter moved the other way.
    let shooting = ShootingOptions::default();
    let mut retraced = 0;
    for b in result
        .branches
        .iter()
        .filter(|b| matches!(b.end, BranchEnd::Retraced { .. }))
    {
        let [.., before, last] = &b.points[..] else {
            panic!("a retraced branch with one point");
        };
        let params = at(last.parameter);
        let z = state_vector(&last.state);
        let back = b.points[..b.points.len() - 8].windows(2).any(|w| {
            let (p0, p1) = (w[0].parameter, w[1].parameter);
            if !(w[0].alike(last) && w[1].alike(last)) || (p0 - last.parameter) * (p1 - last.parameter) > 0.0
            {
                return false;
            }
            let s = (last.parameter - p0) / (p1 - p0);
            let (a, c) = (state_vector(&w[0].state), state_vector(&w[1].state));
            let guess = &a + (c - &a) * s;
            let Ok(orbit) = vibrotribo::orbits::find_periodic_orbit(
                &params,
                &vibrotribo::sensitivity::state_from_vector(guess.as_slice()),
                b.period,
                &shooting,
            ) else {
                return false;
            };
            let d = crate::common::default_case::size(&params, &(state_vector(&orbit.state) - &z));
            d < 1e-6 && (p1 - p0) * (last.parameter - before.parameter) < 0.0
        });
        assert!(
            back,
            "a branch ending retraced at {} is not back on its own orbits",
            last.parameter
        );
        retraced += 1;
    }
    assert!(
        retraced >= 1,
        "the period-2 branch turns back past its grazing's short stretch"
    );
}
