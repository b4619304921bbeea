//! `vibrotribo optimize`: design optimisation over configuration keys
//! ([`vibrotribo::optimize`]): the files (`optimize.json`, `best.toml`,
//! `evaluations.jsonl`, `convergence.png/.svg`), the progress bar, `--resume`.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use vibrotribo::optimize::{
    Cache, Constraint, Evaluation, HistoryPoint, Objective, OptimizeError, OptimizeOptions, Problem, Scale,
    Variable, optimize,
};

use crate::config::ConfigArgs;
use crate::manifest::Kind;
use crate::output::{create_dir, si, write_atomic, write_json};
use crate::plot::{self, Figure, Legend, Series, both};
use crate::progress::{Interrupted, Progress, interrupted};

/// Options of `vibrotribo optimize`.
#[derive(Debug, clap::Args)]
pub struct OptimizeArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// A key to vary and its range, e.g. `harvester.load_resistance=1e9..1e12`,
    /// `mass_ratio=1.5..4` (repeatable; a range spanning a factor of 100 or more, both
    /// bounds positive, is searched on a log scale).
    #[arg(long = "vary", value_name = "KEY=LO..HI", required = true)]
    pub vary: Vec<String>,
    /// What to maximise: `average_power` (W), `expected_power` (W, mean over --starts seeded
    /// random starts, with its standard error), `power_per_mass` (W/kg of the chain).
    #[arg(
        long,
        default_value = "average_power",
        value_name = "average_power|expected_power|power_per_mass"
    )]
    pub objective: String,
    /// An upper bound on a quantity after the transient: `breakdown_ratio<=0.9` (largest
    /// |V_gap|/V_breakdown, Paschen's law) or `max_displacement<=0.05` (largest |x_i|, m)
    /// (repeatable).
    #[arg(long = "constraint", value_name = "QUANTITY<=BOUND")]
    pub constraint: Vec<String>,
    /// Random starts per design for `expected_power`.
    #[arg(long, default_value_t = 4, value_name = "K")]
    pub starts: u64,
    /// Seed of the swarm and of the random starts.
    #[arg(long, default_value_t = 0, value_name = "S")]
    pub seed: u64,
    /// Particles of the swarm (global search).
    #[arg(long, default_value_t = 8)]
    pub particles: usize,
    /// Generations of the swarm after the first.
    #[arg(long, default_value_t = 6)]
    pub swarm_iterations: u64,
    /// Iterations of Nelder–Mead (local search from the swarm's best).
    #[arg(long, default_value_t = 30)]
    pub local_iterations: u64,
    /// Write optimize.json, best.toml, evaluations.jsonl and the convergence plot here.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Continue an interrupted search in --out: its evaluations are reused, and the search
    /// (deterministic for a seed) ends where the uninterrupted one would.
    #[arg(long)]
    pub resume: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

/// What a search is, recorded so that `--resume` continues the same one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Setup {
    vary: Vec<String>,
    objective: String,
    constraints: Vec<String>,
    options: serde_json::Value,
    settings: serde_json::Value,
}

/// One line of `evaluations.jsonl`.
#[derive(Debug, Serialize, Deserialize)]
struct Line {
    unit: Vec<f64>,
    evaluation: Evaluation,
}

/// One varied key in `optimize.json`.
#[derive(Debug, Serialize)]
struct VariableEntry {
    key: String,
    lo: f64,
    hi: f64,
    scale: Scale,
}

/// `optimize.json`.
#[derive(Debug, Serialize)]
struct Manifest {
    /// Always [`Kind::Optimize`].
    command: Kind,
    /// The varied keys and their best values.
    best: serde_json::Map<String, serde_json::Value>,
    /// The best design's objective.
    objective: Option<f64>,
    objective_name: Objective,
    objective_standard_error: Option<f64>,
    /// What ranked the designs (the objective, or its lower 95 % bound under noisy input).
    score: Option<f64>,
    breakdown_ratio: f64,
    max_displacement_m: f64,
    constraints: Vec<Constraint>,
    variables: Vec<VariableEntry>,
    options: OptimizeOptions,
    evaluations: u64,
    history: Vec<HistoryPoint>,
}

