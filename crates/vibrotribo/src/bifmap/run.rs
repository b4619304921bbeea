//! The map's entry point: checks, seeds, then the curves wave by wave (one wave per seed
//! value), each wave's halves in parallel.

use std::ops::ControlFlow;

use super::seeds::{Candidate, candidates, seed_branches};
use super::trace::{Half, Plane, covers, join, trace_half};
use super::types::{
    BifmapError, BifmapOptions, BifurcationMap, HalfEnd, MAX_SEEDS, MapCurve, MapRequest, Stage,
};
use crate::config::{Config, Param};
use crate::curve::canonical_key;
use crate::sweep::{Delivery, run_chunks};

/// Checks a map's request and options against `config` (what [`bifurcation_map`] checks
/// before it starts): an error naming the key, range or option at fault.
pub fn validate(config: &Config, request: &MapRequest, options: &BifmapOptions) -> Result<(), BifmapError> {
    check(config, request, options).map(|_| ())
}

/// Checks the request and options against `config`: the plane of the map.
fn check(config: &Config, request: &MapRequest, options: &BifmapOptions) -> Result<Plane, BifmapError> {
    let x = canonical_key(&request.x);
    let y = canonical_key(&request.y);
    config.check_uncoupled("bifmap")?;
    config.check_periodic("a bifurcation map (`bifmap`)")?;
    let (px, py) = (Param::new(config, &x)?, Param::new(config, &y)?);
    if px.overlaps(&py) {
        return Err(BifmapError::SameKey { x, y });
    }
    for (key, (a, b)) in [(&x, request.x_range), (&y, request.y_range)] {
        if !(a.is_finite() && b.is_finite()) || a == b {
            return Err(BifmapError::Range {
                key: key.clone(),
                from: a,
                to: b,
            });
        }
    }
    for (what, least, value) in [
        ("seed values", 1, request.seeds),
        ("starts per seed value", 2, request.x_starts),
    ] {
        if value < least || value > MAX_SEEDS {
            return Err(BifmapError::Seeds { what, least, value });
        }
    }
    if request.kinds.is_empty() {
        return Err(BifmapError::NoKinds);
    }
    for (name, least, value) in [
        ("branch points", 2, options.branch_points),
        ("curve points", 2, options.curve_points),
        ("max curves", 1, options.max_curves),
    ] {
        if value < least {
            return Err(BifmapError::Count { name, least, value });
        }
    }
    let value = |key: &String, v: f64| {
        let key = key.clone();
        move |source| BifmapError::Value {
            key,
            value: v,
            source,
        }
    };
    for xv in [request.x_range.0, request.x_range.1] {
        let at_x = config.with(&x, toml::Value::Float(xv)).map_err(value(&x, xv))?;
        for yv in [request.y_range.0, request.y_range.1] {
            at_x.with(&y, toml::Value::Float(yv)).map_err(value(&y, yv))?;
        }
    }
    Ok(Plane {
        x,
        y,
        x_range: request.x_range,
        y_range: request.y_range,
    })
}

