//! Attractors and basins against truth from outside the classification: the forced response
//! of a chain that never touches (one attractor, fraction 1, its closed-form section point),
//! the two coexisting motions behind the jump of the paper's Fig. 7 against the up and down
//! continuation sweeps, binomial convergence of the fractions, and independence of the
//! thread count.

use std::ops::ControlFlow;

use vibrotribo::ChainState;
use vibrotribo::attractors::{
    AttractorOptions, Fingerprint, RandomStarts, SectionScale, StartBox, StartRunner, ValueAttractors,
    attractors_across, classify, random_start,
};
use vibrotribo::config::Config;
use vibrotribo::study::PointOptions;
use vibrotribo::sweep::PointRunner;

fn config(keys: &[(&str, toml::Value)]) -> Config {
    let mut c = Config::default();
    c.set_all(keys.iter().map(|(k, v)| (*k, v.clone()))).unwrap();
    c
}

fn array(v: &[f64]) -> toml::Value {
    toml::Value::Array(v.iter().map(|&x| toml::Value::Float(x)).collect())
}

fn starts(config: Config, transient: u64, recorded: u64, mechanics_only: bool) -> StartRunner {
    let options = PointOptions {
        transient_periods: transient,
        recorded_periods: recorded,
        ..PointOptions::default()
    };
    StartRunner::new(
        PointRunner::new(config, options, mechanics_only),
        AttractorOptions::default(),
    )
    .unwrap()
}

/// K random starts of `runner`'s base configuration, classified.
fn random_starts(runner: &StartRunner, k: usize, seed: u64) -> (Vec<Option<Fingerprint>>, SectionScale) {
    let chain = runner.chain(&[]).unwrap();
    let fps = (0..k)
        .map(|s| {
            let start = random_start(&chain, &StartBox::of(&chain), seed, s as u64).unwrap();
            Some(runner.run(&[], Some(&start)).unwrap())
        })
        .collect();
    (fps, SectionScale::of(&chain))
}

#[test]
fn an_impact_free_chain_has_one_attractor_at_its_forced_response() {
    let c = config(&[("oscillator.gaps", array(&[10.0, 10.0]))]);
    let chain = c.chain().clone();
    let runner = starts(c, 500, 20, true);
    let (fps, scale) = random_starts(&runner, 12, 3);
    let cl = classify(&fps, &scale, runner.options());
    assert_eq!(cl.attractors.len(), 1, "{:?}", cl.attractors);
    let a = &cl.attractors[0];
    assert_eq!((a.period, a.starts), (1, 12));
    assert_eq!(cl.fraction(0), (1.0, 0.0));
    assert_eq!(a.impacts_per_period, 0.0);
    // x = Im(H A e^{iωt}), H = (k + icω)/(k − mω² + icω): at t = 0, x = A Im H, v = Aω Re H,
    // up to what is left of the start after 500 periods: e^{−(c/2m)·500T} ≈ e⁻¹⁹ of it.
    let (w, amp) = (chain.omega(), chain.excitation.amplitude);
    let decay = (0..3)
        .map(|i| (-chain.damping[i] / (2.0 * chain.masses[i]) * 500.0 * chain.period()).exp())
        .fold(0.0, f64::max);
    let b = StartBox::of(&chain);
    for i in 0..3 {
        let (m, k, cc) = (chain.masses[i], chain.stiffness[i], chain.damping[i]);
        let (nr, ni) = (k, cc * w);
        let (dr, di) = (k - m * w * w, cc * w);
        let d2 = dr * dr + di * di;
        let (hr, hi) = ((nr * dr + ni * di) / d2, (ni * dr - nr * di) / d2);
        let (x, v) = (amp * hi, amp * w * hr);
        // A velocity start of size V leaves V/ω_n in position and V in velocity.
        let wn = (k / m).sqrt();
        let left = 4.0 * decay * (b.positions + b.velocities / wn.min(w));
        assert!(
            (a.points[i] - x).abs() < left,
            "x{i}: {} vs {x} ({left})",
            a.points[i]
        );
        assert!(
            (a.points[3 + i] - v).abs() < left * wn,
            "v{i}: {} vs {v}",
            a.points[3 + i]
        );
    }
}

