//! The branches behind an orbit diagram of the paper: its periodic orbits continued through
//! grazing and onto doubled branches, from both ends of the diagram's range and from the
//! periodic stretches of the brute-force diagram they do not reach, drawn over the very
//! same brute-force points, and where the two disagree, in numbers.

use anyhow::Result;
use vibrotribo::ChainParams;
use vibrotribo::branch::{BranchOptions, config_family, continue_config};
use vibrotribo::config::Config;
use vibrotribo::orbits::{Continuation, ContinuationOptions, ShootingOptions};
use vibrotribo::study::PointResult;

use super::context::Ctx;
use crate::branch_picture::{Axes, Drawing, draw_over, section_positions};
use crate::progress::check_interrupt;

/// A brute-force orbit diagram of the report (each value from rest) to draw branches over.
pub(super) struct Diagram<'a> {
    /// File stem of the picture.
    pub name: &'a str,
    /// Its title.
    pub title: String,
    /// The parameter's label.
    pub x_label: &'a str,
    /// The configuration.
    pub base: &'a Config,
    /// The swept key.
    pub key: &'a str,
    /// The values.
    pub values: &'a [f64],
    /// The brute-force runs, one per value.
    pub results: &'a [PointResult],
}

/// A stable stretch of a branch as the comparison reads it: parameters, and the orbit's
/// X2 = x2/δ1 at t = kT (k = 0 … P − 1) at each point.
struct Stretch {
    period: u32,
    stable: Vec<bool>,
    parameter: Vec<f64>,
    sections: Vec<Vec<f64>>,
}

/// How a value of the diagram compares with the continued branches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Class {
    /// Periodic, on a continued stable branch of its period; or not periodic with no stable
    /// continued orbit there.
    Agrees,
    /// Periodic (period P), on no continued branch of period P.
    Missed(usize),
    /// Periodic (period P), on a continued branch of period P labelled unstable there.
    OnUnstable(usize),
    /// Not periodic from rest, but a continued orbit there is stable (another attractor
    /// from rest).
    Elsewhere,
    /// Periodic (period P) but not on the stable continued orbits there (another attractor
    /// from rest).
    OtherOrbit(usize),
}

fn lerp(a: f64, b: f64, t: f64) -> f64 {
    a + t * (b - a)
}

/// Whether the brute-force samples `samples` (one period's worth) lie on the orbit of a
/// segment `j, j + 1` of `s` at parameter `v`, within `tolerance` plus the segment's extent.
fn on_segment(s: &Stretch, j: usize, v: f64, samples: &[f64], tolerance: f64) -> bool {
    let (pa, pb) = (s.parameter[j], s.parameter[j + 1]);
    let t = if pa == pb { 0.0 } else { (v - pa) / (pb - pa) };
    let (a, b) = (&s.sections[j], &s.sections[j + 1]);
    samples.iter().all(|x| {
        a.iter().zip(b).any(|(&p, &q)| {
            let at = lerp(p, q, t);
            (x - at).abs() <= tolerance + (p - q).abs()
        })
    })
}

/// The segments of `s` that bracket `v`, with whether both ends are stable.
fn brackets(s: &Stretch, v: f64) -> impl Iterator<Item = (usize, bool)> + '_ {
    s.parameter
        .windows(2)
        .enumerate()
        .filter(move |(_, w)| (w[0] - v) * (w[1] - v) <= 0.0)
        .map(|(j, _)| (j, s.stable[j] && s.stable[j + 1]))
}

