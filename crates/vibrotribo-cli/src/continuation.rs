//! `vibrotribo continue`: a periodic orbit followed in a parameter by pseudo-arclength
//! continuation ([`vibrotribo::orbits::continue_orbit`]), with its stability, the
//! bifurcations located on the way (folds, period doublings followed onto the doubled
//! branch, Neimark–Sacker, grazing, sticking), and the power along the branches.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use vibrotribo::ChainParams;
use vibrotribo::branch::{BranchError, BranchOptions, config_family, continue_config};
use vibrotribo::config::Config;
use vibrotribo::orbits::{
    Bifurcation, BifurcationKind, BranchEnd, BranchPoint, Continuation, ContinuationOptions, OrbitError,
    ShootingOptions,
};

use crate::branch_picture::Drawing;
pub use crate::branch_picture::{Diagram, describe};
use crate::config::ConfigArgs;
use crate::manifest::{
    BifurcationRecord, BranchRecord, CascadeRecord, ContinueManifest, Kind, ParentRecord, to_value,
};
use crate::output::{CsvFile, create_dir, csv_text, multipliers_text, numbered, write_json};
use crate::progress::{Interrupted, Progress, interrupted, orbit_cancel};

/// Values of the brute-force orbit diagram under a continuation's picture, by default.
pub const DEFAULT_DIAGRAM_STEPS: usize = 200;

/// Options of `vibrotribo continue`.
#[derive(Debug, clap::Args)]
pub struct ContinueArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// The parameter: any key `sweep --param` accepts (`omega_ratio`, `mass_ratio`,
    /// `gap_ratio`, `excitation.amplitude`, …).
    #[arg(long)]
    pub param: String,
    /// Start of the branch: the orbit found there.
    #[arg(long, allow_negative_numbers = true)]
    pub from: f64,
    /// The other end of the range.
    #[arg(long, allow_negative_numbers = true)]
    pub to: f64,
    /// Period of the first orbit, in excitation periods (default: detected after the
    /// transient).
    #[arg(long)]
    pub period: Option<u32>,
    /// Periods simulated at `--from` from the configured initial state before shooting.
    #[arg(long, default_value_t = BranchOptions::default().transient)]
    pub transient: u32,
    /// Period doublings followed onto the doubled branch (a cascade P → 2P → 4P … this deep).
    #[arg(long, default_value_t = BranchOptions::default().continuation.doubling_depth)]
    pub doublings: u32,
    /// Most points per branch.
    #[arg(long, default_value_t = BranchOptions::default().continuation.max_points)]
    pub max_points: usize,
    /// Mechanics only: no power along the branches.
    #[arg(long)]
    pub mechanics_only: bool,
    /// Write branch.csv, bifurcations.csv and continue.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also draw the branches over a brute-force orbit diagram (without --out: into vibrotribo-out/continue).
    #[arg(long)]
    pub plot: bool,
    /// Values of the brute-force orbit diagram drawn under the branches with --plot.
    #[arg(long, default_value_t = DEFAULT_DIAGRAM_STEPS)]
    pub diagram_steps: usize,
    /// The mass shown in the plot (1-based; default 2, or 1 for a single mass).
    #[arg(long)]
    pub mass: Option<usize>,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs `vibrotribo continue`.