#[test]
fn the_default_case_is_multistable_and_each_attractor_is_a_stable_orbit_by_shooting() {
    // Starts from rest settle on the paper's six-impact orbit; random starts mostly find
    // five-impact orbits, some of them still ringing down (a multiplier near −1) at the
    // 1e-5 level after 500 periods: each attractor's section point is one Newton solve from
    // a stable periodic orbit.
    let runner = starts(Config::default(), 500, 100, true);
    let (fps, scale) = random_starts(&runner, 24, 2);
    let cl = classify(&fps, &scale, runner.options());
    let chain = runner.chain(&[]).unwrap();
    let impacts: Vec<f64> = cl.attractors.iter().map(|a| a.impacts_per_period).collect();
    println!(
        "impacts per period {impacts:?}, starts {:?}",
        cl.attractors.iter().map(|a| a.starts).collect::<Vec<_>>()
    );
    assert!(impacts.contains(&6.0) && impacts.contains(&5.0), "{impacts:?}");
    for a in &cl.attractors {
        assert_eq!(a.period, 1);
        let orbit = vibrotribo::orbits::find_periodic_orbit(
            &chain,
            &a.state(),
            1,
            &vibrotribo::orbits::ShootingOptions::default(),
        )
        .unwrap();
        assert!(orbit.stable, "{:?}", orbit.multipliers);
        let z = vibrotribo::sensitivity::state_vector(&orbit.state);
        for (i, (p, q)) in a.points.iter().zip(z.iter()).enumerate() {
            let d = scale.scaled(i, p - q).abs();
            assert!(
                d < runner.options().period_tolerance,
                "coordinate {i}: {p} vs {q}"
            );
        }
        println!(
            "orbit with {} impacts/period: largest multiplier {:.4}",
            a.impacts_per_period, orbit.multipliers[0]
        );
    }
}

#[test]
fn a_hyperchaotic_attractor_is_one_non_periodic_attractor() {
    // Fig. 14's chain at R_m = 6.54, Ω = 0.72: λ1 = 3.3, λ2 = 1.1 1/s (tests/suite/lyapunov.rs).
    let c = config(&[
        ("oscillator.masses", array(&[0.05, 0.327, 0.05])),
        ("omega_ratio", toml::Value::Float(0.72)),
    ]);
    let runner = starts(c, 300, 100, true);
    let (fps, scale) = random_starts(&runner, 12, 4);
    let cl = classify(&fps, &scale, runner.options());
    assert_eq!(
        cl.attractors.len(),
        1,
        "{:?}",
        cl.attractors.iter().map(|a| a.starts).collect::<Vec<_>>()
    );
    assert_eq!((cl.attractors[0].period, cl.attractors[0].starts), (0, 12));
}

/// Fig. 7's chain (m = 90, 120, 90 g, Ω = 0.70) at spacing ratio `r`.
fn fig7(r: f64) -> Config {
    config(&[
        ("oscillator.masses", array(&[0.09, 0.12, 0.09])),
        ("gap_ratio", toml::Value::Float(r)),
    ])
}

/// Where the two motions coexist with basins of comparable size.
const BISTABLE: f64 = 1.09;

/// The final state of a continuation sweep of R_δ from `from` to [`BISTABLE`] (from rest at
/// `from`).
fn continued_state(from: f64) -> ChainState {
    let options = PointOptions {
        transient_periods: 300,
        recorded_periods: 64,
        ..PointOptions::default()
    };
    let runner = PointRunner::new(fig7(1.0), options, true);
    let values = vibrotribo::sweep::grid(from, BISTABLE, 6);
    let order: Vec<usize> = (0..values.len()).collect();
    let (_, state) =
        vibrotribo::sweep::run_continued(&runner, "gap_ratio", &values, &order, None, |_, r, _| {
            r.map(|_| ControlFlow::Continue(()))
        })
        .unwrap();
    state.unwrap()
}

#[test]
fn the_jump_of_fig_7_hides_two_attractors_the_continuation_sweeps_find() {
    // `sweep --continuation up` from R_δ = 1 stays on a four-impact orbit up to R_δ ≈ 1.10,
    // `down` from 1.2 on a two-impact one down to R_δ = 1: both coexist at 1.09.
    let runner = starts(fig7(BISTABLE), 300, 64, true);
    let (fps, scale) = random_starts(&runner, 24, 1);
    let cl = classify(&fps, &scale, runner.options());
    for a in &cl.attractors {
        println!(
            "period {}, {} impacts/period, {} of 24 starts, section {:?}",
            a.period, a.impacts_per_period, a.starts, a.points
        );
    }
    assert_eq!(cl.attractors.len(), 2);
    assert!(cl.attractors.iter().all(|a| a.period == 1));
    let mut impacts: Vec<f64> = cl.attractors.iter().map(|a| a.impacts_per_period).collect();
    impacts.sort_by(f64::total_cmp);
    assert_eq!(impacts, [2.0, 4.0]);
    // Each attractor's section point is where one of the continuation sweeps ends.
    let l = scale.length;
    for (from, impacts) in [(1.0, 4.0), (1.2, 2.0)] {
        let z = continued_state(from);
        let a = cl
            .attractors
            .iter()
            .find(|a| a.impacts_per_period == impacts)
            .unwrap();
        for i in 0..3 {
            assert!(
                (a.points[i] - z.positions[i]).abs() < 1e-6 * l,
                "sweep from {from}: x{i} {} vs {}",
                a.points[i],
                z.positions[i]
            );
        }
    }
}