/// The class of each value of the diagram.
fn classify(d: &Diagram<'_>, scale: f64, stretches: &[Stretch]) -> Vec<Class> {
    let all: Vec<f64> = d
        .results
        .iter()
        .flat_map(|r| r.position_series(1).map(|x| x * scale).collect::<Vec<_>>())
        .collect();
    let (lo, hi) = all.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
        (a.min(x), b.max(x))
    });
    let tolerance = 0.02 * (hi - lo).max(f64::MIN_POSITIVE);
    d.values
        .iter()
        .zip(d.results)
        .map(|(&v, r)| {
            let p = r.period();
            let stable_here = stretches.iter().any(|s| brackets(s, v).any(|(_, stable)| stable));
            if p == 0 {
                return if stable_here {
                    Class::Elsewhere
                } else {
                    Class::Agrees
                };
            }
            let series: Vec<f64> = r.position_series(1).map(|x| x * scale).collect();
            let samples = &series[series.len().saturating_sub(p)..];
            let mut unstable = false;
            for s in stretches.iter().filter(|s| s.period as usize == p) {
                for (j, stable) in brackets(s, v) {
                    if on_segment(s, j, v, samples, tolerance) {
                        if stable {
                            return Class::Agrees;
                        }
                        unstable = true;
                    }
                }
            }
            if unstable {
                Class::OnUnstable(p)
            } else if stable_here {
                Class::OtherOrbit(p)
            } else {
                Class::Missed(p)
            }
        })
        .collect()
}

/// The stretches of consecutive values of one class, as `a–b (period P)` texts.
fn stretches_of(values: &[f64], classes: &[Class], want: impl Fn(Class) -> bool) -> Vec<String> {
    let mut out = Vec::new();
    let mut j = 0;
    while j < classes.len() {
        if !want(classes[j]) {
            j += 1;
            continue;
        }
        let start = j;
        while j + 1 < classes.len() && classes[j + 1] == classes[start] {
            j += 1;
        }
        let period = match classes[start] {
            Class::Missed(p) | Class::OnUnstable(p) | Class::OtherOrbit(p) => format!(" (period {p})"),
            _ => String::new(),
        };
        out.push(if start == j {
            format!("{:.4}{period}", values[start])
        } else {
            format!("{:.4}–{:.4}{period}", values[start], values[j])
        });
        j += 1;
    }
    out
}

/// The largest stretch of values periodic on brute force and on no continued branch (at
/// least three values): the index of its middle.
fn largest_gap(classes: &[Class]) -> Option<usize> {
    let mut best: Option<(usize, usize)> = None;
    let mut j = 0;
    while j < classes.len() {
        if !matches!(classes[j], Class::Missed(_)) {
            j += 1;
            continue;
        }
        let start = j;
        while j + 1 < classes.len() && classes[j + 1] == classes[start] {
            j += 1;
        }
        if j - start + 1 >= 3 && best.is_none_or(|(a, b)| j - start > b - a) {
            best = Some((start, j));
        }
        j += 1;
    }
    best.map(|(a, b)| (a + b) / 2)
}

/// The stretches of every branch of `continuations`.
fn stretches(d: &Diagram<'_>, scale: f64, continuations: &[Continuation]) -> Vec<Stretch> {
    let family = config_family(d.base, d.key);
    continuations
        .iter()
        .flat_map(|c| &c.branches)
        .map(|b| Stretch {
            period: b.period,
            stable: b.points.iter().map(|p| p.stable).collect(),
            parameter: b.points.iter().map(|p| p.parameter).collect(),
            sections: b
                .points
                .iter()
                .map(|p| {
                    section_positions(&family(p.parameter), &p.state, b.period, 1, d.base)
                        .into_iter()
                        .map(|x| x * scale)
                        .collect()
                })
                .collect(),
        })
        .collect()
}

