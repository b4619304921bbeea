//! Pictures of result directories (`vibrotribo plot DIR`, and `--plot` on each command): each
//! kind told by its manifest and drawn by its command's drawing code; the sweep's and the
//! map's pictures here (a `simulate` directory's in [`crate::run_analyses`]).

use std::path::Path;

use anyhow::{Result, bail};

use crate::manifest::{Kind, MapManifest, SweepManifest, kind_of, read_of};
use crate::output::{column, numbers, read_csv};
use crate::plot::{self, Figure, HeatMap, Legend, Scale, Series, both};

/// Draws whatever `dir` holds: the output directory of any command that writes one, told by
/// its manifest; each kind with the drawing code of its command's `--plot`.
pub fn plot_dir(dir: &Path, psd_mass: Option<usize>) -> Result<()> {
    if !dir.exists() {
        bail!("{} does not exist", dir.display());
    }
    if !dir.is_dir() {
        bail!(
            "{} is not a directory (plot takes an output directory)",
            dir.display()
        );
    }
    match kind_of(dir)? {
        Some(Kind::Sweep) => plot_sweep(dir),
        Some(Kind::Map) => plot_map(dir),
        Some(Kind::Basins) => {
            crate::basins::finish(dir)?;
            crate::basins::plot_basins(dir)
        }
        Some(Kind::Attractors) => crate::attractors::plot_attractors(dir),
        Some(Kind::Chirp) => crate::chirp::plot_chirp(dir),
        Some(Kind::Lyapunov) => crate::lyapunov::plot_lyapunov(dir),
        Some(Kind::Simulate) => crate::run_analyses::analyze_run(dir, psd_mass),
        Some(Kind::Continue) => {
            crate::branch_picture::plot_dir(dir, None, crate::continuation::DEFAULT_DIAGRAM_STEPS)
        }
        Some(Kind::LoadSweep) => crate::load_sweep::plot_load_sweep(dir),
        Some(Kind::Periodic) => crate::periodic::plot_periodic(dir),
        Some(Kind::OptimizeMassRatio) => crate::mass_ratio_picture::plot_optimize_mass_ratio(dir),
        Some(Kind::Optimize) => crate::optimize::plot_convergence(dir),
        Some(Kind::Response) => crate::response_picture::plot_response(dir),
        Some(Kind::BandResponse) => crate::response_picture::plot_band_response(dir),
        Some(Kind::Bifmap) => crate::bifmap_picture::plot_dir(dir),
        Some(Kind::Curve) => crate::curve_picture::plot_curve(dir),
        None => bail!(
            "{} holds no vibrotribo results (expected the manifest of a command: {})",
            dir.display(),
            Kind::manifests().collect::<Vec<_>>().join(", ")
        ),
    }
}

