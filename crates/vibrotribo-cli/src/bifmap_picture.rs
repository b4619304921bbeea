//! The picture of a bifurcation map, drawn from the files of a `bifmap` directory
//! (`bifmap --plot`, `plot DIR`, `reproduce`): the average power of the power map as a heat
//! map (impacts per period with `--mechanics-only`), the map's points whose motion is not
//! periodic marked, the curves over it coloured by kind (period-2P and longer dashed), and
//! the codimension-two points.

use std::path::Path;

use anyhow::{Context, Result, bail};

use crate::manifest::{BifmapManifest, read};
use crate::output::{column, numbers, read_csv};
use crate::plot::{self, Figure, HeatMap, Legend, Series, Shape, both};

/// The curve kinds by name: legend entry and palette colour.
const KINDS: [(&str, &str, usize); 4] = [
    ("fold", "fold", 1),
    ("period_doubling", "period doubling", 3),
    ("neimark_sacker", "Neimark–Sacker", 6),
    ("grazing", "grazing", 0),
];

/// A curve as drawn: its kind, period and points.
struct Drawn {
    kind: String,
    period: u32,
    x: Vec<f64>,
    y: Vec<f64>,
}

/// The curves of `curves.csv` (columns `curve`, the two keys, `kind`, `period`), in order.
fn read_curves(dir: &Path, xk: &str, yk: &str) -> Result<Vec<Drawn>> {
    let (h, rows) = read_csv(&dir.join("curves.csv"))?;
    let (ci, cx, cy, ck, cp) = (
        column(&h, "curve")?,
        column(&h, xk)?,
        column(&h, yk)?,
        column(&h, "kind")?,
        column(&h, "period")?,
    );
    let mut out: Vec<(usize, Drawn)> = Vec::new();
    for r in &rows {
        let id: usize = r[ci].parse().context("curves.csv: curve")?;
        let number = |c: usize| -> Result<f64> {
            r[c].parse::<f64>()
                .with_context(|| format!("curves.csv: {} is not a number", r[c]))
        };
        if out.last().is_none_or(|(last, _)| *last != id) {
            out.push((
                id,
                Drawn {
                    kind: r[ck].clone(),
                    period: r[cp].parse().context("curves.csv: period")?,
                    x: Vec::new(),
                    y: Vec::new(),
                },
            ));
        }
        let d = &mut out.last_mut().expect("pushed above").1;
        d.x.push(number(cx)?);
        d.y.push(number(cy)?);
    }
    Ok(out.into_iter().map(|(_, d)| d).collect())
}

/// The legend entry of a curve.
fn label_of(kind: &str, period: u32) -> String {
    let name = KINDS.iter().find(|k| k.0 == kind).map_or(kind, |k| k.1);
    if period == 1 {
        name.to_string()
    } else {
        format!("{name} (period {period})")
    }
}

/// The corner of the plane `x × y` whose quarter holds the fewest points of the curves (where
/// the legend hides the least).
fn emptiest_corner(curves: &[Drawn], (x0, x1): (f64, f64), (y0, y1): (f64, f64)) -> Legend {
    let (xm, ym) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let count = |top: bool, right: bool| {
        curves
            .iter()
            .flat_map(|c| c.x.iter().zip(&c.y))
            .filter(|&(&x, &y)| (y >= ym) == top && (x >= xm) == right)
            .count()
    };
    [
        (Legend::UpperRight, count(true, true)),
        (Legend::UpperLeft, count(true, false)),
        (Legend::LowerRight, count(false, true)),
        (Legend::LowerLeft, count(false, false)),
    ]
    .into_iter()
    .min_by_key(|(_, n)| *n)
    .map_or(Legend::UpperRight, |(l, _)| l)
}