/// Runs `vibrotribo optimize`.
pub fn run(args: &OptimizeArgs) -> Result<()> {
    let config = args.input.load()?;
    let variables = args
        .vary
        .iter()
        .map(|v| Variable::parse(&config, v))
        .collect::<Result<Vec<_>, OptimizeError>>()?;
    let objective: Objective = args.objective.parse()?;
    let constraints = args
        .constraint
        .iter()
        .map(|c| Constraint::parse(c))
        .collect::<Result<Vec<_>, OptimizeError>>()?;
    let options = OptimizeOptions {
        starts: args.starts,
        seed: args.seed,
        particles: args.particles,
        swarm_iterations: args.swarm_iterations,
        local_iterations: args.local_iterations,
    };
    let problem = Problem {
        base: config.clone(),
        variables,
        objective,
        constraints,
        options,
    };
    problem.validate()?;
    let dir = &args.out;
    create_dir(dir)?;
    let setup = Setup {
        vary: args.vary.clone(),
        objective: args.objective.clone(),
        constraints: args.constraint.clone(),
        options: serde_json::to_value(options)?,
        settings: serde_json::to_value(config.table())?,
    };
    let mut cache = Cache::default();
    let evaluations = dir.join("evaluations.jsonl");
    let setup_path = dir.join("optimize_setup.json");
    if args.resume {
        let recorded: Setup = serde_json::from_str(
            &std::fs::read_to_string(&setup_path)
                .with_context(|| format!("--resume: cannot read {}", setup_path.display()))?,
        )
        .with_context(|| format!("--resume: {}", setup_path.display()))?;
        if recorded != setup {
            bail!(
                "--resume: {} holds a different search (other --vary, --objective, --constraint, options or configuration)",
                dir.display()
            );
        }
        read_cache(&evaluations, &mut cache)?;
    } else {
        if evaluations.exists() {
            bail!(
                "{} already holds a search: --resume to continue it, or another --out",
                dir.display()
            );
        }
        write_atomic(&setup_path, serde_json::to_string_pretty(&setup)?.as_bytes())?;
    }
    let file = Mutex::new(
        std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&evaluations)
            .with_context(|| format!("cannot open {}", evaluations.display()))?,
    );
    let writes: Mutex<Option<std::io::Error>> = Mutex::new(None);
    let total = (options.particles as u64) * (options.swarm_iterations + 1) + 2 * options.local_iterations;
    let progress = Progress::new(total, "designs", args.quiet);
    let on_eval = |unit: &[f64], e: &Evaluation, cached: bool| {
        progress.inc(1);
        if cached {
            return;
        }
        let line = serde_json::to_string(&Line {
            unit: unit.to_vec(),
            evaluation: e.clone(),
        });
        let mut f = file.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let r = line
            .map_err(std::io::Error::other)
            .and_then(|l| writeln!(f, "{l}").and_then(|()| f.flush()));
        if let Err(e) = r {
            writes
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .get_or_insert(e);
        }
    };
    let stop = || interrupted();
    let result = optimize(&problem, &mut cache, &on_eval, &stop);
    progress.finish();
    if let Some(e) = writes
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
    {
        return Err(anyhow::Error::from(e).context(format!("cannot write {}", evaluations.display())));
    }
    let result = match result {
        Err(OptimizeError::Stopped { .. }) if interrupted() => {
            return Err(Interrupted {
                what: format!(
                    "{} designs evaluated are in {}; --resume continues",
                    cache.len(),
                    evaluations.display()
                ),
            }
            .into());
        }
        other => other?,
    };
    let best = &result.best;
    let mut best_map = serde_json::Map::new();
    for (v, value) in problem.variables.iter().zip(&best.values) {
        best_map.insert(v.key.clone(), serde_json::json!(value));
    }
    let manifest = Manifest {
        command: Kind::Optimize,
        best: best_map,
        objective: best.objective,
        objective_name: objective,
        objective_standard_error: best.standard_error,
        score: best.score,
        breakdown_ratio: best.breakdown_ratio,
        max_displacement_m: best.max_displacement_m,
        constraints: problem.constraints.clone(),
        variables: problem
            .variables
            .iter()
            .map(|v| VariableEntry {
                key: v.key.clone(),
                lo: v.lo,
                hi: v.hi,
                scale: v.scale,
            })
            .collect(),
        options,
        evaluations: result.evaluations,
        history: result.history.clone(),
    };
    write_json(&dir.join("optimize.json"), &serde_json::to_value(&manifest)?)?;
    let design = problem.design(&result.best_unit)?;
    let mut table = design.table().clone();
    anchor_record(&mut table, args.input.config.as_deref())?;
    let toml = toml::to_string(&table).context("cannot write the best design as TOML")?;
    write_atomic(&dir.join("best.toml"), toml.as_bytes())?;
    plot_convergence(dir)?;
    print_result(&problem, &manifest, dir);
    Ok(())
}

