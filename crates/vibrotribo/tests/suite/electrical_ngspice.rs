//! The charge solver against ngspice on the same piecewise-linear gap waveforms: a synthetic
//! one (sinusoidal gaps that both close every period) and one taken from a real run of the
//! paper's chatter case (three periods after the start-up, with chatter sequences and triple
//! closures). Energy must agree within 0.1 % for the resistor and the rectifier loads.
//!
//! ngspice is required: CI installs it (`apt-get install -y ngspice`); without it these tests
//! fail with a message saying so.

use vibrotribo::electrical::spice::{SpiceError, SpiceOptions, SpiceRun, run_ngspice};
use vibrotribo::electrical::{ChargeOptions, ChargeSolver, Diode, HarvesterParams, Load, PwlGaps, Rectifier};
use vibrotribo::{ChainParams, ChainState, EventKind, EventLog, SimOptions, Simulator, Trajectory};

const TOLERANCE: f64 = 1e-3;

fn ngspice(params: &HarvesterParams, pwl: &PwlGaps, t_end: f64) -> SpiceRun {
    match run_ngspice(params, pwl, t_end, &SpiceOptions::default()) {
        Ok(run) => run,
        Err(e @ SpiceError::NotFound { .. }) => {
            panic!("this test needs ngspice, which is not installed or not on PATH: {e}")
        }
        Err(e) => panic!("ngspice failed: {e}"),
    }
}

fn loads() -> [HarvesterParams; 2] {
    [
        HarvesterParams {
            load: Load::Resistor { resistance: 1e5 },
            ..HarvesterParams::default()
        },
        HarvesterParams {
            load: Load::Rectifier(Rectifier {
                storage_capacitance: 1e-6,
                // ngspice needs a conducting path at the floating bridge; the library models
                // the same leakage (see the spice module docs).
                diode: Diode {
                    parallel_conductance: 1e-10,
                    ..Rectifier::default().diode
                },
                ..Rectifier::default()
            }),
            ..HarvesterParams::default()
        },
    ]
}

/// Runs both simulators on `pwl` and compares total energy, energy per period and (rectifier)
/// the storage voltage at the end of every period.
fn compare(name: &str, pwl: &PwlGaps, period: f64) {
    let t_end = *pwl.times().last().unwrap();
    for params in loads() {
        let spice = ngspice(&params, pwl, t_end);
        let mut solver =
            ChargeSolver::new(&params, period, pwl.gap_count(), ChargeOptions::default()).unwrap();
        solver.run_pwl(pwl).unwrap();
        let load = params.load.kind().as_str();
        let ours = solver.total_energy();
        let theirs = *spice.energy_j.last().unwrap();
        let rel = (theirs - ours) / ours;
        println!(
            "{name}, {load}: energy ngspice {theirs:.9e} J, vibrotribo {ours:.9e} J, relative difference {rel:.2e} \
             (ngspice {:.2} s, {} time points)",
            spice.elapsed.as_secs_f64(),
            spice.time.len()
        );
        assert!(
            rel.abs() <= TOLERANCE,
            "{name}, {load}: energy differs by {rel:e}"
        );
        for p in solver.periods() {
            let theirs = spice.at(&spice.energy_j, p.t_end) - spice.at(&spice.energy_j, p.t_start);
            let rel = (theirs - p.energy_j) / p.energy_j;
            println!(
                "  period {} ({:.4}–{:.4} s): ngspice {theirs:.6e} J, vibrotribo {:.6e} J, relative difference {rel:.2e}",
                p.index, p.t_start, p.t_end, p.energy_j
            );
            assert!(
                rel.abs() <= TOLERANCE,
                "{name}, {load}, period {}: energy differs by {rel:e}",
                p.index
            );
            if let Some(vs) = p.storage_voltage_v {
                let theirs = spice.at(&spice.storage_voltage_v, p.t_end);
                let rel = (theirs - vs) / vs;
                println!(
                    "  storage voltage at {:.4} s: ngspice {theirs:.6} V, vibrotribo {vs:.6} V ({rel:.2e})",
                    p.t_end
                );
                assert!(
                    rel.abs() <= TOLERANCE,
                    "{name}, storage voltage differs by {rel:e}"
                );
            }
        }
    }
}

#[test]
fn ngspice_agrees_on_sinusoidal_gaps() {
    // Both gaps close once per period (T = 0.1 s), out of phase: C and V_oc both swing.
    let (period, n) = (0.1, 2000);
    let omega = 2.0 * std::f64::consts::PI / period;
    let times: Vec<f64> = (0..=3 * n).map(|j| j as f64 * period / n as f64).collect();
    let mut values = Vec::with_capacity(2 * times.len());
    for &t in &times {
        let (s, c) = (omega * t).sin_cos();
        values.push(2.5e-3 * (1.0 + s));
        values.push(2.5e-3 * (1.0 - c));
    }
    let pwl = PwlGaps::new(times, values, 2).unwrap();
    compare("sinusoidal gaps", &pwl, period);
}

#[test]
fn ngspice_agrees_on_a_chatter_run() {
    let chain = ChainParams::paper_chatter_case();
    let period = chain.period();
    let mut sim = Simulator::new(&chain, &ChainState::at_rest(3), SimOptions::default()).unwrap();
    sim.run_until(3.0 * period, &mut ()).unwrap();
    let mut trajectory = Trajectory::new(&sim);
    let mut log = EventLog::default();
    sim.run_until(6.0 * period, &mut (&mut trajectory, &mut log))
        .unwrap();
    let count = |k: EventKind| log.events.iter().filter(|e| e.event.kind == k).count();
    println!(
        "chatter run, periods 3–6: {} impacts, {} chatter sequences, {} sticks",
        count(EventKind::Impact),
        count(EventKind::Chatter),
        count(EventKind::Stick)
    );
    assert!(count(EventKind::Chatter) >= 2, "the window must hold chatter");
    let pwl = PwlGaps::from_trajectory(&trajectory, period / 2000.0, 6.0 * period).unwrap();
    compare("chatter run", &pwl, period);
}

#[test]
fn a_missing_ngspice_is_an_error_that_says_so() {
    let pwl = PwlGaps::new(vec![0.0, 1e-3], vec![1e-3, 1e-3, 1e-3, 1e-3], 2).unwrap();
    let options = SpiceOptions {
        executable: "vibrotribo-no-such-ngspice".into(),
        ..SpiceOptions::default()
    };
    let err = run_ngspice(&HarvesterParams::default(), &pwl, 1e-3, &options).unwrap_err();
    assert!(matches!(err, SpiceError::NotFound { .. }), "{err:?}");
    assert!(err.to_string().contains("install ngspice"), "{err}");
}
