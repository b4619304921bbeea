//! The kinds of plot: lines, points, phase portraits and heat maps, each written to a PNG or
//! SVG file.

use super::figure::{Figure, HeatMap, Series};
use super::style::{finite_bounds, widen};
use super::xy::check_series;
use super::xy::{HeatChart, Layers, write, xy_chart};
use anyhow::{Result, anyhow, ensure};
use std::path::Path;

/// Lines (solid or dashed) with marks of `marker_px` pixels on top, each series in its
/// colour: e.g. branches of periodic orbits over an orbit diagram.
pub fn lines_and_points(
    path: &Path,
    figure: &Figure,
    lines: &[Series<'_>],
    points: &[Series<'_>],
    marker_px: u32,
) -> Result<()> {
    let layers = Layers {
        lines,
        points,
        marker_px,
    };
    write(path, figure.size, &xy_chart(figure, layers)?)
}

/// Lines through each series, one colour per series.
pub fn line_plot(path: &Path, figure: &Figure, series: &[Series<'_>]) -> Result<()> {
    let layers = Layers {
        lines: series,
        points: &[],
        marker_px: 1,
    };
    write(path, figure.size, &xy_chart(figure, layers)?)
}

/// Each series as points of `marker_px` pixels (1 = single pixels, the usual choice for
/// orbit diagrams), one colour per series. Fast for millions of points: each occupied pixel
/// is drawn once.
pub fn scatter_plot(path: &Path, figure: &Figure, series: &[Series<'_>], marker_px: u32) -> Result<()> {
    let layers = Layers {
        lines: &[],
        points: series,
        marker_px,
    };
    write(path, figure.size, &xy_chart(figure, layers)?)
}

/// Phase portrait: each trajectory (x = position, y = velocity) as a line, and the
/// Poincaré `section` points (if any) as black 7-pixel marks on top.
pub fn phase_portrait(
    path: &Path,
    figure: &Figure,
    trajectories: &[Series<'_>],
    section: Option<Series<'_>>,
) -> Result<()> {
    let points: Vec<Series<'_>> = section.into_iter().collect();
    let layers = Layers {
        lines: trajectories,
        points: &points,
        marker_px: 7,
    };
    write(path, figure.size, &xy_chart(figure, layers)?)
}

/// A heat map of `map` with a colour bar on the right.
pub fn heat_map(path: &Path, figure: &Figure, map: &HeatMap<'_>) -> Result<()> {
    heat_map_with(path, figure, map, &[], &[], 1)
}

/// A heat map of `map` with a colour bar on the right, and `lines` and `points` (marks of
/// `marker_px` pixels) in the map's coordinates drawn over it, with their legend: e.g.
/// bifurcation curves over a power map.
pub fn heat_map_with(
    path: &Path,
    figure: &Figure,
    map: &HeatMap<'_>,
    lines: &[Series<'_>],
    points: &[Series<'_>],
    marker_px: u32,
) -> Result<()> {
    ensure!(
        map.nx > 0 && map.ny > 0,
        "heat map grid is empty ({} × {} cells)",
        map.nx,
        map.ny
    );
    ensure!(
        map.values.len() == map.nx * map.ny,
        "heat map has {} values for {} × {} cells",
        map.values.len(),
        map.nx,
        map.ny
    );
    for (i, s) in lines.iter().chain(points).enumerate() {
        check_series(s, i)?;
    }
    for (name, (a, b)) in [("x", map.x_edges), ("y", map.y_edges)] {
        ensure!(
            a.is_finite() && b.is_finite() && a < b,
            "heat map {name} edges must be finite and increasing, got {a} to {b}"
        );
    }
    let (lo, hi) = match map.colour_range {
        Some((lo, hi)) => {
            ensure!(
                lo.is_finite() && hi.is_finite() && lo < hi,
                "colour range must be finite and increasing, got {lo} to {hi}"
            );
            (lo, hi)
        }
        None => {
            let (lo, hi) = finite_bounds(map.values.iter().copied())
                .ok_or_else(|| anyhow!("heat map has no finite value to colour"))?;
            widen(lo, hi)
        }
    };
    write(
        path,
        figure.size,
        &HeatChart {
            figure,
            map,
            range: (lo, hi),
            layers: Layers {
                lines,
                points,
                marker_px,
            },
        },
    )
}
