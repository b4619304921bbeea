//! Beyond the paper: two-way coupling. The electrostatic force of the charges acts
//! back on the masses (`harvester.coupling = "two_way"`): how much does it change the paper's
//! default and chatter cases, the chatter case's response over Ω, and the optimal load?
//! Every run uses the exact V_oc law in both modes, so that only the coupling differs.

use std::fmt::Write as _;
use std::time::Instant;

use anyhow::{Context, Result};
use rayon::prelude::*;
use toml::Value;
use vibrotribo::config::Config;
use vibrotribo::electrical::{EPSILON_0, log_spaced};
use vibrotribo::study::simulate;

use super::context::Ctx;
use super::draw::both;
use crate::output::si;
use crate::plot::{self, Figure, Scale, Series};

/// The chatter case of Sect. 4.4 (m1 = m3 = 50 g, R_m = 3, δ = 5 mm).
const CHATTER: [(&str, &str); 2] = [
    ("oscillator.masses", "[0.05, 0.15, 0.05]"),
    ("oscillator.gaps", "[0.005, 0.005]"),
];

/// The two modes, one-way first.
const MODES: [&str; 2] = ["one_way", "two_way"];

/// A relative change of the average power above which the Ω scan names the value, %.
const NOTABLE_PERCENT: f64 = 10.0;

/// One run: which case, which mode, how long.
#[derive(Debug, Clone)]
struct Job {
    chatter: bool,
    omega: f64,
    resistance: f64,
    two_way: bool,
    periods: u64,
    transient: u64,
}

/// What one run delivered after its transient.
#[derive(Debug, Clone, Copy)]
struct Cell {
    power_w: f64,
    impacts_per_period: f64,
    chatter_per_period: f64,
    sticks_per_period: f64,
}

/// A run's result (or why it failed) and its wall time, s.
#[derive(Debug, Clone)]
struct Done {
    cell: std::result::Result<Cell, String>,
    seconds: f64,
}

impl Done {
    fn power(&self) -> f64 {
        self.cell.as_ref().map_or(f64::NAN, |c| c.power_w)
    }
}

fn parse(v: &str) -> Result<Value> {
    let t: toml::Table = toml::from_str(&format!("v = {v}"))?;
    Ok(t["v"].clone())
}

/// The configuration of `job`: the paper's default case (or the chatter case), exact V_oc.
fn config(job: &Job) -> Result<Config> {
    let mut keys: Vec<(&str, Value)> = Vec::new();
    if job.chatter {
        for (k, v) in CHATTER {
            keys.push((k, parse(v)?));
        }
    }
    let mode = MODES[usize::from(job.two_way)];
    keys.extend([
        ("excitation.omega_ratio", Value::Float(job.omega)),
        ("harvester.voc_model", Value::String("exact".into())),
        ("harvester.coupling", Value::String(mode.into())),
        ("harvester.load_resistance", Value::Float(job.resistance)),
        ("run.periods", Value::Integer(job.periods as i64)),
        ("run.transient_periods", Value::Integer(job.transient as i64)),
    ]);
    let mut c = Config::default();
    c.set_all(keys)?;
    Ok(c)
}

/// Runs `job`; a failure (bad configuration, event limit, solver) is kept as its message.
fn run(job: &Job) -> Done {
    let t0 = Instant::now();
    let cell = (|| -> std::result::Result<Cell, String> {
        let c = config(job).map_err(|e| format!("{e:#}"))?;
        let spec = c.run_spec(false);
        let o = simulate(&spec, &mut ()).map_err(|e| e.to_string())?;
        if let Some(e) = o.failure() {
            return Err(format!("after {} complete periods: {e}", o.periods));
        }
        let recorded = (spec.periods - spec.transient_periods).max(1) as f64;
        let power = o
            .electrical
            .as_ref()
            .and_then(|e| e.power_after(spec.transient_periods as usize))
            .map(|p| p.average_power_w)
            .ok_or("no average power")?;
        let impacts: u64 = o.stats.impacts_after_transient().iter().sum();
        Ok(Cell {
            power_w: power,
            impacts_per_period: impacts as f64 / recorded,
            chatter_per_period: o.stats.chatter_sequences as f64 / recorded,
            sticks_per_period: o.stats.sticks as f64 / recorded,
        })
    })();
    Done {
        cell,
        seconds: t0.elapsed().as_secs_f64(),
    }
}

