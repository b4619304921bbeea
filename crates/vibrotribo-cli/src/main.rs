//! The `vibrotribo` command-line program: argument parsing, configuration files, output
//! files and plots. All physics lives in the `vibrotribo` library.

// First, so that its `print!` and `println!` (which survive a closed pipe or a full disk)
// replace the standard ones in every module below.
#[macro_use]
mod stdout;

mod attractors;
mod band_response;
mod basins;
mod bifmap;
mod bifmap_picture;
mod branch_picture;
mod chirp;
mod config;
mod continuation;
mod curve;
mod curve_picture;
mod decimal;
mod export_spice;
mod job;
mod limits;
mod load_sweep;
mod lyapunov;
mod manifest;
mod map;
mod mass_ratio_picture;
mod merge;
mod merit;
mod optimize;
mod output;
mod periodic;
mod plot;
mod plots;
mod progress;
mod reproduce;
mod response;
mod response_picture;
mod run_analyses;
mod serve;
mod simulate;
mod sweep;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Exact event-driven simulation of vibro-impact triboelectric energy harvesters.
#[derive(Debug, Parser)]
#[command(name = "vibrotribo", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Simulate one configuration (the paper's default case if no file is given).
    Simulate(simulate::SimulateArgs),
    /// Average power against load resistance on one run; the optimal load; the V–Q cycle.
    LoadSweep(load_sweep::LoadSweepArgs),
    /// Write an ngspice netlist of a run's harvester driven by its gap waveforms.
    ExportSpice(export_spice::ExportSpiceArgs),
    /// The periodic orbit near a run, by shooting: Floquet multipliers, stability, power.
    Periodic(periodic::PeriodicArgs),
    /// Follow a periodic orbit in a parameter: stability, bifurcations, power along the branch.
    Continue(continuation::ContinueArgs),
    /// Follow a fold, period doubling, Neimark–Sacker or grazing point in a second parameter:
    /// the bifurcation curve and its codimension-two points.
    Curve(curve::CurveArgs),
    /// A bifurcation map in two parameters: the fold, period-doubling, Neimark–Sacker and
    /// grazing curves (from seed branches), their codimension-two points, over the power map.
    Bifmap(bifmap::BifmapArgs),
    /// Sweep one parameter: orbit diagram, impact velocities, period, power.
    Sweep(sweep::SweepArgs),
    /// Combine the shards of one sweep, map or basins job (`--shard I/N`) into the unsharded
    /// output.
    Merge(job::MergeArgs),
    /// Frequency-sweep experiment: a slow chirp of the base up and down in Ω, the response
    /// per cycle (amplitudes, impacts, power), its jumps and the hysteresis between them.
    Chirp(chirp::ChirpArgs),
    /// Average power, period and impacts per period on a two-parameter grid.
    Map(map::MapArgs),
    /// The optimal mass ratio R_mo(Ω) and its quadratic fit (the paper's Fig. 16).
    OptimizeMassRatio(map::OptimizeArgs),
    /// Frequency response: power against a parameter (Ω) from an up and a down sweep (side
    /// by side, a thread each) and the branches between them, with the peak and the
    /// half-power bandwidth.
    Response(response::ResponseArgs),
    /// Response to band-limited random input: power against the centre frequency of the
    /// band (fixed width and RMS acceleration), the mean over seeds, with the bandwidth.
    BandResponse(band_response::BandResponseArgs),
    /// Optimise a design over several keys (particle swarm, then Nelder–Mead) for average or
    /// expected power or power per mass, under breakdown and displacement constraints.
    Optimize(optimize::OptimizeArgs),
    /// Basins of attraction over two initial conditions: the attractors, their basin
    /// fractions, periods, impacts and power (each start settles, by default until its motion
    /// repeats, at most --settle-cap periods, or exactly --transient periods (default 500)
    /// with --settle fixed; then 100 recorded periods unless --recorded says).
    Basins(basins::BasinsArgs),
    /// Attractors of random starts across a parameter: basin fractions (± standard error),
    /// power per attractor and the expected power of an unknown start.
    Attractors(attractors::AttractorsArgs),
    /// Lyapunov spectrum (all 2N exponents, through impacts and sticking) with its spread.
    Lyapunov(lyapunov::LyapunovArgs),
    /// Recompute the paper's study (Figs. 5–25) and write REPORT.md comparing its findings.
    Reproduce(reproduce::ReproduceArgs),
    /// Draw the pictures (and per-run analyses) of a simulate, sweep or map directory.
    Plot(PlotArgs),
    /// A local web page to explore a configuration: parameters, the run, an orbit diagram,
    /// a power map and basins, computed live by the same engine (all assets built in; Ctrl-C
    /// stops).
    Serve(serve::ServeArgs),
    /// Write the configuration reference (every key, its unit, default and allowed values) as
    /// Markdown: the guide's `reference/configuration.md`.
    #[command(hide = true)]
    ConfigReference,
}

