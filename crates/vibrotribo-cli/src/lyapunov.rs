//! `vibrotribo lyapunov`: the Lyapunov spectrum of one configuration
//! ([`vibrotribo::study::lyapunov_spectrum`]), with its convergence.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Result, bail};
use vibrotribo::lyapunov::{LyapunovOptions, LyapunovSpectrum};
use vibrotribo::study::{Ending, lyapunov_spectrum};

use crate::config::ConfigArgs;
use crate::manifest::{Kind, LyapunovManifest, RunningRecord, finite, finite_all, read, to_value};
use crate::output::{create_dir, write_json};
use crate::plot::{self, Figure, Legend, Series};
use crate::progress::{Interrupted, Progress, Watch};

/// Options of `vibrotribo lyapunov`.
#[derive(Debug, clap::Args)]
pub struct LyapunovArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// Excitation periods averaged over, after the transient.
    #[arg(long, default_value_t = 1000)]
    pub periods: u64,
    /// Transient periods (the motion settles and the tangent vectors align).
    #[arg(long, default_value_t = 300)]
    pub transient: u64,
    /// Seed of the random initial tangent basis.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Batches of periods for the spread (batch means).
    #[arg(long, default_value_t = 10)]
    pub batches: usize,
    /// Write lyapunov.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also draw the running exponents (PNG and SVG) into the output directory.
    #[arg(long)]
    pub plot: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Build a random base motion even if it costs more than 10⁹ harmonic evaluations.
    #[arg(long)]
    pub allow_large: bool,
}

/// An exponent for people: `−∞` for a collapsed direction.
fn show(x: f64) -> String {
    if x == f64::NEG_INFINITY {
        "−∞".into()
    } else {
        format!("{x:+.5}")
    }
}

/// Runs `vibrotribo lyapunov`.
pub fn run(args: &LyapunovArgs) -> Result<()> {
    if args.periods == 0 {
        bail!("--periods must be at least 1");
    }
    let config = args.input.load_within(args.allow_large)?;
    config.check_uncoupled("lyapunov")?;
    config.check_periodic("Lyapunov exponents (`lyapunov`)")?;
    let mut spec = config.run_spec(true);
    spec.transient_periods = args.transient;
    spec.periods = args.transient + args.periods;
    let options = LyapunovOptions {
        seed: args.seed,
        batches: args.batches,
        ..LyapunovOptions::default()
    };
    let mut watch = Watch {
        progress: Progress::new(spec.periods, "periods", args.quiet),
    };
    let started = Instant::now();
    let run = lyapunov_spectrum(&spec, &options, &mut watch)?;
    watch.progress.finish();
    let elapsed = started.elapsed().as_secs_f64();
    if let Ending::Failed(e) = &run.outcome.ending {
        eprintln!(
            "warning: the run failed after {} periods: {e}",
            run.outcome.periods
        );
    }
    let interrupted = run.outcome.ending == Ending::Stopped;
    let spectrum = run.spectrum?;
    println!(
        "Lyapunov spectrum over {} periods after {} transient ({:.2} s simulated, {elapsed:.2} s):",
        spectrum.periods, args.transient, spectrum.time
    );
    for (i, (l, s)) in spectrum.exponents.iter().zip(&spectrum.spread).enumerate() {
        if l.is_finite() {
            println!("  λ{} = {} ± {:.5} 1/s", i + 1, show(*l), s);
        } else {
            println!("  λ{} = −∞ (a stuck contact removes this direction)", i + 1);
        }
    }
    println!(
        "  sum {} 1/s, Kaplan–Yorke dimension {:.3}, {} directions collapsed by sticking, {} periods skipped at {} non-differentiable points",
        show(spectrum.sum()),
        spectrum.kaplan_yorke_dimension(),
        spectrum.collapsed,
        spectrum.skipped_periods,
        spectrum.non_smooth_count
    );
    if let Some(dir) = &args.out {
        create_dir(dir)?;
        write_json(
            &dir.join("lyapunov.json"),
            &to_value(&manifest(&spectrum, args, interrupted, &config)?)?,
        )?;
        if args.plot {
            plot_lyapunov(dir)?;
        }
        println!("  wrote {}/lyapunov.json", dir.display());
    }
    if interrupted {
        return Err(Interrupted {
            what: format!(
                "after {} periods{}",
                run.outcome.periods,
                if args.out.is_some() {
                    "; lyapunov.json holds the spectrum so far, marked \"interrupted\": true"
                } else {
                    ""
                }
            ),
        }
        .into());
    }
    Ok(())
}

/// `lyapunov.json`: exponents (1/s, largest first; `null` for −∞), their spread, the
/// convergence and the settings.
fn manifest(
    s: &LyapunovSpectrum,
    args: &LyapunovArgs,
    interrupted: bool,
    config: &vibrotribo::config::Config,
) -> Result<LyapunovManifest> {
    Ok(LyapunovManifest {
        command: Kind::Lyapunov,
        exponents: finite_all(&s.exponents),
        spread: finite_all(&s.spread),
        periods: s.periods,
        time_s: s.time,
        largest: finite(s.largest()),
        largest_spread: finite(s.largest_spread()),
        sum: finite(s.sum()),
        kaplan_yorke_dimension: finite(s.kaplan_yorke_dimension()),
        collapsed: s.collapsed,
        skipped_periods: s.skipped_periods,
        non_smooth_count: s.non_smooth_count,
        non_smooth: s.non_smooth.iter().map(ToString::to_string).collect(),
        reorthonormalisations: s.reorthonormalisations,
        batches: s.batches.iter().map(|b| finite_all(b)).collect(),
        running: s
            .running
            .iter()
            .map(|(n, e)| RunningRecord {
                periods: *n,
                exponents: finite_all(e),
            })
            .collect(),
        transient_periods: args.transient,
        seed: args.seed,
        interrupted,
        settings: crate::manifest::settings_of(config)?,
    })
}

/// Draws the running exponents of a `lyapunov` directory (`lyapunov_running.png`/`.svg`).
pub fn plot_lyapunov(dir: &Path) -> Result<()> {
    let m: LyapunovManifest = read(&dir.join("lyapunov.json"))?;
    let periods: Vec<f64> = m.running.iter().map(|r| r.periods as f64).collect();
    let dim = m.exponents.len();
    let columns: Vec<Vec<f64>> = (0..dim)
        .map(|i| {
            m.running
                .iter()
                .map(|r| r.exponents.get(i).copied().flatten().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let labels: Vec<String> = (1..=dim).map(|i| format!("λ{i}")).collect();
    let series: Vec<Series<'_>> = labels
        .iter()
        .zip(&columns)
        .filter(|(_, c)| c.iter().any(|x| x.is_finite()))
        .map(|(l, c)| Series::new(l, &periods, c))
        .collect();
    let mut fig = Figure::new(
        "Running Lyapunov exponents (after each batch of periods)",
        "periods averaged",
        "λ [1/s]",
    );
    fig.legend = Legend::UpperRight;
    crate::plot::both(dir, "lyapunov_running", |path| {
        plot::line_plot(path, &fig, &series)
    })
}
