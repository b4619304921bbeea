//! Beyond the paper: the paper's device re-optimised over its gaps, mass ratio, stiffness
//! and load under its sine and under the recorded vibration, with every air gap kept below
//! 90 % of breakdown (the search of `vibrotribo optimize`): how much more power than the
//! paper's design, which constraint binds, how robust the optimum is to the start (expected
//! power over random starts), and what the optimum does to the half-power bandwidth.

use anyhow::{Context, Result, bail};
use vibrotribo::config::Config;
use vibrotribo::optimize::{
    Cache, Constraint, Evaluation, Objective, OptimizeError, OptimizeOptions, Problem, Variable, evaluate,
    optimize,
};
use vibrotribo::response::{ResponseOptions, frequency_response};
use vibrotribo::study::{Direction, SettleMode};
use vibrotribo::sweep::grid;

use super::context::Ctx;
use super::draw::lines;
use super::vibration::with_record;
use crate::output::si;
use crate::plot::{Figure, Legend};
use crate::progress::{Interrupted, interrupted};

/// The varied keys and their ranges.
const VARY: [&str; 4] = [
    "oscillator.gaps=0.005..0.04",
    "mass_ratio=1.2..4",
    "oscillator.stiffness=60..240",
    "harvester.load_resistance=1e9..1e12",
];

/// The breakdown limit, and the ratio at which it counts as binding.
const LIMIT: f64 = 0.9;
const BINDS_FROM: f64 = 0.98 * LIMIT;

/// The paper's default case driven by the recorded vibration (`configs/record_default.toml`),
/// its record file named by [`RECORD_FILE`].
const RECORD_DEFAULT: &str = include_str!("../../../../configs/record_default.toml");
const RECORD_FILE: &str = "\"records/rjob_vertical_acceleration.csv\"";

/// The work of one mode.
struct Sizes {
    /// The search over the four keys.
    search: OptimizeOptions,
    /// The search over the paper's design's load alone.
    load: OptimizeOptions,
    /// Random starts of the robustness check.
    starts: u64,
    /// `run.periods`, `run.transient_periods` of every design's run.
    periods: (i64, i64),
    /// Values of Ω of the frequency responses.
    response_steps: usize,
}

impl Sizes {
    fn of(quick: bool) -> Self {
        if quick {
            Sizes {
                search: OptimizeOptions {
                    particles: 4,
                    swarm_iterations: 1,
                    local_iterations: 4,
                    ..OptimizeOptions::default()
                },
                load: OptimizeOptions {
                    particles: 3,
                    swarm_iterations: 1,
                    local_iterations: 3,
                    ..OptimizeOptions::default()
                },
                starts: 3,
                periods: (40, 20),
                response_steps: 11,
            }
        } else {
            Sizes {
                search: OptimizeOptions {
                    particles: 8,
                    swarm_iterations: 4,
                    local_iterations: 20,
                    ..OptimizeOptions::default()
                },
                load: OptimizeOptions {
                    particles: 6,
                    swarm_iterations: 3,
                    local_iterations: 12,
                    ..OptimizeOptions::default()
                },
                starts: 8,
                periods: (100, 50),
                response_steps: 26,
            }
        }
    }
}

/// One re-optimisation and what it is compared with.
struct Redesign {
    /// The paper's design at its 100 kΩ.
    paper: Evaluation,
    /// The paper's design at its best load within the limit (`None`: no load of the range
    /// keeps it there) and that load, Ω.
    paper_best_load: Option<(Evaluation, f64)>,
    /// The best design found.
    best: Evaluation,
    /// Its keys, in the order of [`VARY`].
    variables: Vec<Variable>,
    /// Its place in the unit cube.
    best_unit: Vec<f64>,
    /// Designs the search evaluated.
    evaluations: u64,
    /// The best design from random starts (`expected_power`).
    expected: Evaluation,
    /// The best design as a configuration.
    design: Config,
    /// Random starts of `expected`.
    starts: u64,
}

fn problem(base: &Config, vary: &[&str], objective: Objective, options: OptimizeOptions) -> Result<Problem> {
    let p = Problem {
        base: base.clone(),
        variables: vary
            .iter()
            .map(|v| Variable::parse(base, v))
            .collect::<Result<_, _>>()?,
        objective,
        constraints: vec![Constraint::parse(&format!("breakdown_ratio<={LIMIT}"))?],
        options,
    };
    p.validate()?;
    Ok(p)
}

