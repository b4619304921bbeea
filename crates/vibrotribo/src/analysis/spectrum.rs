//! Power spectral density by Welch's method.
//!
//! The signal `x_0 … x_{L−1}`, sampled at `f_s` Hz, is cut into segments of `N` samples that
//! start every `N − ⌊overlap·N⌋` samples (trailing samples that do not fill a segment are
//! not used). Each segment is (optionally) made zero-mean, multiplied by a window `w_n` and
//! transformed, `X_k = Σ_n w_n x_n e^{−2πikn/N}`; the one-sided density at `f_k = k f_s / N`,
//! k = 0, …, ⌊N/2⌋, averaged over the segments, is
//!
//! ```text
//! P_k = c_k |X_k|² / (f_s Σ_n w_n²),    c_k = 1 at k = 0 and at k = N/2 (N even), else 2,
//! ```
//!
//! in units²/Hz. With this scaling `Σ_k P_k Δf` (Δf = f_s/N) equals the mean of
//! `(w_n x_n)² / mean(w²)` over a segment (Parseval), so the integral of the density is the
//! signal's variance and the integral over a spectral peak is the power of that component
//! (`A²/2` for a sinusoid of amplitude A). This is the convention of SciPy's
//! `scipy.signal.welch(..., scaling="density")` with its default periodic Hann window and
//! `detrend="constant"`.

use super::{AnalysisError, Sum, check_finite, check_positive, invalid};
use rustfft::FftPlanner;
use rustfft::num_complex::Complex;

/// Window applied to each segment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Window {
    /// Periodic (DFT-even) Hann window `w_n = ½ (1 − cos(2πn/N))`, n = 0, …, N−1: side lobes
    /// −31 dB falling 18 dB per octave, equivalent noise bandwidth 1.5 bins. The default.
    #[default]
    Hann,
    /// No window (`w_n = 1`): the sharpest main lobe, but −13 dB side lobes that leak the
    /// power of strong peaks across the spectrum.
    Rectangular,
}

impl Window {
    /// The `n` window coefficients.
    pub fn coefficients(self, n: usize) -> Vec<f64> {
        match self {
            Window::Hann => (0..n)
                .map(|j| 0.5 * (1.0 - (std::f64::consts::TAU * j as f64 / n as f64).cos()))
                .collect(),
            Window::Rectangular => vec![1.0; n],
        }
    }

    /// Lower-case name: `hann`, `rectangular`.
    pub fn as_str(self) -> &'static str {
        match self {
            Window::Hann => "hann",
            Window::Rectangular => "rectangular",
        }
    }
}

/// What is removed from each segment before windowing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
#[non_exhaustive]
pub enum Detrend {
    /// Subtract each segment's mean (keeps a large offset from leaking into low frequencies).
    /// The default.
    #[default]
    Mean,
    /// Use the samples as they are; the mean then shows as power at f = 0.
    None,
}

/// Settings of [`welch_psd`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct WelchOptions {
    /// Segment length N, samples (≥ 2, at most the signal length). The frequency resolution
    /// is `f_s/N`. Default 1024.
    pub segment_len: usize,
    /// Fraction of a segment shared with the next, in [0, 1). Default 0.5.
    pub overlap: f64,
    /// Window applied to each segment. Default Hann.
    pub window: Window,
    /// What is removed from each segment first. Default: its mean.
    pub detrend: Detrend,
}

impl Default for WelchOptions {
    fn default() -> Self {
        WelchOptions {
            segment_len: 1024,
            overlap: 0.5,
            window: Window::default(),
            detrend: Detrend::default(),
        }
    }
}

impl WelchOptions {
    /// Checks the options (the segment length against the signal is checked by
    /// [`welch_psd`]).
    pub fn validate(&self) -> Result<(), AnalysisError> {
        if self.segment_len < 2 {
            return Err(invalid(
                "segment_len",
                self.segment_len as f64,
                "must be at least 2",
            ));
        }
        let o = self.overlap;
        if !o.is_finite() || !(0.0..1.0).contains(&o) {
            return Err(invalid("overlap", o, "must lie in [0, 1)"));
        }
        Ok(())
    }

