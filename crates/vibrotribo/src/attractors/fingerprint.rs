//! Where one start ended: its stroboscopic set, condensed into a [`Fingerprint`].

use crate::analysis::{PeriodOptions, detect_period};
use crate::error::{ParamError, check, check_positive};
use crate::model::ChainParams;
use crate::sensitivity::length_scale;
use crate::study::PointResult;

/// Settings of the attractor fingerprints, their classification and their tracking across
/// a parameter (see the [module docs](super)). Lengths are in the section's scaled units:
/// positions over `L = Σδ + A`, velocities over `L·ω`.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AttractorOptions {
    /// A start's section repeats with period p when every recorded point is within this
    /// distance of the point p periods before (scaled max-norm, the last
    /// `(repeats + 1)·max_period` points; [`detect_period`]). Coarser than a sweep's period
    /// test on purpose: a start still settling onto an orbit with a slowly decaying mode
    /// (a multiplier near −1 rings at a period of 2, 7, 9… at the 1e-5 level) is that orbit
    /// for a basin picture. Default 1e-3 (0.13 mm and 4 mm/s in the paper's default case).
    pub period_tolerance: f64,
    /// Two periodic sets of the same period are one attractor when every point of each is
    /// within this distance of a point of the other (scaled Hausdorff distance); at least
    /// twice `period_tolerance`, since both starts carry their residual transient.
    /// Default 3e-3.
    pub match_tolerance: f64,
    /// Edge of the cells a non-periodic section cloud is binned into (scaled); two clouds
    /// that occupy a common cell belong to one attractor. Coarse enough that the ~100
    /// section points of two starts on one chaotic attractor share cells (at 0.02 the
    /// hyperchaotic motion of the paper's Fig. 14 chain at R_m = 6.54, Kaplan–Yorke dimension
    /// 3.7, fell apart into 11 groups of 16 starts; at 0.05 it is one), fine enough to keep
    /// apart attractors that far apart. Default 0.05.
    pub cell: f64,
    /// Across parameter values, an attractor continues one of the previous value when their
    /// sets are within this scaled Hausdorff distance (the nearest pairs first). It must
    /// exceed how far an attractor moves between neighbouring values (the section states
    /// can move fast where an impact falls near the section time: 0.05–0.1 per 0.01 of R_δ
    /// near the jump of the paper's Fig. 7) and stay below the distance between distinct
    /// attractors. Default 0.25.
    pub continuation_distance: f64,
}

impl Default for AttractorOptions {
    fn default() -> Self {
        AttractorOptions {
            period_tolerance: 1e-3,
            match_tolerance: 3e-3,
            cell: 0.05,
            continuation_distance: 0.25,
        }
    }
}

impl AttractorOptions {
    /// Checks the options, naming the field at fault.
    pub fn validate(&self) -> Result<(), ParamError> {
        check(
            "period_tolerance",
            self.period_tolerance,
            self.period_tolerance > 0.0 && self.period_tolerance < 1.0,
            "must lie in (0, 1)",
        )?;
        check_positive("match_tolerance", self.match_tolerance)?;
        check_positive("cell", self.cell)?;
        check_positive("continuation_distance", self.continuation_distance)
    }
}

/// The units of the stroboscopic section: positions in `L = Σδ + A`, m, velocities in
/// `L·ω`, m/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SectionScale {
    /// Masses N.
    pub masses: usize,
    /// Length unit L, m.
    pub length: f64,
    /// Speed unit L·ω, m/s.
    pub speed: f64,
}

impl SectionScale {
    /// The units of the chain `params`.
    pub fn of(params: &ChainParams) -> Self {
        let length = length_scale(params);
        SectionScale {
            masses: params.len(),
            length,
            speed: length * params.omega(),
        }
    }

    /// Coordinate `i` of a state `[x₁ … x_N, v₁ … v_N]` in scaled units.
    pub fn scaled(&self, i: usize, value: f64) -> f64 {
        if i < self.masses {
            value / self.length
        } else {
            value / self.speed
        }
    }

    /// Coordinate `i` back in SI units.
    pub fn unscaled(&self, i: usize, value: f64) -> f64 {
        if i < self.masses {
            value * self.length
        } else {
            value * self.speed
        }
    }
}

/// Where one start ended, condensed from the stroboscopic states `z(nT)` of its recorded
/// periods.
#[derive(Debug, Clone, PartialEq)]
pub struct Fingerprint {
    /// Period of the section in excitation periods (positions and velocities repeat within
    /// [`AttractorOptions::period_tolerance`]); 0 if it did not repeat.
    pub period: usize,
    /// Periodic: the `period` section states `[x₁ … x_N, v₁ … v_N]` (m, m/s), flattened,
    /// starting with the smallest (lexicographic order). Non-periodic: the last recorded
    /// section state. Either way the first `2N` values are a state on the attractor at a
    /// section time (t ≡ 0 mod T), from which a run stays on it.
    pub points: Vec<f64>,
    /// Non-periodic: the cells of edge [`AttractorOptions::cell`] (scaled units) the section
    /// cloud occupies, flattened `2N` indices each, sorted and distinct; empty if periodic.
    pub cells: Vec<i32>,
    /// Impacts per period, all contacts.
    pub impacts_per_period: f64,
    /// Average power over the recorded periods, W (with a harvester).
    pub power_w: Option<f64>,
}

