//! The picture of a continuation: its branches (stable solid, unstable dashed) over a
//! brute-force orbit diagram, with each bifurcation marked by its kind. Drawn from a
//! [`Continuation`] (`continue --plot`, `reproduce`) or from the files of a `continue`
//! directory (`plot DIR`), through one [`Drawing`], so both give the same picture.

use std::path::Path;

use anyhow::{Context, Result, bail};
use vibrotribo::config::Config;
use vibrotribo::orbits::{BifurcationKind, Continuation};
use vibrotribo::study::PointOptions;
use vibrotribo::sweep::{PointRunner, grid};
use vibrotribo::{ChainParams, ChainState, Simulator};

use crate::manifest::{ContinueManifest, config_of, read};
use crate::output::{column, read_csv};
use crate::plot::{self, Figure, Legend, Series, Shape, both};

/// A point of a branch as drawn: the parameter, the orbit's state at t ≡ 0 (mod T) and its
/// stability.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawnPoint {
    /// The parameter's value.
    pub parameter: f64,
    /// The orbit's state on the section.
    pub state: ChainState,
    /// Whether the orbit is stable.
    pub stable: bool,
}

/// A bifurcation as drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawnBifurcation {
    /// Its kind's name, as `bifurcations.csv` writes it (`fold`, `period_doubling`, …).
    pub kind: String,
    /// The parameter there.
    pub parameter: f64,
    /// The orbit's state on the section there.
    pub state: ChainState,
}

/// A branch as drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawnBranch {
    /// Period of its orbits, in excitation periods.
    pub period: u32,
    /// Its points, in order.
    pub points: Vec<DrawnPoint>,
    /// Its bifurcations.
    pub bifurcations: Vec<DrawnBifurcation>,
}

/// What a picture of branches draws.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Drawing {
    /// The branches.
    pub branches: Vec<DrawnBranch>,
}

impl Drawing {
    /// The drawing of a continuation's result.
    pub fn of(result: &Continuation) -> Self {
        let branches = result
            .branches
            .iter()
            .map(|b| DrawnBranch {
                period: b.period,
                points: b
                    .points
                    .iter()
                    .map(|p| DrawnPoint {
                        parameter: p.parameter,
                        state: p.state.clone(),
                        stable: p.stable,
                    })
                    .collect(),
                bifurcations: b
                    .bifurcations
                    .iter()
                    .map(|f| DrawnBifurcation {
                        kind: describe(&f.kind).0.to_string(),
                        parameter: f.parameter,
                        state: f.point.state.clone(),
                    })
                    .collect(),
            })
            .collect();
        Drawing { branches }
    }

    /// The drawing of a `continue` directory: `branch.csv` and the bifurcations of
    /// `continue.json` (`m`).
    pub fn read(dir: &Path, m: &ContinueManifest) -> Result<Self> {
        let (h, rows) = read_csv(&dir.join("branch.csv"))?;
        let masses = h
            .iter()
            .filter(|c| c.starts_with('x') && c.ends_with("_m"))
            .count();
        let (cb, cp, cs) = (column(&h, "branch")?, column(&h, "param")?, column(&h, "stable")?);
        let xs: Vec<usize> = (1..=masses)
            .map(|i| column(&h, &format!("x{i}_m")))
            .collect::<Result<_>>()?;
        let vs: Vec<usize> = (1..=masses)
            .map(|i| column(&h, &format!("v{i}_m_s")))
            .collect::<Result<_>>()?;
        let mut branches: Vec<DrawnBranch> = m
            .branches
            .iter()
            .map(|b| DrawnBranch {
                period: b.period,
                points: Vec::new(),
                bifurcations: Vec::new(),
            })
            .collect();
        let number = |r: &[String], c: usize| -> Result<f64> {
            r[c].parse::<f64>()
                .with_context(|| format!("branch.csv: {} is not a number", r[c]))
        };
        for r in &rows {
            let b: usize = r[cb].parse().context("branch.csv: branch")?;
            let Some(branch) = branches.get_mut(b) else {
                bail!("branch.csv: branch {b} is not in continue.json");
            };
            branch.points.push(DrawnPoint {
                parameter: number(r, cp)?,
                state: ChainState {
                    positions: xs.iter().map(|&c| number(r, c)).collect::<Result<_>>()?,
                    velocities: vs.iter().map(|&c| number(r, c)).collect::<Result<_>>()?,
                },
                stable: r[cs] == "true",
            });
        }
        for f in &m.bifurcations {
            let Some(branch) = branches.get_mut(f.branch) else {
                bail!(
                    "continue.json: bifurcation on branch {}, which it does not list",
                    f.branch
                );
            };
            if f.state.len() != 2 * masses {
                bail!(
                    "continue.json: a bifurcation's state has {} entries, expected {} (positions and velocities)",
                    f.state.len(),
                    2 * masses
                );
            }
            branch.bifurcations.push(DrawnBifurcation {
                kind: f.kind.clone(),
                parameter: f.param,
                state: ChainState {
                    positions: f.state[..masses].to_vec(),
                    velocities: f.state[masses..].to_vec(),
                },
            });
        }
        Ok(Drawing { branches })
    }
}

/// The default brute-force diagram of `continue --plot` (the mass shown, 1-based: `None` for
/// the default; values of the diagram).
pub fn diagram_of<'a>(
    m: &'a ContinueManifest,
    masses: usize,
    mass: Option<usize>,
    steps: usize,
) -> Result<Diagram<'a>> {
    let mass = mass.unwrap_or(if masses > 1 { 2 } else { 1 });
    if mass == 0 || mass > masses {
        bail!("the mass shown must be between 1 and {masses}");
    }
    Ok(Diagram {
        param: &m.param,
        range: (m.from.min(m.to), m.from.max(m.to)),
        mass: mass - 1,
        transient: u64::from(m.transient_periods.max(300)),
        steps,
    })
}

