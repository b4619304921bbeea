//! `vibrotribo continue`: a periodic orbit followed in a parameter by pseudo-arclength
//! continuation ([`vibrotribo::orbits::continue_orbit`]), with its stability, the
//! bifurcations located on the way (folds, period doublings followed onto the doubled
//! branch, Neimark–Sacker, grazing, sticking), and the power along the branches.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use serde_json::json;
use vibrotribo::branch::{BranchOptions, config_family, continue_config};
use vibrotribo::config::Config;
use vibrotribo::orbits::{
    Bifurcation, BifurcationKind, BranchEnd, BranchPoint, Continuation, ContinuationOptions,
};
use vibrotribo::study::PointOptions;
use vibrotribo::sweep::{PointRunner, grid};
use vibrotribo::{ChainParams, ChainState, Simulator};

use crate::config::ConfigArgs;
use crate::output::{CsvFile, create_dir, csv_text, numbered, write_json};
use crate::plot::{self, Figure, Legend, Series, Shape, both};

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
    #[arg(long, default_value_t = 200)]
    pub diagram_steps: usize,
    /// The mass shown in the plot (1-based; default 2, or 1 for a single mass).
    #[arg(long)]
    pub mass: Option<usize>,
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
            ..d.continuation
        },
    };
    let result = continue_config(&config, &args.param, args.from, args.to, None, &options)?;
    let family = config_family(&config, &args.param);
    let power = if args.mechanics_only {
        None
    } else {
        Some(vibrotribo::branch::branch_powers(
            &config,
            &args.param,
            &result,
            || std::ops::ControlFlow::Continue(()),
        ))
    };
    print_continuation(&args.param, &result);
    if let Some(dir) = &args.out {
        create_dir(dir)?;
        write_files(dir, &config, args, &result, power.as_deref())?;
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
    Ok(())
}

/// What a bifurcation is, in words, with its detail.
pub fn describe(kind: &BifurcationKind) -> (&'static str, String) {
    match kind {
        BifurcationKind::Fold => ("fold", String::new()),
        BifurcationKind::BranchPoint => ("branch_point", String::new()),
        BifurcationKind::PeriodDoubling => ("period_doubling", String::new()),
        BifurcationKind::NeimarkSacker { angle } => ("neimark_sacker", format!("angle {angle} rad")),
        BifurcationKind::Grazing { contact, appears } => (
            "grazing",
            format!(
                "contact {}: impact {}",
                contact + 1,
                if *appears { "appears" } else { "disappears" }
            ),
        ),
        BifurcationKind::Sticking { contact, onset } => (
            "sticking",
            format!(
                "contact {}: sticking {}",
                contact + 1,
                if *onset { "begins" } else { "ends" }
            ),
        ),
        BifurcationKind::SequenceChange => ("sequence_change", String::new()),
        _ => ("other", format!("{kind:?}")),
    }
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
        BranchEnd::SwitchFailed { parameter } => {
            format!("could not switch onto the doubled branch at {parameter}")
        }
        BranchEnd::Collapsed { parameter } => format!("fell back onto the half-period orbit at {parameter}"),
        BranchEnd::Closed { parameter } => format!("a closed curve, back at its start at {parameter}"),
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

fn multipliers_text(p: &BranchPoint) -> String {
    p.multipliers
        .iter()
        .map(|m| format!("{}{:+}i", m.re, m.im))
        .collect::<Vec<_>>()
        .join(" ")
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
                csv_text(&multipliers_text(&f.point)),
                f.crossing.map_or(String::new(), |c| c.kind.name().to_string()),
                f.crossing
                    .and_then(|c| c.nordmark)
                    .map_or(String::new(), |n| n.name().to_string()),
                f.after
                    .as_ref()
                    .map_or(String::new(), |a| csv_text(&multipliers_text(a))),
            ])?;
            listed.push(bifurcation_json(i, f));
        }
    }
    bif.flush()?;
    let branches: Vec<serde_json::Value> = result
        .branches
        .iter()
        .map(|b| {
            json!({
                "period": b.period,
                "parent": b.parent.map(|(p, k)| json!({"branch": p, "bifurcation": k})),
                "points": b.points.len(),
                "end": end_text(&b.end),
            })
        })
        .collect();
    write_json(
        &dir.join("continue.json"),
        &json!({
            "command": "continue",
            "param": args.param,
            "from": args.from,
            "to": args.to,
            "transient_periods": args.transient,
            "doublings": args.doublings,
            "max_points": args.max_points,
            "mechanics_only": args.mechanics_only,
            "branches": branches,
            "bifurcations": listed,
            "cascade": cascade_json(result),
            "settings": config.table(),
            "vibrotribo_version": env!("CARGO_PKG_VERSION"),
        }),
    )
}