impl Fingerprint {
    /// The fingerprint of a sweep point's result (its stroboscopic positions and
    /// velocities), on the section units `scale` of its chain.
    ///
    /// Errors if the result holds fewer section points than the period test reads
    /// (`recorded_periods` too small for `max_period`).
    pub fn of(
        result: &PointResult,
        scale: &SectionScale,
        period_options: &PeriodOptions,
        options: &AttractorOptions,
    ) -> Result<Self, ParamError> {
        let n = scale.masses;
        let dim = 2 * n;
        let count = result.strobe_periods.len();
        let mut z = Vec::with_capacity(count * dim);
        for j in 0..count {
            z.extend_from_slice(&result.strobe[j * n..(j + 1) * n]);
            z.extend_from_slice(&result.strobe_velocities[j * n..(j + 1) * n]);
        }
        let scaled: Vec<f64> = z
            .iter()
            .enumerate()
            .map(|(k, &v)| scale.scaled(k % dim, v))
            .collect();
        let popts = PeriodOptions {
            tolerance: options.period_tolerance,
            scale: Some(1.0),
            ..period_options.clone()
        };
        let period = detect_period(&scaled, dim, &popts)
            .map_err(|_| {
                ParamError::invalid(
                    "recorded_periods",
                    count as f64,
                    "too few section points for the period test",
                )
            })?
            .period()
            .unwrap_or(0);
        let (points, cells) = if period > 0 {
            let tail = &z[(count - period) * dim..];
            let mut pts: Vec<&[f64]> = tail.chunks_exact(dim).collect();
            let first = (0..period)
                .min_by(|&a, &b| lexicographic(pts[a], pts[b]))
                .unwrap_or(0);
            pts.rotate_left(first);
            (pts.concat(), Vec::new())
        } else {
            let last = z[(count - 1) * dim..].to_vec();
            let mut cells: Vec<Vec<i32>> = scaled
                .chunks_exact(dim)
                .map(|p| p.iter().map(|v| (v / options.cell).floor() as i32).collect())
                .collect();
            cells.sort();
            cells.dedup();
            (last, cells.concat())
        };
        Ok(Fingerprint {
            period,
            points,
            cells,
            impacts_per_period: result.total_impacts_per_period(),
            power_w: result.average_power_w,
        })
    }

    /// A state on the attractor at a section time (the first section point).
    pub fn state(&self) -> crate::ChainState {
        let n = self.points.len() / (2 * self.period.max(1));
        crate::sensitivity::state_from_vector(&self.points[..2 * n])
    }

    /// The section points in scaled units, flattened.
    pub(crate) fn scaled_points(&self, scale: &SectionScale) -> Vec<f64> {
        let dim = 2 * scale.masses;
        self.points
            .iter()
            .enumerate()
            .map(|(k, &v)| scale.scaled(k % dim, v))
            .collect()
    }
}

fn lexicographic(a: &[f64], b: &[f64]) -> std::cmp::Ordering {
    a.iter()
        .zip(b)
        .map(|(x, y)| x.total_cmp(y))
        .find(|o| o.is_ne())
        .unwrap_or(std::cmp::Ordering::Equal)
}

/// The Hausdorff distance between two point sets (flattened, `dim` coordinates each) in the
/// max-norm: the largest distance from a point of either set to the nearest of the other.
pub(crate) fn hausdorff(a: &[f64], b: &[f64], dim: usize) -> f64 {
    let directed = |p: &[f64], q: &[f64]| {
        p.chunks_exact(dim)
            .map(|x| {
                q.chunks_exact(dim)
                    .map(|y| x.iter().zip(y).fold(0.0f64, |m, (u, v)| m.max((u - v).abs())))
                    .fold(f64::INFINITY, f64::min)
            })
            .fold(0.0f64, f64::max)
    };
    directed(a, b).max(directed(b, a))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hausdorff_distance() {
        let a = [0.0, 0.0, 1.0, 1.0];
        let b = [1.0, 1.0, 0.0, 0.1];
        assert!((hausdorff(&a, &b, 2) - 0.1).abs() < 1e-15);
        assert_eq!(hausdorff(&a, &a, 2), 0.0);
        let c = [5.0, 5.0];
        assert_eq!(hausdorff(&a, &c, 2), 5.0);
    }
}
