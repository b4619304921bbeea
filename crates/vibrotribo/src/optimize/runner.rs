//! The search: a seeded particle swarm over the unit cube, then Nelder–Mead from its best
//! (both argmin's), with every evaluation through a cache and a callback, the best design
//! tracked independently of the order parallel evaluations finish in, and a history per
//! iteration.

use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

use argmin::core::observers::{Observe, ObserverMode};
use argmin::core::{CostFunction, Executor, KV, State};
use argmin::solver::neldermead::NelderMead;
use argmin::solver::particleswarm::ParticleSwarm;
use rand::SeedableRng;

use super::error::OptimizeError;
use super::evaluate::{Evaluation, evaluate};
use super::problem::{OptimizeOptions, Problem};

/// Evaluations already made, by their position in the unit cube (bit for bit): a resumed
/// search is served from here and retraces the interrupted one.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Cache {
    entries: HashMap<Vec<u64>, Evaluation>,
}

impl Cache {
    /// Records the evaluation of the design at `unit`.
    pub fn insert(&mut self, unit: &[f64], evaluation: Evaluation) {
        self.entries.insert(key(unit), evaluation);
    }

    /// The evaluation of the design at `unit`, if made.
    pub fn get(&self, unit: &[f64]) -> Option<&Evaluation> {
        self.entries.get(&key(unit))
    }

    /// Number of evaluations held.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether none is held.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

fn key(unit: &[f64]) -> Vec<u64> {
    unit.iter().map(|u| u.to_bits()).collect()
}

/// The search after one iteration.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct HistoryPoint {
    /// `swarm` or `local`.
    pub phase: &'static str,
    /// Iteration within the phase (0: the swarm's first generation, or the simplex).
    pub iteration: u64,
    /// Evaluations requested so far (cached ones included).
    pub evaluations: u64,
    /// The best feasible design's objective so far (`None` while none is feasible).
    pub best_objective: Option<f64>,
    /// The best design's values so far, in the order of the variables.
    pub best_values: Vec<f64>,
}

/// What a search found.
#[derive(Debug, Clone, PartialEq)]
pub struct OptimizeResult {
    /// The best design's position in the unit cube.
    pub best_unit: Vec<f64>,
    /// Its evaluation (values, objective, constraints).
    pub best: Evaluation,
    /// One point per iteration of each phase.
    pub history: Vec<HistoryPoint>,
    /// Evaluations requested (cached ones included).
    pub evaluations: u64,
}

/// Cost of an evaluation for a minimiser: `−score` when feasible, above every feasible
/// cost and growing with the violation when not, higher still when the run failed.
fn cost_of(e: &Evaluation) -> f64 {
    match e.score {
        Some(s) if e.violation == 0.0 => -s,
        Some(_) => 1e30 * (1.0 + e.violation),
        None => 1e31,
    }
}

/// The best so far: lowest cost, ties to the lexicographically smaller position (so that
/// the order in which parallel evaluations finish does not matter).
type Best = Option<(f64, Vec<f64>, Evaluation)>;

struct Shared<'a> {
    dim: usize,
    eval: &'a (dyn Fn(&[f64]) -> Evaluation + Sync),
    cache: Mutex<&'a mut Cache>,
    on_eval: &'a (dyn Fn(&[f64], &Evaluation, bool) + Sync),
    stop: &'a (dyn Fn() -> bool + Sync),
    count: Arc<AtomicU64>,
    best: Arc<Mutex<Best>>,
}

/// The cost function argmin sees.
struct Cost<'a, 'b>(&'b Shared<'a>);

impl CostFunction for Cost<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, p: &Vec<f64>) -> Result<f64, argmin::core::Error> {
        let s = self.0;
        if (s.stop)() {
            return Err(argmin::core::Error::msg("interrupted"));
        }
        if p.len() != s.dim || p.iter().any(|x| !x.is_finite()) {
            return Ok(1e32);
        }
        // Nelder–Mead may step outside the cube: the design at the nearest point of the cube,
        // penalised by the distance.
        let unit: Vec<f64> = p.iter().map(|x| x.clamp(0.0, 1.0)).collect();
        let outside = p
            .iter()
            .zip(&unit)
            .map(|(x, u)| (x - u).powi(2))
            .sum::<f64>()
            .sqrt();
        let cached = s
            .cache
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .get(&unit)
            .cloned();
        let (e, was_cached) = match cached {
            Some(e) => (e, true),
            None => {
                let e = (s.eval)(&unit);
                s.cache
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner)
                    .insert(&unit, e.clone());
                (e, false)
            }
        };
        (s.on_eval)(&unit, &e, was_cached);
        s.count.fetch_add(1, Ordering::SeqCst);
        let c = cost_of(&e);
        {
            let mut best = s.best.lock().unwrap_or_else(PoisonError::into_inner);
            let better = match &*best {
                None => true,
                Some((bc, bu, _)) => c < *bc || (c == *bc && unit.as_slice() < bu.as_slice()),
            };
            if better {
                *best = Some((c, unit.clone(), e));
            }
        }
        Ok(c + outside * c.abs().max(1e-300))
    }
}

