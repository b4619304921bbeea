//! Figs. 13–19: the mass ratio R_m: impacts per period (Fig. 13), the optimal mass ratio
//! (Figs. 14–16), high frequencies (Fig. 17), Ω = 0.30 (Figs. 18–19).

use anyhow::Result;
use rayon::prelude::*;
use vibrotribo::analysis::fit_quadratic;
use vibrotribo::study::PointResult;

use super::context::{Ctx, Verdict};
use super::draw::{both, closing_speeds, impact_figure, lines, orbit_figure, return_map, running_power};
use super::overlay::{Diagram, branches_over};
use super::runs::{arr, config, describe_motions, f, motion_of, run_series, sweep, with};
use crate::job::RunArgs;
use crate::map::{optima, paper_fit, plot_optimal_mass_ratio, refine_maximum};
use crate::output::si;
use crate::plot::{Figure, Legend, Scale};
use vibrotribo::sweep::grid;

pub(super) fn fig_13(ctx: &mut Ctx) -> Result<()> {
    let mut images = Vec::new();
    let mut per = Vec::new();
    for r in [1.2, 1.6, 2.5] {
        let loaded = config(&[("mass_ratio_m2_fixed", f(r))])?;
        let run = run_series(&loaded, ctx.budget.series, 2, 400, true)?;
        let s = &run.series;
        let samples = &run.samples;
        // Impacts per period between m1 and m2 over the kept two periods.
        let impacts12 = s.impacts.iter().filter(|(contact, _)| *contact == 0).count() as f64 / 2.0;
        let curve = run.electrical.as_ref().expect("electrical").power_curve();
        let p = curve.last().copied().unwrap_or(f64::NAN);
        per.push((r, impacts12, p));
        let fig = Figure::new(
            format!("D1 at R_m = {r} (last two periods)"),
            "time t [s]",
            "D1 [m]",
        );
        images.push(lines(
            ctx,
            &format!("fig13_d1_{r}"),
            &fig,
            &[("D1", &s.t, &s.d[0])],
        )?);
        let fig = Figure::new(
            format!("Current I at R_m = {r} (last two periods)"),
            "time t [s]",
            "I [A]",
        );
        images.push(lines(
            ctx,
            &format!("fig13_current_{r}"),
            &fig,
            &[("I", &samples.times, &samples.current_a)],
        )?);
        images.push(running_power(
            ctx,
            &format!("fig13_power_{r}"),
            format!("Running average power at R_m = {r}"),
            Scale::Linear,
            &[("P_a".into(), curve)],
        )?);
    }
    // R_m = 1, symmetric: impacts die out from a perturbed start.
    let equal = config(&[
        ("oscillator.masses", arr(&[0.12, 0.12, 0.12])),
        ("run.initial_velocities", arr(&[-1.0, 0.5, 1.5])),
    ])?;
    let run = run_series(&equal, 400, 100, 10, false)?;
    let late_impacts = run.series.impacts.len();
    ctx.figure(
        "13",
        "Gap D1, current and running power for three mass ratios",
        "Default case with m2 = 120 g, m1 = m3 = m2/R_m, R_m ∈ {1.2, 1.6, 2.5}, Ω = 0.70, R = 100 kΩ.".into(),
        images,
    );
    let rising_impacts = per.windows(2).all(|w| w[1].1 >= w[0].1);
    let rising_power = per.windows(2).all(|w| w[1].2 > w[0].2);
    let ours = per
        .iter()
        .map(|(r, i, p)| format!("R_m = {r}: {i:.1} m1–m2 impacts/period, P_a = {}", si(*p, "W")))
        .collect::<Vec<_>>()
        .join("; ");
    let one_to_three = (per[0].1 - 1.0).abs() < 0.01 && (per[2].1 - 3.0).abs() < 0.01;
    ctx.finding(
        "13",
        "From R_m = 1.2 through 1.6 to 2.5 the m1–m2 impacts per period rise from one to three, and power rises with them.",
        ours,
        if one_to_three && rising_power {
            Verdict::Agrees
        } else if rising_impacts || rising_power {
            Verdict::Partly
        } else {
            Verdict::Differs
        },
    );
    ctx.finding(
        "Sect. 4.3",
        "R_m = 1 with symmetric parameters: no impacts at steady state.",
        format!("Equal masses started with velocities (−1, 0.5, 1.5) m/s: {late_impacts} impacts in periods 300–400."),
        if late_impacts == 0 { Verdict::Agrees } else { Verdict::Differs },
    );
    Ok(())
}