/// Draws `continuation.png`/`.svg` from the files of the `continue` directory `dir`, with the
/// mass `mass` (1-based; `None`: the default) and `steps` values of the diagram.
pub fn plot_dir(dir: &Path, mass: Option<usize>, steps: usize) -> Result<()> {
    let m: ContinueManifest = read(&dir.join("continue.json"))?;
    let config = config_of(&m.settings)?;
    let drawing = Drawing::read(dir, &m)?;
    let diagram = diagram_of(&m, config.chain().len(), mass, steps)?;
    let family = vibrotribo::branch::config_family(&config, &m.param);
    draw(dir, "continuation", &config, &diagram, &drawing, &family)
}

/// The bifurcation kinds by their name in `bifurcations.csv`: legend entry, marker shape and
/// palette colour.
const MARKS: [(&str, &str, Shape, usize); 7] = [
    ("fold", "fold", Shape::Triangle, 1),
    ("branch_point", "branch point", Shape::Square, 4),
    ("period_doubling", "period doubling", Shape::Circle, 2),
    ("neimark_sacker", "Neimark–Sacker", Shape::Diamond, 6),
    ("grazing", "grazing", Shape::Cross, 5),
    ("sticking", "sticking", Shape::Square, 8),
    ("sequence_change", "sequence change", Shape::Diamond, 9),
];

/// The legend entry, marker shape and palette colour of a bifurcation's kind (by name).
pub fn marker_of(kind: &str) -> (&'static str, Shape, usize) {
    MARKS
        .iter()
        .find(|m| m.0 == kind)
        .map_or(("other", Shape::Diamond, 7), |m| (m.1, m.2, m.3))
}

/// The bifurcations of one kind on a picture: legend entry, marker shape, palette colour, and
/// the points (parameter, section position).
type Marks = (&'static str, Shape, usize, Vec<f64>, Vec<f64>);

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

/// The branches (stable solid, unstable dashed; every point of a period-P orbit on the
/// section) over a brute-force orbit diagram, bifurcations marked: `{name}.png`/`.svg`.
pub fn draw(
    dir: &Path,
    name: &str,
    config: &Config,
    diagram: &Diagram<'_>,
    drawing: &Drawing,
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
    let axes = Axes {
        title: format!("Periodic orbits in {}", diagram.param),
        x_label: diagram.param.to_string(),
        y_label: format!("x{} at t = nT [m]", mass + 1),
        mass,
        scale: 1.0,
    };
    draw_over(dir, name, config, &axes, (&dx, &dy), drawing, family)
}

/// How a picture of branches is labelled and scaled.
pub struct Axes {
    /// The title.
    pub title: String,
    /// The parameter's label.
    pub x_label: String,
    /// The position's label.
    pub y_label: String,
    /// The mass shown, 0-based.
    pub mass: usize,
    /// Positions are drawn times this (1: metres).
    pub scale: f64,
}

/// The branches of `drawing` (scaled and labelled by `axes`) over the brute-force points
/// `brute` (parameter, position already scaled), bifurcations marked: `{name}.png`/`.svg`.
pub fn draw_over(
    dir: &Path,
    name: &str,
    config: &Config,
    axes: &Axes,
    (dx, dy): (&[f64], &[f64]),
    drawing: &Drawing,
    family: &impl Fn(f64) -> ChainParams,
) -> Result<()> {
    let mass = axes.mass;
    let scaled = |v: Vec<f64>| v.into_iter().map(|x| x * axes.scale).collect::<Vec<f64>>();
    // Branch curves: one series per run of equal stability and per section point.
    let mut curves: Vec<(Vec<f64>, Vec<f64>, bool)> = Vec::new();
    for b in &drawing.branches {
        let sections: Vec<Vec<f64>> = b
            .points
            .iter()
            .map(|p| {
                scaled(section_positions(
                    &family(p.parameter),
                    &p.state,
                    b.period,
                    mass,
                    config,
                ))
            })
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
    for b in &drawing.branches {
        for f in &b.bifurcations {
            let (label, shape, colour) = marker_of(&f.kind);
            let ys = scaled(section_positions(
                &family(f.parameter),
                &f.state,
                b.period,
                mass,
                config,
            ));
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
    let mut points = vec![Series::new("brute force", dx, dy).colour(7)];
    points.extend(
        marks
            .iter()
            .map(|(label, shape, colour, x, y)| Series::new(label, x, y).colour(*colour).marker(*shape, 11)),
    );
    let mut fig = Figure::new(axes.title.clone(), axes.x_label.clone(), axes.y_label.clone());
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

/// What a bifurcation is ([`BifurcationKind::name`]), with its detail in words.
pub fn describe(kind: &BifurcationKind) -> (&'static str, String) {
    let detail = match kind {
        BifurcationKind::NeimarkSacker { angle } => format!("angle {angle} rad"),
        BifurcationKind::Grazing { contact, appears } => format!(
            "contact {}: impact {}",
            contact + 1,
            if *appears { "appears" } else { "disappears" }
        ),
        BifurcationKind::Sticking { contact, onset } => format!(
            "contact {}: sticking {}",
            contact + 1,
            if *onset { "begins" } else { "ends" }
        ),
        _ => String::new(),
    };
    (kind.name(), detail)
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
