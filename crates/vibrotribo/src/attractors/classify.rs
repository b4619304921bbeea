//! Starts grouped by the attractor they end on ([`classify`]).

use std::collections::HashMap;

use super::fingerprint::{AttractorOptions, Fingerprint, SectionScale, hausdorff};

/// One attractor found among a set of starts.
#[derive(Debug, Clone, PartialEq)]
pub struct Attractor {
    /// Period in excitation periods, 0 if non-periodic.
    pub period: usize,
    /// The section states of its first start ([`Fingerprint::points`]: periodic, its
    /// `period` states; non-periodic, its last state), m and m/s, flattened `2N` each.
    pub points: Vec<f64>,
    /// Non-periodic: the cells its starts' section clouds occupy (flattened `2N` indices
    /// each, sorted); empty if periodic.
    pub cells: Vec<i32>,
    /// Starts that end on it (0 for an attractor found only by continuing one of the
    /// previous parameter value: it exists, but no random start landed in its basin).
    pub starts: usize,
    /// Index of its first start (in the order classified).
    pub first: usize,
    /// Mean impacts per period of its starts.
    pub impacts_per_period: f64,
    /// Mean average power of its starts, W (`None` without a harvester).
    pub power_w: Option<f64>,
    /// Standard error of that mean, W (`None` with fewer than two powers): the spread of a
    /// non-periodic attractor's finite-window power; ~0 for a periodic one.
    pub power_se: Option<f64>,
}

impl Attractor {
    /// The attractor of one start alone (with `starts` counted).
    fn of(f: &Fingerprint, starts: usize, first: usize) -> Self {
        Attractor {
            period: f.period,
            points: f.points.clone(),
            cells: f.cells.clone(),
            starts,
            first,
            impacts_per_period: f.impacts_per_period,
            power_w: f.power_w,
            power_se: None,
        }
    }

    /// Whether the start `f` ends on this attractor (the rules of [`classify`]).
    pub fn holds(&self, f: &Fingerprint, scale: &SectionScale, options: &AttractorOptions) -> bool {
        let dim = 2 * scale.masses;
        if self.period != f.period {
            return false;
        }
        if self.is_periodic() {
            let mine = f.scaled_points(scale);
            let theirs: Vec<f64> = self
                .points
                .iter()
                .enumerate()
                .map(|(k, &v)| scale.scaled(k % dim, v))
                .collect();
            hausdorff(&theirs, &mine, dim) <= options.match_tolerance
        } else {
            let cells: std::collections::HashSet<&[i32]> = self.cells.chunks_exact(dim).collect();
            f.cells.chunks_exact(dim).any(|c| cells.contains(c))
        }
    }

    /// A state on the attractor at a section time.
    pub fn state(&self) -> crate::ChainState {
        let dim = self.points.len() / self.period.max(1);
        crate::sensitivity::state_from_vector(&self.points[..dim])
    }

    /// Whether the attractor is periodic.
    pub fn is_periodic(&self) -> bool {
        self.period > 0
    }

    /// Its set in scaled section units (the periodic points, or the centres of the cells),
    /// flattened, for distances between attractors.
    pub(crate) fn scaled_set(&self, scale: &SectionScale, cell: f64) -> Vec<f64> {
        if self.is_periodic() {
            let dim = 2 * scale.masses;
            self.points
                .iter()
                .enumerate()
                .map(|(k, &v)| scale.scaled(k % dim, v))
                .collect()
        } else {
            self.cells.iter().map(|&c| (f64::from(c) + 0.5) * cell).collect()
        }
    }
}

/// Starts grouped by attractor.
#[derive(Debug, Clone, PartialEq)]
pub struct Classification {
    /// The attractor of each start (an index into `attractors`), `None` for a start that
    /// failed.
    pub labels: Vec<Option<usize>>,
    /// The attractors, in the order of their first start.
    pub attractors: Vec<Attractor>,
}

impl Classification {
    /// The attractor the start `f` ends on, if it is one of these.
    pub fn find(&self, f: &Fingerprint, scale: &SectionScale, options: &AttractorOptions) -> Option<usize> {
        self.attractors.iter().position(|a| a.holds(f, scale, options))
    }

