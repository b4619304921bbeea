//! Bifurcation curves in two parameters against the closed form of the impact oscillator
//! (Shaw & Holmes 1983): one mass of 50 g on 120 N/m, c = 0.02 N·s/m, base amplitude 10 mm,
//! a stop fixed above at the gap, r = 0.8. The period-doubling curve of the (1,1) orbit in
//! (Ω, gap) where the closed-form map `S Φ(T)` has a multiplier −1; the fold curve where two
//! (1,1) orbits meet (a double root of the closed-form (1,1) conditions); the grazing curve of
//! the impact-free orbit where its steady amplitude equals the gap; every point of a curve a
//! true orbit of the engine.

use crate::common::impact_oscillator;

use impact_oscillator::{ImpactOscillator, OneOne};
use vibrotribo::config::Config;
use vibrotribo::curve::{CurveConfigOptions, CurveRequest, curve_config};
use vibrotribo::orbits::curve::{CurveKind, CurveOptions, CurvePoint};
use vibrotribo::{ChainState, SimOptions, Simulator};

const M: f64 = 0.05;
const K: f64 = 120.0;
const C: f64 = 0.02;
const A: f64 = 0.01;
const R: f64 = 0.8;
const GAP_KEY: &str = "oscillator.stops.upper.gap";

fn config(omega_ratio: f64, gap: f64) -> Config {
    config_from(omega_ratio, gap, (0.0, 0.0))
}

/// The impact oscillator starting from `(x, v)` at t = 0.
fn config_from(omega_ratio: f64, gap: f64, start: (f64, f64)) -> Config {
    let text = format!(
        "[oscillator]\nmasses = [{M}]\nstiffness = {K}\ndamping = {C}\n\n\
         [oscillator.stops.upper]\ngap = {gap}\nrestitution = {R}\nframe = \"fixed\"\n\n\
         [excitation]\namplitude = {A}\nomega_ratio = {omega_ratio}\n\n\
         [run]\ninitial_positions = [{:e}]\ninitial_velocities = [{:e}]\n",
        start.0, start.1
    );
    Config::from_toml_str(&text).expect("the test's configuration is valid")
}

fn wn() -> f64 {
    (K / M).sqrt()
}

fn textbook(omega_ratio: f64, gap: f64) -> ImpactOscillator {
    ImpactOscillator {
        m: M,
        k: K,
        c: C,
        amplitude: A,
        omega: omega_ratio * wn(),
        gap,
        r: R,
        moving: false,
    }
}

/// Every (1,1) orbit of the closed form, from a scan of impact phases and speeds.
fn one_one_orbits(io: &ImpactOscillator) -> Vec<OneOne> {
    let mut out: Vec<OneOne> = Vec::new();
    for j in 0..48 {
        for v in [0.05, 0.2, 0.5] {
            if let Some(o) = io.one_one((io.period() * f64::from(j) / 48.0, v))
                && !out
                    .iter()
                    .any(|p| (p.t0 - o.t0).abs() < 1e-9 && (p.speed - o.speed).abs() < 1e-9)
            {
                out.push(o);
            }
        }
    }
    out
}

/// The closed-form (1,1) orbit at (Ω, gap) nearest the impact speed `speed`.
fn nearest(omega_ratio: f64, gap: f64, speed: f64) -> Option<OneOne> {
    let io = textbook(omega_ratio, gap);
    one_one_orbits(&io)
        .into_iter()
        .min_by(|a, b| (a.speed - speed).abs().total_cmp(&(b.speed - speed).abs()))
}

/// The largest impact speed of the engine's orbit through `p` over one period, m/s.
fn impact_speed(c: &Config, p: &CurvePoint, period: u32) -> f64 {
    let chain = c.chain();
    let mut sim = Simulator::new(chain, &p.state, SimOptions::default()).expect("valid start");
    let mut log = vibrotribo::EventLog::default();
    sim.run_until(f64::from(period) * chain.period(), &mut log)
        .expect("the orbit runs");
    log.events
        .iter()
        .map(|e| e.event.velocity_before.abs())
        .fold(0.0, f64::max)
}

