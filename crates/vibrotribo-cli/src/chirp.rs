//! `vibrotribo chirp`: a frequency-sweep experiment, the chain driven by a slow chirp of the
//! base up and then down in Ω ([`vibrotribo::study::chirp_study`]); the per-cycle response
//! of both directions (`response.csv`), their jumps (`chirp.json`) and the two response
//! curves drawn together (`--plot`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Result, bail};
use vibrotribo::config::Config;
use vibrotribo::excitation::Sweep;
use vibrotribo::study::{
    ChirpError, ChirpOptions, ChirpRun, DEFAULT_JUMP_WINDOW, DEFAULT_SAMPLES_PER_CYCLE, Direction, Ending,
    chirp_inputs, run_chirp,
};

use crate::config::ConfigArgs;
use crate::manifest::{
    ChirpManifest, ChirpRunRecord, ChirpSettingsRecord, HysteresisRecord, JumpRecord, Kind, read,
    settings_of, to_value, version,
};
use crate::output::{CsvFile, column, create_dir, numbered, numbers, read_csv, write_json};
use crate::plot::{self, Figure, Legend, Series, both};
use crate::progress::{Interrupted, Progress, Watch, interrupted, orbit_cancel};

/// `--sweep`: how the frequency moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SweepLaw(pub Sweep);

impl std::str::FromStr for SweepLaw {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "linear" => Ok(SweepLaw(Sweep::Linear)),
            "logarithmic" => Ok(SweepLaw(Sweep::Logarithmic)),
            other => Err(format!(
                "unknown --sweep {other:?}: expected linear or logarithmic"
            )),
        }
    }
}

/// Options of `vibrotribo chirp`.
#[derive(Debug, clap::Args)]
pub struct ChirpArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// Lower end of the sweep, Ω = ω/√(k1/m1).
    #[arg(long, allow_negative_numbers = true)]
    pub from: f64,
    /// Upper end of the sweep, Ω (above --from).
    #[arg(long, allow_negative_numbers = true)]
    pub to: f64,
    /// Duration of each chirp (up, then down), s.
    #[arg(long, allow_negative_numbers = true, value_name = "SECONDS")]
    pub duration: f64,
    /// `linear` or `logarithmic` in frequency.
    #[arg(long, default_value = "linear", value_name = "linear|logarithmic", value_parser = clap::value_parser!(SweepLaw))]
    pub sweep: SweepLaw,
    /// Base displacement amplitude, m (default: the configuration's excitation.amplitude).
    #[arg(long, allow_negative_numbers = true, value_name = "M")]
    pub amplitude: Option<f64>,
    /// Mechanics only: no harvester, no power column (faster).
    #[arg(long)]
    pub mechanics_only: bool,
    /// Start each chirp from the configuration's initial state instead of the steady motion
    /// at its start frequency (the start-up transient then shows in the response).
    #[arg(long)]
    pub from_rest: bool,
    /// Samples of the motion per cycle at the highest frequency (amplitudes are the extremes
    /// over the samples and the events).
    #[arg(long, default_value_t = DEFAULT_SAMPLES_PER_CYCLE)]
    pub samples_per_cycle: u64,
    /// The jump is where the median amplitude of this many cycles after a cycle boundary
    /// differs most from that of as many before it (1: the plain cycle-to-cycle change).
    #[arg(long, default_value_t = DEFAULT_JUMP_WINDOW, value_name = "CYCLES")]
    pub jump_window: usize,
    /// Write response.csv and chirp.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also draw the response curves, up and down together (without --out: into vibrotribo-out/chirp).
    #[arg(long)]
    pub plot: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

/// A library error in the words of the command line (`--from`, `--duration`, …).
fn option_error(e: ChirpError) -> anyhow::Error {
    match e {
        ChirpError::Option { option, message } => {
            anyhow::anyhow!("--{}: {message}", option.replace('_', "-"))
        }
        other => other.into(),
    }
}