/// The bifurcation map of `config` in two keys: the fold, period-doubling, Neimark–Sacker
/// and grazing curves (those of `request.kinds`) in the plane `x_range × y_range`.
///
/// At each of `request.seeds` values of the second key, the orbits found after a transient
/// from the configured initial state at `request.x_starts` values of the first key are
/// continued in it towards both ends of its range (one that lies on an earlier start's
/// branch is not followed again), with `options.doublings` period doublings followed. Every
/// bifurcation of a kind asked for that lies on no curve traced so far is then followed in
/// the second key towards both ends of its range, seed value by seed value from the first
/// end; one found again at a later seed is counted on its curve
/// ([`MapCurve::found_again`]), not traced twice. A curve's halves end as `curve` ends
/// them, or where they leave the plane ([`HalfEnd::LeftMap`]).
///
/// The work of each stage runs in parallel on the current rayon pool; the result does not
/// depend on the thread count. `progress` is called on the calling thread as it goes;
/// [`BifmapOptions::cancel`] stops it with what is done (`complete` false).
pub fn bifurcation_map(
    config: &Config,
    request: &MapRequest,
    options: &BifmapOptions,
    mut progress: impl FnMut(Stage),
) -> Result<BifurcationMap, BifmapError> {
    let plane = check(config, request, options)?;
    let x_span = (request.x_range.1 - request.x_range.0).abs();
    let seeds = seed_branches(config, &plane.x, &plane.y, request, options, &mut progress);
    let found = candidates(&seeds, &request.kinds, 1e-6 * x_span);
    let mut map = BifurcationMap {
        x: plane.x.clone(),
        y: plane.y.clone(),
        located: found.iter().map(Candidate::point).collect(),
        curves: Vec::new(),
        untraced: 0,
        complete: false,
        seeds,
    };
    let tolerance = 1e-4 * x_span;
    let mut halves = (0, 0);
    let mut start = 0;
    while start < found.len() && !options.cancel.requested() {
        let end = start
            + found[start..]
                .iter()
                .take_while(|c| c.y == found[start].y)
                .count();
        let wave = start..end;
        start = end;
        let fresh = fresh_candidates(&mut map, &found, wave, options.max_curves, tolerance);
        let traced = trace_wave(config, &plane, &fresh, options, &mut halves, &mut progress);
        // Two bifurcations of one wave can lie on one curve (two folds meeting at a cusp).
        for ((j, c), curve) in fresh.iter().zip(traced) {
            let on = map.curves.iter().position(|k| covers(k, c, tolerance));
            match on {
                Some(k) => map.curves[k].found_again += 1,
                None => map.curves.push(curve),
            }
            map.located[*j].curve = Some(on.unwrap_or(map.curves.len() - 1));
        }
    }
    map.complete = !options.cancel.requested();
    Ok(map)
}

/// The candidates `wave` of `found` that lie on no curve of `map` (each found again is
/// counted on its curve and its located point marked), at most as many as `max_curves`
/// leaves room for (the rest counted in `map.untraced`), with their indices.
fn fresh_candidates(
    map: &mut BifurcationMap,
    found: &[Candidate],
    wave: std::ops::Range<usize>,
    max_curves: usize,
    tolerance: f64,
) -> Vec<(usize, Candidate)> {
    let mut fresh = Vec::new();
    for j in wave {
        let c = &found[j];
        match map.curves.iter().position(|k| covers(k, c, tolerance)) {
            Some(k) => {
                map.curves[k].found_again += 1;
                map.located[j].curve = Some(k);
            }
            None => fresh.push((j, c.clone())),
        }
    }
    let room = max_curves.saturating_sub(map.curves.len());
    if fresh.len() > room {
        map.untraced += fresh.len() - room;
        fresh.truncate(room);
    }
    fresh
}

/// Traces both halves of every candidate of a wave in parallel, the curves in the order of
/// `fresh` (a half not reached before a stop ends [`HalfEnd::Stopped`]); `halves` counts the
/// halves done and known for `progress`.
fn trace_wave(
    config: &Config,
    plane: &Plane,
    fresh: &[(usize, Candidate)],
    options: &BifmapOptions,
    halves: &mut (usize, usize),
    progress: &mut dyn FnMut(Stage),
) -> Vec<MapCurve> {
    let ends = [plane.y_range.0, plane.y_range.1];
    let jobs: Vec<(usize, usize)> = fresh
        .iter()
        .enumerate()
        .flat_map(|(i, (_, c))| (0..2).filter(move |&s| c.y != ends[s]).map(move |s| (i, s)))
        .collect();
    halves.1 += jobs.len();
    progress(Stage::Curves {
        done: halves.0,
        total: halves.1,
    });
    let mut traced: Vec<[Option<Half>; 2]> = vec![[None, None]; fresh.len()];
    run_chunks(
        &jobs,
        rayon::current_num_threads().max(1),
        |&(i, s)| trace_half(config, plane, &fresh[i].1, ends[s], options),
        |d| {
            if let Delivery::Point(&(i, s), half) = d {
                traced[i][s] = Some(half);
                halves.0 += 1;
                progress(Stage::Curves {
                    done: halves.0,
                    total: halves.1,
                });
            }
            if options.cancel.requested() {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
    );
    for &(i, s) in &jobs {
        traced[i][s].get_or_insert(Half {
            curve: None,
            end: HalfEnd::Stopped,
        });
    }
    fresh
        .iter()
        .zip(traced)
        .map(|((_, c), [a, b])| join(c, a, b))
        .collect()
}