    /// Adds the attractor of `f`, found by some other means than the starts classified (it
    /// holds none of them), and returns its index.
    pub fn add_unvisited(&mut self, f: &Fingerprint) -> usize {
        self.attractors.push(Attractor::of(f, 0, self.labels.len()));
        self.attractors.len() - 1
    }

    /// Starts classified (those that did not fail).
    pub fn classified(&self) -> usize {
        self.labels.iter().flatten().count()
    }

    /// The fraction of the classified starts that end on attractor `a`, and its binomial
    /// standard error `√(f(1 − f)/K)`.
    pub fn fraction(&self, a: usize) -> (f64, f64) {
        let k = self.classified() as f64;
        let f = self.attractors[a].starts as f64 / k;
        (f, (f * (1.0 - f) / k).sqrt())
    }

    /// The expected power over the classified starts (each start's own power: the basin
    /// fractions weighting the attractors' powers), W, and its standard error; `None`
    /// without powers.
    pub fn expected_power(&self, fingerprints: &[Option<Fingerprint>]) -> Option<(f64, f64)> {
        let powers: Vec<f64> = fingerprints.iter().flatten().filter_map(|f| f.power_w).collect();
        mean_and_se(&powers)
    }
}

/// Mean and standard error of the mean (`None` if empty; the error `NaN` for one value).
pub(crate) fn mean_and_se(values: &[f64]) -> Option<(f64, f64)> {
    if values.is_empty() {
        return None;
    }
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    Some((mean, (var / n).sqrt()))
}

/// An attractor being assembled.
struct Draft {
    period: usize,
    /// Periodic: the first start's points, scaled.
    scaled: Vec<f64>,
    members: Vec<usize>,
}

