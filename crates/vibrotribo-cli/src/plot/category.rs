//! Categorical figures: a grid of cells coloured by category (basins of attraction), and
//! shares stacked as bands against a parameter (basin fractions); each with a legend naming
//! the categories.

use super::figure::{Figure, Format};
use super::heat::MISSING;
use super::style::{LABEL_PX, PALETTE, TICK_PX, err, font, tick_label, titled};
use super::xy::{Render, write};
use anyhow::{Result, ensure};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// The colour of category `k` (Tableau 10, then darker and lighter shades of it).
pub(super) fn category_colour(k: usize) -> RGBColor {
    let base = PALETTE[k % PALETTE.len()];
    let shade = |c: u8, f: f64| (c as f64 * f).round().min(255.0) as u8;
    match (k / PALETTE.len()) % 3 {
        0 => base,
        1 => RGBColor(shade(base.0, 0.6), shade(base.1, 0.6), shade(base.2, 0.6)),
        _ => RGBColor(
            255 - shade(255 - base.0, 0.5),
            255 - shade(255 - base.1, 0.5),
            255 - shade(255 - base.2, 0.5),
        ),
    }
}

/// Categories on a regular grid of `nx × ny` cells, each centred on a node
/// (`x_nodes.0..=x_nodes.1`, `y_nodes.0..=y_nodes.1`), with their names.
#[derive(Debug, Clone, Copy)]
pub struct CategoryMap<'a> {
    /// First and last node along x.
    pub x_nodes: (f64, f64),
    /// First and last node along y.
    pub y_nodes: (f64, f64),
    /// Nodes along x.
    pub nx: usize,
    /// Nodes along y.
    pub ny: usize,
    /// Category of each node, row-major from the bottom (`cells[iy·nx + ix]`); `None` is
    /// drawn grey (a failed point).
    pub cells: &'a [Option<usize>],
    /// Legend entry of each category.
    pub names: &'a [String],
    /// Legend entry of the grey cells (drawn only if some cell is `None`).
    pub missing: &'a str,
}

struct CategoryChart<'f, 'a> {
    figure: &'f Figure,
    map: &'f CategoryMap<'a>,
}

/// Legend lines: colour and text.
type Entries<'a> = Vec<(RGBColor, &'a str)>;

/// Draws a legend column on `area`: a swatch and a text per entry.
fn draw_legend<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, entries: &Entries<'_>) -> Result<()> {
    let row = 26;
    for (i, (colour, text)) in entries.iter().enumerate() {
        let y = 30 + i as i32 * row;
        area.draw(&Rectangle::new([(8, y), (28, y + 18)], colour.filled()))
            .map_err(err)?;
        area.draw(&Text::new(text.to_string(), (36, y + 1), font(TICK_PX)))
            .map_err(err)?;
    }
    Ok(())
}

/// Width of the legend column for `entries`, px.
fn legend_width(entries: &Entries<'_>) -> u32 {
    let chars = entries.iter().map(|e| e.1.chars().count()).max().unwrap_or(0);
    (50 + chars * 9).clamp(120, 560) as u32
}

impl Render for CategoryChart<'_, '_> {
    fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, _format: Format) -> Result<()> {
        let m = self.map;
        let area = titled(root, &self.figure.title)?;
        let mut entries: Entries<'_> = m
            .names
            .iter()
            .enumerate()
            .map(|(k, n)| (category_colour(k), n.as_str()))
            .collect();
        if m.cells.iter().any(Option::is_none) {
            entries.push((MISSING, m.missing));
        }
        let (w, _) = area.dim_in_pixel();
        let (main, legend) = area.split_horizontally(w.saturating_sub(legend_width(&entries)));
        let half = |(a, b): (f64, f64), n: usize| {
            let h = if n > 1 {
                0.5 * (b - a) / (n - 1) as f64
            } else {
                0.5
            };
            (a - h, b + h)
        };
        let (x0, x1) = half(m.x_nodes, m.nx);
        let (y0, y1) = half(m.y_nodes, m.ny);
        let formatter = |v: &f64| tick_label(*v);
        let mut chart = ChartBuilder::on(&main)
            .margin(16)
            .margin_right(8)
            .x_label_area_size(60)
            .y_label_area_size(90)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(err)?;
        let dx = (x1 - x0) / m.nx as f64;
        let dy = (y1 - y0) / m.ny as f64;
        chart
            .draw_series((0..m.ny).flat_map(|iy| {
                (0..m.nx).map(move |ix| {
                    let colour = m.cells[iy * m.nx + ix].map_or(MISSING, category_colour);
                    let (a, b) = (x0 + ix as f64 * dx, y0 + iy as f64 * dy);
                    Rectangle::new([(a, b), (a + dx, b + dy)], colour.filled())
                })
            }))
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(&self.figure.x_label)
            .y_desc(&self.figure.y_label)
            .axis_desc_style(font(LABEL_PX))
            .label_style(font(TICK_PX))
            .x_label_formatter(&formatter)
            .y_label_formatter(&formatter)
            .draw()
            .map_err(err)?;
        draw_legend(&legend, &entries)
    }
}

