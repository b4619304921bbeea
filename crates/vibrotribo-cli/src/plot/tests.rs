//! Tests of the plots.

use super::draw::{heat_map, line_plot, phase_portrait, scatter_plot};
use super::figure::{Figure, Format, HeatMap, Legend, Scale, Series};
use super::style::{ensure_font, tick_label};
use super::xy::{Layers, clip_polyline, draw_xy, xy_chart};
use plotters::prelude::*;
use std::f64::consts::TAU;
use std::path::Path;
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

#[test]
fn dashes_cover_the_line_in_alternating_pieces() {
    use super::xy::dashes;
    // A straight line of 100 px: dashes of 9 px with gaps of 6 px, the first from the start.
    let pieces = dashes(&[(0, 0), (100, 0)], 9.0, 6.0);
    assert_eq!(pieces.len(), 7, "{pieces:?}");
    assert_eq!(pieces[0], vec![(0, 0), (9, 0)]);
    assert_eq!(pieces[1], vec![(15, 0), (24, 0)]);
    let drawn: i32 = pieces.iter().map(|p| p.last().unwrap().0 - p[0].0).sum();
    assert_eq!(drawn, 7 * 9);
    // The pattern runs on across a corner.
    let corner = dashes(&[(0, 0), (5, 0), (5, 10)], 9.0, 6.0);
    assert_eq!(corner[0], vec![(0, 0), (5, 0), (5, 4)]);
}

#[test]
fn titles_shrink_then_shorten_to_fit() {
    use super::style::{TITLE_MIN_PX, TITLE_PX, fitted_title};
    // A stand-in measure: every character half the font size wide.
    let width = |t: &str, px: u32| t.chars().count() as u32 * px / 2;
    let short = "Orbit diagram";
    assert_eq!(fitted_title(short, 1000, width), (short.to_string(), TITLE_PX));
    let long = "x".repeat(80);
    let (text, px) = fitted_title(&long, 80 * 11, width);
    assert_eq!(text, long, "fits at a smaller size");
    assert!((TITLE_MIN_PX..TITLE_PX).contains(&px) && width(&text, px) <= 80 * 11);
    let (text, px) = fitted_title(&long, 300, width);
    assert_eq!(px, TITLE_MIN_PX);
    assert!(text.ends_with('…') && width(&text, px) <= 300, "{text}");
    assert!(text.chars().count() > 20, "shortened no more than needed: {text}");
}

#[test]
fn markers_stay_inside_their_size() {
    use super::figure::{Marker, Shape};
    use super::xy::marker_outline;
    for shape in [
        Shape::Circle,
        Shape::Triangle,
        Shape::Diamond,
        Shape::Square,
        Shape::Cross,
    ] {
        let marker = Marker { shape, size_px: 12 };
        let outline = marker_outline(marker, (100, 50));
        assert!(outline.len() >= 3, "{shape:?}");
        for (x, y) in outline {
            assert!(
                (x - 100).abs() <= 6 && (y - 50).abs() <= 6,
                "{shape:?}: ({x}, {y})"
            );
        }
    }
}
