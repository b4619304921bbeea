//! Frequency response: the peak of power against frequency and its half-power bandwidth,
//! over the branches of up and down sweeps (or continuation) taken together.
//!
//! The response at each frequency is the largest power any branch reaches there (the
//! envelope a designer can hope for when the device may sit on any coexisting orbit), each
//! branch interpolated linearly between its own samples; the peak is the envelope's largest
//! sample, and the half-power band is the interval around it where the envelope stays at or
//! above half the peak, its edges interpolated linearly between samples. Frequencies are in the caller's unit (Ω, or Hz for the centre frequency of a
//! random input's band).

use super::AnalysisError;

/// The peak and half-power bandwidth of a frequency response.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Bandwidth {
    /// Frequency of the peak.
    pub peak_frequency: f64,
    /// Power at the peak, W.
    pub peak_power: f64,
    /// Lower edge of the half-power band (`None` where the response is still above half the
    /// peak at the lowest frequency).
    pub lower: Option<f64>,
    /// Upper edge (`None` where it is above half the peak at the highest frequency).
    pub upper: Option<f64>,
}

impl Bandwidth {
    /// Width of the half-power band (`None` where an edge lies outside the frequencies).
    pub fn width(&self) -> Option<f64> {
        Some(self.upper? - self.lower?)
    }
}

/// The envelope of the `branches`, each a list of `(frequency, power)` samples in order
/// along the branch: at every frequency any branch has a sample at (sorted, each once), the
/// largest power of any branch there, a branch counting wherever a pair of its consecutive
/// samples spans the frequency (its power interpolated linearly between them). Branches
/// sampled on different frequencies (sweeps on a grid, continuation points between) thus
/// combine without a branch dropping out between its own samples. A non-finite power breaks
/// its branch there; a branch may fold back in frequency.
pub fn envelope(branches: &[&[(f64, f64)]]) -> Result<Vec<(f64, f64)>, AnalysisError> {
    let mut frequencies: Vec<f64> = Vec::new();
    for b in branches {
        for (i, &(f, p)) in b.iter().enumerate() {
            if !f.is_finite() {
                return Err(AnalysisError::NonFinite {
                    what: "frequencies",
                    index: i,
                    value: f,
                });
            }
            if p.is_finite() {
                frequencies.push(f);
            }
        }
    }
    if frequencies.is_empty() {
        return Err(AnalysisError::Empty {
            what: "frequency response",
        });
    }
    frequencies.sort_by(f64::total_cmp);
    frequencies.dedup();
    let mut out: Vec<(f64, f64)> = frequencies.iter().map(|&f| (f, f64::NEG_INFINITY)).collect();
    let raise = |out: &mut Vec<(f64, f64)>, k: usize, p: f64| out[k].1 = out[k].1.max(p);
    let index = |f: f64| frequencies.partition_point(|&x| x < f);
    for b in branches {
        for (&(f, p), k) in b.iter().zip(0..) {
            if p.is_finite() {
                raise(&mut out, index(f), p);
            }
            let Some(&(g, q)) = b.get(k + 1) else {
                continue;
            };
            if !(p.is_finite() && q.is_finite()) || f == g {
                continue;
            }
            let (lo, hi) = (f.min(g), f.max(g));
            let (first, end) = (index(lo), index(hi));
            for (j, &x) in frequencies[first..end].iter().enumerate() {
                if x > lo {
                    raise(&mut out, first + j, p + (q - p) * (x - f) / (g - f));
                }
            }
        }
    }
    Ok(out)
}

/// The peak and half-power band of the envelope of `branches` ([`envelope`]).
pub fn half_power_bandwidth(branches: &[&[(f64, f64)]]) -> Result<Bandwidth, AnalysisError> {
    let env = envelope(branches)?;
    let (k, &(peak_frequency, peak_power)) = env
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.1.total_cmp(&b.1.1))
        .ok_or(AnalysisError::Empty {
            what: "frequency response",
        })?;
    let half = 0.5 * peak_power;
    let crossing = |a: (f64, f64), b: (f64, f64)| a.0 + (half - a.1) * (b.0 - a.0) / (b.1 - a.1);
    let lower = (0..k)
        .rev()
        .find(|&i| env[i].1 < half)
        .map(|i| crossing(env[i], env[i + 1]));
    let upper = (k + 1..env.len())
        .find(|&i| env[i].1 < half)
        .map(|i| crossing(env[i - 1], env[i]));
    Ok(Bandwidth {
        peak_frequency,
        peak_power,
        lower,
        upper,
    })
}