/// Orbit diagrams, impact-velocity diagrams and the summary curves of a sweep.
pub fn plot_sweep(dir: &Path) -> Result<()> {
    let m: SweepManifest = read_of(dir, Kind::Sweep)?;
    let param = m.axis.param;
    let delta1 = m.settings["oscillator"]["gaps"]
        .as_array()
        .and_then(|g| g.first())
        .and_then(|g| g.as_f64())
        .unwrap_or(0.020);
    let (oh, orows) = read_csv(&dir.join("orbit.csv"))?;
    let p = numbers(&orows, 0);
    let masses = oh.len() - 2;
    let (sh, srows) = read_csv(&dir.join("summary.csv"))?;
    // The motion of each value, to colour the orbit diagram by (older files have none).
    let motion_of: std::collections::HashMap<String, String> = match column(&sh, "motion") {
        Ok(c) => srows
            .iter()
            .map(|r| (r[0].clone(), r.get(c).cloned().unwrap_or_default()))
            .collect(),
        Err(_) => Default::default(),
    };
    let motions: Vec<&str> = orows
        .iter()
        .map(|r| motion_of.get(&r[0]).map_or("", String::as_str))
        .collect();
    for i in 0..masses {
        let x: Vec<f64> = numbers(&orows, 2 + i).iter().map(|v| v / delta1).collect();
        let mut fig = Figure::new(
            format!("Orbit diagram: X{} = x{}/δ1 at t = nT", i + 1, i + 1),
            param.clone(),
            format!("X{} (dimensionless)", i + 1),
        );
        let groups = by_motion(&motions, &p, &x);
        fig.legend = if groups.len() > 1 || groups.iter().any(|g| !g.0.is_empty()) {
            Legend::UpperLeft
        } else {
            Legend::Hidden
        };
        let series: Vec<Series<'_>> = groups
            .iter()
            .map(|(name, k, xs, ys)| {
                if name.is_empty() {
                    Series::unlabelled(xs, ys)
                } else {
                    Series::new(name, xs, ys).colour(*k)
                }
            })
            .collect();
        both(dir, &format!("orbit_x{}", i + 1), |path| {
            plot::scatter_plot(path, &fig, &series, 2)
        })?;
    }
    let (ih, irows) = read_csv(&dir.join("impacts.csv"))?;
    let (pc, cc, vc) = (
        column(&ih, "param")?,
        column(&ih, "contact")?,
        column(&ih, "rel_velocity_m_s")?,
    );
    let ip = numbers(&irows, pc);
    let ic = numbers(&irows, cc);
    let iv = numbers(&irows, vc);
    for k in 1..masses {
        let (xs, ys): (Vec<f64>, Vec<f64>) = ip
            .iter()
            .zip(&ic)
            .zip(&iv)
            .filter(|((_, c), _)| **c as usize == k)
            .map(|((p, _), v)| (*p, *v))
            .unzip();
        let mut fig = Figure::new(
            format!(
                "Impact velocities V{}{} (closing speed before each impact)",
                k,
                k + 1
            ),
            param.clone(),
            format!("V{}{} [m/s]", k, k + 1),
        );
        fig.legend = Legend::Hidden;
        both(dir, &format!("impacts_v{}{}", k, k + 1), |path| {
            plot::scatter_plot(path, &fig, &[Series::unlabelled(&xs, &ys)], 2)
        })?;
    }
    let sp = numbers(&srows, column(&sh, "param")?);
    let power = numbers(&srows, column(&sh, "average_power_w")?);
    if power.iter().any(|x| x.is_finite()) {
        let mut fig = Figure::new("Average power", param.clone(), "P_a [W]");
        fig.legend = Legend::Hidden;
        if power.iter().all(|x| !x.is_finite() || *x > 0.0) {
            fig.y_scale = Scale::Log;
        }
        both(dir, "power", |path| {
            plot::line_plot(path, &fig, &[Series::unlabelled(&sp, &power)])
        })?;
    }
    if let Ok(c) = column(&sh, "lyapunov_max_1_s") {
        let l = numbers(&srows, c);
        let spread = numbers(&srows, column(&sh, "lyapunov_spread_1_s")?);
        let (lo, hi): (Vec<f64>, Vec<f64>) = l
            .iter()
            .zip(&spread)
            .map(|(l, s)| (l - 3.0 * s, l + 3.0 * s))
            .unzip();
        let zero = vec![0.0; sp.len()];
        let mut fig = Figure::new(
            "Largest Lyapunov exponent (± 3 batch-means standard errors)",
            param.clone(),
            "λ1 [1/s]",
        );
        fig.legend = Legend::UpperLeft;
        both(dir, "lyapunov", |path| {
            plot::line_plot(
                path,
                &fig,
                &[
                    Series::new("λ1", &sp, &l),
                    Series::new("λ1 − 3σ", &sp, &lo),
                    Series::new("λ1 + 3σ", &sp, &hi),
                    Series::unlabelled(&sp, &zero),
                ],
            )
        })?;
    }
    let ipp = numbers(&srows, column(&sh, "impacts_per_period")?);
    let period = numbers(&srows, column(&sh, "period")?);
    let mut fig = Figure::new(
        "Impacts per period and detected period (0: non-periodic)",
        param.clone(),
        "count",
    );
    fig.legend = Legend::UpperLeft;
    both(dir, "impacts_and_period", |path| {
        plot::scatter_plot(
            path,
            &fig,
            &[
                Series::new("impacts per period", &sp, &ipp),
                Series::new("period", &sp, &period),
            ],
            7,
        )
    })
}

