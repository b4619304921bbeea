//! Work counters of the charge solver per excitation period (steps, rejections, waveform
//! evaluations, Newton iterations) on the paper's default and chatter cases, for several loads.
//!
//! `cargo run --release -p vibrotribo --example electrical_work`
use std::time::Instant;
use vibrotribo::electrical::{ChargeOptions, ChargeSolver, HarvesterParams, Load, Rectifier};
use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator, Trajectory};

fn main() {
    for (name, chain, periods) in [
        ("default", ChainParams::default(), 50.0),
        ("chatter", ChainParams::paper_chatter_case(), 20.0),
    ] {
        let mut sim =
            Simulator::new(&chain, &ChainState::at_rest(chain.len()), SimOptions::default()).unwrap();
        let mut traj = Trajectory::new(&sim);
        sim.run_until(periods * chain.period(), &mut traj).unwrap();
        let loads: Vec<(String, HarvesterParams)> = [1e3, 1e5, 1e8, 1e10]
            .iter()
            .map(|&r| {
                (
                    format!("R = {r:e} Ω"),
                    HarvesterParams {
                        load: Load::Resistor { resistance: r },
                        ..HarvesterParams::default()
                    },
                )
            })
            .chain(std::iter::once((
                "rectifier".to_string(),
                HarvesterParams {
                    load: Load::Rectifier(Rectifier::default()),
                    ..HarvesterParams::default()
                },
            )))
            .collect();
        println!(
            "{name} case, {periods} periods, {} flow segments",
            traj.segments().len()
        );
        for (label, params) in &loads {
            let mut s = ChargeSolver::for_chain(params, &chain, ChargeOptions::default()).unwrap();
            let start = Instant::now();
            s.run_trajectory(&traj).unwrap();
            let el = start.elapsed().as_secs_f64();
            let st = s.stats();
            let p = periods;
            println!(
                "  {label:>16}: {:8.1} steps, {:6.1} rejected, {:8.1} evaluations, {:5.1} pieces, {:7.1} Newton per period; {:7.1} µs per period; energy {:.9e} J",
                st.steps as f64 / p,
                st.rejected as f64 / p,
                st.waveform_evaluations as f64 / p,
                st.pieces as f64 / p,
                st.newton_iterations as f64 / p,
                el / p * 1e6,
                s.total_energy()
            );
        }
    }
}