pub(super) fn figs_14_16(ctx: &mut Ctx) -> Result<()> {
    let base = config(&[
        ("oscillator.masses", arr(&[0.05, 0.15, 0.05])),
        ("omega_ratio", f(0.72)),
    ])?;
    let values = grid(1.5, 8.0, ctx.budget.coarse);
    let res = sweep(ctx, &base, "mass_ratio", &values, false)?;
    let a = orbit_figure(
        ctx,
        "fig14a_orbit_x2",
        "Orbit diagram of X2 against R_m (Ω = 0.72)",
        "R_m = m2/m1",
        "X2",
        &values,
        &res,
        1.0 / 0.020,
    )?;
    let b = impact_figure(
        ctx,
        "fig14b_v12",
        "Impact velocities V12 against R_m (Ω = 0.72)",
        "R_m",
        "V12 [m/s]",
        &values,
        &res,
        0,
    )?;
    let power: Vec<f64> = res
        .iter()
        .map(|r| r.average_power_w.unwrap_or(f64::NAN))
        .collect();
    let mut fig = Figure::new("Average power against R_m (Ω = 0.72)", "R_m", "P_a [W]");
    fig.legend = Legend::Hidden;
    let c = lines(ctx, "fig14c_power", &fig, &[("P_a", &values, &power)])?;
    let (d, text, agree) = branches_over(
        ctx,
        &Diagram {
            name: "fig14d_branches",
            title: "Continued branches over the orbit diagram of X2 against R_m (Ω = 0.72)".into(),
            x_label: "R_m = m2/m1",
            base: &base,
            key: "mass_ratio",
            values: &values,
            results: &res,
        },
    )?;
    ctx.figure(
        "14",
        "Bifurcation diagrams against the mass ratio at Ω = 0.72",
        format!(
            "m1 = m3 = 50 g, m2 = R_m·m1, δ1 = δ2 = 20 mm, Ω = 0.72; {} values from rest. The last picture draws the continued periodic orbits over the orbit diagram: {text}",
            values.len()
        ),
        vec![a, b, c, d],
    );
    branch_finding(
        ctx,
        "14 (branches)",
        "The orbit diagram of X2 against R_m at Ω = 0.72 (runs from rest).",
        &text,
        agree,
    );
    let (best_r, best_p) = refine_maximum(&values, &power).unwrap_or((f64::NAN, f64::NAN));
    let vmax: Vec<f64> = res
        .iter()
        .map(|r| closing_speeds(r, 0).fold(0.0, f64::max))
        .collect();
    let (vi, _) = vmax
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .unwrap_or((0, &0.0));
    let at4 = res[values.iter().position(|v| *v >= 4.0 - 1e-9).unwrap_or(0)].impacts_per_period[0];
    ctx.finding(
        "14–15",
        "At Ω = 0.72 (m1 = m3 = 50 g) the optimal mass ratio is about 3.5; non-periodic for R_m ≈ 3.06–3.64; three m1–m2 impacts per cycle at R_m = 4.",
        format!(
            "On R_m ∈ [1.5, 8] power is largest at R_m = {best_r:.2} ({}); the largest V12 (the paper's criterion) is at R_m = {:.2}; not periodic after settling: {}; m1–m2 impacts per period at R_m = 4: {at4:.2}.",
            si(best_p, "W"),
            values[vi],
            describe_motions(&values, &res, values[1] - values[0])
        ),
        Verdict::of(
            usize::from((best_r - 3.5).abs() < 0.3) + usize::from((at4 - 3.0).abs() < 0.01),
            2,
        ),
    );
    // Fig. 15: running power at three mass ratios.
    let mut curves = Vec::new();
    for r in [2.5, 3.0, 3.5] {
        let run = run_series(&with(&base, "mass_ratio", r)?, ctx.budget.series, 1, 20, true)?;
        curves.push((
            format!("R_m = {r}"),
            run.electrical.expect("electrical").power_curve(),
        ));
    }
    let img = running_power(
        ctx,
        "fig15_power",
        "Running average power at Ω = 0.72".into(),
        Scale::Linear,
        &curves,
    )?;
    let finals: Vec<f64> = curves
        .iter()
        .map(|c| c.1.last().copied().unwrap_or(f64::NAN))
        .collect();
    ctx.figure(
        "15",
        "Running average power for R_m = 2.5, 3.0, 3.5 at Ω = 0.72",
        "Parameters of Fig. 14.".into(),
        vec![img],
    );
    ctx.finding(
        "15",
        "Of R_m = 2.5, 3.0 and 3.5 at Ω = 0.72, R_m = 3.5 gives the most power.",
        format!(
            "P_a after {} periods: {}.",
            ctx.budget.series,
            finals.iter().map(|p| si(*p, "W")).collect::<Vec<_>>().join(", ")
        ),
        if finals[2] >= finals[0] && finals[2] >= finals[1] {
            Verdict::Agrees
        } else {
            Verdict::Differs
        },
    );
    // Fig. 16: R_mo(Ω).
    let omegas = grid(0.55, 0.95, if ctx.quick { 5 } else { 9 });
    let ratios = grid(1.2, 7.0, if ctx.quick { 30 } else { 117 });
    let runner = ctx.run_args(false).runner(base.clone())?;
    let pts: Vec<(f64, f64)> = omegas
        .iter()
        .flat_map(|&w| ratios.iter().map(move |&r| (w, r)))
        .collect();
    let pw: Vec<f64> = pts
        .par_iter()
        .map(|&(w, r)| {
            runner
                .run(&[("omega_ratio", w), ("mass_ratio", r)], None)
                .map(|p| p.average_power_w.unwrap_or(f64::NAN))
        })
        .collect::<Result<_, _>>()?;
    let opt = optima(&omegas, &ratios, &pw);
    let ws: Vec<f64> = opt.iter().map(|o| o.0).collect();
    let rs: Vec<f64> = opt.iter().map(|o| o.1).collect();
    let fit = fit_quadratic(&ws, &rs).ok();
    let img = both(ctx, "fig16_optimal_mass_ratio", |p| {
        plot_optimal_mass_ratio(p, &ws, &rs, fit.as_ref(), (0.55, 0.95))
    })?;
    ctx.figure(
        "16",
        "Optimal mass ratio against Ω",
        format!(
            "Parameters of Fig. 14; {} values of Ω on [0.55, 0.95] × {} values of R_m on [1.2, 7]; optimum refined by a parabola through the best grid point.",
            omegas.len(),
            ratios.len()
        ),
        vec![img],
    );
    let decreasing = rs.windows(2).filter(|w| w[1] <= w[0]).count();
    let fit_text = fit.as_ref().map_or("no fit".into(), |q| {
        format!(
            "R_mo = {:.2}Ω² {:+.2}Ω {:+.2} (R² = {:.3})",
            q.a,
            q.b,
            q.c,
            q.r_squared.unwrap_or(f64::NAN)
        )
    });
    let max_dev = ws
        .iter()
        .zip(&rs)
        .map(|(w, r)| (r - paper_fit(*w)).abs())
        .fold(0.0, f64::max);
    ctx.finding(
        "16",
        "R_mo decreases with Ω; R_mo = 11.43Ω² − 28.46Ω + 18.03 on [0.55, 0.95].",
        format!(
            "Optima {}; {} of {} steps decrease; {fit_text}; largest deviation from the paper's fit {max_dev:.2}.",
            ws.iter().zip(&rs).map(|(w, r)| format!("Ω {w:.2} → {r:.2}")).collect::<Vec<_>>().join(", "),
            decreasing,
            rs.len().saturating_sub(1)
        ),
        if max_dev < 0.5 && decreasing + 1 == rs.len() {
            Verdict::Agrees
        } else if decreasing * 2 >= rs.len().saturating_sub(1) {
            Verdict::Partly
        } else {
            Verdict::Differs
        },
    );
    Ok(())
}

