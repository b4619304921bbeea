//! The spectrum from the logarithms of the QR factors, period by period, with its
//! batch-means spread.

use crate::sensitivity::NonSmoothPoint;

/// The logarithms `ln|R_ii|` summed over each averaged period, and its length.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PeriodLogs {
    dim: usize,
    logs: Vec<f64>,
    times: Vec<f64>,
}

impl PeriodLogs {
    pub fn new(dim: usize) -> Self {
        PeriodLogs {
            dim,
            logs: Vec::new(),
            times: Vec::new(),
        }
    }

    pub fn push(&mut self, logs: &[f64], time: f64) {
        debug_assert_eq!(logs.len(), self.dim);
        self.logs.extend_from_slice(logs);
        self.times.push(time);
    }

    pub fn len(&self) -> usize {
        self.times.len()
    }

    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// The exponents (per column of the tangent basis) over periods `range`, 1/s.
    fn rates(&self, range: std::ops::Range<usize>) -> Vec<f64> {
        let time: f64 = self.times[range.clone()].iter().sum();
        (0..self.dim)
            .map(|i| range.clone().map(|p| self.logs[p * self.dim + i]).sum::<f64>() / time)
            .collect()
    }
}

/// What happened on the way: skipped periods, non-differentiable points, work.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Diagnostics {
    pub skipped_periods: u64,
    pub non_smooth: Vec<NonSmoothPoint>,
    pub non_smooth_count: u64,
    pub reorthonormalisations: u64,
}

/// The Lyapunov spectrum of a run, with its convergence estimate.
#[derive(Debug, Clone, PartialEq)]
pub struct LyapunovSpectrum {
    /// The 2N exponents, 1/s, largest first. The directions a stuck contact (or a chatter
    /// accumulation) removes are `−∞` ([`collapsed`](Self::collapsed) of them, last).
    pub exponents: Vec<f64>,
    /// The convergence estimate of each exponent, 1/s: the standard error of the mean of the
    /// exponents of [`batches`](Self::batches) consecutive batches of periods (batch means),
    /// combined in quadrature, where the batches drift smoothly (a least-squares trend more
    /// than 8 of its standard errors from 0), with the largest difference between the final exponent and
    /// the [`running`](Self::running) estimates over the second half of the window (the
    /// finite-time bias of a window whose tangent vectors are still aligning, which the
    /// scatter of the batches does not measure); plus half the gap to a neighbouring
    /// exponent within 1 % of it (two estimates of one exponent, such as the pair of a
    /// complex Floquet multiplier, that the averaging splits); NaN with fewer than two
    /// periods, 0 for a `−∞` exponent.
    pub spread: Vec<f64>,
    /// Number of `−∞` exponents: 2 per contact stuck at the same time at the worst moment of
    /// the averaged window (a stuck contact, or a chatter sequence that ends in one,
    /// maps a neighbourhood of the trajectory onto the sticking surface in finite time).
    pub collapsed: usize,
    /// Excitation periods averaged over.
    pub periods: u64,
    /// Time averaged over, s.
    pub time: f64,
    /// The exponents, 1/s, of each batch of consecutive periods (same order as
    /// [`exponents`](Self::exponents)), whose spread gives [`spread`](Self::spread).
    pub batches: Vec<Vec<f64>>,
    /// The running estimate after each batch: (periods averaged so far, exponents in 1/s).
    pub running: Vec<(u64, Vec<f64>)>,
    /// Periods after the transient left out because they met a non-differentiable point
    /// (grazing, simultaneous impacts), and the period after each such one (its tangent
    /// vectors are realigned, not averaged).
    pub skipped_periods: u64,
    /// The first non-differentiable points met (at most 16).
    pub non_smooth: Vec<NonSmoothPoint>,
    /// How many non-differentiable points were met, transient included.
    pub non_smooth_count: u64,
    /// QR re-orthonormalisations done, transient included.
    pub reorthonormalisations: u64,
}

