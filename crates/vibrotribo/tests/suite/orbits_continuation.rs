//! Continuation of periodic orbits against truth from outside it: where a brute-force
//! orbit diagram splits, the closed-form multipliers of a chain that never touches, and
//! independent shooting on either side of each located fold, Neimark–Sacker and grazing
//! point; the cascade and the ends of branches.

use nalgebra::{Complex, DMatrix, DVector};
use vibrotribo::orbits::{
    BifurcationKind, BranchEnd, ContinuationOptions, OrbitError, PeriodicOrbit, ShootingOptions,
    continue_orbit, find_periodic_orbit, periodic_orbit_from_transient,
};
use vibrotribo::sensitivity::state_vector;
use vibrotribo::{ChainParams, ChainState, Excitation, Frequency, SimOptions, Simulator};

/// A two-mass chain: m = (50, 100) g, k = (120, k₂) N/m, c = 0.02 N s/m, δ = 10 mm,
/// A = 50 mm.
fn pair(k2: f64, mu: f64, omega: f64) -> ChainParams {
    ChainParams {
        masses: vec![0.05, 0.1],
        stiffness: vec![120.0, k2],
        damping: vec![0.02, 0.02],
        gaps: vec![0.01],
        restitution: mu,
        excitation: Excitation {
            amplitude: 0.05,
            frequency: Frequency::OmegaRatio(omega),
        },
        stops: Default::default(),
        forces: Vec::new(),
    }
}

/// The default case with m₂ = R_m·m₁.
fn mass_ratio(rm: f64) -> ChainParams {
    let mut p = ChainParams::default();
    p.masses[1] = rm * p.masses[0];
    p
}

fn orbit(params: &ChainParams, transient: u32) -> PeriodicOrbit {
    periodic_orbit_from_transient(
        params,
        &ChainState::at_rest(params.len()),
        transient,
        Some(1),
        &ShootingOptions::default(),
    )
    .unwrap()
}

/// Least-squares polynomial of degree 2 through `(x, y)`; its root nearest `near`.
fn quadratic_root(points: &[(f64, f64)], near: f64) -> f64 {
    let (mut a, mut b) = (DMatrix::<f64>::zeros(3, 3), DVector::<f64>::zeros(3));
    for &(x, y) in points {
        let r = [1.0, x - near, (x - near).powi(2)];
        for i in 0..3 {
            for j in 0..3 {
                a[(i, j)] += r[i] * r[j];
            }
            b[i] += r[i] * y;
        }
    }
    let c = a.lu().solve(&b).unwrap();
    let disc = (c[1] * c[1] - 4.0 * c[2] * c[0]).sqrt();
    let roots = [(-c[1] + disc) / (2.0 * c[2]), (-c[1] - disc) / (2.0 * c[2])];
    near + if roots[0].abs() < roots[1].abs() {
        roots[0]
    } else {
        roots[1]
    }
}

