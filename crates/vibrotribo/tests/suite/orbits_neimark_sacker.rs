//! The paper's default case continued down from Ω = 0.7: its symmetric period-1 orbit loses
//! stability at a Neimark–Sacker point. Checked against direct simulation, not against the
//! code's own monodromy matrix: the Jacobian of the stroboscopic map by central differences
//! of plain runs has a complex pair that crosses the unit circle where the located point
//! says, at its angle; and a run started next to the orbit spirals in on one side and out on
//! the other, turning by that angle each period.

use nalgebra::{DMatrix, DVector};
use vibrotribo::ChainParams;
use vibrotribo::orbits::{
    BifurcationKind, ContinuationOptions, ShootingOptions, continue_orbit, find_periodic_orbit,
};
use vibrotribo::sensitivity::{Horizon, length_scale, speed_scale, state_vector};

use super::common::default_case::{chain, start_orbit};
use super::common::fd;

/// The Jacobian of the one-period stroboscopic map at `z` by central differences of plain
/// runs, each coordinate stepped by 1e-6 of its scale.
fn fd_jacobian(params: &ChainParams, z: &DVector<f64>) -> DMatrix<f64> {
    let n = z.len();
    let (lx, lv) = (length_scale(params), speed_scale(params));
    let mut j = DMatrix::zeros(n, n);
    for c in 0..n {
        let h = 1e-6 * if c < n / 2 { lx } else { lv };
        let mut plus = z.clone();
        plus[c] += h;
        let mut minus = z.clone();
        minus[c] -= h;
        let (zp, _) = fd::run(params, &plus, Horizon::Periods(1)).expect("a plain run");
        let (zm, _) = fd::run(params, &minus, Horizon::Periods(1)).expect("a plain run");
        j.set_column(c, &((zp - zm) / (2.0 * h)));
    }
    j
}

/// The complex pair of `j` nearest the unit circle: (modulus, |angle|).
fn pair(j: DMatrix<f64>) -> (f64, f64) {
    let m = j
        .complex_eigenvalues()
        .iter()
        .filter(|m| m.im.abs() > 1e-9)
        .min_by(|a, b| (a.norm() - 1.0).abs().total_cmp(&(b.norm() - 1.0).abs()))
        .copied()
        .expect("a complex pair");
    (m.norm(), m.arg().abs())
}

#[test]
fn a_neimark_sacker_point_is_where_direct_simulation_starts_to_spiral_out() {
    let start = start_orbit();
    let result = continue_orbit(
        "omega_ratio",
        chain,
        0.7,
        0.462,
        &start.state,
        1,
        &ContinuationOptions::default(),
    )
    .unwrap();
    let ns = result.branches[0]
        .bifurcations
        .iter()
        .find(|b| matches!(b.kind, BifurcationKind::NeimarkSacker { .. }))
        .expect("a Neimark–Sacker point");
    let BifurcationKind::NeimarkSacker { angle } = ns.kind else {
        unreachable!()
    };
    println!("Neimark–Sacker at Ω = {:.10}, angle {angle}", ns.parameter);

    // The finite-difference pair on either side: its modulus crosses 1 at the located point.
    let delta = 2e-4;
    let at = |omega: f64| {
        let o = find_periodic_orbit(&chain(omega), &ns.point.state, 1, &ShootingOptions::default()).unwrap();
        let z = state_vector(&o.state);
        (pair(fd_jacobian(&o.params, &z)), o)
    };
    let ((above, angle_above), orbit_above) = at(ns.parameter + delta);
    let ((below, angle_below), orbit_below) = at(ns.parameter - delta);
    println!(
        "finite differences: |μ| = {below} at Ω − δ, {above} at Ω + δ; angles {angle_below} {angle_above}"
    );
    assert!(above < 1.0 && below > 1.0, "{below} {above}");
    assert!(
        (0.5 * (angle_above + angle_below) - angle).abs() < 1e-3,
        "{angle}"
    );
    // Closer in, where the modulus is linear in Ω to well below the tolerance.
    let near = delta / 10.0;
    let ((above_near, _), _) = at(ns.parameter + near);
    let ((below_near, _), _) = at(ns.parameter - near);
    let crossing = ns.parameter - near + 2.0 * near * (below_near - 1.0) / (below_near - above_near);
    println!("finite differences cross at {crossing}");
    assert!(
        (crossing - ns.parameter).abs() < 1e-7,
        "finite differences cross at {crossing}, the point is at {}",
        ns.parameter
    );

    // Direct simulation from the orbit, perturbed: the deviation spirals in above and out
    // below, at the rate of the pair and turning by its angle each period.
    for (orbit, modulus, grows) in [(&orbit_above, above, false), (&orbit_below, below, true)] {
        let star = state_vector(&orbit.state);
        let mut z = star.clone();
        z[0] += 1e-7 * length_scale(&orbit.params);
        let periods = 1500;
        let mut deviations = Vec::with_capacity(periods);
        for _ in 0..periods {
            z = fd::run(&orbit.params, &z, Horizon::Periods(1))
                .expect("a plain run")
                .0;
            deviations.push(&z - &star);
        }
        // The rate from the deviation's size over whole periods, after the faster modes have
        // died out: ln d(n) on a line of slope ln |μ|, through its oscillation with the angle.
        let log_size = |n: usize| deviations[n].norm().ln();
        let (n0, n1) = (300, periods - 1);
        let rate = ((log_size(n1) - log_size(n0)) / (n1 - n0) as f64).exp();
        println!(
            "Ω = {}: deviation rate {rate} per period, pair modulus {modulus}",
            orbit.params.omega_ratio()
        );
        assert_eq!(rate > 1.0, grows, "{rate}");
        assert!(
            (rate - modulus).abs() < 0.2 * (modulus - 1.0).abs(),
            "{rate} vs {modulus}"
        );
        // The turn per period from the sign changes of one coordinate of the deviation,
        // r^n cos(nθ + φ) sampled once a period: 2 per turn, θ/π per period (θ < π).
        let changes = (n0..n1)
            .filter(|&n| deviations[n][0].signum() != deviations[n + 1][0].signum())
            .count();
        let turn = std::f64::consts::PI * changes as f64 / (n1 - n0) as f64;
        println!("  turn per period {turn} rad (the located angle {angle})");
        assert!((turn - angle).abs() < 1e-2, "{turn} vs {angle}");
    }
}
