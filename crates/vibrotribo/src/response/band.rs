//! The response to random input: average power against the centre frequency of the band of
//! a band-limited random base motion, the band moved across frequencies at a fixed width
//! and RMS acceleration, over several seeds.
//!
//! The configuration's base motion is band-limited noise with a flat one-sided spectrum
//! (`excitation.kind = "random"` with `rms_acceleration`, `f_low_hz`, `f_high_hz`: a seeded
//! random-phase multisine, [`Psd::Flat`]). At each centre f_c the band becomes
//! [f_c − B/2, f_c + B/2] at the same RMS acceleration (so the spectral level stays
//! rms²/B), and the run is repeated with the seeds s₀, s₀ + 1, …, s₀ + K − 1 (s₀ the
//! configured `excitation.seed`). The power at f_c is the mean over the seeds whose run
//! succeeded, with its standard error s/√n (s the sample standard deviation of the n
//! powers): a confidence interval for the power an unknown realisation of the noise
//! delivers. Each run is a sweep point of fixed length (transient, then recorded periods of
//! the reference period T = 2π/ω of `excitation.omega_ratio`); the runs are independent and
//! run in parallel.

use std::ops::ControlFlow;

use super::error::ResponseError;
use crate::analysis::{AnalysisError, Bandwidth, half_power_bandwidth};
use crate::config::Config;
use crate::excitation::{ExcitationSpec, Psd};
use crate::study::PointResult;
use crate::sweep::{Delivery, PointRunner, SweepError, run_grid, run_grid_on};

/// The key of a random base motion's lower band edge.
pub const F_LOW_KEY: &str = "excitation.f_low_hz";
/// The key of a random base motion's upper band edge.
pub const F_HIGH_KEY: &str = "excitation.f_high_hz";
/// The key of a random base motion's seed.
pub const SEED_KEY: &str = "excitation.seed";

/// The default number of seeds of a random-band response.
pub const DEFAULT_BAND_SEEDS: u64 = 8;

/// What a random-band response runs.
#[derive(Debug, Clone, PartialEq)]
pub struct BandOptions {
    /// Centre frequencies of the band, Hz (finite, strictly increasing).
    pub centres_hz: Vec<f64>,
    /// Width of the band, Hz (`None`: the configured `f_high_hz − f_low_hz`).
    pub width_hz: Option<f64>,
    /// Seeds per centre (≥ 2 for a standard error). Default [`DEFAULT_BAND_SEEDS`].
    pub seeds: u64,
}

/// A random-band response checked against its configuration: what every point sets.
#[derive(Debug, Clone, PartialEq)]
pub struct BandPlan {
    /// Centre frequencies, Hz.
    pub centres_hz: Vec<f64>,
    /// Width of the band, Hz.
    pub width_hz: f64,
    /// RMS base acceleration, m/s² (the configuration's).
    pub rms_acceleration: f64,
    /// The seeds run at every centre.
    pub seeds: Vec<u64>,
}

