//! Whether a stroboscopic series has settled, and how fast it is settling.
//!
//! A series `s_j ∈ ℝᴰ` converging onto a periodic orbit of period p has return distances
//!
//! ```text
//! d_j = ‖s_j − s_{j−p}‖₂ / scale
//! ```
//!
//! that shrink geometrically, `d_j ≈ d_0 · r^j`, where r is the modulus of the slowest
//! Floquet multiplier taken to the power 1/p (for a linear chain without contacts, the slowest
//! mode's decay over one excitation period, `exp(−ζωₙT)`). [`fit_convergence`] fits
//! `ln d_j` by least squares against j and reports the rate r, the slope's standard error,
//! and how many more periods it takes to bring the distance down to a tolerance.
//!
//! Two further functions read a finite window of a motion that is not periodic:
//! [`closed_curve_ratio`] tells a section that lies on a closed curve (the section of a
//! two-torus, quasi-periodic motion) from a cloud, and [`batch_means_se`] gives the
//! standard error of the mean of a correlated series (the average power of a non-periodic
//! motion) from the means of consecutive batches.

use nalgebra::{DMatrix, SymmetricEigen};

/// Distances between returns `p` samples apart of a `dim`-dimensional row-major series,
/// relative to `scale`: `d_j = ‖s_j − s_{j−p}‖₂ / scale` for `j = p … len − 1` (see the
/// module docs). Given positions and velocities over a frequency (a state in one unit), the
/// Euclidean norm of a lightly damped mode's part decays smoothly, where a single component
/// (or the largest) swings through zero at the mode's beat with the forcing. Empty if the
/// series holds `p` samples or fewer, or if `p` or `dim` is 0.
pub fn return_distances(samples: &[f64], dim: usize, p: usize, scale: f64) -> Vec<f64> {
    if dim == 0 || p == 0 {
        return Vec::new();
    }
    let n = samples.len() / dim;
    (p..n)
        .map(|j| {
            let (a, b) = (
                &samples[j * dim..(j + 1) * dim],
                &samples[(j - p) * dim..(j - p + 1) * dim],
            );
            a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt() / scale
        })
        .collect()
}

/// The largest magnitude of a series' entries (the amplitude [`detect_period`](super::detect_period)
/// measures its tolerance against), or `f64::MIN_POSITIVE` for an all-zero series.
pub fn amplitude(samples: &[f64]) -> f64 {
    samples
        .iter()
        .map(|x| x.abs())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE)
}

/// A geometric fit of return distances (see [`fit_convergence`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Convergence {
    /// Slope of `ln d` per sample (per excitation period for a stroboscopic series).
    pub slope: f64,
    /// Standard error of the slope (least squares; the residuals of a motion with a complex
    /// slowest multiplier are correlated, so take it as a scale rather than a confidence).
    pub slope_se: f64,
    /// The distance at the last sample, read off the fitted line (relative to the scale).
    pub distance: f64,
    /// Samples the fit covers.
    pub samples: usize,
    /// Root mean square of the residuals of `ln d` about the line.
    pub rms: f64,
}

impl Convergence {
    /// Rate per sample `r = exp(slope)`: below 1 where the distances shrink.
    pub fn rate(&self) -> f64 {
        self.slope.exp()
    }

    /// Whether the distances shrink geometrically beyond doubt: a negative slope at least 5
    /// standard errors from 0, and either the distance halved over the samples fitted or
    /// the points within 0.25 (in ln d, root mean square) of the line, a slow but clean
    /// geometric decay.
    pub fn converging(&self) -> bool {
        self.slope < 0.0 && self.slope + 5.0 * self.slope_se < 0.0 && (self.halved() || self.rms <= 0.25)
    }

    /// Whether the fitted distance at least halved over the samples fitted (a decline that
    /// the residual of a motion already within the period tolerance of its orbit cannot
    /// produce at a lag that is not the orbit's period).
    pub fn halved(&self) -> bool {
        self.slope * (self.samples.saturating_sub(1)) as f64 <= -std::f64::consts::LN_2
    }

    /// Samples still needed, at the fitted rate, for the distance to fall to `tolerance`
    /// (0 if it already has; `None` unless [`converging`](Self::converging)).
    pub fn samples_needed(&self, tolerance: f64) -> Option<f64> {
        if !self.converging() {
            return None;
        }
        Some(((tolerance / self.distance).ln() / self.slope).max(0.0))
    }
}

