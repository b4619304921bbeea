//! [`LyapunovObserver`]: tangent vectors carried along a run by the exact state-transition
//! matrix, re-orthonormalised by QR (see the [module docs](super)).

use nalgebra::DMatrix;

use super::error::LyapunovError;
use super::options::LyapunovOptions;
use super::spectrum::{LyapunovSpectrum, PeriodLogs};
use crate::dynamics::{Event, Flow, Observer, StateView};
use crate::error::ParamError;
use crate::model::ChainParams;
use crate::random::SplitMix64;
use crate::sensitivity::{NonSmoothPoint, Sensitivity};

/// Non-differentiable points kept for the report (all are counted).
const KEPT_POINTS: usize = 16;

/// A [`dynamics` observer](crate::Observer) that carries 2N tangent vectors along a run with
/// the exact state-transition matrix of [`Sensitivity`], re-orthonormalises them by QR at
/// every period's end (and earlier when they grow too much), and from the end of the
/// transient on accumulates the logarithms of the QR factor's diagonal: the Lyapunov
/// spectrum ([`finish`](Self::finish)). Attach it to a run from t = 0 (through
/// [`Mechanics`](crate::study::Mechanics) in [`simulate`](crate::study::simulate), or to a
/// [`Simulator`](crate::Simulator) directly);
/// [`study::lyapunov_spectrum`](crate::study::lyapunov_spectrum) does that.
///
/// ```
/// use vibrotribo::lyapunov::{LyapunovObserver, LyapunovOptions};
/// use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator};
///
/// let params = ChainParams::default();
/// let mut lyap = LyapunovObserver::new(&params, 20, &LyapunovOptions::default())?;
/// let mut sim = Simulator::new(&params, &ChainState::at_rest(3), SimOptions::default())?;
/// sim.run_until(60.0 * params.period(), &mut lyap)?;
/// let spectrum = lyap.finish()?;
/// assert_eq!(spectrum.exponents.len(), 6);
/// assert!(spectrum.largest() < 0.0); // the default case settles on a stable orbit
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct LyapunovObserver {
    sens: Sensitivity,
    /// The tangent basis (orthonormal columns), 2N × 2N.
    q: DMatrix<f64>,
    /// Scratch: Φ·Q.
    m: DMatrix<f64>,
    masses: usize,
    period: f64,
    transient: u64,
    max_growth: f64,
    /// Longest block, s: `ln(max_growth) / max_i(c_i/m_i)`, over which no direction can
    /// contract by more than `max_growth` (∞ without damping).
    horizon: f64,
    options: LyapunovOptions,
    /// Whether the first piece of flow has been seen.
    started: bool,
    /// Period boundaries t = kT passed, and the next one, s.
    boundaries: u64,
    next_boundary: f64,
    /// A boundary passed since the last fold at a boundary (the fold may wait for a chatter
    /// jump to end).
    due: bool,
    /// Start of the current block (the interval since the last fold), s, and the boundaries
    /// passed then.
    block_start: f64,
    block_start_boundaries: u64,
    /// Fewest clusters during the current block.
    block_clusters: usize,
    /// The current block met a non-differentiable point.
    broken: bool,
    /// The current period follows one that was broken: its tangent vectors are stale, it is
    /// not averaged.
    recovering: bool,
    /// Logarithms and time accumulated in the current period.
    current: Vec<f64>,
    current_time: f64,
    /// The periods averaged so far.
    logs: PeriodLogs,
    /// Fewest clusters over the averaged blocks.
    window_clusters: usize,
    skipped: u64,
    points: Vec<NonSmoothPoint>,
    point_count: u64,
    folds: u64,
}

impl LyapunovObserver {
    /// An observer for the chain `params` (that of the simulator it watches) that averages
    /// from the end of the first `transient_periods` excitation periods on. Errors on invalid
    /// options.
    pub fn new(
        params: &ChainParams,
        transient_periods: u64,
        options: &LyapunovOptions,
    ) -> Result<Self, ParamError> {
        options.validate()?;
        params.validate()?;
        let n = params.len();
        let dim = 2 * n;
        Ok(LyapunovObserver {
            sens: Sensitivity::new(params, options.sensitivity.clone()),
            q: random_basis(dim, options.seed),
            m: DMatrix::zeros(dim, dim),
            masses: n,
            period: params.period(),
            transient: transient_periods,
            max_growth: options.max_growth,
            horizon: options.max_growth.ln()
                / params
                    .damping
                    .iter()
                    .zip(&params.masses)
                    .map(|(c, m)| c / m)
                    .fold(0.0, f64::max),
            options: options.clone(),
            started: false,
            boundaries: 0,
            next_boundary: params.period(),
            due: false,
            block_start: 0.0,
            block_start_boundaries: 0,
            block_clusters: n,
            broken: false,
            recovering: false,
            current: vec![0.0; dim],
            current_time: 0.0,
            logs: PeriodLogs::new(dim),
            window_clusters: n,
            skipped: 0,
            points: Vec::new(),
            point_count: 0,
            folds: 0,
        })
    }

    /// Periods averaged so far.
    pub fn periods(&self) -> u64 {
        self.logs.len() as u64
    }