/// The search of `p`, stopped by SIGINT/SIGTERM.
fn search(p: &Problem) -> Result<Result<vibrotribo::optimize::OptimizeResult, OptimizeError>> {
    let r = optimize(p, &mut Cache::default(), &|_, _, _| {}, &interrupted);
    if matches!(r, Err(OptimizeError::Stopped { .. })) {
        return Err(Interrupted {
            what: "in the re-optimisation; REPORT.md is written only by a complete run".into(),
        }
        .into());
    }
    Ok(r)
}

/// `config` with its reference frequency held in hertz (`excitation.frequency_hz`) instead
/// of as Ω: a design of other masses or stiffness is then driven at the same frequency (the
/// designer's vibration does not move with the device), and its runs last as many seconds.
fn at_fixed_frequency(config: &Config) -> Result<Config> {
    let hz = config.chain().omega() / std::f64::consts::TAU;
    Ok(config.with("excitation.frequency_hz", hz.into())?)
}

/// The paper's device re-optimised under the base motion of `base`.
fn redesign(base: &Config, sizes: &Sizes) -> Result<Redesign> {
    let (periods, transient) = sizes.periods;
    let mut base = at_fixed_frequency(base)?;
    base.set_all([
        ("run.periods", periods.into()),
        ("run.transient_periods", transient.into()),
    ])?;
    // The paper's 100 kΩ: the middle of a log range 10 kΩ–1 MΩ.
    let at_100k = problem(
        &base,
        &["harvester.load_resistance=1e4..1e6"],
        Objective::AveragePower,
        sizes.load,
    )?;
    let paper = evaluate(&at_100k, &[0.5]);
    let load = problem(&base, &[VARY[3]], Objective::AveragePower, sizes.load)?;
    let paper_best_load = match search(&load)? {
        Ok(r) => {
            let resistance = r.best.values[0];
            Some((r.best, resistance))
        }
        Err(OptimizeError::Infeasible { .. }) => None,
        Err(e) => return Err(e).context("the paper's design's best load"),
    };
    let full = problem(&base, &VARY, Objective::AveragePower, sizes.search)?;
    let r = search(&full)?.context("the re-optimisation")?;
    let robust = problem(
        &base,
        &VARY,
        Objective::ExpectedPower,
        OptimizeOptions {
            starts: sizes.starts,
            seed: 1,
            ..sizes.search
        },
    )?;
    let expected = evaluate(&robust, &r.best_unit);
    Ok(Redesign {
        paper,
        paper_best_load,
        design: full.design(&r.best_unit)?,
        best: r.best,
        variables: full.variables,
        best_unit: r.best_unit,
        evaluations: r.evaluations,
        expected,
        starts: sizes.starts,
    })
}

/// The paper's default case under the recorded vibration, the record at `path`.
fn record_config(path: &std::path::Path) -> Result<Config> {
    if !RECORD_DEFAULT.contains(RECORD_FILE) {
        bail!("configs/record_default.toml no longer names {RECORD_FILE}");
    }
    let text = RECORD_DEFAULT.replace(RECORD_FILE, &format!("{:?}", path.display().to_string()));
    Ok(Config::from_toml_str(&text)?)
}

pub(super) fn design(ctx: &mut Ctx) -> Result<()> {
    let sizes = Sizes::of(ctx.quick);
    let sine = redesign(&Config::default(), &sizes)?;
    let record = with_record(|path| redesign(&record_config(path)?, &sizes))?;
    let (paper_band, best_band) = bandwidths(ctx, &sine, &sizes)?;
    let (periods, transient) = sizes.periods;
    let paper_config = Config::default();
    let paper = paper_config.chain();
    ctx.extras.push(format!(
        "**The paper's device re-optimised.** Its {} searched together with every air gap kept below {LIMIT} of breakdown (`vibrotribo optimize`: a particle swarm, then Nelder–Mead; each design a run of {periods} periods, {transient} of them transient), the drive held at the paper's frequency in hertz ({:.3} Hz, its Ω = {:.2} for the paper's design), so that a softer or heavier design meets the same vibration. {} {}",
        ranges(&sine.variables),
        paper.omega() / std::f64::consts::TAU,
        paper.omega_ratio(),
        paragraph("the sine", &sine),
        paragraph("the recorded vibration (`configs/record_default.toml`)", &record),
    ));
    ctx.extras.push(bandwidth_paragraph(&sine, paper_band, best_band));
    Ok(())
}

