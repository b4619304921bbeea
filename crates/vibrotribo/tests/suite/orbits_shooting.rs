//! Periodic orbits by shooting against truth from outside the solver: the forced response
//! and the multipliers exp(λT) of a chain that never touches, the long-run motion of the
//! paper's default case, the decay and growth of perturbations measured by direct
//! simulation, and the error reports.

use crate::common;

use common::Lcg;
use nalgebra::{Complex, DMatrix, DVector};
use vibrotribo::orbits::{
    NewtonFailure, OrbitError, ShootingOptions, find_periodic_orbit, periodic_orbit_from_transient,
};
use vibrotribo::sensitivity::{length_scale, state_from_vector, state_vector};
use vibrotribo::{ChainParams, ChainState, Excitation, Frequency, SimOptions, Simulator};

/// The state after `periods` excitation periods from `z` at t = 0.
fn advance(params: &ChainParams, z: &DVector<f64>, periods: u32) -> DVector<f64> {
    let mut sim = Simulator::new(params, &state_from_vector(z.as_slice()), SimOptions::default()).unwrap();
    sim.run_until(f64::from(periods) * params.period(), &mut ())
        .unwrap();
    state_vector(&sim.state())
}

/// The two-mass chain of the period-doubling tests: m = (50, 100) g, k = (120, 50) N/m,
/// δ = 10 mm, μ = 0.5, A = 50 mm.
fn pair(omega: f64) -> ChainParams {
    ChainParams {
        masses: vec![0.05, 0.1],
        stiffness: vec![120.0, 50.0],
        damping: vec![0.02, 0.02],
        gaps: vec![0.01],
        restitution: 0.5,
        excitation: Excitation {
            amplitude: 0.05,
            frequency: Frequency::OmegaRatio(omega),
        },
        stops: Default::default(),
        forces: Vec::new(),
    }
}

