//! [`Chirp`]: a frequency sweep of the base displacement, `y(t) = A sin φ(t)`, linear or
//! logarithmic in frequency, up or down, and its clamped spline within a stated error.

use std::f64::consts::TAU;

use super::budget::WorkBudget;
use super::error::SignalError;
use super::harmonics::{SplineAccuracy, intervals_for, sample_smooth_within};
use super::spline::PiecewiseCubic;

/// How the instantaneous frequency moves from its start to its end value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Sweep {
    /// f(t) = f₀ + (f₁ − f₀) t/D.
    Linear,
    /// f(t) = f₀ (f₁/f₀)^{t/D} (equal time per octave).
    Logarithmic,
}

impl Sweep {
    /// Its name: `linear` or `logarithmic`.
    pub fn as_str(self) -> &'static str {
        match self {
            Sweep::Linear => "linear",
            Sweep::Logarithmic => "logarithmic",
        }
    }
}

/// A chirp of the base displacement over `[0, D]`: `y(t) = A sin φ(t)` with φ(0) = 0 and
/// φ'(t) = 2π f(t) (the amplitude is a displacement, constant over the sweep; the base
/// acceleration then grows as f²). An up-sweep has f₁ > f₀, a down-sweep f₁ < f₀.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Chirp {
    /// Displacement amplitude A, m.
    pub amplitude: f64,
    /// Frequency f₀ at t = 0, Hz.
    pub f_start_hz: f64,
    /// Frequency f₁ at t = D, Hz.
    pub f_end_hz: f64,
    /// Duration D, s.
    pub duration: f64,
    /// Linear or logarithmic.
    pub sweep: Sweep,
}

impl Chirp {
    /// Checks the parameters: finite, amplitude ≥ 0, frequencies and duration > 0.
    pub fn validate(&self) -> Result<(), SignalError> {
        let ok = self.amplitude.is_finite()
            && self.amplitude >= 0.0
            && [self.f_start_hz, self.f_end_hz, self.duration]
                .iter()
                .all(|x| x.is_finite() && *x > 0.0);
        if ok {
            Ok(())
        } else {
            Err(SignalError::Invalid(format!(
                "a chirp needs a finite amplitude ≥ 0 and positive frequencies and duration, got {self:?}"
            )))
        }
    }

    /// ln(f₁/f₀)/D, 1/s (0 for a linear sweep).
    fn log_rate(&self) -> f64 {
        match self.sweep {
            Sweep::Linear => 0.0,
            Sweep::Logarithmic => (self.f_end_hz / self.f_start_hz).ln() / self.duration,
        }
    }

    /// The instantaneous frequency f(t) = φ'(t)/2π, Hz.
    pub fn frequency_hz(&self, t: f64) -> f64 {
        match self.sweep {
            Sweep::Linear => self.f_start_hz + (self.f_end_hz - self.f_start_hz) * t / self.duration,
            Sweep::Logarithmic => self.f_start_hz * (self.log_rate() * t).exp(),
        }
    }

    /// The phase φ(t), rad.
    pub fn phase(&self, t: f64) -> f64 {
        let (f0, f1, d) = (self.f_start_hz, self.f_end_hz, self.duration);
        let rate = self.log_rate();
        match self.sweep {
            Sweep::Logarithmic if rate != 0.0 => TAU * f0 * (rate * t).exp_m1() / rate,
            _ => TAU * (f0 * t + (f1 - f0) * t * t / (2.0 * d)),
        }
    }

    /// Displacement (m) and velocity (m/s) at `t` (s).
    pub fn displacement_velocity(&self, t: f64) -> [f64; 2] {
        let (s, c) = self.phase(t).sin_cos();
        [
            self.amplitude * s,
            self.amplitude * TAU * self.frequency_hz(t) * c,
        ]
    }

    /// A bound on |y''''| over the sweep, m/s⁴, from Faà di Bruno's formula:
    /// A (W⁴ + 6 W² P₂ + 4 W P₃ + 3 P₂² + P₄) with W the largest 2πf and P_k the largest
    /// |φ^{(k)}| (each maximum taken separately, so an upper bound).
    pub fn fourth_derivative_bound(&self) -> f64 {
        let w = TAU * self.f_start_hz.max(self.f_end_hz);
        let (p2, p3, p4) = match self.sweep {
            Sweep::Linear => (
                TAU * (self.f_end_hz - self.f_start_hz).abs() / self.duration,
                0.0,
                0.0,
            ),
            Sweep::Logarithmic => {
                let r = self.log_rate().abs();
                (w * r, w * r * r, w * r * r * r)
            }
        };
        self.amplitude * (w.powi(4) + 6.0 * w * w * p2 + 4.0 * w * p3 + 3.0 * p2 * p2 + p4)
    }

    /// The number of spline intervals [`to_spline`](Self::to_spline) would use for
    /// `tolerance` (m) (checks the parameters without building).
    pub fn intervals_needed(&self, tolerance: f64) -> Result<usize, SignalError> {
        self.validate()?;
        if !(tolerance.is_finite() && tolerance > 0.0) {
            return Err(SignalError::Invalid(format!(
                "spline tolerance {tolerance} m: must be finite and > 0"
            )));
        }
        intervals_for(
            self.duration,
            tolerance,
            self.fourth_derivative_bound(),
            3,
            "the chirp",
        )
    }

    /// The clamped cubic spline of the chirp on equal knots over `[0, D]`, close enough that
    /// the displacement error is at most `tolerance` (m) by the bound of
    /// [`spline_error_bounds`](super::spline_error_bounds), and the bounds achieved.
    pub fn to_spline(&self, tolerance: f64) -> Result<(PiecewiseCubic, SplineAccuracy), SignalError> {
        self.to_spline_within(tolerance, &WorkBudget::unlimited())
    }

    /// [`to_spline`](Self::to_spline) stopped by `budget`'s flag ([`SignalError::Stopped`];
    /// a spline of millions of knots takes seconds).
    pub fn to_spline_within(
        &self,
        tolerance: f64,
        budget: &WorkBudget,
    ) -> Result<(PiecewiseCubic, SplineAccuracy), SignalError> {
        let n = self.intervals_needed(tolerance)?;
        let m4 = self.fourth_derivative_bound();
        let spline = sample_smooth_within(|t| self.displacement_velocity(t), self.duration, n, budget)?;
        Ok((spline, SplineAccuracy::new(self.duration / n as f64, m4)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The phase's derivative (central difference) is 2π f(t); φ(0) = 0.
    #[test]
    fn phase_is_the_integral_of_the_frequency() {
        for sweep in [Sweep::Linear, Sweep::Logarithmic] {
            for (f0, f1) in [(2.0, 8.0), (8.0, 2.0)] {
                let c = Chirp {
                    amplitude: 0.01,
                    f_start_hz: f0,
                    f_end_hz: f1,
                    duration: 10.0,
                    sweep,
                };
                assert_eq!(c.phase(0.0), 0.0);
                for t in [0.5, 5.0, 9.5] {
                    let dt = 1e-5;
                    let d = (c.phase(t + dt) - c.phase(t - dt)) / (2.0 * dt);
                    assert!((d / TAU - c.frequency_hz(t)).abs() < 1e-6, "{sweep:?} {t}");
                }
            }
        }
    }
}
