//! A branch that lands on a branch followed before past a change of sequence ends there. In
//! the paper's default case the two asymmetric branches born at the symmetry-breaking
//! pitchfork (Ω ≈ 0.45869) come down to the grazings near Ω = 0.4533, where they join the
//! first branch's family. Each must end as `RunsOnto` the first branch, at a point that is
//! (1) a true orbit, run forward by the plain simulator (not the shooting map), and (2) the
//! orbit that shooting finds at that parameter from the first branch's own points (its chord
//! there), so that the claim does not rest on the continuation's own test.

use nalgebra::DVector;
use vibrotribo::ChainParams;
use vibrotribo::branch::{BranchOptions, continue_config};
use vibrotribo::config::Config;
use vibrotribo::orbits::{
    BifurcationKind, BranchEnd, Continuation, ContinuationOptions, ShootingOptions, find_periodic_orbit,
};
use vibrotribo::sensitivity::{Horizon, state_from_vector, state_vector};

use super::common::default_case::{pitchfork_branches, size};
use super::common::fd;
use super::orbits_grazing::check_branch_point;

/// The continuation parameter of these tests.
const KEY: &str = "excitation.omega_ratio";

#[test]
fn the_pitchforks_branches_end_where_they_run_onto_the_first_branch() {
    // As `vibrotribo continue` runs it, from Ω = 0.7 to 0.3: the first branch, its first
    // period doubling's branch and the pitchfork's two branches.
    let config = Config::default();
    let key = "excitation.omega_ratio";
    let options = BranchOptions {
        continuation: ContinuationOptions {
            doubling_depth: 1,
            max_branches: 4,
            ..ContinuationOptions::default()
        },
        ..BranchOptions::default()
    };
    let result = continue_config(&config, key, 0.7, 0.3, None, &options).unwrap();
    let at = |p: f64| config.with(key, toml::Value::Float(p)).unwrap();
    let shooting = ShootingOptions {
        sim: config.sim_options().clone(),
        ..ShootingOptions::default()
    };
    let branches = &result.branches;
    for (i, b) in branches.iter().enumerate() {
        println!(
            "branch {i} (period {}): {} points, {:?}",
            b.period,
            b.points.len(),
            b.end
        );
    }
    let mirrors = pitchfork_branches(branches);
    assert_eq!(mirrors.len(), 2, "the pitchfork's two branches: {mirrors:?}");
    for i in mirrors {
        let b = &branches[i];
        let BranchEnd::RunsOnto { parameter, branch } = b.end else {
            panic!("branch {i} does not end on another branch: {:?}", b.end);
        };
        assert_eq!(branch, 0, "branch {i} runs onto branch {branch}");
        let last = b.points.last().expect("a branch with points");
        assert_eq!(last.parameter, parameter);
        let params = at(parameter).chain().clone();
        let z = state_vector(&last.state);
        // (1) A true orbit.
        let once = fd::run(&params, &z, Horizon::Periods(1)).expect("a plain run").0;
        let closes = size(&params, &(&once - &z));
        assert!(
            closes < 1e-9,
            "branch {i}'s last orbit does not close: {closes:e}"
        );
        // (2) The first branch's orbit at that parameter: shooting from the chord between the
        // first branch's two points around it with the same impacts.
        let first = &branches[0].points;
        let chord = first
            .windows(2)
            .filter(|w| {
                w.iter().all(|q| q.impacts_per_period == last.impacts_per_period)
                    && (w[0].parameter - parameter) * (w[1].parameter - parameter) <= 0.0
                    && w[0].parameter != w[1].parameter
            })
            .map(|w| {
                let s = (parameter - w[0].parameter) / (w[1].parameter - w[0].parameter);
                let (a, c) = (state_vector(&w[0].state), state_vector(&w[1].state));
                &a + (c - &a) * s
            })
            .collect::<Vec<DVector<f64>>>();
        let nearest = chord
            .iter()
            .filter_map(|g| {
                let orbit =
                    find_periodic_orbit(&params, &state_from_vector(g.as_slice()), 1, &shooting).ok()?;
                Some(size(&params, &(state_vector(&orbit.state) - &z)))
            })
            .fold(f64::INFINITY, f64::min);
        println!(
            "branch {i} ends at Ω = {parameter:.10}: closes to {closes:.1e}; the first branch's orbit there is {nearest:.1e} away ({} chords)",
            chord.len()
        );
        assert!(
            nearest < 1e-6,
            "no orbit of the first branch at {parameter} is branch {i}'s last orbit (nearest {nearest:e})"
        );
        // It ended at the first orbit on the first branch: it does not repeat it.
        assert!(b.points.len() < 400, "branch {i} has {} points", b.points.len());
    }
}