/// A basin picture: `map`'s cells coloured by category, the legend on the right.
pub fn category_map(path: &Path, figure: &Figure, map: &CategoryMap<'_>) -> Result<()> {
    ensure!(
        map.nx > 0 && map.ny > 0 && map.cells.len() == map.nx * map.ny,
        "category map has {} cells for {} × {} nodes",
        map.cells.len(),
        map.nx,
        map.ny
    );
    ensure!(
        map.cells.iter().flatten().all(|&k| k < map.names.len()),
        "category map has a cell without a name"
    );
    let mut figure = figure.clone();
    figure.size.0 += 200;
    write(path, figure.size, &CategoryChart { figure: &figure, map })
}

/// Shares of categories against a parameter: `shares[k][i]` is category k's share at `x[i]`
/// (NaN or 0 where absent), drawn as bands stacked in category order.
#[derive(Debug, Clone, Copy)]
pub struct Bands<'a> {
    /// The parameter values (increasing).
    pub x: &'a [f64],
    /// One row of shares per category.
    pub shares: &'a [Vec<f64>],
    /// Legend entry of each category.
    pub names: &'a [String],
}

struct BandChart<'f, 'a> {
    figure: &'f Figure,
    bands: &'f Bands<'a>,
}

impl Render for BandChart<'_, '_> {
    fn render<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, _format: Format) -> Result<()> {
        let b = self.bands;
        let area = titled(root, &self.figure.title)?;
        let entries: Entries<'_> = b
            .names
            .iter()
            .enumerate()
            .map(|(k, n)| (category_colour(k), n.as_str()))
            .collect();
        let (w, _) = area.dim_in_pixel();
        let (main, legend) = area.split_horizontally(w.saturating_sub(legend_width(&entries)));
        let (x0, x1) = (b.x[0], b.x[b.x.len() - 1]);
        let (x0, x1) = if x1 > x0 { (x0, x1) } else { (x0 - 0.5, x1 + 0.5) };
        let total: Vec<f64> = (0..b.x.len())
            .map(|i| b.shares.iter().map(|r| clean(r[i])).sum::<f64>())
            .collect();
        let top = total.iter().copied().fold(1.0f64, f64::max);
        let formatter = |v: &f64| tick_label(*v);
        let mut chart = ChartBuilder::on(&main)
            .margin(16)
            .margin_right(8)
            .x_label_area_size(60)
            .y_label_area_size(90)
            .build_cartesian_2d(x0..x1, 0.0..top)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc(&self.figure.x_label)
            .y_desc(&self.figure.y_label)
            .axis_desc_style(font(LABEL_PX))
            .label_style(font(TICK_PX))
            .x_label_formatter(&formatter)
            .y_label_formatter(&formatter)
            .draw()
            .map_err(err)?;
        let mut below = vec![0.0; b.x.len()];
        for (k, row) in b.shares.iter().enumerate() {
            let above: Vec<f64> = below.iter().zip(row).map(|(l, s)| l + clean(*s)).collect();
            let mut outline: Vec<(f64, f64)> = b.x.iter().copied().zip(above.iter().copied()).collect();
            outline.extend(b.x.iter().copied().zip(below.iter().copied()).rev());
            chart
                .draw_series(std::iter::once(Polygon::new(
                    outline,
                    category_colour(k).filled(),
                )))
                .map_err(err)?;
            below = above;
        }
        draw_legend(&legend, &entries)
    }
}

fn clean(v: f64) -> f64 {
    if v.is_finite() { v.max(0.0) } else { 0.0 }
}

/// Stacked bands of `bands`, the legend on the right.
pub fn stacked_bands(path: &Path, figure: &Figure, bands: &Bands<'_>) -> Result<()> {
    ensure!(!bands.x.is_empty(), "stacked bands need at least one x value");
    ensure!(
        bands.shares.iter().all(|r| r.len() == bands.x.len()) && bands.names.len() == bands.shares.len(),
        "stacked bands: every category needs a name and one share per x value"
    );
    let mut figure = figure.clone();
    figure.size.0 += 200;
    write(
        path,
        figure.size,
        &BandChart {
            figure: &figure,
            bands,
        },
    )
}
