//! What the paper's "non-periodic" motions are, and which motions coexist: the Lyapunov
//! spectrum at each non-periodic window the paper names (chaotic, quasi-periodic on a torus,
//! or a stable orbit after all), the largest exponent across the chatter range of Fig. 20,
//! the average power of Figs. 14–16's candidates with batch-means error bars, the basins
//! behind Fig. 7's jump, and the expected power of an unknown start across Fig. 20's Ω.

use std::cmp::Ordering;

use anyhow::{Context, Result, bail};
use rayon::prelude::*;
use vibrotribo::analysis::batch_means_se;
use vibrotribo::attractors::{AttractorOptions, DEFAULT_START_PERIODS, RandomStarts, StartRunner};
use vibrotribo::config::Config;
use vibrotribo::lyapunov::{LyapunovOptions, LyapunovSpectrum};
use vibrotribo::study::{PointOptions, PointResult, exponent_sign, lyapunov_spectrum};
use vibrotribo::sweep::{PointRunner, grid};

use super::context::{Ctx, Verdict};
use super::draw::lines;
use super::runs::{arr, chatter_case, config, f, with};
use crate::basins::BasinGrid;
use crate::config::ConfigArgs;
use crate::manifest::Axis;
use crate::output::si;
use crate::plot::{Figure, Scale};
use crate::progress::{Interrupted, check_interrupt};

/// How a motion's largest Lyapunov exponent classifies it (the sweeps' rule,
/// [`exponent_sign`]): clearly positive (beyond three batch-means standard errors) is
/// chaotic, clearly negative a stable periodic orbit, and within the error bar of 0 neutral
/// (a quasi-periodic torus).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Motion {
    Chaotic,
    Quasiperiodic,
    Periodic,
}

impl Motion {
    fn of(s: &LyapunovSpectrum) -> Self {
        match exponent_sign(s.largest(), s.largest_spread()) {
            Ordering::Greater => Motion::Chaotic,
            Ordering::Less => Motion::Periodic,
            Ordering::Equal => Motion::Quasiperiodic,
        }
    }

    fn text(self) -> &'static str {
        match self {
            Motion::Chaotic => "chaotic",
            Motion::Quasiperiodic => "quasi-periodic (λ1 = 0 within its error)",
            Motion::Periodic => "a stable periodic orbit (λ1 < 0)",
        }
    }
}

/// The spectrum of `config` from rest: `transient` periods, then `periods` averaged over.
fn spectrum(config: &Config, transient: u64, periods: u64) -> Result<LyapunovSpectrum> {
    let mut spec = config.run_spec(true);
    spec.periods = transient + periods;
    spec.transient_periods = transient;
    let run = lyapunov_spectrum(&spec, &LyapunovOptions::default(), &mut ())?;
    Ok(run.spectrum?)
}

/// `λ = v ± e 1/s` with the exponent per forcing period.
fn exponent_text(s: &LyapunovSpectrum, period_s: f64) -> String {
    format!(
        "λ1 = {:+.4} ± {:.4} 1/s (λ1·T = {:+.2e}), λ2 = {:+.4} ± {:.4} 1/s",
        s.largest(),
        s.largest_spread(),
        s.largest() * period_s,
        s.exponents.get(1).copied().unwrap_or(f64::NAN),
        s.spread.get(1).copied().unwrap_or(f64::NAN),
    )
}

pub(super) fn dynamics(ctx: &mut Ctx) -> Result<()> {
    windows(ctx)?;
    chatter_range(ctx)?;
    power_error_bars(ctx)?;
    basin_pictures(ctx)?;
    expected_power(ctx)
}