/// The slowest impact's closing speed over `period` periods from `z` at `p`, m/s, by the plain
/// simulator.
fn slowest_impact(
    at: &impl Fn(f64) -> vibrotribo::ChainParams,
    p: f64,
    z: &DVector<f64>,
    period: u32,
) -> f64 {
    let (_, events) = fd::run(&at(p), z, Horizon::Periods(period)).expect("a plain run");
    events
        .iter()
        .filter(|e| e.kind == vibrotribo::dynamics::EventKind::Impact)
        .map(|e| e.velocity_before.abs())
        .fold(f64::INFINITY, f64::min)
}

/// Where an impact of the old orbit disappears across a change of sequence, the point is a
/// grazing only if that impact vanishes there: by the plain simulator, the edge orbit's
/// slowest impact speed, over its rate of change from the branch's point before it,
/// extrapolates to zero within 1e-6 of the range of the edge. Where it does not (the impact
/// is still as fast as ~1e-3 m/s at an edge located to 1e-8), the point is a
/// `sequence_change`: the old orbit was lost there and the orbit found beyond is of another
/// family.
#[test]
fn an_impact_that_disappears_at_a_grazing_vanishes_there() {
    // The default case's first four branches: the pitchfork's branches lose their
    // eight-impact orbits where those are still striking at ~1e-3 m/s.
    let config = Config::default();
    let result = follow(&config, (0.7, 0.3), None, first_four());
    let (grazings, changes) = lost_impacts(&config, &result, 0.4);
    println!("{grazings} grazings");
    assert!(
        changes >= 2,
        "the pitchfork's branches lose their eight-impact orbits: {changes}"
    );
}

/// The same over every branch `vibrotribo continue` follows by default (16 on this range,
/// to period 8): deep in the period-doubling window, where the shooting at a fixed distance
/// behind an edge does not converge, the branch's own points before the edge decide. There,
/// too, no branch ends at a grazing; every point of every branch is a true orbit by the plain
/// simulator (it returns to itself after its period, no gap below zero on the way); and at
/// every grazing crossed the orbit beyond is one born there, next to the edge orbit: no
/// farther from it than the square-root law allows (the distance, Euclidean in the length
/// and speed scales, below three times the square root of the parameter step over the
/// range), not an orbit of another family that has the new sequence.
#[test]
fn every_impact_lost_on_the_default_continuation_vanishes_where_called_a_grazing() {
    let config = Config::default();
    let result = follow(&config, (0.7, 0.3), None, ContinuationOptions::default());
    let (grazings, changes) = lost_impacts(&config, &result, 0.4);
    assert!(
        changes >= 5,
        "sequence changes where an impact is lost: {changes} ({grazings} grazings)"
    );
    let at = |p: f64| at(&config, p);
    let mut crossed = 0;
    for (i, b) in result.branches.iter().enumerate() {
        assert!(
            !matches!(b.end, BranchEnd::Grazing { .. }),
            "branch {i} ends at a grazing: {:?}",
            b.end
        );
        for p in &b.points {
            check_branch_point(&at(p.parameter), p, b.period);
        }
        for f in &b.bifurcations {
            let (BifurcationKind::Grazing { appears, .. }, Some(after)) = (&f.kind, &f.after) else {
                continue;
            };
            let params = at(after.parameter);
            check_branch_point(&params, after, b.period);
            let (z0, z1) = (state_vector(&f.point.state), state_vector(&after.state));
            let distance = size(&params, &(&z1 - &z0));
            let step = (after.parameter - f.parameter).abs() / 0.4;
            println!(
                "branch {i}: grazing at {:.10} ({}): beyond it {distance:.2e} from the edge orbit {step:.1e} of the range on",
                f.parameter,
                if *appears {
                    "impact appears"
                } else {
                    "impact disappears"
                },
            );
            assert!(
                distance < 3.0 * step.sqrt(),
                "the orbit beyond is not next to the edge orbit: {distance:e} at {step:e}"
            );
            crossed += 1;
        }
    }
    assert!(crossed >= 5, "grazings crossed: {crossed}");
}

