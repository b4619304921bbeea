//! Plots for the command line: PNG or SVG (chosen by the file extension), drawn with
//! `plotters` and an embedded font, so that no system font library is needed.
//!
//! Four kinds of figure, each with a title, axis labels (give the unit in them, e.g.
//! `"time t (s)"`) and an optional legend:
//!
//! - [`line_plot`]: several series as lines (time histories, running power, a PSD with
//!   [`Scale::Log`] on y);
//! - [`scatter_plot`]: many tiny points (orbit and bifurcation diagrams). Points are
//!   rasterised to the plot's pixel grid first, so a million points cost one mark per
//!   occupied pixel, in PNG and SVG alike;
//! - [`phase_portrait`]: trajectories in the (x, v) plane with optional Poincaré points;
//! - [`heat_map`]: values on a regular 2-D grid with a colour bar (viridis).
//!
//! Text is set in DejaVu Sans (`assets/DejaVuSans.ttf`, licence in
//! `assets/DejaVuSans-LICENSE`), registered with plotters' `ab_glyph` font table. SVG files
//! name the font family `sans-serif` and leave the glyphs to the viewer.

use anyhow::{Context, Result, anyhow, bail, ensure};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};
use std::ops::Range;
use std::path::Path;
use std::sync::OnceLock;

/// DejaVu Sans, embedded (see `assets/DejaVuSans-LICENSE`).
static FONT_DATA: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// The font family every text element asks for; the embedded font is registered under it.
const FAMILY: &str = "sans-serif";

/// Registers the embedded font once per process.
fn ensure_font() -> Result<()> {
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
}

impl<'a> Series<'a> {
    /// A labelled series.
    pub fn new(label: &'a str, x: &'a [f64], y: &'a [f64]) -> Self {
        Series {
            label: Some(label),
            x,
            y,
        }
    }

    /// A series without a legend entry.
    pub fn unlabelled(x: &'a [f64], y: &'a [f64]) -> Self {
        Series { label: None, x, y }
    }
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

// ---------------------------------------------------------------------------------------
// Rendering.

/// What an x–y chart draws: lines, then points on top.
struct Layers<'s, 'a> {
    lines: &'s [Series<'a>],
    points: &'s [Series<'a>],
    marker_px: u32,
}

impl Layers<'_, '_> {
    fn all(&self) -> impl Iterator<Item = &Series<'_>> {
        self.lines.iter().chain(self.points)
    }
}

/// Line colours: the Tableau 10 palette, distinguishable and colour-blind aware.
const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

const TITLE_PX: u32 = 28;
const LABEL_PX: u32 = 22;
const TICK_PX: u32 = 17;

fn font(px: u32) -> TextStyle<'static> {
    (FAMILY, px).into_font().color(&BLACK)
}

/// Something that can draw itself on any plotters backend.
trait Render {
    /// Draws on `root`, a backend of `format`.
    fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, format: Format) -> Result<()>;
}

/// An x–y chart, checked, with its axis ranges (see [`xy_chart`]).
struct XyChart<'f, 's, 'a> {
    figure: &'f Figure,
    layers: Layers<'s, 'a>,
    x: Range<f64>,
    y: Range<f64>,
}

impl Render for XyChart<'_, '_, '_> {
    fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, format: Format) -> Result<()> {
        draw_xy(root, self, format)
    }
}

/// A heat map with its colour range.
struct HeatChart<'f, 'm, 'a> {
    figure: &'f Figure,
    map: &'m HeatMap<'a>,
    range: (f64, f64),
}

impl Render for HeatChart<'_, '_, '_> {
    fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, _format: Format) -> Result<()> {
        draw_heat_map(root, self.figure, self.map, self.range)
    }
}

