//! Tracing a map's curves: each half of a curve from its seed towards one end of the second
//! key's range, on a family of chains bounded to the plane of the map, and whether a curve
//! already traced passes through a bifurcation located elsewhere.

use std::sync::atomic::{AtomicUsize, Ordering};

use super::seeds::Candidate;
use super::types::{BifmapOptions, HalfEnd, MapCurve};
use crate::ChainParams;
use crate::config::Config;
use crate::curve::{config_family2, curve_start_of};
use crate::orbits::curve::{Curve, CurveEnd, CurveOptions, continue_curve};
use crate::orbits::{Cancel, ShootingOptions};

/// Fraction of each range by which the plane of a map is widened before a curve counts as
/// leaving it.
pub(super) const MARGIN: f64 = 0.05;

/// Largest arclength step of a map's curves, in the scaled units of
/// [`CurveOptions`](crate::orbits::curve::CurveOptions) (whose own default is 0.05): a map
/// wants the whole curve across the plane more than its fine detail, and the corrector
/// halves a step that fails.
pub(super) const MAX_STEP: f64 = 0.2;

/// The plane of a map: its keys and ranges.
#[derive(Debug, Clone)]
pub(super) struct Plane {
    pub x: String,
    pub y: String,
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
}

impl Plane {
    /// `(lo, hi)` of a range widened by [`MARGIN`] of its width on both sides.
    fn widened((a, b): (f64, f64)) -> (f64, f64) {
        let (lo, hi) = (a.min(b), a.max(b));
        let m = MARGIN * (hi - lo);
        (lo - m, hi + m)
    }

    /// Whether `(p1, p2)` lies in the widened plane.
    fn contains(&self, p1: f64, p2: f64) -> bool {
        let (x0, x1) = Self::widened(self.x_range);
        let (y0, y1) = Self::widened(self.y_range);
        (x0..=x1).contains(&p1) && (y0..=y1).contains(&p2)
    }

    /// Whether `(p1, p2)` lies within twice [`MARGIN`] of an edge of the widened plane, or
    /// outside it.
    fn near_edge(&self, p1: f64, p2: f64) -> bool {
        let near = |v: f64, (a, b): (f64, f64)| {
            let (lo, hi) = Self::widened((a, b));
            let m = 2.0 * MARGIN * (b - a).abs();
            v <= lo + m || v >= hi - m
        };
        near(p1, self.x_range) || near(p2, self.y_range)
    }
}

/// The chains of `config` in the plane (`config_family2`), refusing (a chain that fails its
/// validation, so that the corrector fails at once) every point outside the widened plane
/// and every point once `cancel` asks to stop; `refused` counts the points refused.
fn bounded_family<'a>(
    config: &'a Config,
    plane: &'a Plane,
    cancel: &'a Cancel,
    refused: &'a AtomicUsize,
) -> impl Fn(f64, f64) -> ChainParams + 'a {
    let inner = config_family2(config, &plane.x, &plane.y);
    let n = config.chain().len();
    move |p1: f64, p2: f64| {
        if cancel.requested() || !plane.contains(p1, p2) {
            refused.fetch_add(1, Ordering::Relaxed);
            return ChainParams {
                masses: vec![f64::NAN; n],
                ..config.chain().clone()
            };
        }
        inner(p1, p2)
    }
}

/// One half of a curve: its points, codimension-two points, and why it ended.
#[derive(Debug, Clone)]
pub(super) struct Half {
    pub curve: Option<Curve>,
    pub end: HalfEnd,
}

