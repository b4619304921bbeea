//! The periodic orbits behind the paper's orbit diagrams, followed by continuation: what the
//! jump of Fig. 7 is, where the grazing of Fig. 9 is, how the non-periodic windows of
//! Figs. 14–15 and 18–19 arise. Each finding is computed here; the verdicts follow from the
//! located values.

use anyhow::Result;
use vibrotribo::ChainParams;
use vibrotribo::config::Config;
use vibrotribo::orbits::{
    BifurcationKind, Continuation, ContinuationOptions, ShootingOptions, continue_orbit,
    periodic_orbit_from_transient,
};
use vibrotribo::study::PointOptions;
use vibrotribo::sweep::{PointRunner, grid, run_continued};

use super::context::{Ctx, Verdict};
use super::runs::{arr, config, f};
use crate::continuation::{Diagram, plot_branches};

/// A continuation of the period-`period` orbit of `base` in `key` from `from` to `to`
/// (found after a transient at `from`), mechanics only.
fn follow(base: &Config, key: &str, from: f64, to: f64, period: u32, depth: u32) -> Result<Continuation> {
    let at = |p: f64| base.with(key, p.into());
    let start = at(from)?;
    at(to)?;
    let (lo, hi) = (from.min(to), from.max(to));
    let fallback = start.chain().clone();
    let family = |p: f64| at(p.clamp(lo, hi)).map_or_else(|_| fallback.clone(), |c| c.chain().clone());
    let shooting = ShootingOptions::default();
    let first =
        periodic_orbit_from_transient(start.chain(), start.initial_state(), 300, Some(period), &shooting)?;
    Ok(continue_orbit(
        key,
        family,
        from,
        to,
        &first.state,
        first.period,
        &ContinuationOptions {
            doubling_depth: depth,
            shooting,
            ..ContinuationOptions::default()
        },
    )?)
}

/// The family of chains of `base` along `key` (as [`follow`] uses it).
fn family_of<'a>(base: &'a Config, key: &'a str) -> impl Fn(f64) -> ChainParams + 'a {
    move |p: f64| {
        base.with(key, p.into())
            .map_or_else(|_| base.chain().clone(), |c| c.chain().clone())
    }
}

/// The bifurcations of every branch, in order along each.
fn bifurcations(c: &Continuation) -> impl Iterator<Item = (&BifurcationKind, f64, f64)> {
    c.branches
        .iter()
        .flat_map(|b| b.bifurcations.iter())
        .map(|f| (&f.kind, f.parameter, f.precision))
}

/// Draws the branches over an orbit diagram of x2 and returns the PNG's name.
fn picture(
    ctx: &Ctx,
    name: &str,
    base: &Config,
    key: &str,
    range: (f64, f64),
    c: &Continuation,
) -> Result<String> {
    let diagram = Diagram {
        param: key,
        range,
        mass: 1,
        transient: ctx.budget.transient,
        steps: if ctx.quick { 100 } else { 300 },
    };
    plot_branches(&ctx.out, name, base, &diagram, c, &family_of(base, key))?;
    Ok(format!("{name}.png"))
}

/// The first parameter value of `values` (in the order given) from which the m1–m2 impacts
/// per period of a sweep continued from one value to the next differ from `before`.
fn continued_switch(
    base: &Config,
    key: &str,
    values: &[f64],
    options: PointOptions,
    before: f64,
) -> Result<Option<f64>> {
    let runner = PointRunner::new(base.clone(), options, true);
    let order: Vec<usize> = (0..values.len()).collect();
    let mut switch = None;
    run_continued(&runner, key, values, &order, None, |j, r, _| {
        if let Ok(p) = r
            && switch.is_none()
            && (p.impacts_per_period[0] - before).abs() > 0.5
        {
            switch = Some(values[j]);
        }
        Ok(if switch.is_some() {
            std::ops::ControlFlow::Break(())
        } else {
            std::ops::ControlFlow::Continue(())
        })
    })?;
    Ok(switch)
}

