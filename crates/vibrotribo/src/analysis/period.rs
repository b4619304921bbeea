//! Period of a stroboscopic series.
//!
//! A series of samples `s_j ∈ ℝᴰ` (e.g. the N positions of a [`StroboscopicSection`]
//! sample) has period p when `s_j = s_{j−p}`. Numerically, [`detect_period`] looks at the
//! last `W + P` samples, with `P = max_period` and `W = repeats · P`, and measures for each
//! candidate p = 1, …, P the mismatch
//!
//! ```text
//! e(p) = max_{j in the last W samples} max_d |s_{j,d} − s_{j−p,d}| / scale,
//! scale = max_{j,d} |s_{j,d}|   (over the last W + P samples)
//! ```
//!
//! and returns the smallest p with `e(p) ≤ tolerance`. Every candidate is checked on the same
//! W comparisons, so a short period must hold over as long a stretch as a long one. The
//! scale is the series' amplitude (its largest magnitude), so the tolerance is relative to
//! the size of the motion, and a period-1 series (whose samples barely differ) is judged
//! against its size, not against its noise. The components should share a unit (positions,
//! say). For series that hover near zero, give a reference scale in
//! [`PeriodOptions::scale`] (the gap δ₁, say).
//!
//! A quasi-periodic orbit whose rotation number is within `tolerance` of a rational m/p with
//! p ≤ P is reported as period p: the test cannot tell them apart on a finite series.
//!
//! [`StroboscopicSection`]: super::StroboscopicSection

use super::{AnalysisError, check_finite, check_positive, invalid};

/// Settings of [`detect_period`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PeriodOptions {
    /// Largest period tested P, in samples (excitation periods for a stroboscopic series).
    /// Default 64.
    pub max_period: usize,
    /// Relative tolerance on the mismatch, as a fraction of the series' peak-to-peak range.
    /// Default 1e-4.
    pub tolerance: f64,
    /// Each candidate is checked on `repeats · max_period` trailing samples. Default 3, so
    /// the default test reads the last 256 samples.
    pub repeats: usize,
    /// Magnitude the tolerance is relative to, in the series' unit (m for positions).
    /// Default `None`: the series' amplitude, the largest |s_{j,d}| over the samples read.
    pub scale: Option<f64>,
}

impl Default for PeriodOptions {
    fn default() -> Self {
        PeriodOptions {
            max_period: 64,
            tolerance: 1e-4,
            repeats: 3,
            scale: None,
        }
    }
}

impl PeriodOptions {
    /// Checks the options.
    pub fn validate(&self) -> Result<(), AnalysisError> {
        if self.max_period == 0 {
            return Err(invalid("max_period", 0.0, "must be positive"));
        }
        if self.repeats == 0 {
            return Err(invalid("repeats", 0.0, "must be positive"));
        }
        let tol = self.tolerance;
        if !tol.is_finite() || !(0.0..1.0).contains(&tol) {
            return Err(invalid("tolerance", tol, "must lie in [0, 1)"));
        }
        if let Some(scale) = self.scale {
            check_positive("scale", scale)?;
        }
        Ok(())
    }

    /// Number of trailing samples the test reads: `(repeats + 1) · max_period`.
    pub fn samples_needed(&self) -> usize {
        self.repeats.saturating_add(1).saturating_mul(self.max_period)
    }
}

/// Verdict of [`detect_period`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Periodicity {
    /// The series repeats with `period` samples (the smallest such period).
    Periodic {
        /// Period, in samples (≥ 1).
        period: usize,
        /// Its relative mismatch e(p) (≤ the tolerance).
        mismatch: f64,
    },
    /// No period up to `max_period` fits within the tolerance.
    NonPeriodic {
        /// The candidate period that came closest.
        closest_period: usize,
        /// Its relative mismatch e(p) (> the tolerance).
        mismatch: f64,
    },
}

impl Periodicity {
    /// The period, if periodic.
    pub fn period(&self) -> Option<usize> {
        match *self {
            Periodicity::Periodic { period, .. } => Some(period),
            Periodicity::NonPeriodic { .. } => None,
        }
    }
}

