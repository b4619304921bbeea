//! Rendering: the PNG and SVG backends, axis ranges and ticks, and x–y charts (lines,
//! rasterised points, clipping).

use super::figure::{Figure, Format, HeatMap, Legend, Marker, Scale, Series, Shape};
use super::heat::draw_heat_map;
use super::style::{
    LABEL_PX, PALETTE, TICK_PX, ensure_font, err, finite_bounds, font, tick_label, titled, widen,
};
use anyhow::{Context, Result, ensure};
use plotters::coord::Shift;
use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use std::ops::Range;
use std::path::Path;

/// A figure with nothing to draw (no finite data on an axis): [`both`](super::both)
/// skips it with a note instead of failing the command.
#[derive(Debug)]
pub struct NothingToDraw(pub String);

impl std::fmt::Display for NothingToDraw {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "nothing to draw ({})", self.0)
    }
}

impl std::error::Error for NothingToDraw {}

/// What an x–y chart draws: lines, then points on top.
pub(super) struct Layers<'s, 'a> {
    pub(super) lines: &'s [Series<'a>],
    pub(super) points: &'s [Series<'a>],
    pub(super) marker_px: u32,
}

impl Layers<'_, '_> {
    fn all(&self) -> impl Iterator<Item = &Series<'_>> {
        self.lines.iter().chain(self.points)
    }
}

/// Something that can draw itself on any plotters backend.
pub(super) trait Render {
    /// Draws on `root`, a backend of `format`.
    fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, format: Format) -> Result<()>;
}

/// An x–y chart, checked, with its axis ranges (see [`xy_chart`]).
pub(super) struct XyChart<'f, 's, 'a> {
    pub(super) figure: &'f Figure,
    pub(super) layers: Layers<'s, 'a>,
    pub(super) x: Range<f64>,
    pub(super) y: Range<f64>,
}

impl Render for XyChart<'_, '_, '_> {
    fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, format: Format) -> Result<()> {
        draw_xy(root, self, format)
    }
}

/// A heat map with its colour range and the layers drawn over it.
pub(super) struct HeatChart<'f, 'm, 's, 'a> {
    pub(super) figure: &'f Figure,
    pub(super) map: &'m HeatMap<'a>,
    pub(super) range: (f64, f64),
    pub(super) layers: Layers<'s, 'a>,
}

impl Render for HeatChart<'_, '_, '_, '_> {
    fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, format: Format) -> Result<()> {
        draw_heat_map(root, self.figure, self.map, self.range, &self.layers, format)
    }
}

/// Renders `chart` with the backend that `path`'s extension asks for and writes the file.
pub(super) fn write(path: &Path, size: (u32, u32), chart: &impl Render) -> Result<()> {
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
    super::drawn::record(path);
    Ok(())
}

/// The axis range: as given, or the data's range with 3 % margins (on a log axis, a factor
/// margin over the positive values).
pub(super) fn axis_range(
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
            let (lo, hi) = finite_bounds(data)
                .ok_or_else(|| NothingToDraw(format!("no finite data on the {axis} axis")))?;
            let (lo, hi) = widen(lo, hi);
            let m = 0.03 * (hi - lo);
            Ok(lo - m..hi + m)
        }
        Scale::Log => {
            let (lo, hi) = finite_bounds(data.filter(|v| *v > 0.0))
                .ok_or_else(|| NothingToDraw(format!("no positive data on the logarithmic {axis} axis")))?;
            let (lo, hi) = if hi > lo { (lo, hi) } else { (lo / 2.0, hi * 2.0) };
            let m = (hi / lo).powf(0.03);
            Ok(lo / m..hi * m)
        }
    }
}

pub(super) fn check_series(s: &Series<'_>, index: usize) -> Result<()> {
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
pub(super) fn xy_chart<'f, 's, 'a>(
    figure: &'f Figure,
    layers: Layers<'s, 'a>,
) -> Result<XyChart<'f, 's, 'a>> {
    if layers.all().next().is_none() {
        return Err(NothingToDraw("no series given".into()).into());
    }
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

