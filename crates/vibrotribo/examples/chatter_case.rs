//! The paper's chatter case (Sect. 4.4): m1 = m3 = 50 g, R_m = 3, δ = 5 mm, Ω = 0.60.
//! Prints a count of events, then the events of the last period.
//!
//! `cargo run --release --example chatter_case -- 200`
use vibrotribo::{ChainParams, ChainState, EventKind, EventLog, SimOptions, Simulator};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let params = ChainParams::paper_chatter_case();
    let periods: f64 = std::env::args().nth(1).map_or(Ok(20.0), |s| s.parse())?;
    let mut sim = Simulator::new(&params, &ChainState::at_rest(3), SimOptions::default())?;
    let mut log = EventLog::default();
    let started = std::time::Instant::now();
    sim.run_until(periods * params.period(), &mut log)?;
    let elapsed = started.elapsed();
    let count = |k: EventKind| log.events.iter().filter(|e| e.event.kind == k).count();
    println!(
        "{periods} periods, {} events in {elapsed:?}: impacts {}, sticks {}, releases {}, chatter sequences {}",
        log.events.len(),
        count(EventKind::Impact),
        count(EventKind::Stick),
        count(EventKind::Release),
        count(EventKind::Chatter)
    );
    println!("time_s kind contact v_before v_after sequence_impacts");
    let last = (periods - 1.0) * params.period();
    for e in log.events.iter().filter(|e| e.event.time > last) {
        let ev = &e.event;
        println!(
            "{:.12} {} {} {:.3e} {:.3e} {}",
            ev.time,
            ev.kind.as_str(),
            ev.contact + 1,
            ev.velocity_before,
            ev.velocity_after,
            ev.sequence_impacts
        );
    }
    Ok(())
}