/// Groups the starts `fingerprints` (in the order given; `None` for a failed start) by the
/// attractor they end on, with the section units `scale`:
///
/// - a periodic start joins the first attractor (in order of creation) of the same period
///   whose points are within [`AttractorOptions::match_tolerance`] of its own (Hausdorff);
/// - a non-periodic start joins every non-periodic attractor that shares one of its
///   section cells (the recurrence grid of Attractors.jl's `AttractorsViaRecurrences`),
///   merging them if it links several;
/// - otherwise it starts a new attractor.
///
/// The result depends only on the fingerprints and their order, not on how they were
/// computed (threads, shards).
pub fn classify(
    fingerprints: &[Option<Fingerprint>],
    scale: &SectionScale,
    options: &AttractorOptions,
) -> Classification {
    let dim = 2 * scale.masses;
    let mut drafts: Vec<Draft> = Vec::new();
    let mut parent: Vec<usize> = Vec::new();
    let mut owner: HashMap<&[i32], usize> = HashMap::new();
    let find = |parent: &[usize], mut a: usize| {
        while parent[a] != a {
            a = parent[a];
        }
        a
    };
    let mut labels = vec![None; fingerprints.len()];
    for (i, f) in fingerprints.iter().enumerate() {
        let Some(f) = f else { continue };
        let target = if f.period > 0 {
            let mine = f.scaled_points(scale);
            let found = (0..drafts.len()).find(|&d| {
                parent[d] == d
                    && drafts[d].period == f.period
                    && hausdorff(&drafts[d].scaled, &mine, dim) <= options.match_tolerance
            });
            found.unwrap_or_else(|| {
                drafts.push(Draft {
                    period: f.period,
                    scaled: mine,
                    members: Vec::new(),
                });
                parent.push(drafts.len() - 1);
                drafts.len() - 1
            })
        } else {
            let mut linked: Vec<usize> = f
                .cells
                .chunks_exact(dim)
                .filter_map(|c| owner.get(c).map(|&d| find(&parent, d)))
                .collect();
            linked.sort_unstable();
            linked.dedup();
            match linked.first() {
                None => {
                    drafts.push(Draft {
                        period: 0,
                        scaled: Vec::new(),
                        members: Vec::new(),
                    });
                    parent.push(drafts.len() - 1);
                    drafts.len() - 1
                }
                Some(&root) => {
                    for &other in &linked[1..] {
                        parent[other] = root;
                        let moved = std::mem::take(&mut drafts[other].members);
                        drafts[root].members.extend(moved);
                    }
                    root
                }
            }
        };
        drafts[target].members.push(i);
        if f.period == 0 {
            for c in f.cells.chunks_exact(dim) {
                owner.entry(c).or_insert(target);
            }
        }
    }
    // Final attractors: the roots, in the order of their first start.
    let mut roots: Vec<usize> = (0..drafts.len()).filter(|&d| parent[d] == d).collect();
    for d in &roots {
        drafts[*d].members.sort_unstable();
    }
    roots.sort_by_key(|&d| drafts[d].members[0]);
    let mut attractors = Vec::with_capacity(roots.len());
    for (id, &d) in roots.iter().enumerate() {
        let members = &drafts[d].members;
        for &m in members {
            labels[m] = Some(id);
        }
        let fps: Vec<&Fingerprint> = members.iter().filter_map(|&m| fingerprints[m].as_ref()).collect();
        let n = fps.len() as f64;
        let period = drafts[d].period;
        let cells = if period > 0 {
            Vec::new()
        } else {
            let mut cells: Vec<&[i32]> = fps.iter().flat_map(|f| f.cells.chunks_exact(dim)).collect();
            cells.sort_unstable();
            cells.dedup();
            cells.concat()
        };
        let powers: Vec<f64> = fps.iter().filter_map(|f| f.power_w).collect();
        let power = mean_and_se(&powers);
        attractors.push(Attractor {
            period,
            points: fps[0].points.clone(),
            cells,
            starts: members.len(),
            first: members[0],
            impacts_per_period: fps.iter().map(|f| f.impacts_per_period).sum::<f64>() / n,
            power_w: power.map(|p| p.0),
            power_se: power.map(|p| p.1).filter(|se| se.is_finite()),
        });
    }
    Classification { labels, attractors }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn periodic(x: f64, period: usize) -> Option<Fingerprint> {
        Some(Fingerprint {
            period,
            points: (0..period).flat_map(|k| [x + k as f64, 0.0, 0.0, 0.0]).collect(),
            cells: Vec::new(),
            impacts_per_period: 1.0,
            power_w: Some(x),
        })
    }

    fn cloud(cells: &[[i32; 4]]) -> Option<Fingerprint> {
        Some(Fingerprint {
            period: 0,
            points: vec![0.0; 4],
            cells: cells.concat(),
            impacts_per_period: 2.0,
            power_w: Some(1.0),
        })
    }

    /// Periodic sets by tolerance and period; clouds by shared cells, merged when a later
    /// start links two; failed starts unlabelled; attractors numbered by first start.
    #[test]
    fn groups_by_set() {
        let scale = SectionScale {
            masses: 2,
            length: 1.0,
            speed: 1.0,
        };
        let options = AttractorOptions::default();
        let fps = vec![
            cloud(&[[0, 0, 0, 0], [1, 0, 0, 0]]),
            periodic(0.5, 1),
            periodic(0.5 + 1e-4, 1),
            periodic(0.5, 2),
            None,
            cloud(&[[5, 5, 5, 5]]),
            cloud(&[[1, 0, 0, 0], [5, 5, 5, 5]]),
            periodic(0.6, 1),
        ];
        let c = classify(&fps, &scale, &options);
        assert_eq!(
            c.labels,
            vec![
                Some(0),
                Some(1),
                Some(1),
                Some(2),
                None,
                Some(0),
                Some(0),
                Some(3)
            ]
        );
        assert_eq!(c.attractors.len(), 4);
        assert_eq!(c.attractors[0].starts, 3);
        assert_eq!(c.attractors[0].cells.len(), 3 * 4);
        assert_eq!(c.classified(), 7);
        let (f, se) = c.fraction(0);
        assert!((f - 3.0 / 7.0).abs() < 1e-15 && (se - (f * (1.0 - f) / 7.0).sqrt()).abs() < 1e-15);
        assert!((c.attractors[1].power_w.unwrap() - (0.5 + 0.5 + 1e-4) / 2.0).abs() < 1e-15);
    }
}
