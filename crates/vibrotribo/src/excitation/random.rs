//! [`RandomSpec`]: band-limited random base acceleration with a given one-sided power
//! spectral density, as a random-phase multisine on the frequency grid 1/D, integrated
//! exactly to displacement and made into a clamped spline (values by FFT).

use std::f64::consts::{FRAC_PI_2, TAU};

use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

use super::budget::WorkBudget;
use super::error::SignalError;
use super::harmonics::{
    Harmonic, MAX_KNOTS, SplineAccuracy, evaluate_sum, fourth_derivative_bound, intervals_for,
};
use super::pieces::HarmonicPieces;
use super::spline::{EndCondition, PiecewiseCubic};
use crate::random::SplitMix64;

/// The largest number of frequency components of a random signal.
pub const MAX_COMPONENTS: usize = 2_000_000;

/// A one-sided power spectral density of the base acceleration, (m/s²)²/Hz.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Psd {
    /// Flat between `f_low_hz` and `f_high_hz` (Hz, inclusive), zero outside, at the level
    /// that gives the RMS acceleration `rms` (m/s²) exactly: every one of the K grid
    /// frequencies in the band gets the amplitude rms·√(2/K), so the level is
    /// rms²/(K/D) ≈ rms²/(f_high − f_low).
    Flat {
        /// RMS acceleration, m/s².
        rms: f64,
        /// Lower band edge, Hz.
        f_low_hz: f64,
        /// Upper band edge, Hz.
        f_high_hz: f64,
    },
    /// Linear interpolation between points (frequencies Hz, strictly increasing; values
    /// (m/s²)²/Hz, ≥ 0), zero outside the table. A grid frequency f gets the amplitude
    /// √(2 S(f)/D), so the variance is Σ S(f_k)/D ≈ ∫ S df.
    Table {
        /// Frequencies, Hz.
        frequencies_hz: Vec<f64>,
        /// PSD values, (m/s²)²/Hz.
        values: Vec<f64>,
    },
}

impl Psd {
    /// The density at `f` (Hz) as given: the flat level rms²/(f_high − f_low) in the band
    /// for [`Psd::Flat`], the interpolated table otherwise; (m/s²)²/Hz.
    pub fn at(&self, f: f64) -> f64 {
        match self {
            Psd::Flat {
                rms,
                f_low_hz,
                f_high_hz,
            } => {
                if (*f_low_hz..=*f_high_hz).contains(&f) {
                    rms * rms / (f_high_hz - f_low_hz)
                } else {
                    0.0
                }
            }
            Psd::Table {
                frequencies_hz: fs,
                values,
            } => {
                if fs.is_empty() || f < fs[0] || f > fs[fs.len() - 1] {
                    return 0.0;
                }
                let i = fs.partition_point(|&x| x <= f).clamp(1, fs.len() - 1);
                let (f0, f1) = (fs[i - 1], fs[i]);
                values[i - 1] + (values[i] - values[i - 1]) * (f - f0) / (f1 - f0)
            }
        }
    }

    /// The band: lowest and highest frequency with a nonzero density, Hz.
    pub fn band(&self) -> (f64, f64) {
        match self {
            Psd::Flat {
                f_low_hz, f_high_hz, ..
            } => (*f_low_hz, *f_high_hz),
            Psd::Table { frequencies_hz, .. } => (
                frequencies_hz.first().copied().unwrap_or(0.0),
                frequencies_hz.last().copied().unwrap_or(0.0),
            ),
        }
    }

    /// Checks the density (messages in the terms of the configuration's keys).
    pub fn validate(&self) -> Result<(), SignalError> {
        match self {
            Psd::Flat {
                rms,
                f_low_hz,
                f_high_hz,
            } => {
                if !(rms.is_finite() && *rms >= 0.0) {
                    return Err(SignalError::Invalid(format!(
                        "rms_acceleration = {rms}: must be finite and ≥ 0"
                    )));
                }
                if !(f_low_hz.is_finite() && *f_low_hz > 0.0 && f_high_hz.is_finite() && f_high_hz > f_low_hz)
                {
                    return Err(SignalError::Invalid(format!(
                        "f_low_hz = {f_low_hz}, f_high_hz = {f_high_hz}: need 0 < f_low_hz < f_high_hz, finite"
                    )));
                }
            }
            Psd::Table {
                frequencies_hz: fs,
                values,
            } => {
                if fs.len() < 2 || fs.len() != values.len() {
                    return Err(SignalError::Invalid(format!(
                        "psd_frequencies_hz and psd_values need the same number of points, at least 2 (got {} and {})",
                        fs.len(),
                        values.len()
                    )));
                }
                if let Some(i) = fs.iter().position(|f| !(f.is_finite() && *f > 0.0)) {
                    return Err(SignalError::Invalid(format!(
                        "psd_frequencies_hz[{i}] = {}: must be finite and > 0",
                        fs[i]
                    )));
                }
                if let Some(i) = fs.windows(2).position(|w| w[1] <= w[0]) {
                    return Err(SignalError::Invalid(format!(
                        "psd_frequencies_hz[{}] = {} after {}: the frequencies must increase strictly",
                        i + 1,
                        fs[i + 1],
                        fs[i]
                    )));
                }
                if let Some(i) = values.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
                    return Err(SignalError::Invalid(format!(
                        "psd_values[{i}] = {}: must be finite and ≥ 0",
                        values[i]
                    )));
                }
            }
        }
        Ok(())
    }
}