pub fn run(args: &ContinueArgs) -> Result<()> {
    if args.period == Some(0) {
        bail!("--period must be at least 1");
    }
    if !(args.from.is_finite() && args.to.is_finite()) || args.from == args.to {
        bail!("--from and --to must be finite and different");
    }
    let config = args.input.load()?;
    config.check_uncoupled("continue")?;
    config.check_periodic("continuation of periodic orbits (`continue`)")?;
    let mass = args.mass.unwrap_or(if config.chain().len() > 1 { 2 } else { 1 });
    if mass == 0 || mass > config.chain().len() {
        bail!("--mass must be between 1 and {}", config.chain().len());
    }
    let d = BranchOptions::default();
    let options = BranchOptions {
        transient: args.transient,
        period: args.period,
        continuation: ContinuationOptions {
            doubling_depth: args.doublings,
            max_points: args.max_points,
            shooting: ShootingOptions {
                cancel: orbit_cancel(),
                ..d.continuation.shooting
            },
            ..d.continuation
        },
    };
    let spinner = Progress::spinner("continuing", args.quiet);
    let result = continue_config(&config, &args.param, args.from, args.to, None, &options);
    spinner.finish();
    let result = match result {
        Err(BranchError::FirstOrbit {
            source: OrbitError::Cancelled,
            ..
        }) => {
            return Err(Interrupted {
                what: "stopped before the first orbit was found; nothing written".into(),
            }
            .into());
        }
        other => other?,
    };
    let family = config_family(&config, &args.param);
    let power = if args.mechanics_only {
        None
    } else {
        let points = result.branches.iter().map(|b| b.points.len() as u64).sum();
        let bar = Progress::new(points, "power", args.quiet);
        let powers = vibrotribo::branch::branch_powers(&config, &args.param, &result, || {
            bar.inc(1);
            if interrupted() {
                std::ops::ControlFlow::Break(())
            } else {
                std::ops::ControlFlow::Continue(())
            }
        });
        bar.finish();
        Some(powers)
    };
    // Stopped by a signal during the continuation or the power: what was computed is written,
    // marked incomplete (the power of points not reached is left empty).
    let complete = result.complete && !interrupted();
    print_continuation(&args.param, &result);
    if let Some(dir) = &args.out {
        create_dir(dir)?;
        write_files(dir, &config, args, &result, power.as_deref(), complete)?;
        if args.plot {
            let diagram = Diagram {
                param: &args.param,
                range: (args.from.min(args.to), args.from.max(args.to)),
                mass: mass - 1,
                transient: u64::from(args.transient.max(300)),
                steps: args.diagram_steps,
            };
            plot_branches(dir, "continuation", &config, &diagram, &result, &family)?;
        }
        println!(
            "  wrote {0}/branch.csv, {0}/bifurcations.csv, {0}/continue.json",
            dir.display()
        );
    }
    if !complete {
        return Err(Interrupted {
            what: match &args.out {
                Some(dir) => format!(
                    "the files in {} hold the branches as far as they were followed (\"complete\": false)",
                    dir.display()
                ),
                None => "the branches above are as far as they were followed".into(),
            },
        }
        .into());
    }
    Ok(())
}

/// How a branch ends, in words.
pub fn end_text(end: &BranchEnd) -> String {
    match end {
        BranchEnd::RangeEnd { parameter } => format!("range end at {parameter}"),
        BranchEnd::MaxPoints => "point limit reached".into(),
        BranchEnd::StepFloor {
            parameter, reason, ..
        } => {
            format!("no continuation past {parameter} (step floor: {reason:?})")
        }
        BranchEnd::Grazing {
            parameter,
            contact,
            gap,
        } => format!(
            "runs into a grazing of contact {} at {parameter} (gap minimum {gap:.3e} m): no orbit with the new impact found on either side",
            contact + 1
        ),
        BranchEnd::CascadeDepth { parameter } => {
            format!("period doubling at {parameter} beyond the depth followed (--doublings)")
        }
        BranchEnd::Unlocated {
            parameter,
            between: (a, b),
        } => format!(
            "a multiplier near −1 could not be located between {a} and {b}: not followed past {parameter}"
        ),
        BranchEnd::SwitchFailed { parameter } => {
            format!("could not switch onto the doubled branch at {parameter}")
        }
        BranchEnd::Collapsed { parameter } => format!("fell back onto the half-period orbit at {parameter}"),
        BranchEnd::Closed { parameter } => format!("closes on itself at {parameter} (followed once round)"),
        BranchEnd::Retraced { parameter } => format!(
            "turns back along its own orbits at {parameter} past a change of sequence (from there on it repeats them in reverse)"
        ),
        BranchEnd::Rejoined { parameter, branch } => {
            format!("reaches the branch point of branch {branch} at {parameter}, followed from there")
        }
        BranchEnd::RunsOnto { parameter, branch } => {
            format!(
                "runs onto branch {branch} at {parameter} past a change of sequence (from there on it is that branch)"
            )
        }
        BranchEnd::Stopped { parameter } => format!("stopped by a signal after {parameter}"),
        other => format!("{other:?}"),
    }
}