/// The jobs of one case in both modes (one-way, two-way).
fn pair(chatter: bool, omega: f64, resistance: f64, (periods, transient): (u64, u64)) -> [Job; 2] {
    [false, true].map(|two_way| Job {
        chatter,
        omega,
        resistance,
        two_way,
        periods,
        transient,
    })
}

/// (two-way − one-way)/one-way of the powers, %.
fn change(p: &[Done; 2]) -> f64 {
    100.0 * (p[1].power() - p[0].power()) / p[0].power()
}

fn show(d: &Done) -> String {
    match &d.cell {
        Ok(c) => format!(
            "{}; {:.2} impacts, {:.2} chatter sequences/period",
            si(c.power_w, "W"),
            c.impacts_per_period,
            c.chatter_per_period
        ),
        Err(e) => format!("**failed** ({e})"),
    }
}

fn failure_text(d: &Done) -> Option<&str> {
    d.cell.as_ref().err().map(String::as_str)
}

pub(super) fn coupling(ctx: &mut Ctx) -> Result<()> {
    let started = Instant::now();
    let paper_load = 1e5;
    let long = (100, 50);
    let scan_len = if ctx.quick { (60, 30) } else { (100, 50) };
    let omegas: Vec<f64> = {
        let n = if ctx.quick { 21 } else { 36 };
        (0..n).map(|i| 0.3 + 0.7 * i as f64 / (n - 1) as f64).collect()
    };
    let loads = log_spaced(1e3, 1e13, if ctx.quick { 11 } else { 21 });

    // Every independent run at once (the two-way ones first: they are the long ones).
    let mut jobs: Vec<Job> = Vec::new();
    let cases = [(false, 0.70), (true, 0.600), (true, 0.765)];
    for (chatter, omega) in cases {
        jobs.extend(pair(chatter, omega, paper_load, long));
    }
    for &w in &omegas {
        jobs.extend(pair(true, w, paper_load, scan_len));
    }
    for &r in &loads {
        jobs.extend(pair(false, 0.70, r, long));
    }
    let mut order: Vec<usize> = (0..jobs.len()).collect();
    order.sort_by_key(|&i| !jobs[i].two_way);
    let mut done: Vec<Option<Done>> = vec![None; jobs.len()];
    let results: Vec<(usize, Done)> = order.par_iter().map(|&i| (i, run(&jobs[i]))).collect();
    for (i, d) in results {
        done[i] = Some(d);
    }
    let done: Vec<Done> = done.into_iter().map(|d| d.expect("every job ran")).collect();
    let pairs: Vec<[Done; 2]> = done.chunks(2).map(|c| [c[0].clone(), c[1].clone()]).collect();
    let (case_pairs, rest) = pairs.split_at(cases.len());
    let (scan, sweep) = rest.split_at(omegas.len());

    // The load sweep's optimum in each mode, refined by golden-section search in log R.
    let (one, two) = rayon::join(|| refine(&loads, sweep, false), || refine(&loads, sweep, true));
    let optima = [one, two];

    let seconds: [f64; 2] = [0, 1].map(|m| {
        done.iter()
            .zip(&jobs)
            .filter(|(_, j)| j.two_way == (m == 1))
            .map(|(d, _)| d.seconds)
            .sum::<f64>()
            + optima[m].runs_seconds
    });

    // Item 1: the three cases.
    let reference = Config::default();
    let h = reference.harvester();
    let k1 = reference.chain().stiffness[0];
    let shift = h.charge_density.powi(2) * h.area / (2.0 * EPSILON_0 * k1);
    let chatter_gap = 0.005;
    let default_gap = reference.chain().gaps[0];
    let mut md = format!(
        "**Two-way coupling.** With `harvester.coupling = \"two_way\"` the electrostatic attraction of the plates' charges, −(aQ + b)²/(2ε₀S) per gap, acts back on the masses (coupling tolerance {:.0e} m). At Q = 0 it is σ²S/(2ε₀) = {} per gap, which alone would pull each outer mass {:.2} mm towards the middle one (σ²S/(2ε₀k), k = {k1} N/m): {:.0} % of the default case's {:.0} mm gaps and {:.0} % of the chatter case's {:.0} mm. Both modes use the exact V_oc law, so that only the coupling differs; 100 kΩ; {} periods, the first {} transient. Cells: average power; impacts and chatter sequences per period after the transient.\n\n| case | one-way | two-way | change |\n|---|---|---|---|\n",
        h.coupling_tolerance,
        si(shift * k1, "N"),
        shift * 1e3,
        100.0 * shift / default_gap,
        default_gap * 1e3,
        100.0 * shift / chatter_gap,
        chatter_gap * 1e3,
        long.0,
        long.1,
    );
    let names = [
        "default (Sect. 4.1), Ω = 0.700",
        "chatter (Sect. 4.4), Ω = 0.600",
        "chatter (Sect. 4.4), Ω = 0.765",
    ];
    for (name, p) in names.iter().zip(case_pairs) {
        let _ = writeln!(
            md,
            "| {name} | {} | {} | {:+.2} % |",
            show(&p[0]),
            show(&p[1]),
            change(p)
        );
    }
    ctx.extras.push(md);

    // Item 2: the chatter case over Ω.
    let img = scan_figure(ctx, &omegas, scan)?;
    write_scan_csv(ctx, &omegas, scan)?;
    ctx.figure(
        "extra",
        "Two-way coupling: the chatter case over Ω",
        format!(
            "Average power of the chatter case (Sect. 4.4, 100 kΩ, exact V_oc) against Ω, one-way and two-way, {} values, each from rest over {} periods ({} transient). Failed runs are left out (see \"Beyond the paper\"); the numbers are in `extra_coupling_omega.csv`.",
            omegas.len(),
            scan_len.0,
            scan_len.1
        ),
        vec![img],
    );
    ctx.extras.push(scan_text(&omegas, scan, scan_len));

    // Item 3: the load sweep.
    let img = sweep_figure(ctx, &loads, sweep)?;
    ctx.figure(
        "extra",
        "Two-way coupling: average power against the load",
        format!(
            "The default case (Ω = 0.70, exact V_oc), one-way and two-way, each load a full run of {} periods ({} transient). Failed runs are left out.",
            long.0, long.1
        ),
        vec![img],
    );
    ctx.extras
        .push(sweep_text(&loads, sweep, &optima, &case_pairs[0], long));
    ctx.extras.push(format!(
        "**Cost of the coupling.** This step ran {} one-way and {} two-way simulations in {:.0} s on the clock, as many at a time as there are worker threads; their run times add up to {:.1} s one-way and {:.1} s two-way ({:.0}× as long a run on average). The default case's 100 periods took {:.3} s one-way and {:.2} s two-way ({:.0}×).",
        jobs.len() / 2 + optima[0].runs,
        jobs.len() / 2 + optima[1].runs,
        started.elapsed().as_secs_f64(),
        seconds[0],
        seconds[1],
        (seconds[1] / (jobs.len() / 2 + optima[1].runs) as f64) / (seconds[0] / (jobs.len() / 2 + optima[0].runs) as f64),
        case_pairs[0][0].seconds,
        case_pairs[0][1].seconds,
        case_pairs[0][1].seconds / case_pairs[0][0].seconds,
    ));
    Ok(())
}

