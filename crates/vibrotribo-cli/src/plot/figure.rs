//! The figures: their description (title, axes, scales, legend), the data series, and the
//! four kinds of plot.

use super::xy::{HeatChart, Layers, finite_bounds, widen, write, xy_chart};
use anyhow::{Result, anyhow, bail, ensure};
use plotters::style::{FontStyle, register_font};
use std::path::Path;
use std::sync::OnceLock;

/// DejaVu Sans, embedded (see `assets/DejaVuSans-LICENSE`).
pub(super) static FONT_DATA: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

/// The font family every text element asks for; the embedded font is registered under it.
pub(super) const FAMILY: &str = "sans-serif";

/// Registers the embedded font once per process.
pub(super) fn ensure_font() -> Result<()> {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| register_font(FAMILY, FontStyle::Normal, FONT_DATA).is_ok());
    ensure!(ok, "the embedded plot font could not be loaded");
    Ok(())
}

/// Output format, from the file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Portable Network Graphics (`.png`), a bitmap.
    Png,
    /// Scalable Vector Graphics (`.svg`).
    Svg,
}

impl Format {
    /// The format for `path`'s extension (`png` or `svg`, any case).
    pub fn from_path(path: &Path) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        match ext.as_str() {
            "png" => Ok(Format::Png),
            "svg" => Ok(Format::Svg),
            _ => bail!(
                "cannot tell the plot format of {}: the file name must end in .png or .svg",
                path.display()
            ),
        }
    }
}

/// Scale of an axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scale {
    /// Linear. The default.
    #[default]
    Linear,
    /// Base-10 logarithmic; points with values ≤ 0 are left out.
    Log,
}

/// Where the legend goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Legend {
    /// Inside the plot, upper right. The default.
    #[default]
    UpperRight,
    /// Inside the plot, upper left.
    UpperLeft,
    /// No legend, even if series have labels.
    Hidden,
}

/// What every figure has: title, axis labels, size, scales and ranges.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Title above the plot.
    pub title: String,
    /// Horizontal axis label, with its unit, e.g. `"time t (s)"`.
    pub x_label: String,
    /// Vertical axis label, with its unit.
    pub y_label: String,
    /// Image size (width, height), pixels. Default 1000 × 700.
    pub size: (u32, u32),
    /// Scale of the vertical axis (line plots, scatter plots and phase portraits). Default
    /// linear.
    pub y_scale: Scale,
    /// Horizontal range; `None` (default) fits the data.
    pub x_range: Option<(f64, f64)>,
    /// Vertical range; `None` (default) fits the data.
    pub y_range: Option<(f64, f64)>,
    /// Legend position (drawn only when some series has a label). Default upper right.
    pub legend: Legend,
}

impl Figure {
    /// A 1000 × 700 figure with linear axes fitted to the data.
    pub fn new(title: impl Into<String>, x_label: impl Into<String>, y_label: impl Into<String>) -> Self {
        Figure {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            size: (1000, 700),
            y_scale: Scale::Linear,
            x_range: None,
            y_range: None,
            legend: Legend::UpperRight,
        }
    }
}

/// A data series: points `(x[i], y[i])`, drawn in the order given. Non-finite points are
/// skipped (a line is broken there).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Series<'a> {
    /// Legend entry; `None` leaves the series out of the legend.
    pub label: Option<&'a str>,
    /// Horizontal coordinates.
    pub x: &'a [f64],
    /// Vertical coordinates (same length as `x`).
    pub y: &'a [f64],
    /// As a line: dashed instead of solid.
    pub dashed: bool,
    /// Colour: an index into the palette; `None` (default) takes the series' position.
    pub colour: Option<usize>,
}

impl<'a> Series<'a> {
    /// A labelled series.
    pub fn new(label: &'a str, x: &'a [f64], y: &'a [f64]) -> Self {
        Series {
            label: Some(label),
            x,
            y,
            dashed: false,
            colour: None,
        }
    }

    /// A series without a legend entry.
    pub fn unlabelled(x: &'a [f64], y: &'a [f64]) -> Self {
        Series {
            label: None,
            x,
            y,
            dashed: false,
            colour: None,
        }
    }

    /// The same series drawn dashed (as a line).
    pub fn dashed(self) -> Self {
        Series { dashed: true, ..self }
    }

    /// The same series in palette colour `index` (0 blue, 1 orange, 2 green, 3 red, …).
    pub fn colour(self, index: usize) -> Self {
        Series {
            colour: Some(index),
            ..self
        }
    }
}

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
/// Poincaré `section` points (if any) as black 5-pixel marks on top.
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
        marker_px: 5,
    };
    write(path, figure.size, &xy_chart(figure, layers)?)
}

/// Values on a regular grid of `nx × ny` cells covering `[x_edges.0, x_edges.1] ×
/// [y_edges.0, y_edges.1]`. Non-finite values are drawn grey.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeatMap<'a> {
    /// Left and right edges of the grid, in x units.
    pub x_edges: (f64, f64),
    /// Bottom and top edges of the grid, in y units.
    pub y_edges: (f64, f64),
    /// Cells along x.
    pub nx: usize,
    /// Cells along y.
    pub ny: usize,
    /// Cell values, row-major from the bottom: `values[iy·nx + ix]` is the cell with
    /// lower-left corner `(x₀ + ix·Δx, y₀ + iy·Δy)`.
    pub values: &'a [f64],
    /// Colour-bar label, with its unit, e.g. `"average power (µW)"`.
    pub colour_label: &'a str,
    /// Values mapped to the ends of the colour scale; `None` uses the finite data's range.
    pub colour_range: Option<(f64, f64)>,
}

impl<'a> HeatMap<'a> {
    /// A grid whose values were computed at the nodes `x_first..=x_last` (nx of them) and
    /// `y_first..=y_last` (ny): each cell is centred on its node.
    pub fn centred_on_nodes(
        x_nodes: (f64, f64),
        y_nodes: (f64, f64),
        nx: usize,
        ny: usize,
        values: &'a [f64],
        colour_label: &'a str,
    ) -> Self {
        let half = |(first, last): (f64, f64), n: usize| {
            let h = if n > 1 {
                0.5 * (last - first) / (n - 1) as f64
            } else {
                0.5
            };
            (first - h, last + h)
        };
        HeatMap {
            x_edges: half(x_nodes, nx),
            y_edges: half(y_nodes, ny),
            nx,
            ny,
            values,
            colour_label,
            colour_range: None,
        }
    }
}

/// A heat map of `map` with a colour bar on the right.
pub fn heat_map(path: &Path, figure: &Figure, map: &HeatMap<'_>) -> Result<()> {
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
        },
    )
}
