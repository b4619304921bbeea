//! A sweep point's label must be the attractor its run reaches from its start: adaptive
//! settling once accepted a stable orbit found by Newton shooting that the run never
//! approached (the chatter chain at Ω = 1.19, labelled period 1 while its run from rest
//! ends on period 7). The truth here is a plain run of 3000 transient periods from the same
//! start, judged on bistable cases: the chatter chain, the paper's Fig. 7 chain at
//! R_δ = 1.09 (two coexisting period-1 orbits) started in each basin and between them, and
//! the impact oscillator at Ω = 3.05, where a period-2 orbit coexists with an irregular
//! attractor.

use vibrotribo::config::Config;
use vibrotribo::study::{AutoSettle, Motion, PointOptions, PointResult, SettleMode, run_point};
use vibrotribo::{ChainParams, ChainState, SimOptions};

pub(crate) fn config(base: Config, keys: &[(&str, toml::Value)]) -> Config {
    let mut c = base;
    c.set_all(keys.iter().map(|(k, v)| (*k, v.clone()))).unwrap();
    c
}

pub(crate) fn float(x: f64) -> toml::Value {
    toml::Value::Float(x)
}

pub(crate) fn array(v: &[f64]) -> toml::Value {
    toml::Value::Array(v.iter().map(|&x| toml::Value::Float(x)).collect())
}

pub(crate) fn options(transient: u64, settle: SettleMode) -> PointOptions {
    PointOptions {
        transient_periods: transient,
        recorded_periods: 100,
        settle,
        classify: true,
        ..PointOptions::default()
    }
}

/// The default sweep's point (`--settle auto`, 300 + 100 periods) and the plain run of 3000
/// transient and 100 recorded periods from the same start.
pub(crate) fn judged(
    params: &ChainParams,
    start: &ChainState,
    sim: &SimOptions,
) -> (PointResult, PointResult) {
    let auto = run_point(
        params,
        start,
        sim,
        None,
        &options(300, SettleMode::Auto(AutoSettle::default())),
    )
    .unwrap();
    let long = run_point(params, start, sim, None, &options(3000, SettleMode::Fixed)).unwrap();
    (auto, long)
}

/// The label agrees with the long run: the same minimal period and impacts per period where
/// the long run is periodic, not periodic where it is not.
pub(crate) fn assert_agrees(what: &str, auto: &PointResult, long: &PointResult) {
    let (a, l) = (auto.motion.as_ref().unwrap(), long.motion.as_ref().unwrap());
    println!(
        "{what}: auto {} period {} ({:?}, coexisting {:?}, {} settling periods), long {} period {}",
        a.motion,
        auto.period(),
        a.label_source,
        a.coexisting,
        a.settle_periods,
        l.motion,
        long.period()
    );
    if l.motion == Motion::Periodic {
        assert_eq!(a.motion, Motion::Periodic, "{what}: {a:?}");
        assert_eq!(auto.period(), long.period(), "{what}: {a:?}");
        let (ia, il) = (auto.total_impacts_per_period(), long.total_impacts_per_period());
        // Over 100 recorded periods an orbit of period p counts impacts over whole orbits
        // and at most one partial one.
        let slack = auto.period() as f64 * il / 100.0 + 1e-9;
        assert!((ia - il).abs() <= slack, "{what}: impacts {ia} vs {il}");
        assert!(a.label_source.is_some(), "{what}: {a:?}");
    } else {
        assert_ne!(a.motion, Motion::Periodic, "{what}: {a:?}");
    }
}

/// The chatter case at Ω = 1.19 from rest: a stable period-1 orbit lies near the run's early
/// transient, but the run goes to a period-7 orbit. The label is the run's, and the orbit
/// it does not approach is reported as coexisting.
#[test]
fn chatter_chain_at_omega_1_19_is_labelled_with_the_orbit_its_run_reaches() {
    let c = config(
        Config::default(),
        &[
            ("oscillator.masses", array(&[0.05, 0.15, 0.05])),
            ("oscillator.gaps", array(&[0.005, 0.005])),
            ("excitation.omega_ratio", float(1.19)),
        ],
    );
    let params = c.chain();
    let (auto, long) = judged(params, &ChainState::at_rest(3), c.sim_options());
    assert_agrees("chatter Ω = 1.19", &auto, &long);
    let m = auto.motion.as_ref().unwrap();
    if let Some((p, radius)) = m.coexisting {
        assert_ne!(p as usize, auto.period(), "{m:?}");
        assert!(radius < 1.0, "{m:?}");
    }
}

/// Fig. 7's chain (m = 90, 120, 90 g, Ω = 0.70) at spacing ratio `r`.
pub(crate) fn fig7(r: f64) -> Config {
    config(
        Config::default(),
        &[
            ("oscillator.masses", array(&[0.09, 0.12, 0.09])),
            ("gap_ratio", float(r)),
        ],
    )
}