/// The load sweep's best point in one mode, refined.
struct Optimum {
    resistance_ohm: f64,
    power_w: f64,
    /// Why it is not refined (at the grid's edge, a neighbour failed), if it is not.
    unrefined: Option<String>,
    /// A failure during the refinement.
    failure: Option<String>,
    runs: usize,
    runs_seconds: f64,
}

/// The best grid point of `sweep` in mode `two_way`, refined by golden-section search for the
/// maximum of P(ln R) between its neighbours (to 1 % in R).
fn refine(loads: &[f64], sweep: &[[Done; 2]], two_way: bool) -> Optimum {
    let m = usize::from(two_way);
    let powers: Vec<f64> = sweep.iter().map(|p| p[m].power()).collect();
    let best = (0..loads.len())
        .filter(|&i| powers[i].is_finite())
        .max_by(|&a, &b| powers[a].total_cmp(&powers[b]));
    let Some(best) = best else {
        return Optimum {
            resistance_ohm: f64::NAN,
            power_w: f64::NAN,
            unrefined: Some("every run failed".into()),
            failure: None,
            runs: 0,
            runs_seconds: 0.0,
        };
    };
    let mut o = Optimum {
        resistance_ohm: loads[best],
        power_w: powers[best],
        unrefined: None,
        failure: None,
        runs: 0,
        runs_seconds: 0.0,
    };
    if best == 0 || best + 1 == loads.len() {
        o.unrefined = Some("the best grid point is at the grid's edge".into());
        return o;
    }
    if !(powers[best - 1].is_finite() && powers[best + 1].is_finite()) {
        o.unrefined = Some("a neighbour of the best grid point failed".into());
        return o;
    }
    let mut evaluate = |ln_r: f64| -> f64 {
        let d = run(&Job {
            chatter: false,
            omega: 0.70,
            resistance: ln_r.exp(),
            two_way,
            periods: 100,
            transient: 50,
        });
        o.runs += 1;
        o.runs_seconds += d.seconds;
        if let Err(e) = &d.cell {
            o.failure
                .get_or_insert_with(|| format!("R = {}: {e}", si(ln_r.exp(), "Ω")));
        }
        d.power()
    };
    let inv_phi = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (loads[best - 1].ln(), loads[best + 1].ln());
    let mut x1 = b - inv_phi * (b - a);
    let mut x2 = a + inv_phi * (b - a);
    let mut p1 = evaluate(x1);
    let mut p2 = evaluate(x2);
    while b - a > 1e-2 && p1.is_finite() && p2.is_finite() {
        if p1 >= p2 {
            b = x2;
            x2 = x1;
            p2 = p1;
            x1 = b - inv_phi * (b - a);
            p1 = evaluate(x1);
        } else {
            a = x1;
            x1 = x2;
            p1 = p2;
            x2 = a + inv_phi * (b - a);
            p2 = evaluate(x2);
        }
    }
    for (x, p) in [(x1, p1), (x2, p2)] {
        if p.is_finite() && p > o.power_w {
            o.resistance_ohm = x.exp();
            o.power_w = p;
        }
    }
    o
}