#[test]
fn period_doubling_is_where_the_brute_force_orbit_diagram_splits() {
    let family = |omega: f64| pair(50.0, 0.5, omega);
    let start = orbit(&family(0.51), 300);
    let options = ContinuationOptions {
        doubling_depth: 1,
        ..ContinuationOptions::default()
    };
    let result = continue_orbit("omega_ratio", family, 0.51, 0.53, &start.state, 1, &options).unwrap();
    let main = &result.branches[0];
    let doublings: Vec<_> = main
        .bifurcations
        .iter()
        .filter(|b| b.kind == BifurcationKind::PeriodDoubling)
        .collect();
    assert_eq!(doublings.len(), 2, "{:?}", main.bifurcations);
    let pd = doublings[0];
    assert!(pd.precision <= 1e-8, "{}", pd.precision);
    let critical = pd
        .point
        .multipliers
        .iter()
        .map(|m| (m + 1.0).norm())
        .fold(f64::INFINITY, f64::min);
    assert!(critical < 1e-6, "no multiplier at −1: {:?}", pd.point.multipliers);
    // The doubled branch: born at the first doubling, stable, back on the orbit of period 1
    // at the second (a period-doubling bubble), followed once.
    assert_eq!(result.branches.len(), 2);
    let doubled = &result.branches[1];
    assert_eq!((doubled.period, doubled.parent), (2, Some((0, 0))));
    assert!(doubled.points[1].parameter > pd.parameter && doubled.points[1].stable);
    match doubled.end {
        BranchEnd::Collapsed { parameter } => assert!((parameter - doublings[1].parameter).abs() < 1e-4),
        ref e => panic!("the bubble should close at the second doubling, ended {e:?}"),
    }
    assert_eq!(doublings[1].child, Some(1));

    // Brute force: the 2-cycle's amplitude s after 8000 periods on Ω = 0.5146 … 0.5153, each
    // run from the previous one's end (as an orbit diagram is drawn), fitted by s² = quadratic
    // in Ω and extrapolated to zero.
    let mut state = start.state.clone();
    let mut squares = Vec::new();
    for j in 0..8 {
        let omega = 0.5146 + 1e-4 * f64::from(j);
        let params = family(omega);
        let mut sim = Simulator::new(&params, &state, SimOptions::default()).unwrap();
        sim.run_until(8000.0 * params.period(), &mut ()).unwrap();
        let a = sim.state();
        sim.run_until(8001.0 * params.period(), &mut ()).unwrap();
        state = sim.state();
        let s2: f64 = (0..2)
            .map(|i| (a.positions[i] - state.positions[i]).powi(2))
            .sum();
        squares.push((omega, s2));
    }
    let split = quadratic_root(&squares, 0.5146);
    println!(
        "period doubling: continuation {:.10}, brute-force split {split:.10}",
        pd.parameter
    );
    assert!((split - pd.parameter).abs() < 5e-6);
    // The brute-force 2-cycle at Ω = 0.5153 is the doubled branch's orbit there.
    let on_branch = doubled
        .points
        .iter()
        .min_by(|a, b| {
            (a.parameter - 0.5153)
                .abs()
                .total_cmp(&(b.parameter - 0.5153).abs())
        })
        .unwrap();
    let two = find_periodic_orbit(&family(0.5153), &on_branch.state, 2, &ShootingOptions::default()).unwrap();
    let z = state_vector(&two.state);
    let b0 = state_vector(&state);
    let mut sim1 = Simulator::new(&family(0.5153), &state, SimOptions::default()).unwrap();
    sim1.run_until(family(0.5153).period(), &mut ()).unwrap();
    let b1 = state_vector(&sim1.state());
    let err = (&z - &b0).amax().min((&z - &b1).amax());
    assert!(err < 1e-9, "2-cycle from shooting vs brute force: {err:e}");
    assert!(two.stable);
}

