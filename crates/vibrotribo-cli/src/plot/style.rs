//! The look every figure shares: the embedded font, text sizes, the palette, titles and tick
//! labels, and the ranges of data.

use anyhow::{Result, anyhow, ensure};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};
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

/// Line colours: the Tableau 10 palette, distinguishable and colour-blind aware.
pub(super) const PALETTE: [RGBColor; 10] = [
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

pub(super) const TITLE_PX: u32 = 28;
pub(super) const LABEL_PX: u32 = 22;
pub(super) const TICK_PX: u32 = 17;

pub(super) fn font(px: u32) -> TextStyle<'static> {
    (FAMILY, px).into_font().color(&BLACK)
}

/// Maps a plotters error (whose backend error need not be `Send`) to `anyhow`.
pub(super) fn err<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("plotting failed: {e}")
}

/// Smallest and largest finite value, if any.
pub(super) fn finite_bounds(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.filter(|v| v.is_finite()).fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// Gives an empty range some width.
pub(super) fn widen(lo: f64, hi: f64) -> (f64, f64) {
    if hi > lo {
        (lo, hi)
    } else {
        let d = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
        (lo - d, hi + d)
    }
}

/// Fills `root` white and sets the title in a band at its top; returns the area below.
pub(super) fn titled<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
) -> Result<DrawingArea<DB, Shift>> {
    root.fill(&WHITE).map_err(err)?;
    let (width, _) = root.dim_in_pixel();
    let room = width.saturating_sub(24);
    let (text, px) = fitted_title(title, room, |t, px| {
        root.estimate_text_size(t, &font(px))
            .map(|(w, _)| w)
            .unwrap_or(u32::MAX)
    });
    root.margin(10, 0, 0, 0).titled(&text, font(px)).map_err(err)
}

/// Smallest title size, pixels: below it a title is shortened instead.
pub(super) const TITLE_MIN_PX: u32 = 18;

/// The title as it fits in `room` pixels (`width` measures a text at a size): at
/// [`TITLE_PX`], else at the largest size down to [`TITLE_MIN_PX`] that fits, else
/// shortened at that size with an ellipsis.
pub(super) fn fitted_title(title: &str, room: u32, width: impl Fn(&str, u32) -> u32) -> (String, u32) {
    for px in (TITLE_MIN_PX..=TITLE_PX).rev().step_by(2) {
        if width(title, px) <= room {
            return (title.to_string(), px);
        }
    }
    let chars: Vec<char> = title.chars().collect();
    let mut keep = chars.len();
    while keep > 1 {
        keep -= 1;
        let short: String = chars[..keep].iter().collect::<String>().trim_end().to_string() + "…";
        if width(&short, TITLE_MIN_PX) <= room {
            return (short, TITLE_MIN_PX);
        }
    }
    ("…".to_string(), TITLE_MIN_PX)
}

/// Compact tick label: plain decimals for moderate magnitudes, else scientific notation.
pub(super) fn tick_label(v: f64) -> String {
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