    /// The options for a record of `len` samples that sets no segment length of its own
    /// (a run's positions after its transient): segments of a power of two near a quarter of
    /// the record, at least 16 samples, at most half the record's next power of two and never
    /// longer than the record, so that several overlapping segments are averaged; Hann
    /// window, half overlap, each segment's mean removed. A record shorter than 2 samples
    /// gives a segment [`welch_psd`] refuses.
    pub fn for_record(len: usize) -> Self {
        let segment = (len / 4)
            .next_power_of_two()
            .min(len.next_power_of_two() / 2)
            .max(16);
        WelchOptions {
            segment_len: segment.min(len),
            ..WelchOptions::default()
        }
    }

    /// Samples between the starts of consecutive segments, `N − ⌊overlap·N⌋` (≥ 1).
    pub fn step(&self) -> usize {
        let shared = (self.overlap * self.segment_len as f64).floor() as usize;
        self.segment_len.saturating_sub(shared).max(1)
    }
}

/// A one-sided power spectral density.
#[derive(Debug, Clone, PartialEq)]
pub struct Psd {
    /// Frequencies `f_k = k f_s / N`, k = 0, …, ⌊N/2⌋, Hz.
    pub frequencies: Vec<f64>,
    /// Density at each frequency, (signal unit)²/Hz.
    pub density: Vec<f64>,
    /// Bin spacing (frequency resolution) `f_s/N`, Hz.
    pub resolution: f64,
    /// Equivalent noise bandwidth of the window, `f_s Σw² / (Σw)²`, Hz: the width over which a
    /// pure tone's power is spread at its peak (1.5 bins for Hann).
    pub noise_bandwidth: f64,
    /// Sampling rate f_s, Hz.
    pub sample_rate: f64,
    /// Segment length N, samples.
    pub segment_len: usize,
    /// Number of segments averaged.
    pub segments: usize,
    /// Window used.
    pub window: Window,
    /// Detrending used.
    pub detrend: Detrend,
}

impl Psd {
    /// Power in `[f_lo, f_hi]`, unit²: `Σ P_k Δf` over the bins with `f_lo ≤ f_k ≤ f_hi`.
    /// Over all bins it is the signal's (windowed) mean square.
    pub fn band_power(&self, f_lo: f64, f_hi: f64) -> f64 {
        let mut sum = Sum::default();
        for (f, p) in self.frequencies.iter().zip(&self.density) {
            if *f >= f_lo && *f <= f_hi {
                sum.add(*p);
            }
        }
        sum.value() * self.resolution
    }

    /// Total power `Σ P_k Δf`, unit² (the variance when segments are made zero-mean).
    pub fn total_power(&self) -> f64 {
        self.band_power(f64::NEG_INFINITY, f64::INFINITY)
    }

    /// The bin of largest density above `f_min`, Hz, as (frequency Hz, density unit²/Hz).
    pub fn peak_above(&self, f_min: f64) -> Option<(f64, f64)> {
        self.frequencies
            .iter()
            .zip(&self.density)
            .filter(|(f, _)| **f >= f_min)
            .max_by(|a, b| a.1.total_cmp(b.1))
            .map(|(f, p)| (*f, *p))
    }
}