/// The branches of the diagram's configuration over its brute-force points:
/// `{name}.png`/`.svg`, and the comparison in words (with the class counts, for a verdict:
/// values that agree and values in all).
pub(super) fn branches_over(ctx: &Ctx, d: &Diagram<'_>) -> Result<(String, String, (usize, usize))> {
    let scale = 1.0 / d.base.chain().gaps[0];
    let options = BranchOptions {
        transient: 300,
        period: None,
        continuation: ContinuationOptions {
            doubling_depth: 2,
            max_points: if ctx.quick { 800 } else { 2000 },
            shooting: ShootingOptions {
                sim: d.base.sim_options().clone(),
                cancel: crate::progress::orbit_cancel(),
                ..ShootingOptions::default()
            },
            ..ContinuationOptions::default()
        },
    };
    let (first, last) = (d.values[0], d.values[d.values.len() - 1]);
    let mut continuations: Vec<Continuation> = [(first, last), (last, first)]
        .iter()
        .filter_map(|&(a, b)| continue_config(d.base, d.key, a, b, None, &options).ok())
        .collect();
    let mut all = stretches(d, scale, &continuations);
    let mut classes = classify(d, scale, &all);
    // Orbits the ends do not reach: continued from a brute-force state in the middle of the
    // largest periodic stretch that no branch accounts for.
    let mut extra = 0;
    for _ in 0..if ctx.quick { 1 } else { 3 } {
        let Some(j) = largest_gap(&classes) else { break };
        let r = &d.results[j];
        let guess = (r.final_state.clone(), r.period() as u32);
        let v = d.values[j];
        for end in [first, last] {
            if let Ok(c) = continue_config(d.base, d.key, v, end, Some(guess.clone()), &options) {
                continuations.push(c);
            }
        }
        extra += 1;
        all = stretches(d, scale, &continuations);
        classes = classify(d, scale, &all);
    }
    check_interrupt(|| "during a continuation; REPORT.md is written only by a complete run".into())?;
    let (dx, dy): (Vec<f64>, Vec<f64>) = d
        .values
        .iter()
        .zip(d.results)
        .flat_map(|(&v, r)| {
            r.position_series(1)
                .map(move |x| (v, x * scale))
                .collect::<Vec<_>>()
        })
        .unzip();
    let mut drawing = Drawing::default();
    for c in &continuations {
        drawing.branches.extend(Drawing::of(c).branches);
    }
    let axes = Axes {
        title: d.title.clone(),
        x_label: d.x_label.to_string(),
        y_label: "X2 = x2/δ1 at t = nT".into(),
        mass: 1,
        scale,
    };
    let family = config_family(d.base, d.key);
    draw_over(
        &ctx.out,
        d.name,
        d.base,
        &axes,
        (&dx, &dy),
        &drawing,
        &|p: f64| -> ChainParams { family(p) },
    )?;
    let count = |f: fn(Class) -> bool| classes.iter().filter(|c| f(**c)).count();
    let periodic = d.results.iter().filter(|r| r.period() > 0).count();
    let agree = count(|c| c == Class::Agrees);
    let branches: usize = continuations.iter().map(|c| c.branches.len()).sum();
    let list = |f: fn(Class) -> bool| {
        let s = stretches_of(d.values, &classes, f);
        if s.is_empty() {
            "none".to_string()
        } else {
            s.join(", ")
        }
    };
    let text = format!(
        "{} branches continued from both ends{}; of {} values ({periodic} periodic from rest) {agree} agree with them (a periodic run on a stable continued orbit of its period within 2 % of the diagram's height, or a non-periodic run where no continued orbit is stable). Periodic from rest on no continued branch: {} values ({}). Periodic on a continued branch labelled unstable there: {} ({}). A stable continued orbit that the run from rest does not reach (another attractor): {} values non-periodic from rest ({}), {} periodic on another orbit ({}).",
        branches,
        if extra > 0 {
            format!(
                " and from {extra} brute-force state{} they did not reach",
                if extra > 1 { "s" } else { "" }
            )
        } else {
            String::new()
        },
        d.values.len(),
        count(|c| matches!(c, Class::Missed(_))),
        list(|c| matches!(c, Class::Missed(_))),
        count(|c| matches!(c, Class::OnUnstable(_))),
        list(|c| matches!(c, Class::OnUnstable(_))),
        count(|c| c == Class::Elsewhere),
        list(|c| c == Class::Elsewhere),
        count(|c| matches!(c, Class::OtherOrbit(_))),
        list(|c| matches!(c, Class::OtherOrbit(_))),
    );
    Ok((format!("{}.png", d.name), text, (agree, d.values.len())))
}
