//! The figures: their description (title, axes, scales, legend, output format), the data
//! series and the heat-map grid.

use anyhow::{Result, bail};
use std::path::Path;

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
    /// Inside the plot, lower right.
    LowerRight,
    /// Inside the plot, lower left.
    LowerLeft,
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
    /// As points: a marker of its own (shape and size) instead of the chart's small squares;
    /// for a few points that must stand out, such as bifurcations on a branch.
    pub marker: Option<Marker>,
    /// As a line: drawn 3 px wide over a white band, to stand out over a heat map.
    pub halo: bool,
}

/// A point marker: a shape drawn `size_px` pixels across, filled (a cross is stroked).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Marker {
    /// The shape.
    pub shape: Shape,
    /// Width and height, pixels.
    pub size_px: u32,
}

/// The shape of a [`Marker`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// A disc.
    Circle,
    /// A triangle pointing up.
    Triangle,
    /// A square standing on a corner.
    Diamond,
    /// A square.
    Square,
    /// A diagonal cross.
    Cross,
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
            marker: None,
            halo: false,
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
            marker: None,
            halo: false,
        }
    }

    /// The same series drawn (as a line) over a white band.
    pub fn halo(self) -> Self {
        Series { halo: true, ..self }
    }

    /// The same series drawn dashed (as a line).
    pub fn dashed(self) -> Self {
        Series { dashed: true, ..self }
    }

    /// The same series drawn (as points) with `shape` markers `size_px` pixels across.
    pub fn marker(self, shape: Shape, size_px: u32) -> Self {
        Series {
            marker: Some(Marker { shape, size_px }),
            ..self
        }
    }

    /// The same series in palette colour `index` (0 blue, 1 orange, 2 green, 3 red, …).
    pub fn colour(self, index: usize) -> Self {
        Series {
            colour: Some(index),
            ..self
        }
    }
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
