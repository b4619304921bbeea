//! The largest Floquet multiplier of a sweep point's orbit ([`PointOptions::floquet`]), and
//! the stable orbits its shots find that the run is not on.
//!
//! For a recorded window that repeats with period p, Newton shooting starts at the window's
//! final state and converges to a periodic orbit of period p. That orbit is the window's own
//! only if one of the window's stroboscopic samples lies within the period tolerance of the
//! orbit's section state (the largest position difference over the window's amplitude, as
//! the period test measures it), or if the run, simulated on from its final state, approaches
//! it at the rate of its multipliers (the test the settling uses). Only then is its largest
//! multiplier modulus the point's `max_abs_multiplier`. Otherwise the shot left the window's
//! orbit: the point has no multiplier ([`FloquetError::OtherOrbit`]), and the orbit, if it is
//! stable and the run does not approach it, is a coexisting attractor.
//!
//! A window that does not repeat, and is not settling onto an orbit, has no orbit of its own,
//! but the run may pass close to a stable orbit it does not stay on. Newton shooting (with
//! the settling's shot settings) starts at the window's closest returns: at the three
//! periods p ≤ 12 where a sample comes nearest to the sample p before it, from that sample.
//! A stable orbit it finds that the window is not on and that the run, simulated on, does not
//! approach is a coexisting attractor too. Most shots from an irregular window end on the
//! unstable orbits embedded in it, which are not reported.
//!
//! A coexisting orbit is reported at its minimal period ([`MotionReport::coexisting`], the
//! `coexisting_period` column); the point's label stays what its run does. The run used to
//! check an approach is at most as long as the point's transient and recorded window
//! together; where it would take longer, no claim is made either way.
//!
//! [`MotionReport::coexisting`]: super::MotionReport::coexisting

use thiserror::Error;

use super::point::{PointError, PointOptions, PointResult};
use super::settle::{Shot, ShotOrbit};
use crate::analysis::{Periodicity, amplitude};
use crate::model::{ChainParams, ChainState, SimOptions};
use crate::orbits::{OrbitError, ShootingOptions, find_periodic_orbit};

/// Why a point has no largest Floquet multiplier modulus
/// ([`PointResult::max_abs_multiplier`]).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum FloquetError {
    /// Newton shooting failed (at a grazing point, say).
    #[error(transparent)]
    Shooting(#[from] OrbitError),
    /// Newton shooting from the window's final state converged to an orbit the run is not on:
    /// its multipliers are not the point's.
    #[error(
        "Newton shooting from the recorded window's end converged to a period-{period} orbit \
         (largest multiplier modulus {spectral_radius}) that the run is not on"
    )]
    OtherOrbit {
        /// The orbit's minimal period, in excitation periods.
        period: u32,
        /// Its largest multiplier modulus, taken over that period.
        spectral_radius: f64,
    },
}

/// What Floquet shooting found for a point.
pub(super) struct Floquet {
    /// The point's largest multiplier modulus, for a periodic window.
    pub(super) max_abs_multiplier: Option<Result<f64, FloquetError>>,
    /// A stable orbit the run is not on.
    pub(super) coexisting: Option<ShotOrbit>,
}

impl Floquet {
    fn none() -> Self {
        Floquet {
            max_abs_multiplier: None,
            coexisting: None,
        }
    }
}

