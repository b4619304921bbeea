//! A grazing crossed as a non-smooth fold, against the closed form of the impact oscillator
//! (50 g on 120 N/m, c = 0.02 N s/m, base amplitude 10 mm, r = 0.8, a stop fixed 15 mm
//! above the static position). Followed down in Ω from 2.0, the impact-free orbit grazes the
//! stop where its steady amplitude equals the gap; the (1,1) orbit with a slow impact lies on
//! the impact-free side (the two meet at the grazing and vanish together), so the branch
//! turns back onto it, goes up in Ω to the smooth fold where it meets the fast (1,1) orbit,
//! and comes down again on that one. The closed form's (1,1) conditions, reduced to the
//! impact time, place the grazing, the slow orbit's impact speed and the fold.

use crate::common::impact_oscillator::ImpactOscillator;
use vibrotribo::nalgebra::Complex;
use vibrotribo::orbits::{BifurcationKind, BranchEnd, ContinuationOptions, CrossingKind, continue_orbit};
use vibrotribo::{ChainParams, ChainState, Excitation, Frequency, Stop, StopFrame, Stops};

const M: f64 = 0.05;
const K: f64 = 120.0;
const C: f64 = 0.02;
const A: f64 = 0.01;
const GAP: f64 = 0.015;
const R: f64 = 0.8;

fn wn() -> f64 {
    (K / M).sqrt()
}

fn oscillator(omega_ratio: f64) -> ChainParams {
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
                gap: GAP,
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

/// Bisection for the sign change of `f` in [lo, hi].
fn bisect(f: impl Fn(f64) -> f64, (mut lo, mut hi): (f64, f64)) -> f64 {
    let f_lo = f(lo);
    assert!(f_lo * f(hi) < 0.0, "no sign change in [{lo}, {hi}]");
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if f(mid) * f_lo > 0.0 { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

/// Where the impact-free steady motion's amplitude equals the gap, above resonance.
fn closed_form_grazing() -> f64 {
    let steady = |w: f64| {
        let om = w * wn();
        A * (K * K + C * C * om * om).sqrt() / ((K - M * om * om).powi(2) + C * C * om * om).sqrt()
    };
    bisect(|w| steady(w) - GAP, (1.1, 2.0))
}

/// Impact speeds of every (1,1) orbit at Ω: the roots of the reduced condition over a period
/// with v > 0, m/s.
fn one_one_speeds(omega_ratio: f64) -> Vec<f64> {
    let io = textbook(omega_ratio);
    let n = 4000;
    let g = |t: f64| io.reduced(t).0;
    let at = |i: usize| io.period() * i as f64 / n as f64;
    (0..n)
        .filter(|&i| g(at(i)) * g(at(i + 1)) < 0.0)
        .map(|i| io.reduced(bisect(g, (at(i), at(i + 1)))).1)
        .filter(|&v| v > 0.0)
        .collect()
}

fn fold_test(multipliers: &[Complex<f64>]) -> f64 {
    let one = Complex::new(1.0, 0.0);
    multipliers.iter().fold(one, |p, l| p * (l - one)).re
}

#[test]
fn a_grazing_crossed_as_a_non_smooth_fold_and_the_smooth_fold_beyond_match_the_closed_form() {
    let grazing = closed_form_grazing();
    let (x, v) = textbook(2.0).xp(0.0);
    let start = ChainState {
        positions: vec![x],
        velocities: vec![v],
    };
    let options = ContinuationOptions {
        doubling_depth: 0,
        ..ContinuationOptions::default()
    };
    let result = continue_orbit("omega_ratio", oscillator, 2.0, 1.0, &start, 1, &options).unwrap();
    let main = &result.branches[0];
    println!(
        "closed-form grazing {grazing:.12}; bifurcations {:?}; end {:?}",
        main.bifurcations
            .iter()
            .map(|b| (b.kind, b.parameter, b.crossing.map(|c| c.kind)))
            .collect::<Vec<_>>(),
        main.end
    );
    assert!(
        matches!(main.end, BranchEnd::RangeEnd { parameter } if parameter == 1.0),
        "the branch ends at {:?}",
        main.end
    );

    // The grazing, crossed as a non-smooth fold: det(Φ − I) changes sign (Feigin's rule).
    let g = main
        .bifurcations
        .iter()
        .find(|b| {
            matches!(
                b.kind,
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
    assert_eq!(g.crossing.expect("crossed").kind, CrossingKind::NonSmoothFold);
    let after = g.after.as_ref().expect("the orbit beyond");
    assert!(
        after.parameter > grazing,
        "the slow orbit lies on the impact-free side"
    );
    assert!(fold_test(&g.point.multipliers) * fold_test(&after.multipliers) < 0.0);

    // The smooth fold of the (1,1) orbits where the reduced condition's double root is.
    let fold = main
        .bifurcations
        .iter()
        .find(|b| b.kind == BifurcationKind::Fold)
        .expect("the fold of the (1,1) orbits");
    let window = (0.035, 0.045);
    let want = bisect(|w| textbook(w).fold_function(window), (1.768, 1.775));
    println!("fold at Ω = {:.12}, closed form {want:.12}", fold.parameter);
    assert!(
        (fold.parameter - want).abs() < 1e-8,
        "fold at {} vs {want}",
        fold.parameter
    );

    // Between the grazing and the fold, on the slow orbit: one impact per period at the speed
    // of a closed-form (1,1) orbit, which vanishes at the grazing.
    // The slow leg: from the first impacting point to the fold, the branch's largest Ω.
    let first = main
        .points
        .iter()
        .position(|p| p.impacts_per_period == vec![0.0, 1.0])
        .expect("an impacting point");
    let turn = (first..main.points.len())
        .max_by(|&i, &j| main.points[i].parameter.total_cmp(&main.points[j].parameter))
        .expect("points");
    let slow: Vec<_> = main.points[first..turn]
        .iter()
        .filter(|p| p.parameter < fold.parameter - 1e-2)
        .collect();
    let mut compared = 0;
    for p in slow {
        let speed = p.min_closing_speed.expect("an impact").1;
        if speed < 1e-3 {
            continue;
        }
        let want = one_one_speeds(p.parameter)
            .into_iter()
            .min_by(|a, b| (a - speed).abs().total_cmp(&(b - speed).abs()))
            .expect("a closed-form (1,1) orbit");
        assert!(
            (speed - want).abs() <= 1e-7 * want,
            "Ω = {}: impact speed {speed} vs closed form {want}",
            p.parameter
        );
        compared += 1;
    }
    assert!(compared >= 5, "{compared} points compared with the closed form");
}