/// Where the closed-form (1,1) orbit at `gap` has a multiplier −1, by bisection in Ω on
/// `(1 + λ₁)(1 + λ₂)` over [lo, hi], following the orbit of impact speed `speed`.
fn closed_form_doubling(gap: f64, lo: f64, hi: f64, speed: f64) -> Option<f64> {
    let f = |w: f64| {
        let o = nearest(w, gap, speed)?;
        Some(textbook(w, gap).doubling_function(&o))
    };
    let (mut lo, mut hi) = (lo, hi);
    let f_lo = f(lo)?;
    if f_lo * f(hi)? > 0.0 {
        return None;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if f(mid)? * f_lo > 0.0 { lo = mid } else { hi = mid }
    }
    Some(0.5 * (lo + hi))
}

/// The engine's orbit through the point, run for its period, returns to its state.
fn assert_true_orbit(c: &Config, p: &CurvePoint, period: u32) {
    let chain = c.chain();
    let mut sim = Simulator::new(chain, &p.state, SimOptions::default()).expect("valid start");
    sim.run_until(f64::from(period) * chain.period(), &mut ())
        .expect("the orbit runs");
    let end: ChainState = sim.state();
    let length = 0.01;
    let speed = length * chain.omega();
    let dx = (end.positions[0] - p.state.positions[0]).abs() / length;
    let dv = (end.velocities[0] - p.state.velocities[0]).abs() / speed;
    assert!(
        dx < 1e-9 && dv < 1e-9,
        "the point ({}, {}) is no orbit: returns off by {dx:e}, {dv:e} (scaled)",
        p.parameter,
        p.parameter2
    );
}

/// The distance of the point's nearest multiplier to the real number `at`.
fn distance_to_multiplier(p: &CurvePoint, at: f64) -> f64 {
    p.multipliers
        .iter()
        .map(|l| (l.re - at).hypot(l.im))
        .fold(f64::INFINITY, f64::min)
}

fn options(max_points: usize) -> CurveConfigOptions {
    CurveConfigOptions {
        curve: CurveOptions {
            max_points,
            ..CurveOptions::default()
        },
        ..CurveConfigOptions::default()
    }
}

/// The period-doubling curve of the (1,1) orbit in (Ω, gap) lies where the closed-form map
/// has a multiplier −1, and each of its points is an orbit of the engine.
#[test]
fn period_doubling_curve_matches_the_closed_form() {
    let request = CurveRequest {
        kind: CurveKind::PeriodDoubling,
        key: "omega_ratio".into(),
        near: 2.455,
        key2: GAP_KEY.into(),
        from2: 0.001,
        to2: 0.0015,
        period: Some(1),
    };
    let base = config(2.45, 0.001);
    let result = curve_config(&base, &request, &options(40)).expect("the curve is computed");
    assert_eq!(result.key, "excitation.omega_ratio");
    let curve = &result.curve;
    println!(
        "located at Ω = {}, {} points, end {:?}, codim2 {:?}",
        result.located.parameter,
        curve.points.len(),
        curve.end,
        curve
            .codim2
            .iter()
            .map(|p| (p.kind, p.point.parameter, p.point.parameter2))
            .collect::<Vec<_>>()
    );
    assert!(curve.points.len() >= 3, "only {} points", curve.points.len());
    let last = curve.points.last().expect("points");
    assert!(
        last.parameter2 > 0.0012,
        "the curve stops at gap {}",
        last.parameter2
    );
    let stride = (curve.points.len() / 4).max(1);
    for p in curve.points.iter().step_by(stride).chain([last]) {
        let c = config(p.parameter, p.parameter2);
        assert_true_orbit(&c, p, curve.period);
        let lambda = distance_to_multiplier(p, -1.0);
        assert!(lambda < 1e-8, "no multiplier at −1 at {p:?}");
        let speed = impact_speed(&c, p, curve.period);
        let want = closed_form_doubling(p.parameter2, p.parameter - 0.01, p.parameter + 0.01, speed)
            .unwrap_or_else(|| {
                panic!(
                    "no closed-form doubling near Ω = {} at gap {}",
                    p.parameter, p.parameter2
                )
            });
        println!(
            "gap {:.6}: Ω = {:.12}, closed form {want:.12}",
            p.parameter2, p.parameter
        );
        assert!(
            (p.parameter - want).abs() < 1e-6,
            "doubling at gap {}: Ω = {} vs closed form {want}",
            p.parameter2,
            p.parameter
        );
    }
}