#[test]
fn an_impact_free_branch_has_the_closed_form_multipliers() {
    let family = |omega: f64| ChainParams {
        gaps: vec![10.0],
        ..pair(50.0, 0.5, omega)
    };
    let start = orbit(&family(0.5), 5);
    let result = continue_orbit(
        "omega_ratio",
        family,
        0.5,
        1.5,
        &start.state,
        1,
        &ContinuationOptions::default(),
    )
    .unwrap();
    let branch = &result.branches[0];
    assert!(branch.bifurcations.is_empty(), "{:?}", branch.bifurcations);
    assert_eq!(branch.end, BranchEnd::RangeEnd { parameter: 1.5 });
    assert!(branch.points.len() > 5);
    for point in &branch.points {
        let params = family(point.parameter);
        let t = params.period();
        for mu in &point.multipliers {
            let nearest = (0..2)
                .flat_map(|i| {
                    let (m, k, c) = (params.masses[i], params.stiffness[i], params.damping[i]);
                    let disc = Complex::new((c / m).powi(2) - 4.0 * k / m, 0.0).sqrt();
                    [1.0, -1.0].map(|s| ((Complex::new(-c / m, 0.0) + disc * s) * 0.5 * t).exp())
                })
                .map(|e| (e - mu).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(nearest < 1e-10, "Ω = {}: {mu}", point.parameter);
        }
    }
}

#[test]
fn a_fold_is_a_turning_point_of_the_orbits() {
    // Default case along R_m from 2.5 down: the branch turns back at R_m ≈ 2.3243.
    let start = orbit(&mass_ratio(2.5), 300);
    let result = continue_orbit(
        "mass_ratio",
        mass_ratio,
        2.5,
        1.2,
        &start.state,
        1,
        &ContinuationOptions::default(),
    )
    .unwrap();
    let branch = &result.branches[0];
    let fold = branch
        .bifurcations
        .iter()
        .find(|b| b.kind == BifurcationKind::Fold)
        .unwrap_or_else(|| panic!("{:?}", branch.bifurcations));
    assert!(fold.precision <= 1e-8);
    let p = fold.parameter;
    println!("fold at R_m = {p:.10}");
    // Every point of the branch lies on the side R_m ≥ fold; two orbits exist just above it,
    // none just below.
    assert!(branch.points.iter().all(|q| q.parameter >= p - 1e-9));
    let options = ShootingOptions::default();
    let above = mass_ratio(p + 1e-4);
    let (before, after): (Vec<_>, Vec<_>) = branch
        .points
        .iter()
        .partition(|q| q.arclength < fold.point.arclength);
    let one = find_periodic_orbit(&above, &before.last().unwrap().state, 1, &options).unwrap();
    let two = find_periodic_orbit(&above, &after.first().unwrap().state, 1, &options).unwrap();
    let distance = (state_vector(&one.state) - state_vector(&two.state)).amax();
    assert!(
        distance > 1e-4,
        "the two orbits above the fold coincide: {distance:e}"
    );
    let below = find_periodic_orbit(&mass_ratio(p - 1e-4), &fold.point.state, 1, &options);
    assert!(
        matches!(below, Err(OrbitError::NoConvergence { .. })),
        "{below:?}"
    );
}

#[test]
fn a_neimark_sacker_point_is_a_complex_pair_crossing_the_unit_circle() {
    let start = orbit(&mass_ratio(2.5), 300);
    let result = continue_orbit(
        "mass_ratio",
        mass_ratio,
        2.5,
        3.0,
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
    println!("Neimark–Sacker at R_m = {:.10}, angle {angle}", ns.parameter);
    let modulus = |rm: f64| {
        let o =
            find_periodic_orbit(&mass_ratio(rm), &ns.point.state, 1, &ShootingOptions::default()).unwrap();
        let pair = o
            .multipliers
            .iter()
            .filter(|m| m.im.abs() > 1e-9)
            .min_by(|a, b| (a.norm() - 1.0).abs().total_cmp(&(b.norm() - 1.0).abs()))
            .copied()
            .unwrap();
        (pair.norm(), pair.arg().abs())
    };
    let (below, angle_below) = modulus(ns.parameter - 1e-5);
    let (above, _) = modulus(ns.parameter + 1e-5);
    assert!((below - 1.0) * (above - 1.0) < 0.0, "{below} {above}");
    assert!((angle_below - angle).abs() < 1e-4);
}

#[test]
fn a_grazing_is_where_the_new_impact_speed_vanishes() {
    // Ω = 0.30, m₁ = m₃ = 50 g (the paper's Fig. 18): along R_m the impact-free orbit grazes
    // both contacts at once (the chain is symmetric); beyond, the new impacts' closing speed
    // grows in proportion to the distance from the grazing point (the fixed point of the
    // square-root map near grazing).
    let family = |rm: f64| ChainParams {
        masses: vec![0.05, rm * 0.05, 0.05],
        excitation: Excitation {
            frequency: Frequency::OmegaRatio(0.30),
            ..Excitation::default()
        },
        ..ChainParams::default()
    };
    let start = orbit(&family(2.0), 400);
    let options = ContinuationOptions {
        doubling_depth: 0,
        ..ContinuationOptions::default()
    };
    let result = continue_orbit("mass_ratio", family, 2.0, 2.9, &start.state, 1, &options).unwrap();
    let g = result.branches[0]
        .bifurcations
        .iter()
        .find(|b| matches!(b.kind, BifurcationKind::Grazing { appears: true, .. }))
        .expect("a grazing");
    assert!(g.precision <= 1e-8, "{}", g.precision);
    let after = g.after.as_ref().unwrap();
    println!(
        "grazing {:?} at {} ({:?}); after at {}: impacts {:?}, slowest {:?}",
        g.kind, g.parameter, g.crossing, after.parameter, after.impacts_per_period, after.min_closing_speed
    );
    // Independent shooting beyond the grazing point, and a linear fit of the speed.
    let loose = ShootingOptions {
        tolerance: 1e-10,
        max_iterations: 80,
        ..ShootingOptions::default()
    };
    let speeds: Vec<(f64, f64)> = [3e-4, 6e-4]
        .iter()
        .map(|d| {
            let p = g.parameter + d;
            let o = find_periodic_orbit(&family(p), &after.state, 1, &loose).unwrap();
            (p, o.min_closing_speed().unwrap().1)
        })
        .collect();
    let ((p1, v1), (p2, v2)) = (speeds[0], speeds[1]);
    let zero = p1 - v1 * (p2 - p1) / (v2 - v1);
    println!(
        "grazing at {:.10}; speeds {speeds:?} extrapolate to zero at {zero:.10}",
        g.parameter
    );
    assert!((zero - g.parameter).abs() < 1e-6);
    // Before it: no impact at all.
    let before = find_periodic_orbit(
        &family(g.parameter - 1e-4),
        &g.point.state,
        1,
        &ShootingOptions::default(),
    )
    .unwrap();
    assert_eq!(before.impacts_per_period(), vec![0.0, 0.0]);
}

#[test]
fn a_cascade_is_followed_to_the_requested_depth() {
    // k₂ = 30 N/m, μ = 0.7: doublings 1 → 2 → 4 → 8 → 16 near Ω = 1.04–1.07.
    let family = |omega: f64| pair(30.0, 0.7, omega);
    let start = orbit(&family(1.0), 300);
    let options = ContinuationOptions {
        doubling_depth: 4,
        ..ContinuationOptions::default()
    };
    let result = continue_orbit("omega_ratio", family, 1.0, 1.13, &start.state, 1, &options).unwrap();
    let periods: Vec<u32> = result.branches.iter().map(|b| b.period).collect();
    println!("periods {periods:?}");
    for (i, b) in result.branches.iter().enumerate().skip(1) {
        let (parent, k) = b.parent.expect("a doubled branch has a parent");
        assert_eq!(b.period, 2 * result.branches[parent].period);
        let pd = &result.branches[parent].bifurcations[k];
        assert_eq!(pd.kind, BifurcationKind::PeriodDoubling);
        assert_eq!(pd.child, Some(i));
        if let Some(first) = b.points.first() {
            assert!((first.parameter - pd.parameter).abs() < 1e-3);
        }
    }
    assert!(periods.contains(&16), "{periods:?}");
    assert!(result.branches.iter().all(|b| b.period <= 16));
    assert!(
        result
            .branches
            .iter()
            .any(|b| matches!(b.end, BranchEnd::CascadeDepth { .. })),
        "{:?}",
        result.branches.iter().map(|b| &b.end).collect::<Vec<_>>()
    );
}

#[test]
fn bad_input_and_chaotic_ranges_end_cleanly() {
    let family = |omega: f64| pair(30.0, 0.7, omega);
    let start = orbit(&family(1.0), 300);
    let options = ContinuationOptions::default();
    assert!(matches!(
        continue_orbit("omega_ratio", family, 1.0, 1.1, &start.state, 0, &options),
        Err(OrbitError::ZeroPeriod)
    ));
    assert!(matches!(
        continue_orbit("omega_ratio", family, 1.0, 1.0, &start.state, 1, &options),
        Err(OrbitError::Param(_))
    ));
    assert!(matches!(
        continue_orbit("omega_ratio", family, 1.0, f64::NAN, &start.state, 1, &options),
        Err(OrbitError::Param(_))
    ));
    // No orbit near the guess at `from`: Newton's failure with its residuals.
    let mut far = start.state.clone();
    far.velocities[0] += 5.0;
    let short = ContinuationOptions {
        shooting: ShootingOptions {
            max_iterations: 3,
            ..ShootingOptions::default()
        },
        ..options.clone()
    };
    assert!(matches!(
        continue_orbit("omega_ratio", family, 1.0, 1.1, &far, 1, &short),
        Err(OrbitError::NoConvergence { .. })
    ));
    // Through the chaotic window beyond Ω ≈ 1.065 with a small budget: every branch ends,
    // within the budget.
    let budget = ContinuationOptions {
        max_points: 60,
        max_branches: 4,
        doubling_depth: 8,
        ..options
    };
    let result = continue_orbit("omega_ratio", family, 1.0, 1.3, &start.state, 1, &budget).unwrap();
    assert!(result.branches.len() <= 4);
    assert!(result.branches.iter().all(|b| b.points.len() <= 60));
}
