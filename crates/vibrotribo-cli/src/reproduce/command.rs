//! The `reproduce` command: its options and the sequence of the paper's figures.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};

use super::bifmaps::bifurcation_maps;
use super::chatter::figs_20_25;
use super::configurations::figs_5_6;
use super::context::{Budget, Ctx};
use super::coupling::coupling;
use super::design::design;
use super::dynamics::dynamics;
use super::extras::extras;
use super::mass_ratio::{fig_13, fig_17, figs_14_16, figs_18_19};
use super::orbits::periodic_orbits;
use super::report::write_report;
use super::spacing::{fig_12, figs_7_11};
use super::vibration::vibration;
use crate::job::set_threads;
use crate::output::create_dir;
use crate::progress::check_interrupt;

/// Options of `vibrotribo reproduce`.
#[derive(Debug, clap::Args)]
pub struct ReproduceArgs {
    /// Coarser grids and shorter runs (a few minutes on two cores).
    #[arg(long)]
    pub quick: bool,
    /// Output directory (REPORT.md, figures, data).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress output.
    #[arg(long, short)]
    pub quiet: bool,
}

/// One part of the reproduction.
type Step = fn(&mut Ctx) -> Result<()>;

/// Runs `vibrotribo reproduce`.
pub fn run(args: &ReproduceArgs) -> Result<()> {
    set_threads(args.threads)?;
    create_dir(&args.out)?;
    let budget = if args.quick {
        Budget {
            transient: 300,
            recorded: 128,
            coarse: 201,
            fine: 101,
            series: 100,
        }
    } else {
        Budget {
            transient: 400,
            recorded: 128,
            coarse: 401,
            fine: 201,
            series: 200,
        }
    };
    let mut ctx = Ctx {
        out: args.out.clone(),
        budget,
        quick: args.quick,
        quiet: args.quiet,
        figures: Vec::new(),
        findings: Vec::new(),
        extras: Vec::new(),
        failures: std::sync::Mutex::new(Vec::new()),
    };
    let started = Instant::now();
    let steps: [(&str, Step); 15] = [
        ("Figs. 5–6: mass configurations", figs_5_6),
        ("Figs. 7–11: asymmetric spacing R_δ", figs_7_11),
        ("Fig. 12: symmetric spacing δ", fig_12),
        ("Fig. 13: mass ratio and impacts per period", fig_13),
        ("Figs. 14–16: optimal mass ratio", figs_14_16),
        ("Fig. 17: high frequencies", fig_17),
        ("Figs. 18–19: Ω = 0.30", figs_18_19),
        ("Figs. 20–25: chatter", figs_20_25),
        ("periodic orbits behind Figs. 7, 9, 14–15, 18–19", periodic_orbits),
        (
            "bifurcation maps of the default case in (Ω, R_m) and (Ω, R_δ)",
            bifurcation_maps,
        ),
        (
            "what the non-periodic motions are: exponents, error bars, basins, expected power",
            dynamics,
        ),
        ("beyond the paper: loads and V_oc model", extras),
        ("beyond the paper: real vibration (record, noise)", vibration),
        ("beyond the paper: two-way coupling", coupling),
        (
            "beyond the paper: the device re-optimised under the breakdown limit",
            design,
        ),
    ];
    for (what, step) in steps {
        let t0 = Instant::now();
        ctx.say(&format!("{what} …"));
        step(&mut ctx).with_context(|| what.to_string())?;
        ctx.say(&format!("{what}: {:.1} s", t0.elapsed().as_secs_f64()));
        check_interrupt(|| {
            format!(
                "after {what}: the figures of the finished steps are in {}; REPORT.md is written only by a complete run",
                ctx.out.display()
            )
        })?;
    }
    let elapsed = started.elapsed().as_secs_f64();
    write_report(&ctx, elapsed)?;
    println!(
        "reproduced {} figures and {} findings in {elapsed:.1} s; see {}",
        ctx.figures.len(),
        ctx.findings.len(),
        args.out.join("REPORT.md").display()
    );
    Ok(())
}