/// The searched ranges of [`VARY`] in words: gaps in mm, the load in GΩ.
fn ranges(variables: &[Variable]) -> String {
    // Rounded to 1e-6 of the unit shown, so that 0.005 m reads 5 mm, not 5.000000000000001.
    let shown = |x: f64| (x * 1e6).round() / 1e6;
    let range = |i: usize, scale: f64| {
        variables.get(i).map_or(String::new(), |v| {
            format!("{}–{}", shown(v.lo * scale), shown(v.hi * scale))
        })
    };
    format!(
        "gaps δ₁ = δ₂ ({} mm), mass ratio R_m ({}), stiffness k of every spring ({} N/m) and load R ({} GΩ)",
        range(0, 1e3),
        range(1, 1.0),
        range(2, 1.0),
        range(3, 1e-9)
    )
}

/// What binds at the optimum: the breakdown limit, the ends of the ranges.
fn binding(r: &Redesign) -> String {
    let mut binds = Vec::new();
    if r.best.breakdown_ratio >= BINDS_FROM {
        binds.push(format!(
            "air breakdown (ratio {:.3} at the limit {LIMIT})",
            r.best.breakdown_ratio
        ));
    }
    for (v, &u) in r.variables.iter().zip(&r.best_unit) {
        if u <= 0.01 {
            binds.push(format!("the lower end of {} ({})", v.key, v.lo));
        } else if u >= 0.99 {
            binds.push(format!("the upper end of {} ({})", v.key, v.hi));
        }
    }
    if binds.is_empty() {
        format!(
            "nothing binds: the optimum is inside the ranges and below the limit (breakdown ratio {:.3})",
            r.best.breakdown_ratio
        )
    } else {
        let verb = if binds.len() == 1 { "binds" } else { "bind" };
        format!("{} {verb}", binds.join(" and "))
    }
}

/// The design's values in words.
fn values(r: &Redesign) -> String {
    let v = &r.best.values;
    format!(
        "δ = {}, R_m = {:.2}, k = {:.0} N/m, R = {}",
        si(v[0], "m"),
        v[1],
        v[2],
        si(v[3], "Ω")
    )
}

fn with_se(e: &Evaluation) -> String {
    let p = e.objective.unwrap_or(f64::NAN);
    match e.standard_error {
        Some(s) if s > 0.0 => format!("{} ± {}", si(p, "W"), si(s, "W")),
        _ => si(p, "W"),
    }
}

/// One drive's result in words, every number and judgement from the run.
fn paragraph(drive: &str, r: &Redesign) -> String {
    let best = r.best.objective.unwrap_or(f64::NAN);
    let paper = r.paper.objective.unwrap_or(f64::NAN);
    let against = match &r.paper_best_load {
        Some((e, load)) => {
            let p = e.objective.unwrap_or(f64::NAN);
            format!(
                "{} at its best load within the limit, {} (breakdown ratio {:.3}): {:.2}× that{}, {:.3e}× its 100 kΩ",
                with_se(e),
                si(*load, "Ω"),
                e.breakdown_ratio,
                best / p,
                {
                    // Two noisy estimates differ significantly when their difference
                    // exceeds twice its standard error.
                    let se = |e: &Evaluation| e.standard_error.unwrap_or(0.0);
                    let noise = 2.0 * (se(&r.best).powi(2) + se(e).powi(2)).sqrt();
                    if (best - p).abs() <= noise {
                        format!(
                            " — a difference within the noise of the two estimates (twice its standard error, {})",
                            si(noise, "W")
                        )
                    } else if best < p {
                        format!(
                            " — less, so a search of {} designs stops short of the optimum, which is at least the paper's design at that load",
                            r.evaluations
                        )
                    } else {
                        String::new()
                    }
                },
                best / paper
            )
        }
        None => format!(
            "no load of 1–1000 GΩ keeps the paper's design within the limit; {:.3e}× its 100 kΩ",
            best / paper
        ),
    };
    let k = r.expected.standard_error.map(|s| s * (r.starts as f64).sqrt());
    let mean = r.expected.objective.unwrap_or(f64::NAN);
    let robust = match k {
        Some(spread) => {
            // Under a noisy input a run's own power is uncertain by its standard error: starts
            // that differ by no more than twice that differ by the input's noise alone.
            let noise = 2.0 * r.best.standard_error.unwrap_or(0.0);
            let tolerance = (0.02 * best).max(noise);
            let same = spread <= tolerance && (mean - best).abs() <= tolerance;
            format!(
                "{} random starts of the optimum expect {} (spread of the starts {}, {:.1} % of the optimum; largest breakdown ratio {:.3}): {}",
                r.starts,
                with_se(&r.expected),
                si(spread, "W"),
                100.0 * spread / best,
                r.expected.breakdown_ratio,
                if same && noise > 0.02 * best {
                    "the starts differ by no more than the noise of the input"
                } else if same {
                    "every start ends on a motion of that power"
                } else if mean < best {
                    "the starts end on motions of less power, so the optimum depends on the start"
                } else {
                    "the starts differ in power"
                }
            )
        }
        None => format!(
            "the random starts could not be evaluated ({})",
            r.expected.failure.clone().unwrap_or_default()
        ),
    };
    format!(
        "Under {drive}: {} (breakdown ratio {:.3}, {} designs) with {}, against the paper's design at 100 kΩ, {} (ratio {:.3}), and {against}; {}; {robust}.",
        with_se(&r.best),
        r.best.breakdown_ratio,
        r.evaluations,
        values(r),
        with_se(&r.paper),
        r.paper.breakdown_ratio,
        binding(r),
    )
}