/// A finding on how the continued branches account for a brute-force diagram: agrees when
/// every value does.
fn branch_finding(ctx: &mut Ctx, figures: &str, paper: &str, text: &str, (agree, total): (usize, usize)) {
    ctx.finding(
        figures,
        paper,
        format!("Continued orbits: {text}"),
        Verdict::of(agree, total),
    );
}

/// Runs of period p, 2p, 4p (consecutive runs of equal detected period) along a sweep, in
/// either direction of the parameter, described as "p → 2p → 4p at R_m = a–b".
pub(super) fn doubling_runs(values: &[f64], results: &[PointResult]) -> Vec<String> {
    let mut runs: Vec<(usize, f64, f64)> = Vec::new();
    for (v, r) in values.iter().zip(results) {
        let p = r.period();
        match runs.last_mut() {
            Some(last) if last.0 == p => last.2 = *v,
            _ => runs.push((p, *v, *v)),
        }
    }
    let mut out = Vec::new();
    for w in runs.windows(3) {
        let (a, b, c) = (w[0].0, w[1].0, w[2].0);
        let up = a > 0 && b == 2 * a && c == 2 * b;
        let down = c > 0 && b == 2 * c && a == 2 * b;
        if up || down {
            out.push(format!("{a} → {b} → {c} at R_m = {:.3}–{:.3}", w[0].1, w[2].2));
        }
    }
    out
}

