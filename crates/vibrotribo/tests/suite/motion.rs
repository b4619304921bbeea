//! Settling and the classification of a point's motion against truth from outside the
//! settling code: the closed-form decay exp(−c/(2m)·T) per period of a mass that touches
//! nothing, the steady state a fixed transient thousands of periods long reaches, a periodic
//! orbit found by Newton shooting (started on and off it), the Lyapunov exponents the
//! README's 10 000-period runs give (chaotic R_m = 6.54, quasi-periodic R_m = 3.3 at
//! Ω = 0.72), and the bit-identity of `SettleMode::Fixed` with the earlier results.

use vibrotribo::orbits::{ShootingOptions, periodic_orbit_from_transient};
use vibrotribo::study::{
    AutoSettle, Motion, MotionReport, PointOptions, PointResult, SettleEnding, SettleMode, run_point,
};
use vibrotribo::{ChainParams, ChainState, Excitation, Frequency, SimOptions};

/// Masses on their springs, with gaps of 1 m and a 5 mm base motion: no contact ever.
/// Damping c/(2m) = 0.5, 0.05 and 0.5 1/s: the middle mass is the slowest.
fn free_chain() -> ChainParams {
    ChainParams {
        masses: vec![0.05, 0.1, 0.05],
        stiffness: vec![120.0; 3],
        damping: vec![0.05, 0.01, 0.05],
        gaps: vec![1.0, 1.0],
        excitation: Excitation {
            amplitude: 0.005,
            frequency: Frequency::OmegaRatio(0.7),
        },
        ..ChainParams::default()
    }
}

/// The paper's chain (A = 80 mm, μ = 0.6) with masses `m`, default gaps, Ω = `omega`.
fn three(m: [f64; 3], omega: f64) -> ChainParams {
    ChainParams {
        masses: m.to_vec(),
        excitation: Excitation {
            amplitude: 0.08,
            frequency: Frequency::OmegaRatio(omega),
        },
        ..ChainParams::default()
    }
}

fn options(transient: u64, recorded: u64, settle: SettleMode) -> PointOptions {
    PointOptions {
        transient_periods: transient,
        recorded_periods: recorded,
        settle,
        classify: true,
        ..PointOptions::default()
    }
}

fn auto(cap: u64, shoot: bool) -> SettleMode {
    SettleMode::Auto(AutoSettle {
        cap_periods: cap,
        shoot,
        ..AutoSettle::default()
    })
}

fn point(params: &ChainParams, initial: &ChainState, o: &PointOptions) -> (PointResult, MotionReport) {
    let p = run_point(params, initial, &SimOptions::default(), None, o).unwrap();
    let m = p.motion.clone().expect("classified");
    (p, m)
}

/// The middle mass displaced by 2 cm, the others at rest.
fn displaced() -> ChainState {
    ChainState {
        positions: vec![0.0, 0.02, 0.0],
        velocities: vec![0.0; 3],
    }
}

/// A chain that touches nothing: with too short a cap (and no shooting) it is `settling`
/// at the slowest mass's closed-form rate exp(−c₂/(2m₂)·T) per period, and the periods it
/// says it still needs are what a longer settling takes; with shooting it is `periodic`
/// long before, on the steady state a 4000-period fixed transient reaches.
#[test]
fn free_chain_settles_at_the_closed_form_rate() {
    let params = free_chain();
    let t = params.period();
    let rate = (-0.01 / (2.0 * 0.1) * t).exp();
    let (_, short) = point(&params, &displaced(), &options(100, 100, auto(300, false)));
    assert_eq!(short.motion, Motion::Settling, "{short:?}");
    assert_eq!(short.settle_ending, SettleEnding::Cap);
    let measured = short.rate.unwrap();
    assert!(
        (measured - rate).abs() < 2e-4,
        "rate {measured} vs closed form {rate}"
    );
    let needed = short.periods_needed.unwrap();

    // Without a cap worth speaking of, settling takes what was announced: the recorded
    // window ended at 300 + 20 + 100 periods.
    let (_, long) = point(&params, &displaced(), &options(100, 100, auto(20_000, false)));
    assert_eq!(long.motion, Motion::Periodic, "{long:?}");
    assert_eq!(long.settle_ending, SettleEnding::Repeated);
    let announced = 420.0 + needed;
    let took = long.settle_periods as f64;
    assert!(
        (took - announced).abs() < 0.1 * announced,
        "took {took} periods, announced {announced}"
    );

    // Newton shooting finishes the approach far sooner, on the same steady state.
    let (shot, m) = point(&params, &displaced(), &options(100, 100, auto(2000, true)));
    assert_eq!(m.motion, Motion::Periodic, "{m:?}");
    assert_eq!(m.settle_ending, SettleEnding::Shot);
    assert!(m.settle_periods < long.settle_periods / 2, "{m:?}");
    assert_eq!(shot.period(), 1);
    let (steady, _) = point(&params, &displaced(), &options(4000, 10, SettleMode::Fixed));
    for (a, b) in shot.strobe[..3].iter().zip(&steady.strobe[..3]) {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }
}