#[test]
fn impact_free_orbit_is_the_forced_response_with_multipliers_exp_lambda_t() {
    let mut rng = Lcg(99);
    for n in 2..=5 {
        let params = ChainParams {
            masses: (0..n).map(|_| rng.range(0.03, 0.2)).collect(),
            stiffness: (0..n).map(|_| rng.range(80.0, 200.0)).collect(),
            damping: (0..n).map(|_| rng.range(0.005, 0.3)).collect(),
            gaps: vec![10.0; n - 1],
            restitution: 0.6,
            excitation: Excitation {
                amplitude: 0.03,
                frequency: Frequency::OmegaRatio(rng.range(0.3, 1.5)),
            },
            stops: Default::default(),
            forces: Vec::new(),
        };
        let orbit =
            find_periodic_orbit(&params, &ChainState::at_rest(n), 1, &ShootingOptions::default()).unwrap();
        assert!(orbit.events.is_empty());
        let (w, a, t) = (params.omega(), params.excitation.amplitude, params.period());
        let mut expected = Vec::new();
        for i in 0..n {
            let (m, k, c) = (params.masses[i], params.stiffness[i], params.damping[i]);
            // y = A sin ωt = Im(A e^{iωt}); x = Im(X e^{iωt}) with X = (k + icω)A / (k − mω² + icω).
            let x = Complex::new(k, c * w) * a / Complex::new(k - m * w * w, c * w);
            let (x0, v0) = (x.im, w * x.re);
            assert!(
                (orbit.state.positions[i] - x0).abs() < 1e-12 * (1.0 + x0.abs()),
                "N = {n}, x{i}"
            );
            assert!(
                (orbit.state.velocities[i] - v0).abs() < 1e-11 * (1.0 + v0.abs()),
                "N = {n}, v{i}"
            );
            // λ² + (c/m)λ + k/m = 0.
            let disc = Complex::new((c / m).powi(2) - 4.0 * k / m, 0.0).sqrt();
            for s in [1.0, -1.0] {
                expected.push(((Complex::new(-c / m, 0.0) + disc * s) * 0.5 * t).exp());
            }
        }
        for mu in &orbit.multipliers {
            let nearest = expected
                .iter()
                .map(|e| (e - mu).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(nearest < 1e-10, "N = {n}: multiplier {mu} not among {expected:?}");
        }
        assert!(orbit.stable);
    }
}

#[test]
fn default_case_orbit_from_a_short_transient_is_the_long_run_motion() {
    let params = ChainParams::default();
    let orbit = periodic_orbit_from_transient(
        &params,
        &ChainState::at_rest(3),
        3,
        Some(1),
        &ShootingOptions::default(),
    )
    .unwrap();
    println!("residuals {:?}", orbit.residuals);
    assert!(orbit.residual <= 1e-12);
    assert!(orbit.residuals.len() >= 4, "Newton should have had work to do");
    // Quadratic convergence: the last step squares the error (up to a constant).
    let r = &orbit.residuals;
    let (a, b) = (r[r.len() - 3], r[r.len() - 2]);
    assert!(b < 10.0 * a * a.sqrt(), "not converging fast: {r:?}");
    // The motion from rest after 400 periods.
    let long = advance(&params, &state_vector(&ChainState::at_rest(3)), 400);
    let err = (long - state_vector(&orbit.state)).amax() / length_scale(&params);
    assert!(err < 1e-10, "orbit vs 400 periods of simulation: {err:e}");
    assert!(orbit.stable);
    assert_eq!(orbit.impacts_per_period(), vec![3.0, 3.0]);
    // The period read off the transient.
    let detected = periodic_orbit_from_transient(
        &params,
        &ChainState::at_rest(3),
        50,
        None,
        &ShootingOptions::default(),
    )
    .unwrap();
    assert_eq!(detected.period, 1);
}

/// Least-squares fit of δ_{k+2} = p δ_{k+1} + q δ_k over the measured deviations: the roots
/// of x² − p x − q are the dominant pair of multipliers (Prony's method).
fn prony(deviations: &[DVector<f64>]) -> [Complex<f64>; 2] {
    let (mut a, mut b) = (DMatrix::<f64>::zeros(2, 2), DVector::<f64>::zeros(2));
    for w in deviations.windows(3) {
        for ((d0, d1), d2) in w[0].iter().zip(w[1].iter()).zip(w[2].iter()) {
            let row = [*d1, *d0];
            for r in 0..2 {
                for c in 0..2 {
                    a[(r, c)] += row[r] * row[c];
                }
                b[r] += row[r] * d2;
            }
        }
    }
    let pq = a.lu().solve(&b).unwrap();
    let disc = Complex::new(pq[0] * pq[0] + 4.0 * pq[1], 0.0).sqrt();
    [(disc + pq[0]) * 0.5, (-disc + pq[0]) * 0.5]
}

#[test]
fn dominant_multipliers_match_the_decay_of_a_perturbation() {
    // Default case: a stable orbit whose dominant multipliers are a complex pair. Perturb the
    // orbit in an arbitrary direction, simulate, and read the decay off the deviations once
    // the next pair (|λ| = 0.53 against 0.79) has died out (periods 30–60: 0.67³⁰ ≈ 6e-6).
    let params = ChainParams::default();
    let orbit = periodic_orbit_from_transient(
        &params,
        &ChainState::at_rest(3),
        50,
        Some(1),
        &ShootingOptions::default(),
    )
    .unwrap();
    let z_star = state_vector(&orbit.state);
    let l = length_scale(&params);
    let v = l * params.omega();
    let direction = DVector::from_vec(vec![0.3, -0.5, 0.2, 0.4, 0.1, -0.6]);
    let scale = DVector::from_fn(6, |i, _| if i < 3 { l } else { v });
    let mut z = &z_star + direction.component_mul(&scale) * 1e-3;
    let mut deviations = Vec::new();
    for k in 0..61 {
        if k >= 30 {
            deviations.push((&z - &z_star).component_div(&scale));
        }
        z = advance(&params, &z, 1);
    }
    let fitted = prony(&deviations);
    let want = orbit.multipliers[0];
    println!(
        "multipliers {:?}; fitted from the simulation {fitted:?}",
        &orbit.multipliers[..2]
    );
    let err = fitted
        .iter()
        .map(|f| (f - want).norm().min((f - want.conj()).norm()))
        .fold(0.0, f64::max);
    assert!(
        err < 1e-4 * want.norm(),
        "dominant pair {want} vs decay {fitted:?}"
    );
}

#[test]
fn an_unstable_orbit_is_found_and_perturbations_grow_by_its_multiplier() {
    // Past its period doubling (Ω ≈ 0.5145) the pair's period-1 orbit is unstable with a
    // multiplier below −1; start Newton from the stable orbit at Ω = 0.512.
    let stable = periodic_orbit_from_transient(
        &pair(0.512),
        &ChainState::at_rest(2),
        400,
        Some(1),
        &ShootingOptions::default(),
    )
    .unwrap();
    assert!(stable.stable);
    let params = pair(0.518);
    let orbit = find_periodic_orbit(&params, &stable.state, 1, &ShootingOptions::default()).unwrap();
    assert!(orbit.residual <= 1e-12 && !orbit.stable);
    let lambda = orbit.multipliers[0];
    assert!(
        lambda.im.abs() < 1e-12 && lambda.re < -1.0,
        "{:?}",
        orbit.multipliers
    );
    // Direct simulation: deviations alternate in sign and grow by λ per period.
    let z_star = state_vector(&orbit.state);
    let mut z = z_star.clone();
    z[0] += 1e-9;
    let mut previous: Option<DVector<f64>> = None;
    let mut ratio = 0.0;
    for _ in 0..12 {
        z = advance(&params, &z, 1);
        let d = &z - &z_star;
        if let Some(p) = &previous {
            ratio = d.dot(p) / p.dot(p);
        }
        previous = Some(d);
    }
    println!("multiplier {lambda}, growth measured {ratio}");
    assert!(
        (ratio - lambda.re).abs() < 1e-3 * lambda.re.abs(),
        "{ratio} vs {lambda}"
    );
}

#[test]
fn an_orbit_with_sticking_has_two_zero_multipliers() {
    // The paper's chatter case at Ω = 0.60: every period a chatter sequence ends in sticking.
    let params = ChainParams::paper_chatter_case();
    let orbit = periodic_orbit_from_transient(
        &params,
        &ChainState::at_rest(3),
        100,
        Some(1),
        &ShootingOptions::default(),
    )
    .unwrap();
    assert!(
        orbit.sticks(),
        "{:?}",
        orbit.events.iter().map(|e| e.kind).collect::<Vec<_>>()
    );
    let zeros = orbit.multipliers.iter().filter(|m| m.norm() < 1e-10).count();
    println!("multipliers {:?}", orbit.multipliers);
    assert!(zeros >= 2, "{:?}", orbit.multipliers);
}

#[test]
fn failures_are_reported() {
    let params = ChainParams::default();
    let options = ShootingOptions::default();
    assert!(matches!(
        find_periodic_orbit(&params, &ChainState::at_rest(3), 0, &options),
        Err(OrbitError::ZeroPeriod)
    ));
    assert!(matches!(
        periodic_orbit_from_transient(&params, &ChainState::at_rest(3), 10, Some(0), &options),
        Err(OrbitError::ZeroPeriod)
    ));
    // Two iterations from rest are not enough: the residual history comes back.
    let short = ShootingOptions {
        max_iterations: 2,
        ..options.clone()
    };
    match find_periodic_orbit(&params, &ChainState::at_rest(3), 1, &short) {
        Err(OrbitError::NoConvergence {
            period,
            reason,
            residuals,
        }) => {
            assert_eq!(period, 1);
            assert!(matches!(
                reason,
                NewtonFailure::Iterations | NewtonFailure::LineSearch
            ));
            assert!(!residuals.is_empty() && residuals[0] > 1e-3, "{residuals:?}");
            let message = find_periodic_orbit(&params, &ChainState::at_rest(3), 1, &short)
                .unwrap_err()
                .to_string();
            assert!(message.contains("residuals ["), "{message}");
        }
        other => panic!("expected no convergence, got {other:?}"),
    }
    // A non-periodic motion (the pair with k₂ = 30 N/m, μ = 0.7 at Ω = 1.06): the period
    // cannot be read off the transient.
    let chaotic = ChainParams {
        stiffness: vec![120.0, 30.0],
        restitution: 0.7,
        ..pair(1.06)
    };
    match periodic_orbit_from_transient(&chaotic, &ChainState::at_rest(2), 300, None, &options) {
        Err(OrbitError::NotPeriodic { max_period, .. }) => assert_eq!(max_period, 64),
        Ok(o) => panic!("expected no period, found period {}", o.period),
        Err(e) => panic!("expected no period, got {e}"),
    }
}