/// Shoots the orbit of the recorded window of `point` (see the module docs of
/// `study/floquet.rs`), and with `search` seeks stable orbits near a window that does not
/// repeat, polling `options.cancel`. Fails only with [`PointError::Stopped`].
pub(super) fn floquet(
    params: &ChainParams,
    sim_options: &SimOptions,
    options: &PointOptions,
    point: &PointResult,
    search: bool,
) -> Result<Floquet, PointError> {
    let n = params.len();
    let scale = amplitude(&point.strobe);
    let shot = Shot {
        params,
        sim_options,
        scale,
        tolerance: options.period_tolerance,
        cancel: &options.cancel,
    };
    let budget = options.transient_periods + options.recorded_periods;
    let on_window =
        |state: &ChainState| closest(&point.strobe, n, &state.positions) <= options.period_tolerance * scale;
    match point.periodicity {
        Some(Periodicity::Periodic { period, .. }) => {
            let found = find_periodic_orbit(
                params,
                &point.final_state,
                period as u32,
                &ShootingOptions {
                    sim: sim_options.clone(),
                    cancel: options.cancel.clone(),
                    ..ShootingOptions::default()
                },
            );
            if options.cancel.requested() {
                return Err(PointError::Stopped { periods: 0 });
            }
            let orbit = match found {
                Ok(orbit) => orbit,
                Err(e) => {
                    return Ok(Floquet {
                        max_abs_multiplier: Some(Err(e.into())),
                        coexisting: None,
                    });
                }
            };
            let approached = if on_window(&orbit.state) {
                Some(true)
            } else {
                unless_failed(shot.approaches(&point.final_state, &orbit, budget))?.flatten()
            };
            if approached == Some(true) {
                return Ok(Floquet {
                    max_abs_multiplier: Some(Ok(orbit.spectral_radius())),
                    coexisting: None,
                });
            }
            let other = unless_failed(shot.minimal(&orbit))?.unwrap_or_else(|| ShotOrbit {
                period: orbit.period,
                spectral_radius: orbit.spectral_radius(),
                state: orbit.state.clone(),
            });
            Ok(Floquet {
                max_abs_multiplier: Some(Err(FloquetError::OtherOrbit {
                    period: other.period,
                    spectral_radius: other.spectral_radius,
                })),
                coexisting: (approached == Some(false)).then_some(other),
            })
        }
        Some(Periodicity::NonPeriodic { .. }) if search => {
            for (p, seed) in close_returns(point, n) {
                let Some(orbit) = shot.shoot(&seed, p as u32)? else {
                    continue;
                };
                if !orbit.stable || on_window(&orbit.state) {
                    continue;
                }
                if let Some(Some(false)) = unless_failed(shot.approaches(&point.final_state, &orbit, budget))?
                    && let Some(o) = unless_failed(shot.minimal(&orbit))?
                {
                    return Ok(Floquet {
                        max_abs_multiplier: None,
                        coexisting: Some(o),
                    });
                }
            }
            Ok(Floquet::none())
        }
        _ => Ok(Floquet::none()),
    }
}

/// A check's result, `None` where its run failed (an event limit, say: the check then makes
/// no claim); a stop is passed on.
fn unless_failed<T>(r: Result<T, PointError>) -> Result<Option<T>, PointError> {
    match r {
        Ok(v) => Ok(Some(v)),
        Err(e @ PointError::Stopped { .. }) => Err(e),
        Err(_) => Ok(None),
    }
}

/// The smallest distance, in the largest coordinate, between `x` and the samples of
/// `positions` (`n` per sample); infinite without samples.
fn closest(positions: &[f64], n: usize, x: &[f64]) -> f64 {
    positions
        .chunks_exact(n)
        .map(|s| s.iter().zip(x).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max))
        .fold(f64::INFINITY, f64::min)
}

/// Periods at which a window that does not repeat is searched for stable orbits: up to
/// this, the [`SEARCHED`] whose closest returns come nearest.
const SEARCH_PERIODS: usize = 12;

/// Shots a window that does not repeat gets ([`close_returns`]).
const SEARCHED: usize = 3;

