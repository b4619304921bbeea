//! The engine alone, for profiling (`perf record`, `valgrind --tool=callgrind`): the paper's
//! default or chatter case from rest, with only the `RunStats` observer, as the `engine`
//! criterion benchmark runs it, for as many periods as asked (default 20 000). Prints the
//! events, the wall time and events/s.
//!
//! `cargo run --release -p vibrotribo --example engine_loop -- [default|chatter] [PERIODS]`
use vibrotribo::analysis::RunStats;
use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let case = args.get(1).map(String::as_str).unwrap_or("default");
    let periods: f64 = match args.get(2).map(|s| s.parse::<f64>()) {
        None => 20000.0,
        Some(Ok(p)) if p.is_finite() && p > 0.0 => p,
        _ => {
            eprintln!(
                "engine_loop: PERIODS must be a positive number, got {:?}",
                args[2]
            );
            std::process::exit(2);
        }
    };
    let params = match case {
        "default" => ChainParams::default(),
        "chatter" => ChainParams::paper_chatter_case(),
        other => {
            eprintln!("engine_loop: the case is `default` or `chatter`, got `{other}`");
            std::process::exit(2);
        }
    };
    let mut sim = Simulator::new(&params, &ChainState::at_rest(params.len()), SimOptions::default()).unwrap();
    let mut stats = RunStats::new(params.len() - 1, params.period(), 0);
    let t0 = std::time::Instant::now();
    sim.run_until(periods * params.period(), &mut stats).unwrap();
    let dt = t0.elapsed().as_secs_f64();
    println!(
        "{case}: {} events in {periods} periods, {:.3} s, {:.0} events/s",
        stats.events,
        dt,
        stats.events as f64 / dt
    );
}