    /// The spectrum over the periods averaged so far (the running value; the run may go on).
    pub fn spectrum(&self) -> Result<LyapunovSpectrum, LyapunovError> {
        if self.logs.is_empty() {
            return Err(LyapunovError::NoPeriods {
                skipped: self.skipped,
                first: self.points.first().cloned(),
            });
        }
        let collapsed = 2 * (self.masses - self.window_clusters);
        Ok(LyapunovSpectrum::from_logs(
            &self.logs,
            collapsed,
            self.options.batches,
            super::spectrum::Diagnostics {
                skipped_periods: self.skipped,
                non_smooth: self.points.clone(),
                non_smooth_count: self.point_count,
                reorthonormalisations: self.folds,
            },
        ))
    }

    /// The spectrum over every period averaged (see [`spectrum`](Self::spectrum)).
    pub fn finish(self) -> Result<LyapunovSpectrum, LyapunovError> {
        self.spectrum()
    }

    /// Re-orthonormalises at time `t` (after a piece of flow): `Φ·Q = Q′R`, Q ← Q′, Φ ← I.
    fn fold(&mut self, t: f64) {
        let Ok(phi) = self.sens.stm() else {
            return;
        };
        self.m.gemm(1.0, phi, &self.q, 0.0);
        let qr = self.m.clone().qr();
        let r = qr.r();
        let averaged = self.block_start_boundaries >= self.transient && !self.recovering;
        if averaged {
            for (i, c) in self.current.iter_mut().enumerate() {
                *c += r[(i, i)].abs().ln();
            }
            self.current_time += t - self.block_start;
            self.window_clusters = self.window_clusters.min(self.block_clusters);
        }
        self.q = qr.q();
        let restarted = self.sens.restart();
        debug_assert!(restarted, "a fold happens only where the product can be split");
        self.folds += 1;
        self.start_block(t);
        if self.due {
            self.due = false;
            if self.recovering && self.boundaries > self.transient {
                self.skipped += 1;
            }
            self.recovering = false;
            self.close_period();
        }
    }

    fn start_block(&mut self, t: f64) {
        self.block_start = t;
        self.block_start_boundaries = self.boundaries;
        self.block_clusters = self.masses;
    }

    /// Files the current period's logarithms (if it was averaged).
    fn close_period(&mut self) {
        if self.current_time > 0.0 {
            self.logs.push(&self.current, self.current_time);
        }
        self.current.fill(0.0);
        self.current_time = 0.0;
    }

    /// Drops the period that met a non-differentiable point and starts afresh at `t` (a
    /// boundary): Φ ← I after the events there; the next period only realigns the vectors.
    fn drop_period(&mut self, t: f64) {
        if self.boundaries > self.transient {
            self.skipped += 1;
        }
        self.current.fill(0.0);
        self.current_time = 0.0;
        self.sens.reset();
        self.broken = false;
        self.recovering = true;
        self.due = false;
        self.start_block(t);
    }
}

/// A random orthonormal basis of ℝ^dim (QR of a matrix of standard normal entries).
fn random_basis(dim: usize, seed: u64) -> DMatrix<f64> {
    let mut rng = SplitMix64::stream(seed, &[dim as u64]);
    let a = DMatrix::from_fn(dim, dim, |_, _| rng.normal());
    a.qr().q()
}

impl LyapunovObserver {
    /// One piece of flow (or a part of one, `split` where the block reaches its horizon):
    /// Φ, the clock, and a fold where one is due.
    fn piece(&mut self, flow: &Flow<'_>, split: bool) {
        self.sens.flow(flow);
        self.block_clusters = self.block_clusters.min(flow.clusters().len());
        while flow.t_end >= self.next_boundary {
            self.boundaries += 1;
            self.next_boundary = (self.boundaries + 1) as f64 * self.period;
            self.due = true;
        }
        if !self.broken
            && let Some(p) = self.sens.non_smooth()
        {
            self.broken = true;
            self.point_count += 1;
            if self.points.len() < KEPT_POINTS {
                self.points.push(p.clone());
            }
        }
        if self.broken {
            if self.due {
                self.drop_period(flow.t_end);
            }
            return;
        }
        if self.sens.chatter_pending() {
            return;
        }
        let long = split || flow.t_end - self.block_start >= self.horizon;
        let grown = || self.sens.stm().is_ok_and(|phi| phi.amax() > self.max_growth);
        if self.due || long || grown() {
            self.fold(flow.t_end);
        }
    }
}

impl Observer for LyapunovObserver {
    fn flow(&mut self, flow: &Flow<'_>) {
        if !self.started {
            self.started = true;
            self.boundaries = (flow.t_start / self.period + 1e-9).floor().max(0.0) as u64;
            self.next_boundary = (self.boundaries + 1) as f64 * self.period;
            self.start_block(flow.t_start);
        }
        // A piece longer than the block horizon is taken in parts (the closed-form Jacobian
        // over the whole piece would have lost the fastest-decaying directions).
        let mut a = flow.t_start;
        loop {
            let limit = self.block_start + self.horizon;
            let split = limit > a && limit < flow.t_end;
            let b = if split { limit } else { flow.t_end };
            self.piece(
                &Flow {
                    t_start: a,
                    t_end: b,
                    ..*flow
                },
                split,
            );
            if b >= flow.t_end {
                break;
            }
            a = b;
        }
    }

    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        self.sens.event(event, state);
    }
}
