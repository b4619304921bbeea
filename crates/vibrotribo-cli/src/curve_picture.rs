//! The picture of a `curve` directory (`plot DIR`): the bifurcation curve in the plane of its
//! two parameters, from `curve.csv`, with its codimension-two points from `curve.json`.

use std::path::Path;

use anyhow::{Result, bail};

use crate::branch_picture::marker_of;
use crate::manifest::{CurveManifest, Kind, read_of};
use crate::output::{column, numbers, read_csv};
use crate::plot::{self, Figure, Legend, Series, both};

/// The codimension-two points of one kind: their legend label, marker, colour and places.
struct Marks {
    label: String,
    shape: plot::Shape,
    colour: usize,
    px: Vec<f64>,
    py: Vec<f64>,
}

/// Draws `curve.png`/`.svg` of the `curve` directory `dir`: the curve's points joined in
/// their order along it, and each codimension-two point marked by its kind.
pub fn plot_curve(dir: &Path) -> Result<()> {
    let m: CurveManifest = read_of(dir, Kind::Curve)?;
    let (h, rows) = read_csv(&dir.join("curve.csv"))?;
    let x = numbers(&rows, column(&h, &m.param)?);
    let y = numbers(&rows, column(&h, &m.param2)?);
    if x.is_empty() {
        bail!("{}: curve.csv holds no point", dir.display());
    }
    let line_label = format!("{} curve", marker_of(&m.kind).0);
    let line = [Series::new(&line_label, &x, &y).colour(0)];
    let start = ([x[0]], [y[0]]);
    // One legend entry per kind of codimension-two point.
    let mut kinds: Vec<&str> = m.codim2.iter().map(|p| p.kind.as_str()).collect();
    kinds.sort_unstable();
    kinds.dedup();
    let marks: Vec<Marks> = kinds
        .iter()
        .map(|k| {
            let (_, shape, colour) = marker_of(k.trim_start_matches("meets_"));
            let (px, py) = m
                .codim2
                .iter()
                .filter(|p| p.kind == *k)
                .map(|p| (p.param, p.param2))
                .unzip();
            let label = match k.strip_prefix("meets_") {
                Some(other) => format!("meets a {} curve", marker_of(other).0),
                None => marker_of(k).0.to_string(),
            };
            Marks {
                label,
                shape,
                colour,
                px,
                py,
            }
        })
        .collect();
    // The point the curve was located at, then the codimension-two points.
    let mut points = vec![
        Series::new("located", &start.0, &start.1)
            .colour(7)
            .marker(plot::Shape::Circle, 9),
    ];
    points.extend(marks.iter().map(|m| {
        Series::new(&m.label, &m.px, &m.py)
            .colour(m.colour)
            .marker(m.shape, 11)
    }));
    let mut fig = Figure::new(
        format!("The {line_label} of period {}: {} points", m.period, m.points),
        m.param.clone(),
        m.param2.clone(),
    );
    fig.legend = Legend::UpperLeft;
    both(dir, "curve", |path| {
        plot::lines_and_points(path, &fig, &line, &points, 3)
    })
}
