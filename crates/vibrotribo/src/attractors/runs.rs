//! Starts run over a configuration's keys: fingerprints of sweep points ([`StartRunner`]),
//! and the attractors of random starts followed across a parameter ([`attractors_across`]).

use std::ops::ControlFlow;

use super::classify::{Classification, classify};
use super::fingerprint::{AttractorOptions, Fingerprint, SectionScale};
use super::starts::{StartBox, random_start};
use super::track::AttractorTracker;
use crate::config::ConfigError;
use crate::model::{ChainParams, ChainState};
use crate::study::{PointError, StudyError};
use crate::sweep::{Delivery, PointRunner, SweepError, run_chunks};

/// Runs starts: a sweep point of the base configuration with keys set (its transient, its
/// recorded periods, its harvester) condensed into the [`Fingerprint`] of where it ended.
#[derive(Debug, Clone)]
pub struct StartRunner {
    runner: PointRunner,
    options: AttractorOptions,
}

impl StartRunner {
    /// Starts run by `runner` and fingerprinted with `options` (validated).
    pub fn new(runner: PointRunner, options: AttractorOptions) -> Result<Self, crate::ParamError> {
        options.validate()?;
        Ok(StartRunner { runner, options })
    }

    /// The point runner.
    pub fn point_runner(&self) -> &PointRunner {
        &self.runner
    }

    /// The attractor options.
    pub fn options(&self) -> &AttractorOptions {
        &self.options
    }

    /// The section units of the configuration with `keys` set.
    pub fn scale(&self, keys: &[(&str, f64)]) -> Result<SectionScale, ConfigError> {
        Ok(SectionScale::of(self.runner.configure(keys)?.chain()))
    }

    /// The chain of the configuration with `keys` set.
    pub fn chain(&self, keys: &[(&str, f64)]) -> Result<ChainParams, ConfigError> {
        Ok(self.runner.configure(keys)?.chain().clone())
    }

    /// Runs the configuration with `keys` set from `initial` (or its configured initial
    /// state) and fingerprints where it ends.
    pub fn run(&self, keys: &[(&str, f64)], initial: Option<&ChainState>) -> Result<Fingerprint, SweepError> {
        let config = self.runner.configure(keys)?;
        let result = self.runner.run_config(&config, initial)?;
        Fingerprint::of(
            &result,
            &SectionScale::of(config.chain()),
            &self.runner.options().period_options(),
            &self.options,
        )
        .map_err(|e| SweepError::Point(PointError::Study(StudyError::Param(e))))
    }
}

/// The attractors of the random starts at one parameter value.
#[derive(Debug, Clone, PartialEq)]
pub struct ValueAttractors {
    /// The parameter value.
    pub value: f64,
    /// The starts grouped by attractor (labels in sample order).
    pub classification: Classification,
    /// The global identity of each attractor of `classification` ([`AttractorTracker`]).
    pub ids: Vec<usize>,
    /// The expected power (mean over the starts of their average power), W, and its
    /// standard error; `None` without a harvester.
    pub expected_power: Option<(f64, f64)>,
    /// Starts that failed, and the first failure.
    pub failed: usize,
    /// The first failure's message.
    pub first_error: Option<String>,
}

/// What [`attractors_across`] hands over, in order.
#[derive(Debug)]
pub enum AcrossDelivery<'a> {
    /// One start finished (a progress tick).
    Start,
    /// All the starts of a value finished, classified and tracked.
    Value(&'a ValueAttractors),
    /// The end of a chunk of starts: a checkpoint where the run may stop.
    Chunk,
}

