//! Plots for the command line: PNG or SVG (chosen by the file extension), drawn with
//! `plotters` and an embedded font, so that no system font library is needed.
//!
//! Six kinds of figure, each with a title, axis labels (give the unit in them, e.g.
//! `"time t (s)"`) and an optional legend:
//!
//! - [`line_plot`]: several series as lines (time histories, running power, a PSD with
//!   [`Scale::Log`] on y);
//! - [`scatter_plot`]: many tiny points (orbit and bifurcation diagrams). Points are
//!   rasterised to the plot's pixel grid first, so a million points cost one mark per
//!   occupied pixel, in PNG and SVG alike;
//! - [`phase_portrait`]: trajectories in the (x, v) plane with optional Poincaré points;
//! - [`heat_map`]: values on a regular 2-D grid with a colour bar (viridis);
//! - [`category_map`]: a grid coloured by category with a legend (basins of attraction);
//! - [`stacked_bands`]: shares of categories stacked against a parameter, with a legend.
//!
//! Text is set in DejaVu Sans (`assets/DejaVuSans.ttf`, licence in
//! `assets/DejaVuSans-LICENSE`), registered with plotters' `ab_glyph` font table. SVG files
//! name the font family `sans-serif` and leave the glyphs to the viewer.

mod category;
mod draw;
pub mod drawn;
mod figure;
mod files;
mod heat;
mod style;
#[cfg(test)]
mod tests;
mod xy;

pub use category::{Bands, CategoryMap, category_map, stacked_bands};
pub use draw::{heat_map, heat_map_with, line_plot, lines_and_points, phase_portrait, scatter_plot};
pub use figure::{Figure, HeatMap, Legend, Scale, Series, Shape};
pub use files::both;