/// Renders `chart` with the backend that `path`'s extension asks for and writes the file.
fn write(path: &Path, size: (u32, u32), chart: &impl Render) -> Result<()> {
    ensure_font()?;
    let (w, h) = size;
    ensure!(
        w >= 200 && h >= 150,
        "plot size {w} × {h} px is too small (minimum 200 × 150)"
    );
    let context = || format!("cannot write plot {}", path.display());
    let format = Format::from_path(path)?;
    match format {
        Format::Png => {
            let root = BitMapBackend::new(path, size).into_drawing_area();
            chart.render(&root, format).with_context(context)?;
            root.present().map_err(err).with_context(context)?;
        }
        Format::Svg => {
            let root = SVGBackend::new(path, size).into_drawing_area();
            chart.render(&root, format).with_context(context)?;
            root.present().map_err(err).with_context(context)?;
        }
    }
    Ok(())
}

/// Maps a plotters error (whose backend error need not be `Send`) to `anyhow`.
fn err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("plotting failed: {e}")
}

/// Smallest and largest finite value, if any.
fn finite_bounds(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.filter(|v| v.is_finite()).fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// Gives an empty range some width.
fn widen(lo: f64, hi: f64) -> (f64, f64) {
    if hi > lo {
        (lo, hi)
    } else {
        let d = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
        (lo - d, hi + d)
    }
}

/// The axis range: as given, or the data's range with 3 % margins (on a log axis, a factor
/// margin over the positive values).
fn axis_range(
    given: Option<(f64, f64)>,
    data: impl Iterator<Item = f64>,
    scale: Scale,
    axis: &str,
) -> Result<Range<f64>> {
    if let Some((a, b)) = given {
        ensure!(
            a.is_finite() && b.is_finite() && a < b,
            "{axis} range must be finite and increasing, got {a} to {b}"
        );
        ensure!(
            scale == Scale::Linear || a > 0.0,
            "{axis} range of a log axis must be positive, got {a} to {b}"
        );
        return Ok(a..b);
    }
    match scale {
        Scale::Linear => {
            let (lo, hi) =
                finite_bounds(data).ok_or_else(|| anyhow!("no finite data to plot on the {axis} axis"))?;
            let (lo, hi) = widen(lo, hi);
            let m = 0.03 * (hi - lo);
            Ok(lo - m..hi + m)
        }
        Scale::Log => {
            let (lo, hi) = finite_bounds(data.filter(|v| *v > 0.0))
                .ok_or_else(|| anyhow!("no positive data to plot on the logarithmic {axis} axis"))?;
            let (lo, hi) = if hi > lo { (lo, hi) } else { (lo / 2.0, hi * 2.0) };
            let m = (hi / lo).powf(0.03);
            Ok(lo / m..hi * m)
        }
    }
}

/// Fills `root` white and sets the title in a band at its top; returns the area below.
fn titled<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, title: &str) -> Result<DrawingArea<DB, Shift>> {
    root.fill(&WHITE).map_err(err)?;
    root.margin(10, 0, 0, 0)
        .titled(title, font(TITLE_PX))
        .map_err(err)
}

/// Compact tick label: plain decimals for moderate magnitudes, else scientific notation.
fn tick_label(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        "0".to_string()
    } else if (1e-3..1e5).contains(&a) {
        let s = format!("{v:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" { "0".to_string() } else { s.to_string() }
    } else {
        let s = format!("{v:.3e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        format!("{mantissa}e{exponent}")
    }
}

fn check_series(s: &Series<'_>, index: usize) -> Result<()> {
    ensure!(
        s.x.len() == s.y.len(),
        "series {} ({}) has {} x values but {} y values",
        index + 1,
        s.label.unwrap_or("unlabelled"),
        s.x.len(),
        s.y.len()
    );
    Ok(())
}

/// Checks the series and works out the axis ranges, before any file is created.
fn xy_chart<'f, 's, 'a>(figure: &'f Figure, layers: Layers<'s, 'a>) -> Result<XyChart<'f, 's, 'a>> {
    ensure!(layers.all().next().is_some(), "nothing to plot: no series given");
    for (i, s) in layers.all().enumerate() {
        check_series(s, i)?;
    }
    let x = axis_range(
        figure.x_range,
        layers.all().flat_map(|s| s.x.iter().copied()),
        Scale::Linear,
        "x",
    )?;
    let y_data = layers.all().flat_map(|s| {
        s.x.iter()
            .zip(s.y)
            .filter(|(x, _)| x.is_finite())
            .map(|(_, y)| *y)
    });
    let y = axis_range(figure.y_range, y_data, figure.y_scale, "y")?;
    Ok(XyChart { figure, layers, x, y })
}

