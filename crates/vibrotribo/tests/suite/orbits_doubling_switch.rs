//! Switching onto the doubled branch at every period doubling of mirror-image branches: the
//! paper's default case has a symmetric chain (m1 = m3, equal gaps), so the two asymmetric
//! branches born at its symmetry-breaking pitchfork (Ω ≈ 0.45869) are mirror images of each
//! other and double at the same Ω. Both doublings must give a doubled branch; the first orbit
//! of each, run forward by the plain simulator (not the shooting map), returns to its state
//! after twice the period of its parent and not after once.

use vibrotribo::orbits::{BifurcationKind, BranchEnd, ContinuationOptions, continue_orbit};
use vibrotribo::sensitivity::{Horizon, state_vector};

use super::common::default_case::{chain, pitchfork_branches, size, start_orbit};
use super::common::fd;

#[test]
fn both_mirror_image_doublings_switch_onto_a_true_doubled_orbit() {
    let start = start_orbit();
    let options = ContinuationOptions {
        doubling_depth: 1,
        ..ContinuationOptions::default()
    };
    let result = continue_orbit("omega_ratio", chain, 0.7, 0.45, &start.state, 1, &options).unwrap();
    let branches = &result.branches;
    // The two branches born at the first branch's branch point.
    let mirrors = pitchfork_branches(branches);
    assert_eq!(mirrors.len(), 2, "the pitchfork's two branches: {mirrors:?}");
    // Their first period doublings, at the same Ω.
    let doubling = |i: usize| {
        branches[i]
            .bifurcations
            .iter()
            .find(|f| f.kind == BifurcationKind::PeriodDoubling)
            .unwrap_or_else(|| panic!("branch {i} has no period doubling"))
    };
    let (a, b) = (doubling(mirrors[0]), doubling(mirrors[1]));
    println!("doublings at {:.10} and {:.10}", a.parameter, b.parameter);
    assert!(
        (a.parameter - b.parameter).abs() < 1e-8,
        "{} {}",
        a.parameter,
        b.parameter
    );
    for f in [a, b] {
        let child = f.child.expect("a doubled branch is born at the doubling");
        let doubled = &branches[child];
        assert!(
            !matches!(doubled.end, BranchEnd::SwitchFailed { .. }) && !doubled.points.is_empty(),
            "the doubled branch {child} at {} was not started: {:?}",
            f.parameter,
            doubled.end
        );
        assert_eq!(doubled.period, 2);
        let first = &doubled.points[0];
        assert!(
            (first.parameter - f.parameter).abs() < 1e-3,
            "{} far from {}",
            first.parameter,
            f.parameter
        );
        let params = chain(first.parameter);
        let z = state_vector(&first.state);
        let once = fd::run(&params, &z, Horizon::Periods(1)).expect("a plain run").0;
        let twice = fd::run(&params, &once, Horizon::Periods(1))
            .expect("a plain run")
            .0;
        let (closes, half) = (size(&params, &(&twice - &z)), size(&params, &(&once - &z)));
        println!(
            "branch {child}: first orbit at Ω = {:.10}, after 2 periods {closes:.2e}, after 1 period {half:.2e}",
            first.parameter
        );
        assert!(
            closes < 1e-9,
            "branch {child}'s first orbit does not close: {closes:e}"
        );
        assert!(
            half > 1e-6,
            "branch {child}'s first orbit is of period 1: {half:e}"
        );
    }
}
