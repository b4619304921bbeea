//! The `vibrotribo` command-line program: argument parsing, configuration files, output
//! files and plots. All physics lives in the `vibrotribo` library.

mod config;
mod export_spice;
mod harvester;
mod load_sweep;
mod output;
#[allow(dead_code)] // parts are used as commands gain --plot
mod plot;
mod progress;
mod simulate;

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
}

fn run() -> anyhow::Result<()> {
    let cli = Cli::parse();
    progress::install_interrupt_handler();
    match cli.command {
        Command::Simulate(args) => simulate::run(&args),
        Command::LoadSweep(args) => load_sweep::run(&args),
        Command::ExportSpice(args) => export_spice::run(&args),
    }
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