/// Classifies the starts of one value, continues the attractors of the previous value from
/// their states (a seed that ends on an attractor no start found adds it, with no starts),
/// and tracks their identities.
fn finish_value(
    starts: &StartRunner,
    key: &str,
    value: f64,
    results: Vec<Result<Fingerprint, SweepError>>,
    previous: Option<&ValueAttractors>,
    scale: &SectionScale,
    tracker: &mut AttractorTracker,
) -> ValueAttractors {
    let options = starts.options();
    let first_error = results
        .iter()
        .find_map(|r| r.as_ref().err().map(ToString::to_string));
    let fingerprints: Vec<Option<Fingerprint>> = results.into_iter().map(Result::ok).collect();
    let mut classification = classify(&fingerprints, scale, options);
    let mut continued = Vec::new();
    for (a, &id) in previous
        .map_or(&[][..], |p| &p.classification.attractors[..])
        .iter()
        .zip(previous.map_or(&[][..], |p| &p.ids[..]))
    {
        let Ok(f) = starts.run(&[(key, value)], Some(&a.state())) else {
            continue;
        };
        let target = match classification.find(&f, scale, options) {
            Some(t) => t,
            None => classification.add_unvisited(&f),
        };
        continued.push((id, target));
    }
    let ids = tracker.track(&classification.attractors, &continued, scale, options);
    ValueAttractors {
        value,
        failed: fingerprints.iter().filter(|f| f.is_none()).count(),
        first_error,
        expected_power: classification.expected_power(&fingerprints),
        classification,
        ids,
    }
}

/// How the starts of [`attractors_across`] are drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RandomStarts {
    /// Random starts per value, K.
    pub samples: usize,
    /// Seed of the starts: start s is [`random_start`]`(chain, bounds, seed, s)` at every
    /// value (common random numbers: the same starts wherever they fit the chain).
    pub seed: u64,
    /// The box the starts are drawn from (`None`: [`StartBox::of`] the chain at each value).
    pub bounds: Option<StartBox>,
}

/// At each value of `key` in `values`, runs `sampling.samples` random starts (in parallel
/// chunks of `chunk` starts, the results independent of the thread count), groups them by
/// attractor ([`classify`], in sample order), runs every attractor of the previous value
/// from one of its states at this value (seeded continuation: an attractor that no start
/// found but a seed reaches is kept, with no starts) and gives the attractors global
/// identities from value to value ([`AttractorTracker`]). `on` sees every start, every finished value
/// and every chunk's end, and may stop the run there. Returns the values finished.
///
/// Errors if a value makes a bad configuration or no start fits its chain.
pub fn attractors_across<F>(
    starts: &StartRunner,
    key: &str,
    values: &[f64],
    sampling: &RandomStarts,
    chunk: usize,
    mut on: F,
) -> Result<Vec<ValueAttractors>, SweepError>
where
    F: FnMut(AcrossDelivery<'_>) -> ControlFlow<()>,
{
    let k = sampling.samples;
    let mut chains = Vec::with_capacity(values.len());
    for &v in values {
        chains.push(starts.chain(&[(key, v)])?);
    }
    let mut initial: Vec<ChainState> = Vec::with_capacity(values.len() * k);
    for chain in &chains {
        let bounds = sampling.bounds.unwrap_or_else(|| StartBox::of(chain));
        for s in 0..k {
            initial.push(
                random_start(chain, &bounds, sampling.seed, s as u64)
                    .map_err(|e| SweepError::Point(PointError::Study(StudyError::Param(e))))?,
            );
        }
    }
    let points: Vec<(usize, usize)> = (0..values.len())
        .flat_map(|j| (0..k).map(move |s| (j, s)))
        .collect();
    let mut tracker = AttractorTracker::new();
    let mut done: Vec<ValueAttractors> = Vec::new();
    let mut current: Vec<Result<Fingerprint, SweepError>> = Vec::with_capacity(k);
    run_chunks(
        &points,
        chunk,
        |&(j, s)| starts.run(&[(key, values[j])], Some(&initial[j * k + s])),
        |d| match d {
            Delivery::Point(&(j, _), r) => {
                current.push(r);
                if on(AcrossDelivery::Start).is_break() {
                    return ControlFlow::Break(());
                }
                if current.len() < k {
                    return ControlFlow::Continue(());
                }
                let results = std::mem::take(&mut current);
                let scale = SectionScale::of(&chains[j]);
                let value = finish_value(starts, key, values[j], results, done.last(), &scale, &mut tracker);
                done.push(value);
                on(AcrossDelivery::Value(done.last().expect("just pushed")))
            }
            Delivery::Chunk(_) => on(AcrossDelivery::Chunk),
        },
    );
    Ok(done)
}
