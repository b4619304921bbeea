//! The stability a continued branch states is what direct simulation from its states shows:
//! the paper's default case continued down from Ω = 0.7, through its Neimark–Sacker point,
//! its grazing and the branches born at its period doublings; from points of every branch,
//! a plain run started next to the orbit comes back to it where the multipliers say
//! "stable", and leaves it where they say "unstable", over as many periods as they predict
//! for a factor of 10⁶ (the test asks for 10).

use vibrotribo::orbits::{ContinuationOptions, continue_orbit};
use vibrotribo::sensitivity::{Horizon, length_scale, speed_scale, state_vector};

use super::common::default_case::{chain, size, start_orbit};
use super::common::fd;

#[test]
fn branch_stability_is_what_a_perturbed_run_from_its_states_shows() {
    let start = start_orbit();
    let options = ContinuationOptions {
        doubling_depth: 1,
        ..ContinuationOptions::default()
    };
    let result = continue_orbit("omega_ratio", chain, 0.7, 0.45, &start.state, 1, &options).unwrap();
    let (mut stable, mut unstable) = (0, 0);
    for (b, branch) in result.branches.iter().enumerate() {
        // Points whose largest multiplier is clearly inside or outside the unit circle, and
        // whose impacts are not grazing ones (the map is smooth in a ball around the orbit).
        // Up to six of each kind per branch, spread along it.
        let decided = |stable: bool| -> Vec<_> {
            let points: Vec<_> = branch
                .points
                .iter()
                .filter(|p| p.stable == stable)
                .filter(|p| (p.spectral_radius() - 1.0).abs() > 5e-3)
                .filter(|p| p.min_closing_speed.is_none_or(|(_, v)| v > 1e-3))
                .collect();
            let every = points.len().div_ceil(6).max(1);
            points.into_iter().step_by(every).collect()
        };
        for p in [decided(true), decided(false)].concat() {
            let params = chain(p.parameter);
            let star = state_vector(&p.state);
            let rho = p.spectral_radius();
            // Periods of the branch over which the multipliers predict a factor of 10⁶ (a
            // deviation of 1e-9 of the scales stays within the linear range when it grows),
            // so that the largest multiplier's mode dominates whatever share of the start's
            // deviation it holds.
            let n = (1e6f64.ln() / rho.ln().abs()).floor().clamp(1.0, 4000.0) as usize;
            let mut z = star.clone();
            let d0 = 1e-9;
            for i in 0..z.len() {
                let scale = if i < z.len() / 2 {
                    length_scale(&params)
                } else {
                    speed_scale(&params)
                };
                z[i] += d0 * scale * if i % 2 == 0 { 1.0 } else { -1.0 } / (z.len() as f64).sqrt();
            }
            let first = size(&params, &(&z - &star));
            for _ in 0..n {
                z = fd::run(&params, &z, Horizon::Periods(branch.period))
                    .expect("a plain run")
                    .0;
            }
            let last = size(&params, &(&z - &star));
            let factor = last / first;
            println!(
                "branch {b} (period {}), Ω = {:.7}: ρ = {rho:.5}, after {n} orbit periods the deviation changed by {factor:.3e}",
                branch.period, p.parameter
            );
            if p.stable {
                stable += 1;
                assert!(
                    factor < 0.1,
                    "stable point at {} came back by {factor} only",
                    p.parameter
                );
            } else {
                unstable += 1;
                assert!(
                    factor > 10.0,
                    "unstable point at {} left by {factor} only",
                    p.parameter
                );
            }
        }
    }
    println!("{stable} stable and {unstable} unstable points checked");
    assert!(stable >= 5 && unstable >= 5, "{stable} {unstable}");
}