/// The steady amplitude of the impact-free motion, m.
fn steady_amplitude(omega_ratio: f64) -> f64 {
    let w = omega_ratio * wn();
    A * (K * K + C * C * w * w).sqrt() / ((K - M * w * w).powi(2) + C * C * w * w).sqrt()
}

/// The grazing curve of the impact-free orbit in (Ω, gap) lies where its steady amplitude
/// equals the gap, and each point is an orbit of the engine that touches the stop.
#[test]
fn grazing_curve_is_where_the_steady_amplitude_equals_the_gap() {
    let request = CurveRequest {
        kind: CurveKind::Grazing,
        key: "omega_ratio".into(),
        near: 3.4,
        key2: GAP_KEY.into(),
        from2: 0.001,
        to2: 0.002,
        period: Some(1),
    };
    // Started on the closed-form steady motion at Ω = 3.4 (amplitude 0.95 mm, clear of the
    // stop at 1 mm), which the transient keeps.
    let start = textbook(3.4, 0.001).xp(0.0);
    let base = config_from(3.4, 0.001, start);
    let result = curve_config(&base, &request, &options(80)).expect("the curve is computed");
    let curve = &result.curve;
    println!(
        "located at Ω = {}, {} points, end {:?}, codim2 {:?}",
        result.located.parameter,
        curve.points.len(),
        curve.end,
        curve
            .codim2
            .iter()
            .map(|p| (p.kind, p.point.parameter, p.point.parameter2))
            .collect::<Vec<_>>()
    );
    assert_eq!(curve.contact, Some(1), "the upper stop is contact 2 of one mass");
    assert!(curve.points.len() >= 5, "only {} points", curve.points.len());
    for p in &curve.points {
        let amplitude = steady_amplitude(p.parameter);
        assert!(
            (amplitude - p.parameter2).abs() < 1e-10,
            "at Ω = {}: amplitude {amplitude} vs gap {}",
            p.parameter,
            p.parameter2
        );
        // The grazing orbit touches the stop with zero speed: with the stop raised by 1 nm it is
        // an impact-free orbit of the engine, lowered by 1 nm it hits it.
        let above = config(p.parameter, p.parameter2 + 1e-9);
        assert_true_orbit(&above, p, curve.period);
        assert_eq!(
            impact_speed(&above, p, curve.period),
            0.0,
            "an impact 1 nm above the grazing"
        );
        let below = config(p.parameter, p.parameter2 - 1e-9);
        assert!(
            impact_speed(&below, p, curve.period) > 0.0,
            "no impact 1 nm below the grazing at {p:?}"
        );
    }
    let last = curve.points.last().expect("points");
    assert!(
        (last.parameter2 - 0.002).abs() < 1e-12,
        "the curve ends at gap {} short of the range",
        last.parameter2
    );
}