/// Whether a series of batch values drifts smoothly: the least-squares slope against the
/// batch index is more than 8 of its standard errors from 0 (with 10 batches, the line
/// explains over 88 % of their variance). A rate whose tangent vectors are still aligning
/// fits such a line; the batches of a chaotic motion, scattered at random, almost never do.
fn trending(values: &[f64]) -> bool {
    let n = values.len();
    if n < 3 || values.iter().any(|v| !v.is_finite()) {
        return false;
    }
    let mean_x = (n - 1) as f64 / 2.0;
    let mean_y = values.iter().sum::<f64>() / n as f64;
    let sxx: f64 = (0..n).map(|k| (k as f64 - mean_x).powi(2)).sum();
    let sxy: f64 = values
        .iter()
        .enumerate()
        .map(|(k, y)| (k as f64 - mean_x) * (y - mean_y))
        .sum();
    let slope = sxy / sxx;
    let ssr: f64 = values
        .iter()
        .enumerate()
        .map(|(k, y)| (y - mean_y - slope * (k as f64 - mean_x)).powi(2))
        .sum();
    let se = (ssr / (n - 2) as f64 / sxx).sqrt();
    slope.abs() > 8.0 * se
}

/// Neighbouring exponents closer than this fraction of the larger modulus are taken as one
/// exponent the run does not resolve (see [`widen_unresolved`]).
const UNRESOLVED: f64 = 0.01;

/// The spreads of `exponents` (largest first) widened by half the gap to a neighbour closer
/// than [`UNRESOLVED`] of the larger modulus. A pair of complex Floquet multipliers gives
/// two equal exponents, which the QR averaging splits into a larger and a smaller estimate
/// about their common value; the split persists over the window (it does not shrink like
/// the batch scatter), so it is part of each estimate's error, not of its scatter.
fn widen_unresolved(exponents: &[f64], spread: &[f64]) -> Vec<f64> {
    let half_gap = |i: usize, j: usize| {
        let (a, b) = (exponents[i], exponents[j]);
        let close = a.is_finite() && b.is_finite() && (a - b).abs() <= UNRESOLVED * a.abs().max(b.abs());
        if close { (a - b).abs() / 2.0 } else { 0.0 }
    };
    (0..exponents.len())
        .map(|i| {
            let before = if i > 0 { half_gap(i - 1, i) } else { 0.0 };
            let after = if i + 1 < exponents.len() {
                half_gap(i, i + 1)
            } else {
                0.0
            };
            spread[i] + before.max(after)
        })
        .collect()
}