/// The first branch, its first period doubling's branch and the pitchfork's two branches.
fn first_four() -> ContinuationOptions {
    ContinuationOptions {
        doubling_depth: 1,
        max_branches: 4,
        ..ContinuationOptions::default()
    }
}

/// `config`'s branches over `(from, to)` in Ω with `continuation`, as `vibrotribo continue`
/// follows them.
fn follow(
    config: &Config,
    (from, to): (f64, f64),
    period: Option<u32>,
    continuation: ContinuationOptions,
) -> Continuation {
    let options = BranchOptions {
        period,
        continuation,
        ..BranchOptions::default()
    };
    continue_config(config, KEY, from, to, None, &options).unwrap()
}

/// The default chain of `config` at Ω = `p`.
fn at(config: &Config, p: f64) -> ChainParams {
    config.with(KEY, toml::Value::Float(p)).unwrap().chain().clone()
}

/// Checks every change of sequence of `result` (over a range `range` wide) that loses an
/// impact (tests above); the grazings and sequence changes seen.
fn lost_impacts(config: &Config, result: &Continuation, range: f64) -> (usize, usize) {
    let at = |p: f64| at(config, p);
    let (mut grazings, mut changes) = (0, 0);
    for (i, b) in result.branches.iter().enumerate() {
        for f in b.bifurcations.iter().filter(|f| f.crossing.is_some()) {
            let Some(after) = &f.after else { continue };
            let lost =
                f.point.impacts_per_period.iter().sum::<f64>() > after.impacts_per_period.iter().sum::<f64>();
            if !lost {
                continue;
            }
            // The branch's point before the edge, on the old sequence.
            let Some(prev) = b.points.iter().rev().find(|q| {
                q.impacts_per_period == f.point.impacts_per_period
                    && q.parameter != f.parameter
                    && (q.parameter - f.parameter).abs() < 1e-3 * range
            }) else {
                continue;
            };
            let v_edge = slowest_impact(&at, f.parameter, &state_vector(&f.point.state), b.period);
            let v_prev = slowest_impact(&at, prev.parameter, &state_vector(&prev.state), b.period);
            let rate = (v_prev - v_edge).abs() / (prev.parameter - f.parameter).abs();
            let to_zero = v_edge / rate;
            println!(
                "branch {i}, {:?} at {:.10}: slowest impact {v_edge:.3e} m/s, zero {to_zero:.2e} away",
                f.kind, f.parameter
            );
            match f.kind {
                BifurcationKind::Grazing { appears: false, .. } => {
                    grazings += 1;
                    assert!(
                        to_zero < 1e-6 * range,
                        "a grazing whose impact does not vanish: {to_zero:e}"
                    );
                }
                BifurcationKind::SequenceChange => {
                    changes += 1;
                    assert!(
                        to_zero > 1e-5 * range,
                        "a vanishing impact not called a grazing: {to_zero:e}"
                    );
                }
                _ => {}
            }
        }
    }
    println!("{grazings} grazings and {changes} sequence changes where an impact is lost");
    (grazings, changes)
}