/// The Lyapunov spectra of the paper's non-periodic windows.
fn windows(ctx: &mut Ctx) -> Result<()> {
    // R_m = 4.21's weak chaos (λ1·T ≈ 5e-3) needs some 10⁴ periods to stand out of its error.
    let (transient, periods) = if ctx.quick { (1000, 10_000) } else { (1000, 30_000) };
    let spacing = config(&[
        ("oscillator.masses", arr(&[0.09, 0.12, 0.09])),
        ("omega_ratio", f(0.70)),
    ])?;
    let ratio = config(&[("oscillator.masses", arr(&[0.05, 0.15, 0.05]))])?;
    let cases: Vec<(&str, &str, Config)> = vec![
        (
            "10",
            "R_δ = 1.423 (Ω = 0.70)",
            with(&spacing, "gap_ratio", 1.423)?,
        ),
        (
            "14–15",
            "R_m = 3.3 (Ω = 0.72, inside 3.06–3.64)",
            with(&with(&ratio, "omega_ratio", 0.72)?, "mass_ratio", 3.3)?,
        ),
        (
            "14–16",
            "R_m = 6.54 (Ω = 0.72, the largest power of row 14–15)",
            with(&with(&ratio, "omega_ratio", 0.72)?, "mass_ratio", 6.54)?,
        ),
        (
            "18–19",
            "R_m = 4.21 (Ω = 0.30)",
            with(&with(&ratio, "omega_ratio", 0.30)?, "mass_ratio", 4.21)?,
        ),
    ];
    let spectra: Vec<Result<LyapunovSpectrum>> = cases
        .par_iter()
        .map(|(_, _, c)| spectrum(c, transient, periods))
        .collect();
    check_interrupt(|| "during the Lyapunov spectra; REPORT.md is written only by a complete run".into())?;
    let mut parts = Vec::new();
    let mut nonperiodic = 0;
    for ((fig, label, c), s) in cases.iter().zip(spectra) {
        let s = s.with_context(|| format!("Lyapunov spectrum at {label}"))?;
        let motion = Motion::of(&s);
        nonperiodic += usize::from(motion != Motion::Periodic);
        parts.push(format!(
            "Fig. {fig}, {label}: {} — {}",
            exponent_text(&s, c.chain().period()),
            motion.text()
        ));
    }
    ctx.finding(
        "10, 14–15, 18–19 (exponents)",
        "Non-periodic motion at R_δ = 1.423 (Fig. 10), for R_m ≈ 3.06–3.64 at Ω = 0.72 (Figs. 14–15) and at R_m = 4.21, Ω = 0.30 (Fig. 19).",
        format!(
            "Lyapunov spectra over {periods} periods after {transient} from rest (error: batch-means standard error over 10 batches; chaotic when λ1 > 3 errors): {}.",
            parts.join("; ")
        ),
        Verdict::of(nonperiodic, cases.len()),
    );
    Ok(())
}

/// The largest Lyapunov exponent across the chatter range of Fig. 20.
fn chatter_range(ctx: &mut Ctx) -> Result<()> {
    let base = chatter_case()?;
    let values = grid(0.3, 0.65, if ctx.quick { 36 } else { 71 });
    let options = PointOptions {
        transient_periods: ctx.budget.transient,
        recorded_periods: if ctx.quick { 300 } else { 1000 },
        lyapunov: Some(LyapunovOptions::default()),
        ..PointOptions::default()
    };
    let runner = PointRunner::new(base, options, true);
    let results: Vec<Result<PointResult>> = values
        .par_iter()
        .map(|&v| {
            runner
                .run(&[("omega_ratio", v)], None)
                .map_err(anyhow::Error::from)
        })
        .collect();
    check_interrupt(|| {
        "during the chatter range's exponents; REPORT.md is written only by a complete run".into()
    })?;
    let mut chaotic = Vec::new();
    let mut largest = f64::NEG_INFINITY;
    let mut chatters = Vec::with_capacity(values.len());
    for (r, v) in results.into_iter().zip(&values) {
        let r = r.with_context(|| format!("omega_ratio = {v}"))?;
        chatters.push(r.chatter);
        let s = match r.lyapunov {
            Some(Ok(s)) => s,
            Some(Err(e)) => bail!("omega_ratio = {v}: {e}"),
            None => bail!("omega_ratio = {v}: no Lyapunov spectrum"),
        };
        largest = largest.max(s.largest());
        if Motion::of(&s) == Motion::Chaotic {
            chaotic.push(format!("{v:.3}"));
        }
    }
    ctx.finding(
        "20 (exponents)",
        "Chatter at low Ω: many consecutive impacts per period, a band of points in Fig. 20's orbit diagram.",
        format!(
            "Largest Lyapunov exponent at {} values of Ω in [0.30, 0.65] (chatter at {} of them): chaotic at {}; the largest λ1 is {largest:+.4} 1/s. Chatter that ends in sticking collapses two directions (λ = −∞): the band of Fig. 20 is {}.",
            values.len(),
            chatters.iter().filter(|&&c| c).count(),
            if chaotic.is_empty() { "none".to_string() } else { chaotic.join(", ") },
            if chaotic.is_empty() {
                "periodic chatter orbits (many impacts per period), not chaos"
            } else {
                "periodic chatter orbits except where chaotic"
            }
        ),
        chatter_verdict(&chatters),
    );
    Ok(())
}

