//! Bifurcation maps of the paper's device (the default case: m1 = m3 = 48 g, m2 = 120 g,
//! δ1 = δ2 = 20 mm) in (Ω, R_m) and (Ω, R_δ): its fold, period-doubling, Neimark–Sacker and
//! grazing curves over its power map (`vibrotribo bifmap`): where a designer should and
//! should not operate.

use anyhow::Result;

use super::context::Ctx;
use crate::bifmap::{BifmapArgs, make};
use crate::config::ConfigArgs;
use crate::manifest::{BifmapManifest, read};
use crate::output::{column, numbers, read_csv, si};

/// One map of the step: its directory, second key, range and label.
struct Plane {
    dir: &'static str,
    key: &'static str,
    range: (f64, f64),
    label: &'static str,
}

const PLANES: [Plane; 2] = [
    Plane {
        dir: "bifmap_mass_ratio",
        key: "mass_ratio",
        range: (1.5, 5.0),
        label: "R_m",
    },
    Plane {
        dir: "bifmap_gap_ratio",
        key: "gap_ratio",
        range: (0.8, 1.6),
        label: "R_δ",
    },
];

fn args_of(ctx: &Ctx, plane: &Plane) -> BifmapArgs {
    let quick = ctx.quick;
    BifmapArgs {
        input: ConfigArgs {
            config: None,
            set: Vec::new(),
        },
        x: "omega_ratio".into(),
        x_from: 0.5,
        x_to: 1.0,
        x_steps: if quick { 11 } else { 26 },
        y: plane.key.into(),
        y_from: plane.range.0,
        y_to: plane.range.1,
        y_steps: if quick { 8 } else { 15 },
        seeds: if quick { 3 } else { 6 },
        x_starts: if quick { 3 } else { 5 },
        kinds: ["fold", "period_doubling", "neimark_sacker", "grazing"]
            .map(String::from)
            .to_vec(),
        period: None,
        doublings: 1,
        orbit_transient: 200,
        branch_points: if quick { 600 } else { 1000 },
        curve_points: if quick { 60 } else { 200 },
        max_curves: if quick { 24 } else { 64 },
        out: Some(ctx.path(plane.dir)),
        plot: true,
        run: ctx.run_args(false),
    }
}

/// What a map says to a designer, from its files: the curves by kind, the codimension-two
/// points, the share of the plane that is periodic, and the best power there.
fn summary(ctx: &Ctx, plane: &Plane) -> Result<String> {
    let dir = ctx.path(plane.dir);
    let m: BifmapManifest = read(&dir.join("bifmap.json"))?;
    let kinds = ["fold", "period_doubling", "neimark_sacker", "grazing"];
    let counts: Vec<String> = kinds
        .iter()
        .map(|k| {
            let traced = m.curves.iter().filter(|c| c.kind == *k && c.points > 1).count();
            format!("{traced} {}", k.replace('_', "-"))
        })
        .collect();
    let not_started = m.curves.iter().filter(|c| c.points <= 1).count();
    let (h, rows) = read_csv(&dir.join("map.csv"))?;
    let power = numbers(&rows, column(&h, "average_power_w")?);
    let (mx, my) = (numbers(&rows, column(&h, "x")?), numbers(&rows, column(&h, "y")?));
    let motion = column(&h, "motion")?;
    let periodic: Vec<bool> = rows.iter().map(|r| r[motion] == "periodic").collect();
    let best = |only_periodic: bool| {
        (0..rows.len())
            .filter(|&j| power[j].is_finite() && (!only_periodic || periodic[j]))
            .max_by(|&a, &b| power[a].total_cmp(&power[b]))
    };
    let describe = |j: Option<usize>| {
        j.map_or("none".to_string(), |j| {
            format!(
                "{} at Ω = {:.3}, {} = {:.3} ({})",
                si(power[j], "W"),
                mx[j],
                plane.label,
                my[j],
                rows[j][motion]
            )
        })
    };
    Ok(format!(
        "Bifurcation map of the default case in (Ω, {label}), Ω 0.5–1.0 × {label} {}–{} ({} × {} power-map points, {} seed values × {} starts): curves traced: {}{}; {} codimension-two points; {} of {} power-map points periodic after settling. Largest average power {}; among the periodic points {}.",
        plane.range.0,
        plane.range.1,
        m.x.steps,
        m.y.steps,
        m.seed_values.len(),
        m.x_starts.len(),
        counts.join(", "),
        if not_started > 0 {
            format!(" ({not_started} more located but not continuable from their seed)")
        } else {
            String::new()
        },
        m.codim2_points,
        periodic.iter().filter(|p| **p).count(),
        rows.len(),
        describe(best(false)),
        describe(best(true)),
        label = plane.label,
    ))
}

pub(super) fn bifurcation_maps(ctx: &mut Ctx) -> Result<()> {
    let mut images = Vec::new();
    let mut texts = Vec::new();
    for plane in &PLANES {
        let complete = make(&args_of(ctx, plane), false)?;
        crate::progress::check_interrupt(|| {
            "during a bifurcation map; REPORT.md is written only by a complete run".into()
        })?;
        if !complete {
            anyhow::bail!("the bifurcation map in {} stopped before its end", plane.key);
        }
        images.push(format!("{}/bifmap.png", plane.dir));
        texts.push(summary(ctx, plane)?);
    }
    ctx.figure(
        "maps",
        "Bifurcation maps of the default case",
        format!(
            "Fold, period-doubling, Neimark–Sacker and grazing curves (`vibrotribo bifmap`) over the average power (log scale; R = 100 kΩ, {} transient and {} recorded periods per point from rest), the power-map points whose motion is quasiperiodic or chaotic crossed, codimension-two points marked; curves of period-2 orbits dashed. A design point between the curves, away from the crossed region, keeps its periodic motion when the parameters drift. {}",
            ctx.budget.transient,
            ctx.budget.recorded,
            texts.join(" ")
        ),
        images,
    );
    for t in texts {
        ctx.extras.push(t);
    }
    Ok(())
}
