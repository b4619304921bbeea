//! The bifurcation map of the impact oscillator (one mass of 50 g on 120 N/m, c = 0.02 N·s/m,
//! base amplitude 10 mm, a stop fixed above at the gap, r = 0.8) in (Ω, gap), against its
//! closed form (Shaw & Holmes 1983): the grazing curve of the impact-free orbit where its
//! steady amplitude equals the gap, the period-doubling curve of the (1,1) orbit where the
//! closed-form impact map `S Φ(T)` has a multiplier −1. Both are found from the seed
//! branches alone, each once.

use crate::common::impact_oscillator;

use impact_oscillator::{ImpactOscillator, OneOne};
use vibrotribo::bifmap::{BifmapError, BifmapOptions, BifurcationMap, HalfEnd, MapRequest, bifurcation_map};
use vibrotribo::config::Config;
use vibrotribo::orbits::curve::{CurveEnd, CurveKind};

const M: f64 = 0.05;
const K: f64 = 120.0;
const C: f64 = 0.02;
const A: f64 = 0.01;
const R: f64 = 0.8;
const GAP_KEY: &str = "oscillator.stops.upper.gap";

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

/// The impact oscillator at (Ω, gap), starting on the impact-free steady motion of Ω = 3.5.
fn config(omega_ratio: f64, gap: f64) -> Config {
    let (x, v) = textbook(3.5, gap).xp(0.0);
    let text = format!(
        "[oscillator]\nmasses = [{M}]\nstiffness = {K}\ndamping = {C}\n\n\
         [oscillator.stops.upper]\ngap = {gap}\nrestitution = {R}\nframe = \"fixed\"\n\n\
         [excitation]\namplitude = {A}\nomega_ratio = {omega_ratio}\n\n\
         [run]\ninitial_positions = [{x:e}]\ninitial_velocities = [{v:e}]\n"
    );
    Config::from_toml_str(&text).expect("the test's configuration is valid")
}

