//! The point runner and the grid and continued runners of sweeps and maps.

use std::ops::ControlFlow;

use rayon::prelude::*;

use crate::config::{Config, ConfigError, Param};
use crate::model::ChainState;
use crate::study::{PointError, PointOptions, PointResult, run_point_driven};

/// How the points of a one-parameter sweep start.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "lowercase"))]
pub enum Continuation {
    /// Every value starts from the configured initial state; values run in parallel.
    #[default]
    None,
    /// Values in increasing order, each starting from the previous one's final state.
    Up,
    /// Values in decreasing order, each starting from the previous one's final state.
    Down,
}

impl std::str::FromStr for Continuation {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "none" => Ok(Continuation::None),
            "up" => Ok(Continuation::Up),
            "down" => Ok(Continuation::Down),
            other => Err(format!(
                "unknown continuation {other:?}: expected none, up or down"
            )),
        }
    }
}

impl Continuation {
    /// The name used on the command line and in files: `none`, `up`, `down`.
    pub fn as_str(self) -> &'static str {
        match self {
            Continuation::None => "none",
            Continuation::Up => "up",
            Continuation::Down => "down",
        }
    }
}

/// `steps` values equally spaced from `from` to `to` (both included; `to` exactly).
pub fn grid(from: f64, to: f64, steps: usize) -> Vec<f64> {
    match steps {
        0 => Vec::new(),
        1 => vec![from],
        _ => (0..steps)
            .map(|j| {
                if j == steps - 1 {
                    to
                } else {
                    from + (to - from) * j as f64 / (steps - 1) as f64
                }
            })
            .collect(),
    }
}

/// A sweep point could not be set up or failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SweepError {
    /// Setting the point's keys gave a bad configuration.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The point's run failed.
    #[error(transparent)]
    Point(#[from] PointError),
}

/// Runs the points of a sweep or a map: the base configuration with keys set, condensed by
/// [`run_point`](crate::study::run_point).
#[derive(Debug, Clone)]
pub struct PointRunner {
    base: Config,
    options: PointOptions,
    mechanics_only: bool,
}

impl PointRunner {
    /// Points of `base` with `options` (transient, recorded periods, …); with the harvester
    /// unless `mechanics_only`.
    pub fn new(base: Config, options: PointOptions, mechanics_only: bool) -> Self {
        PointRunner {
            base,
            options,
            mechanics_only,
        }
    }

    /// This runner with its points stopped by `cancel` ([`PointOptions::cancel`]): a point
    /// it stops ends in [`PointError::Stopped`] (see [`is_stopped`]).
    pub fn with_cancel(mut self, cancel: crate::orbits::Cancel) -> Self {
        self.options.cancel = cancel;
        self
    }

    /// The point options in use.
    pub fn options(&self) -> &PointOptions {
        &self.options
    }

    /// The base configuration.
    pub fn base(&self) -> &Config {
        &self.base
    }

    /// Whether the harvester is left out.
    pub fn mechanics_only(&self) -> bool {
        self.mechanics_only
    }

    /// Number of masses of the chain (the same at every point: keys set numbers, not arrays).
    pub fn masses(&self) -> usize {
        self.base.chain().len()
    }

    /// Number of contacts of the base configuration's chain (N − 1, or N + 1 with stops:
    /// [`ChainParams::contact_count`](crate::ChainParams::contact_count)).
    pub fn contacts(&self) -> usize {
        self.base.chain().contact_count()
    }

    /// The parameter `key` of the base configuration ([`Param::new`]).
    pub fn param(&self, key: &str) -> Result<Param, ConfigError> {
        Param::new(&self.base, key)
    }

    /// The base configuration with each `(key, value)` of `keys` set (validated).
    pub fn configure(&self, keys: &[(&str, f64)]) -> Result<Config, ConfigError> {
        let params = keys
            .iter()
            .map(|&(k, v)| Ok((self.param(k)?, v)))
            .collect::<Result<Vec<_>, ConfigError>>()?;
        let values: Vec<(&Param, f64)> = params.iter().map(|(p, v)| (p, *v)).collect();
        self.base.with_values(&values)
    }

    /// Runs the configuration with `keys` set, from `initial` (if it fits the chain) or the
    /// configured initial state.
    pub fn run(&self, keys: &[(&str, f64)], initial: Option<&ChainState>) -> Result<PointResult, SweepError> {
        self.run_config(&self.configure(keys)?, initial)
    }

    /// Runs the configuration with the parameters of `values` set (see [`run`](Self::run)).
    pub fn run_values(
        &self,
        values: &[(&Param, f64)],
        initial: Option<&ChainState>,
    ) -> Result<PointResult, SweepError> {
        self.run_config(&self.base.with_values(values)?, initial)
    }

    /// Runs `config` (one of [`configure`](Self::configure)'s) with this runner's point
    /// options, from `initial` (if it fits the chain) or the configured initial state.
    pub fn run_config(
        &self,
        config: &Config,
        initial: Option<&ChainState>,
    ) -> Result<PointResult, SweepError> {
        let params = config.chain();
        let initial = match initial {
            Some(s) if s.positions.len() == params.len() && params.validate_state(s).is_ok() => s,
            _ => config.initial_state(),
        };
        let harvester = (!self.mechanics_only).then(|| (config.harvester(), config.charge_options()));
        let spec = config.run_spec(true);
        Ok(run_point_driven(
            params,
            initial,
            config.sim_options(),
            harvester,
            &self.options,
            spec.base_motion.as_ref(),
        )?)
    }
}

/// Whether a point's result is a stop ([`PointError::Stopped`]) rather than a result: it
/// holds nothing of the point, and a job that writes its points in order stops writing there.
pub fn is_stopped(result: &Result<PointResult, SweepError>) -> bool {
    matches!(result, Err(SweepError::Point(PointError::Stopped { .. })))
}

