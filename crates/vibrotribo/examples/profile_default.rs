//! Runs the default case for many periods (for profiling).
use vibrotribo::analysis::RunStats;
use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator};
fn main() {
    let params = ChainParams::default();
    let mut sim = Simulator::new(&params, &ChainState::at_rest(3), SimOptions::default()).unwrap();
    let mut stats = RunStats::new(2, params.period(), 0);
    sim.run_until(2000.0 * params.period(), &mut stats).unwrap();
    println!("{} events", stats.events);
}
