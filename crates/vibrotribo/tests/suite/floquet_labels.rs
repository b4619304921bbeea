//! `--floquet` reports the largest multiplier of the orbit a point's run is on, and a stable
//! orbit its shots find that the run is not on as coexisting, never as the point's label: a
//! shot started at the window's end was taken for the point's orbit without a check that it
//! stayed there. The truth is outside the shooting: the decay of a perturbation of the long
//! run's state, simulated and fitted by Prony's method, and the plain long runs of
//! `labels.rs` on its bistable cases (Fig. 7's chain at R_δ = 1.09, whose two period-1
//! attractors have multipliers of different modulus; the impact oscillator at Ω = 3.05, a
//! period-2 orbit beside an irregular attractor; the chatter chain at Ω = 1.19).

use nalgebra::{Complex, DMatrix, DVector};
use vibrotribo::config::Config;
use vibrotribo::sensitivity::{length_scale, state_from_vector, state_vector};
use vibrotribo::study::{AutoSettle, Motion, PointOptions, PointResult, SettleMode, run_point};
use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator};

use crate::common::Lcg;
use crate::labels::{array, assert_agrees, config, continued, fig7, float, options};

/// The point with `--floquet` under both settle modes, and the plain run of 3000 transient
/// periods from the same start.
fn floquet_points(
    params: &ChainParams,
    start: &ChainState,
    sim: &SimOptions,
) -> (Vec<PointResult>, PointResult) {
    let points = [SettleMode::Fixed, SettleMode::Auto(AutoSettle::default())]
        .into_iter()
        .map(|settle| {
            let o = PointOptions {
                floquet: true,
                ..options(300, settle)
            };
            run_point(params, start, sim, None, &o).unwrap()
        })
        .collect();
    let long = run_point(params, start, sim, None, &options(3000, SettleMode::Fixed)).unwrap();
    (points, long)
}

/// The largest modulus of the dominant multipliers of the orbit through `on` (a state on a
/// stable orbit of `period` excitation periods), read off the decay of a perturbation by
/// direct simulation: Prony's fit δ_{k+2} = p δ_{k+1} + q δ_k over the returns `from..=to`
/// (each `period` periods), once the faster directions have died out; the perturbation is
/// `size` times the length scale Σδ + A (positions) and that times ω (velocities), small
/// enough to stay linear and large enough to stay above rounding over the returns read.
fn decay_rate(
    params: &ChainParams,
    on: &ChainState,
    period: u32,
    (from, to): (usize, usize),
    size: f64,
) -> f64 {
    let n = params.len();
    let l = length_scale(params);
    let scale = DVector::from_fn(2 * n, |i, _| if i < n { l } else { l * params.omega() });
    let star = state_vector(on);
    let direction = DVector::from_fn(2 * n, |i, _| [0.3, -0.5, 0.2, 0.4, 0.1, -0.6][i % 6]);
    let mut z = &star + direction.component_mul(&scale) * size;
    let mut deviations = Vec::new();
    for k in 0..=to {
        if k >= from {
            deviations.push((&z - &star).component_div(&scale));
        }
        let mut sim =
            Simulator::new(params, &state_from_vector(z.as_slice()), SimOptions::default()).unwrap();
        sim.run_until(f64::from(period) * params.period(), &mut ())
            .unwrap();
        z = state_vector(&sim.state());
    }
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
    ((disc + pq[0]) * 0.5).norm().max(((-disc + pq[0]) * 0.5).norm())
}

#[test]
fn fig7_chain_reports_the_multiplier_of_the_orbit_each_run_reaches() {
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
    let params = c.chain();
    let mut rates = Vec::new();
    for (what, start) in [
        ("up", &up),
        ("down", &down),
        ("between", &mid),
        ("rest", &ChainState::at_rest(3)),
    ] {
        let (points, long) = floquet_points(params, start, c.sim_options());
        let decay = decay_rate(params, &long.final_state, 1, (60, 200), 1e-4);
        for p in &points {
            assert_agrees(what, p, &long);
            let m = p.motion.as_ref().unwrap();
            let radius = *p.max_abs_multiplier.as_ref().unwrap().as_ref().unwrap();
            println!(
                "{what} ({}): max |μ| {radius}, decay of a perturbation {decay}, coexisting {:?}",
                m.settle_ending.as_str(),
                m.coexisting
            );
            assert!((radius - decay).abs() < 1e-5, "{what}: {radius} vs decay {decay}");
        }
        rates.push((long.total_impacts_per_period(), decay));
    }
    // The two attractors' multipliers differ by more than the check's tolerance, so a
    // multiplier taken from the other orbit would fail it.
    let (four, two) = rates.iter().partition::<Vec<&(f64, f64)>, _>(|(i, _)| *i > 3.0);
    assert!(!four.is_empty() && !two.is_empty(), "{rates:?}");
    assert!((four[0].1 - two[0].1).abs() > 2e-3, "{rates:?}");
}

