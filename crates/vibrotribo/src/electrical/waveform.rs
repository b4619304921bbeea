//! Gap waveforms that drive the charge solver: the simulator's exact [`Flow`] (which the
//! solver, as an observer or replaying a trajectory, expands into piecewise Taylor polynomials
//! first), any closure, and piecewise-linear tables (the form ngspice reads).

use crate::dynamics::{Flow, GapPolynomial, Trajectory};
use crate::error::ParamError;

/// Gaps as a smooth function of time on the interval the solver is advanced over.
///
/// Contract: on `[t0, t1]` of a call to
/// [`ChargeSolver::advance`](super::ChargeSolver::advance) the gaps are smooth (a kink, such as
/// an impact, must fall on an interval end), and values at the ends are the limits from inside
/// the interval.
pub trait GapWaveform {
    /// Writes every gap d_k, m, and its rate d_k', m/s, at time `t`, s (slices of length N − 1).
    fn gaps(&self, t: f64, gaps: &mut [f64], rates: &mut [f64]);

    /// Writes every gap d_k, m, at time `t`, s, where the rates are not needed (the solver's
    /// stage points). The default calls [`gaps`](Self::gaps) and drops the rates.
    fn gap_values(&self, t: f64, gaps: &mut [f64]) {
        let n = gaps.len();
        if n <= 64 {
            let mut rates = [0.0; 64];
            self.gaps(t, gaps, &mut rates[..n]);
        } else {
            let mut rates = vec![0.0; n];
            self.gaps(t, gaps, &mut rates);
        }
    }

    /// Writes the gaps, m, at each of `times`, s: `gaps[i·n + k]` is gap k at `times[i]`, n the
    /// number of gaps (`gaps.len() = times.len()·n`). The solver asks for all stage points of a
    /// step at once. The default calls [`gap_values`](Self::gap_values) for each time.
    fn gap_values_at(&self, times: &[f64], gaps: &mut [f64]) {
        let n = gaps.len() / times.len().max(1);
        for (t, g) in times.iter().zip(gaps.chunks_exact_mut(n.max(1))) {
            self.gap_values(*t, g);
        }
    }
}

/// The simulator's flow as piecewise Taylor polynomials, accurate to the rounding of the closed
/// form and much cheaper to evaluate (see `dynamics::taylor`).
impl GapWaveform for GapPolynomial {
    #[inline]
    fn gaps(&self, t: f64, gaps: &mut [f64], rates: &mut [f64]) {
        self.values_and_rates(t, gaps, rates)
    }

    #[inline]
    fn gap_values(&self, t: f64, gaps: &mut [f64]) {
        self.values(t, gaps)
    }

    #[inline]
    fn gap_values_at(&self, times: &[f64], gaps: &mut [f64]) {
        self.values_many(times, gaps)
    }
}

impl GapWaveform for Flow<'_> {
    #[inline]
    fn gaps(&self, t: f64, gaps: &mut [f64], rates: &mut [f64]) {
        self.gaps_at(t, gaps, rates)
    }
}

impl<F: Fn(f64, &mut [f64], &mut [f64])> GapWaveform for F {
    #[inline]
    fn gaps(&self, t: f64, gaps: &mut [f64], rates: &mut [f64]) {
        self(t, gaps, rates)
    }
}

/// Piecewise-linear gaps: values at increasing times, linear in between (what an ngspice `PWL`
/// source describes).
#[derive(Debug, Clone, PartialEq)]
pub struct PwlGaps {
    times: Vec<f64>,
    /// Row-major: `values[j * n + k]` is gap k at `times[j]`, m.
    values: Vec<f64>,
    n: usize,
}

impl PwlGaps {
    /// A table of `n` gaps (m) at strictly increasing `times` (s); `values[j * n + k]` is gap k
    /// at `times[j]`. Needs at least two times.
    pub fn new(times: Vec<f64>, values: Vec<f64>, n: usize) -> Result<Self, ParamError> {
        if times.len() < 2 {
            return Err(ParamError::Length {
                name: "pwl.times".into(),
                expected: 2,
                got: times.len(),
            });
        }
        if values.len() != times.len() * n || n == 0 {
            return Err(ParamError::Length {
                name: "pwl.values".into(),
                expected: times.len() * n.max(1),
                got: values.len(),
            });
        }
        for (j, w) in times.windows(2).enumerate() {
            if !w[0].is_finite() || !w[1].is_finite() || w[1] <= w[0] {
                return Err(ParamError::Invalid {
                    name: format!("pwl.times[{}]", j + 1),
                    value: w[1],
                    reason: "times must be finite and strictly increasing",
                });
            }
        }
        if let Some(j) = values.iter().position(|v| !v.is_finite()) {
            return Err(ParamError::Invalid {
                name: format!("pwl.values[{j}]"),
                value: values[j],
                reason: "must be a finite number",
            });
        }
        Ok(PwlGaps { times, values, n })
    }

