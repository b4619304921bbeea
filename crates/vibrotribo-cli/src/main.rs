//! The `vibrotribo` command-line program: argument parsing, configuration files, output
//! files and plots. All physics lives in the `vibrotribo` library.

mod config;
mod harvester;
mod output;
#[allow(dead_code)] // wired into commands as they gain --plot
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
}

fn run() -> anyhow::Result<()> {
    let cli = Cli::parse();
    progress::install_interrupt_handler();
    match cli.command {
        Command::Simulate(args) => simulate::run(&args),
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