/// The [`SEARCHED`] periods p ≤ [`SEARCH_PERIODS`] at which the recorded window comes closest
/// to repeating somewhere (the smallest distance, in the largest coordinate, between a sample
/// and the one p before it), nearest first, each with the state of that sample: where a
/// search for an orbit of period p starts.
fn close_returns(point: &PointResult, n: usize) -> Vec<(usize, ChainState)> {
    let rows: Vec<&[f64]> = point.strobe.chunks_exact(n).collect();
    let distance = |j: usize, p: usize| closest(rows[j - p], n, rows[j]);
    let mut best: Vec<(f64, usize, usize)> = (1..=SEARCH_PERIODS.min(rows.len().saturating_sub(1)))
        .filter_map(|p| {
            (p..rows.len())
                .map(|j| (distance(j, p), p, j))
                .min_by(|a, b| a.0.total_cmp(&b.0))
        })
        .collect();
    best.sort_by(|a, b| a.0.total_cmp(&b.0));
    best.into_iter()
        .take(SEARCHED)
        .filter_map(|(_, p, j)| {
            Some((
                p,
                ChainState {
                    positions: rows[j].to_vec(),
                    velocities: point.strobe_velocities.get(j * n..(j + 1) * n)?.to_vec(),
                },
            ))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::run_point;

    /// Fig. 7's chain (m = 90, 120, 90 g, Ω = 0.70) at spacing ratio `r`.
    fn fig7(r: f64) -> ChainParams {
        let mut p = ChainParams {
            masses: vec![0.09, 0.12, 0.09],
            ..ChainParams::default()
        };
        p.gaps[1] = r * p.gaps[0];
        p
    }

    /// The point at R_δ = 1.09 reached by a continuation in R_δ from `from` (from rest) in 5
    /// steps: on the four-impact orbit from 1.0, on the two-impact one from 1.2.
    fn continued(from: f64, floquet: bool) -> PointResult {
        let mut state = ChainState::at_rest(3);
        for k in 0..5 {
            let p = fig7(from + (1.09 - from) * f64::from(k) / 5.0);
            state = run_point(&p, &state, &SimOptions::default(), None, &PointOptions::default())
                .unwrap()
                .final_state;
        }
        let options = PointOptions {
            floquet,
            ..PointOptions::default()
        };
        run_point(&fig7(1.09), &state, &SimOptions::default(), None, &options).unwrap()
    }

    /// A window on one attractor of Fig. 7's bistable chain that passes within 1e-3 of the
    /// other (twice in a row, its closest return) and does not repeat: the shot from there
    /// finds the other, stable orbit, the window is not on it and the run, simulated on from
    /// its end, does not approach it: a coexisting orbit, of period 1 and the multiplier of
    /// that attractor's own run. With the run's end on that orbit instead, the run goes
    /// there, and nothing is claimed.
    #[test]
    fn a_stable_orbit_the_window_passes_but_does_not_stay_on_is_coexisting() {
        let (up, down) = (continued(1.0, false), continued(1.2, true));
        assert!(
            (up.total_impacts_per_period() - down.total_impacts_per_period()).abs() > 1.0,
            "the two attractors"
        );
        let other = *down.max_abs_multiplier.as_ref().unwrap().as_ref().unwrap();
        let mut window = up.clone();
        let scale = amplitude(&window.strobe);
        for j in [10, 11] {
            for i in 0..3 {
                window.strobe[3 * j + i] = down.final_state.positions[i] + 1e-3 * scale;
                window.strobe_velocities[3 * j + i] = down.final_state.velocities[i];
            }
        }
        window.periodicity = Some(Periodicity::NonPeriodic {
            closest_period: 1,
            mismatch: 0.1,
        });
        let params = fig7(1.09);
        let options = PointOptions {
            floquet: true,
            ..PointOptions::default()
        };
        let f = floquet(&params, &SimOptions::default(), &options, &window, true).unwrap();
        let o = f.coexisting.expect("the other attractor is coexisting");
        assert!(f.max_abs_multiplier.is_none());
        assert_eq!(o.period, 1);
        assert!(
            (o.spectral_radius - other).abs() < 1e-9,
            "{} vs {other}",
            o.spectral_radius
        );
        // Not searched: nothing.
        let f = floquet(&params, &SimOptions::default(), &options, &window, false).unwrap();
        assert!(f.coexisting.is_none());
        // A run that ends on that orbit goes there.
        window.final_state = down.final_state.clone();
        let f = floquet(&params, &SimOptions::default(), &options, &window, true).unwrap();
        assert!(f.coexisting.is_none(), "{:?}", f.coexisting.map(|o| o.period));
    }
}