/// Random base acceleration: a random-phase multisine of duration D (periodic with period D)
/// whose components sit on the grid f_k = k/D inside the density's band, with amplitudes
/// from the density and phases uniform on [0, 2π) drawn from `seed` and k alone (so the
/// same seed gives the same signal, and a component's phase does not depend on the band).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RandomSpec {
    /// The one-sided PSD of the base acceleration.
    pub psd: Psd,
    /// Seed of the phases.
    pub seed: u64,
    /// Duration D, s (the grid spacing is 1/D).
    pub duration: f64,
}

impl RandomSpec {
    /// The grid indices k (f_k = k/D, k ≥ 1) inside the band.
    fn grid(&self) -> Result<std::ops::RangeInclusive<u64>, SignalError> {
        self.psd.validate()?;
        let d = self.duration;
        if !(d.is_finite() && d > 0.0) {
            return Err(SignalError::Invalid(format!(
                "duration = {d} s: must be finite and > 0"
            )));
        }
        let (lo, hi) = self.psd.band();
        let k0 = (lo * d).ceil().max(1.0);
        let k1 = (hi * d).floor();
        if k1 < k0 {
            return Err(SignalError::Invalid(format!(
                "the band {lo}–{hi} Hz holds no frequency of the grid 1/D = {} Hz: widen it or lengthen the duration",
                1.0 / d
            )));
        }
        if k1 - k0 + 1.0 > MAX_COMPONENTS as f64 {
            return Err(SignalError::TooLarge(format!(
                "the band {lo}–{hi} Hz over {d} s holds {} grid frequencies (at most {MAX_COMPONENTS})",
                k1 - k0 + 1.0
            )));
        }
        Ok(k0 as u64..=k1 as u64)
    }

    /// The acceleration components as (grid index k, amplitude m/s², phase rad):
    /// a(t) = Σ a_k cos(2π k t/D + φ_k).
    pub fn acceleration_components(&self) -> Result<Vec<(u64, f64, f64)>, SignalError> {
        let grid = self.grid()?;
        let count = (grid.end() - grid.start() + 1) as f64;
        let d = self.duration;
        Ok(grid
            .map(|k| {
                let amplitude = match &self.psd {
                    Psd::Flat { rms, .. } => rms * (2.0 / count).sqrt(),
                    table => (2.0 * table.at(k as f64 / d) / d).sqrt(),
                };
                let phase = TAU * SplitMix64::stream(self.seed, &[k]).uniform();
                (k, amplitude, phase)
            })
            .collect())
    }

    /// The exact displacement as harmonics: a_k cos(ω_k t + φ_k) integrated twice is
    /// (a_k/ω_k²) sin(ω_k t + φ_k − π/2) (zero mean, no drift: every component is periodic).
    pub fn displacement_harmonics(&self) -> Result<Vec<Harmonic>, SignalError> {
        let d = self.duration;
        Ok(self
            .acceleration_components()?
            .into_iter()
            .map(|(k, a, phase)| {
                let omega = TAU * k as f64 / d;
                Harmonic {
                    amplitude: a / (omega * omega),
                    omega,
                    phase: phase - FRAC_PI_2,
                }
            })
            .collect())
    }

    /// The displacement harmonics, the number of spline intervals (an FFT-friendly size
    /// with at least 2 per period of the highest component) and M₄ for `relative_tolerance`.
    fn plan(&self, relative_tolerance: f64) -> Result<(Vec<Harmonic>, usize, f64), SignalError> {
        if !(relative_tolerance.is_finite() && relative_tolerance > 0.0) {
            return Err(SignalError::Invalid(format!(
                "spline_tolerance = {relative_tolerance}: must be finite and > 0"
            )));
        }
        let harmonics = self.displacement_harmonics()?;
        let d = self.duration;
        let rms = (harmonics.iter().map(|h| h.amplitude * h.amplitude).sum::<f64>() / 2.0).sqrt();
        let m4 = fourth_derivative_bound(&harmonics);
        let k_max = (harmonics.last().map_or(0.0, |h| h.omega) * d / TAU).round() as usize;
        let wanted = if m4 > 0.0 {
            intervals_for(
                d,
                relative_tolerance * rms,
                m4,
                2 * k_max + 2,
                "the random signal",
            )?
        } else {
            4
        };
        let n = smooth_size(wanted);
        if n > MAX_KNOTS {
            return Err(SignalError::TooLarge(format!(
                "the random signal would need {n} spline knots (at most {MAX_KNOTS})"
            )));
        }
        Ok((harmonics, n, m4))
    }