/// Traces the curve through `c` from its seed value towards `towards`.
pub(super) fn trace_half(
    config: &Config,
    plane: &Plane,
    c: &Candidate,
    towards: f64,
    options: &BifmapOptions,
) -> Half {
    let refused = AtomicUsize::new(0);
    let family = bounded_family(config, plane, &options.cancel, &refused);
    let curve_options = CurveOptions {
        max_points: options.curve_points,
        max_step: MAX_STEP,
        shooting: ShootingOptions {
            sim: config.sim_options().clone(),
            ..ShootingOptions::default()
        },
        ..CurveOptions::default()
    };
    let start = curve_start_of(&c.located, c.period);
    let result = continue_curve(&family, c.kind, &start, c.y, towards, &curve_options);
    let stopped = options.cancel.requested();
    match result {
        Err(_) if stopped => Half {
            curve: None,
            end: HalfEnd::Stopped,
        },
        Err(e) => Half {
            curve: None,
            end: HalfEnd::NoStart(e),
        },
        Ok(curve) => {
            let end = half_end(plane, &curve, stopped, refused.load(Ordering::Relaxed) > 0);
            Half {
                curve: Some(curve),
                end,
            }
        }
    }
}

/// Why a traced half ended, in the map's terms.
fn half_end(plane: &Plane, curve: &Curve, stopped: bool, refused: bool) -> HalfEnd {
    let last = curve.points.last();
    match &curve.end {
        CurveEnd::StepFloor { .. } if stopped => HalfEnd::Stopped,
        CurveEnd::StepFloor { .. }
            if refused && last.is_some_and(|p| plane.near_edge(p.parameter, p.parameter2)) =>
        {
            let p = last.expect("checked above");
            HalfEnd::LeftMap {
                x: p.parameter,
                y: p.parameter2,
            }
        }
        end => HalfEnd::Curve(end.clone()),
    }
}

/// The curve of `c` from its two halves (`first` towards `y_range.0`, `second` towards
/// `y_range.1`; `None` where the seed sits on that end).
pub(super) fn join(c: &Candidate, first: Option<Half>, second: Option<Half>) -> MapCurve {
    let mut points = Vec::new();
    let mut codim2 = Vec::new();
    if let Some(Half { curve: Some(h), .. }) = &first {
        points.extend(h.points.iter().rev().map(|p| {
            let mut p = p.clone();
            p.arclength = -p.arclength;
            p
        }));
        codim2.extend(h.codim2.iter().rev().map(|q| {
            let mut q = q.clone();
            q.point.arclength = -q.point.arclength;
            q
        }));
    }
    if let Some(Half { curve: Some(h), .. }) = &second {
        // Both halves start at the seed's point: keep it once.
        let skip = usize::from(!points.is_empty());
        points.extend(h.points.iter().skip(skip).cloned());
        codim2.extend(h.codim2.iter().cloned());
    }
    let contact = first
        .iter()
        .chain(&second)
        .find_map(|h| h.curve.as_ref().and_then(|c| c.contact))
        .or(c.contact);
    MapCurve {
        kind: c.kind,
        period: c.period,
        contact,
        seed: c.seed,
        located: c.located.clone(),
        points,
        codim2,
        ends: [first.map(|h| h.end), second.map(|h| h.end)],
        found_again: 0,
    }
}

/// Whether `curve` passes through the bifurcation `c`: same kind, period and contact, and a
/// segment of the curve crossing the seed value `c.y` at a first-key value within the
/// segment's own extent in it (plus `x_tolerance`) of `c`'s.
pub(super) fn covers(curve: &MapCurve, c: &Candidate, x_tolerance: f64) -> bool {
    if curve.kind != c.kind || curve.period != c.period || curve.contact != c.contact {
        return false;
    }
    let x = c.located.parameter;
    let y = c.y;
    let close = |xa: f64, xb: f64, x_at: f64| (x_at - x).abs() <= (xa - xb).abs() + x_tolerance;
    if let [only] = curve.points.as_slice() {
        return only.parameter2 == y && close(only.parameter, only.parameter, only.parameter);
    }
    curve.points.windows(2).any(|w| {
        let (a, b) = (&w[0], &w[1]);
        let (ya, yb) = (a.parameter2 - y, b.parameter2 - y);
        if ya * yb > 0.0 {
            return false;
        }
        let t = if ya == yb { 0.0 } else { ya / (ya - yb) };
        close(
            a.parameter,
            b.parameter,
            a.parameter + t * (b.parameter - a.parameter),
        )
    })
}