fn draw_xy<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    chart: &XyChart<'_, '_, '_>,
    format: Format,
) -> Result<()> {
    let area = titled(root, &chart.figure.title)?;
    let (x, y) = (chart.x.clone(), chart.y.clone());
    let y_span = y.end - y.start;
    match chart.figure.y_scale {
        Scale::Linear => draw_xy_on(
            root,
            &area,
            chart.figure,
            &chart.layers,
            format,
            x,
            y,
            Some(y_span),
        ),
        Scale::Log => draw_xy_on(
            root,
            &area,
            chart.figure,
            &chart.layers,
            format,
            x,
            y.log_scale(),
            None,
        ),
    }
}

/// Builds the chart on `area` with y coordinate `y` and draws mesh, lines, points, legend.
/// `y_span` is the extent of a linear y axis (for tick labels), `None` for a log axis.
#[allow(clippy::too_many_arguments)]
fn draw_xy_on<DB, Y>(
    root: &DrawingArea<DB, Shift>,
    area: &DrawingArea<DB, Shift>,
    figure: &Figure,
    layers: &Layers<'_, '_>,
    format: Format,
    x: Range<f64>,
    y: Y,
    y_span: Option<f64>,
) -> Result<()>
where
    DB: DrawingBackend,
    Y: AsRangedCoord<Value = f64>,
    Y::CoordDescType: ValueFormatter<f64>,
{
    // Ticks of a linear axis that are rounding away from 0 (e.g. −5.6e-17) read as 0.
    let x_span = x.end - x.start;
    let snap = |v: f64, span: Option<f64>| match span {
        Some(span) if v.abs() < 1e-9 * span.abs() => 0.0,
        _ => v,
    };
    let fx = move |v: &f64| tick_label(snap(*v, Some(x_span)));
    let fy = move |v: &f64| tick_label(snap(*v, y_span));
    let mut chart = ChartBuilder::on(area)
        .margin(16)
        .margin_right(28)
        .x_label_area_size(60)
        .y_label_area_size(90)
        .build_cartesian_2d(x, y)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(&figure.x_label)
        .y_desc(&figure.y_label)
        .axis_desc_style(font(LABEL_PX))
        .label_style(font(TICK_PX))
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(210, 210, 210))
        .draw()
        .map_err(err)?;

    // The plotting area in pixels: drawing there clips to the axes.
    let plot = chart.plotting_area().strip_coord_spec();
    let log_y = figure.y_scale == Scale::Log;
    let usable = |x: f64, y: f64| x.is_finite() && y.is_finite() && (!log_y || y > 0.0);
    for (i, s) in layers.lines.iter().enumerate() {
        let colour = PALETTE[i % PALETTE.len()];
        // One polyline per run of usable points, in pixels of the plotting area, thinned
        // to points at least 2 px apart (the last point of a run is always kept): dense
        // series draw as clean lines and stay small in SVG, at a visual error under 2 px.
        let base = plot.get_base_pixel();
        let mut runs: Vec<Vec<(i32, i32)>> = vec![Vec::new()];
        let mut pending: Option<(i32, i32)> = None;
        for (&px, &py) in s.x.iter().zip(s.y) {
            let run = runs.last_mut().expect("runs is never empty");
            if !usable(px, py) {
                run.extend(pending.take());
                if !run.is_empty() {
                    runs.push(Vec::new());
                }
                continue;
            }
            let (bx, by) = chart.backend_coord(&(px, py));
            let here = (bx - base.0, by - base.1);
            match run.last() {
                Some(&(lx, ly)) if (here.0 - lx).abs() + (here.1 - ly).abs() < 2 => pending = Some(here),
                _ => {
                    run.push(here);
                    pending = None;
                }
            }
        }
        runs.last_mut().expect("runs is never empty").extend(pending);
        let (w, h) = plot.dim_in_pixel();
        for run in runs.iter().flat_map(|r| clip_polyline(r, w as i32, h as i32)) {
            match format {
                Format::Svg => plot
                    .draw(&PathElement::new(run, colour.stroke_width(2)))
                    .map_err(err)?,
                // plotters' bitmap lines wider than 1 px come out hollow on steep segments:
                // draw the 1-px line three times, offset by a pixel right and down.
                Format::Png => {
                    for (ox, oy) in [(0, 0), (1, 0), (0, 1)] {
                        let shifted: Vec<(i32, i32)> = run.iter().map(|&(x, y)| (x + ox, y + oy)).collect();
                        plot.draw(&PathElement::new(shifted, colour.stroke_width(1)))
                            .map_err(err)?;
                    }
                }
            }
        }
        if let Some(label) = s.label {
            chart
                .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
                .map_err(err)?
                .label(label)
                .legend(move |(lx, ly)| {
                    PathElement::new(vec![(lx, ly), (lx + 24, ly)], colour.stroke_width(3))
                });
        }
    }

    // Points: rasterise to the plotting area's pixels, then mark each occupied pixel once.
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let (width, height) = (
        (xs.end - xs.start).max(0) as usize,
        (ys.end - ys.start).max(0) as usize,
    );
    let mut occupied = vec![false; width * height];
    let half = (layers.marker_px.max(1) as i32 - 1) / 2;
    for (i, s) in layers.points.iter().enumerate() {
        let colour = if layers.lines.is_empty() {
            PALETTE[i % PALETTE.len()]
        } else {
            BLACK
        };
        occupied.iter_mut().for_each(|o| *o = false);
        for (&px, &py) in s.x.iter().zip(s.y) {
            if !usable(px, py) {
                continue;
            }
            let (bx, by) = chart.backend_coord(&(px, py));
            if !xs.contains(&bx) || !ys.contains(&by) {
                continue;
            }
            let cell = (by - ys.start) as usize * width + (bx - xs.start) as usize;
            if occupied[cell] {
                continue;
            }
            occupied[cell] = true;
            if half == 0 {
                root.draw_pixel((bx, by), &colour).map_err(err)?;
            } else {
                root.draw(&Rectangle::new(
                    [(bx - half, by - half), (bx + half, by + half)],
                    colour.filled(),
                ))
                .map_err(err)?;
            }
        }
        if let Some(label) = s.label {
            chart
                .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
                .map_err(err)?
                .label(label)
                .legend(move |(lx, ly)| {
                    Rectangle::new([(lx + 6, ly - 5), (lx + 16, ly + 5)], colour.filled())
                });
        }
    }

    let position = match figure.legend {
        Legend::UpperRight => SeriesLabelPosition::UpperRight,
        Legend::UpperLeft => SeriesLabelPosition::UpperLeft,
        Legend::Hidden => return Ok(()),
    };
    if layers.all().any(|s| s.label.is_some()) {
        chart
            .configure_series_labels()
            .position(position)
            .label_font(font(TICK_PX))
            .background_style(WHITE.mix(0.85))
            .border_style(RGBColor(150, 150, 150))
            .margin(12)
            .draw()
            .map_err(err)?;
    }
    Ok(())
}

