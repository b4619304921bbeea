//! The per-run analyses of a `simulate` directory: the Poincaré sections the run's own
//! observers take ([`RunSections`]: the library's stroboscopic and impact sections, every
//! contact, stops included), written as `poincare_strobe.csv` and `poincare_impacts.csv`
//! beside the run's files; and the pictures `--plot` and `plot DIR` draw from those files,
//! `summary.json` and `trajectory.csv`: time histories, phase portraits, the sections, the
//! power spectral densities (written as `psd_x{i}.csv`) and the running power.

use std::path::Path;

use anyhow::{Result, bail};
use vibrotribo::analysis::{
    ImpactSection, StroboscopicOptions, StroboscopicSection, WelchOptions, welch_psd,
};
use vibrotribo::report::RunSummary;
use vibrotribo::study::{Mechanics, RunObserver, RunSpec};

use crate::manifest::{Kind, read_of};
use crate::output::{CsvFile, column, numbered, numbers, read_csv, si};
use crate::plot::{self, Figure, Legend, Scale, Series, both};

/// The stroboscopic section (t = nT after the transient) and the impact section (every
/// impact after the transient) of a run, taken by the run's observers from the exact flow.
pub struct RunSections {
    sections: Mechanics<(StroboscopicSection, ImpactSection)>,
}

impl RunSections {
    /// The sections of a run of `spec`.
    pub fn new(spec: &RunSpec) -> Result<Self> {
        let (n, period) = (spec.chain.len(), spec.chain.period());
        let strobe = StroboscopicSection::new(
            n,
            period,
            StroboscopicOptions {
                phase_time: 0.0,
                transient_periods: spec.transient_periods,
            },
        )?;
        let impacts = ImpactSection::new(n, period, spec.transient_periods as f64 * period)?;
        Ok(RunSections {
            sections: Mechanics::new((strobe, impacts)),
        })
    }

    /// The observer that takes the sections.
    pub fn observer(&mut self) -> &mut impl RunObserver {
        &mut self.sections
    }

    /// Writes `poincare_strobe.csv` (period, time, positions, velocities) and
    /// `poincare_impacts.csv` (time, phase t/T mod 1, contact 1-based, closing speed) to `dir`.
    pub fn write(&self, dir: &Path) -> Result<()> {
        let (strobe, impacts) = &self.sections.inner;
        let n = strobe.masses();
        let mut csv = CsvFile::create(&dir.join(STROBE), &strobe_header(n))?;
        for (j, (&index, &time)) in strobe.indices.iter().zip(&strobe.times).enumerate() {
            let mut row = vec![index as f64, time];
            row.extend(strobe.positions_at(j).unwrap_or_default());
            row.extend(strobe.velocities_at(j).unwrap_or_default());
            csv.row(row)?;
        }
        csv.flush()?;
        let mut csv = CsvFile::create(&dir.join(IMPACTS), &IMPACT_COLUMNS)?;
        for p in &impacts.points {
            csv.row([
                p.time.to_string(),
                p.phase.to_string(),
                (p.contact + 1).to_string(),
                p.closing_speed.to_string(),
            ])?;
        }
        csv.flush()
    }
}

/// The stroboscopic section's file.
const STROBE: &str = "poincare_strobe.csv";
/// The impact section's file.
const IMPACTS: &str = "poincare_impacts.csv";
/// The impact section's columns.
const IMPACT_COLUMNS: [&str; 4] = ["time_s", "phase", "contact", "rel_velocity_m_s"];

fn strobe_header(masses: usize) -> Vec<String> {
    let mut h = vec!["period".to_string(), "time_s".to_string()];
    h.extend(numbered("x", masses, "_m"));
    h.extend(numbered("v", masses, "_m_s"));
    h
}

/// Reads a section file of `dir` (written by `simulate --out`).
fn read_section(dir: &Path, name: &str) -> Result<(Vec<String>, Vec<Vec<String>>)> {
    let path = dir.join(name);
    if !path.exists() {
        bail!(
            "{} has no {name}: the sections are taken during the run and written by `vibrotribo simulate --out` (run it again to draw them)",
            dir.display()
        );
    }
    read_csv(&path)
}

