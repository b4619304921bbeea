//! Figs. 7–12: asymmetric spacing R_δ (Figs. 7–11) and symmetric spacing δ (Fig. 12).

use anyhow::Result;
use rayon::prelude::*;
use vibrotribo::analysis::{WelchOptions, welch_psd};
use vibrotribo::study::PointResult;

use super::context::{Ctx, Verdict};
use super::draw::{closing_speeds, d1_figures, impact_figure, lines, orbit_figure, return_map, scatter};
use super::overlay::{Diagram, branches_over};
use super::runs::{arr, config, f, mean, motion_of, run_series, sweep, with};
use crate::job::RunArgs;
use crate::output::si;
use crate::plot::{Figure, Legend, Scale};
use vibrotribo::sweep::grid;

pub(super) fn figs_7_11(ctx: &mut Ctx) -> Result<()> {
    let base = config(&[
        ("oscillator.masses", arr(&[0.09, 0.12, 0.09])),
        ("omega_ratio", f(0.70)),
    ])?;
    // Orbit and impact-velocity diagrams only: the mechanics (the coupling is one-way).
    let values = grid(1.0, 1.6, ctx.budget.coarse);
    let results = sweep(ctx, &base, "gap_ratio", &values, true)?;
    let a = orbit_figure(
        ctx,
        "fig07a_orbit_x2",
        "Orbit diagram of X2 against R_δ",
        "R_δ = δ2/δ1",
        "X2 = x2/δ1",
        &values,
        &results,
        1.0 / 0.020,
    )?;
    let fine = grid(1.40, 1.52, ctx.budget.fine);
    let fres = sweep(ctx, &base, "gap_ratio", &fine, true)?;
    let b = orbit_figure(
        ctx,
        "fig07b_orbit_x2_zoom",
        "Orbit diagram of X2, R_δ = 1.40–1.52",
        "R_δ",
        "X2",
        &fine,
        &fres,
        1.0 / 0.020,
    )?;
    let c = impact_figure(
        ctx,
        "fig07c_v12",
        "Impact velocities V12 against R_δ",
        "R_δ",
        "V12 [m/s]",
        &values,
        &results,
        0,
    )?;
    let d = impact_figure(
        ctx,
        "fig07d_v23",
        "Impact velocities V23 against R_δ",
        "R_δ",
        "V23 [m/s]",
        &values,
        &results,
        1,
    )?;
    let (e, text_e, agree_e) = branches_over(
        ctx,
        &Diagram {
            name: "fig07a_branches",
            title: "Continued branches over the orbit diagram of X2 against R_δ".into(),
            x_label: "R_δ = δ2/δ1",
            base: &base,
            key: "gap_ratio",
            values: &values,
            results: &results,
        },
    )?;
    let (g, text_g, agree_g) = branches_over(
        ctx,
        &Diagram {
            name: "fig07b_branches",
            title: "Continued branches over the orbit diagram of X2, R_δ = 1.40–1.52".into(),
            x_label: "R_δ",
            base: &base,
            key: "gap_ratio",
            values: &fine,
            results: &fres,
        },
    )?;
    ctx.figure(
        "7",
        "Bifurcation diagrams against the spacing ratio R_δ",
        format!(
            "m1 = m3 = 90 g, m2 = 120 g, δ1 = 20 mm, Ω = 0.70, other parameters as Sect. 4.1. Each value from rest; {} transient and {} recorded periods; {} values on [1.0, 1.6] and {} on [1.40, 1.52]. The last two pictures draw the periodic orbits continued through grazing and onto doubled branches (stable solid, unstable dashed, bifurcations marked) over the same points. On [1.0, 1.6]: {text_e} On [1.40, 1.52]: {text_g}",
            ctx.budget.transient, ctx.budget.recorded, values.len(), fine.len()
        ),
        vec![a, b, c, d, e, g],
    );
    for (range, text, (agree, total)) in [
        ("[1.0, 1.6]", &text_e, agree_e),
        ("[1.40, 1.52]", &text_g, agree_g),
    ] {
        ctx.finding(
            "7 (branches)",
            &format!("The orbit diagram of X2 against R_δ on {range} (runs from rest)."),
            format!("Continued orbits: {text}"),
            Verdict::of(agree, total),
        );
    }

    // The jump from two to one impacts per cycle (Fig. 8): locate it on a fine grid.
    let jump_grid = grid(1.05, 1.12, if ctx.quick { 36 } else { 141 });
    let jres = sweep(ctx, &base, "gap_ratio", &jump_grid, true)?;
    // The paper counts impacts per contact (Fig. 7c, d show V12 and V23 apart).
    let counts: Vec<f64> = jres.iter().map(|r| r.impacts_per_period[0]).collect();
    let mut jumps = Vec::new();
    for w in 0..jump_grid.len() - 1 {
        if counts[w] != counts[w + 1] {
            jumps.push(format!(
                "{:.2} → {:.2} m1–m2 impacts/period between R_δ = {:.4} and {:.4}",
                counts[w],
                counts[w + 1],
                jump_grid[w],
                jump_grid[w + 1]
            ));
        }
    }
    let at = |x: f64| {
        let j = jump_grid.iter().position(|v| *v >= x - 1e-12).unwrap_or(0);
        counts[j]
    };
    let (c1085, c1090) = (at(1.085), at(1.090));
    let agrees = (c1085 - 2.0).abs() < 0.01 && (c1090 - 1.0).abs() < 0.01;
    let jump_between = jumps.iter().any(|j| j.contains("2.00 → 1.00"));
    // Fig. 8: D1 at the two points.
    let mut images = Vec::new();
    for r in [1.085, 1.090] {
        let run = run_series(&with(&base, "gap_ratio", r)?, ctx.budget.series, 2, 400, false)?;
        images.extend(d1_figures(
            ctx,
            &run.series,
            ("fig08", r),
            &format!("R_δ = {r}"),
            ": time history (last two periods)",
        )?);
    }
    ctx.figure(
        "8",
        "D1 at the jump",
        "R_δ = 1.085 and 1.090, parameters of Fig. 7; time histories and phase plots of the gap D1 over the last two periods.".into(),
        images,
    );
    ctx.finding(
        "7–8",
        "A jump: two impacts per cycle for R_δ ≤ 1.085, one from R_δ = 1.090.",
        format!(
            "m1–m2 impacts per period {c1085:.2} at R_δ = 1.085 and {c1090:.2} at 1.090. Changes on [1.05, 1.12]: {}.",
            if jumps.is_empty() { "none".into() } else { jumps.join("; ") }
        ),
        if agrees {
            Verdict::Agrees
        } else if jump_between {
            Verdict::Partly
        } else {
            Verdict::Differs
        },
    );

    // Grazing near R_δ = 1.419 (Fig. 9): a grazing bifurcation is where an m1–m2 impact
    // appears with zero closing speed. Locate changes of the m1–m2 impact count on a fine grid
    // and the slowest m1–m2 impact next to each.
    let graze_grid = grid(1.40, 1.44, if ctx.quick { 81 } else { 401 });
    let gres = sweep(ctx, &base, "gap_ratio", &graze_grid, true)?;
    let slowest = |r: &PointResult| closing_speeds(r, 0).fold(f64::INFINITY, f64::min);
    let typical = {
        let mut v: Vec<f64> = closing_speeds(&gres[0], 0).collect();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    };
    let mut births = Vec::new();
    for w in 0..graze_grid.len() - 1 {
        let (a, b) = (&gres[w], &gres[w + 1]);
        if b.impacts_per_period[0] > a.impacts_per_period[0] {
            births.push((graze_grid[w], graze_grid[w + 1], slowest(b)));
        }
    }
    let first = births.first().copied();
    let near = first.is_some_and(|(lo, hi, v)| lo <= 1.424 && hi >= 1.414 && v < 0.05 * typical);
    let grazing: Vec<f64> = gres
        .iter()
        .zip(&graze_grid)
        .filter(|(r, _)| r.grazing)
        .map(|(_, v)| *v)
        .collect();
    let mut images = Vec::new();
    let run = run_series(
        &with(&base, "gap_ratio", 1.419)?,
        ctx.budget.series,
        2,
        400,
        false,
    )?;
    for (k, name) in [(0, "D1"), (1, "D2")] {
        let s = &run.series;
        let fig = Figure::new(
            format!("{name} at R_δ = 1.419 (last two periods)"),
            "time t [s]",
            format!("{name} [m]"),
        );
        images.push(lines(
            ctx,
            &format!("fig09_{}", name.to_lowercase()),
            &fig,
            &[(name, &s.t, &s.d[k])],
        )?);
    }
    ctx.figure(
        "9",
        "Gaps at the reported grazing point",
        "R_δ = 1.419, parameters of Fig. 7.".into(),
        images,
    );
    ctx.finding(
        "7, 9",
        "A grazing bifurcation at R_δ ≈ 1.419 (grazing only between m1 and m2).",
        format!(
            "On [1.40, 1.44] ({} values) a new m1–m2 impact first appears between R_δ = {}, its closing speed {} there against a typical {}; {} values with an impact slower than 1e-3·Aω.",
            graze_grid.len(),
            first.map_or("— (none appears)".into(), |(lo, hi, _)| format!("{lo:.4} and {hi:.4}")),
            first.map_or("—".into(), |(_, _, v)| si(v, "m/s")),
            si(typical, "m/s"),
            grazing.len()
        ),
        if near { Verdict::Agrees } else if first.is_some() { Verdict::Partly } else { Verdict::Differs },
    );

    // Fig. 10–11: four motions, long runs.
    let long = (RunArgs {
        transient: Some(if ctx.quick { 600 } else { 2000 }),
        recorded: Some(256),
        ..ctx.run_args(false)
    })
    .runner(base.clone())?;
    let points = [
        (1.415, "periodic"),
        (1.423, "non-periodic"),
        (1.430, "period 8"),
        (1.512, "period 13"),
    ];
    let res: Vec<PointResult> = points
        .par_iter()
        .map(|(r, _)| long.run(&[("gap_ratio", *r)], None))
        .collect::<Result<_, _>>()?;
    let mut images = Vec::new();
    let mut lines_text = Vec::new();
    let mut matches = 0;
    for ((r, claim), p) in points.iter().zip(&res) {
        let period = p.period();
        let ours = if period == 0 {
            format!("not periodic ({})", motion_of(p))
        } else {
            format!("period {period}")
        };
        let ok = match *claim {
            "periodic" => period > 0,
            "non-periodic" => period == 0,
            other => other == ours,
        };
        matches += usize::from(ok);
        lines_text.push(format!(
            "R_δ = {r}: paper {claim}, vibrotribo {ours}, P_a = {}",
            si(p.average_power_w.unwrap_or(f64::NAN), "W")
        ));
        // The PSD of x2 needs denser samples than one per period: a separate run, 64 samples
        // per period over its last 64 periods.
        let run = run_series(
            &with(&base, "gap_ratio", *r)?,
            ctx.budget.series + 64,
            64,
            64,
            false,
        )?;
        let fs = 64.0 / run.params.period();
        if let Ok(psd) = welch_psd(
            &run.series.x[1],
            fs,
            &WelchOptions {
                segment_len: 1024,
                ..WelchOptions::default()
            },
        ) {
            let mut fig = Figure::new(
                format!(
                    "PSD of X2 at R_δ = {r} ({claim} in the paper; Welch, Hann, Δf = {})",
                    si(psd.resolution, "Hz")
                ),
                "frequency [Hz]",
                "PSD [m²/Hz]",
            );
            fig.y_scale = Scale::Log;
            fig.legend = Legend::Hidden;
            let fr: Vec<f64> = psd.frequencies[1..].to_vec();
            let de: Vec<f64> = psd.density[1..].to_vec();
            images.push(lines(ctx, &format!("fig10_psd_{r}"), &fig, &[("PSD", &fr, &de)])?);
        }
        images.push(return_map(
            ctx,
            &format!("fig10_poincare_{r}"),
            format!("Poincaré section of X2 at R_δ = {r}: X2(n+1) against X2(n)"),
            p,
            1,
            0.020,
            5,
        )?);
    }
    ctx.figure(
        "10",
        "PSD and Poincaré sections of X2 for four motions",
        format!("Parameters of Fig. 7 at R_δ = 1.415, 1.423, 1.430, 1.512; {} transient and 256 recorded periods for the period and the section.\n\n{}", if ctx.quick { 600 } else { 2000 }, lines_text.join("\n\n")),
        images,
    );
    ctx.finding(
        "10",
        "R_δ = 1.415 periodic, 1.423 non-periodic, 1.430 period 8, 1.512 period 13.",
        lines_text.join("; "),
        Verdict::of(matches, 4),
    );
    // Fig. 11: power against the order of the periodicity.
    // The claim orders periodic motions by period; a non-periodic one has no order.
    let mut ordered: Vec<(usize, f64)> = res
        .iter()
        .map(|p| {
            (
                if p.period() == 0 { usize::MAX } else { p.period() },
                p.average_power_w.unwrap_or(f64::NAN),
            )
        })
        .collect();
    ordered.sort_by_key(|o| o.0);
    let periodic: Vec<&(usize, f64)> = ordered.iter().filter(|o| o.0 != usize::MAX).collect();
    let decreasing = periodic.len() >= 2 && periodic.windows(2).all(|w| w[1].1 <= w[0].1 || w[1].0 == w[0].0);
    let labels: Vec<String> = points.iter().map(|p| format!("{}", p.0)).collect();
    let xs: Vec<f64> = (0..res.len()).map(|i| i as f64).collect();
    let ys: Vec<f64> = res
        .iter()
        .map(|p| p.average_power_w.unwrap_or(f64::NAN))
        .collect();
    let fig = Figure::new(
        format!("Average power of the four motions (R_δ = {})", labels.join(", ")),
        "motion (0: 1.415, 1: 1.423, 2: 1.430, 3: 1.512)",
        "P_a [W]",
    );
    let img = scatter(ctx, "fig11_power", fig, &xs, &ys, 9)?;
    ctx.figure(
        "11",
        "Average power of the four motions",
        "From the runs of Fig. 10.".into(),
        vec![img],
    );
    let max_p = ys.iter().copied().fold(0.0f64, f64::max);
    ctx.finding(
        "11",
        "Higher-order periodic motion gives less power; none gives more than a few µW.",
        format!(
            "Power by detected period (NP: non-periodic, not part of the ordering): {}; largest {}.",
            ordered
                .iter()
                .map(|(p, w)| format!(
                    "{} → {}",
                    if *p == usize::MAX {
                        "NP".into()
                    } else {
                        p.to_string()
                    },
                    si(*w, "W")
                ))
                .collect::<Vec<_>>()
                .join(", "),
            si(max_p, "W")
        ),
        Verdict::of(usize::from(decreasing) + usize::from(max_p < 1e-5), 2),
    );
    Ok(())
}

