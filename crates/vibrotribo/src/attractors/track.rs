//! Attractors followed from one parameter value to the next ([`AttractorTracker`]).

use super::classify::Attractor;
use super::fingerprint::{AttractorOptions, SectionScale, hausdorff};

/// The last set seen of an attractor with a global identity (its index).
#[derive(Debug, Clone)]
struct Known {
    set: Vec<f64>,
}

/// Gives the attractors found at successive parameter values global identities.
///
/// The evidence, strongest first (Attractors.jl's seeded continuation, then its matching by
/// set distance):
///
/// 1. **Continuation**: a known attractor run from one of its states at the new value
///    (`continued`: which attractor its seed ends on). An attractor that several seeds
///    reach continues the known one whose set lies nearest (the others vanished into it).
/// 2. **Set distance**: an attractor no seed reached continues the nearest known attractor
///    not yet continued, if their sets (scaled section units: the periodic points, or the
///    centres of the cells a non-periodic cloud occupies) are within
///    [`AttractorOptions::continuation_distance`] in the Hausdorff distance (nearest pairs
///    first). So an attractor that vanished for a while keeps its identity when it comes
///    back near where it was last seen.
/// 3. Otherwise a new identity, numbered in order of appearance.
#[derive(Debug, Clone, Default)]
pub struct AttractorTracker {
    known: Vec<Known>,
}

impl AttractorTracker {
    /// A tracker that knows no attractor yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of identities given so far.
    pub fn len(&self) -> usize {
        self.known.len()
    }

    /// Whether no identity was given yet.
    pub fn is_empty(&self) -> bool {
        self.known.is_empty()
    }

    /// The global identities of `attractors` (found at one parameter value, with section
    /// units `scale`), in their order. `continued` pairs a known identity with the index in
    /// `attractors` its seed ended on (step 1 above; empty without seeds).
    pub fn track(
        &mut self,
        attractors: &[Attractor],
        continued: &[(usize, usize)],
        scale: &SectionScale,
        options: &AttractorOptions,
    ) -> Vec<usize> {
        let dim = 2 * scale.masses;
        let sets: Vec<Vec<f64>> = attractors
            .iter()
            .map(|a| a.scaled_set(scale, options.cell))
            .collect();
        let mut ids: Vec<Option<usize>> = vec![None; attractors.len()];
        let mut taken = vec![false; self.known.len()];
        // 1. Seeds: the nearest of the known attractors that flow into each one.
        for (a, set) in sets.iter().enumerate() {
            let best = continued
                .iter()
                .filter(|&&(k, target)| target == a && k < self.known.len())
                .map(|&(k, _)| (hausdorff(set, &self.known[k].set, dim), k))
                .min_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            if let Some((_, k)) = best {
                ids[a] = Some(k);
                taken[k] = true;
            }
        }
        // Known attractors whose seed went elsewhere vanished here: not matched by distance.
        for &(k, _) in continued {
            if k < taken.len() {
                taken[k] = true;
            }
        }
        // 2. Set distance, nearest pairs first.
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        for (a, set) in sets.iter().enumerate() {
            if ids[a].is_some() {
                continue;
            }
            for (k, known) in self.known.iter().enumerate() {
                if taken[k] {
                    continue;
                }
                let d = hausdorff(set, &known.set, dim);
                if d <= options.continuation_distance {
                    pairs.push((d, a, k));
                }
            }
        }
        pairs.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
        for (_, a, k) in pairs {
            if ids[a].is_none() && !taken[k] {
                ids[a] = Some(k);
                taken[k] = true;
            }
        }
        // 3. New identities.
        let mut out = Vec::with_capacity(attractors.len());
        for (a, set) in sets.into_iter().enumerate() {
            let id = match ids[a] {
                Some(id) => {
                    self.known[id].set = set;
                    id
                }
                None => {
                    let id = self.known.len();
                    self.known.push(Known { set });
                    id
                }
            };
            out.push(id);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(x: f64, period: usize) -> Attractor {
        Attractor {
            period,
            points: (0..period).flat_map(|k| [x + 0.01 * k as f64, 0.0]).collect(),
            cells: Vec::new(),
            starts: 1,
            first: 0,
            impacts_per_period: 0.0,
            power_w: None,
            power_se: None,
        }
    }

    #[test]
    fn nearest_pairs_first_and_identities_kept() {
        let scale = SectionScale {
            masses: 1,
            length: 1.0,
            speed: 1.0,
        };
        let o = AttractorOptions::default();
        let mut t = AttractorTracker::new();
        assert_eq!(t.track(&[at(0.0, 1), at(0.5, 1)], &[], &scale, &o), vec![0, 1]);
        // They move a little and swap order; a third appears far away.
        assert_eq!(
            t.track(&[at(0.52, 1), at(0.02, 2), at(2.0, 1)], &[], &scale, &o),
            vec![1, 0, 2]
        );
        // Attractor 1 vanishes for a value and comes back.
        assert_eq!(t.track(&[at(0.03, 2)], &[], &scale, &o), vec![0]);
        assert_eq!(t.track(&[at(0.53, 1), at(0.04, 2)], &[], &scale, &o), vec![1, 0]);
        // Seeds beat distance: the seeds of attractors 0 and 1 both end on the one at 0.6,
        // which continues the nearer, 1; attractor 0 vanished into it, so the one that
        // appeared where 0 was is new.
        assert_eq!(
            t.track(&[at(0.05, 1), at(0.6, 1)], &[(0, 1), (1, 1)], &scale, &o),
            vec![3, 1]
        );
        assert_eq!(t.len(), 4);
    }
}