/// The pictures of a `simulate` directory: time histories over the last two periods, phase
/// portraits with their stroboscopic section, the impact section, the power spectral
/// densities of the positions after the transient (written as `psd_x{i}.csv`; only mass
/// `psd_mass` if given), the running average power and, with a harvester, the V–Q cycle.
pub fn analyze_run(dir: &Path, psd_mass: Option<usize>) -> Result<()> {
    let summary: RunSummary = read_of(dir, Kind::Simulate)?;
    let period = summary.excitation_period_s;
    let transient = summary.transient_periods as f64 * period;
    let cmeo_cycle = summary
        .merit
        .as_ref()
        .and_then(|m| m.merit.as_ref())
        .map(|m| m.cmeo_cycle_vq);
    crate::merit::plot_vq(dir, cmeo_cycle.as_ref(), transient)?;
    let (h, rows) = read_csv(&dir.join("trajectory.csv"))?;
    let t = numbers(&rows, 0);
    let masses = summary.parameters.len();
    draw_time_histories(dir, &h, &rows, &t, masses, period)?;
    let xs: Vec<Vec<f64>> = (1..=masses)
        .map(|i| column(&h, &format!("x{i}_m")).map(|c| numbers(&rows, c)))
        .collect::<Result<_>>()?;
    let vs: Vec<Vec<f64>> = (1..=masses)
        .map(|i| column(&h, &format!("v{i}_m_s")).map(|c| numbers(&rows, c)))
        .collect::<Result<_>>()?;
    // Phase portraits after the transient, with the stroboscopic section the run took.
    let (sh, srows) = read_section(dir, STROBE)?;
    let after: Vec<usize> = (0..t.len()).filter(|&j| t[j] >= transient).collect();
    for i in 0..masses {
        let x: Vec<f64> = after.iter().map(|&j| xs[i][j]).collect();
        let v: Vec<f64> = after.iter().map(|&j| vs[i][j]).collect();
        let sx = numbers(&srows, column(&sh, &format!("x{}_m", i + 1))?);
        let sv = numbers(&srows, column(&sh, &format!("v{}_m_s", i + 1))?);
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
    draw_impact_section(dir, masses)?;
    // Samples per period, as the run took them (a summary written without the key: the
    // settings' value, or its default).
    let spp = summary
        .samples_per_period
        .or_else(|| summary.settings["run"]["samples_per_period"].as_u64())
        .unwrap_or(vibrotribo::study::RunSettings::default().samples_per_period)
        .max(1) as usize;
    // The first sample at t = nT after the transient.
    let first = (0..t.len())
        .step_by(spp)
        .find(|&j| t[j] >= transient * (1.0 - 1e-12))
        .unwrap_or(0);
    for i in (0..masses).filter(|i| psd_mass.is_none_or(|m| m == i + 1)) {
        draw_psd(dir, i, &xs[i][first..], spp as f64 / period)?;
    }
    // Running average power P_a(N).
    if let Some(e) = &summary.electrical {
        let y = &e.power_curve;
        let n: Vec<f64> = (1..=y.len()).map(|k| k as f64).collect();
        let mut fig = Figure::new(
            "Running average power P_a(N) (seed eq. 14)",
            "periods N",
            "P_a [W]",
        );
        fig.legend = Legend::Hidden;
        both(dir, "power_curve", |path| {
            plot::line_plot(path, &fig, &[Series::unlabelled(&n, y)])
        })?;
    }
    Ok(())
}

/// The gaps and the harvester's signals over the last two periods of the run.
fn draw_time_histories(
    dir: &Path,
    h: &[String],
    rows: &[Vec<String>],
    t: &[f64],
    masses: usize,
    period: f64,
) -> Result<()> {
    let t_last = t.last().copied().unwrap_or(0.0);
    let recent: Vec<usize> = (0..t.len()).filter(|&j| t[j] >= t_last - 2.0 * period).collect();
    let pick = |v: &[f64]| -> Vec<f64> { recent.iter().map(|&j| v[j]).collect() };
    let tr = pick(t);
    let d: Vec<Vec<f64>> = (1..masses)
        .map(|k| column(h, &format!("d{k}_m")).map(|c| pick(&numbers(rows, c))))
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
        if let Ok(c) = column(h, col) {
            let y = pick(&numbers(rows, c));
            let mut fig = Figure::new(format!("{title} (last two periods)"), "time t [s]", ylabel);
            fig.legend = Legend::Hidden;
            both(dir, name, |path| {
                plot::line_plot(path, &fig, &[Series::unlabelled(&tr, &y)])
            })?;
        }
    }
    Ok(())
}

/// The impact section the run took: excitation phase and closing speed of every impact after
/// the transient, one series per contact (every contact between masses; a stop's where it
/// was hit).
fn draw_impact_section(dir: &Path, masses: usize) -> Result<()> {
    let (h, rows) = read_section(dir, IMPACTS)?;
    let (phase, contact, speed) = (
        numbers(&rows, column(&h, "phase")?),
        numbers(&rows, column(&h, "contact")?),
        numbers(&rows, column(&h, "rel_velocity_m_s")?),
    );
    // Contacts 1 … N − 1 between the masses, N the lower stop, N + 1 the upper stop.
    let mut per_contact: Vec<(Vec<f64>, Vec<f64>)> = vec![(vec![], vec![]); masses + 1];
    for ((p, k), v) in phase.iter().zip(&contact).zip(&speed) {
        if let Some(pc) = (*k as usize).checked_sub(1).and_then(|k| per_contact.get_mut(k)) {
            pc.0.push(*p);
            pc.1.push(*v);
        }
    }
    let names: Vec<String> = (1..=masses + 1)
        .map(|k| match k {
            k if k < masses => format!("V{}{}", k, k + 1),
            k if k == masses => format!("V{masses} (lower stop)"),
            _ => "V1 (upper stop)".to_string(),
        })
        .collect();
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
    })
}

/// The power spectral density of mass `i`'s positions `x` sampled at `fs`, Hz (Welch, Hann
/// window, segments by [`WelchOptions::for_record`]): `psd_x{i}.csv` and its picture; a note
/// and nothing else where it cannot be taken.
fn draw_psd(dir: &Path, i: usize, x: &[f64], fs: f64) -> Result<()> {
    let psd = match welch_psd(x, fs, &WelchOptions::for_record(x.len())) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("no PSD of x{}: {e}", i + 1);
            return Ok(());
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
    })
}