/// Runs `vibrotribo chirp`.
pub fn run(args: &ChirpArgs) -> Result<()> {
    let config = args.input.load()?;
    let options = ChirpOptions {
        from: args.from,
        to: args.to,
        duration_s: args.duration,
        sweep: args.sweep.0,
        amplitude: args.amplitude,
        mechanics_only: args.mechanics_only,
        settled_start: !args.from_rest,
        samples_per_cycle: args.samples_per_cycle,
        jump_window: args.jump_window,
        cancel: orbit_cancel(),
        ..ChirpOptions::new(args.from, args.to, args.duration)
    };
    // Both chirps checked first: a bad option fails before anything runs.
    let (spec, options) = chirp_inputs(&config, &options).map_err(option_error)?;
    let periods = 2 * options.run_periods(&spec.chain);
    if let Some(dir) = &args.out {
        create_dir(dir)?;
    }
    let started = Instant::now();
    let mut watch = Watch {
        progress: Progress::new(periods, "periods", args.quiet),
    };
    let mut runs = Vec::new();
    for d in [Direction::Up, Direction::Down] {
        let r = match run_chirp(&spec, &options, d, &mut watch) {
            Ok(r) => r,
            // Stopped by a signal while building the chirp's base motion or settling at its
            // start frequency: the chirps done are kept (none for the up chirp).
            Err(_) if interrupted() => break,
            Err(e) => return Err(option_error(e)),
        };
        let stop = r.outcome.ending != Ending::Completed;
        runs.push(r);
        if stop {
            break;
        }
    }
    watch.progress.finish();
    let elapsed = started.elapsed().as_secs_f64();
    print_summary(&config, &options, &runs, elapsed);
    if let Some(dir) = &args.out {
        write_response(dir, &config, &runs, args.mechanics_only)?;
        write_json(
            &dir.join("chirp.json"),
            &to_value(&manifest(&config, &options, &runs, elapsed)?)?,
        )?;
        println!("  wrote {0}/response.csv, {0}/chirp.json", dir.display());
        if args.plot {
            plot_chirp(dir)?;
        }
    }
    for r in &runs {
        if let Ending::Failed(e) = &r.outcome.ending {
            bail!(
                "the {} chirp stopped after {} periods: {e}",
                r.direction.as_str(),
                r.outcome.periods
            );
        }
    }
    if runs.len() < 2 || runs.iter().any(|r| r.outcome.ending == Ending::Stopped) {
        let completed = runs
            .iter()
            .filter(|r| r.outcome.ending == Ending::Completed)
            .count();
        return Err(Interrupted {
            what: format!(
                "after {completed} of {} chirps{}",
                2,
                if args.out.is_some() {
                    "; the files hold the cycles completed, chirp.json says \"complete\": false"
                } else {
                    ""
                }
            ),
        }
        .into());
    }
    Ok(())
}

fn print_summary(config: &Config, options: &ChirpOptions, runs: &[ChirpRun], elapsed: f64) {
    let chain = config.chain();
    let hz = chain.omega() / chain.omega_ratio() / std::f64::consts::TAU;
    println!(
        "vibrotribo chirp: {} masses, Ω from {} to {} ({:.4} to {:.4} Hz), {} s each way ({}), amplitude {}",
        chain.len(),
        options.from,
        options.to,
        options.from * hz,
        options.to * hz,
        options.duration_s,
        options.sweep.as_str(),
        runs.first()
            .map_or("not reached (no chirp ran)".to_string(), |r| format!(
                "{} m",
                r.chirp.amplitude
            )),
    );
    for r in runs {
        match &r.jump {
            Some(j) => println!(
                "  {:>4}: {} cycles, {} impacts; largest jump at Ω = {:.4}: mass {} amplitude {:+.4e} m ({:.1}% of its largest)",
                r.direction.as_str(),
                r.cycles.len(),
                r.cycles.iter().map(|c| c.impacts).sum::<u64>(),
                j.omega_ratio,
                j.mass + 1,
                j.size_m,
                100.0 * j.relative
            ),
            None if r.cycles.len() < 2 * options.jump_window => println!(
                "  {:>4}: {} cycles; no jump located: that needs at least 2 × --jump-window = {} cycles",
                r.direction.as_str(),
                r.cycles.len(),
                2 * options.jump_window
            ),
            None => println!(
                "  {:>4}: {} cycles; no jump located",
                r.direction.as_str(),
                r.cycles.len()
            ),
        }
    }
    if let [up, down] = runs
        && let (Some(u), Some(d)) = (&up.jump, &down.jump)
    {
        println!(
            "  hysteresis: up jumps at Ω = {:.4}, down at Ω = {:.4} (apart by {:.4})",
            u.omega_ratio,
            d.omega_ratio,
            u.omega_ratio - d.omega_ratio
        );
    }
    println!("  ran in {elapsed:.2} s");
}