    /// Points of [`from_trajectory`](Self::from_trajectory) over `periods` excitation periods
    /// sampled every `dt_fraction` of a period, segment boundaries aside (an estimate, to
    /// refuse a mistyped size before anything is allocated).
    pub fn estimated_points(periods: f64, dt_fraction: f64) -> f64 {
        periods / dt_fraction + 1.0
    }

    /// Bytes held while building `points` points of `gaps` gaps (the candidate times, the
    /// kept times, the values), an estimate.
    pub fn estimated_bytes(points: f64, gaps: usize) -> f64 {
        points * (2.0 + gaps as f64) * std::mem::size_of::<f64>() as f64
    }

    /// Samples a recorded trajectory from its start to `t_end`, s, every `dt` seconds, adding
    /// every segment boundary (impact kinks); points closer than `dt/1000` to the previous one
    /// are dropped.
    pub fn from_trajectory(trajectory: &Trajectory, dt: f64, t_end: f64) -> Result<Self, ParamError> {
        let (t_start, t_last) = trajectory.span().ok_or(ParamError::Length {
            name: "trajectory.segments".into(),
            expected: 1,
            got: 0,
        })?;
        if !dt.is_finite() || dt <= 0.0 {
            return Err(ParamError::Invalid {
                name: "pwl.dt".into(),
                value: dt,
                reason: "must be positive",
            });
        }
        let t_end = t_end.min(t_last);
        let n = trajectory.gap_count();
        let mut candidates: Vec<f64> = Vec::new();
        let steps = ((t_end - t_start) / dt).floor() as usize;
        candidates.extend((0..=steps).map(|j| t_start + j as f64 * dt));
        for s in trajectory.segments() {
            if s.t_start < t_end {
                candidates.push(s.t_start);
            }
        }
        candidates.push(t_end);
        candidates.sort_by(f64::total_cmp);
        let min_spacing = dt * 1e-3;
        let mut times: Vec<f64> = Vec::with_capacity(candidates.len());
        for t in candidates {
            match times.last() {
                Some(&last) if t - last < min_spacing => {}
                _ => times.push(t),
            }
        }
        // Keep the exact end point.
        if let Some(last) = times.last_mut() {
            *last = t_end;
        }
        let mut values = vec![0.0; times.len() * n];
        let mut rates = vec![0.0; n];
        for (j, &t) in times.iter().enumerate() {
            if let Some(flow) = trajectory.flow_at(t) {
                flow.gaps_at(t, &mut values[j * n..(j + 1) * n], &mut rates);
            }
        }
        PwlGaps::new(times, values, n)
    }

    /// Number of gaps.
    pub fn gap_count(&self) -> usize {
        self.n
    }

    /// Breakpoint times, s.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// Gap `k` at breakpoint `j`, m.
    pub fn value(&self, j: usize, k: usize) -> f64 {
        self.values[j * self.n + k]
    }

    /// Number of linear pieces.
    pub fn pieces(&self) -> usize {
        self.times.len() - 1
    }

    /// Piece `j` (between `times[j]` and `times[j+1]`) as a waveform, exact on that interval.
    pub fn piece(&self, j: usize) -> PwlPiece<'_> {
        PwlPiece { pwl: self, j }
    }
}

/// One linear piece of a [`PwlGaps`] (extended linearly beyond its interval).
#[derive(Debug, Clone, Copy)]
pub struct PwlPiece<'a> {
    pwl: &'a PwlGaps,
    j: usize,
}

impl PwlPiece<'_> {
    /// Start and end of the piece, s.
    pub fn span(&self) -> (f64, f64) {
        (self.pwl.times[self.j], self.pwl.times[self.j + 1])
    }
}

impl GapWaveform for PwlPiece<'_> {
    #[inline]
    fn gaps(&self, t: f64, gaps: &mut [f64], rates: &mut [f64]) {
        let n = self.pwl.n;
        let (t0, t1) = self.span();
        let a = &self.pwl.values[self.j * n..(self.j + 1) * n];
        let b = &self.pwl.values[(self.j + 1) * n..(self.j + 2) * n];
        let inv = 1.0 / (t1 - t0);
        for k in 0..n {
            let slope = (b[k] - a[k]) * inv;
            rates[k] = slope;
            gaps[k] = a[k] + slope * (t - t0);
        }
    }
}