pub(super) fn fig_17(ctx: &mut Ctx) -> Result<()> {
    let mut images = Vec::new();
    let mut texts = Vec::new();
    let mut saturate = 0;
    let mut branch_texts = Vec::new();
    for w in [1.30, 2.00] {
        let base = config(&[
            ("oscillator.masses", arr(&[0.05, 0.15, 0.05])),
            ("omega_ratio", f(w)),
        ])?;
        let values = grid(1.5, 8.0, ctx.budget.fine);
        let res = sweep(ctx, &base, "mass_ratio", &values, true)?;
        images.push(orbit_figure(
            ctx,
            &format!("fig17a_orbit_{w}"),
            &format!("Orbit diagram of X2 against R_m, Ω = {w}"),
            "R_m",
            "X2",
            &values,
            &res,
            1.0 / 0.020,
        )?);
        let (img, text, agree) = branches_over(
            ctx,
            &Diagram {
                name: &format!("fig17c_branches_{w}"),
                title: format!("Continued branches over the orbit diagram of X2 against R_m, Ω = {w}"),
                x_label: "R_m",
                base: &base,
                key: "mass_ratio",
                values: &values,
                results: &res,
            },
        )?;
        images.push(img);
        branch_texts.push(format!("Ω = {w}: {text}"));
        branch_finding(
            ctx,
            "17 (branches)",
            &format!("The orbit diagram of X2 against R_m at Ω = {w} (runs from rest)."),
            &text,
            agree,
        );
        images.push(impact_figure(
            ctx,
            &format!("fig17b_v12_{w}"),
            &format!("V12 against R_m, Ω = {w}"),
            "R_m",
            "V12 [m/s]",
            &values,
            &res,
            0,
        )?);
        let vmax: Vec<f64> = res
            .iter()
            .map(|r| closing_speeds(r, 0).fold(0.0, f64::max))
            .collect();
        let third = vmax.len() / 3;
        let tail = &vmax[2 * third..];
        let tail_max = tail.iter().copied().fold(0.0, f64::max);
        let spread = (tail_max - tail.iter().copied().fold(f64::INFINITY, f64::min)) / tail_max;
        let (imax, _) = vmax
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .unwrap_or((0, &0.0));
        let interior_peak = imax > 0 && imax < 2 * third && vmax[imax] > 1.1 * tail_max;
        if spread < 0.15 && !interior_peak {
            saturate += 1;
        }
        texts.push(format!(
            "Ω = {w}: largest V12 {} at R_m = {:.2}; over R_m ∈ [{:.2}, 8] the largest V12 varies by {:.0} %",
            si(vmax[imax], "m/s"),
            values[imax],
            values[2 * third],
            100.0 * spread
        ));
    }
    ctx.figure(
        "17",
        "Orbit and impact-velocity diagrams at high frequencies",
        format!(
            "m1 = m3 = 50 g, δ = 20 mm, Ω = 1.30 and 2.00, R_m from 1.5 to 8; with each orbit diagram the continued periodic orbits over it. {}",
            branch_texts.join(" ")
        ),
        images,
    );
    ctx.finding(
        "17",
        "At Ω = 1.30 and 2.00 the impact velocity levels off as R_m grows: no optimal mass ratio.",
        texts.join("; "),
        Verdict::of(saturate, 2),
    );
    Ok(())
}