/// The motions in the order of their colours.
const MOTIONS: [&str; 4] = ["periodic", "settling", "quasiperiodic", "chaotic"];

/// The points `(x, y)` grouped by their motion (`motions`, one per point): per motion
/// present, its name, colour index and points; points without a motion in one unnamed group.
fn by_motion<'a>(motions: &[&str], x: &[f64], y: &[f64]) -> Vec<(&'a str, usize, Vec<f64>, Vec<f64>)> {
    let mut groups = Vec::new();
    for (k, name) in MOTIONS.iter().copied().chain([""]).enumerate() {
        let (xs, ys): (Vec<f64>, Vec<f64>) = motions
            .iter()
            .zip(x.iter().zip(y))
            .filter(|(m, _)| {
                if name.is_empty() {
                    !MOTIONS.contains(m)
                } else {
                    **m == name
                }
            })
            .map(|(_, (a, b))| (*a, *b))
            .unzip();
        if !xs.is_empty() {
            groups.push((name, k, xs, ys));
        }
    }
    groups
}

/// Heat maps of a two-parameter map.
pub fn plot_map(dir: &Path) -> Result<()> {
    let m: MapManifest = read_of(dir, Kind::Map)?;
    let (xk, yk) = (m.x.param, m.y.param);
    let (xs, ys) = (m.x.values, m.y.values);
    let (h, rows) = read_csv(&dir.join("map.csv"))?;
    for (col, title, label, log) in [
        ("average_power_w", "Average power", "log10(P_a / W)", true),
        ("period", "Detected period (0: non-periodic)", "period", false),
        (
            "impacts_per_period",
            "Impacts per period",
            "impacts per period",
            false,
        ),
    ] {
        let c = column(&h, col)?;
        let v = numbers(&rows, c);
        if v.iter().all(|x| !x.is_finite()) {
            continue;
        }
        let values: Vec<f64> = v
            .iter()
            .map(|x| {
                if log {
                    if *x > 0.0 { x.log10() } else { f64::NAN }
                } else {
                    *x
                }
            })
            .collect();
        // map.csv rows run over x fastest, y slowest: row-major from the bottom.
        let map = HeatMap::centred_on_nodes(
            (xs[0], xs[xs.len() - 1]),
            (ys[0], ys[ys.len() - 1]),
            xs.len(),
            ys.len(),
            &values,
            label,
        );
        let fig = Figure::new(title, xk.clone(), yk.clone());
        both(dir, &format!("map_{col}"), |path| {
            plot::heat_map(path, &fig, &map)
        })?;
    }
    if let Ok(c) = column(&h, "motion") {
        let cells: Vec<Option<usize>> = rows
            .iter()
            .map(|r| MOTIONS.iter().position(|m| r.get(c).is_some_and(|v| v == m)))
            .collect();
        let names: Vec<String> = MOTIONS.map(String::from).to_vec();
        let map = plot::CategoryMap {
            x_nodes: (xs[0], xs[xs.len() - 1]),
            y_nodes: (ys[0], ys[ys.len() - 1]),
            nx: xs.len(),
            ny: ys.len(),
            cells: &cells,
            names: &names,
            missing: "failed",
        };
        let fig = Figure::new("Motion", xk.clone(), yk.clone());
        both(dir, "map_motion", |path| plot::category_map(path, &fig, &map))?;
    }
    Ok(())
}
