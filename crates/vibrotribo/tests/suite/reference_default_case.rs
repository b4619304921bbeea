//! The paper's default case against `tests/data/reference/` (an independent adaptive integrator
//! with event functions at rtol 1e-11, whose impact times are good to about 1e-9 s).

use crate::common;

use common::{read_csv, reference_dir};
use vibrotribo::{ChainParams, ChainState, EventKind, EventLog, SimOptions, Simulator, Trajectory};

fn run_default(periods: f64) -> (ChainParams, EventLog, Trajectory) {
    let params = ChainParams::default();
    let mut sim = Simulator::new(&params, &ChainState::at_rest(3), SimOptions::default()).unwrap();
    let mut log = EventLog::default();
    let mut traj = Trajectory::new(&sim);
    sim.run_until(periods * params.period(), &mut (&mut log, &mut traj))
        .unwrap();
    (params, log, traj)
}

#[test]
fn impacts_match_reference() {
    let reference = read_csv(&reference_dir().join("default-case-impacts.csv"));
    let (_, log, _) = run_default(40.0);
    let ours: Vec<_> = log
        .events
        .iter()
        .filter(|e| e.event.kind == EventKind::Impact)
        .collect();
    assert_eq!(ours.len(), reference.len(), "number of impacts in 40 periods");
    let (mut worst_t, mut worst_v) = (0.0f64, 0.0f64);
    for (i, (r, o)) in reference.iter().zip(&ours).enumerate() {
        let (t, contact, v) = (r[0], r[1] as usize, r[2]);
        assert_eq!(o.event.contact + 1, contact, "impact {i} at t = {t}: contact");
        worst_t = worst_t.max((o.event.time - t).abs());
        worst_v = worst_v.max((o.event.velocity_before - v).abs() / v);
        // The reference is good to ~1e-9 s and prints 12 decimals.
        assert!(
            (o.event.time - t).abs() < 1e-9,
            "impact {i}: t = {} vs reference {t}",
            o.event.time
        );
        assert!(
            (o.event.velocity_before - v).abs() < 1e-8 * v,
            "impact {i} at t = {t}: speed {} vs reference {v}",
            o.event.velocity_before
        );
    }
    println!("max |Δt| = {worst_t:.2e} s, max relative Δv = {worst_v:.2e}");
    // No sticking or chatter in this case.
    assert!(log.events.iter().all(|e| e.event.kind == EventKind::Impact));
}

#[test]
fn stroboscopic_positions_match_reference() {
    let reference = read_csv(&reference_dir().join("default-case-strobe.csv"));
    let (params, _, traj) = run_default(40.0);
    let (mut x, mut v) = (vec![0.0; 3], vec![0.0; 3]);
    let mut worst = 0.0f64;
    for row in &reference {
        let t = row[0] * params.period();
        assert!(traj.state_at(t, &mut x, &mut v));
        for i in 0..3 {
            worst = worst.max((x[i] - row[1 + i]).abs());
        }
    }
    println!("max |Δx| at t = nT: {worst:.2e} m");
    assert!(worst < 1e-9, "stroboscopic positions differ by {worst:e} m");
}

#[test]
fn impacts_per_period_match_reference() {
    let summary = std::fs::read_to_string(reference_dir().join("default-case-summary.json")).unwrap();
    // Pull the impacts_per_period array out of the JSON without a JSON dependency.
    let start = summary.find("\"impacts_per_period\"").unwrap();
    let open = start + summary[start..].find('[').unwrap();
    let close = open + summary[open..].find(']').unwrap();
    let expected: Vec<usize> = summary[open + 1..close]
        .split(',')
        .map(|s| s.trim().parse().unwrap())
        .collect();
    let (params, log, _) = run_default(40.0);
    let mut counts = vec![0usize; 40];
    for e in log.events.iter().filter(|e| e.event.kind == EventKind::Impact) {
        counts[(e.event.time / params.period()).floor() as usize] += 1;
    }
    assert_eq!(counts, expected);
}