fn scan_figure(ctx: &Ctx, omegas: &[f64], scan: &[[Done; 2]]) -> Result<String> {
    let fig = Figure::new("Chatter case: average power against Ω", "Ω", "P_a [W]");
    two_curves(ctx, "extra_coupling_omega", fig, omegas, scan)
}

/// Both modes' powers against `xs` on a log scale, lines broken and marks left out where a
/// run failed (a value with failed neighbours shows as a mark alone).
fn two_curves(ctx: &Ctx, name: &str, mut fig: Figure, xs: &[f64], pairs: &[[Done; 2]]) -> Result<String> {
    let curve = |m: usize| -> Vec<f64> {
        pairs
            .iter()
            .map(|p| Some(p[m].power()).filter(|&w| w > 0.0).unwrap_or(f64::NAN))
            .collect()
    };
    let (y0, y1) = (curve(0), curve(1));
    fig.y_scale = Scale::Log;
    both(ctx, name, |path| {
        plot::lines_and_points(
            path,
            &fig,
            &[
                Series::new("one-way", xs, &y0).colour(0),
                Series::new("two-way", xs, &y1).colour(1),
            ],
            &[
                Series::unlabelled(xs, &y0).colour(0),
                Series::unlabelled(xs, &y1).colour(1),
            ],
            5,
        )
    })
}

fn write_scan_csv(ctx: &Ctx, omegas: &[f64], scan: &[[Done; 2]]) -> Result<()> {
    let mut csv = String::from(
        "omega_ratio,mode,power_w,impacts_per_period,chatter_per_period,sticks_per_period,seconds,failure\n",
    );
    for (w, p) in omegas.iter().zip(scan) {
        for (m, d) in p.iter().enumerate() {
            let (cells, failure) = match &d.cell {
                Ok(c) => (
                    format!(
                        "{:e},{},{},{}",
                        c.power_w, c.impacts_per_period, c.chatter_per_period, c.sticks_per_period
                    ),
                    String::new(),
                ),
                Err(e) => (",,,".into(), format!("\"{}\"", e.replace('"', "'"))),
            };
            let _ = writeln!(csv, "{w},{},{cells},{:.3},{failure}", MODES[m], d.seconds);
        }
    }
    let path = ctx.path("extra_coupling_omega.csv");
    std::fs::write(&path, csv).with_context(|| path.display().to_string())
}

