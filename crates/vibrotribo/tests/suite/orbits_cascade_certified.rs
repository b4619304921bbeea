//! Every period doubling a continuation reports is one that direct simulation confirms. The
//! impact oscillator (50 g on 120 N/m, c = 0.02 N·s/m, base amplitude 10 mm, a stop fixed
//! 1 mm above, r = 0.8) is continued through its cascade as `vibrotribo continue` does from a
//! configuration, its first orbit shot after a transient from the steady motion at Ω = 3.4
//! (0.95 mm from rest) run at Ω = 3.6. On that path the period-16 branch's first step lands
//! past the next doubling and onto another orbit: `det(Φ + I)` changes sign between two
//! orbits that no multiplier crossing −1 joins. Truth from outside the continuation: the
//! period a long direct simulation settles to doubles across every doubling of the cascade,
//! and every period doubling reported anywhere is located to the location tolerance.

use vibrotribo::branch::{BranchOptions, continue_config};
use vibrotribo::config::Config;
use vibrotribo::orbits::{BifurcationKind, ContinuationOptions, cascade};
use vibrotribo::{ChainState, Simulator};

const CONFIG: &str = r#"
[oscillator]
masses = [0.05]
stiffness = 120.0
damping = 0.02

[oscillator.stops.upper]
gap = 0.001
restitution = 0.8
frame = "fixed"

[excitation]
amplitude = 0.01
omega_ratio = 2.5

[run]
periods = 200
transient_periods = 150
initial_positions = [-2.8778e-5]
initial_velocities = [-0.157720]
"#;

/// The stroboscopic period (1, 2, 4, … 64) the oscillator of `config` settles to at Ω from
/// `state` after 6000 periods of transient, by direct simulation; `None` if none repeats to
/// 1e-9 m over the next 256 periods.
fn brute_force_period(config: &Config, omega_ratio: f64, state: &ChainState) -> Option<usize> {
    let params = config
        .with("omega_ratio", toml::Value::Float(omega_ratio))
        .unwrap()
        .chain()
        .clone();
    let mut sim = Simulator::new(&params, state, config.sim_options().clone()).unwrap();
    let t = params.period();
    sim.run_until(6000.0 * t, &mut ()).unwrap();
    let mut x = Vec::new();
    for k in 1..=256 {
        sim.run_until((6000.0 + f64::from(k)) * t, &mut ()).unwrap();
        x.push(sim.state().positions[0]);
    }
    [1, 2, 4, 8, 16, 32, 64]
        .into_iter()
        .find(|&p| (0..x.len() - p).all(|i| (x[i] - x[i + p]).abs() < 1e-9))
}

#[test]
fn every_reported_doubling_of_the_cascade_is_where_the_brute_force_period_doubles() {
    let config = Config::from_toml_str(CONFIG).unwrap();
    let options = BranchOptions {
        period: Some(1),
        continuation: ContinuationOptions {
            doubling_depth: 4,
            ..ContinuationOptions::default()
        },
        ..BranchOptions::default()
    };
    let result = continue_config(&config, "omega_ratio", 3.6, 2.4, None, &options).unwrap();
    let chain = cascade(&result);
    let points: Vec<f64> = chain.iter().map(|b| b.parameter).collect();
    println!("cascade at {points:?}");
    assert!(points.len() >= 4, "{points:?}");
    assert!((points[0] - 2.4551988).abs() < 1e-6 && (points[1] - 2.4861677).abs() < 1e-6);
    // Direct simulation on either side of each doubling, a fifth of the way to its
    // neighbours (past the last, a fifth of the interval before it shrunk by 4.669), from the
    // orbit at the point: the branch's period before it, twice that after.
    let sign = (points[1] - points[0]).signum();
    for (k, b) in chain.iter().enumerate() {
        let p = b.parameter;
        let below = if k == 0 {
            0.2 * (points[1] - p).abs()
        } else {
            0.2 * (p - points[k - 1]).abs()
        };
        let above = match points.get(k + 1) {
            Some(q) => 0.2 * (q - p).abs(),
            None => 0.2 * (p - points[k - 1]).abs() / 4.669,
        };
        let period = 1usize << k;
        let before = brute_force_period(&config, p - sign * below, &b.point.state);
        let after = brute_force_period(&config, p + sign * above, &b.point.state);
        println!("doubling {k} at {p}: brute-force period {before:?} before, {after:?} after");
        assert_eq!(before, Some(period), "before the doubling at {p}");
        assert_eq!(after, Some(2 * period), "after the doubling at {p}");
    }
    // Every period doubling reported on any branch is located to the tolerance.
    let tolerance = options.continuation.location_tolerance;
    for (i, b) in result.branches.iter().enumerate() {
        println!("branch {i} (period {}): {:?}", b.period, b.end);
        for f in b
            .bifurcations
            .iter()
            .filter(|f| f.kind == BifurcationKind::PeriodDoubling)
        {
            println!("  period doubling at {} ± {:.1e}", f.parameter, f.precision);
            assert!(
                f.precision <= tolerance,
                "branch {i}: a period doubling at {} ± {:.1e}",
                f.parameter,
                f.precision
            );
        }
    }
}