/// Average power with a batch-means standard error: `batches` consecutive runs of `runner`
/// (no transient), each continuing from the last one's final state, from `state`.
fn batch_power(
    runner: &PointRunner,
    keys: &[(&str, f64)],
    mut state: vibrotribo::ChainState,
    batches: usize,
) -> Result<(f64, f64)> {
    let mut powers = Vec::with_capacity(batches);
    for _ in 0..batches {
        let r = runner.run(keys, Some(&state))?;
        powers.push(r.average_power_w.context("no average power")?);
        state = r.final_state;
    }
    let mean = powers.iter().sum::<f64>() / powers.len() as f64;
    // Each window is one batch.
    let se = batch_means_se(&powers, batches).context("fewer than two windows")?;
    Ok((mean, se))
}

/// Figs. 14–16's candidates for the optimal mass ratio at Ω = 0.72, with error bars.
fn power_error_bars(ctx: &mut Ctx) -> Result<()> {
    let base = config(&[
        ("oscillator.masses", arr(&[0.05, 0.15, 0.05])),
        ("omega_ratio", f(0.72)),
    ])?;
    let window = if ctx.quick { 100 } else { 400 };
    // The first window is the transient (from rest); then 10 batches.
    let first = PointOptions {
        transient_periods: ctx.budget.transient,
        recorded_periods: window,
        ..PointOptions::default()
    };
    let ratios = [2.5, 3.0, 3.5, 6.54];
    let rows: Vec<Result<(f64, f64)>> = ratios
        .par_iter()
        .map(|&rm| {
            let runner = PointRunner::new(base.clone(), first.clone(), false);
            let warm = runner.run(&[("mass_ratio", rm)], None)?;
            let next = PointRunner::new(
                base.clone(),
                PointOptions {
                    transient_periods: 0,
                    ..first.clone()
                },
                false,
            );
            batch_power(&next, &[("mass_ratio", rm)], warm.final_state, 10)
        })
        .collect();
    check_interrupt(|| "during the power error bars; REPORT.md is written only by a complete run".into())?;
    let rows: Vec<(f64, f64)> = rows.into_iter().collect::<Result<_>>()?;
    let text: Vec<String> = ratios
        .iter()
        .zip(&rows)
        .map(|(rm, (p, e))| format!("R_m = {rm}: {} ± {}", si(*p, "W"), si(*e, "W")))
        .collect();
    // Fig. 15's claim: 3.5 beats 3.0 and 2.5 by more than the error bars.
    let (p35, e35) = rows[2];
    let beats = |(p, e): (f64, f64)| p35 - p > 2.0 * (e35 * e35 + e * e).sqrt();
    let stands = beats(rows[0]) && beats(rows[1]);
    let (p654, e654) = rows[3];
    ctx.finding(
        "15–16 (error bars)",
        "Of R_m = 2.5, 3.0 and 3.5 at Ω = 0.72, R_m = 3.5 gives the most power; the optimal mass ratio is about 3.5.",
        format!(
            "Average power over 10 consecutive windows of {window} periods after {} from rest, mean ± batch-means standard error: {}. R_m = 3.5 {} R_m = 2.5 and 3.0 by more than two standard errors; R_m = 6.54 (chaotic, see row 10, 14–15, 18–19) gives {:.1} times R_m = 3.5's power, {:.0} standard errors above it.",
            ctx.budget.transient,
            text.join(", "),
            if stands { "beats" } else { "does not beat" },
            p654 / p35,
            (p654 - p35) / (e35 * e35 + e654 * e654).sqrt()
        ),
        if stands { Verdict::Partly } else { Verdict::Differs },
    );
    Ok(())
}