/// The cascade of period doublings from the first branch and its Feigenbaum ratios.
fn cascade_json(result: &Continuation) -> serde_json::Value {
    let points: Vec<f64> = vibrotribo::orbits::cascade(result)
        .iter()
        .map(|b| b.parameter)
        .collect();
    json!({
        "period_doublings": points,
        "feigenbaum_ratios": vibrotribo::orbits::feigenbaum_ratios(&points),
    })
}

fn bifurcation_json(branch: usize, f: &Bifurcation) -> serde_json::Value {
    let (kind, detail) = describe(&f.kind);
    json!({
        "branch": branch,
        "kind": kind,
        "detail": detail,
        "param": f.parameter,
        "precision": f.precision,
        "child_branch": f.child,
        "multipliers": f.point.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>(),
        "crossing": f.crossing.map(|c| c.kind.name()),
        "nordmark": f.crossing.and_then(|c| c.nordmark).map(|n| n.name()),
        "multipliers_after": f.after.as_ref().map(|a| a.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>()),
    })
}

/// The positions of `mass` at t = kT, k = 0 … period − 1, along the orbit through `state`.
pub fn section_positions(
    chain: &ChainParams,
    state: &ChainState,
    period: u32,
    mass: usize,
    config: &Config,
) -> Vec<f64> {
    let mut out = vec![state.positions[mass]];
    let Ok(mut sim) = Simulator::new(chain, state, config.sim_options().clone()) else {
        return out;
    };
    for k in 1..period {
        if sim.run_until(f64::from(k) * chain.period(), &mut ()).is_err() {
            break;
        }
        out.push(sim.state().positions[mass]);
    }
    out
}

/// The brute-force orbit diagram under a picture of branches.
pub struct Diagram<'a> {
    /// The parameter's key.
    pub param: &'a str,
    /// Its range.
    pub range: (f64, f64),
    /// The mass shown, 0-based.
    pub mass: usize,
    /// Transient periods of each value (from the configured initial state).
    pub transient: u64,
    /// Values of the parameter.
    pub steps: usize,
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
    let mass = diagram.mass;
    let (lo, hi) = diagram.range;
    // Brute force: every value from the configured initial state, mechanics only.
    let options = PointOptions {
        transient_periods: diagram.transient,
        recorded_periods: 64,
        ..PointOptions::default()
    };
    let runner = PointRunner::new(config.clone(), options, true);
    let values = grid(lo, hi, diagram.steps.max(2));
    let mut dx = Vec::new();
    let mut dy = Vec::new();
    let _ = vibrotribo::sweep::run_grid(
        &runner,
        &values,
        |&v| vec![(diagram.param, v)],
        64,
        |d| {
            if let vibrotribo::sweep::Delivery::Point(&v, Ok(p)) = d {
                for x in p.position_series(mass) {
                    dx.push(v);
                    dy.push(x);
                }
            }
            std::ops::ControlFlow::Continue(())
        },
    );
    // Branch curves: one series per run of equal stability and per section point.
    let mut curves: Vec<(Vec<f64>, Vec<f64>, bool)> = Vec::new();
    for b in &result.branches {
        let sections: Vec<Vec<f64>> = b
            .points
            .iter()
            .map(|p| section_positions(&family(p.parameter), &p.state, b.period, mass, config))
            .collect();
        for k in 0..b.period as usize {
            let mut start = 0;
            while start < b.points.len() {
                let stable = b.points[start].stable;
                let mut end = start;
                while end + 1 < b.points.len() && b.points[end + 1].stable == stable {
                    end += 1;
                }
                // Runs overlap by one point so that the branch is drawn without holes.
                let stop = (end + 1).min(b.points.len() - 1);
                let xs: Vec<f64> = (start..=stop).map(|j| b.points[j].parameter).collect();
                let ys: Vec<f64> = (start..=stop)
                    .map(|j| sections[j].get(k).copied().unwrap_or(f64::NAN))
                    .collect();
                curves.push((xs, ys, stable));
                start = end + 1;
            }
        }
    }
    // Bifurcations: a marker per kind on the branch, at each section point of its orbit.
    let mut marks: Vec<Marks> = Vec::new();
    for b in &result.branches {
        for f in &b.bifurcations {
            let (label, shape, colour) = marker_of(&f.kind);
            let ys = section_positions(&family(f.parameter), &f.point.state, b.period, mass, config);
            let at = match marks.iter().position(|m| m.0 == label) {
                Some(i) => i,
                None => {
                    marks.push((label, shape, colour, Vec::new(), Vec::new()));
                    marks.len() - 1
                }
            };
            for y in ys {
                marks[at].3.push(f.parameter);
                marks[at].4.push(y);
            }
        }
    }
    let mut lines: Vec<Series> = Vec::new();
    let (mut stable_named, mut unstable_named) = (false, false);
    for (x, y, stable) in &curves {
        let named = if *stable {
            &mut stable_named
        } else {
            &mut unstable_named
        };
        let s = if *named {
            Series::unlabelled(x, y)
        } else {
            Series::new(if *stable { "stable" } else { "unstable" }, x, y)
        };
        *named = true;
        lines.push(if *stable {
            s.colour(0)
        } else {
            s.colour(3).dashed()
        });
    }
    let mut points = vec![Series::new("brute force", &dx, &dy).colour(7)];
    points.extend(
        marks
            .iter()
            .map(|(label, shape, colour, x, y)| Series::new(label, x, y).colour(*colour).marker(*shape, 11)),
    );
    let mut fig = Figure::new(
        format!("Periodic orbits in {}", diagram.param),
        diagram.param,
        format!("x{} at t = nT [m]", mass + 1),
    );
    let all_x = dx.iter().chain(curves.iter().flat_map(|c| c.0.iter()));
    let all_y = dy.iter().chain(curves.iter().flat_map(|c| c.1.iter()));
    fig.legend = emptier_upper_corner(all_x.copied().zip(all_y.copied()));
    both(dir, name, |path| {
        plot::lines_and_points(path, &fig, &lines, &points, 3)
    })
}