fn print_continuation(param: &str, result: &Continuation) {
    println!(
        "vibrotribo continue: {} branch(es) in {param}",
        result.branches.len()
    );
    for (i, b) in result.branches.iter().enumerate() {
        let stable = b.points.iter().filter(|p| p.stable).count();
        println!(
            "  branch {i} (period {}{}): {} points ({stable} stable); {}",
            b.period,
            b.parent
                .map_or(String::new(), |(p, _)| format!(", born on branch {p}")),
            b.points.len(),
            end_text(&b.end)
        );
        for f in &b.bifurcations {
            let (kind, detail) = describe(&f.kind);
            let crossing = f.crossing.map_or(String::new(), |c| {
                let nordmark = c
                    .nordmark
                    .map_or(String::new(), |n| format!(", square-root map: {}", n.name()));
                let radius = |p: &BranchPoint| p.spectral_radius();
                format!(
                    " [{}{nordmark}; |λ|max {:.4} → {:.4}]",
                    c.kind.name(),
                    radius(&f.point),
                    f.after.as_ref().map_or(f64::NAN, radius)
                )
            });
            println!(
                "    {kind} at {param} = {:.10} (±{:.1e}){}{crossing}",
                f.parameter,
                f.precision,
                if detail.is_empty() {
                    String::new()
                } else {
                    format!(": {detail}")
                }
            );
        }
    }
    let cascade: Vec<f64> = vibrotribo::orbits::cascade(result)
        .iter()
        .map(|b| b.parameter)
        .collect();
    if cascade.len() >= 3 {
        let ratios = vibrotribo::orbits::feigenbaum_ratios(&cascade);
        println!(
            "  cascade: period doublings at {param} = {}; Feigenbaum ratios {}",
            cascade
                .iter()
                .map(|p| format!("{p:.10}"))
                .collect::<Vec<_>>()
                .join(", "),
            ratios
                .iter()
                .map(|r| format!("{r:.4}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
}

/// The columns and rows of `branch.csv`: every point of every branch, numbers written
/// exactly (`power`: the average power along each branch, W, if computed).
pub fn branch_table(
    config: &Config,
    result: &Continuation,
    power: Option<&[Vec<f64>]>,
) -> (Vec<String>, Vec<Vec<String>>) {
    let n = config.chain().len();
    let mut cols: Vec<String> = [
        "branch",
        "period",
        "param",
        "stable",
        "max_abs_multiplier",
        "unstable_multipliers",
    ]
    .map(String::from)
    .to_vec();
    cols.extend(numbered("x", n, "_m"));
    cols.extend(numbered("v", n, "_m_s"));
    cols.push("impacts_per_period".into());
    cols.extend(numbered(
        "impacts_per_period_",
        config.chain().contact_count(),
        "",
    ));
    cols.extend(["min_closing_speed_m_s", "sticks", "average_power_w", "arclength"].map(String::from));
    let mut rows = Vec::new();
    for (i, b) in result.branches.iter().enumerate() {
        for (j, p) in b.points.iter().enumerate() {
            let mut row = vec![
                i.to_string(),
                b.period.to_string(),
                p.parameter.to_string(),
                p.stable.to_string(),
                p.spectral_radius().to_string(),
                p.multipliers
                    .iter()
                    .filter(|m| m.norm() > 1.0)
                    .count()
                    .to_string(),
            ];
            row.extend(p.state.positions.iter().map(f64::to_string));
            row.extend(p.state.velocities.iter().map(f64::to_string));
            row.push(p.impacts_per_period.iter().sum::<f64>().to_string());
            row.extend(p.impacts_per_period.iter().map(f64::to_string));
            row.push(p.min_closing_speed.map_or(String::new(), |m| m.1.to_string()));
            row.push(p.sticks.to_string());
            row.push(
                power
                    .and_then(|pw| pw.get(i).and_then(|b| b.get(j)))
                    .filter(|v| v.is_finite())
                    .map_or(String::new(), |v| v.to_string()),
            );
            row.push(p.arclength.to_string());
            rows.push(row);
        }
    }
    (cols, rows)
}

fn write_files(
    dir: &Path,
    config: &Config,
    args: &ContinueArgs,
    result: &Continuation,
    power: Option<&[Vec<f64>]>,
    complete: bool,
) -> Result<()> {
    let (cols, rows) = branch_table(config, result, power);
    let mut csv = CsvFile::create(&dir.join("branch.csv"), &cols)?;
    for row in rows {
        csv.row(row)?;
    }
    csv.flush()?;
    let mut bif = CsvFile::create(
        &dir.join("bifurcations.csv"),
        &[
            "branch",
            "kind",
            "param",
            "precision",
            "contact",
            "detail",
            "child_branch",
            "multipliers",
            "crossing",
            "nordmark",
            "multipliers_after",
            "other_child_branch",
        ],
    )?;
    let mut listed = Vec::new();
    for (i, b) in result.branches.iter().enumerate() {
        for f in &b.bifurcations {
            let (kind, detail) = describe(&f.kind);
            let contact = match f.kind {
                BifurcationKind::Grazing { contact, .. } | BifurcationKind::Sticking { contact, .. } => {
                    (contact + 1).to_string()
                }
                _ => String::new(),
            };
            bif.row([
                i.to_string(),
                kind.to_string(),
                f.parameter.to_string(),
                f.precision.to_string(),
                contact,
                csv_text(&detail),
                f.child.map_or(String::new(), |c| c.to_string()),
                csv_text(&multipliers_text(&f.point.multipliers)),
                f.crossing.map_or(String::new(), |c| c.kind.name().to_string()),
                f.crossing
                    .and_then(|c| c.nordmark)
                    .map_or(String::new(), |n| n.name().to_string()),
                f.after
                    .as_ref()
                    .map_or(String::new(), |a| csv_text(&multipliers_text(&a.multipliers))),
                f.other_child.map_or(String::new(), |c| c.to_string()),
            ])?;
            listed.push(bifurcation_record(i, f));
        }
    }
    bif.flush()?;
    let branches: Vec<BranchRecord> = result
        .branches
        .iter()
        .map(|b| BranchRecord {
            period: b.period,
            parent: b
                .parent
                .map(|(branch, bifurcation)| ParentRecord { branch, bifurcation }),
            points: b.points.len(),
            end: end_text(&b.end),
        })
        .collect();
    let points: Vec<f64> = vibrotribo::orbits::cascade(result)
        .iter()
        .map(|b| b.parameter)
        .collect();
    let manifest = ContinueManifest {
        command: Kind::Continue,
        complete,
        param: args.param.clone(),
        from: args.from,
        to: args.to,
        transient_periods: args.transient,
        doublings: args.doublings,
        max_points: args.max_points,
        mechanics_only: args.mechanics_only,
        branches,
        bifurcations: listed,
        cascade: CascadeRecord {
            feigenbaum_ratios: vibrotribo::orbits::feigenbaum_ratios(&points),
            period_doublings: points,
        },
        settings: crate::manifest::settings_of(config)?,
        vibrotribo_version: crate::manifest::version(),
    };
    write_json(&dir.join("continue.json"), &to_value(&manifest)?)
}

fn bifurcation_record(branch: usize, f: &Bifurcation) -> BifurcationRecord {
    let (kind, detail) = describe(&f.kind);
    let pairs = |p: &BranchPoint| p.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>();
    BifurcationRecord {
        branch,
        kind: kind.to_string(),
        detail,
        param: f.parameter,
        precision: f.precision,
        child_branch: f.child,
        other_child_branch: f.other_child,
        multipliers: pairs(&f.point),
        crossing: f.crossing.map(|c| c.kind.name().to_string()),
        nordmark: f.crossing.and_then(|c| c.nordmark).map(|n| n.name().to_string()),
        multipliers_after: f.after.as_ref().map(pairs),
        state: f
            .point
            .state
            .positions
            .iter()
            .chain(&f.point.state.velocities)
            .copied()
            .collect(),
    }
}

/// The branches (stable solid, unstable dashed; every point of a period-P orbit on the
/// section) over a brute-force orbit diagram, bifurcations marked: `{name}.png`/`.svg`.
pub fn plot_branches(
    dir: &Path,
    name: &str,
    config: &Config,
    diagram: &Diagram<'_>,
    result: &Continuation,
    family: &impl Fn(f64) -> ChainParams,
) -> Result<()> {
    crate::branch_picture::draw(dir, name, config, diagram, &Drawing::of(result), family)
}