/// Records one [`HistoryPoint`] per iteration.
struct Recorder {
    phase: &'static str,
    count: Arc<AtomicU64>,
    best: Arc<Mutex<Best>>,
    history: Arc<Mutex<Vec<HistoryPoint>>>,
}

impl<I: State> Observe<I> for Recorder {
    fn observe_iter(&mut self, state: &I, _kv: &KV) -> Result<(), argmin::core::Error> {
        let best = self.best.lock().unwrap_or_else(PoisonError::into_inner);
        let (objective, values) = match &*best {
            Some((_, _, e)) => (e.feasible().then_some(e.objective).flatten(), e.values.clone()),
            None => (None, Vec::new()),
        };
        self.history
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push(HistoryPoint {
                phase: self.phase,
                iteration: state.get_iter(),
                evaluations: self.count.load(Ordering::SeqCst),
                best_objective: objective,
                best_values: values,
            });
        Ok(())
    }
}

/// Maximises `problem`'s objective under its constraints ([`optimize_with`] on
/// [`evaluate`]); `cache` serves and keeps the evaluations, `on_eval` hears of each (its
/// position, evaluation, whether from the cache), and `stop` returning true ends the search
/// with [`OptimizeError::Stopped`].
pub fn optimize(
    problem: &Problem,
    cache: &mut Cache,
    on_eval: &(dyn Fn(&[f64], &Evaluation, bool) + Sync),
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<OptimizeResult, OptimizeError> {
    problem.validate()?;
    let eval = |u: &[f64]| evaluate(problem, u);
    let result = optimize_with(
        problem.variables.len(),
        &problem.options,
        &eval,
        cache,
        on_eval,
        stop,
    )?;
    if !result.best.feasible() {
        let b = &result.best;
        return Err(OptimizeError::Infeasible {
            constraints: problem
                .constraints
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", "),
            evaluations: result.evaluations,
            least: match &b.failure {
                Some(f) => format!("the run failed: {f}"),
                None => format!(
                    "breakdown_ratio = {:.4}, max_displacement = {:.6} m",
                    b.breakdown_ratio, b.max_displacement_m
                ),
            },
        });
    }
    Ok(result)
}

/// The search on any evaluation of the unit cube of dimension `dim`: a particle swarm of
/// `options.particles` for `options.swarm_iterations` generations, seeded with
/// `options.seed`, then Nelder–Mead for `options.local_iterations` from a simplex of side
/// 0.05 at the swarm's best.
pub fn optimize_with(
    dim: usize,
    options: &OptimizeOptions,
    eval: &(dyn Fn(&[f64]) -> Evaluation + Sync),
    cache: &mut Cache,
    on_eval: &(dyn Fn(&[f64], &Evaluation, bool) + Sync),
    stop: &(dyn Fn() -> bool + Sync),
) -> Result<OptimizeResult, OptimizeError> {
    options.validate()?;
    let shared = Shared {
        dim,
        eval,
        cache: Mutex::new(cache),
        on_eval,
        stop,
        count: Arc::new(AtomicU64::new(0)),
        best: Arc::new(Mutex::new(None)),
    };
    let history = Arc::new(Mutex::new(Vec::new()));
    let stopped = |e: argmin::core::Error| OptimizeError::Stopped {
        reason: e.to_string(),
    };
    let swarm = ParticleSwarm::new((vec![0.0; dim], vec![1.0; dim]), options.particles)
        .with_rng_generator(rand::rngs::StdRng::seed_from_u64(options.seed));
    Executor::new(Cost(&shared), swarm)
        .configure(|s| s.max_iters(options.swarm_iterations))
        .add_observer(
            Recorder {
                phase: "swarm",
                count: Arc::clone(&shared.count),
                best: Arc::clone(&shared.best),
                history: Arc::clone(&history),
            },
            ObserverMode::Always,
        )
        .run()
        .map_err(stopped)?;
    let start = shared
        .best
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .as_ref()
        .map(|b| b.1.clone())
        .unwrap_or_else(|| vec![0.5; dim]);
    if options.local_iterations > 0 {
        let mut simplex = vec![start.clone()];
        for k in 0..dim {
            let mut p = start.clone();
            // Step inwards, so that every vertex lies in the cube.
            p[k] = if p[k] + 0.05 <= 1.0 {
                p[k] + 0.05
            } else {
                p[k] - 0.05
            };
            simplex.push(p);
        }
        let local = NelderMead::new(simplex);
        Executor::new(Cost(&shared), local)
            .configure(|s| s.max_iters(options.local_iterations))
            .add_observer(
                Recorder {
                    phase: "local",
                    count: Arc::clone(&shared.count),
                    best: Arc::clone(&shared.best),
                    history: Arc::clone(&history),
                },
                ObserverMode::Always,
            )
            .run()
            .map_err(stopped)?;
    }
    let evaluations = shared.count.load(Ordering::SeqCst);
    let best = shared.best.lock().unwrap_or_else(PoisonError::into_inner).take();
    let history = std::mem::take(&mut *history.lock().unwrap_or_else(PoisonError::into_inner));
    match best {
        Some((_, best_unit, best)) => Ok(OptimizeResult {
            best_unit,
            best,
            history,
            evaluations,
        }),
        None => Err(OptimizeError::Stopped {
            reason: "no design was evaluated".into(),
        }),
    }
}