/// Draws `bifmap.png`/`.svg` from the files of the `bifmap` directory `dir`.
pub fn plot_dir(dir: &Path) -> Result<()> {
    let m: BifmapManifest = read(&dir.join("bifmap.json"))?;
    let (xs, ys) = (&m.x.values, &m.y.values);
    if xs.is_empty() || ys.is_empty() {
        bail!("bifmap.json: the power map's grid is empty");
    }
    let (h, rows) = read_csv(&dir.join("map.csv"))?;
    if rows.len() != xs.len() * ys.len() {
        bail!(
            "map.csv has {} rows for a grid of {} × {} points: the map is incomplete",
            rows.len(),
            xs.len(),
            ys.len()
        );
    }
    // map.csv runs over x fastest, y slowest, each in the order of its range: the picture
    // wants both increasing.
    let (nxs, nys) = (xs.len(), ys.len());
    let ordered = |v: Vec<f64>| -> Vec<f64> {
        let mut out = Vec::with_capacity(v.len());
        for iy in 0..nys {
            let jy = if ys[0] <= ys[nys - 1] { iy } else { nys - 1 - iy };
            for ix in 0..nxs {
                let jx = if xs[0] <= xs[nxs - 1] { ix } else { nxs - 1 - ix };
                out.push(v[jy * nxs + jx]);
            }
        }
        out
    };
    let power = numbers(&rows, column(&h, "average_power_w")?);
    let (values, colour_label, what): (Vec<f64>, &str, &str) = if power.iter().any(|p| *p > 0.0) {
        (
            power
                .iter()
                .map(|p| if *p > 0.0 { p.log10() } else { f64::NAN })
                .collect(),
            "log10(P_a / W)",
            "average power",
        )
    } else {
        (
            numbers(&rows, column(&h, "impacts_per_period")?),
            "impacts per period",
            "impacts per period",
        )
    };
    let (mx, my) = (numbers(&rows, column(&h, "x")?), numbers(&rows, column(&h, "y")?));
    let motion = column(&h, "motion")?;
    let (nx, ny): (Vec<f64>, Vec<f64>) = rows
        .iter()
        .zip(mx.iter().zip(&my))
        .filter(|(r, _)| matches!(r[motion].as_str(), "quasiperiodic" | "chaotic"))
        .map(|(_, (x, y))| (*x, *y))
        .unzip();
    let curves = read_curves(dir, &m.x.param, &m.y.param)?;
    let (h2, rows2) = read_csv(&dir.join("codim2.csv"))?;
    let (qx, qy) = (
        numbers(&rows2, column(&h2, &m.x.param)?),
        numbers(&rows2, column(&h2, &m.y.param)?),
    );
    let labels: Vec<String> = curves.iter().map(|c| label_of(&c.kind, c.period)).collect();
    let mut lines = Vec::new();
    for (i, c) in curves.iter().enumerate() {
        let colour = KINDS.iter().find(|k| k.0 == c.kind).map_or(7, |k| k.2);
        // One legend entry per kind and period.
        let first = labels[..i].iter().all(|l| *l != labels[i]);
        let s = if first {
            Series::new(&labels[i], &c.x, &c.y)
        } else {
            Series::unlabelled(&c.x, &c.y)
        };
        let s = s.colour(colour).halo();
        lines.push(if c.period > 1 { s.dashed() } else { s });
    }
    let mut points = Vec::new();
    if !nx.is_empty() {
        points.push(
            Series::new("not periodic (map)", &nx, &ny)
                .colour(7)
                .marker(Shape::Cross, 10),
        );
    }
    if !qx.is_empty() {
        points.push(
            Series::new("codimension-two point", &qx, &qy)
                .colour(9)
                .marker(Shape::Diamond, 13),
        );
    }
    let values = ordered(values);
    let span = |v: &[f64]| (v[0].min(v[v.len() - 1]), v[0].max(v[v.len() - 1]));
    let ((x0, x1), (y0, y1)) = (span(xs), span(ys));
    let map = HeatMap::centred_on_nodes((x0, x1), (y0, y1), nxs, nys, &values, colour_label);
    let mut fig = Figure::new(
        format!("Bifurcation curves over the {what}"),
        m.x.param.clone(),
        m.y.param.clone(),
    );
    fig.size = (1100, 800);
    fig.legend = emptiest_corner(&curves, (x0, x1), (y0, y1));
    both(dir, "bifmap", |path| {
        plot::heat_map_with(path, &fig, &map, &lines, &points, 5)
    })
}