/// The upper corner of the data's box with fewer points in its top-left or top-right third
/// (where the legend hides the least).
fn emptier_upper_corner(points: impl Iterator<Item = (f64, f64)> + Clone) -> Legend {
    let finite = points.filter(|(x, y)| x.is_finite() && y.is_finite());
    let bounds = |pick: fn(&(f64, f64)) -> f64| {
        finite
            .clone()
            .map(|p| pick(&p))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            })
    };
    let ((x0, x1), (y0, y1)) = (bounds(|p| p.0), bounds(|p| p.1));
    let top = y1 - (y1 - y0) / 3.0;
    let count = |left: bool| {
        finite
            .clone()
            .filter(|(x, y)| {
                *y >= top
                    && if left {
                        *x <= x0 + (x1 - x0) / 3.0
                    } else {
                        *x >= x1 - (x1 - x0) / 3.0
                    }
            })
            .count()
    };
    if count(true) < count(false) {
        Legend::UpperLeft
    } else {
        Legend::UpperRight
    }
}

/// The bifurcations of one kind on a picture: legend entry, marker shape, palette colour, and
/// the points (parameter, section position).
type Marks = (&'static str, Shape, usize, Vec<f64>, Vec<f64>);

/// The legend entry, marker shape and palette colour of a bifurcation's kind.
fn marker_of(kind: &BifurcationKind) -> (&'static str, Shape, usize) {
    match kind {
        BifurcationKind::Fold => ("fold", Shape::Triangle, 1),
        BifurcationKind::BranchPoint => ("branch point", Shape::Square, 4),
        BifurcationKind::PeriodDoubling => ("period doubling", Shape::Circle, 2),
        BifurcationKind::NeimarkSacker { .. } => ("Neimark–Sacker", Shape::Diamond, 6),
        BifurcationKind::Grazing { .. } => ("grazing", Shape::Cross, 5),
        BifurcationKind::Sticking { .. } => ("sticking", Shape::Square, 8),
        BifurcationKind::SequenceChange => ("sequence change", Shape::Diamond, 9),
        _ => ("other", Shape::Diamond, 7),
    }
}