/// The normalised frequency responses (P/P_peak against the drive frequency in Hz, up and
/// down sweeps) of the paper's design at its best admissible load (or its 100 kΩ) and of the
/// re-optimised design under the sine, drawn together; their half-power bands.
fn bandwidths(ctx: &mut Ctx, r: &Redesign, sizes: &Sizes) -> Result<(Option<Band>, Option<Band>)> {
    let base = at_fixed_frequency(&Config::default())?;
    let paper = match &r.paper_best_load {
        Some((_, load)) => base.with("harvester.load_resistance", (*load).into())?,
        None => base,
    };
    let values = grid(4.0, 8.0, sizes.response_steps);
    let mut curves = Vec::new();
    let mut bands = Vec::new();
    for config in [paper, r.design.clone()] {
        let runner = crate::job::RunArgs {
            transient: Some(60),
            recorded: Some(40),
            settle: SettleMode::Fixed,
            ..ctx.run_args(false)
        }
        .runner(config)?;
        let stop = |_| {
            if interrupted() {
                std::ops::ControlFlow::Break(())
            } else {
                std::ops::ControlFlow::Continue(())
            }
        };
        let response = frequency_response(
            &runner,
            "excitation.frequency_hz",
            &values,
            &ResponseOptions::default(),
            &stop,
        )?;
        if !response.complete {
            return Err(Interrupted {
                what: "in the frequency responses; REPORT.md is written only by a complete run".into(),
            }
            .into());
        }
        let band = response.bandwidth().ok();
        let peak = band.map_or(f64::NAN, |b| b.peak_power);
        for d in [Direction::Up, Direction::Down] {
            let (x, y): (Vec<f64>, Vec<f64>) = response
                .sweep(d)
                .power(&values)
                .into_iter()
                .map(|(o, p)| (o, p / peak))
                .unzip();
            curves.push((x, y));
        }
        bands.push(band.map(|b| Band {
            peak_at: b.peak_frequency,
            lower: b.lower,
            upper: b.upper,
        }));
    }
    let mut fig = Figure::new(
        "Normalised frequency response under the sine: the paper's design and the re-optimised one",
        "frequency of the base motion f (Hz)",
        "P / P_peak",
    );
    fig.legend = Legend::UpperLeft;
    let labels = [
        "paper's design, up sweep",
        "paper's design, down sweep",
        "re-optimised, up sweep",
        "re-optimised, down sweep",
    ];
    let series: Vec<(&str, &[f64], &[f64])> = labels
        .iter()
        .zip(&curves)
        .map(|(l, (x, y))| (*l, x.as_slice(), y.as_slice()))
        .collect();
    let img = lines(ctx, "extra_design_response", &fig, &series)?;
    ctx.figure(
        "extra",
        "Frequency response of the paper's design and the re-optimised one",
        format!(
            "Average power against the frequency of the paper's sine (A = 80 mm; the paper's Ω = 0.70 is {:.3} Hz), each design's up and down sweeps normalised by its peak; {} values, 60 transient and 40 recorded periods each. The paper's design at {}.",
            Config::default().chain().omega() / std::f64::consts::TAU,
            values.len(),
            match &r.paper_best_load {
                Some((_, load)) => format!("its best load within the breakdown limit, {}", si(*load, "Ω")),
                None => "its 100 kΩ".into(),
            }
        ),
        vec![img],
    );
    let mut bands = bands.into_iter();
    Ok((bands.next().flatten(), bands.next().flatten()))
}