/// The least-squares line through `ln d_j` against j of the return distances `distances`
/// (zeros, exact returns, are left out of the fit), or `None` with fewer than 3 positive
/// distances.
pub fn fit_convergence(distances: &[f64]) -> Option<Convergence> {
    let points: Vec<(f64, f64)> = distances
        .iter()
        .enumerate()
        .filter(|(_, d)| **d > 0.0 && d.is_finite())
        .map(|(j, d)| (j as f64, d.ln()))
        .collect();
    let m = points.len();
    if m < 3 {
        return None;
    }
    let mean_x = points.iter().map(|p| p.0).sum::<f64>() / m as f64;
    let mean_y = points.iter().map(|p| p.1).sum::<f64>() / m as f64;
    let sxx: f64 = points.iter().map(|p| (p.0 - mean_x).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let intercept = mean_y - slope * mean_x;
    let ssr: f64 = points
        .iter()
        .map(|p| (p.1 - intercept - slope * p.0).powi(2))
        .sum();
    let last = (distances.len() - 1) as f64;
    Some(Convergence {
        slope,
        slope_se: (ssr / (m - 2).max(1) as f64 / sxx).sqrt(),
        distance: (intercept + slope * last).exp(),
        samples: distances.len(),
        rms: (ssr / m as f64).sqrt(),
    })
}

/// The smallest lag p ≤ `max_period` at which the return distances of `samples` (see
/// [`return_distances`]) converge geometrically, with its fit; else `fallback` and the fit
/// there. An orbit of period q is approached at lags q, 2q, …, and no other: its smallest
/// converging lag is its period, even where a slow mode nearly repeats at another lag (a
/// mode turning 10 times in 7 periods makes lag 7 the closest match of the positions).
pub fn converging_lag(
    samples: &[f64],
    dim: usize,
    max_period: usize,
    scale: f64,
    fallback: usize,
) -> (usize, Option<Convergence>) {
    let fit = |p| fit_convergence(&return_distances(samples, dim, p, scale));
    (1..=max_period)
        .find_map(|p| fit(p).filter(Convergence::converging).map(|f| (p, Some(f))))
        .unwrap_or_else(|| (fallback, fit(fallback)))
}

/// The smallest proper divisor d of `p` at which the return distances of `samples` (see
/// [`return_distances`]) shrink geometrically ([`Convergence::converging`]) and at least
/// halved over the series ([`Convergence::halved`]), with its fit; `None` if there is none.
///
/// A series that repeats at lag p within a tolerance yet has such a divisor is not on an
/// orbit of period p: it is converging onto an orbit of period d along a slow spiral whose
/// rotation nearly closes after p/d turns (a multiplier near a root of unity), and the
/// period-p match is an artefact of the window. On an orbit of period p the distances at a
/// lag d that is not a period stay at the distance between the orbit's points.
pub fn contracting_divisor(
    samples: &[f64],
    dim: usize,
    p: usize,
    scale: f64,
) -> Option<(usize, Convergence)> {
    (1..p).filter(|d| p.is_multiple_of(*d)).find_map(|d| {
        fit_convergence(&return_distances(samples, dim, d, scale))
            .filter(|c| c.converging() && c.halved())
            .map(|c| (d, c))
    })
}

/// How far a set of section points is from lying on one closed curve: the points, in a
/// `dim`-dimensional row-major array, are ordered by their angle about their centroid in the
/// plane of their two principal axes, and the length of the closed polygon through them in
/// that order (measured in all `dim` dimensions) is divided by the set's diameter.
///
/// Points on a closed curve that the plane sees as a loop around the centroid (the section
/// of a two-torus) give a small ratio, π for a circle, about 2 for a thin ellipse,
/// whatever their number; a cloud gives a ratio that grows with the number of points (the
/// angular order jumps back and forth across the cloud). `None` with fewer than 8 points or
/// a set of zero extent.
pub fn closed_curve_ratio(points: &[f64], dim: usize) -> Option<f64> {
    if dim < 2 {
        return None;
    }
    let n = points.len() / dim;
    if n < 8 {
        return None;
    }
    let row = |j: usize| &points[j * dim..(j + 1) * dim];
    let mut centroid = vec![0.0; dim];
    for j in 0..n {
        for (c, x) in centroid.iter_mut().zip(row(j)) {
            *c += x / n as f64;
        }
    }
    let mut cov = DMatrix::<f64>::zeros(dim, dim);
    for j in 0..n {
        let r = row(j);
        for a in 0..dim {
            for b in 0..dim {
                cov[(a, b)] += (r[a] - centroid[a]) * (r[b] - centroid[b]);
            }
        }
    }
    let eig = SymmetricEigen::new(cov);
    let mut order: Vec<usize> = (0..dim).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[b].total_cmp(&eig.eigenvalues[a]));
    let (u, v) = (
        eig.eigenvectors.column(order[0]),
        eig.eigenvectors.column(order[1]),
    );
    let mut angles: Vec<(f64, usize)> = (0..n)
        .map(|j| {
            let r = row(j);
            let (mut a, mut b) = (0.0f64, 0.0f64);
            for d in 0..dim {
                a += (r[d] - centroid[d]) * u[d];
                b += (r[d] - centroid[d]) * v[d];
            }
            (b.atan2(a), j)
        })
        .collect();
    angles.sort_by(|x, y| x.0.total_cmp(&y.0));
    let dist = |i: usize, j: usize| {
        row(i)
            .iter()
            .zip(row(j))
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let length: f64 = (0..n).map(|k| dist(angles[k].1, angles[(k + 1) % n].1)).sum();
    let mut diameter = 0.0f64;
    for i in 0..n {
        for j in i + 1..n {
            diameter = diameter.max(dist(i, j));
        }
    }
    (diameter > 0.0).then(|| length / diameter)
}

/// Below this [`closed_curve_ratio`] a section counts as a closed curve: twice a circle's π
/// (room for an uneven or non-convex curve), well below what 50 or more points of a cloud give.
pub const CLOSED_CURVE_RATIO: f64 = 2.0 * std::f64::consts::PI;

/// The batch-means standard error of the mean of `values`: the values split into `batches`
/// consecutive batches of (nearly) equal length (batch k holds values `k·n/b … (k+1)·n/b`),
/// the standard deviation of the batch means divided by √b. Values correlated over fewer
/// samples than a batch holds give an honest error of their mean. `None` with fewer than 2
/// values (b is at most the number of values).
pub fn batch_means_se(values: &[f64], batches: usize) -> Option<f64> {
    let n = values.len();
    let b = batches.min(n);
    if b < 2 {
        return None;
    }
    let means: Vec<f64> = (0..b)
        .map(|k| {
            let s = &values[k * n / b..(k + 1) * n / b];
            s.iter().sum::<f64>() / s.len() as f64
        })
        .collect();
    let mean = means.iter().sum::<f64>() / b as f64;
    let var = means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (b - 1) as f64;
    Some((var / b as f64).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A geometric sequence is fitted exactly: slope ln r, zero error, the periods needed
    /// from the closed form ln(tol/d)/ln r.
    #[test]
    fn geometric_distances_fit_exactly() {
        let r: f64 = 0.9;
        let d: Vec<f64> = (0..40).map(|j| 0.5 * r.powi(j)).collect();
        let c = fit_convergence(&d).unwrap();
        assert!((c.rate() - r).abs() < 1e-12, "{c:?}");
        assert!(c.slope_se < 1e-12);
        assert!(c.converging());
        let last = 0.5 * r.powi(39);
        assert!((c.distance - last).abs() < 1e-12 * last);
        let needed = c.samples_needed(1e-8).unwrap();
        assert!((needed - (1e-8 / last).ln() / r.ln()).abs() < 1e-9);
        assert_eq!(c.samples_needed(1.0), Some(0.0));
    }

    /// Distances that do not shrink are not converging.
    #[test]
    fn noise_is_not_converging() {
        let mut x: f64 = 0.3;
        let d: Vec<f64> = (0..100)
            .map(|_| {
                x = 4.0 * x * (1.0 - x);
                x.abs()
            })
            .collect();
        let c = fit_convergence(&d).unwrap();
        assert!(!c.converging(), "{c:?}");
    }

    /// Return distances of a series with period 2 vanish at p = 2 and not at p = 1.
    #[test]
    fn return_distances_of_a_period_two_series() {
        let s = [1.0, -2.0, 3.0, 4.0, 1.0, -2.0, 3.0, 4.0];
        assert_eq!(return_distances(&s, 2, 2, 1.0), vec![0.0, 0.0]);
        let d = 40f64.sqrt() / 2.0;
        assert_eq!(return_distances(&s, 2, 1, 2.0), vec![d, d, d]);
        assert!(return_distances(&s, 2, 4, 1.0).is_empty());
    }

    /// A circle (points at an irrational rotation) has ratio π; an ellipse in three
    /// dimensions, tilted, stays below the threshold; a cloud of 100 points is above it, and
    /// its ratio grows with the number of points.
    #[test]
    fn closed_curves_and_clouds() {
        let golden = 0.5 * (5f64.sqrt() - 1.0);
        let circle: Vec<f64> = (0..200)
            .flat_map(|j| {
                let a = std::f64::consts::TAU * golden * j as f64;
                [a.cos(), a.sin()]
            })
            .collect();
        let r = closed_curve_ratio(&circle, 2).unwrap();
        assert!((r - std::f64::consts::PI).abs() < 1e-3, "{r}");
        let ellipse: Vec<f64> = (0..100)
            .flat_map(|j| {
                let a = std::f64::consts::TAU * golden * j as f64;
                [3.0 * a.cos(), a.sin(), 0.5 * a.cos() + 0.2 * a.sin()]
            })
            .collect();
        assert!(closed_curve_ratio(&ellipse, 3).unwrap() < CLOSED_CURVE_RATIO);
        let mut x: f64 = 0.1;
        let mut next = || {
            x = 4.0 * x * (1.0 - x);
            x
        };
        let cloud: Vec<f64> = (0..400).flat_map(|_| [next(), next(), next()]).collect();
        let c100 = closed_curve_ratio(&cloud[..300], 3).unwrap();
        let c400 = closed_curve_ratio(&cloud, 3).unwrap();
        assert!(c100 > CLOSED_CURVE_RATIO, "{c100}");
        // The ratio of a cloud grows with its number of points (about as √n).
        assert!(c400 > 1.5 * c100, "{c100} {c400}");
    }

    /// A slow spiral onto a fixed point, turning by nearly π per step (multiplier
    /// 0.99·e^{i(π − 0.01)}): its lag-2 returns nearly vanish, its lag-1 returns shrink
    /// geometrically at 0.99, so 1 is a contracting divisor of 2; an exact period-2 series
    /// (with a decaying perturbation far below its lag-1 distance) has none.
    #[test]
    fn a_spiral_is_not_a_period_two_orbit() {
        let (r, a) = (0.99f64, std::f64::consts::PI - 0.01);
        let spiral: Vec<f64> = (0..300)
            .flat_map(|j| {
                let (m, t) = (r.powi(j), a * j as f64);
                [1.0 + m * t.cos(), m * t.sin()]
            })
            .collect();
        // |μ² − 1| ≈ 0.028 against |μ − 1| ≈ 1.99: the lag-2 returns nearly close.
        let (lag1, lag2) = (
            return_distances(&spiral, 2, 1, 1.0),
            return_distances(&spiral, 2, 2, 1.0),
        );
        let (l1, l2) = (lag1[lag1.len() - 1], lag2[lag2.len() - 1]);
        assert!(l2 < l1 / 20.0, "lag 2: {l2}, lag 1: {l1}");
        let (d, fit) = contracting_divisor(&spiral, 2, 2, 1.0).unwrap();
        assert_eq!(d, 1);
        assert!((fit.rate() - r).abs() < 1e-3, "{fit:?}");
        let orbit: Vec<f64> = (0..300)
            .flat_map(|j| {
                let e = 1e-6 * 0.9f64.powi(j);
                [[0.2, 0.7][j as usize % 2] + e, 0.1 - e]
            })
            .collect();
        assert_eq!(contracting_divisor(&orbit, 2, 2, 1.0), None);
    }

    /// Batch means of independent values: the error of the mean is σ/√n for uncorrelated
    /// values of standard deviation σ (checked on ±1 alternating in batches of even length,
    /// where every batch mean is 0, and on a trend, where it is the closed form).
    #[test]
    fn batch_means() {
        let alternating: Vec<f64> = (0..100).map(|j| if j % 2 == 0 { 1.0 } else { -1.0 }).collect();
        assert_eq!(batch_means_se(&alternating, 10), Some(0.0));
        // Batches of one value each: the standard deviation of 0..9 is √(55/6).
        let ramp: Vec<f64> = (0..10).map(f64::from).collect();
        let se = batch_means_se(&ramp, 10).unwrap();
        assert!((se - (55.0f64 / 6.0).sqrt() / 10f64.sqrt()).abs() < 1e-12);
        assert_eq!(batch_means_se(&[1.0], 10), None);
    }
}