/// The steady amplitude of the impact-free motion, m.
fn steady_amplitude(omega_ratio: f64) -> f64 {
    let w = omega_ratio * wn();
    A * (K * K + C * C * w * w).sqrt() / ((K - M * w * w).powi(2) + C * C * w * w).sqrt()
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

/// Where the closed-form (1,1) orbit at `gap` has a multiplier −1 between Ω = lo and hi
/// (the orbit with the largest impact speed, the one that doubles), by bisection.
fn closed_form_doubling(gap: f64, lo: f64, hi: f64) -> Option<f64> {
    let f = |w: f64| {
        let io = textbook(w, gap);
        let o = one_one_orbits(&io)
            .into_iter()
            .max_by(|a, b| a.speed.total_cmp(&b.speed))?;
        Some(io.doubling_function(&o))
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

fn small_options() -> BifmapOptions {
    BifmapOptions {
        curve_points: 60,
        branch_points: 600,
        ..BifmapOptions::default()
    }
}

fn the_map() -> BifurcationMap {
    let mut request = MapRequest::new("omega_ratio", (2.35, 3.5), GAP_KEY, (0.001, 0.0014));
    request.seeds = 2;
    // The ends only: the impact-free orbit at Ω = 3.5 and the impacting one at 2.35.
    request.x_starts = 2;
    request.kinds = vec![CurveKind::PeriodDoubling, CurveKind::Grazing];
    bifurcation_map(&config(3.0, 0.001), &request, &small_options(), |_| {}).expect("the map is computed")
}

fn describe(map: &BifurcationMap) -> String {
    map.curves
        .iter()
        .map(|c| {
            format!(
                "{} P{} from seed {} ({} points, ends {:?}, found again {})",
                c.kind.name(),
                c.period,
                c.seed,
                c.points.len(),
                c.ends,
                c.found_again
            )
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The map's grazing and period-doubling curves are the closed form's, each found once.
#[test]
fn the_impact_oscillators_map_has_the_closed_form_curves() {
    let map = the_map();
    println!("{}\nlocated {:?}", describe(&map), map.located);
    assert!(map.complete);
    assert_eq!(map.x, "excitation.omega_ratio");
    let grazing: Vec<_> = map
        .curves
        .iter()
        .filter(|c| c.kind == CurveKind::Grazing && c.period == 1)
        .collect();
    assert_eq!(grazing.len(), 1, "one grazing curve:\n{}", describe(&map));
    let g = grazing[0];
    assert_eq!(g.contact, Some(1), "the upper stop is contact 2 of one mass");
    for p in &g.points {
        let amplitude = steady_amplitude(p.parameter);
        assert!(
            (amplitude - p.parameter2).abs() < 1e-10,
            "at Ω = {}: amplitude {amplitude} vs gap {}",
            p.parameter,
            p.parameter2
        );
    }
    // It spans the gap range: the seed at 1 mm runs up to 1.4 mm, found again there.
    let (lo, hi) = g.points.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| {
        (a.min(p.parameter2), b.max(p.parameter2))
    });
    assert!(lo <= 0.001 + 1e-12 && hi >= 0.0014 - 1e-12, "gaps {lo}..{hi}");
    assert!(
        matches!(g.ends[1], Some(HalfEnd::Curve(CurveEnd::RangeEnd { .. }))),
        "{:?}",
        g.ends
    );
    assert_eq!(g.found_again, 1, "the seed at 1.4 mm finds the same curve");

    let doubling: Vec<_> = map
        .curves
        .iter()
        .filter(|c| c.kind == CurveKind::PeriodDoubling && c.period == 1)
        .collect();
    assert_eq!(
        doubling.len(),
        1,
        "one period-1 doubling curve:\n{}",
        describe(&map)
    );
    let d = doubling[0];
    assert!(d.points.len() >= 3, "{} points", d.points.len());
    let stride = (d.points.len() / 4).max(1);
    for p in d.points.iter().step_by(stride).chain(d.points.last()) {
        let want =
            closed_form_doubling(p.parameter2, p.parameter - 0.01, p.parameter + 0.01).unwrap_or_else(|| {
                panic!(
                    "no closed-form doubling near Ω = {} at gap {}",
                    p.parameter, p.parameter2
                )
            });
        assert!(
            (p.parameter - want).abs() < 1e-6,
            "doubling at gap {}: Ω = {} vs closed form {want}",
            p.parameter2,
            p.parameter
        );
    }
    // Every located point lies on a curve.
    assert!(map.located.iter().all(|l| l.curve.is_some()), "{:?}", map.located);
}

/// Bad requests are refused with the problem named.
#[test]
fn bad_requests_name_the_problem() {
    let c = config(3.0, 0.001);
    let run = |r: &MapRequest, o: &BifmapOptions| bifurcation_map(&c, r, o, |_| {}).unwrap_err();
    let base = MapRequest::new("omega_ratio", (2.35, 3.5), GAP_KEY, (0.001, 0.0014));
    let o = BifmapOptions::default();
    let same = MapRequest {
        y: "excitation.omega_ratio".into(),
        ..base.clone()
    };
    assert!(matches!(run(&same, &o), BifmapError::SameKey { .. }));
    let empty = MapRequest {
        x_range: (2.0, 2.0),
        ..base.clone()
    };
    let e = run(&empty, &o);
    assert!(e.to_string().contains("excitation.omega_ratio"), "{e}");
    let nan = MapRequest {
        y_range: (0.001, f64::NAN),
        ..base.clone()
    };
    assert!(matches!(run(&nan, &o), BifmapError::Range { .. }));
    let negative = MapRequest {
        x_range: (-1.0, 2.0),
        ..base.clone()
    };
    let e = run(&negative, &o);
    assert!(e.to_string().contains("omega_ratio"), "{e}");
    let none = MapRequest {
        seeds: 0,
        ..base.clone()
    };
    assert!(matches!(run(&none, &o), BifmapError::Seeds { value: 0, .. }));
    let no_kinds = MapRequest {
        kinds: Vec::new(),
        ..base.clone()
    };
    assert!(matches!(run(&no_kinds, &o), BifmapError::NoKinds));
    let unknown = MapRequest {
        y: "oscillator.no_such_key".into(),
        ..base.clone()
    };
    let e = run(&unknown, &o);
    assert!(e.to_string().contains("no_such_key"), "{e}");
    let one_point = BifmapOptions {
        curve_points: 1,
        ..o.clone()
    };
    assert!(matches!(run(&base, &one_point), BifmapError::Count { .. }));
}