/// What [`run_grid`] (and [`run_chunks`]) hands over, in grid order (handed over once, by
/// value: its size does not matter).
#[derive(Debug)]
#[allow(clippy::large_enum_variant)]
pub enum Delivery<'a, P, R = Result<PointResult, SweepError>> {
    /// A point and its result.
    Point(&'a P, R),
    /// The end of a chunk, with the number of points delivered so far: a checkpoint.
    Chunk(usize),
}

/// Runs `points` (each set up by `keys`) in parallel chunks of `chunk` points on the current
/// rayon pool and hands each point's result to `on` in grid order, then the end of the chunk
/// ([`Delivery::Chunk`]); `on` may stop the run (a progress bar, an interrupt, a file
/// checkpoint, a failed write). Returns how many points were delivered.
pub fn run_grid<'k, P, F>(
    runner: &PointRunner,
    points: &[P],
    keys: impl Fn(&P) -> Vec<(&'k str, f64)> + Sync,
    chunk: usize,
    on: F,
) -> usize
where
    P: Sync,
    F: FnMut(Delivery<'_, P>) -> ControlFlow<()>,
{
    run_chunks(points, chunk, |p| runner.run(&keys(p), None), on)
}

/// [`run_grid`] on the threads of `pool`, while `on` runs on the calling thread (which can
/// then be the one that must see an interrupt, such as Python's main thread).
pub fn run_grid_on<'k, P, F>(
    pool: &rayon::ThreadPool,
    runner: &PointRunner,
    points: &[P],
    keys: impl Fn(&P) -> Vec<(&'k str, f64)> + Sync,
    chunk: usize,
    on: F,
) -> usize
where
    P: Sync,
    F: FnMut(Delivery<'_, P>) -> ControlFlow<()>,
{
    in_chunks(
        points,
        chunk,
        |block| pool.install(|| block.par_iter().map(|p| runner.run(&keys(p), None)).collect()),
        on,
    )
}

/// Runs `work` on `points` in parallel chunks of `chunk` points on the current rayon pool and
/// hands each result to `on` in order, then the end of the chunk; `on` may stop the run.
/// Returns how many points were delivered. What is delivered does not depend on the thread
/// count. [`run_grid`] is this with a sweep point as the work.
pub fn run_chunks<P, R, W, F>(points: &[P], chunk: usize, work: W, on: F) -> usize
where
    P: Sync,
    R: Send,
    W: Fn(&P) -> R + Sync,
    F: FnMut(Delivery<'_, P, R>) -> ControlFlow<()>,
{
    in_chunks(points, chunk, |block| block.par_iter().map(&work).collect(), on)
}

/// `points` in chunks of `chunk`, each computed by `compute` and delivered to `on` in order.
fn in_chunks<P, R, F>(points: &[P], chunk: usize, compute: impl Fn(&[P]) -> Vec<R>, mut on: F) -> usize
where
    F: FnMut(Delivery<'_, P, R>) -> ControlFlow<()>,
{
    let mut done = 0;
    for block in points.chunks(chunk.max(1)) {
        for (p, r) in block.iter().zip(compute(block)) {
            done += 1;
            if on(Delivery::Point(p, r)).is_break() {
                return done;
            }
        }
        if on(Delivery::Chunk(done)).is_break() {
            break;
        }
    }
    done
}

/// Runs the values `order` (indices into `values`) of `key` one after the other, each from the
/// previous one's final state (`state` to start with; a failed point passes the state it
/// got on), calling `deliver` with each result and its final state, and stopping when it
/// says so. Returns how many were delivered and the last final state.
pub fn run_continued<D>(
    runner: &PointRunner,
    key: &str,
    values: &[f64],
    order: &[usize],
    mut state: Option<ChainState>,
    mut deliver: D,
) -> Result<(usize, Option<ChainState>), SweepError>
where
    D: FnMut(
        usize,
        Result<PointResult, SweepError>,
        Option<&ChainState>,
    ) -> Result<ControlFlow<()>, SweepError>,
{
    let param = runner.param(key)?;
    let mut done = 0;
    for &j in order {
        let r = runner.run_values(&[(&param, values[j])], state.as_ref());
        if let Ok(p) = &r {
            state = Some(p.final_state.clone());
        }
        done += 1;
        if deliver(j, r, state.as_ref())?.is_break() {
            break;
        }
    }
    Ok((done, state))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::run_point;

    #[test]
    fn grids_end_exactly() {
        assert_eq!(grid(0.5, 0.9, 1), vec![0.5]);
        let g = grid(0.55, 0.95, 24);
        assert_eq!(g.len(), 24);
        assert_eq!(g[23], 0.95);
        assert!(grid(1.0, 2.0, 0).is_empty());
    }

    /// A point run through the runner is the same as a simulation of the configuration with
    /// the key set, and runs from rest unless given a state.
    #[test]
    fn points_follow_their_configuration() {
        let options = PointOptions {
            transient_periods: 20,
            recorded_periods: 10,
            ..PointOptions::default()
        };
        let runner = PointRunner::new(Config::default(), options.clone(), true);
        let p = runner.run(&[("omega_ratio", 0.75)], None).unwrap();
        let c = Config::default()
            .with("excitation.omega_ratio", 0.75.into())
            .unwrap();
        let q = run_point(c.chain(), c.initial_state(), c.sim_options(), None, &options).unwrap();
        assert_eq!(p, q);
        let e = runner.run(&[("omega_ratio", -1.0)], None).unwrap_err();
        assert!(e.to_string().contains("excitation.omega_ratio"), "{e}");
    }
}