/// The state at t = 0 of the closed-form (1,1) orbit at Ω nearest the impact speed `speed`:
/// the motion after its impact, run on to the end of the period.
fn one_one_start(omega_ratio: f64, gap: f64, speed: f64) -> (f64, f64) {
    let io = textbook(omega_ratio, gap);
    let o = nearest(omega_ratio, gap, speed).expect("a closed-form (1,1) orbit");
    let (p, pd) = io.xp(o.t0);
    let (h0, h1) = (gap - p, -R * o.speed - pd);
    let f = io.propagator(io.period() - o.t0);
    let (x, v) = io.xp(0.0);
    (x + f[0][0] * h0 + f[0][1] * h1, v + f[1][0] * h0 + f[1][1] * h1)
}

/// The impact time of the engine's orbit through `p` in its period, s.
fn impact_time(c: &Config, p: &CurvePoint) -> f64 {
    let chain = c.chain();
    let mut sim = Simulator::new(chain, &p.state, SimOptions::default()).expect("valid start");
    let mut log = vibrotribo::EventLog::default();
    sim.run_until(chain.period(), &mut log).expect("the orbit runs");
    log.events.first().expect("an impact").event.time
}

/// Where the closed-form (1,1) orbits of impact times near `t_fold` meet at `gap`: the (1,1)
/// conditions reduced to the impact time have a double root there, so the extremum of the
/// reduced residual over impact times within a twentieth of a period of `t_fold` changes sign;
/// by bisection in Ω over `bracket`.
fn closed_form_fold(gap: f64, t_fold: f64, bracket: (f64, f64)) -> f64 {
    let extremum = |w: f64| {
        let io = textbook(w, gap);
        io.fold_function((t_fold - 0.05 * io.period(), t_fold + 0.05 * io.period()))
    };
    let (mut lo, mut hi) = bracket;
    let f_lo = extremum(lo);
    assert!(
        f_lo * extremum(hi) < 0.0,
        "no closed-form fold in {bracket:?} at gap {gap}"
    );
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if extremum(mid) * f_lo > 0.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    0.5 * (lo + hi)
}

/// The fold curve of the (1,1) orbits in (Ω, gap), where the slow orbit born at the grazing of
/// the impact-free motion meets the fast one, lies where the closed-form (1,1) conditions have
/// a double root, and each of its points is an orbit of the engine with a multiplier at +1.
#[test]
fn fold_curve_matches_the_closed_form() {
    let gap = 0.015;
    // Started on the fast (1,1) orbit at Ω = 1.77 (the motion from rest there is impact-free).
    let start = one_one_start(1.77, gap, 3.7);
    let request = CurveRequest {
        kind: CurveKind::Fold,
        key: "omega_ratio".into(),
        near: 1.77,
        key2: GAP_KEY.into(),
        from2: gap,
        to2: 0.02,
        period: Some(1),
    };
    let base = config_from(1.77, gap, start);
    let result = curve_config(&base, &request, &options(40)).expect("the curve is computed");
    let curve = &result.curve;
    println!(
        "located at Ω = {}, {} points, end {:?}",
        result.located.parameter,
        curve.points.len(),
        curve.end
    );
    assert!(curve.points.len() >= 5, "only {} points", curve.points.len());
    let last = curve.points.last().expect("points");
    assert!(
        last.parameter2 > 0.018,
        "the curve stops at gap {}",
        last.parameter2
    );
    let stride = (curve.points.len() / 4).max(1);
    for p in curve.points.iter().step_by(stride).chain([last]) {
        let c = config(p.parameter, p.parameter2);
        assert_true_orbit(&c, p, curve.period);
        let lambda = distance_to_multiplier(p, 1.0);
        assert!(lambda < 1e-8, "no multiplier at +1 at {p:?}");
        let t = impact_time(&c, p);
        let want = closed_form_fold(p.parameter2, t, (p.parameter - 5e-4, p.parameter + 5e-4));
        println!(
            "gap {:.6}: Ω = {:.12}, closed form {want:.12}",
            p.parameter2, p.parameter
        );
        assert!(
            (p.parameter - want).abs() < 1e-8,
            "fold at gap {}: Ω = {} vs closed form {want}",
            p.parameter2,
            p.parameter
        );
    }
}
