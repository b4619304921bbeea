//! `vibrotribo band-response`: the response to band-limited random input
//! ([`vibrotribo::response::band_response`]): average power against the centre frequency of
//! the band, moved across frequencies at a fixed width and RMS acceleration, the mean over
//! several seeds with its standard error; `response.csv`, `seeds.csv`,
//! `band_response.json` and the picture.

use std::ops::ControlFlow;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use vibrotribo::response::{
    BandOptions, BandPlan, BandResponse, DEFAULT_BAND_SEEDS, ResponseError, band_response, band_seed_table,
    band_table,
};
use vibrotribo::sweep::{PointRunner, grid};

use crate::config::ConfigArgs;
use crate::manifest::{BandResponseManifest, to_value};
use crate::output::{check_out_dir, create_dir, write_json};
use crate::progress::{Interrupted, Progress, interrupted};
use crate::response::{PointArgs, check_range, write_rows};
use crate::response_picture::band_text;

/// Options of `vibrotribo band-response`.
#[derive(Debug, clap::Args)]
pub struct BandResponseArgs {
    /// A configuration whose base motion is band-limited noise with a flat spectrum
    /// (`excitation.kind = "random"`, `rms_acceleration`, `f_low_hz`, `f_high_hz`).
    #[command(flatten)]
    pub input: ConfigArgs,
    /// First centre frequency of the band, Hz.
    #[arg(long, allow_negative_numbers = true, value_name = "HZ")]
    pub from: f64,
    /// Last centre frequency, Hz (above --from).
    #[arg(long, allow_negative_numbers = true, value_name = "HZ")]
    pub to: f64,
    /// Number of centres, equally spaced from --from to --to.
    #[arg(long)]
    pub steps: usize,
    /// Width of the band, Hz (default: the configured f_high_hz − f_low_hz).
    #[arg(long, allow_negative_numbers = true, value_name = "HZ")]
    pub width: Option<f64>,
    /// Seeds per centre: excitation.seed, excitation.seed + 1, … (the power is their mean,
    /// with its standard error).
    #[arg(long, default_value_t = DEFAULT_BAND_SEEDS)]
    pub seeds: u64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    #[command(flatten)]
    pub run: PointArgs,
    /// Write response.csv, seeds.csv and band_response.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also draw the response (without --out: into vibrotribo-out/band-response).
    #[arg(long)]
    pub plot: bool,
}

/// Runs `vibrotribo band-response`.
pub fn run(args: &BandResponseArgs) -> Result<()> {
    check_range(args.from, args.to, args.steps)?;
    crate::job::set_threads(args.threads)?;
    let runner = args.run.runner(args.input.load_within(args.run.allow_large)?)?;
    let plan = BandPlan::new(
        runner.base(),
        &BandOptions {
            centres_hz: grid(args.from, args.to, args.steps),
            width_hz: args.width,
            seeds: args.seeds,
        },
    )
    .map_err(option_error)?;
    let points = plan.points().len();
    args.run.check_size(
        "--steps × --seeds",
        &runner,
        points as f64,
        rayon::current_num_threads() as f64,
    )?;
    if let Some(dir) = &args.out {
        check_out_dir(dir, "band_response.json", args.run.force, |_| true)?;
    }
    let started = Instant::now();
    let bar = Progress::new(points as u64, "runs", args.run.quiet);
    let r = band_response(&runner, &plan, None, || {
        bar.inc(1);
        if interrupted() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    })?;
    bar.finish();
    let elapsed = started.elapsed().as_secs_f64();
    let bandwidth = r.summary().bandwidth;
    println!(
        "vibrotribo band-response: {} Hz band at {} m/s² RMS, centres {} to {} Hz ({} values) × {} seeds in {elapsed:.2} s",
        plan.width_hz,
        plan.rms_acceleration,
        args.from,
        args.to,
        args.steps,
        plan.seeds.len()
    );
    println!("  {}", band_text(bandwidth.as_ref(), " Hz"));
    if let Some(dir) = &args.out {
        create_dir(dir)?;
        write_rows(&dir.join("response.csv"), &band_table(&r))?;
        write_rows(&dir.join("seeds.csv"), &band_seed_table(&r))?;
        let m = manifest(args, &runner, &r, elapsed)?;
        write_json(&dir.join("band_response.json"), &to_value(&m)?)?;
        println!(
            "  wrote {0}/response.csv, {0}/seeds.csv, {0}/band_response.json",
            dir.display()
        );
        if args.plot {
            crate::response_picture::plot_band_response(dir)?;
        }
    }
    if !r.complete {
        return Err(Interrupted {
            what: format!(
                "after {} of {points} runs{}",
                r.results.len(),
                if args.out.is_some() {
                    "; the files hold the centres whose seeds all ran (\"complete\": false)"
                } else {
                    ""
                }
            ),
        }
        .into());
    }
    Ok(())
}

/// A library error in the words of the command line (`--width`, `--seeds`).
fn option_error(e: ResponseError) -> anyhow::Error {
    match e {
        ResponseError::Option { name, value, reason } => {
            let option = match name {
                "width_hz" => "--width",
                "seeds" => "--seeds",
                other => other,
            };
            anyhow::anyhow!("{option} {value}: {reason}")
        }
        other => other.into(),
    }
}

/// `band_response.json`.
fn manifest(
    args: &BandResponseArgs,
    runner: &PointRunner,
    r: &BandResponse,
    elapsed: f64,
) -> Result<BandResponseManifest> {
    Ok(BandResponseManifest::new(
        runner,
        (args.from, args.to, args.steps),
        r.summary(),
        elapsed,
    )?)
}