/// The basins over x2(0) ∈ `x` and v2(0) ∈ ±3 m/s (m1, m3 at rest) of the default case with
/// `sets`, computed by the library ([`StartRunner`]) and written into `name/` as `vibrotribo
/// basins` writes its directory ([`crate::basins::write_grid`]) with its picture; returns the
/// grid size and one line per attractor.
fn basins(ctx: &Ctx, name: &str, sets: &[&str], x: (f64, f64)) -> Result<(usize, Vec<String>)> {
    let dir = ctx.path(name);
    let n = if ctx.quick { 24 } else { 60 };
    let base = ConfigArgs {
        config: None,
        set: sets.iter().map(|s| s.to_string()).collect(),
    }
    .load()?;
    let starts = StartRunner::new(
        ctx.run_args(true).runner_or(base, DEFAULT_START_PERIODS)?,
        AttractorOptions::default(),
    )
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    let axis = |param: &str, (from, to): (f64, f64)| Axis::new(param, (from, to), grid(from, to, n));
    let grid = BasinGrid {
        starts,
        x: axis("run.initial_positions[1]", x),
        y: axis("run.initial_velocities[1]", (-3.0, 3.0)),
    };
    let (done, classified) = crate::basins::write_grid(&grid, &dir, true)?;
    let Some(c) = classified else {
        return Err(Interrupted {
            what: format!(
                "after {done} of the {} starts of {name}/; REPORT.md is written only by a complete run",
                n * n
            ),
        }
        .into());
    };
    crate::basins::plot_basins(&dir)?;
    let described = c
        .attractors
        .iter()
        .enumerate()
        .map(|(a, at)| {
            let period = if at.period == 0 {
                "non-periodic".to_string()
            } else {
                format!("period {}", at.period)
            };
            format!(
                "attractor {} ({period}, {:.2} impacts per period): {:.0} % of the starts",
                a + 1,
                at.impacts_per_period,
                100.0 * c.fraction(a).0
            )
        })
        .collect();
    Ok((n, described))
}