impl LyapunovSpectrum {
    /// Builds the spectrum from the period logs: exponents per column of the tangent basis,
    /// the last `collapsed` set to −∞, sorted largest first.
    pub(crate) fn from_logs(logs: &PeriodLogs, collapsed: usize, batches: usize, d: Diagnostics) -> Self {
        let dim = logs.dim;
        let periods = logs.len();
        let mut exponents = logs.rates(0..periods);
        let b = batches.min(periods).max(1);
        let bounds: Vec<usize> = (0..=b).map(|k| k * periods / b).collect();
        let mut batch_rates: Vec<Vec<f64>> = bounds.windows(2).map(|w| logs.rates(w[0]..w[1])).collect();
        let mut running: Vec<(u64, Vec<f64>)> = bounds[1..]
            .iter()
            .map(|&end| (end as u64, logs.rates(0..end)))
            .collect();
        let mut spread: Vec<f64> = (0..dim)
            .map(|i| {
                if b < 2 {
                    return f64::NAN;
                }
                let mean = batch_rates.iter().map(|r| r[i]).sum::<f64>() / b as f64;
                let var = batch_rates.iter().map(|r| (r[i] - mean).powi(2)).sum::<f64>() / (b - 1) as f64;
                let column: Vec<f64> = batch_rates.iter().map(|r| r[i]).collect();
                let drift = if trending(&column) {
                    // The running estimate's largest distance from the final one over the
                    // second half of the window: the finite-time bias of an exponent whose
                    // batches drift (tangent vectors still aligning between two nearly
                    // equal exponents), which the scatter of the batches does not measure.
                    running
                        .iter()
                        .filter(|(end, _)| 2 * *end as usize >= periods)
                        .map(|(_, r)| (r[i] - exponents[i]).abs())
                        .fold(0.0, f64::max)
                } else {
                    0.0
                };
                (var / b as f64 + drift * drift).sqrt()
            })
            .collect();
        let collapsed = collapsed.min(dim);
        for i in dim - collapsed..dim {
            exponents[i] = f64::NEG_INFINITY;
            spread[i] = 0.0;
            for r in batch_rates.iter_mut().chain(running.iter_mut().map(|r| &mut r.1)) {
                r[i] = f64::NEG_INFINITY;
            }
        }
        // Largest first (the QR ordering already is, up to the scatter of nearly equal
        // exponents).
        let mut order: Vec<usize> = (0..dim).collect();
        order.sort_by(|&a, &b| exponents[b].total_cmp(&exponents[a]));
        let permute = |v: &[f64]| order.iter().map(|&i| v[i]).collect::<Vec<f64>>();
        let exponents = permute(&exponents);
        let spread = widen_unresolved(&exponents, &permute(&spread));
        LyapunovSpectrum {
            exponents,
            spread,
            collapsed,
            periods: periods as u64,
            time: logs.times.iter().sum(),
            batches: batch_rates.iter().map(|r| permute(r)).collect(),
            running: running.iter().map(|(n, r)| (*n, permute(r))).collect(),
            skipped_periods: d.skipped_periods,
            non_smooth: d.non_smooth,
            non_smooth_count: d.non_smooth_count,
            reorthonormalisations: d.reorthonormalisations,
        }
    }

    /// The largest exponent, 1/s.
    pub fn largest(&self) -> f64 {
        self.exponents.first().copied().unwrap_or(f64::NAN)
    }

    /// The spread of the largest exponent, 1/s.
    pub fn largest_spread(&self) -> f64 {
        self.spread.first().copied().unwrap_or(f64::NAN)
    }

    /// The sum of the exponents, 1/s: the mean phase-space contraction rate (−∞ if a
    /// direction collapsed).
    pub fn sum(&self) -> f64 {
        self.exponents.iter().sum()
    }

