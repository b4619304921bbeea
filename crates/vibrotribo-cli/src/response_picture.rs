//! The pictures of `response` and `band-response` directories: power against the swept
//! parameter (or the band's centre), with the peak and the half-power band marked.

use std::path::Path;

use anyhow::Result;

use vibrotribo::response::BandwidthRecord;

use crate::manifest::{BandResponseManifest, ResponseManifest, read};
use crate::output::{column, numbers, read_csv, si};
use crate::plot::{self, Figure, Legend, Series, Shape, both};

/// A peak and band in words.
pub fn band_text(b: Option<&BandwidthRecord>, unit: &str) -> String {
    let Some(b) = b else {
        return "no power".into();
    };
    let edge = |e: Option<f64>, side: &str| e.map_or(format!("beyond the {side} end"), |x| format!("{x:.5}"));
    format!(
        "peak {} at {:.5}{unit}; half-power band {} to {}{}",
        si(b.peak_power_w, "W"),
        b.peak_at,
        edge(b.lower, "lower"),
        edge(b.upper, "upper"),
        b.width
            .map_or(String::new(), |w| format!(" (width {w:.5}{unit})"))
    )
}

/// The half-power line (from the lower to the upper edge, or across the range where an edge
/// is missing) and the marks of the peak and the edges.
struct BandMarks {
    line_x: Vec<f64>,
    line_y: Vec<f64>,
    peak_x: Vec<f64>,
    peak_y: Vec<f64>,
    edges_x: Vec<f64>,
    edges_y: Vec<f64>,
}

impl BandMarks {
    fn of(b: Option<&BandwidthRecord>, (from, to): (f64, f64)) -> Self {
        let Some(b) = b else {
            return BandMarks {
                line_x: Vec::new(),
                line_y: Vec::new(),
                peak_x: Vec::new(),
                peak_y: Vec::new(),
                edges_x: Vec::new(),
                edges_y: Vec::new(),
            };
        };
        let half = 0.5 * b.peak_power_w;
        let edges: Vec<f64> = [b.lower, b.upper].into_iter().flatten().collect();
        BandMarks {
            line_x: vec![b.lower.unwrap_or(from), b.upper.unwrap_or(to)],
            line_y: vec![half, half],
            peak_x: vec![b.peak_at],
            peak_y: vec![b.peak_power_w],
            edges_y: vec![half; edges.len()],
            edges_x: edges,
        }
    }

    fn lines(&self) -> Series<'_> {
        Series::new("half power", &self.line_x, &self.line_y)
            .dashed()
            .colour(7)
    }

    fn points(&self) -> [Series<'_>; 2] {
        [
            Series::new("peak", &self.peak_x, &self.peak_y)
                .marker(Shape::Circle, 11)
                .colour(3),
            Series::new("half-power edges", &self.edges_x, &self.edges_y)
                .marker(Shape::Triangle, 11)
                .colour(3),
        ]
    }
}

/// The upper corner for the legend over the less power: the one whose side (the outer 40 %
/// of the range) holds the smaller largest power of `curves` (each as x and y).
fn legend_corner(curves: &[(&[f64], &[f64])], (from, to): (f64, f64)) -> Legend {
    let side_max = |inside: &dyn Fn(f64) -> bool| {
        curves
            .iter()
            .flat_map(|(x, y)| x.iter().zip(y.iter()))
            .filter(|(x, y)| inside(**x) && y.is_finite())
            .fold(f64::NEG_INFINITY, |m, (_, y)| m.max(*y))
    };
    let span = to - from;
    let left = side_max(&|x| x <= from + 0.4 * span);
    let right = side_max(&|x| x >= to - 0.4 * span);
    if right < left {
        Legend::UpperRight
    } else {
        Legend::UpperLeft
    }
}