/// The visible pieces of a polyline inside the rectangle `[0, w) × [0, h)` (drawing areas
/// clamp points outside to their edge, which would draw false lines along it).
fn clip_polyline(points: &[(i32, i32)], w: i32, h: i32) -> Vec<Vec<(i32, i32)>> {
    let mut pieces: Vec<Vec<(i32, i32)>> = Vec::new();
    if let [only] = points {
        if (0..w).contains(&only.0) && (0..h).contains(&only.1) {
            pieces.push(vec![*only]);
        }
        return pieces;
    }
    for pair in points.windows(2) {
        let Some((p, q)) = clip_segment(pair[0], pair[1], w, h) else {
            continue;
        };
        match pieces.last_mut() {
            Some(piece) if piece.last() == Some(&p) => piece.push(q),
            _ => pieces.push(vec![p, q]),
        }
    }
    pieces
}

/// Liang–Barsky clipping of the segment a–b to `[0, w−1] × [0, h−1]`.
fn clip_segment(a: (i32, i32), b: (i32, i32), w: i32, h: i32) -> Option<((i32, i32), (i32, i32))> {
    let (x0, y0) = (a.0 as f64, a.1 as f64);
    let (dx, dy) = (b.0 as f64 - x0, b.1 as f64 - y0);
    let (xmax, ymax) = ((w - 1) as f64, (h - 1) as f64);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-dx, x0), (dx, xmax - x0), (-dy, y0), (dy, ymax - y0)] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    if t0 > t1 {
        return None;
    }
    let at = |t: f64| ((x0 + t * dx).round() as i32, (y0 + t * dy).round() as i32);
    Some((
        if t0 > 0.0 { at(t0) } else { a },
        if t1 < 1.0 { at(t1) } else { b },
    ))
}