pub(super) fn draw_xy<DB: DrawingBackend>(
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
pub(super) fn draw_xy_on<DB, Y>(
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

    draw_layers(root, &mut chart, layers, format, figure.y_scale == Scale::Log)?;
    draw_legend(&mut chart, figure.legend, layers)
}

/// Draws the lines of `layers` (clipped to the plotting area, thinned, dashed, over a white
/// band where the series asks for a halo), then its points (rasterised: each occupied pixel
/// marked once), each labelled series with a legend entry. `log_y`: points with y ≤ 0 are
/// left out.
pub(super) fn draw_layers<'a, DB, Y>(
    root: &DrawingArea<DB, Shift>,
    chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, Y>>,
    layers: &Layers<'_, '_>,
    format: Format,
    log_y: bool,
) -> Result<()>
where
    DB: DrawingBackend + 'a,
    Y: Ranged<ValueType = f64>,
{
    // The plotting area in pixels: drawing there clips to the axes.
    let plot = chart.plotting_area().strip_coord_spec();
    let usable = |x: f64, y: f64| x.is_finite() && y.is_finite() && (!log_y || y > 0.0);
    for (i, s) in layers.lines.iter().enumerate() {
        let colour = PALETTE[s.colour.unwrap_or(i) % PALETTE.len()];
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
        let clipped: Vec<Vec<(i32, i32)>> = runs
            .iter()
            .flat_map(|r| clip_polyline(r, w as i32, h as i32))
            .collect();
        if s.halo {
            for run in &clipped {
                stroke(&plot, run, WHITE, HALO_PX, format)?;
            }
        }
        let pieces: Vec<Vec<(i32, i32)>> = if s.dashed {
            clipped
                .iter()
                .flat_map(|r| dashes(r, DASH_ON, DASH_OFF))
                .collect()
        } else {
            clipped
        };
        let width = if s.halo { 3 } else { 2 };
        for run in &pieces {
            stroke(&plot, run, colour, width, format)?;
        }
        if let Some(label) = s.label {
            let dashed = s.dashed;
            chart
                .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
                .map_err(err)?
                .label(label)
                .legend(move |(lx, ly)| {
                    // Two strokes: touching for a solid line, apart for a dashed one.
                    let (first_end, second_start) = if dashed {
                        (lx + 9, lx + 15)
                    } else {
                        (lx + 12, lx + 12)
                    };
                    EmptyElement::at((lx, ly))
                        + PathElement::new(vec![(0, 0), (first_end - lx, 0)], colour.stroke_width(3))
                        + PathElement::new(vec![(second_start - lx, 0), (24, 0)], colour.stroke_width(3))
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
        let colour = match s.colour {
            Some(c) => PALETTE[c % PALETTE.len()],
            None if layers.lines.is_empty() => PALETTE[i % PALETTE.len()],
            None => BLACK,
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
            if let Some(marker) = s.marker {
                draw_marker(root, marker, (bx, by), colour)?;
            } else if half == 0 {
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
            let series = chart
                .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())
                .map_err(err)?
                .label(label);
            match s.marker {
                Some(marker) => {
                    let shown = Marker {
                        size_px: marker.size_px.min(14),
                        ..marker
                    };
                    series.legend(move |(lx, ly)| {
                        Polygon::new(marker_outline(shown, (lx + 11, ly)), colour.filled())
                    });
                }
                None => {
                    series.legend(move |(lx, ly)| {
                        Rectangle::new([(lx + 6, ly - 5), (lx + 16, ly + 5)], colour.filled())
                    });
                }
            }
        }
    }

    Ok(())
}

/// The legend of the labelled series of `layers` at `legend` (none when hidden or when no
/// series has a label).
pub(super) fn draw_legend<'a, DB, Y>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, Y>>,
    legend: Legend,
    layers: &Layers<'_, '_>,
) -> Result<()>
where
    DB: DrawingBackend + 'a,
    Y: Ranged<ValueType = f64>,
{
    let position = match legend {
        Legend::UpperRight => SeriesLabelPosition::UpperRight,
        Legend::UpperLeft => SeriesLabelPosition::UpperLeft,
        Legend::LowerRight => SeriesLabelPosition::LowerRight,
        Legend::LowerLeft => SeriesLabelPosition::LowerLeft,
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

/// Width of the white band under a line with a halo, pixels.
const HALO_PX: u32 = 7;

/// Draws the polyline `run` (pixels of `plot`) `width` pixels wide.
fn stroke<DB: DrawingBackend>(
    plot: &DrawingArea<DB, Shift>,
    run: &[(i32, i32)],
    colour: RGBColor,
    width: u32,
    format: Format,
) -> Result<()> {
    match format {
        Format::Svg => plot
            .draw(&PathElement::new(run.to_vec(), colour.stroke_width(width)))
            .map_err(err),
        // plotters' bitmap lines wider than 1 px come out hollow on steep segments: draw
        // the 1-px line several times, offset by a pixel (right and down for 2 px, over a
        // diamond for wider lines).
        Format::Png => {
            let reach = (width / 2) as i32;
            let offsets: Vec<(i32, i32)> = if width <= 2 {
                vec![(0, 0), (1, 0), (0, 1)]
            } else {
                (-reach..=reach)
                    .flat_map(|ox| (-reach..=reach).map(move |oy| (ox, oy)))
                    .filter(|(ox, oy)| ox.abs() + oy.abs() <= reach)
                    .collect()
            };
            for (ox, oy) in offsets {
                let shifted: Vec<(i32, i32)> = run.iter().map(|&(x, y)| (x + ox, y + oy)).collect();
                plot.draw(&PathElement::new(shifted, colour.stroke_width(1)))
                    .map_err(err)?;
            }
            Ok(())
        }
    }
}

/// The outline of `marker` centred on the pixel `at`, as a polygon (a disc as 16 sides, a
/// cross as its twelve corners), so that every shape is one kind of element.
pub(super) fn marker_outline(marker: Marker, at: (i32, i32)) -> Vec<(i32, i32)> {
    let r = f64::from(marker.size_px.max(3)) / 2.0;
    let (cx, cy) = (f64::from(at.0), f64::from(at.1));
    let corners: Vec<(f64, f64)> = match marker.shape {
        Shape::Circle => (0..16)
            .map(|k| {
                let a = std::f64::consts::TAU * f64::from(k) / 16.0;
                (r * a.cos(), r * a.sin())
            })
            .collect(),
        // Pixel y grows downwards: the apex has the smallest y.
        Shape::Triangle => vec![(0.0, -r), (r, 0.8 * r), (-r, 0.8 * r)],
        Shape::Diamond => vec![(0.0, -r), (r, 0.0), (0.0, r), (-r, 0.0)],
        Shape::Square => {
            let h = 0.85 * r;
            vec![(-h, -h), (h, -h), (h, h), (-h, h)]
        }
        Shape::Cross => {
            // An X of arms `w` wide: the twelve corners of two crossed bars.
            let (a, w) = (0.8 * r, 0.25 * r);
            vec![
                (-a, -a + w),
                (-a + w, -a),
                (0.0, -w),
                (a - w, -a),
                (a, -a + w),
                (w, 0.0),
                (a, a - w),
                (a - w, a),
                (0.0, w),
                (-a + w, a),
                (-a, a - w),
                (-w, 0.0),
            ]
        }
    };
    corners
        .into_iter()
        .map(|(dx, dy)| ((cx + dx).round() as i32, (cy + dy).round() as i32))
        .collect()
}

/// Draws `marker` at the pixel `at` of `root`, filled, with a darker outline.
fn draw_marker<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    marker: Marker,
    at: (i32, i32),
    colour: RGBColor,
) -> Result<()> {
    let outline = marker_outline(marker, at);
    root.draw(&Polygon::new(outline.clone(), colour.filled()))
        .map_err(err)?;
    let mut closed = outline;
    closed.push(closed[0]);
    root.draw(&PathElement::new(closed, BLACK.mix(0.6).stroke_width(1)))
        .map_err(err)
}

/// The visible pieces of a polyline inside the rectangle `[0, w) × [0, h)` (drawing areas
/// clamp points outside to their edge, which would draw false lines along it).
/// (See also [`dashes`].)
pub(super) fn clip_polyline(points: &[(i32, i32)], w: i32, h: i32) -> Vec<Vec<(i32, i32)>> {
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
pub(super) fn clip_segment(a: (i32, i32), b: (i32, i32), w: i32, h: i32) -> Option<((i32, i32), (i32, i32))> {
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

/// Dash length of a dashed line, pixels.
const DASH_ON: f64 = 9.0;
/// Gap between dashes, pixels.
const DASH_OFF: f64 = 6.0;

/// The pieces of the polyline `run` (pixels) drawn as dashes `on` long with gaps `off`,
/// measured along its length.
pub(super) fn dashes(run: &[(i32, i32)], on: f64, off: f64) -> Vec<Vec<(i32, i32)>> {
    let mut out = Vec::new();
    let mut current: Vec<(i32, i32)> = Vec::new();
    // Position within the dash pattern, pixels, and whether the pen is down.
    let (mut along, mut down) = (0.0f64, true);
    if let Some(&first) = run.first() {
        current.push(first);
    }
    for pair in run.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let (dx, dy) = (f64::from(b.0 - a.0), f64::from(b.1 - a.1));
        let length = dx.hypot(dy);
        let mut done = 0.0;
        while length - done > 1e-9 {
            let left = if down { on } else { off } - along;
            let step = left.min(length - done);
            done += step;
            along += step;
            let p = (
                a.0 + (dx * done / length).round() as i32,
                a.1 + (dy * done / length).round() as i32,
            );
            if down {
                current.push(p);
            }
            if along >= if down { on } else { off } - 1e-9 {
                along = 0.0;
                if down && current.len() > 1 {
                    out.push(std::mem::take(&mut current));
                }
                current.clear();
                down = !down;
                if down {
                    current.push(p);
                }
            }
        }
    }
    if down && current.len() > 1 {
        out.push(current);
    }
    out
}