pub(super) fn figs_18_19(ctx: &mut Ctx) -> Result<()> {
    let base = config(&[
        ("oscillator.masses", arr(&[0.05, 0.15, 0.05])),
        ("omega_ratio", f(0.30)),
    ])?;
    let values = grid(1.5, 6.0, ctx.budget.coarse);
    let res = sweep(ctx, &base, "mass_ratio", &values, true)?;
    let a = orbit_figure(
        ctx,
        "fig18a_orbit_x2",
        "Orbit diagram of X2 against R_m, Ω = 0.30",
        "R_m",
        "X2",
        &values,
        &res,
        1.0 / 0.020,
    )?;
    let fine = grid(3.9, 4.5, ctx.budget.fine);
    let fres = sweep(ctx, &base, "mass_ratio", &fine, true)?;
    let b = orbit_figure(
        ctx,
        "fig18b_orbit_x2_zoom",
        "Orbit diagram of X2, R_m = 3.9–4.5, Ω = 0.30",
        "R_m",
        "X2",
        &fine,
        &fres,
        1.0 / 0.020,
    )?;
    let mut texts = Vec::new();
    let mut images = vec![a, b];
    for (name, range, v, r) in [
        ("fig18c_branches", "[1.5, 6]", &values, &res),
        ("fig18d_branches_zoom", "[3.9, 4.5]", &fine, &fres),
    ] {
        let (img, text, agree) = branches_over(
            ctx,
            &Diagram {
                name,
                title: format!("Continued branches over the orbit diagram of X2, R_m on {range}, Ω = 0.30"),
                x_label: "R_m",
                base: &base,
                key: "mass_ratio",
                values: v,
                results: r,
            },
        )?;
        images.push(img);
        branch_finding(
            ctx,
            "18 (branches)",
            &format!("The orbit diagram of X2 against R_m on {range} at Ω = 0.30 (runs from rest)."),
            &text,
            agree,
        );
        texts.push(format!("On {range}: {text}"));
    }
    ctx.figure(
        "18",
        "Orbit diagram against R_m at Ω = 0.30",
        format!(
            "m1 = m3 = 50 g, δ = 20 mm, Ω = 0.30; {} values on [1.5, 6], {} on [3.9, 4.5]; the last two pictures draw the continued periodic orbits over them. {}",
            values.len(),
            fine.len(),
            texts.join(" ")
        ),
        images,
    );
    let periods: Vec<usize> = res
        .iter()
        .map(PointResult::period)
        .chain(fres.iter().map(PointResult::period))
        .collect();
    let non_periodic = periods.contains(&0);
    // A cascade: consecutive runs of period p, 2p, 4p along the parameter (either way).
    let cascades: Vec<String> = [(&values, &res), (&fine, &fres)]
        .iter()
        .flat_map(|(v, r)| doubling_runs(v, r))
        .collect();
    let doubling = !cascades.is_empty();
    // Fig. 19: Poincaré sections at R_m = 4.21.
    let long = (RunArgs {
        transient: Some(if ctx.quick { 300 } else { 1000 }),
        recorded: Some(if ctx.quick { 300 } else { 2000 }),
        ..ctx.run_args(true)
    })
    .runner(base.clone())?;
    let p = long.run(&[("mass_ratio", 4.21)], None)?;
    let mut images = Vec::new();
    for i in 0..3 {
        images.push(return_map(
            ctx,
            &format!("fig19_poincare_x{}", i + 1),
            format!("Poincaré section of X{} at Ω = 0.30, R_m = 4.21", i + 1),
            &p,
            i,
            0.020,
            3,
        )?);
    }
    let period_421 = p.period();
    let motion_421 = motion_of(&p);
    ctx.figure(
        "19",
        "Poincaré sections at Ω = 0.30, R_m = 4.21",
        format!(
            "Stroboscopic samples X_i(n+1) against X_i(n) over {} periods after {} transient periods.",
            p.strobe_periods.len(),
            if ctx.quick { 300 } else { 1000 }
        ),
        images,
    );
    ctx.finding(
        "18–19",
        "At Ω = 0.30 a period-doubling cascade with non-periodic windows as R_m varies; non-periodic at R_m = 4.21.",
        format!(
            "Period-doubling sequences (runs of period p → 2p → 4p along R_m): {}; not periodic after settling: {}; R_m = 4.21: {}.",
            if cascades.is_empty() { "none".to_string() } else { cascades.join("; ") },
            describe_motions(&values, &res, values[1] - values[0]),
            if period_421 == 0 { motion_421.to_string() } else { format!("period {period_421}") }
        ),
        if doubling && non_periodic && period_421 == 0 {
            Verdict::Agrees
        } else if non_periodic || doubling {
            Verdict::Partly
        } else {
            Verdict::Differs
        },
    );
    Ok(())
}
