//! The seeds of a map: at each seed value of the second key, the branches continued in the
//! first key from both ends of its range, and the bifurcations located on them that curves
//! can follow.

use std::ops::ControlFlow;

use super::types::{BifmapOptions, LocatedPoint, MapRequest, Seed, SeedOutcome, Stage};
use crate::branch::{BranchError, BranchOptions, continue_config};
use crate::config::Config;
use crate::curve::curve_kind_of;
use crate::orbits::curve::CurveKind;
use crate::orbits::{
    Bifurcation, BifurcationKind, ContinuationOptions, PeriodicOrbit, ShootingOptions,
    periodic_orbit_from_transient,
};
use crate::sensitivity::length_scale;
use crate::sweep::{Delivery, grid, run_chunks};
use crate::{ChainState, SimOptions, Simulator};

/// A bifurcation located on a seed's branch, to be followed in the second key.
#[derive(Debug, Clone)]
pub(super) struct Candidate {
    /// Index of the seed.
    pub seed: usize,
    /// The second key's value there.
    pub y: f64,
    /// The curve it lies on.
    pub kind: CurveKind,
    /// Period of its branch.
    pub period: u32,
    /// Grazing: the contact.
    pub contact: Option<usize>,
    /// The bifurcation.
    pub located: Bifurcation,
}

impl Candidate {
    /// Its entry in [`BifurcationMap::located`](super::BifurcationMap::located), on no
    /// curve yet.
    pub fn point(&self) -> LocatedPoint {
        LocatedPoint {
            seed: self.seed,
            y: self.y,
            x: self.located.parameter,
            kind: self.kind,
            period: self.period,
            contact: self.contact,
            curve: None,
        }
    }
}

/// The branch options of a map's seeds.
fn branch_options(config: &Config, options: &BifmapOptions) -> BranchOptions {
    let d = ContinuationOptions::default();
    BranchOptions {
        transient: options.transient,
        period: options.period,
        continuation: ContinuationOptions {
            doubling_depth: options.doublings,
            max_points: options.branch_points,
            shooting: ShootingOptions {
                sim: config.sim_options().clone(),
                cancel: options.cancel.clone(),
                ..d.shooting.clone()
            },
            ..d
        },
    }
}

/// The seed values of the second key, in the order of its range.
pub(super) fn seed_values(request: &MapRequest) -> Vec<f64> {
    grid(request.y_range.0, request.y_range.1, request.seeds)
}

