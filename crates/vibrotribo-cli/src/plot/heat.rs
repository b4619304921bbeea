//! Heat maps: the viridis colour scale and the grid with its colour bar.

use super::figure::{Figure, Format, HeatMap};
use super::style::{LABEL_PX, TICK_PX, err, font, tick_label, titled};
use super::xy::{Layers, draw_layers, draw_legend};
use anyhow::Result;
use plotters::coord::Shift;
use plotters::prelude::*;

/// Matplotlib's viridis at 0, 0.1, …, 1 (perceptually uniform, colour-blind safe).
pub(super) const VIRIDIS: [(u8, u8, u8); 11] = [
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
pub(super) fn viridis(t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0) * (VIRIDIS.len() - 1) as f64;
    let i = (t.floor() as usize).min(VIRIDIS.len() - 2);
    let f = t - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |p: u8, q: u8| (p as f64 + f * (q as f64 - p as f64)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

pub(super) const MISSING: RGBColor = RGBColor(200, 200, 200);

/// The heat map `map` coloured over `(lo, hi)`, with `layers` (lines and points in the map's
/// coordinates) drawn over it and their legend.
pub(super) fn draw_heat_map<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    figure: &Figure,
    map: &HeatMap<'_>,
    (lo, hi): (f64, f64),
    layers: &Layers<'_, '_>,
    format: Format,
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
    draw_layers(root, &mut chart, layers, format, false)?;
    draw_legend(&mut chart, figure.legend, layers)?;

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
