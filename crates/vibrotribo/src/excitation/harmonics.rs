//! [`Harmonic`]: one sinusoidal component of the base displacement, sums of them
//! (multisines), and their sampling into a clamped cubic spline within a stated error.

use super::budget::WorkBudget;
use super::error::SignalError;
use super::spline::{EndCondition, PiecewiseCubic, knot_spacing, spline_error_bounds};

/// One harmonic of the base displacement, `y(t) = A sin(ω t + φ)`. With φ = 0 it is the
/// harmonic excitation of [`Excitation`](crate::Excitation).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Harmonic {
    /// Displacement amplitude A, m.
    pub amplitude: f64,
    /// Angular frequency ω, rad/s.
    pub omega: f64,
    /// Phase φ at t = 0, rad.
    pub phase: f64,
}

impl Harmonic {
    /// Displacement (m), velocity (m/s) and acceleration (m/s²) at `t` (s).
    pub fn evaluate(&self, t: f64) -> [f64; 3] {
        let (s, c) = (self.omega * t + self.phase).sin_cos();
        let a = self.amplitude;
        let w = self.omega;
        [a * s, a * w * c, -a * w * w * s]
    }
}

/// The sum of `harmonics` at `t` (s): displacement (m), velocity (m/s), acceleration (m/s²).
pub fn evaluate_sum(harmonics: &[Harmonic], t: f64) -> [f64; 3] {
    harmonics.iter().fold([0.0; 3], |acc, h| {
        let v = h.evaluate(t);
        [acc[0] + v[0], acc[1] + v[1], acc[2] + v[2]]
    })
}

/// A bound on |y''''| of the sum of `harmonics`, m/s⁴: Σ |A| ω⁴.
pub fn fourth_derivative_bound(harmonics: &[Harmonic]) -> f64 {
    harmonics
        .iter()
        .map(|h| h.amplitude.abs() * h.omega.powi(4))
        .sum()
}

/// What sampling a smooth signal into a spline achieved.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SplineAccuracy {
    /// Knot spacing h, s.
    pub knot_spacing: f64,
    /// The bound M₄ on |y''''| used, m/s⁴.
    pub fourth_derivative_bound: f64,
    /// Bounds on the errors of the displacement (m), velocity (m/s) and acceleration (m/s²)
    /// against the exact signal ([`spline_error_bounds`]).
    pub error_bounds: [f64; 3],
}

impl SplineAccuracy {
    /// The accuracy of knots `h` apart for a signal with |y''''| ≤ `m4`.
    pub fn new(h: f64, m4: f64) -> Self {
        SplineAccuracy {
            knot_spacing: h,
            fourth_derivative_bound: m4,
            error_bounds: spline_error_bounds(h, m4),
        }
    }
}

/// The largest number of knots a sampled signal may have (memory: 40 bytes a knot).
pub const MAX_KNOTS: usize = 20_000_000;

/// The number of equal intervals over `[0, end]` (s) that keeps the clamped spline of a signal
/// with |y''''| ≤ `m4` (m/s⁴) within `tolerance` (m), at least `min` of them. An error (in
/// the words of `what`) if more than [`MAX_KNOTS`] would be needed.
pub(crate) fn intervals_for(
    end: f64,
    tolerance: f64,
    m4: f64,
    min: usize,
    what: &str,
) -> Result<usize, SignalError> {
    let h = if m4 > 0.0 {
        knot_spacing(tolerance, m4)
    } else {
        end
    };
    let n = (end / h).ceil();
    if !(n.is_finite() && n < MAX_KNOTS as f64) {
        return Err(SignalError::TooLarge(format!(
            "{what} would need {n:.3e} spline knots (at most {MAX_KNOTS}): raise the tolerance or shorten the signal"
        )));
    }
    Ok((n as usize).max(min))
}

/// The clamped cubic spline of the signal `f(t) = [y, y']` (m, m/s) on `intervals` equal
/// intervals of `[0, end]` (s).
pub(crate) fn sample_smooth(
    f: impl Fn(f64) -> [f64; 2],
    end: f64,
    intervals: usize,
) -> Result<PiecewiseCubic, SignalError> {
    sample_smooth_within(f, end, intervals, &WorkBudget::unlimited())
}

/// Knots sampled between two looks at the stop flag ([`sample_smooth_within`]).
const POLL_KNOTS: usize = 1 << 14;

/// [`sample_smooth`] stopped by `budget`'s flag (read every 16 384 knots:
/// [`SignalError::Stopped`]).
pub(crate) fn sample_smooth_within(
    f: impl Fn(f64) -> [f64; 2],
    end: f64,
    intervals: usize,
    budget: &WorkBudget,
) -> Result<PiecewiseCubic, SignalError> {
    let times: Vec<f64> = (0..=intervals)
        .map(|k| end * k as f64 / intervals as f64)
        .collect();
    let mut values = Vec::with_capacity(times.len());
    for (k, &t) in times.iter().enumerate() {
        if k % POLL_KNOTS == 0 && budget.stopped() {
            return Err(SignalError::Stopped { done: k, intervals });
        }
        values.push(f(t)[0]);
    }
    let ends = EndCondition::Clamped {
        start_slope: f(0.0)[1],
        end_slope: f(end)[1],
    };
    PiecewiseCubic::interpolate(&times, &values, ends)
}

/// The clamped cubic spline of the sum of `harmonics` on `[0, end]` (s), with equal knots
/// close enough that the displacement error is at most `tolerance` (m), and the bounds it
/// achieves (for an engine that takes only piecewise-polynomial base motion).
pub fn harmonics_to_spline(
    harmonics: &[Harmonic],
    end: f64,
    tolerance: f64,
) -> Result<(PiecewiseCubic, SplineAccuracy), SignalError> {
    if !(end > 0.0 && end.is_finite() && tolerance > 0.0 && tolerance.is_finite()) {
        return Err(SignalError::Invalid(format!(
            "a spline needs a positive end time and tolerance, got end = {end} s, tolerance = {tolerance} m"
        )));
    }
    let m4 = fourth_derivative_bound(harmonics);
    let n = intervals_for(end, tolerance, m4, 1, "the multisine")?;
    let spline = sample_smooth(
        |t| {
            let [y, v, _] = evaluate_sum(harmonics, t);
            [y, v]
        },
        end,
        n,
    )?;
    Ok((spline, SplineAccuracy::new(end / n as f64, m4)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The spline of A sin(ωt + φ) at the spacing the tolerance asks for meets the
    /// Hall–Meyer bounds, checked against the sine itself on a fine grid.
    #[test]
    fn spline_of_a_sine_meets_its_bounds() {
        let h = Harmonic {
            amplitude: 0.08,
            omega: 35.0,
            phase: 0.3,
        };
        let (s, acc) = harmonics_to_spline(&[h], 2.0, 1e-10).unwrap();
        assert!(acc.error_bounds[0] <= 1e-10 * (1.0 + 1e-12));
        let mut worst = [0.0f64; 3];
        for k in 0..=20_000 {
            let t = 2.0 * k as f64 / 20_000.0;
            let got = s.evaluate(t);
            let exact = h.evaluate(t);
            for d in 0..3 {
                worst[d] = worst[d].max((got[d] - exact[d]).abs());
            }
        }
        for d in 0..3 {
            assert!(
                worst[d] <= acc.error_bounds[d],
                "derivative {d}: {worst:?} vs {acc:?}"
            );
        }
    }
}
