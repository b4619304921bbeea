//! Figure helpers: orbit and impact-velocity diagrams, scatter plots, return maps, time
//! histories, running power.

use std::path::Path;

use anyhow::Result;
use vibrotribo::study::PointResult;

use super::context::Ctx;
use super::runs::Series1;
use crate::plot::{self, Figure, Legend, Scale, Series};

/// Draws `draw` as PNG and SVG in the output directory; returns the PNG's file name.
pub(super) fn both(ctx: &Ctx, name: &str, draw: impl Fn(&Path) -> Result<()>) -> Result<String> {
    crate::plot::both(&ctx.out, name, draw)?;
    Ok(format!("{name}.png"))
}

pub(super) fn orbit_points(
    values: &[f64],
    results: &[PointResult],
    mass: usize,
    scale: f64,
) -> (Vec<f64>, Vec<f64>) {
    let mut xs = Vec::new();
    let mut ys = Vec::new();
    for (v, r) in values.iter().zip(results) {
        for x in r.position_series(mass) {
            xs.push(*v);
            ys.push(x * scale);
        }
    }
    (xs, ys)
}

/// Closing speeds, m/s, of the impacts of `r` at `contact` (0-based).
pub(super) fn closing_speeds(r: &PointResult, contact: usize) -> impl Iterator<Item = f64> + '_ {
    r.impacts
        .iter()
        .filter(move |i| i.contact == contact)
        .map(|i| i.closing_speed)
}

pub(super) fn impact_points(values: &[f64], results: &[PointResult], contact: usize) -> (Vec<f64>, Vec<f64>) {
    let mut xs = Vec::new();
    let mut ys = Vec::new();
    for (v, r) in values.iter().zip(results) {
        for speed in closing_speeds(r, contact) {
            xs.push(*v);
            ys.push(speed);
        }
    }
    (xs, ys)
}

/// An orbit diagram (one mass's stroboscopic samples against the parameter, times `scale`).
#[allow(clippy::too_many_arguments)]
pub(super) fn orbit_figure(
    ctx: &Ctx,
    name: &str,
    title: &str,
    xl: &str,
    yl: &str,
    values: &[f64],
    results: &[PointResult],
    scale: f64,
) -> Result<String> {
    let (x, y) = orbit_points(values, results, 1, scale);
    scatter(ctx, name, Figure::new(title, xl, yl), &x, &y, 2)
}

/// An impact-velocity diagram (closing speeds at `contact` against the parameter).
#[allow(clippy::too_many_arguments)]
pub(super) fn impact_figure(
    ctx: &Ctx,
    name: &str,
    title: &str,
    xl: &str,
    yl: &str,
    values: &[f64],
    results: &[PointResult],
    contact: usize,
) -> Result<String> {
    let (x, y) = impact_points(values, results, contact);
    scatter(ctx, name, Figure::new(title, xl, yl), &x, &y, 2)
}

/// The points (`x`, `y`) as marks of `marker_px` pixels, without a legend.
pub(super) fn scatter(
    ctx: &Ctx,
    name: &str,
    mut fig: Figure,
    x: &[f64],
    y: &[f64],
    marker_px: u32,
) -> Result<String> {
    fig.legend = Legend::Hidden;
    both(ctx, name, |p| {
        plot::scatter_plot(p, &fig, &[Series::unlabelled(x, y)], marker_px)
    })
}

/// The return map (Poincaré section) X(n+1) against X(n) of mass `mass` (0-based) of `p`,
/// X = x/`delta1` at t = nT.
pub(super) fn return_map(
    ctx: &Ctx,
    name: &str,
    title: String,
    p: &PointResult,
    mass: usize,
    delta1: f64,
    marker_px: u32,
) -> Result<String> {
    let x: Vec<f64> = p.position_series(mass).map(|x| x / delta1).collect();
    let next = &x[x.len().min(1)..];
    let label = format!("X{}", mass + 1);
    let fig = Figure::new(title, format!("{label}(n)"), format!("{label}(n+1)"));
    scatter(ctx, name, fig, &x[..next.len()], next, marker_px)
}

pub(super) fn lines(
    ctx: &Ctx,
    name: &str,
    fig: &Figure,
    series: &[(&str, &[f64], &[f64])],
) -> Result<String> {
    both(ctx, name, |p| {
        let s: Vec<Series> = series.iter().map(|(l, x, y)| Series::new(l, x, y)).collect();
        plot::line_plot(p, fig, &s)
    })
}

/// The gap D1 of `s` at `at` (e.g. `R_δ = 1.085`): its time history (title ending in
/// `history`) and its phase plot, as `{fig}_d1_{tag}` and `{fig}_phase_{tag}`.
pub(super) fn d1_figures(
    ctx: &Ctx,
    s: &Series1,
    (fig, tag): (&str, f64),
    at: &str,
    history: &str,
) -> Result<[String; 2]> {
    let time = Figure::new(format!("D1 at {at}{history}"), "time t [s]", "D1 [m]");
    let phase = Figure::new(format!("D1 at {at}: phase plot"), "D1 [m]", "dD1/dt [m/s]");
    Ok([
        lines(ctx, &format!("{fig}_d1_{tag}"), &time, &[("D1", &s.t, &s.d[0])])?,
        lines(
            ctx,
            &format!("{fig}_phase_{tag}"),
            &phase,
            &[("D1", &s.d[0], &s.rate[0])],
        )?,
    ])
}

/// Running average powers P_a(N), W, each (label, curve), against the number of periods N.
pub(super) fn running_power(
    ctx: &Ctx,
    name: &str,
    title: String,
    y_scale: Scale,
    curves: &[(String, Vec<f64>)],
) -> Result<String> {
    let mut fig = Figure::new(title, "periods N_p", "P_a [W]");
    fig.y_scale = y_scale;
    let longest = curves.iter().map(|(_, c)| c.len()).max().unwrap_or(0);
    let n: Vec<f64> = (1..=longest).map(|k| k as f64).collect();
    let series: Vec<(&str, &[f64], &[f64])> = curves
        .iter()
        .map(|(l, c)| (l.as_str(), &n[..c.len()], c.as_slice()))
        .collect();
    lines(ctx, name, &fig, &series)
}