pub(super) fn fig_12(ctx: &mut Ctx) -> Result<()> {
    let base = config(&[
        ("omega_ratio", f(0.75)),
        ("oscillator.masses", arr(&[0.048, 0.12, 0.048])),
    ])?;
    let values = grid(0.0025, 0.040, ctx.budget.fine);
    let res = sweep(ctx, &base, "gap", &values, true)?;
    let img = orbit_figure(
        ctx,
        "fig12_orbit_deltax2",
        "Orbit diagram of δ·X2 = x2 against the symmetric spacing δ",
        "δ [m]",
        "δ·X2 = x2 [m]",
        &values,
        &res,
        1.0,
    )?;
    ctx.figure(
        "12",
        "Orbit diagram against the symmetric spacing",
        format!(
            "Default case (R_m = 2.5, m2 = 120 g) at Ω = 0.75, δ1 = δ2 = δ from 2.5 to 40 mm ({} values).",
            values.len()
        ),
        vec![img],
    );
    // Amplitude: largest |x2| over the recorded samples, and its trend (Spearman's ρ).
    let amp: Vec<f64> = res
        .iter()
        .map(|r| r.position_series(1).map(f64::abs).fold(0.0, f64::max))
        .collect();
    let rho = spearman(&values, &amp);
    ctx.finding(
        "12",
        "The vibration amplitude grows with the spacing δ; the response is complicated at small δ.",
        format!(
            "Spearman rank correlation of max |x2| at t = nT with δ: {rho:.3}; max |x2| = {} at δ = 2.5 mm, {} at 40 mm.",
            si(amp[0], "m"),
            si(amp[amp.len() - 1], "m")
        ),
        if rho > 0.8 { Verdict::Agrees } else if rho > 0.3 { Verdict::Partly } else { Verdict::Differs },
    );
    Ok(())
}

pub(super) fn spearman(x: &[f64], y: &[f64]) -> f64 {
    let rank = |v: &[f64]| -> Vec<f64> {
        let mut idx: Vec<usize> = (0..v.len()).collect();
        idx.sort_by(|a, b| v[*a].total_cmp(&v[*b]));
        let mut r = vec![0.0; v.len()];
        for (k, &i) in idx.iter().enumerate() {
            r[i] = k as f64;
        }
        r
    };
    let (rx, ry) = (rank(x), rank(y));
    let (mx, my) = (mean(&rx), mean(&ry));
    let cov: f64 = rx.iter().zip(&ry).map(|(a, b)| (a - mx) * (b - my)).sum();
    let vx: f64 = rx.iter().map(|a| (a - mx).powi(2)).sum();
    let vy: f64 = ry.iter().map(|b| (b - my).powi(2)).sum();
    cov / (vx * vy).sqrt()
}
