//! A branch that lands on a branch followed before past a change of sequence ends there. In
//! the paper's default case the two asymmetric branches born at the symmetry-breaking
//! pitchfork (Ω ≈ 0.45869) come down to the grazings near Ω = 0.4533, where they join the
//! first branch's family. Each must end as `RunsOnto` the first branch, at a point that is
//! (1) a true orbit, run forward by the plain simulator (not the shooting map), and (2) the
//! orbit that shooting finds at that parameter from the first branch's own points (its chord
//! there), so that the claim does not rest on the continuation's own test.

use nalgebra::DVector;
use vibrotribo::branch::{BranchOptions, continue_config};
use vibrotribo::config::Config;
use vibrotribo::orbits::{
    BifurcationKind, BranchEnd, ContinuationOptions, ShootingOptions, find_periodic_orbit,
};
use vibrotribo::sensitivity::{Horizon, state_from_vector, state_vector};

use super::common::default_case::size;
use super::common::fd;

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
    let mirrors: Vec<usize> = (0..branches.len())
        .filter(|&i| {
            branches[i].parent.is_some_and(|(b, k)| {
                b == 0 && matches!(branches[0].bifurcations[k].kind, BifurcationKind::BranchPoint)
            })
        })
        .collect();
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