/// The paper's default case with a fourth mass far from every contact (δ₃ = 1 m,
/// c₄/(2m₄) = 0.02 1/s): the three impacting masses settle fast (rate about 0.8 per period),
/// the far mass at its closed-form rate.
#[test]
fn a_mass_far_from_contact_decays_at_its_own_rate() {
    let params = ChainParams {
        masses: vec![0.048, 0.12, 0.048, 0.048],
        stiffness: vec![120.0; 4],
        damping: vec![0.02, 0.02, 0.02, 0.00192],
        gaps: vec![0.02, 0.02, 1.0],
        ..ChainParams::default()
    };
    let initial = ChainState {
        positions: vec![0.0, 0.0, 0.0, 0.01],
        velocities: vec![0.0; 4],
    };
    let rate = (-0.00192 / (2.0 * 0.048) * params.period()).exp();
    let (_, m) = point(&params, &initial, &options(100, 100, auto(300, false)));
    assert_eq!(m.motion, Motion::Settling, "{m:?}");
    let measured = m.rate.unwrap();
    assert!(
        (measured - rate).abs() < 5e-4,
        "rate {measured} vs closed form {rate}"
    );
    let (p, m) = point(&params, &initial, &options(100, 100, auto(2000, true)));
    assert_eq!(m.motion, Motion::Periodic, "{m:?}");
    assert_eq!(m.settle_ending, SettleEnding::Shot, "{m:?}");
    assert!(p.impacts_per_period[0] > 0.0 && p.impacts_per_period[2] == 0.0);
}

/// The paper's default case: started on its period-1 orbit (found by Newton shooting from
/// a transient), the motion repeats at the first check; started from rest, it settles onto
/// the same orbit.
#[test]
fn impacting_orbit_started_on_and_off_it() {
    let params = ChainParams::default();
    let orbit = periodic_orbit_from_transient(
        &params,
        &ChainState::at_rest(3),
        100,
        Some(1),
        &ShootingOptions::default(),
    )
    .unwrap();
    assert!(orbit.stable);
    let o = options(50, 50, auto(2000, true));
    let (on, m) = point(&params, &orbit.state, &o);
    assert_eq!(m.motion, Motion::Periodic);
    assert_eq!(m.settle_ending, SettleEnding::Repeated);
    assert_eq!(m.settle_periods, 50, "the first check");
    assert!(m.residual < 1e-10, "{m:?}");
    let (off, m) = point(&params, &ChainState::at_rest(3), &o);
    assert_eq!(m.motion, Motion::Periodic, "{m:?}");
    assert_eq!(off.period(), 1);
    for (a, b) in on.strobe[..3].iter().zip(&orbit.state.positions) {
        assert!((a - b).abs() < 1e-9, "{a} vs {b}");
    }
    for (a, b) in off.strobe[..3].iter().zip(&orbit.state.positions) {
        assert!((a - b).abs() < 1e-6 * 0.04, "{a} vs {b}");
    }
}

/// Fig. 14's chain at R_m = 6.54, Ω = 0.72 is chaotic (λ₁ = 3.27 ± 0.03 1/s over 10 000
/// periods): so classified from rest and from another start, over 128 and 256 recorded
/// periods, with exponents that agree within their error bars.
#[test]
fn chaotic_case_is_chaotic_whatever_the_start_and_window() {
    let params = three([0.05, 0.05 * 6.54, 0.05], 0.72);
    let other = ChainState {
        positions: vec![0.01, -0.005, 0.0],
        velocities: vec![0.0, 0.1, 0.0],
    };
    let mut seen = Vec::new();
    for (initial, recorded) in [(ChainState::at_rest(3), 128), (other, 256)] {
        let (p, m) = point(&params, &initial, &options(300, recorded, auto(2000, true)));
        assert_eq!(m.motion, Motion::Chaotic, "{m:?}");
        assert_eq!(p.period(), 0);
        assert_eq!(m.settle_ending, SettleEnding::Irregular);
        seen.push(m.lyapunov.unwrap());
    }
    let ((a, sa), (b, sb)) = (seen[0], seen[1]);
    assert!((a - b).abs() < 3.0 * (sa * sa + sb * sb).sqrt(), "{seen:?}");
    assert!(
        (a - 3.27).abs() < 3.0 * sa + 0.1 && (b - 3.27).abs() < 3.0 * sb + 0.1,
        "{seen:?}"
    );
}

/// The same chain at R_m = 3.3 is quasi-periodic (λ₁ = 0.0002 ± 0.0005 1/s over 10 000
/// periods): indistinguishable from 0 over the window, its section a closed curve.
#[test]
fn quasiperiodic_case_is_a_torus() {
    let params = three([0.05, 0.05 * 3.3, 0.05], 0.72);
    let (_, m) = point(
        &params,
        &ChainState::at_rest(3),
        &options(300, 128, auto(2000, true)),
    );
    assert_eq!(m.motion, Motion::Quasiperiodic, "{m:?}");
    assert!(
        m.curve_ratio.unwrap() < vibrotribo::analysis::CLOSED_CURVE_RATIO,
        "{m:?}"
    );
}

/// `SettleMode::Fixed` gives the earlier results bit for bit: classifying adds the motion
/// and nothing else changes.
#[test]
fn fixed_settling_is_unchanged_by_classification() {
    for params in [ChainParams::default(), three([0.05, 0.05 * 6.54, 0.05], 0.72)] {
        let plain = options(60, 40, SettleMode::Fixed);
        let classified = PointOptions {
            classify: true,
            ..plain.clone()
        };
        let plain = PointOptions {
            classify: false,
            ..plain
        };
        let (a, _) = (
            run_point(
                &params,
                &ChainState::at_rest(3),
                &SimOptions::default(),
                None,
                &plain,
            )
            .unwrap(),
            (),
        );
        let mut b = run_point(
            &params,
            &ChainState::at_rest(3),
            &SimOptions::default(),
            None,
            &classified,
        )
        .unwrap();
        assert!(b.motion.is_some());
        b.motion = None;
        assert_eq!(a, b);
    }
}