/// The basins of the coexisting motions behind Fig. 7's jump (R_δ = 1.09) and of Fig. 12's
/// small spacing (δ = 5 mm).
fn basin_pictures(ctx: &mut Ctx) -> Result<()> {
    let (n, seven) = basins(
        ctx,
        "basins_fig07",
        &[
            "oscillator.masses=[0.09,0.12,0.09]",
            "omega_ratio=0.70",
            "gap_ratio=1.09",
        ],
        (-0.021, 0.019),
    )?;
    ctx.finding(
        "7 (basins)",
        "A jump from two impacts per cycle to one between R_δ = 1.085 and 1.090.",
        format!(
            "At R_δ = 1.09, {n} × {n} starts over x2(0) and v2(0) (m1, m3 at rest): {}. The jump of a sweep from rest is the crossing of rest from one basin into the other.",
            seven.join("; ")
        ),
        if seven.len() >= 2 {
            Verdict::Agrees
        } else {
            Verdict::Partly
        },
    );
    let (_, twelve) = basins(
        ctx,
        "basins_fig12",
        &[
            "oscillator.masses=[0.048,0.12,0.048]",
            "omega_ratio=0.75",
            "gap=0.005",
        ],
        (-0.0049, 0.0049),
    )?;
    ctx.finding(
        "12 (basins)",
        "The response is complicated at small spacing δ.",
        format!(
            "At δ = 5 mm (Ω = 0.75), {n} × {n} starts over x2(0) and v2(0): {} attractor{}: {}.",
            twelve.len(),
            if twelve.len() == 1 { "" } else { "s" },
            twelve.join("; ")
        ),
        // Complicated: several coexisting motions, or a non-periodic one.
        if twelve.len() >= 2 || twelve.iter().any(|a| a.contains("non-periodic")) {
            Verdict::Agrees
        } else {
            Verdict::Partly
        },
    );
    ctx.figure(
        "7, 12 (basins)",
        "Basins of the coexisting motions at R_δ = 1.09 and at δ = 5 mm",
        format!(
            "The attractor each start (x2(0), v2(0)) ends on, m1 and m3 at rest, {n} × {n} starts, {} transient periods: m1 = m3 = 90 g, m2 = 120 g, Ω = 0.70, R_δ = 1.09 (Fig. 7's jump); the default case at Ω = 0.75 with δ1 = δ2 = 5 mm (Fig. 12's small spacing).",
            ctx.budget.transient
        ),
        vec!["basins_fig07/basins.png".into(), "basins_fig12/basins.png".into()],
    );
    Ok(())
}

/// The expected power of an unknown start across the chatter and resonant range of Fig. 20,
/// next to the power from rest.
fn expected_power(ctx: &mut Ctx) -> Result<()> {
    let dir = ctx.path("attractors_fig20");
    let (steps, samples) = if ctx.quick { (8, 8) } else { (26, 24) };
    let set = vec![
        "oscillator.masses=[0.05,0.15,0.05]".to_string(),
        "oscillator.gaps=[0.005,0.005]".to_string(),
    ];
    let base = ConfigArgs { config: None, set }.load()?;
    let starts = StartRunner::new(
        ctx.run_args(false).runner_or(base, DEFAULT_START_PERIODS)?,
        AttractorOptions::default(),
    )
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    let (param, range) = ("omega_ratio", (0.55, 0.80));
    let values = grid(range.0, range.1, steps);
    let sampling = RandomStarts {
        samples,
        seed: 1,
        bounds: None,
    };
    let manifest = crate::attractors::manifest_of(&starts, param, range, &values, &sampling)?;
    let (results, done) =
        crate::attractors::write_census(&starts, manifest, &sampling, Some(&dir), true, true)?;
    check_interrupt(|| {
        format!(
            "after {done} of the {} values of attractors_fig20/; REPORT.md is written only by a complete run",
            values.len()
        )
    })?;
    crate::attractors::plot_attractors(&dir)?;
    let omega: Vec<f64> = results.iter().map(|v| v.value).collect();
    let (expected, se): (Vec<f64>, Vec<f64>) = results
        .iter()
        .map(|v| v.expected_power.unwrap_or((f64::NAN, f64::NAN)))
        .unzip();
    let base = chatter_case()?;
    let from_rest: Vec<f64> = super::runs::sweep(ctx, &base, "omega_ratio", &omega, false)?
        .iter()
        .map(|r| r.average_power_w.unwrap_or(f64::NAN))
        .collect();
    let mut fig = Figure::new(
        "Expected power and power from rest (chatter case)",
        "Ω",
        "P_a [W]",
    );
    fig.y_scale = Scale::Log;
    let lo: Vec<f64> = expected.iter().zip(&se).map(|(p, e)| p - 2.0 * e).collect();
    let hi: Vec<f64> = expected.iter().zip(&se).map(|(p, e)| p + 2.0 * e).collect();
    let img = lines(
        ctx,
        "fig20_expected_power",
        &fig,
        &[
            ("from rest (Fig. 20)", &omega, &from_rest),
            ("expected, random starts", &omega, &expected),
            ("expected − 2 SE", &omega, &lo),
            ("expected + 2 SE", &omega, &hi),
        ],
    )?;
    let matters = start_matters(&expected, &se, &from_rest);
    let differ: Vec<String> = omega
        .iter()
        .zip(&matters)
        .filter(|(_, m)| **m)
        .map(|(w, _)| format!("{w:.3}"))
        .collect();
    ctx.finding(
        "20, 23 (expected power)",
        "Power against Ω in the chatter case, from one start (Figs. 20, 23).",
        format!(
            "{samples} random starts per value at {steps} values of Ω in [0.55, 0.80]: the expected power of an unknown start differs from the power from rest by more than two standard errors and 1 % at Ω = {}; elsewhere the start does not matter within that.",
            if differ.is_empty() { "none".to_string() } else { differ.join(", ") }
        ),
        one_start_verdict(&matters),
    );
    ctx.figure(
        "20 (expected power)",
        "Expected power over random starts against Ω (chatter case)",
        format!(
            "m1 = m3 = 50 g, R_m = 3, δ1 = δ2 = 5 mm: the power from rest (Fig. 20's curve) and the mean over {samples} random starts per value with ± 2 standard errors; fractions of each attractor in attractors_fig20/."
        ),
        vec![img, "attractors_fig20/attractor_fractions.png".into()],
    );
    Ok(())
}