/// "no value", "1 value", "n values".
fn count(n: usize) -> String {
    match n {
        0 => "no value".into(),
        1 => "1 value".into(),
        _ => format!("{n} values"),
    }
}

fn list(omegas: &[f64]) -> String {
    omegas
        .iter()
        .map(|w| format!("{w:.3}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn scan_text(omegas: &[f64], scan: &[[Done; 2]], (periods, transient): (u64, u64)) -> String {
    let both: Vec<usize> = (0..omegas.len())
        .filter(|&i| scan[i][0].cell.is_ok() && scan[i][1].cell.is_ok())
        .collect();
    let changes: Vec<(f64, f64)> = both.iter().map(|&i| (omegas[i], change(&scan[i]))).collect();
    let notable: Vec<f64> = changes
        .iter()
        .filter(|(_, c)| c.abs() > NOTABLE_PERCENT)
        .map(|(w, _)| *w)
        .collect();
    let chatters = |d: &Done| d.cell.as_ref().is_ok_and(|c| c.chatter_per_period > 0.0);
    let switched_on: Vec<f64> = both
        .iter()
        .filter(|&&i| !chatters(&scan[i][0]) && chatters(&scan[i][1]))
        .map(|&i| omegas[i])
        .collect();
    let switched_off: Vec<f64> = both
        .iter()
        .filter(|&&i| chatters(&scan[i][0]) && !chatters(&scan[i][1]))
        .map(|&i| omegas[i])
        .collect();
    let mut abs: Vec<f64> = changes.iter().map(|(_, c)| c.abs()).collect();
    abs.sort_by(f64::total_cmp);
    let median = if abs.is_empty() {
        f64::NAN
    } else {
        abs[abs.len() / 2]
    };
    let largest = changes
        .iter()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .copied();
    let mut md = format!(
        "**The chatter case over Ω, coupled.** {} values of Ω from {:.2} to {:.2}, each from rest over {periods} periods ({transient} transient), 100 kΩ, exact V_oc (figure \"Two-way coupling: the chatter case over Ω\", `extra_coupling_omega.csv`). ",
        omegas.len(),
        omegas[0],
        omegas[omegas.len() - 1]
    );
    if both.is_empty() {
        md.push_str("No value ran in both modes. ");
    } else {
        let (lw, lc) = largest.expect("non-empty");
        let _ = write!(
            md,
            "Where both modes ran ({} values), the median absolute change of the average power is {median:.1} % and the largest {lc:+.1} % (Ω = {lw:.3}); it changes by more than {NOTABLE_PERCENT:.0} % at {} of them{}. ",
            both.len(),
            notable.len(),
            if notable.is_empty() {
                String::new()
            } else {
                format!(" (Ω = {})", list(&notable))
            }
        );
        let _ = write!(
            md,
            "Coupling switches chatter on at {}{} and off at {}{}. ",
            count(switched_on.len()),
            if switched_on.is_empty() {
                String::new()
            } else {
                format!(" (Ω = {})", list(&switched_on))
            },
            count(switched_off.len()),
            if switched_off.is_empty() {
                String::new()
            } else {
                format!(" (Ω = {})", list(&switched_off))
            }
        );
    }
    for (m, name) in ["one-way", "two-way"].iter().enumerate() {
        let failed: Vec<(f64, &str)> = omegas
            .iter()
            .zip(scan)
            .filter_map(|(w, p)| failure_text(&p[m]).map(|e| (*w, e)))
            .collect();
        if !failed.is_empty() {
            let ws: Vec<f64> = failed.iter().map(|(w, _)| *w).collect();
            let _ = write!(
                md,
                "The {name} run **failed** at {} values (Ω = {}; first: {}). ",
                failed.len(),
                list(&ws),
                failed[0].1
            );
        }
    }
    md.push_str("\n\n| Ω | one-way | two-way | change |\n|---|---|---|---|\n");
    for (w, p) in omegas.iter().zip(scan) {
        let c = change(p);
        let shown = if c.is_finite() {
            format!("{c:+.1} %")
        } else {
            "–".into()
        };
        let _ = writeln!(md, "| {w:.3} | {} | {} | {shown} |", short(&p[0]), short(&p[1]));
    }
    md
}

/// A table cell: power, impacts and chatter per period, or "failed".
fn short(d: &Done) -> String {
    match &d.cell {
        Ok(c) => format!(
            "{}, {:.1} imp., {:.2} ch.",
            si(c.power_w, "W"),
            c.impacts_per_period,
            c.chatter_per_period
        ),
        Err(_) => "failed".into(),
    }
}

fn sweep_figure(ctx: &Ctx, loads: &[f64], sweep: &[[Done; 2]]) -> Result<String> {
    let xs: Vec<f64> = loads.iter().map(|r| r.log10()).collect();
    let fig = Figure::new(
        "Default case: average power against the load",
        "log10(R / Ω)",
        "P_a [W]",
    );
    two_curves(ctx, "extra_coupling_load", fig, &xs, sweep)
}

fn sweep_text(
    loads: &[f64],
    sweep: &[[Done; 2]],
    optima: &[Optimum; 2],
    paper: &[Done; 2],
    (periods, transient): (u64, u64),
) -> String {
    let mut md = format!(
        "**The optimal load, coupled.** The default case (Ω = 0.70, exact V_oc) at {} loads log-spaced from {} to {}, each a full run of {periods} periods ({transient} transient) in each mode, the best refined by golden-section search in log R to 1 % (figure \"Two-way coupling: average power against the load\"). ",
        loads.len(),
        si(loads[0], "Ω"),
        si(loads[loads.len() - 1], "Ω"),
    );
    for (m, name) in ["One-way", "Two-way"].iter().enumerate() {
        let o = &optima[m];
        let gain = o.power_w / paper[m].power();
        let _ = write!(
            md,
            "{name}: the optimum is {} delivering {}, {:.2e}× the {} at 100 kΩ",
            si(o.resistance_ohm, "Ω"),
            si(o.power_w, "W"),
            gain,
            si(paper[m].power(), "W"),
        );
        if let Some(why) = &o.unrefined {
            let _ = write!(md, " (grid point, not refined: {why})");
        }
        if let Some(e) = &o.failure {
            let _ = write!(md, " (a refinement run failed: {e})");
        }
        md.push_str(". ");
    }
    let (o1, o2) = (&optima[0], &optima[1]);
    let _ = write!(
        md,
        "Coupling moves the optimum by {:+.1} % in R and changes its power by {:+.1} % (the gain over 100 kΩ by {:+.1} %). ",
        100.0 * (o2.resistance_ohm / o1.resistance_ohm - 1.0),
        100.0 * (o2.power_w / o1.power_w - 1.0),
        100.0 * ((o2.power_w / paper[1].power()) / (o1.power_w / paper[0].power()) - 1.0),
    );
    let failed: Vec<String> = loads
        .iter()
        .zip(sweep)
        .filter_map(|(r, p)| failure_text(&p[1]).map(|e| format!("{} ({e})", si(*r, "Ω"))))
        .collect();
    if failed.is_empty() {
        let _ = write!(md, "Every two-way run of the sweep completed.");
    } else {
        let _ = write!(md, "Two-way runs **failed** at {}.", failed.join("; "));
    }
    md.push_str("\n\n| R | one-way | two-way | change |\n|---|---|---|---|\n");
    for (r, p) in loads.iter().zip(sweep) {
        let c = change(p);
        let shown = if c.is_finite() {
            format!("{c:+.2} %")
        } else {
            "–".into()
        };
        let cell = |d: &Done| match &d.cell {
            Ok(c) => si(c.power_w, "W"),
            Err(_) => "failed".into(),
        };
        let _ = writeln!(
            md,
            "| {} | {} | {} | {shown} |",
            si(*r, "Ω"),
            cell(&p[0]),
            cell(&p[1])
        );
    }
    md
}