/// The final state of a continuation in R_δ from `from` (from rest) to 1.09 in 5 steps of
/// 300 + 100 periods: on the four-impact orbit from 1.0, on the two-impact one from 1.2.
pub(crate) fn continued(from: f64) -> ChainState {
    let mut state = ChainState::at_rest(3);
    for k in 0..=5 {
        let c = fig7(from + (1.09 - from) * k as f64 / 5.0);
        let p = run_point(
            c.chain(),
            &state,
            c.sim_options(),
            None,
            &options(300, SettleMode::Fixed),
        )
        .unwrap();
        state = p.final_state;
    }
    state
}

/// Fig. 7's chain (m = 90, 120, 90 g, Ω = 0.70) at R_δ = 1.09, where a four-impact and a
/// two-impact period-1 orbit coexist: started on each orbit's side (the states continuation
/// sweeps from R_δ = 1 and 1.2 end in), between them, and from rest.
#[test]
fn fig7_chain_at_r_delta_1_09_is_labelled_from_each_basin() {
    let (up, down) = (continued(1.0), continued(1.2));
    let mid = ChainState {
        positions: up
            .positions
            .iter()
            .zip(&down.positions)
            .map(|(a, b)| 0.5 * (a + b))
            .collect(),
        velocities: up
            .velocities
            .iter()
            .zip(&down.velocities)
            .map(|(a, b)| 0.5 * (a + b))
            .collect(),
    };
    let c = fig7(1.09);
    let mut impacts = Vec::new();
    for (what, start) in [
        ("up", &up),
        ("down", &down),
        ("between", &mid),
        ("rest", &ChainState::at_rest(3)),
    ] {
        let (auto, long) = judged(c.chain(), start, c.sim_options());
        assert_agrees(what, &auto, &long);
        impacts.push(long.total_impacts_per_period());
    }
    // The two continued states are on the two different attractors.
    assert!((impacts[0] - impacts[1]).abs() > 1.0, "{impacts:?}");
}

/// A fixed-seed generator (64-bit LCG, Knuth's constants), uniform in [0, 1).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The impact oscillator at Ω = 3.05: a period-2 orbit and an irregular attractor share the
/// starts of the box [−A, 0] × ±A·ω (the stop is at the static position). From each of 12 starts the label is the attractor the long
/// run from that start is on.
#[test]
fn impact_oscillator_with_an_orbit_beside_an_irregular_attractor() {
    let base = Config::from_toml_str(include_str!("../../../../configs/impact_oscillator.toml")).unwrap();
    let c = config(base, &[("excitation.omega_ratio", float(3.05))]);
    let params = c.chain();
    let (a, v) = (
        params.excitation.amplitude,
        params.excitation.amplitude * params.omega(),
    );
    let mut rng = Lcg(5);
    let mut kinds = Vec::new();
    for k in 0..12 {
        let start = ChainState {
            // At or below the stop, which sits at the static position.
            positions: vec![-a * rng.next()],
            velocities: vec![v * (2.0 * rng.next() - 1.0)],
        };
        let (auto, long) = judged(params, &start, c.sim_options());
        assert_agrees(&format!("start {k}"), &auto, &long);
        kinds.push(long.period());
    }
    // Both attractors are met.
    assert!(kinds.contains(&0) && kinds.iter().any(|&p| p > 0), "{kinds:?}");
}

/// A chain started next to the unstable orbit between the two basins of Fig. 7's chain at
/// R_δ = 1.09: the segment between a state on each attractor is bisected to the basin
/// boundary (whose points run onto the saddle orbit between them), and runs from either side
/// of it, within 2⁻¹² of the segment, linger near the saddle and leave it. The label is where
/// the run goes.
#[test]
fn a_run_started_at_the_basin_boundary_is_labelled_where_it_goes() {
    let c = fig7(1.09);
    let params = c.chain();
    let impacts = |s: &ChainState| {
        run_point(
            params,
            s,
            c.sim_options(),
            None,
            &options(1000, SettleMode::Fixed),
        )
        .unwrap()
        .total_impacts_per_period()
    };
    let (up, down) = (continued(1.0), continued(1.2));
    let ia = impacts(&up);
    let mix = |t: f64| ChainState {
        positions: up
            .positions
            .iter()
            .zip(&down.positions)
            .map(|(a, b)| a + t * (b - a))
            .collect(),
        velocities: up
            .velocities
            .iter()
            .zip(&down.velocities)
            .map(|(a, b)| a + t * (b - a))
            .collect(),
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..12 {
        let m = 0.5 * (lo + hi);
        if (impacts(&mix(m)) - ia).abs() < 0.5 {
            lo = m;
        } else {
            hi = m;
        }
    }
    for t in [lo, hi] {
        let (auto, long) = judged(params, &mix(t), c.sim_options());
        assert_agrees(&format!("boundary side t = {t}"), &auto, &long);
    }
}