    /// The number of spline intervals [`to_spline`](Self::to_spline) would use (checks the
    /// parameters without building).
    pub fn intervals_needed(&self, relative_tolerance: f64) -> Result<usize, SignalError> {
        self.plan(relative_tolerance).map(|(_, n, _)| n)
    }

    /// The displacement as degree-7 piecewise polynomials over `[0, D]` within
    /// `relative_tolerance` times the RMS displacement ([`HarmonicPieces`], what the engine
    /// is driven by), and the displacement harmonics they interpolate. Refused before it
    /// starts if it costs more than `budget` allows ([`WorkBudget::check`]: harmonics ×
    /// intervals above [`MAX_PIECE_EVALUATIONS`](super::MAX_PIECE_EVALUATIONS)); stopped by
    /// its stop flag.
    pub fn to_pieces(
        &self,
        relative_tolerance: f64,
        budget: &WorkBudget,
    ) -> Result<(HarmonicPieces, Vec<Harmonic>), SignalError> {
        if !(relative_tolerance.is_finite() && relative_tolerance > 0.0) {
            return Err(SignalError::Invalid(format!(
                "spline_tolerance = {relative_tolerance}: must be finite and > 0"
            )));
        }
        let harmonics = self.displacement_harmonics()?;
        let rms = (harmonics.iter().map(|h| h.amplitude * h.amplitude).sum::<f64>() / 2.0).sqrt();
        // A zero signal needs one interval, whatever the tolerance.
        let tolerance = (relative_tolerance * rms).max(f64::MIN_POSITIVE);
        let pieces = HarmonicPieces::new_within(&harmonics, self.duration, tolerance, budget)?;
        Ok((pieces, harmonics))
    }

    /// The clamped cubic spline of the displacement over `[0, D]` on equal knots, close
    /// enough that its error is at most `relative_tolerance` times the RMS displacement
    /// (bound of [`spline_error_bounds`](super::spline_error_bounds) with M₄ = Σ|A_k|ω_k⁴);
    /// the values at the knots by an inverse FFT (exact up to rounding), the end slopes by
    /// direct summation. Also returns the displacement harmonics and the accuracy.
    pub fn to_spline(
        &self,
        relative_tolerance: f64,
    ) -> Result<(PiecewiseCubic, SplineAccuracy, Vec<Harmonic>), SignalError> {
        let (harmonics, n, m4) = self.plan(relative_tolerance)?;
        let d = self.duration;
        let mut buffer = vec![Complex::new(0.0, 0.0); n];
        for h in &harmonics {
            let k = (h.omega * d / TAU).round() as usize;
            buffer[k] = Complex::from_polar(h.amplitude, h.phase);
        }
        FftPlanner::new().plan_fft_inverse(n).process(&mut buffer);
        let mut values: Vec<f64> = buffer.iter().map(|z| z.im).collect();
        values.push(values[0]); // periodic: y(D) = y(0)
        let times: Vec<f64> = (0..=n).map(|j| d * j as f64 / n as f64).collect();
        let slope = evaluate_sum(&harmonics, 0.0)[1];
        let spline = PiecewiseCubic::interpolate(
            &times,
            &values,
            EndCondition::Clamped {
                start_slope: slope,
                end_slope: slope,
            },
        )?;
        Ok((spline, SplineAccuracy::new(d / n as f64, m4), harmonics))
    }
}

/// The smallest number ≥ `n` whose prime factors are 2, 3 and 5 (a fast FFT size).
fn smooth_size(n: usize) -> usize {
    let mut m = n.max(1);
    loop {
        let mut r = m;
        for p in [2, 3, 5] {
            while r.is_multiple_of(p) {
                r /= p;
            }
        }
        if r == 1 {
            return m;
        }
        m += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn smooth_sizes() {
        assert_eq!(smooth_size(7), 8);
        assert_eq!(smooth_size(11), 12);
        assert_eq!(smooth_size(1001), 1024);
        assert_eq!(smooth_size(961), 972);
    }

    /// The FFT values at the knots equal the direct sum of the harmonics.
    #[test]
    fn fft_values_match_direct_sums() {
        let spec = RandomSpec {
            psd: Psd::Flat {
                rms: 1.0,
                f_low_hz: 2.0,
                f_high_hz: 9.0,
            },
            seed: 3,
            duration: 4.0,
        };
        let (s, _, h) = spec.to_spline(1e-9).unwrap();
        let scale = h.iter().map(|h| h.amplitude).sum::<f64>();
        for (i, &t) in s.knots().iter().enumerate().step_by(37) {
            let direct = evaluate_sum(&h, t)[0];
            assert!((s.displacement(t) - direct).abs() < 1e-13 * scale, "knot {i}");
        }
    }
}
