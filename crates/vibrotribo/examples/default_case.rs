//! Runs the paper's default case (Sect. 4.1, configuration (1), m2 = 120 g, R_m = 2.5,
//! Ω = 0.70) from rest for 40 periods and prints every impact, in the format of
//! `crates/vibrotribo/tests/data/reference/default-case-impacts.csv`.
//!
//! `cargo run --release --example default_case`
use vibrotribo::{ChainParams, ChainState, EventKind, EventLog, SimOptions, Simulator};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let params = ChainParams::default();
    let mut sim = Simulator::new(&params, &ChainState::at_rest(3), SimOptions::default())?;
    let mut log = EventLog::default();
    sim.run_until(40.0 * params.period(), &mut log)?;
    println!("time_s,contact,rel_velocity_m_s");
    for e in log.events.iter().filter(|e| e.event.kind == EventKind::Impact) {
        println!(
            "{:.12},{},{:.9}",
            e.event.time,
            e.event.contact + 1,
            e.event.velocity_before
        );
    }
    Ok(())
}