/// Whether the chatter of Fig. 20 sits at low Ω, as the paper says, from whether each value
/// of an increasing Ω grid chattered: chatter at every value of the grid's lower half
/// agrees, at some of them partly, at none differs.
fn chatter_verdict(chatters: &[bool]) -> Verdict {
    let low = &chatters[..chatters.len().div_ceil(2)];
    Verdict::of(low.iter().filter(|&&c| c).count(), low.len())
}

/// At each value, whether the start matters: the expected power of a random start differs
/// from the power from rest by more than two standard errors and 1 %.
fn start_matters(expected: &[f64], se: &[f64], from_rest: &[f64]) -> Vec<bool> {
    expected
        .iter()
        .zip(se)
        .zip(from_rest)
        .map(|((p, e), r)| {
            let d = (r - p).abs();
            d > 2.0 * e && d > 0.01 * p.abs()
        })
        .collect()
}

/// How far the paper's power from one start (rest) stands for the power of any start: at
/// every value where the start does not matter it agrees, at none it differs.
fn one_start_verdict(matters: &[bool]) -> Verdict {
    Verdict::of(matters.iter().filter(|&&m| !m).count(), matters.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chatter_verdict_follows_the_low_omega_values() {
        // No chatter anywhere contradicts "chatter at low Ω".
        assert_eq!(chatter_verdict(&[false; 6]), Verdict::Differs);
        // Chatter only at high Ω: the lower half has none.
        assert_eq!(
            chatter_verdict(&[false, false, false, true, true, true]),
            Verdict::Differs
        );
        assert_eq!(
            chatter_verdict(&[true, false, false, true, true, true]),
            Verdict::Partly
        );
        assert_eq!(
            chatter_verdict(&[true, true, true, false, false, false]),
            Verdict::Agrees
        );
    }

    #[test]
    fn one_start_verdict_counts_the_values_where_the_start_matters() {
        // Expected power 1 ± 0.01 W: from rest 0.5 W is far off, 1.001 W within the error.
        let expected = [1.0, 1.0, 1.0];
        let se = [0.01, 0.01, 0.01];
        let matters = start_matters(&expected, &se, &[0.5, 0.5, 0.5]);
        assert_eq!(matters, [true, true, true]);
        assert_eq!(one_start_verdict(&matters), Verdict::Differs);
        let matters = start_matters(&expected, &se, &[1.001, 0.5, 1.001]);
        assert_eq!(one_start_verdict(&matters), Verdict::Partly);
        let matters = start_matters(&expected, &se, &[1.001, 0.999, 1.0]);
        assert_eq!(one_start_verdict(&matters), Verdict::Agrees);
        // A difference beyond two errors but within 1 % does not count.
        assert_eq!(start_matters(&[1.0], &[0.001], &[1.005]), [false]);
    }
}
