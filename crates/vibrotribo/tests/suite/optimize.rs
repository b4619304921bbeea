//! The design optimiser on problems whose optimum is known in closed form, and its errors.

use vibrotribo::config::Config;
use vibrotribo::optimize::{
    Cache, Constraint, Evaluation, OptimizeError, OptimizeOptions, Scale, Variable, optimize_with,
};

fn quiet(_: &[f64], _: &Evaluation, _: bool) {}
fn never() -> bool {
    false
}

/// Maximise f(x, y) = −(x − 0.8)² − (y − 0.7)² subject to x + y ≤ 1 on the unit square: the
/// unconstrained optimum (0.8, 0.7) is infeasible, and the constrained one is its projection
/// on the line x + y = 1, (0.55, 0.45), with f = −0.125 (Lagrange: ∇f parallel to (1, 1)).
#[test]
fn constrained_optimum_in_closed_form() {
    let eval = |u: &[f64]| {
        let f = -(u[0] - 0.8).powi(2) - (u[1] - 0.7).powi(2);
        Evaluation {
            values: u.to_vec(),
            objective: Some(f),
            score: Some(f),
            violation: (u[0] + u[1] - 1.0).max(0.0),
            ..Evaluation::default()
        }
    };
    let options = OptimizeOptions {
        particles: 20,
        swarm_iterations: 30,
        local_iterations: 200,
        seed: 3,
        ..OptimizeOptions::default()
    };
    let r = optimize_with(2, &options, &eval, &mut Cache::default(), &quiet, &never).unwrap();
    let (x, y) = (r.best_unit[0], r.best_unit[1]);
    assert!(r.best.feasible(), "{:?}", r.best);
    assert!(
        (x - 0.55).abs() < 0.01 && (y - 0.45).abs() < 0.01,
        "found ({x}, {y}), expected (0.55, 0.45)"
    );
    let f = r.best.objective.unwrap();
    assert!((f + 0.125).abs() < 1e-3, "f = {f}, expected −0.125");
    // The history never gets worse.
    let best: Vec<f64> = r.history.iter().filter_map(|h| h.best_objective).collect();
    assert!(best.windows(2).all(|w| w[1] >= w[0]), "{best:?}");
}

/// Seeded: the same seed retraces the same search; a cache filled by a first search serves a
/// second one entirely (the resumed search's path), with the same result.
#[test]
fn seeded_and_resumable() {
    let calls = std::sync::atomic::AtomicU64::new(0);
    let eval = |u: &[f64]| {
        calls.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        let f = (6.0 * u[0]).sin() * (4.0 * u[1]).cos() - 0.1 * u[0];
        Evaluation {
            values: u.to_vec(),
            objective: Some(f),
            score: Some(f),
            ..Evaluation::default()
        }
    };
    let options = OptimizeOptions {
        seed: 11,
        ..OptimizeOptions::default()
    };
    let mut cache = Cache::default();
    let a = optimize_with(2, &options, &eval, &mut cache, &quiet, &never).unwrap();
    let b = optimize_with(2, &options, &eval, &mut Cache::default(), &quiet, &never).unwrap();
    assert_eq!(a, b);
    // Half of the cache, as an interruption would leave it: the resumed search ends where
    // the uninterrupted one did.
    let before = calls.load(std::sync::atomic::Ordering::SeqCst);
    let resumed = optimize_with(2, &options, &eval, &mut cache, &quiet, &never).unwrap();
    assert_eq!(resumed, a);
    assert_eq!(
        calls.load(std::sync::atomic::Ordering::SeqCst),
        before,
        "served from the cache"
    );
    let other = optimize_with(
        2,
        &OptimizeOptions { seed: 12, ..options },
        &eval,
        &mut Cache::default(),
        &quiet,
        &never,
    )
    .unwrap();
    assert_ne!(other.history, a.history, "another seed, another search");
}

/// A stop request ends the search with an error, not a result.
#[test]
fn stop_ends_the_search() {
    let eval = |u: &[f64]| Evaluation {
        values: u.to_vec(),
        objective: Some(0.0),
        score: Some(0.0),
        ..Evaluation::default()
    };
    let stop = || true;
    let r = optimize_with(
        1,
        &OptimizeOptions::default(),
        &eval,
        &mut Cache::default(),
        &quiet,
        &stop,
    );
    assert!(matches!(r, Err(OptimizeError::Stopped { .. })), "{r:?}");
}

/// Bad input is an error naming it.
#[test]
fn errors_name_the_problem() {
    let c = Config::default();
    let v = Variable::parse(&c, "harvester.load_resistance=1e9..1e12").unwrap();
    assert_eq!(v.scale, Scale::Log);
    assert!((v.value(0.5) - 10f64.powf(10.5)).abs() < 1e-3 * 10f64.powf(10.5));
    assert!((v.unit(v.value(0.3)) - 0.3).abs() < 1e-12);
    assert_eq!(
        Variable::parse(&c, "mass_ratio=1.5..4").unwrap().scale,
        Scale::Linear
    );
    let e = Variable::parse(&c, "harvester.load_resistance=1e12..1e9").unwrap_err();
    assert!(matches!(e, OptimizeError::BadRange { .. }), "{e}");
    assert!(e.to_string().contains("harvester.load_resistance"), "{e}");
    let e = Variable::parse(&c, "harvester.no_such_key=1..2").unwrap_err();
    assert!(e.to_string().contains("harvester.no_such_key"), "{e}");
    let e = Variable::parse(&c, "mass_ratio=3").unwrap_err();
    assert!(matches!(e, OptimizeError::VarySyntax { .. }), "{e}");
    let e = Constraint::parse("breakdown_ratio<=-0.5").unwrap_err();
    assert!(matches!(e, OptimizeError::ImpossibleConstraint { .. }), "{e}");
    assert!(e.to_string().contains("breakdown_ratio"), "{e}");
    let e = Constraint::parse("sparks<=1").unwrap_err();
    assert!(e.to_string().contains("sparks"), "{e}");
    assert_eq!(Constraint::parse("max_displacement<=0.05").unwrap().bound, 0.05);
}