impl BandPlan {
    /// Checks `options` against `base` (a flat-spectrum random base motion; every band's
    /// lower edge positive; each point's configuration valid).
    pub fn new(base: &Config, options: &BandOptions) -> Result<Self, ResponseError> {
        let (rms, f_low, f_high, seed) = match base.excitation() {
            ExcitationSpec::Random { spec, .. } => match spec.psd {
                Psd::Flat {
                    rms,
                    f_low_hz,
                    f_high_hz,
                } => (rms, f_low_hz, f_high_hz, spec.seed),
                Psd::Table { .. } => {
                    return Err(ResponseError::NotFlatNoise {
                        found: "a PSD table (psd_frequencies_hz, psd_values)".into(),
                    });
                }
            },
            other => {
                return Err(ResponseError::NotFlatNoise {
                    found: format!("excitation.kind = \"{}\"", other.kind().as_str()),
                });
            }
        };
        let width_hz = options.width_hz.unwrap_or(f_high - f_low);
        if !(width_hz.is_finite() && width_hz > 0.0) {
            return Err(ResponseError::Option {
                name: "width_hz",
                value: width_hz,
                reason: "must be finite and > 0",
            });
        }
        if options.seeds == 0 {
            return Err(ResponseError::Option {
                name: "seeds",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        if options.centres_hz.is_empty() {
            return Err(ResponseError::NoValues);
        }
        let plan = BandPlan {
            centres_hz: options.centres_hz.clone(),
            width_hz,
            rms_acceleration: rms,
            seeds: (0..options.seeds).map(|k| seed.wrapping_add(k)).collect(),
        };
        for (index, &c) in plan.centres_hz.iter().enumerate() {
            if !c.is_finite() || (index > 0 && c <= plan.centres_hz[index - 1]) {
                return Err(ResponseError::BadValues { index, value: c });
            }
            if c - 0.5 * width_hz <= 0.0 {
                return Err(ResponseError::BandBelowZero {
                    centre_hz: c,
                    width_hz,
                });
            }
        }
        Ok(plan)
    }

    /// The band `[f_low, f_high]` centred on `centre_hz`, Hz.
    pub fn band(&self, centre_hz: f64) -> (f64, f64) {
        (centre_hz - 0.5 * self.width_hz, centre_hz + 0.5 * self.width_hz)
    }

    /// The points in the order they run and are delivered: (centre index, seed index), centre
    /// by centre.
    pub fn points(&self) -> Vec<(usize, usize)> {
        (0..self.centres_hz.len())
            .flat_map(|i| (0..self.seeds.len()).map(move |k| (i, k)))
            .collect()
    }

    /// The keys a point sets: both band edges and the seed.
    pub fn keys(&self, (i, k): (usize, usize)) -> Vec<(&'static str, f64)> {
        let (lo, hi) = self.band(self.centres_hz[i]);
        vec![
            (F_LOW_KEY, lo),
            (F_HIGH_KEY, hi),
            (SEED_KEY, self.seeds[k] as f64),
        ]
    }
}

/// The mean power at one centre frequency of a random-band response.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BandPoint {
    /// Centre of the band, Hz.
    pub centre_hz: f64,
    /// Lower edge, Hz.
    pub f_low_hz: f64,
    /// Upper edge, Hz.
    pub f_high_hz: f64,
    /// Mean average power over the seeds whose run succeeded, W (`None`: none did).
    pub power_w: Option<f64>,
    /// Its standard error over the seeds, W (`None` with fewer than two).
    pub power_se_w: Option<f64>,
    /// Seeds whose run succeeded and gave a power.
    pub runs: usize,
    /// Smallest power over those seeds, W.
    pub power_min_w: Option<f64>,
    /// Largest, W.
    pub power_max_w: Option<f64>,
}

/// A random-band response: the runs of every centre and seed.
#[derive(Debug, Clone, PartialEq)]
pub struct BandResponse {
    /// What was run.
    pub plan: BandPlan,
    /// The result of each point, in the order of [`BandPlan::points`]; shorter when stopped.
    pub results: Vec<Result<PointResult, SweepError>>,
    /// Whether every point ran.
    pub complete: bool,
}

impl BandResponse {
    /// The result of centre `i` and seed `k`, if it ran.
    pub fn result(&self, i: usize, k: usize) -> Option<&Result<PointResult, SweepError>> {
        self.results.get(i * self.plan.seeds.len() + k)
    }

    /// The mean power at each centre whose seeds all ran.
    pub fn points(&self) -> Vec<BandPoint> {
        let seeds = self.plan.seeds.len();
        (0..self.plan.centres_hz.len())
            .take_while(|i| (i + 1) * seeds <= self.results.len())
            .map(|i| {
                let powers: Vec<f64> = (0..seeds)
                    .filter_map(|k| self.result(i, k)?.as_ref().ok()?.average_power_w)
                    .filter(|p| p.is_finite())
                    .collect();
                let n = powers.len() as f64;
                let mean = (!powers.is_empty()).then(|| powers.iter().sum::<f64>() / n);
                let se = mean.filter(|_| powers.len() >= 2).map(|m| {
                    let var = powers.iter().map(|p| (p - m).powi(2)).sum::<f64>() / (n - 1.0);
                    (var / n).sqrt()
                });
                let centre = self.plan.centres_hz[i];
                let (lo, hi) = self.plan.band(centre);
                BandPoint {
                    centre_hz: centre,
                    f_low_hz: lo,
                    f_high_hz: hi,
                    power_w: mean,
                    power_se_w: se,
                    runs: powers.len(),
                    power_min_w: powers.iter().copied().reduce(f64::min),
                    power_max_w: powers.iter().copied().reduce(f64::max),
                }
            })
            .collect()
    }

    /// The peak and half-power band of the mean power against the centre frequency, Hz.
    pub fn bandwidth(&self) -> Result<Bandwidth, AnalysisError> {
        let samples: Vec<(f64, f64)> = self
            .points()
            .iter()
            .filter_map(|p| Some((p.centre_hz, p.power_w?)))
            .collect();
        half_power_bandwidth(&[&samples])
    }
}

/// Runs the random-band response `plan` of `runner`'s configuration: every point in parallel
/// (on `pool`, or the current rayon pool), delivered in order; `on` is called on the calling
/// thread after each point and may stop the response (the points delivered are kept,
/// [`BandResponse::complete`] false).
pub fn band_response(
    runner: &PointRunner,
    plan: &BandPlan,
    pool: Option<&rayon::ThreadPool>,
    mut on: impl FnMut() -> ControlFlow<()>,
) -> Result<BandResponse, ResponseError> {
    let points = plan.points();
    for &p in &points {
        runner.configure(&plan.keys(p))?;
    }
    let mut results = Vec::with_capacity(points.len());
    let mut deliver = |d: Delivery<'_, (usize, usize)>| match d {
        Delivery::Point(_, r) => {
            results.push(r);
            on()
        }
        Delivery::Chunk(_) => ControlFlow::Continue(()),
    };
    let keys = |&p: &(usize, usize)| plan.keys(p);
    let chunk = 4 * pool.map_or_else(rayon::current_num_threads, rayon::ThreadPool::current_num_threads);
    let done = match pool {
        Some(pool) => run_grid_on(pool, runner, &points, keys, chunk, &mut deliver),
        None => run_grid(runner, &points, keys, chunk, &mut deliver),
    };
    Ok(BandResponse {
        plan: plan.clone(),
        complete: done == points.len(),
        results,
    })
}