fn across(runner: &StartRunner, values: &[f64], samples: usize, seed: u64) -> Vec<ValueAttractors> {
    let sampling = RandomStarts {
        samples,
        seed,
        bounds: None,
    };
    attractors_across(runner, "gap_ratio", values, &sampling, 16, |_| {
        ControlFlow::Continue(())
    })
    .unwrap()
}

#[test]
fn fractions_converge_within_their_standard_errors() {
    let runner = starts(fig7(BISTABLE), 300, 64, true);
    let small = across(&runner, &[BISTABLE], 40, 11);
    let large = across(&runner, &[BISTABLE], 160, 12);
    let f = |v: &ValueAttractors, impacts: f64| {
        let c = &v.classification;
        let a = c
            .attractors
            .iter()
            .position(|a| a.impacts_per_period == impacts)
            .unwrap();
        c.fraction(a)
    };
    let ((f1, s1), (f2, s2)) = (f(&small[0], 4.0), f(&large[0], 4.0));
    println!("four-impact basin: {f1} ± {s1} (K = 40), {f2} ± {s2} (K = 160)");
    assert!(s2 < s1);
    assert!((f1 - f2).abs() < 3.0 * (s1 * s1 + s2 * s2).sqrt());
}

#[test]
fn attractors_across_a_parameter_do_not_depend_on_the_thread_count() {
    // With the harvester: the expected power is the fraction-weighted attractor power.
    let runner = starts(fig7(1.0), 200, 32, false);
    let values = [1.08, 1.09, 1.12, 1.14];
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| across(&runner, &values, 12, 5))
    };
    let one = run(1);
    assert_eq!(one, run(2));
    for v in &one {
        let c = &v.classification;
        let (p, _) = v.expected_power.unwrap();
        let weighted: f64 = (0..c.attractors.len())
            .map(|a| c.fraction(a).0 * c.attractors[a].power_w.unwrap())
            .sum();
        assert!((p - weighted).abs() < 1e-12 * p, "{p} vs {weighted}");
        println!(
            "R_δ = {}: ids {:?}, impacts {:?}, fractions {:?}",
            v.value,
            v.ids,
            c.attractors
                .iter()
                .map(|a| a.impacts_per_period)
                .collect::<Vec<_>>(),
            (0..c.attractors.len())
                .map(|a| c.fraction(a).0)
                .collect::<Vec<_>>()
        );
    }
    // The two orbits keep their identities from value to value; beyond the jump at
    // R_δ ≈ 1.10 the two-impact one is alone.
    let id = |v: &ValueAttractors, impacts: f64| {
        let c = &v.classification;
        let a = c.attractors.iter().position(|a| a.impacts_per_period == impacts);
        a.map(|a| v.ids[a])
    };
    assert_eq!(id(&one[0], 4.0), id(&one[1], 4.0));
    assert!(id(&one[1], 2.0).is_some());
    assert!(one[1..].iter().all(|v| id(v, 2.0) == id(&one[1], 2.0)));
    assert_eq!(one[3].classification.attractors.len(), 1);
}

#[test]
fn continuation_keeps_an_attractor_no_random_start_finds() {
    // Down from the bistable value: the two-impact orbit's basin shrinks below what 12
    // starts sample, but its seed from the value before still finds it (the `down` sweep
    // follows it to R_δ = 1).
    let runner = starts(fig7(1.0), 300, 32, true);
    let v = across(&runner, &[BISTABLE, 1.07, 1.05], 12, 5);
    let two = |v: &ValueAttractors| {
        let c = &v.classification;
        let a = c.attractors.iter().position(|a| a.impacts_per_period == 2.0)?;
        Some((v.ids[a], c.attractors[a].starts))
    };
    let (id, starts) = two(&v[0]).unwrap();
    assert!(starts > 0);
    for later in &v[1..] {
        let (i, s) = two(later).expect("the two-impact orbit is kept");
        println!("R_δ = {}: two-impact orbit id {i}, {s} starts", later.value);
        assert_eq!(i, id);
        assert_eq!(later.classification.attractors.len(), 2);
    }
}

#[test]
#[ignore = "full size: K = 1000 starts (about a minute on 2 cores)"]
fn fractions_converge_full_size() {
    let runner = starts(fig7(BISTABLE), 300, 64, true);
    let small = across(&runner, &[BISTABLE], 100, 21);
    let large = across(&runner, &[BISTABLE], 1000, 22);
    let f = |v: &ValueAttractors| {
        let c = &v.classification;
        let a = c
            .attractors
            .iter()
            .position(|a| a.impacts_per_period == 4.0)
            .unwrap();
        (c.attractors.len(), c.fraction(a))
    };
    let ((n1, (f1, s1)), (n2, (f2, s2))) = (f(&small[0]), f(&large[0]));
    println!("four-impact basin: {f1} ± {s1} (K = 100), {f2} ± {s2} (K = 1000)");
    assert_eq!((n1, n2), (2, 2));
    assert!((f1 - f2).abs() < 3.0 * (s1 * s1 + s2 * s2).sqrt());
}
