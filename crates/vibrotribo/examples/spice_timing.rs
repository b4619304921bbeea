//! Times ngspice against vibrotribo's charge solver on the same gap waveform, and prints how
//! far they agree.
//!
//! The mechanics of a paper case is simulated, sampled to a piecewise-linear (PWL) table of the
//! gaps (every impact kink plus a uniform grid), and that table drives both ngspice (`PWL`
//! sources, run as `ngspice -b`, start-up included) and the charge solver. The solver is also
//! timed on the exact flow it normally rides on.
//!
//! `cargo run --release --example spice_timing -- [chatter|default] [periods] [resistor|rectifier] [R] [reltol]`
//!
//! The window is the last `periods` periods of a run twice as long (past the start-up).
use std::time::Instant;
use vibrotribo::electrical::spice::{SpiceOptions, run_ngspice};
use vibrotribo::electrical::{
    ChargeOptions, ChargeSolver, Diode, HarvesterParams, Load, LoadKind, PwlGaps, Rectifier,
};
use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator, Trajectory};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let case = args.get(1).map_or("chatter", String::as_str);
    let periods: f64 = args.get(2).map_or(Ok(3.0), |s| s.parse())?;
    let load = match args.get(3).map_or("resistor", String::as_str) {
        "rectifier" => LoadKind::Rectifier,
        _ => LoadKind::Resistor,
    };
    let resistance: f64 = args.get(4).map_or(Ok(1e5), |s| s.parse())?;
    let spice_options = SpiceOptions {
        reltol: args.get(5).map(|s| s.parse()).transpose()?,
        ..SpiceOptions::default()
    };
    let chain = match case {
        "default" => ChainParams::default(),
        _ => ChainParams::paper_chatter_case(),
    };
    let t_start = periods * chain.period();
    let t_end = 2.0 * t_start;
    let mut sim = Simulator::new(&chain, &ChainState::at_rest(chain.len()), SimOptions::default())?;
    sim.run_until(t_start, &mut ())?;
    let mut trajectory = Trajectory::new(&sim);
    sim.run_until(t_end, &mut trajectory)?;
    let pwl = PwlGaps::from_trajectory(&trajectory, chain.period() / 2000.0, t_end)?;
    let load = match load {
        LoadKind::Rectifier => Load::Rectifier(Rectifier {
            // ngspice needs a conducting path at the floating bridge (see the spice module docs).
            diode: Diode {
                parallel_conductance: 1e-10,
                ..Rectifier::default().diode
            },
            ..Rectifier::default()
        }),
        _ => Load::Resistor { resistance },
    };
    let params = HarvesterParams {
        load,
        ..HarvesterParams::default()
    };
    println!(
        "{case} case, {periods} periods, {} load, {} PWL points, {} flow segments",
        load.kind().as_str(),
        pwl.times().len(),
        trajectory.segments().len()
    );

    let runs = 5;
    let mut spice_times = Vec::new();
    let mut pwl_times = Vec::new();
    let mut flow_times = Vec::new();
    let mut spice_energy = 0.0;
    let mut pwl_energy = 0.0;
    let mut flow_energy = 0.0;
    let mut spice_vs = None;
    let mut pwl_vs = None;
    for _ in 0..runs {
        let spice = run_ngspice(&params, &pwl, t_end, &spice_options)?;
        spice_times.push(spice.elapsed.as_secs_f64());
        spice_energy = *spice.energy_j.last().unwrap_or(&f64::NAN);
        spice_vs = spice.storage_voltage_v.last().copied();

        let started = Instant::now();
        let mut solver = ChargeSolver::for_chain(&params, &chain, ChargeOptions::default())?;
        solver.run_pwl(&pwl)?;
        pwl_times.push(started.elapsed().as_secs_f64());
        pwl_energy = solver.total_energy();
        pwl_vs = solver.storage_voltage();

        let started = Instant::now();
        let mut solver = ChargeSolver::for_chain(&params, &chain, ChargeOptions::default())?;
        solver.run_trajectory(&trajectory)?;
        flow_times.push(started.elapsed().as_secs_f64());
        flow_energy = solver.total_energy();
    }
    let (s, p, f) = (median(spice_times), median(pwl_times), median(flow_times));
    println!("median wall time over {runs} runs:");
    println!("  ngspice -b on the PWL table      {:10.3} ms", s * 1e3);
    println!(
        "  vibrotribo on the PWL table      {:10.3} ms   (ngspice / vibrotribo = {:.0})",
        p * 1e3,
        s / p
    );
    println!("  vibrotribo on the exact flow     {:10.3} ms", f * 1e3);
    println!("energy delivered to the load:");
    println!("  ngspice (PWL)     {spice_energy:.9e} J");
    println!(
        "  vibrotribo (PWL)  {pwl_energy:.9e} J   relative difference {:.2e}",
        (spice_energy - pwl_energy) / pwl_energy
    );
    println!(
        "  vibrotribo (flow) {flow_energy:.9e} J   (PWL sampling effect {:.2e})",
        (pwl_energy - flow_energy) / flow_energy
    );
    if let (Some(a), Some(b)) = (spice_vs, pwl_vs) {
        println!("storage voltage at the end: ngspice {a:.6} V, vibrotribo {b:.6} V");
    }
    Ok(())
}