    /// The Kaplan–Yorke (Lyapunov) dimension `j + Σ_{i≤j} λ_i / |λ_{j+1}|`, j the largest
    /// index with a non-negative partial sum (0 if λ₁ < 0; 2N if every partial sum is
    /// non-negative). Of the stroboscopic map's attractor plus 1 for the time direction, it
    /// measures how many directions the motion fills.
    pub fn kaplan_yorke_dimension(&self) -> f64 {
        let mut sum = 0.0;
        for (j, &l) in self.exponents.iter().enumerate() {
            if sum + l < 0.0 {
                return if j == 0 { 0.0 } else { j as f64 + sum / l.abs() };
            }
            sum += l;
        }
        self.exponents.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Batch means of constant per-period rates: the rates themselves, no spread; of
    /// alternating rates: the mean and the standard error of the batch values.
    #[test]
    fn batch_means() {
        let mut logs = PeriodLogs::new(2);
        for p in 0..10 {
            let x = if p % 2 == 0 { 1.0 } else { 3.0 };
            logs.push(&[0.5, -x], 0.5);
        }
        let s = LyapunovSpectrum::from_logs(&logs, 0, 5, Diagnostics::default());
        assert_eq!(s.periods, 10);
        assert!((s.exponents[0] - 1.0).abs() < 1e-15);
        assert!((s.exponents[1] + 4.0).abs() < 1e-15);
        assert!(s.spread[0].abs() < 1e-15 && s.spread[1].abs() < 1e-15);
        let s = LyapunovSpectrum::from_logs(&logs, 0, 10, Diagnostics::default());
        // Batches of one period: −2 and −6 alternating: sd = √(80/9)/... computed by hand.
        let sd = (10.0 * 4.0 / 9.0f64).sqrt();
        assert!((s.spread[1] - sd / 10f64.sqrt()).abs() < 1e-12, "{:?}", s.spread);
        assert_eq!(s.running.last().unwrap().0, 10);
        let s = LyapunovSpectrum::from_logs(&logs, 1, 5, Diagnostics::default());
        assert_eq!(s.exponents[1], f64::NEG_INFINITY);
        assert_eq!(s.sum(), f64::NEG_INFINITY);
    }

    /// Per-period rates approaching λ∞ = −1 as λ∞ + e^{−k/400} (tangent vectors still
    /// aligning): over 1000 periods the batches drift smoothly, their scatter alone puts the
    /// asymptote many standard errors away, the spread with the drift covers it within 3.
    #[test]
    fn a_drifting_exponent_has_a_spread_that_covers_its_bias() {
        let mut logs = PeriodLogs::new(1);
        for k in 0..1000 {
            logs.push(&[-1.0 + (-(k as f64) / 400.0).exp()], 1.0);
        }
        let s = LyapunovSpectrum::from_logs(&logs, 0, 10, Diagnostics::default());
        let bias = s.exponents[0] + 1.0;
        let b = &s.batches;
        let mean = b.iter().map(|r| r[0]).sum::<f64>() / 10.0;
        let se = (b.iter().map(|r| (r[0] - mean).powi(2)).sum::<f64>() / 9.0 / 10.0).sqrt();
        assert!(bias > 3.0 * se, "bias {bias}, batch-means error {se}");
        assert!(bias < 3.0 * s.spread[0], "bias {bias}, spread {}", s.spread[0]);
        // Batches scattered about a constant (no trend) keep their batch-means error.
        let mut logs = PeriodLogs::new(1);
        for k in 0..1000u64 {
            logs.push(&[if (k * 7919) % 13 < 6 { 1.0 } else { -1.0 }], 1.0);
        }
        let s = LyapunovSpectrum::from_logs(&logs, 0, 10, Diagnostics::default());
        let b = &s.batches;
        let mean = b.iter().map(|r| r[0]).sum::<f64>() / 10.0;
        let se = (b.iter().map(|r| (r[0] - mean).powi(2)).sum::<f64>() / 9.0 / 10.0).sqrt();
        assert!(
            (s.spread[0] - se).abs() <= 1e-12 * se.max(1.0),
            "{} vs {se}",
            s.spread[0]
        );
    }

    /// Two estimates within 1 % of each other carry half their gap; a distinct neighbour,
    /// a `−∞` one or a NaN spread is left as it is.
    #[test]
    fn unresolved_neighbours_carry_half_their_gap() {
        let e = [-1.3210, -1.3220, -3.5, f64::NEG_INFINITY];
        let w = widen_unresolved(&e, &[1e-5, 2e-5, 3e-3, 0.0]);
        assert!((w[0] - (1e-5 + 5e-4)).abs() < 1e-15, "{w:?}");
        assert!((w[1] - (2e-5 + 5e-4)).abs() < 1e-15, "{w:?}");
        assert_eq!(&w[2..], &[3e-3, 0.0]);
        assert!(widen_unresolved(&[0.3, 0.298], &[f64::NAN, 0.0])[0].is_nan());
    }

    #[test]
    fn kaplan_yorke() {
        let mut s = LyapunovSpectrum::from_logs(&PeriodLogs::new(0), 0, 2, Diagnostics::default());
        s.exponents = vec![0.5, -0.25, -1.0];
        assert!((s.kaplan_yorke_dimension() - 2.25).abs() < 1e-15);
        s.exponents = vec![-0.1, -1.0];
        assert_eq!(s.kaplan_yorke_dimension(), 0.0);
    }
}