/// The starts of every seed value and what they gave, in order; the seed values run in
/// parallel on the current rayon pool, and `progress` hears of each. Stops early (fewer
/// seed values) when the cancel hook asks.
pub(super) fn seed_branches(
    config: &Config,
    x: &str,
    y: &str,
    request: &MapRequest,
    options: &BifmapOptions,
    progress: &mut dyn FnMut(Stage),
) -> Vec<Seed> {
    let values = seed_values(request);
    let branch = branch_options(config, options);
    let total = values.len();
    let mut seeds = Vec::new();
    let mut done = 0;
    run_chunks(
        &values,
        rayon::current_num_threads().max(1),
        |&v| seed_value(config, (x, y), v, request, &branch),
        |d| {
            if let Delivery::Point(_, mut starts) = d {
                // Indices of earlier starts are counted from this value's first.
                let offset = seeds.len();
                for s in &mut starts {
                    if let SeedOutcome::OnBranch(i) = &mut s.outcome {
                        *i += offset;
                    }
                }
                seeds.extend(starts);
                done += 1;
                progress(Stage::Seeds { done, total });
            }
            if options.cancel.requested() {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
    );
    seeds
}

/// The starts of one seed value `v` of the second key, in order of the first key's start
/// values, each orbit continued towards both ends unless it lies on an earlier start's
/// branches (indices into the returned list).
fn seed_value(
    config: &Config,
    (x, y): (&str, &str),
    v: f64,
    request: &MapRequest,
    branch: &BranchOptions,
) -> Vec<Seed> {
    let (a, b) = request.x_range;
    let mut out: Vec<Seed> = Vec::new();
    let failed = |x_start: f64, x_end: f64, e: BranchError| Seed {
        y: v,
        x_start,
        x_end,
        outcome: SeedOutcome::Failed(e),
    };
    let at_y = match config.with(y, toml::Value::Float(v)) {
        Ok(c) => c,
        Err(source) => {
            let key = y.to_string();
            return vec![failed(
                a,
                b,
                BranchError::Value {
                    key,
                    value: v,
                    source,
                },
            )];
        }
    };
    let shooting = &branch.continuation.shooting;
    for xs in grid(a, b, request.x_starts) {
        if shooting.cancel.requested() {
            break;
        }
        let first = at_y
            .with(x, toml::Value::Float(xs))
            .map_err(|source| BranchError::Value {
                key: x.to_string(),
                value: xs,
                source,
            })
            .and_then(|c| {
                periodic_orbit_from_transient(
                    c.chain(),
                    c.initial_state(),
                    branch.transient,
                    branch.period,
                    shooting,
                )
                .map_err(|source| BranchError::FirstOrbit {
                    key: x.to_string(),
                    value: xs,
                    source,
                })
            });
        let ends: Vec<f64> = [a, b].into_iter().filter(|&e| e != xs).collect();
        let orbit = match first {
            Ok(o) => o,
            Err(e) => {
                out.push(failed(xs, ends[0], e));
                continue;
            }
        };
        if let Some(i) = out.iter().position(|s| on_branch(s, &orbit, xs)) {
            out.extend(ends.iter().map(|&e| Seed {
                y: v,
                x_start: xs,
                x_end: e,
                outcome: SeedOutcome::OnBranch(i),
            }));
            continue;
        }
        for e in ends {
            let guess = Some((orbit.state.clone(), orbit.period));
            let outcome = match continue_config(&at_y, x, xs, e, guess, branch) {
                Ok(c) => SeedOutcome::Branches(c),
                Err(err) => SeedOutcome::Failed(err),
            };
            out.push(Seed {
                y: v,
                x_start: xs,
                x_end: e,
                outcome,
            });
        }
    }
    out
}

/// Whether `orbit` (found at `x`) lies on a branch of `seed`: a branch of its period with a
/// segment bracketing `x` whose state, interpolated there, is within the segment's own
/// extent plus 10⁻³ (in the chain's length and speed scales) of the orbit's state at one of
/// its phases.
fn on_branch(seed: &Seed, orbit: &PeriodicOrbit, x: f64) -> bool {
    let Some(c) = seed.branches() else {
        return false;
    };
    let length = length_scale(&orbit.params);
    let speed = length * orbit.params.omega();
    let phases = phases(orbit);
    let vector = |s: &ChainState| -> Vec<f64> {
        s.positions
            .iter()
            .map(|p| p / length)
            .chain(s.velocities.iter().map(|v| v / speed))
            .collect()
    };
    let distance = |p: &[f64], q: &[f64]| p.iter().zip(q).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let phases: Vec<Vec<f64>> = phases.iter().map(vector).collect();
    c.branches.iter().filter(|b| b.period == orbit.period).any(|b| {
        b.points.windows(2).any(|w| {
            let (pa, pb) = (w[0].parameter, w[1].parameter);
            if (pa - x) * (pb - x) > 0.0 || pa == pb {
                return false;
            }
            let t = (x - pa) / (pb - pa);
            let (za, zb) = (vector(&w[0].state), vector(&w[1].state));
            let z: Vec<f64> = za.iter().zip(&zb).map(|(a, b)| a + t * (b - a)).collect();
            let tolerance = distance(&za, &zb) + 1e-3;
            phases.iter().any(|q| distance(&z, q) <= tolerance)
        })
    })
}

/// The states of `orbit` at t = kT, k = 0 … P − 1 (fewer if a simulation fails).
fn phases(orbit: &PeriodicOrbit) -> Vec<ChainState> {
    let mut out = vec![orbit.state.clone()];
    let Ok(mut sim) = Simulator::new(&orbit.params, &orbit.state, SimOptions::default()) else {
        return out;
    };
    for k in 1..orbit.period {
        if sim
            .run_until(f64::from(k) * orbit.params.period(), &mut ())
            .is_err()
        {
            break;
        }
        out.push(sim.state());
    }
    out
}

/// The bifurcations of the kinds asked for on every seed's branches, a bifurcation found by
/// both branches of one seed value listed once (same kind, period and contact within
/// `x_tolerance` in the first key).
pub(super) fn candidates(seeds: &[Seed], kinds: &[CurveKind], x_tolerance: f64) -> Vec<Candidate> {
    let mut out: Vec<Candidate> = Vec::new();
    for (i, seed) in seeds.iter().enumerate() {
        let Some(c) = seed.branches() else { continue };
        for b in &c.branches {
            for f in &b.bifurcations {
                let Some(kind) = curve_kind_of(&f.kind).filter(|k| kinds.contains(k)) else {
                    continue;
                };
                let contact = match f.kind {
                    BifurcationKind::Grazing { contact, .. } => Some(contact),
                    _ => None,
                };
                let twin = out.iter().any(|o| {
                    o.y == seed.y
                        && o.kind == kind
                        && o.period == b.period
                        && o.contact == contact
                        && (o.located.parameter - f.parameter).abs()
                            <= x_tolerance + o.located.precision + f.precision
                });
                if !twin {
                    out.push(Candidate {
                        seed: i,
                        y: seed.y,
                        kind,
                        period: b.period,
                        contact,
                        located: f.clone(),
                    });
                }
            }
        }
    }
    out
}