/// `response.png/.svg` of a `response` directory: the up sweep (solid) and the down sweep
/// (dashed), the branches (stable solid, unstable dashed) and the overall peak and band.
pub fn plot_response(dir: &Path) -> Result<()> {
    let m: ResponseManifest = read(&dir.join("response.json"))?;
    let (h, rows) = read_csv(&dir.join("response.csv"))?;
    let x = numbers(&rows, column(&h, "param")?);
    let up = numbers(&rows, column(&h, "power_up_w")?);
    let down = numbers(&rows, column(&h, "power_down_w")?);
    // Each branch as two series, its stable and its unstable points (NaN breaks a line).
    let mut branches: Vec<(Vec<f64>, Vec<f64>, Vec<f64>)> = Vec::new();
    if !m.summary.branches.is_empty() {
        let (bh, brows) = read_csv(&dir.join("branches.csv"))?;
        let (bc, pc, sc, wc) = (
            column(&bh, "branch")?,
            column(&bh, "param")?,
            column(&bh, "stable")?,
            column(&bh, "power_w")?,
        );
        for b in &m.summary.branches {
            let rows: Vec<&Vec<String>> = brows.iter().filter(|r| r[bc] == b.branch.to_string()).collect();
            let value = |r: &Vec<String>, c: usize| r[c].parse().unwrap_or(f64::NAN);
            let xs: Vec<f64> = rows.iter().map(|r| value(r, pc)).collect();
            let pick = |stable: bool| -> Vec<f64> {
                rows.iter()
                    .map(|r| {
                        if (r[sc] == "true") == stable {
                            value(r, wc)
                        } else {
                            f64::NAN
                        }
                    })
                    .collect()
            };
            branches.push((xs, pick(true), pick(false)));
        }
    }
    let marks = BandMarks::of(m.summary.bandwidth.as_ref(), (m.axis.from, m.axis.to));
    let mut lines = vec![
        Series::new("up sweep", &x, &up).colour(0),
        Series::new("down sweep", &x, &down).dashed().colour(1),
    ];
    for (i, (xs, stable, unstable)) in branches.iter().enumerate() {
        let (a, b) = if i == 0 {
            (
                Series::new("branches, stable", xs, stable),
                Series::new("branches, unstable", xs, unstable),
            )
        } else {
            (Series::unlabelled(xs, stable), Series::unlabelled(xs, unstable))
        };
        lines.push(a.colour(2));
        lines.push(b.dashed().colour(4));
    }
    lines.push(marks.lines());
    let figure = Figure {
        legend: legend_corner(&[(&x, &up), (&x, &down)], (m.axis.from, m.axis.to)),
        ..Figure::new(
            format!(
                "Frequency response: {}",
                band_text(m.summary.bandwidth.as_ref(), "")
            ),
            m.axis.param.clone(),
            "average power P (W)",
        )
    };
    both(dir, "response", |p| {
        plot::lines_and_points(p, &figure, &lines, &marks.points(), 8)
    })
}

/// `response.png/.svg` of a `band-response` directory: the mean power over the seeds against
/// the band's centre, with its standard error (dashed) and each seed's power (points).
pub fn plot_band_response(dir: &Path) -> Result<()> {
    let m: BandResponseManifest = read(&dir.join("band_response.json"))?;
    let (h, rows) = read_csv(&dir.join("response.csv"))?;
    let x = numbers(&rows, column(&h, "centre_hz")?);
    let mean = numbers(&rows, column(&h, "power_w")?);
    let se = numbers(&rows, column(&h, "power_se_w")?);
    let high: Vec<f64> = mean.iter().zip(&se).map(|(m, s)| m + s).collect();
    let low: Vec<f64> = mean.iter().zip(&se).map(|(m, s)| m - s).collect();
    let (sh, srows) = read_csv(&dir.join("seeds.csv"))?;
    let sx = numbers(&srows, column(&sh, "centre_hz")?);
    let sy = numbers(&srows, column(&sh, "power_w")?);
    let marks = BandMarks::of(m.summary.bandwidth.as_ref(), (m.from, m.to));
    let lines = [
        Series::new("mean over the seeds", &x, &mean).colour(0),
        Series::new("± standard error", &x, &high).dashed().colour(0),
        Series::unlabelled(&x, &low).dashed().colour(0),
        marks.lines(),
    ];
    let [peak, edges] = marks.points();
    let points = [
        Series::new("each seed", &sx, &sy)
            .marker(Shape::Cross, 7)
            .colour(1),
        peak,
        edges,
    ];
    let figure = Figure {
        legend: legend_corner(&[(&x, &high), (&sx, &sy)], (m.from, m.to)),
        ..Figure::new(
            format!(
                "Response to band-limited noise: {} Hz band, {} m/s² RMS, {} seeds",
                m.summary.width_hz,
                m.summary.rms_acceleration,
                m.summary.seeds.len()
            ),
            "centre frequency of the band (Hz)",
            "average power P (W)",
        )
    };
    both(dir, "response", |p| {
        plot::lines_and_points(p, &figure, &lines, &points, 8)
    })
}