/// Matplotlib's viridis at 0, 0.1, …, 1 (perceptually uniform, colour-blind safe).
const VIRIDIS: [(u8, u8, u8); 11] = [
    (0x44, 0x01, 0x54),
    (0x48, 0x24, 0x75),
    (0x41, 0x44, 0x87),
    (0x35, 0x5f, 0x8d),
    (0x2a, 0x78, 0x8e),
    (0x21, 0x91, 0x8c),
    (0x22, 0xa8, 0x84),
    (0x44, 0xbf, 0x70),
    (0x7a, 0xd1, 0x51),
    (0xbd, 0xdf, 0x26),
    (0xfd, 0xe7, 0x25),
];

/// Viridis colour at `t ∈ [0, 1]` (clamped), interpolated linearly between the anchors.
fn viridis(t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0) * (VIRIDIS.len() - 1) as f64;
    let i = (t.floor() as usize).min(VIRIDIS.len() - 2);
    let f = t - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |p: u8, q: u8| (p as f64 + f * (q as f64 - p as f64)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

const MISSING: RGBColor = RGBColor(200, 200, 200);

fn draw_heat_map<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    figure: &Figure,
    map: &HeatMap<'_>,
    (lo, hi): (f64, f64),
) -> Result<()> {
    let area = titled(root, &figure.title)?;
    let (w, _) = area.dim_in_pixel();
    let (main, bar) = area.split_horizontally(w.saturating_sub(170));
    let formatter = |v: &f64| tick_label(*v);

    let x = map.x_edges.0..map.x_edges.1;
    let y = map.y_edges.0..map.y_edges.1;
    let mut chart = ChartBuilder::on(&main)
        .margin(16)
        .margin_right(8)
        .x_label_area_size(60)
        .y_label_area_size(90)
        .build_cartesian_2d(x, y)
        .map_err(err)?;
    let dx = (map.x_edges.1 - map.x_edges.0) / map.nx as f64;
    let dy = (map.y_edges.1 - map.y_edges.0) / map.ny as f64;
    let span = hi - lo;
    chart
        .draw_series((0..map.ny).flat_map(|iy| {
            (0..map.nx).map(move |ix| {
                let v = map.values[iy * map.nx + ix];
                let colour = if v.is_finite() {
                    viridis((v - lo) / span)
                } else {
                    MISSING
                };
                let x0 = map.x_edges.0 + ix as f64 * dx;
                let y0 = map.y_edges.0 + iy as f64 * dy;
                Rectangle::new([(x0, y0), (x0 + dx, y0 + dy)], colour.filled())
            })
        }))
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(&figure.x_label)
        .y_desc(&figure.y_label)
        .axis_desc_style(font(LABEL_PX))
        .label_style(font(TICK_PX))
        .x_label_formatter(&formatter)
        .y_label_formatter(&formatter)
        .draw()
        .map_err(err)?;

    // Colour bar: a column of 256 bands, labelled on its right.
    let mut scale = ChartBuilder::on(&bar)
        .margin_top(16)
        .margin_bottom(76)
        .margin_left(8)
        .margin_right(14)
        .right_y_label_area_size(100)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(err)?;
    let bands = 256;
    scale
        .draw_series((0..bands).map(|k| {
            let a = lo + span * k as f64 / bands as f64;
            let b = lo + span * (k + 1) as f64 / bands as f64;
            Rectangle::new(
                [(0.0, a), (1.0, b)],
                viridis((k as f64 + 0.5) / bands as f64).filled(),
            )
        }))
        .map_err(err)?;
    scale
        .configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .set_all_tick_mark_size(6)
        .y_desc(map.colour_label)
        .axis_desc_style(font(LABEL_PX))
        .label_style(font(TICK_PX))
        .y_label_formatter(&formatter)
        .draw()
        .map_err(err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;
    use std::path::PathBuf;

    /// Where test plots go: `$VIBROTRIBO_PLOT_DIR` if set (to look at them), else a
    /// temporary directory removed after the test.
    struct OutDir {
        path: PathBuf,
        _temp: Option<tempfile::TempDir>,
    }

    fn out_dir() -> OutDir {
        match std::env::var_os("VIBROTRIBO_PLOT_DIR") {
            Some(dir) => {
                let path = PathBuf::from(dir);
                std::fs::create_dir_all(&path).unwrap();
                OutDir { path, _temp: None }
            }
            None => {
                let temp = tempfile::tempdir().unwrap();
                OutDir {
                    path: temp.path().to_path_buf(),
                    _temp: Some(temp),
                }
            }
        }
    }

    /// Checks the PNG signature and that the IHDR chunk records the figure's size.
    fn assert_png(path: &Path, size: (u32, u32)) {
        let bytes = std::fs::read(path).unwrap();
        assert!(
            bytes.len() > 1000,
            "{} is only {} bytes",
            path.display(),
            bytes.len()
        );
        assert_eq!(
            &bytes[..8],
            b"\x89PNG\r\n\x1a\n",
            "{} is not a PNG",
            path.display()
        );
        assert_eq!(&bytes[12..16], b"IHDR");
        let width = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
        let height = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
        assert_eq!((width, height), size, "{}", path.display());
    }

    /// Checks that the SVG is an SVG document carrying every expected text.
    fn assert_svg(path: &Path, texts: &[&str]) {
        let text = std::fs::read_to_string(path).unwrap();
        assert!(text.contains("<svg"), "{} is not an SVG", path.display());
        assert!(
            text.trim_end().ends_with("</svg>"),
            "{} is truncated",
            path.display()
        );
        for t in texts {
            assert!(text.contains(t), "{} lacks the text {t:?}", path.display());
        }
    }

    fn both(dir: &Path, stem: &str) -> [PathBuf; 2] {
        [dir.join(format!("{stem}.png")), dir.join(format!("{stem}.svg"))]
    }

    #[test]
    fn line_plot_of_time_histories_and_a_log_psd() {
        let dir = out_dir();
        let t: Vec<f64> = (0..2000).map(|i| i as f64 * 0.005).collect();
        let x1: Vec<f64> = t.iter().map(|t| 12.0 * (TAU * 0.9 * t).sin()).collect();
        let x2: Vec<f64> = t
            .iter()
            .map(|t| 8.0 * (TAU * 0.9 * t - 0.8).sin() - 4.0)
            .collect();
        let fig = Figure::new("Displacements", "time t (s)", "displacement x (mm)");
        for path in both(&dir.path, "lines") {
            line_plot(
                &path,
                &fig,
                &[Series::new("x1", &t, &x1), Series::new("x2", &t, &x2)],
            )
            .unwrap();
        }
        let [png, svg] = both(&dir.path, "lines");
        assert_png(&png, fig.size);
        assert_svg(
            &svg,
            &["Displacements", "time t (s)", "displacement x (mm)", "x1", "x2"],
        );

        let f: Vec<f64> = (0..513).map(|k| k as f64 * 0.5).collect();
        let p: Vec<f64> = f
            .iter()
            .map(|f| 1e-9 + 1e-3 / (1.0 + ((f - 40.0) / 1.5).powi(2)))
            .collect();
        let psd = Figure {
            y_scale: Scale::Log,
            legend: Legend::Hidden,
            ..Figure::new("Spectrum of x2", "frequency f (Hz)", "PSD (m²/Hz)")
        };
        for path in both(&dir.path, "psd") {
            line_plot(&path, &psd, &[Series::new("x2", &f, &p)]).unwrap();
        }
        let [png, svg] = both(&dir.path, "psd");
        assert_png(&png, psd.size);
        assert_svg(&svg, &["PSD (m²/Hz)", "1e-7", "0.001"]);

        // A zoom: the line is clipped to the axes.
        let zoom = Figure {
            x_range: Some((30.0, 50.0)),
            y_range: Some((1e-6, 2e-3)),
            ..psd
        };
        let path = dir.path.join("psd-zoom.png");
        line_plot(&path, &zoom, &[Series::new("x2", &f, &p)]).unwrap();
        assert_png(&path, zoom.size);
    }

    #[test]
    fn scatter_plot_of_a_million_points() {
        // The logistic map's orbit diagram: 1000 parameters × 1000 iterates.
        let dir = out_dir();
        let mut r_axis = Vec::with_capacity(1_000_000);
        let mut x_axis = Vec::with_capacity(1_000_000);
        for i in 0..1000 {
            let r = 2.8 + 1.2 * i as f64 / 999.0;
            let mut x = 0.5;
            for _ in 0..200 {
                x = r * x * (1.0 - x);
            }
            for _ in 0..1000 {
                x = r * x * (1.0 - x);
                r_axis.push(r);
                x_axis.push(x);
            }
        }
        let fig = Figure::new("Orbit diagram", "parameter r (-)", "x_n (-)");
        for path in both(&dir.path, "scatter") {
            scatter_plot(&path, &fig, &[Series::unlabelled(&r_axis, &x_axis)], 1).unwrap();
        }
        let [png, svg] = both(&dir.path, "scatter");
        assert_png(&png, fig.size);
        assert_svg(&svg, &["Orbit diagram", "parameter r (-)"]);
        // Each occupied pixel is drawn once, so the SVG stays far below one mark per point.
        let marks = std::fs::read_to_string(&svg).unwrap().matches("<rect").count();
        assert!(marks < 400_000, "{marks} marks for 10⁶ points");
    }

    #[test]
    fn phase_portrait_with_section_points() {
        let dir = out_dir();
        let t: Vec<f64> = (0..3000).map(|i| i as f64 * 0.002).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|t| 10.0 * (TAU * t).sin() + 3.0 * (TAU * 3.0 * t).sin())
            .collect();
        let v: Vec<f64> = t
            .iter()
            .map(|t| 10.0 * TAU * (TAU * t).cos() + 9.0 * TAU * (TAU * 3.0 * t).cos())
            .collect();
        let (sx, sv) = ([x[0], x[500]], [v[0], v[500]]);
        let fig = Figure::new("Phase portrait of m2", "position x2 (mm)", "velocity v2 (mm/s)");
        for path in both(&dir.path, "phase") {
            phase_portrait(
                &path,
                &fig,
                &[Series::new("orbit", &x, &v)],
                Some(Series::new("t = nT", &sx, &sv)),
            )
            .unwrap();
        }
        let [png, svg] = both(&dir.path, "phase");
        assert_png(&png, fig.size);
        assert_svg(&svg, &["velocity v2 (mm/s)", "t = nT"]);
    }

    #[test]
    fn heat_map_with_colour_bar() {
        let dir = out_dir();
        let (nx, ny) = (200, 200);
        let mut values = Vec::with_capacity(nx * ny);
        for iy in 0..ny {
            for ix in 0..nx {
                let (u, w) = (ix as f64 / nx as f64, iy as f64 / ny as f64);
                values.push(50.0 * (-((u - 0.6).powi(2) + (w - 0.4).powi(2)) / 0.05).exp());
            }
        }
        values[0] = f64::NAN;
        let map = HeatMap::centred_on_nodes((0.5, 1.0), (1.0, 5.0), nx, ny, &values, "power P (µW)");
        let fig = Figure::new("Average power", "frequency ratio Ω (-)", "mass ratio R_m (-)");
        for path in both(&dir.path, "heat") {
            heat_map(&path, &fig, &map).unwrap();
        }
        let [png, svg] = both(&dir.path, "heat");
        assert_png(&png, fig.size);
        assert_svg(&svg, &["power P (µW)", "mass ratio R_m (-)"]);
    }

    #[test]
    fn text_is_rendered_with_the_embedded_font() {
        // Draw into a memory bitmap: the title band must hold dark (text) pixels, which
        // needs a working font.
        ensure_font().unwrap();
        let (w, h) = (600u32, 400u32);
        let mut buf = vec![0u8; (w * h * 3) as usize];
        let fig = Figure::new("TITLE", "x (m)", "y (m)");
        {
            let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
            let layers = Layers {
                lines: &[Series::unlabelled(&[0.0, 1.0], &[0.0, 1.0])],
                points: &[],
                marker_px: 1,
            };
            draw_xy(&root, &xy_chart(&fig, layers).unwrap(), Format::Png).unwrap();
            root.present().unwrap();
        }
        let dark_in_title = (0..30 * w as usize)
            .filter(|p| buf[3 * p..3 * p + 3].iter().all(|&c| c < 100))
            .count();
        assert!(
            dark_in_title > 50,
            "only {dark_in_title} dark pixels in the title band"
        );
    }

    #[test]
    fn bad_input_is_an_error() {
        let dir = out_dir();
        let fig = Figure::new("t", "x (m)", "y (m)");
        let png = dir.path.join("bad.png");
        let x = [0.0, 1.0];
        assert!(line_plot(&dir.path.join("bad.pdf"), &fig, &[Series::unlabelled(&x, &x)]).is_err());
        assert!(line_plot(&png, &fig, &[]).is_err());
        assert!(line_plot(&png, &fig, &[Series::unlabelled(&x, &x[..1])]).is_err());
        assert!(line_plot(&png, &fig, &[Series::unlabelled(&[f64::NAN], &[1.0])]).is_err());
        let log = Figure {
            y_scale: Scale::Log,
            ..fig.clone()
        };
        assert!(line_plot(&png, &log, &[Series::unlabelled(&x, &[0.0, -1.0])]).is_err());
        let map = HeatMap {
            x_edges: (0.0, 1.0),
            y_edges: (0.0, 1.0),
            nx: 2,
            ny: 2,
            values: &[1.0; 3],
            colour_label: "c",
            colour_range: None,
        };
        assert!(heat_map(&png, &fig, &map).is_err());
        let all_nan = HeatMap {
            values: &[f64::NAN; 4],
            ..map
        };
        assert!(heat_map(&png, &fig, &all_nan).is_err());
        assert!(!png.exists(), "a rejected plot left a file behind");
    }

    #[test]
    fn polylines_are_clipped_not_clamped() {
        // Inside: unchanged.
        assert_eq!(
            clip_polyline(&[(1, 1), (5, 5), (9, 2)], 10, 10),
            vec![vec![(1, 1), (5, 5), (9, 2)]]
        );
        // Leaving and re-entering: two pieces meeting the edge x = 9 (at y = 6.2 on the way
        // back).
        let pieces = clip_polyline(&[(5, 5), (15, 5), (5, 7)], 10, 10);
        assert_eq!(pieces, vec![vec![(5, 5), (9, 5)], vec![(9, 6), (5, 7)]]);
        // Wholly outside, or crossing a corner region outside: nothing.
        assert!(clip_polyline(&[(-5, -5), (-1, 20)], 10, 10).is_empty());
        assert!(clip_polyline(&[(-5, 3), (3, -5)], 10, 10).is_empty());
        // A diagonal through the box is cut at its edges.
        assert_eq!(
            clip_polyline(&[(-10, -10), (20, 20)], 10, 10),
            vec![vec![(0, 0), (9, 9)]]
        );
    }

    #[test]
    fn tick_labels_are_compact() {
        assert_eq!(tick_label(0.0), "0");
        assert_eq!(tick_label(0.30000000000000004), "0.3");
        assert_eq!(tick_label(-2.5), "-2.5");
        assert_eq!(tick_label(1500.0), "1500");
        assert_eq!(tick_label(1e-9), "1e-9");
        assert_eq!(tick_label(2.5e-6), "2.5e-6");
        assert_eq!(tick_label(1.2e6), "1.2e6");
    }
}
