//! Pictures of result directories (`vibrotribo plot DIR`, and `--plot` on each command), and
//! the per-run analyses of a `simulate` directory: Poincaré sections, power spectral
//! densities, phase portraits, time histories and the running average power.

use std::path::Path;

use anyhow::{Context, Result, bail};
use vibrotribo::analysis::{WelchOptions, welch_psd};

use crate::manifest::{Kind, MapManifest, SweepManifest, kind_of, read};
use crate::output::{CsvFile, column, numbers, read_csv, read_json, si};
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
        Some(Kind::Simulate) => analyze_run(dir, psd_mass),
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
        None => bail!(
            "{} holds no vibrotribo results (expected the manifest of a command: summary.json beside trajectory.csv, sweep.json, map.json, basins.json, attractors.json, chirp.json, continue.json, bifmap.json, response.json, band_response.json, lyapunov.json, load_sweep.json, periodic.json, fit.json beside optimum.csv, or optimize.json)",
            dir.display()
        ),
    }
}

/// Orbit diagrams, impact-velocity diagrams and the summary curves of a sweep.
pub fn plot_sweep(dir: &Path) -> Result<()> {
    let m: SweepManifest = read(&dir.join("sweep.json"))?;
    let param = m.param;
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
    let m: MapManifest = read(&dir.join("map.json"))?;
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

/// The per-run analyses of a `simulate` directory: writes `poincare_strobe.csv`,
/// `poincare_impacts.csv`, `psd_x{i}.csv` and draws time histories, phase portraits, the
/// sections, the PSD and the running power.
pub fn analyze_run(dir: &Path, psd_mass: Option<usize>) -> Result<()> {
    let summary = read_json(&dir.join("summary.json"))?;
    let period = summary["excitation_period_s"]
        .as_f64()
        .context("summary.json: excitation_period_s")?;
    let transient = summary["transient_periods"].as_u64().unwrap_or(0) as f64 * period;
    crate::merit::plot_vq(dir, &summary, transient)?;
    let (h, rows) = read_csv(&dir.join("trajectory.csv"))?;
    let t = numbers(&rows, 0);
    let masses = h
        .iter()
        .filter(|c| c.starts_with('x') && c.ends_with("_m"))
        .count();
    // Time histories over the last two periods (the whole run is in trajectory.csv).
    let t_last = t.last().copied().unwrap_or(0.0);
    let recent: Vec<usize> = (0..t.len()).filter(|&j| t[j] >= t_last - 2.0 * period).collect();
    let pick = |v: &[f64]| -> Vec<f64> { recent.iter().map(|&j| v[j]).collect() };
    let tr = pick(&t);
    let d: Vec<Vec<f64>> = (1..masses)
        .map(|k| column(&h, &format!("d{k}_m")).map(|c| pick(&numbers(&rows, c))))
        .collect::<Result<_>>()?;
    let sum: Vec<f64> = (0..tr.len()).map(|j| d.iter().map(|dk| dk[j]).sum()).collect();
    let labels: Vec<String> = (1..masses).map(|k| format!("D{k}")).collect();
    let mut series: Vec<Series> = d
        .iter()
        .zip(&labels)
        .map(|(dk, l)| Series::new(l, &tr, dk))
        .collect();
    if masses > 2 {
        series.push(Series::new("sum of the gaps", &tr, &sum));
    }
    both(dir, "gaps", |path| {
        plot::line_plot(
            path,
            &Figure::new(
                "Gaps between the masses (last two periods)",
                "time t [s]",
                "gap [m]",
            ),
            &series,
        )
    })?;
    for (col, title, ylabel, name) in [
        ("c_f", "Capacitance C", "C [F]", "capacitance"),
        ("v_v", "Load voltage V", "V [V]", "voltage"),
        ("i_a", "Current I", "I [A]", "current"),
        (
            "voc_v",
            "Open-circuit voltage V_oc",
            "V_oc [V]",
            "open_circuit_voltage",
        ),
        ("vs_v", "Storage capacitor voltage", "V_s [V]", "storage_voltage"),
    ] {
        if let Ok(c) = column(&h, col) {
            let y = pick(&numbers(&rows, c));
            let mut fig = Figure::new(format!("{title} (last two periods)"), "time t [s]", ylabel);
            fig.legend = Legend::Hidden;
            both(dir, name, |path| {
                plot::line_plot(path, &fig, &[Series::unlabelled(&tr, &y)])
            })?;
        }
    }
    // Stroboscopic section (grid points at t = nT after the transient) and phase portraits.
    let spp = rows
        .iter()
        .position(|r| r[0].parse::<f64>().is_ok_and(|x| x >= period * (1.0 - 1e-12)))
        .unwrap_or(1)
        .max(1);
    let strobe: Vec<usize> = (0..rows.len())
        .filter(|&j| j % spp == 0 && t[j] >= transient * (1.0 - 1e-12))
        .collect();
    let mut csv = CsvFile::create(&dir.join("poincare_strobe.csv"), &strobe_header(masses))?;
    let xs: Vec<Vec<f64>> = (1..=masses)
        .map(|i| column(&h, &format!("x{i}_m")).map(|c| numbers(&rows, c)))
        .collect::<Result<_>>()?;
    let vs: Vec<Vec<f64>> = (1..=masses)
        .map(|i| column(&h, &format!("v{i}_m_s")).map(|c| numbers(&rows, c)))
        .collect::<Result<_>>()?;
    for &j in &strobe {
        let mut row = vec![(j / spp) as f64, t[j]];
        row.extend(xs.iter().map(|x| x[j]));
        row.extend(vs.iter().map(|v| v[j]));
        csv.row(row)?;
    }
    csv.flush()?;
    for i in 0..masses {
        let after: Vec<usize> = (0..t.len()).filter(|&j| t[j] >= transient).collect();
        let x: Vec<f64> = after.iter().map(|&j| xs[i][j]).collect();
        let v: Vec<f64> = after.iter().map(|&j| vs[i][j]).collect();
        let sx: Vec<f64> = strobe.iter().map(|&j| xs[i][j]).collect();
        let sv: Vec<f64> = strobe.iter().map(|&j| vs[i][j]).collect();
        let fig = Figure::new(
            format!(
                "Phase portrait of m{} after the transient, with its stroboscopic section",
                i + 1
            ),
            format!("x{} [m]", i + 1),
            format!("v{} [m/s]", i + 1),
        );
        both(dir, &format!("phase_x{}", i + 1), |path| {
            plot::phase_portrait(
                path,
                &fig,
                &[Series::new("trajectory", &x, &v)],
                Some(Series::new("t = nT", &sx, &sv)),
            )
        })?;
    }
    // Impact section: phase of the excitation and closing speed of every impact after the
    // transient.
    let (eh, erows) = read_csv(&dir.join("events.csv"))?;
    let (tc, kc, cc, vc) = (
        column(&eh, "time_s")?,
        column(&eh, "kind")?,
        column(&eh, "contact")?,
        column(&eh, "rel_velocity_m_s")?,
    );
    let mut csv = CsvFile::create(
        &dir.join("poincare_impacts.csv"),
        &["time_s", "phase", "contact", "rel_velocity_m_s"],
    )?;
    // Contacts 1 … N − 1 between the masses, N the lower stop, N + 1 the upper stop.
    let mut per_contact: Vec<(Vec<f64>, Vec<f64>)> = vec![(vec![], vec![]); masses + 1];
    for r in erows.iter().filter(|r| r[kc] == "impact") {
        let te: f64 = r[tc].parse().unwrap_or(f64::NAN);
        if te < transient {
            continue;
        }
        let phase = (te / period).fract();
        let k: usize = r[cc].parse().unwrap_or(1);
        let v: f64 = r[vc].parse().unwrap_or(f64::NAN);
        csv.row([te.to_string(), phase.to_string(), k.to_string(), v.to_string()])?;
        if let Some(pc) = per_contact.get_mut(k - 1) {
            pc.0.push(phase);
            pc.1.push(v);
        }
    }
    csv.flush()?;
    let names: Vec<String> = (1..=masses + 1)
        .map(|k| match k {
            k if k < masses => format!("V{}{}", k, k + 1),
            k if k == masses => format!("V{masses} (lower stop)"),
            _ => "V1 (upper stop)".to_string(),
        })
        .collect();
    // Every contact between masses; a stop's only where it was hit.
    let series: Vec<Series> = per_contact
        .iter()
        .zip(&names)
        .enumerate()
        .filter(|(k, ((p, _), _))| *k + 1 < masses || !p.is_empty())
        .map(|(_, ((p, v), n))| Series::new(n, p, v))
        .collect();
    both(dir, "poincare_impacts", |path| {
        plot::scatter_plot(
            path,
            &Figure::new(
                "Impact section: excitation phase and closing speed of each impact",
                "phase t/T mod 1",
                "closing speed [m/s]",
            ),
            &series,
            5,
        )
    })?;
    // Power spectral densities of the positions after the transient (Welch, Hann window).
    let fs = spp as f64 / period;
    let first = strobe.first().copied().unwrap_or(0);
    for i in (0..masses).filter(|i| psd_mass.is_none_or(|m| m == i + 1)) {
        let x = &xs[i][first..];
        let segment = (x.len() / 4)
            .next_power_of_two()
            .min(x.len().next_power_of_two() / 2)
            .max(16);
        let options = WelchOptions {
            segment_len: segment.min(x.len()),
            ..WelchOptions::default()
        };
        let psd = match welch_psd(x, fs, &options) {
            Ok(p) => p,
            Err(e) => {
                eprintln!("no PSD of x{}: {e}", i + 1);
                continue;
            }
        };
        let mut csv = CsvFile::create(
            &dir.join(format!("psd_x{}.csv", i + 1)),
            &["frequency_hz", "psd_m2_per_hz"],
        )?;
        for (f, p) in psd.frequencies.iter().zip(&psd.density) {
            csv.row([*f, *p])?;
        }
        csv.flush()?;
        let mut fig = Figure::new(
            format!(
                "PSD of x{} (Welch, Hann, {} × {} samples, Δf = {})",
                i + 1,
                psd.segments,
                psd.segment_len,
                si(psd.resolution, "Hz")
            ),
            "frequency [Hz]",
            format!("PSD of x{} [m²/Hz]", i + 1),
        );
        fig.y_scale = Scale::Log;
        fig.legend = Legend::Hidden;
        let f: Vec<f64> = psd.frequencies.iter().copied().skip(1).collect();
        let p: Vec<f64> = psd.density.iter().copied().skip(1).collect();
        both(dir, &format!("psd_x{}", i + 1), |path| {
            plot::line_plot(path, &fig, &[Series::unlabelled(&f, &p)])
        })?;
    }
    // Running average power P_a(N).
    if let Some(curve) = summary["power_curve"].as_array() {
        let y: Vec<f64> = curve.iter().map(|v| v.as_f64().unwrap_or(f64::NAN)).collect();
        let n: Vec<f64> = (1..=y.len()).map(|k| k as f64).collect();
        let mut fig = Figure::new(
            "Running average power P_a(N) (seed eq. 14)",
            "periods N",
            "P_a [W]",
        );
        fig.legend = Legend::Hidden;
        both(dir, "power_curve", |path| {
            plot::line_plot(path, &fig, &[Series::unlabelled(&n, &y)])
        })?;
    }
    Ok(())
}

fn strobe_header(masses: usize) -> Vec<String> {
    let mut h = vec!["period".to_string(), "time_s".to_string()];
    h.extend(crate::output::numbered("x", masses, "_m"));
    h.extend(crate::output::numbered("v", masses, "_m_s"));
    h
}