/// A half-power band, Hz.
#[derive(Debug, Clone, Copy)]
struct Band {
    peak_at: f64,
    lower: Option<f64>,
    upper: Option<f64>,
}

impl Band {
    fn text(&self) -> String {
        let edge = |e: Option<f64>, side: &str| {
            e.map_or(format!("past the {side} end of the sweep"), |x| format!("{x:.3}"))
        };
        let width = match (self.lower, self.upper) {
            (Some(l), Some(u)) => format!(", {:.3} Hz wide", u - l),
            _ => String::new(),
        };
        format!(
            "peak at {:.3} Hz, half-power band {} to {} Hz{width}",
            self.peak_at,
            edge(self.lower, "lower"),
            edge(self.upper, "upper")
        )
    }

    fn width(&self) -> Option<f64> {
        Some(self.upper? - self.lower?)
    }
}

/// What the re-optimisation does to the bandwidth, from the two responses.
fn bandwidth_paragraph(r: &Redesign, paper: Option<Band>, best: Option<Band>) -> String {
    let design = match &r.paper_best_load {
        Some((_, load)) => format!("the paper's design at {}", si(*load, "Ω")),
        None => "the paper's design at 100 kΩ".into(),
    };
    let (Some(p), Some(b)) = (paper, best) else {
        return format!(
            "**Bandwidth.** No half-power band could be taken of {design} or of the re-optimised design (no power in the sweeps)."
        );
    };
    let judgement = match (p.width(), b.width()) {
        (Some(wp), Some(wb)) if wb < 0.9 * wp => format!(
            "the re-optimised design buys its power with a band {:.0} % narrower",
            100.0 * (1.0 - wb / wp)
        ),
        (Some(wp), Some(wb)) if wb > 1.1 * wp => format!(
            "the re-optimised design's band is also {:.0} % wider",
            100.0 * (wb / wp - 1.0)
        ),
        (Some(_), Some(_)) => "the two bands are about as wide (within 10 %)".into(),
        _ => "a band that runs past the sweep cannot be compared in width".into(),
    };
    format!(
        "**Bandwidth.** Under the sine (4 to 8 Hz, up and down sweeps together), {design}: {}; the re-optimised design: {}; {judgement}.",
        p.text(),
        b.text()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn redesign(unit: [f64; 4], ratio: f64) -> Redesign {
        let base = Config::default();
        let variables: Vec<Variable> = VARY.iter().map(|v| Variable::parse(&base, v).unwrap()).collect();
        let best = Evaluation {
            values: variables.iter().zip(unit).map(|(v, u)| v.value(u)).collect(),
            objective: Some(1.0),
            breakdown_ratio: ratio,
            ..Evaluation::default()
        };
        Redesign {
            paper: Evaluation::default(),
            paper_best_load: None,
            expected: best.clone(),
            best,
            variables,
            best_unit: unit.to_vec(),
            evaluations: 10,
            design: base,
            starts: 3,
        }
    }

    /// What binds is read off the optimum: the breakdown ratio at its limit, a key at an
    /// end of its range, or nothing.
    #[test]
    fn binding_follows_the_optimum() {
        let free = binding(&redesign([0.5, 0.5, 0.5, 0.5], 0.5));
        assert!(free.starts_with("nothing binds"), "{free}");
        let air = binding(&redesign([0.5, 0.5, 0.5, 0.5], 0.899));
        assert!(
            air.starts_with("air breakdown") && air.ends_with(" binds"),
            "{air}"
        );
        let both = binding(&redesign([0.0, 0.5, 0.5, 1.0], 0.899));
        assert!(
            both.contains("lower end of oscillator.gaps")
                && both.contains("upper end of harvester.load_resistance")
                && both.ends_with(" bind"),
            "{both}"
        );
    }
}