/// Makes a record file named relative to the configuration file (`excitation.file`) absolute,
/// so that best.toml runs from wherever it is.
fn anchor_record(table: &mut toml::Table, config: Option<&Path>) -> Result<()> {
    let (Some(config), Some(excitation)) =
        (config, table.get_mut("excitation").and_then(|v| v.as_table_mut()))
    else {
        return Ok(());
    };
    if let Some(toml::Value::String(file)) = excitation.get_mut("file") {
        let path = Path::new(file.as_str());
        if path.is_relative() {
            let dir = config.parent().unwrap_or(Path::new("."));
            let absolute = std::path::absolute(dir.join(path))
                .with_context(|| format!("cannot resolve the record file {}", path.display()))?;
            *file = absolute.display().to_string();
        }
    }
    Ok(())
}

/// Reads the evaluations of an interrupted search (a last line cut off by the interruption is
/// ignored).
fn read_cache(path: &Path, cache: &mut Cache) -> Result<()> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(anyhow::Error::from(e).context(format!("cannot read {}", path.display()))),
    };
    for line in text.lines() {
        if let Ok(l) = serde_json::from_str::<Line>(line) {
            cache.insert(&l.unit, l.evaluation);
        }
    }
    Ok(())
}

/// What the convergence picture reads of `optimize.json` (the keys of [`Manifest`] it needs).
#[derive(Debug, Deserialize)]
struct ConvergenceView {
    /// The objective's name.
    objective_name: String,
    /// The search after each iteration.
    history: Vec<HistoryView>,
}

/// Of a [`HistoryPoint`]: the evaluations made and the best feasible objective then.
#[derive(Debug, Deserialize)]
struct HistoryView {
    evaluations: u64,
    best_objective: Option<f64>,
}

/// `convergence.png/.svg`: the best feasible objective against the evaluations made, from the
/// `optimize.json` of `dir`.
pub fn plot_convergence(dir: &Path) -> Result<()> {
    let m: ConvergenceView = crate::manifest::read(&dir.join("optimize.json"))?;
    let objective: Objective = m.objective_name.parse()?;
    let (x, y): (Vec<f64>, Vec<f64>) = m
        .history
        .iter()
        .filter_map(|h| Some((h.evaluations as f64, h.best_objective?)))
        .unzip();
    if x.is_empty() {
        return Ok(());
    }
    let unit = if objective == Objective::PowerPerMass {
        "W/kg"
    } else {
        "W"
    };
    let mut fig = Figure::new(
        "Convergence: the best design's objective (swarm, then Nelder–Mead)",
        "designs evaluated",
        format!("{objective} [{unit}]"),
    );
    fig.legend = Legend::Hidden;
    both(dir, "convergence", |path| {
        plot::lines_and_points(
            path,
            &fig,
            &[Series::unlabelled(&x, &y)],
            &[Series::unlabelled(&x, &y)],
            7,
        )
    })
}

fn print_result(problem: &Problem, m: &Manifest, dir: &Path) {
    let unit = if problem.objective == Objective::PowerPerMass {
        "W/kg"
    } else {
        "W"
    };
    println!(
        "vibrotribo optimize: {} = {}{} after {} designs",
        problem.objective,
        m.objective.map_or("n/a".into(), |o| si(o, unit)),
        m.objective_standard_error
            .map_or(String::new(), |s| format!(" ± {}", si(s, unit))),
        m.evaluations
    );
    for v in &problem.variables {
        if let Some(value) = m.best.get(&v.key) {
            println!("  {} = {value}", v.key);
        }
    }
    println!(
        "  breakdown ratio {:.4}, largest displacement {}",
        m.breakdown_ratio,
        si(m.max_displacement_m, "m")
    );
    println!(
        "  wrote {0}/optimize.json, {0}/best.toml, {0}/evaluations.jsonl, {0}/convergence.png",
        dir.display()
    );
}