pub(super) fn periodic_orbits(ctx: &mut Ctx) -> Result<()> {
    // Figs. 7–9: m1 = m3 = 90 g, m2 = 120 g, Ω = 0.70, along R_δ.
    let spacing = config(&[
        ("oscillator.masses", arr(&[0.09, 0.12, 0.09])),
        ("omega_ratio", f(0.70)),
    ])?;
    let jump = follow(&spacing, "gap_ratio", 1.05, 1.12, 1, 0)?;
    let fold = bifurcations(&jump)
        .find(|(k, ..)| matches!(k, BifurcationKind::Fold))
        .map(|(_, p, e)| (p, e));
    let sweep_options = PointOptions {
        transient_periods: ctx.budget.transient,
        recorded_periods: 32,
        ..PointOptions::default()
    };
    let up = continued_switch(
        &spacing,
        "gap_ratio",
        &grid(1.08, 1.12, 81),
        sweep_options.clone(),
        2.0,
    )?;
    let img7 = picture(
        ctx,
        "orbits_fig07_jump",
        &spacing,
        "gap_ratio",
        (1.05, 1.12),
        &jump,
    )?;
    let (ours, verdict) = match fold {
        Some((p, e)) => (
            format!(
                "The two-impact orbit stays stable beyond the jump: it ends at a fold (saddle-node) at R_δ = {p:.10} (±{e:.0e}), where it meets an unstable orbit. A sweep continued upward keeps two m1–m2 impacts per period up to {}; the sweep from rest (row 7–8 above) leaves the orbit earlier because rest lies in the one-impact motion's basin there: its jump is a basin boundary, not a bifurcation.",
                up.map_or("the end of [1.08, 1.12]".to_string(), |u| format!("R_δ = {u:.4}"))
            ),
            if (1.085..=1.090).contains(&p) {
                Verdict::Agrees
            } else {
                Verdict::Partly
            },
        ),
        None => (
            "No fold of the two-impact orbit on [1.05, 1.12].".into(),
            Verdict::Partly,
        ),
    };
    ctx.finding(
        "7–8 (orbits)",
        "The jump from two to one impact per cycle between R_δ = 1.085 and 1.090.",
        ours,
        verdict,
    );

    let graze = follow(&spacing, "gap_ratio", 1.38, 1.45, 1, 0)?;
    let first_change = bifurcations(&graze)
        .find(|(k, ..)| {
            matches!(
                k,
                BifurcationKind::Grazing { .. } | BifurcationKind::SequenceChange
            )
        })
        .map(|(_, p, e)| (p, e));
    let up9 = continued_switch(
        &spacing,
        "gap_ratio",
        &grid(1.416, 1.424, 33),
        sweep_options.clone(),
        1.0,
    )?;
    let img9 = picture(
        ctx,
        "orbits_fig09_grazing",
        &spacing,
        "gap_ratio",
        (1.38, 1.45),
        &graze,
    )?;
    let (ours, verdict) = match first_change {
        Some((p, e)) => (
            format!(
                "The period-1 orbit with one impact per contact gains a second m1–m2 impact at R_δ = {p:.10} (±{e:.0e}) and is unstable beyond; a sweep continued upward keeps one m1–m2 impact per period up to {}. Where the sweep from rest (row 7, 9 above) sees the new impact earlier, rest lies in the basin of another attractor.",
                up9.map_or("the end of [1.416, 1.424]".to_string(), |u| format!(
                    "R_δ = {u:.4}"
                ))
            ),
            if (p - 1.419).abs() <= 0.001 {
                Verdict::Agrees
            } else {
                Verdict::Partly
            },
        ),
        None => (
            "The period-1 orbit's impact sequence does not change on [1.38, 1.45].".into(),
            Verdict::Differs,
        ),
    };
    ctx.finding(
        "9 (orbits)",
        "A grazing bifurcation at R_δ ≈ 1.419.",
        ours,
        verdict,
    );

    // Figs. 14–15: Ω = 0.72, m1 = m3 = 50 g, along R_m.
    let ratio = config(&[
        ("oscillator.masses", arr(&[0.05, 0.15, 0.05])),
        ("omega_ratio", f(0.72)),
    ])?;
    let torus = follow(&ratio, "mass_ratio", 2.5, 7.0, 1, 0)?;
    let ns: Vec<f64> = bifurcations(&torus)
        .filter(|(k, ..)| matches!(k, BifurcationKind::NeimarkSacker { .. }))
        .map(|(_, p, _)| p)
        .collect();
    let fold14 = bifurcations(&torus)
        .find(|(k, ..)| matches!(k, BifurcationKind::Fold))
        .map(|(_, p, _)| p);
    let img14 = picture(
        ctx,
        "orbits_fig14_torus",
        &ratio,
        "mass_ratio",
        (2.5, 7.0),
        &torus,
    )?;
    let window = (ns.len() >= 2).then(|| (ns[0].min(ns[1]), ns[0].max(ns[1])));
    let (ours, verdict) = match window {
        Some((a, b)) => (
            format!(
                "The period-1 orbit loses stability at a Neimark–Sacker bifurcation at R_m = {a:.7} and regains it at a second one at R_m = {b:.7}: the non-periodic window is a torus between them. The orbit then stays stable up to a fold at R_m = {}.",
                fold14.map_or("— (none found)".to_string(), |p| format!("{p:.7}"))
            ),
            if (a - 3.06).abs() < 0.05 && (b - 3.64).abs() < 0.05 {
                Verdict::Agrees
            } else {
                Verdict::Partly
            },
        ),
        None => (format!("Neimark–Sacker points found: {ns:?}."), Verdict::Partly),
    };
    ctx.finding(
        "14–15 (orbits)",
        "Non-periodic motion for R_m ≈ 3.06–3.64 at Ω = 0.72.",
        ours,
        verdict,
    );

    // Figs. 18–19: Ω = 0.30 along R_m, from the period-1 orbit below the window at 4.21.
    let low = config(&[
        ("oscillator.masses", arr(&[0.05, 0.15, 0.05])),
        ("omega_ratio", f(0.30)),
    ])?;
    let route = follow(&low, "mass_ratio", 3.7, 4.3, 1, 4)?;
    let first_loss = bifurcations(&route).find(|(k, ..)| {
        matches!(
            k,
            BifurcationKind::NeimarkSacker { .. } | BifurcationKind::PeriodDoubling | BifurcationKind::Fold
        )
    });
    let doublings: Vec<f64> = bifurcations(&route)
        .filter(|(k, ..)| matches!(k, BifurcationKind::PeriodDoubling))
        .map(|(_, p, _)| p)
        .collect();
    let img18 = picture(ctx, "orbits_fig18_route", &low, "mass_ratio", (3.7, 4.3), &route)?;
    let feigenbaum: Vec<f64> = doublings
        .windows(3)
        .map(|w| (w[1] - w[0]) / (w[2] - w[1]))
        .collect();
    let ours = format!(
        "{}; period doublings on the branches followed: {}{}.",
        match first_loss {
            Some((BifurcationKind::NeimarkSacker { angle }, p, e)) => format!(
                "The period-1 orbit loses stability at a Neimark–Sacker bifurcation at R_m = {p:.7} (±{e:.0e}, rotation {angle:.3} rad): the non-periodic motion up to R_m = 4.21 grows from a torus, not from a period-doubling cascade"
            ),
            Some((k, p, _)) => format!("The period-1 orbit first loses stability at R_m = {p:.7} ({k:?})"),
            None => "The period-1 orbit stays stable on [3.7, 4.3]".to_string(),
        },
        if doublings.is_empty() {
            "none".to_string()
        } else {
            doublings
                .iter()
                .map(|p| format!("{p:.7}"))
                .collect::<Vec<_>>()
                .join(", ")
        },
        if feigenbaum.is_empty() {
            String::new()
        } else {
            format!(
                "; Feigenbaum ratios {}",
                feigenbaum
                    .iter()
                    .map(|r| format!("{r:.3}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        }
    );
    ctx.finding(
        "18–19 (orbits)",
        "A period-doubling cascade as R_m varies at Ω = 0.30; non-periodic at R_m = 4.21.",
        ours,
        if doublings.len() >= 2 {
            Verdict::Agrees
        } else {
            Verdict::Partly
        },
    );
    ctx.figure(
        "orbits",
        "Periodic orbits behind the orbit diagrams",
        "Branches of periodic orbits found by shooting and followed by pseudo-arclength continuation (stable solid, unstable dashed, bifurcations as green lines), over the orbit diagram of x2 at t = nT from rest: Fig. 7's jump, Fig. 9's grazing, Figs. 14–15's window at Ω = 0.72, Figs. 18–19's route at Ω = 0.30.".to_string(),
        vec![img7, img9, img14, img18],
    );
    Ok(())
}