/// `response.csv`: one row per cycle, the up chirp's then the down chirp's.
fn write_response(dir: &Path, config: &Config, runs: &[ChirpRun], mechanics_only: bool) -> Result<()> {
    let n = config.chain().len();
    let mut cols: Vec<String> = ["direction", "cycle", "time_s", "omega_ratio", "frequency_hz"]
        .map(String::from)
        .to_vec();
    cols.extend(numbered("amplitude", n, "_m"));
    cols.push("impacts".into());
    let power = !mechanics_only && n > 1;
    if power {
        cols.push("power_w".into());
    }
    let mut f = CsvFile::create(&dir.join("response.csv"), &cols)?;
    for r in runs {
        for c in &r.cycles {
            let mut row = vec![
                r.direction.as_str().to_string(),
                c.cycle.to_string(),
                c.time_s.to_string(),
                c.omega_ratio.to_string(),
                c.frequency_hz.to_string(),
            ];
            row.extend(c.amplitudes.iter().map(f64::to_string));
            row.push(c.impacts.to_string());
            if power {
                row.push(c.power_w().map_or(String::new(), |p| p.to_string()));
            }
            f.row(row)?;
        }
    }
    f.flush()
}

fn run_record(r: &ChirpRun) -> ChirpRunRecord {
    ChirpRunRecord {
        f_start_hz: r.chirp.f_start_hz,
        f_end_hz_requested: r.chirp.frequency_hz(r.duration_s),
        run_duration_s: r.chirp.duration,
        periods: r.outcome.periods,
        cycles: r.cycles.len(),
        impacts: r.cycles.iter().map(|c| c.impacts).sum::<u64>(),
        complete: r.outcome.ending == Ending::Completed,
        failure: r.outcome.failure().map(|e| e.to_string()),
        jump: r.jump.as_ref().map(|j| JumpRecord {
            omega_ratio: j.omega_ratio,
            frequency_hz: r.chirp.frequency_hz(r.cycles[j.index].end_s),
            cycle: r.cycles[j.index].cycle,
            mass: j.mass + 1,
            size_m: j.size_m,
            relative: j.relative,
        }),
        base_motion: vibrotribo::report::BaseMotionSummary::of(&r.spec),
    }
}

/// `chirp.json`: the settings, per direction the run and its jump, the hysteresis.
fn manifest(
    config: &Config,
    options: &ChirpOptions,
    runs: &[ChirpRun],
    elapsed: f64,
) -> Result<ChirpManifest> {
    let find = |d: Direction| runs.iter().find(|r| r.direction == d);
    let jump = |d: Direction| find(d).and_then(|r| r.jump.as_ref()).map(|j| j.omega_ratio);
    Ok(ChirpManifest {
        command: Kind::Chirp,
        chirp: ChirpSettingsRecord::of(config, options, runs.first().map(|r| r.chirp.amplitude)),
        up: find(Direction::Up).map(run_record),
        down: find(Direction::Down).map(run_record),
        hysteresis: match (jump(Direction::Up), jump(Direction::Down)) {
            (Some(u), Some(d)) => Some(HysteresisRecord {
                up_jump_omega_ratio: u,
                down_jump_omega_ratio: d,
                width: u - d,
            }),
            _ => None,
        },
        complete: runs.len() == 2 && runs.iter().all(|r| r.outcome.ending == Ending::Completed),
        wall_time_s: elapsed,
        settings: settings_of(config)?,
        vibrotribo_version: version(),
    })
}

/// `response.png`/`.svg`: each mass's amplitude against Ω, up (solid) and down (dashed)
/// together, from `response.csv`.
pub fn plot_chirp(dir: &Path) -> Result<()> {
    let m: ChirpManifest = read(&dir.join("chirp.json"))?;
    let (header, rows) = read_csv(&dir.join("response.csv"))?;
    let dir_col = column(&header, "direction")?;
    let omega = column(&header, "omega_ratio")?;
    let masses = header.iter().filter(|h| h.starts_with("amplitude")).count();
    let mut data = Vec::new();
    for i in 0..masses {
        let a = column(&header, &format!("amplitude{}_m", i + 1))?;
        for d in ["up", "down"] {
            let part: Vec<Vec<String>> = rows.iter().filter(|r| r[dir_col] == d).cloned().collect();
            data.push((
                format!("m{} {d}", i + 1),
                numbers(&part, omega),
                numbers(&part, a),
                i,
                d == "down",
            ));
        }
    }
    let series: Vec<Series<'_>> = data
        .iter()
        .map(|(label, x, y, i, down)| {
            let s = Series::new(label, x, y).colour(2 * i + usize::from(*down));
            if *down { s.dashed() } else { s }
        })
        .collect();
    let figure = Figure {
        legend: Legend::UpperLeft,
        ..Figure::new(
            format!(
                "Chirp response, {} s each way ({})",
                serde_json::Value::from(m.chirp.duration_s),
                m.chirp.sweep
            ),
            "Ω = ω/√(k1/m1)",
            "amplitude relative to the base (m)",
        )
    };
    both(dir, "response", |p| plot::line_plot(p, &figure, &series))
}