/// Smallest period of the tail of a `dim`-dimensional series (see the module docs).
///
/// `samples` is row-major: sample j occupies `samples[j·dim .. (j+1)·dim]` (the layout of
/// [`StroboscopicSection::positions`](super::StroboscopicSection::positions)). Only the last
/// [`PeriodOptions::samples_needed`] samples are read; they must be finite.
///
/// ```
/// use vibrotribo::analysis::{PeriodOptions, detect_period};
///
/// // Logistic map at r = 3.2: a stable period-2 orbit.
/// let mut x = 0.3;
/// let series: Vec<f64> = (0..1000).map(|_| { x = 3.2 * x * (1.0 - x); x }).collect();
/// let verdict = detect_period(&series, 1, &PeriodOptions::default())?;
/// assert_eq!(verdict.period(), Some(2));
/// # Ok::<(), vibrotribo::analysis::AnalysisError>(())
/// ```
pub fn detect_period(
    samples: &[f64],
    dim: usize,
    options: &PeriodOptions,
) -> Result<Periodicity, AnalysisError> {
    options.validate()?;
    if dim == 0 {
        return Err(invalid("dim", 0.0, "must be positive"));
    }
    if samples.is_empty() {
        return Err(AnalysisError::Empty { what: "series" });
    }
    if !samples.len().is_multiple_of(dim) {
        return Err(AnalysisError::LengthMismatch {
            what: "series length as a multiple of its dimension",
            expected: samples.len() / dim * dim,
            got: samples.len(),
        });
    }
    let count = samples.len() / dim;
    let needed = options.samples_needed();
    if count < needed {
        return Err(AnalysisError::TooShort {
            what: "series",
            needed,
            got: count,
        });
    }
    let tail_start = (count - needed) * dim;
    let tail = &samples[tail_start..];
    check_finite("series", tail, tail_start)?;

    let scale = options
        .scale
        .unwrap_or_else(|| tail.iter().fold(0.0f64, |m, v| m.max(v.abs())));
    if scale == 0.0 {
        // All samples read are exactly zero.
        return Ok(Periodicity::Periodic {
            period: 1,
            mismatch: 0.0,
        });
    }

    let row = |j: usize| &tail[j * dim..(j + 1) * dim];
    let compared = options.repeats * options.max_period;
    let mut closest = (0, f64::INFINITY);
    for p in 1..=options.max_period {
        let mut worst = 0.0f64;
        for j in needed - compared..needed {
            let (now, then) = (row(j), row(j - p));
            for d in 0..dim {
                worst = worst.max((now[d] - then[d]).abs());
            }
        }
        let mismatch = worst / scale;
        if mismatch <= options.tolerance {
            return Ok(Periodicity::Periodic { period: p, mismatch });
        }
        if mismatch < closest.1 {
            closest = (p, mismatch);
        }
    }
    Ok(Periodicity::NonPeriodic {
        closest_period: closest.0,
        mismatch: closest.1,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed-seed generator (64-bit LCG, Knuth's constants), uniform in [0, 1).
    struct Lcg(u64);

    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// A `dim`-dimensional period-p series of `len` samples: random values on each phase,
    /// plus uniform noise of relative amplitude `noise`.
    fn periodic_series(p: usize, dim: usize, len: usize, noise: f64, seed: u64) -> Vec<f64> {
        let mut rng = Lcg(seed);
        let cycle: Vec<f64> = (0..p * dim).map(|_| rng.next()).collect();
        (0..len * dim)
            .map(|idx| {
                let (j, d) = (idx / dim, idx % dim);
                cycle[(j % p) * dim + d] + noise * (2.0 * rng.next() - 1.0)
            })
            .collect()
    }

    fn logistic(r: f64, skip: usize, len: usize) -> Vec<f64> {
        let mut x = 0.123;
        for _ in 0..skip {
            x = r * x * (1.0 - x);
        }
        (0..len)
            .map(|_| {
                x = r * x * (1.0 - x);
                x
            })
            .collect()
    }

    #[test]
    fn finds_constructed_periods_under_small_noise() {
        let opts = PeriodOptions::default();
        for (k, &p) in [1usize, 2, 3, 8, 13].iter().enumerate() {
            for dim in [1, 3] {
                let s = periodic_series(p, dim, 400, 1e-7, 17 + k as u64);
                let got = detect_period(&s, dim, &opts).unwrap();
                assert_eq!(got.period(), Some(p), "period {p}, dim {dim}: {got:?}");
            }
        }
    }

    #[test]
    fn noise_above_the_tolerance_is_not_periodic() {
        // Noise of ±1e-3 of a unit-range series: differences reach ~2e-3 ≫ 1e-4.
        let s = periodic_series(8, 3, 400, 1e-3, 5);
        let got = detect_period(&s, 3, &PeriodOptions::default()).unwrap();
        assert!(got.period().is_none(), "{got:?}");
        // With a tolerance above the noise the period is found again.
        let loose = PeriodOptions {
            tolerance: 5e-3,
            ..Default::default()
        };
        assert_eq!(detect_period(&s, 3, &loose).unwrap().period(), Some(8));
    }

    #[test]
    fn a_period_is_reported_at_its_smallest() {
        // Period 4 whose second half repeats the first: really period 2.
        let s: Vec<f64> = (0..300).map(|j| [0.1, 0.7][j % 2]).collect();
        assert_eq!(
            detect_period(&s, 1, &PeriodOptions::default()).unwrap().period(),
            Some(2)
        );
        // Constant (also all zero, with no amplitude to scale by): period 1, zero mismatch.
        for value in [0.25, 0.0] {
            let c = vec![value; 300];
            assert_eq!(
                detect_period(&c, 1, &PeriodOptions::default()).unwrap(),
                Periodicity::Periodic {
                    period: 1,
                    mismatch: 0.0
                }
            );
        }
    }

    #[test]
    fn tolerance_is_relative_to_the_amplitude_or_to_a_given_scale() {
        // A period-2 motion of ±1 µm with 1 nm noise: against its own amplitude the noise is
        // 1e-3, above the default tolerance; against a 20 mm gap it is 5e-8, far below.
        let mut rng = Lcg(11);
        let s: Vec<f64> = (0..300)
            .map(|j| [1e-6, -1e-6][j % 2] + 1e-9 * (2.0 * rng.next() - 1.0))
            .collect();
        let own = detect_period(&s, 1, &PeriodOptions::default()).unwrap();
        assert!(own.period().is_none(), "{own:?}");
        let gap = PeriodOptions {
            scale: Some(0.02),
            ..Default::default()
        };
        assert_eq!(detect_period(&s, 1, &gap).unwrap().period(), Some(2));
        // Period 1 with small noise is judged against its size, not its (tiny) spread.
        let one: Vec<f64> = (0..300).map(|_| 0.05 + 1e-8 * (2.0 * rng.next() - 1.0)).collect();
        match detect_period(&one, 1, &PeriodOptions::default()).unwrap() {
            Periodicity::Periodic { period: 1, mismatch } => assert!(mismatch <= 2e-8 / 0.05 + 1e-12),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn only_the_tail_counts() {
        // A transient of noise followed by a clean period-3 tail of exactly 256 samples.
        let mut s = periodic_series(7, 1, 500, 0.5, 3);
        s.extend((0..256).map(|j| [0.2, 0.5, 0.9][j % 3]));
        assert_eq!(
            detect_period(&s, 1, &PeriodOptions::default()).unwrap().period(),
            Some(3)
        );
    }

    #[test]
    fn logistic_map_periodic_windows_and_closed_form_orbit() {
        let opts = PeriodOptions::default();
        // r = 3.2: the 2-cycle x± = ((r+1) ± √((r−3)(r+1))) / 2r.
        let r: f64 = 3.2;
        let s = logistic(r, 5000, 400);
        assert_eq!(detect_period(&s, 1, &opts).unwrap().period(), Some(2));
        let root = ((r - 3.0) * (r + 1.0)).sqrt();
        let (hi, lo) = ((r + 1.0 + root) / (2.0 * r), (r + 1.0 - root) / (2.0 * r));
        let last = &s[s.len() - 2..];
        let (a, b) = (last[0].max(last[1]), last[0].min(last[1]));
        assert!(
            (a - hi).abs() < 1e-12 && (b - lo).abs() < 1e-12,
            "{last:?} vs {hi}, {lo}"
        );
        // r = 3.5: period 4 (between the 4- and 8-cycle doublings at 3.449 and 3.544).
        assert_eq!(
            detect_period(&logistic(3.5, 5000, 400), 1, &opts)
                .unwrap()
                .period(),
            Some(4)
        );
        // r = 3.83: the period-3 window opening at 1 + √8 ≈ 3.8284.
        assert_eq!(
            detect_period(&logistic(3.83, 20000, 400), 1, &opts)
                .unwrap()
                .period(),
            Some(3)
        );
    }

    #[test]
    fn chaotic_logistic_map_is_not_periodic() {
        for r in [3.7, 3.9, 4.0] {
            let s = logistic(r, 1000, 1000);
            let got = detect_period(&s, 1, &PeriodOptions::default()).unwrap();
            assert!(got.period().is_none(), "r = {r}: {got:?}");
        }
    }

    #[test]
    fn quasi_periodic_series_is_not_periodic() {
        // Two incommensurate rotations: golden mean α and √2 − 1. No p ≤ 64 brings pα within
        // 8.1e-3 of an integer (best: 55α ≈ 34), so every candidate leaves a relative
        // mismatch of order 1e-2, two orders above the tolerance.
        let alpha = (5f64.sqrt() - 1.0) / 2.0;
        let beta = 2f64.sqrt() - 1.0;
        let tau = std::f64::consts::TAU;
        let s: Vec<f64> = (0..600)
            .flat_map(|j| {
                let j = j as f64;
                [
                    (tau * alpha * j).sin() + 0.5 * (tau * beta * j).sin(),
                    (tau * alpha * j).cos(),
                ]
            })
            .collect();
        match detect_period(&s, 2, &PeriodOptions::default()).unwrap() {
            Periodicity::NonPeriodic { mismatch, .. } => assert!(mismatch > 1e-3, "mismatch {mismatch}"),
            other => panic!("quasi-periodic series called {other:?}"),
        }
        // A single rotation by the golden mean is also caught: its nearest return within 64
        // samples (p = 55) is off by 2π·|55α − 34| ≈ 0.051 rad.
        let one: Vec<f64> = (0..600).map(|j| (tau * alpha * j as f64).sin()).collect();
        let got = detect_period(&one, 1, &PeriodOptions::default()).unwrap();
        assert!(got.period().is_none(), "{got:?}");
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let opts = PeriodOptions::default();
        assert!(matches!(
            detect_period(&[], 1, &opts),
            Err(AnalysisError::Empty { .. })
        ));
        assert!(matches!(
            detect_period(&[1.0; 100], 1, &opts),
            Err(AnalysisError::TooShort {
                needed: 256,
                got: 100,
                ..
            })
        ));
        assert!(matches!(
            detect_period(&[1.0; 301], 3, &opts),
            Err(AnalysisError::LengthMismatch { .. })
        ));
        assert!(detect_period(&[1.0; 300], 0, &opts).is_err());
        let mut s = vec![1.0; 300];
        s[290] = f64::NAN;
        assert!(matches!(
            detect_period(&s, 1, &opts),
            Err(AnalysisError::NonFinite { index: 290, .. })
        ));
        // A NaN in the unread transient is ignored.
        s[290] = 1.0;
        s[3] = f64::NAN;
        assert_eq!(detect_period(&s, 1, &opts).unwrap().period(), Some(1));
        for bad in [
            PeriodOptions {
                max_period: 0,
                ..Default::default()
            },
            PeriodOptions {
                repeats: 0,
                ..Default::default()
            },
            PeriodOptions {
                tolerance: f64::NAN,
                ..Default::default()
            },
            PeriodOptions {
                tolerance: -1.0,
                ..Default::default()
            },
            PeriodOptions {
                scale: Some(0.0),
                ..Default::default()
            },
            PeriodOptions {
                scale: Some(f64::NAN),
                ..Default::default()
            },
        ] {
            assert!(detect_period(&[1.0; 300], 1, &bad).is_err(), "{bad:?}");
        }
    }
}
