//! The run layer's frequency-sweep experiment (`study::run_chirp`): cycles follow the chirp's
//! phase, the energy per cycle adds up to what the charge solver integrates over the same
//! time, and bad options are errors naming the option.

use vibrotribo::config::Config;
use vibrotribo::study::{ChirpError, ChirpOptions, Direction, run_chirp};

/// The default case swept down from Ω = 0.8 to 0.6 in 10 s: the cycles tile the phase
/// (boundaries where φ = 2πc, Ω decreasing), and the per-cycle energies (trapezoid of V²/R
/// over 200 samples per cycle) add up to the solver's energy (its collocation quadrature) over
/// the whole periods they cover, within 1 %.
#[test]
fn cycles_tile_the_phase_and_the_energy_adds_up() {
    let spec = Config::default().run_spec(false);
    let options = ChirpOptions::new(0.6, 0.8, 10.0);
    let run = run_chirp(&spec, &options, Direction::Down, &mut ()).unwrap();
    let c = &run.cycles;
    assert!(c.len() > 50, "{}", c.len());
    for (k, cy) in c.iter().enumerate() {
        assert_eq!(cy.cycle, k as u64 + 1);
        let phase = run.chirp.phase(cy.start_s) / std::f64::consts::TAU;
        assert!((phase - k as f64).abs() < 1e-9, "cycle {k}: φ/2π = {phase}");
        assert!(cy.end_s <= options.duration_s);
        if k > 0 {
            assert_eq!(cy.start_s, c[k - 1].end_s);
            assert!(cy.omega_ratio < c[k - 1].omega_ratio);
        }
    }
    assert!((c[0].omega_ratio - 0.8).abs() < 0.01 && (c.last().unwrap().omega_ratio - 0.6).abs() < 0.01);
    let e = run.outcome.electrical.as_ref().unwrap();
    let period = e.period;
    let whole = (c.last().unwrap().end_s / period).floor() as usize;
    let solver: f64 = e.periods[..whole].iter().map(|p| p.energy_j).sum();
    // The cycles' energy over [0, whole·T]: the cycles inside, and the share of the one across.
    let t_end = whole as f64 * period;
    let ours: f64 = c
        .iter()
        .map(|cy| {
            let share = ((t_end - cy.start_s) / (cy.end_s - cy.start_s)).clamp(0.0, 1.0);
            cy.energy_j.unwrap() * share
        })
        .sum();
    println!("energy over {whole} periods: cycles {ours:.6e} J, solver {solver:.6e} J");
    assert!((ours - solver).abs() < 0.01 * solver, "{ours} vs {solver}");
}

#[test]
fn bad_options_name_the_option() {
    let spec = Config::default().run_spec(false);
    let cases = [
        (ChirpOptions::new(0.9, 0.8, 10.0), "from"),
        (ChirpOptions::new(-1.0, 0.8, 10.0), "from"),
        (ChirpOptions::new(0.6, f64::INFINITY, 10.0), "to"),
        (ChirpOptions::new(0.6, 0.8, 0.1), "duration"),
        (ChirpOptions::new(0.6, 0.8, 1e6), "duration"),
        (
            ChirpOptions {
                amplitude: Some(-0.1),
                ..ChirpOptions::new(0.6, 0.8, 10.0)
            },
            "amplitude",
        ),
    ];
    for (options, name) in cases {
        match run_chirp(&spec, &options, Direction::Up, &mut ()) {
            Err(ChirpError::Option { option, message }) => {
                assert_eq!(option, name, "{message}");
            }
            other => panic!("{options:?}: {:?}", other.map(|r| r.cycles.len())),
        }
    }
}

/// The experiment takes a run, however it was made: the paper's chain as a `RunSpec` built
/// in code gives the cycles of the same run read from the default configuration, bit for
/// bit; a run under another base motion than the chain's harmonic is refused, naming
/// `excitation.kind`, and so are stops that move with the base.
#[test]
fn a_chirp_takes_any_harmonic_run_and_refuses_another_base_motion() {
    use std::sync::Arc;
    use vibrotribo::ChainParams;
    use vibrotribo::excitation::{BaseMotion, Harmonic};
    use vibrotribo::study::RunSpec;

    let options = ChirpOptions {
        mechanics_only: true,
        settled_start: false,
        ..ChirpOptions::new(0.6, 0.8, 5.0)
    };
    let built = RunSpec::new(ChainParams::default(), 1);
    let read = Config::default().run_spec(true);
    let a = run_chirp(&built, &options, Direction::Up, &mut ()).unwrap();
    let b = run_chirp(&read, &options, Direction::Up, &mut ()).unwrap();
    assert!(a.cycles.len() > 20, "{}", a.cycles.len());
    assert_eq!(a.cycles, b.cycles);

    let chain = ChainParams::default();
    let two = BaseMotion::Harmonics(vec![
        Harmonic {
            amplitude: 0.01,
            omega: chain.omega(),
            phase: 0.0,
        },
        Harmonic {
            amplitude: 0.01,
            omega: 2.0 * chain.omega(),
            phase: 0.0,
        },
    ]);
    let multisine = RunSpec {
        base_motion: Some(Arc::new(two)),
        ..RunSpec::new(chain, 1)
    };
    match run_chirp(&multisine, &options, Direction::Up, &mut ()) {
        Err(e @ ChirpError::Config(_)) => {
            let text = e.to_string();
            assert!(
                text.contains("excitation.kind") && text.contains("multisine"),
                "{text}"
            );
        }
        other => panic!("{:?}", other.map(|r| r.cycles.len())),
    }
    let moving = Config::from_toml_str(
        "[oscillator]\nmasses = [0.05]\nstiffness = 120.0\ndamping = 0.1\n\
         [oscillator.stops.upper]\ngap = 0.001\nrestitution = 0.8\nframe = \"base\"\n",
    )
    .unwrap();
    match run_chirp(&moving.run_spec(true), &options, Direction::Up, &mut ()) {
        Err(e @ ChirpError::Config(_)) => {
            let text = e.to_string();
            assert!(text.contains("chirp") && text.contains("frame"), "{text}");
        }
        other => panic!("{:?}", other.map(|r| r.cycles.len())),
    }
}