/// One-sided PSD of `signal`, sampled at `sample_rate` Hz, by Welch's method (see the module
/// docs for the definition and scaling).
///
/// ```
/// use vibrotribo::analysis::{WelchOptions, welch_psd};
///
/// let fs = 100.0;
/// let x: Vec<f64> = (0..4096).map(|n| (std::f64::consts::TAU * 12.5 * n as f64 / fs).sin()).collect();
/// let psd = welch_psd(&x, fs, &WelchOptions { segment_len: 256, ..Default::default() })?;
/// let (f, _) = psd.peak_above(0.0).unwrap();
/// assert!((f - 12.5).abs() <= psd.resolution);
/// assert!((psd.band_power(10.0, 15.0) - 0.5).abs() < 1e-3); // A²/2
/// # Ok::<(), vibrotribo::analysis::AnalysisError>(())
/// ```
pub fn welch_psd(signal: &[f64], sample_rate: f64, options: &WelchOptions) -> Result<Psd, AnalysisError> {
    options.validate()?;
    check_positive("sample_rate", sample_rate)?;
    if signal.is_empty() {
        return Err(AnalysisError::Empty { what: "signal" });
    }
    let n = options.segment_len;
    if signal.len() < n {
        return Err(AnalysisError::TooShort {
            what: "signal",
            needed: n,
            got: signal.len(),
        });
    }
    check_finite("signal", signal, 0)?;

    let window = options.window.coefficients(n);
    let s1: f64 = window.iter().sum();
    let s2: f64 = window.iter().map(|w| w * w).sum();
    let step = options.step();
    let bins = n / 2 + 1;

    let fft = FftPlanner::<f64>::new().plan_fft_forward(n);
    let mut buffer = vec![Complex::new(0.0, 0.0); n];
    let mut scratch = vec![Complex::new(0.0, 0.0); fft.get_inplace_scratch_len()];
    let mut acc = vec![0.0; bins];
    let mut segments = 0;
    let mut start = 0;
    while start + n <= signal.len() {
        let seg = &signal[start..start + n];
        let mean = match options.detrend {
            Detrend::Mean => seg.iter().sum::<f64>() / n as f64,
            Detrend::None => 0.0,
        };
        for ((b, &x), &w) in buffer.iter_mut().zip(seg).zip(&window) {
            *b = Complex::new((x - mean) * w, 0.0);
        }
        fft.process_with_scratch(&mut buffer, &mut scratch);
        for (a, b) in acc.iter_mut().zip(&buffer) {
            *a += b.norm_sqr();
        }
        segments += 1;
        start += step;
    }

    let norm = 1.0 / (sample_rate * s2 * segments as f64);
    let density = acc
        .iter()
        .enumerate()
        .map(|(k, &a)| {
            let one_sided = if k == 0 || 2 * k == n { 1.0 } else { 2.0 };
            one_sided * a * norm
        })
        .collect();
    let resolution = sample_rate / n as f64;
    Ok(Psd {
        frequencies: (0..bins).map(|k| k as f64 * resolution).collect(),
        density,
        resolution,
        noise_bandwidth: sample_rate * s2 / (s1 * s1),
        sample_rate,
        segment_len: n,
        segments,
        window: options.window,
        detrend: options.detrend,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::TAU;

    fn sines(fs: f64, len: usize, parts: &[(f64, f64, f64)]) -> Vec<f64> {
        (0..len)
            .map(|n| {
                let t = n as f64 / fs;
                parts.iter().map(|&(a, f, ph)| a * (TAU * f * t + ph).sin()).sum()
            })
            .collect()
    }

    #[test]
    fn a_records_options_resolve_its_tone_and_average_segments() {
        // Segment lengths by the rule: a power of two near a quarter of the record.
        let lengths = [(4096, 1024), (5000, 2048), (100, 32), (20, 16), (10, 10), (1, 1)];
        for (len, segment) in lengths {
            assert_eq!(
                WelchOptions::for_record(len).segment_len,
                segment,
                "record of {len}"
            );
        }
        // A tone of amplitude 0.3 at 12.5 Hz: its peak within a bin, its power A²/2
        // (Parseval), several segments averaged.
        let (fs, len) = (100.0, 3000);
        let x = sines(fs, len, &[(0.3, 12.5, 0.4)]);
        let psd = welch_psd(&x, fs, &WelchOptions::for_record(len)).unwrap();
        assert!(psd.segments >= 4, "{} segments", psd.segments);
        let (f, _) = psd.peak_above(0.0).unwrap();
        assert!((f - 12.5).abs() <= psd.resolution, "peak at {f} Hz");
        assert_relative_eq!(psd.band_power(10.0, 15.0), 0.045, max_relative = 2e-2);
        // Too short a record is refused by the estimate, not by the rule.
        assert!(welch_psd(&[1.0], fs, &WelchOptions::for_record(1)).is_err());
    }

    /// Fixed-seed standard normal samples (LCG + Box–Muller).
    fn gaussian(len: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        let mut uniform = move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (0..len)
            .map(|_| {
                let (u, v) = (uniform(), uniform());
                (-2.0 * u.ln()).sqrt() * (TAU * v).cos()
            })
            .collect()
    }

    #[test]
    fn bin_centred_tone_has_the_closed_form_hann_spectrum() {
        // A tone on bin k0 of a periodic Hann window: |X_{k0}| = A N/4 and |X_{k0±1}| = A N/8,
        // zero elsewhere, so P_{k0} = A² N/(3 f_s) and P_{k0±1} = A² N/(12 f_s).
        let (fs, n, k0, a) = (512.0, 256usize, 40usize, 1.7);
        let f0 = k0 as f64 * fs / n as f64;
        let x = sines(fs, 4 * n, &[(a, f0, 0.3)]);
        let opts = WelchOptions {
            segment_len: n,
            ..Default::default()
        };
        let psd = welch_psd(&x, fs, &opts).unwrap();
        assert_eq!(psd.segments, 7, "4N samples, step N/2");
        assert_eq!(psd.frequencies.len(), n / 2 + 1);
        assert_relative_eq!(psd.resolution, 2.0, max_relative = 1e-15);
        assert_relative_eq!(psd.noise_bandwidth, 1.5 * psd.resolution, max_relative = 1e-12);
        let nf = n as f64;
        assert_relative_eq!(psd.density[k0], a * a * nf / (3.0 * fs), max_relative = 1e-10);
        assert_relative_eq!(
            psd.density[k0 - 1],
            a * a * nf / (12.0 * fs),
            max_relative = 1e-10
        );
        assert_relative_eq!(
            psd.density[k0 + 1],
            a * a * nf / (12.0 * fs),
            max_relative = 1e-10
        );
        let leak: f64 = psd
            .density
            .iter()
            .enumerate()
            .filter(|(k, _)| k.abs_diff(k0) > 1)
            .map(|(_, p)| p)
            .sum();
        assert!(leak < 1e-20 * psd.density[k0], "leakage {leak}");
        // The three bins hold exactly the tone's power A²/2.
        assert_relative_eq!(psd.total_power(), a * a / 2.0, max_relative = 1e-12);
    }

    #[test]
    fn sum_of_sines_gives_peaks_with_the_right_powers() {
        // Off-bin tones: the peak power is spread over the main lobe and side lobes;
        // integrating ±6 bins around each recovers A²/2 to the Hann side-lobe leakage.
        let fs = 1000.0;
        let parts = [(2.0, 50.3, 0.1), (0.5, 123.4, 1.0), (0.1, 310.77, 2.0)];
        let x = sines(fs, 20_000, &parts);
        let psd = welch_psd(&x, fs, &WelchOptions::default()).unwrap();
        let df = psd.resolution;
        for &(a, f, _) in &parts {
            let local = psd
                .frequencies
                .iter()
                .zip(&psd.density)
                .filter(|(g, _)| (**g - f).abs() <= 3.0 * df)
                .max_by(|p, q| p.1.total_cmp(q.1))
                .unwrap();
            assert!(
                (local.0 - f).abs() <= df / 2.0 + 1e-12,
                "peak near {f} Hz found at {} Hz (resolution {df} Hz)",
                local.0
            );
            let power = psd.band_power(f - 6.0 * df, f + 6.0 * df);
            assert!(
                (power - a * a / 2.0).abs() <= 1e-4 * a * a / 2.0,
                "tone {a} at {f} Hz: band power {power}, expected {}",
                a * a / 2.0
            );
        }
        // The largest peak overall is the strongest tone.
        let (f_max, _) = psd.peak_above(0.0).unwrap();
        assert!((f_max - 50.3).abs() <= df);
    }

    #[test]
    fn parseval_exact_for_a_single_rectangular_segment() {
        // One segment, no window, no detrending: Σ P_k Δf is exactly the mean square.
        let x: Vec<f64> = gaussian(1000, 9).iter().map(|v| 0.3 + 2.0 * v).collect();
        for n in [1000usize, 999] {
            let opts = WelchOptions {
                segment_len: n,
                overlap: 0.0,
                window: Window::Rectangular,
                detrend: Detrend::None,
            };
            let psd = welch_psd(&x[..n], 50.0, &opts).unwrap();
            let mean_square = x[..n].iter().map(|v| v * v).sum::<f64>() / n as f64;
            assert_eq!(psd.segments, 1);
            assert_relative_eq!(psd.total_power(), mean_square, max_relative = 1e-12);
            // And the DC bin holds the mean²: P_0 Δf = mean².
            let mean = x[..n].iter().sum::<f64>() / n as f64;
            assert_relative_eq!(psd.density[0] * psd.resolution, mean * mean, max_relative = 1e-10);
        }
    }

    #[test]
    fn parseval_welch_integral_is_the_variance() {
        // Coloured noise plus a tone and an offset: with per-segment mean removal and the Hann
        // window, ∫PSD df estimates the variance; 2^17 samples in 255 half-overlapping
        // segments bring the statistical error well below 0.5 %.
        let fs = 200.0;
        let w = gaussian(1 << 17, 42);
        let x: Vec<f64> = (0..w.len())
            .map(|n| {
                let smooth = if n > 0 { 0.5 * (w[n] + w[n - 1]) } else { w[n] };
                5.0 + smooth + 0.8 * (TAU * 17.0 * n as f64 / fs).sin()
            })
            .collect();
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / x.len() as f64;
        let psd = welch_psd(&x, fs, &WelchOptions::default()).unwrap();
        assert_eq!(psd.segments, 255);
        let total = psd.total_power();
        assert!(
            (total - var).abs() < 0.005 * var,
            "∫PSD = {total}, variance = {var}"
        );
        // The closed-form variance: smoothed unit noise 0.5, tone 0.32.
        assert!((var - 0.82).abs() < 0.01, "variance {var}");
        // The noise floor of the two-tap average is (1 + cos 2πf/fs)/fs per Hz (one-sided):
        // check it away from the tone at 60 Hz.
        let k = (60.0 / psd.resolution).round() as usize;
        let f = psd.frequencies[k];
        let expected = (1.0 + (TAU * f / fs).cos()) / fs;
        let avg: f64 = psd.density[k - 5..=k + 5].iter().sum::<f64>() / 11.0;
        assert!(
            (avg - expected).abs() < 0.1 * expected,
            "floor {avg} vs {expected}"
        );
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let opts = WelchOptions {
            segment_len: 8,
            ..Default::default()
        };
        assert!(matches!(
            welch_psd(&[], 1.0, &opts),
            Err(AnalysisError::Empty { .. })
        ));
        assert!(matches!(
            welch_psd(&[1.0; 7], 1.0, &opts),
            Err(AnalysisError::TooShort {
                needed: 8,
                got: 7,
                ..
            })
        ));
        assert!(matches!(
            welch_psd(&[1.0, f64::NAN, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0], 1.0, &opts),
            Err(AnalysisError::NonFinite { index: 1, .. })
        ));
        assert!(welch_psd(&[1.0; 8], 0.0, &opts).is_err());
        assert!(welch_psd(&[1.0; 8], f64::INFINITY, &opts).is_err());
        for bad in [
            WelchOptions {
                segment_len: 1,
                ..Default::default()
            },
            WelchOptions {
                segment_len: 8,
                overlap: 1.0,
                ..Default::default()
            },
            WelchOptions {
                segment_len: 8,
                overlap: f64::NAN,
                ..Default::default()
            },
        ] {
            assert!(welch_psd(&[1.0; 16], 1.0, &bad).is_err(), "{bad:?}");
        }
        // A constant signal with mean removal has zero density everywhere.
        let psd = welch_psd(&[3.0; 16], 1.0, &opts).unwrap();
        assert!(psd.density.iter().all(|p| p.abs() < 1e-28));
    }
}