/// The impact oscillator at Ω = 3.05 from the 12 starts of `labels.rs`: the label is the
/// attractor of the long run from each start (the period-2 orbit or the irregular one); the
/// periodic points' multiplier is the decay rate of the period-2 orbit, and a coexisting orbit,
/// where one is reported beside the irregular attractor, is that orbit (its period and
/// multiplier).
#[test]
fn impact_oscillator_reports_the_period_2_orbit_beside_the_irregular_attractor_only_as_coexisting() {
    let base = Config::from_toml_str(include_str!("../../../../configs/impact_oscillator.toml")).unwrap();
    let c = config(base, &[("excitation.omega_ratio", float(3.05))]);
    let params = c.chain();
    let (a, v) = (
        params.excitation.amplitude,
        params.excitation.amplitude * params.omega(),
    );
    let mut rng = Lcg(5);
    let mut orbit_rate = None;
    let mut seen = Vec::new();
    for k in 0..12 {
        let start = ChainState {
            positions: vec![-a * rng.next()],
            velocities: vec![v * (2.0 * rng.next() - 1.0)],
        };
        let (points, long) = floquet_points(params, &start, c.sim_options());
        for p in &points {
            assert_agrees(&format!("start {k}"), p, &long);
            let m = p.motion.as_ref().unwrap();
            seen.push((m.motion, m.coexisting));
            if m.motion == Motion::Periodic {
                assert_eq!(p.period(), 2, "start {k}: {m:?}");
                let rate = *orbit_rate
                    .get_or_insert_with(|| decay_rate(params, &long.final_state, 2, (2, 20), 1e-7));
                let radius = *p.max_abs_multiplier.as_ref().unwrap().as_ref().unwrap();
                assert!(
                    (radius - rate).abs() < 2e-5 * rate,
                    "start {k}: {radius} vs decay {rate}"
                );
                assert_eq!(m.coexisting, None, "start {k}: {m:?}");
            } else {
                assert!(
                    p.max_abs_multiplier.is_none(),
                    "start {k}: {:?}",
                    p.max_abs_multiplier
                );
            }
        }
    }
    println!("{seen:?}, period-2 decay rate {orbit_rate:?}");
    let rate = orbit_rate.expect("the period-2 orbit is met");
    for (motion, coexisting) in seen {
        if let Some((period, radius)) = coexisting {
            assert_ne!(motion, Motion::Periodic);
            assert_eq!(period, 2, "{coexisting:?}");
            assert!((radius - rate).abs() < 2e-5 * rate, "{radius} vs decay {rate}");
        }
    }
}

/// The chatter chain at Ω = 1.19 from rest: a period-7 attractor, whose multiplier the point
/// reports (the decay rate of its 7-period return), beside a stable period-1 orbit reported
/// only as coexisting.
#[test]
fn chatter_chain_at_omega_1_19_reports_the_period_7_multiplier() {
    let c = config(
        Config::default(),
        &[
            ("oscillator.masses", array(&[0.05, 0.15, 0.05])),
            ("oscillator.gaps", array(&[0.005, 0.005])),
            ("excitation.omega_ratio", float(1.19)),
        ],
    );
    let params = c.chain();
    let (points, long) = floquet_points(params, &ChainState::at_rest(3), c.sim_options());
    let rate = decay_rate(params, &long.final_state, 7, (10, 30), 1e-3);
    for p in &points {
        assert_agrees("chatter Ω = 1.19", p, &long);
        let m = p.motion.as_ref().unwrap();
        let radius = *p.max_abs_multiplier.as_ref().unwrap().as_ref().unwrap();
        println!(
            "{}: max |μ| {radius}, decay {rate}, coexisting {:?}",
            m.settle_ending.as_str(),
            m.coexisting
        );
        assert!((radius - rate).abs() < 1e-4 * rate, "{radius} vs decay {rate}");
        if let Some((period, radius)) = m.coexisting {
            assert_ne!(period as usize, p.period(), "{m:?}");
            assert!(radius < 1.0, "{m:?}");
        }
    }
}