/// Where a command writes when `--plot` is given without `--out`: `vibrotribo-out/COMMAND`
/// in the working directory.
pub const DEFAULT_OUT: &str = "vibrotribo-out";

/// Gives a command run with `--plot` and no `--out` the default folder, and says so.
fn default_out(command: &mut Command) {
    let (name, out, plot) = match command {
        Command::Simulate(a) => ("simulate", &mut a.out, a.plot),
        Command::LoadSweep(a) => ("load-sweep", &mut a.out, a.plot),
        Command::Periodic(a) => ("periodic", &mut a.out, a.plot),
        Command::Continue(a) => ("continue", &mut a.out, a.plot),
        Command::Bifmap(a) => ("bifmap", &mut a.out, a.plot),
        Command::Sweep(a) => ("sweep", &mut a.out, a.plot),
        Command::Chirp(a) => ("chirp", &mut a.out, a.plot),
        Command::Map(a) => ("map", &mut a.out, a.plot),
        Command::OptimizeMassRatio(a) => ("optimize-mass-ratio", &mut a.out, a.plot),
        Command::Lyapunov(a) => ("lyapunov", &mut a.out, a.plot),
        Command::Basins(a) => ("basins", &mut a.out, a.plot),
        Command::Attractors(a) => ("attractors", &mut a.out, a.plot),
        Command::Response(a) => ("response", &mut a.out, a.plot),
        Command::BandResponse(a) => ("band-response", &mut a.out, a.plot),
        _ => return,
    };
    if plot && out.is_none() {
        let dir = std::path::Path::new(DEFAULT_OUT).join(name);
        println!(
            "vibrotribo {name}: no --out given, writing into {}",
            dir.display()
        );
        *out = Some(dir);
    }
}

/// Options of `vibrotribo plot`.
#[derive(Debug, clap::Args)]
struct PlotArgs {
    /// A directory written by a command with `--out` (`simulate`, `sweep`, `map`, `chirp`,
    /// `lyapunov`, `basins`, `attractors`, `continue`, `bifmap`, `response`, `band-response`, …).
    dir: std::path::PathBuf,
    /// PSD of this mass only (1-based; default: every mass).
    #[arg(long)]
    psd_mass: Option<usize>,
}

fn run() -> anyhow::Result<()> {
    let mut cli = Cli::parse();
    default_out(&mut cli.command);
    progress::install_interrupt_handler()
        .map_err(|e| anyhow::anyhow!("cannot install the signal handlers: {e}"))?;
    match cli.command {
        Command::Simulate(args) => simulate::run(&args),
        Command::LoadSweep(args) => load_sweep::run(&args),
        Command::ExportSpice(args) => export_spice::run(&args),
        Command::Periodic(args) => periodic::run(&args),
        Command::Continue(args) => continuation::run(&args),
        Command::Curve(args) => curve::run(&args),
        Command::Bifmap(args) => bifmap::run(&args),
        Command::Sweep(args) => sweep::run(&args),
        Command::Merge(args) => merge::run(&args),
        Command::Chirp(args) => chirp::run(&args),
        Command::Map(args) => map::run(&args),
        Command::OptimizeMassRatio(args) => map::optimize(&args),
        Command::Optimize(args) => optimize::run(&args),
        Command::Response(args) => response::run(&args),
        Command::BandResponse(args) => band_response::run(&args),
        Command::Lyapunov(args) => lyapunov::run(&args),
        Command::Basins(args) => basins::run(&args),
        Command::Attractors(args) => attractors::run(&args),
        Command::Reproduce(args) => reproduce::run(&args),
        Command::Plot(args) => plots::plot_dir(&args.dir, args.psd_mass),
        Command::Serve(args) => serve::run(&args),
        Command::ConfigReference => {
            print!("{}", vibrotribo::config::reference_markdown());
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    let result = run();
    // The pictures drawn, also when the command stopped on the way.
    plot::drawn::report();
    let result = result.and(stdout::finish());
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => match e.downcast_ref::<progress::Interrupted>() {
            Some(stop) => {
                eprintln!("{stop}");
                ExitCode::from(progress::interrupt_status())
            }
            None => {
                eprintln!("error: {e:#}");
                ExitCode::FAILURE
            }
        },
    }
}
