//! Figs. 5–6: the four mass configurations.

use std::fmt::Write as _;

use anyhow::Result;

use super::context::{Ctx, Verdict};
use super::draw::{lines, running_power};
use super::runs::{arr, config, f, mean, run_series};
use crate::output::si;
use crate::plot::{Figure, Scale};

pub(super) fn figs_5_6(ctx: &mut Ctx) -> Result<()> {
    let configs: [(&str, [f64; 3]); 4] = [
        ("(1) m1 = m3 < m2", [0.09, 0.12, 0.09]),
        ("(2) m1 = m3 > m2", [0.12, 0.06, 0.12]),
        ("(3) m1 > m2 > m3", [0.12, 0.096, 0.06]),
        ("(4) m1 < m2 < m3", [0.072, 0.096, 0.12]),
    ];
    // Which side of its static position each mass is on at its impacts, after the transient.
    let mut sides = Vec::new();
    let mut images = Vec::new();
    for (k, (name, m)) in configs.iter().enumerate() {
        let loaded = config(&[("oscillator.masses", arr(m))])?;
        let periods = ctx.budget.series + 40;
        let run = run_series(&loaded, periods, 20, 200, false)?;
        let s = &run.series;
        let mut side = [[false; 2]; 3]; // [mass][below, above]
        for (contact, x) in &s.impacts {
            for i in [*contact, contact + 1] {
                side[i][usize::from(x[i] > 0.0)] = true;
            }
        }
        sides.push(side);
        let labels = ["m1", "m2", "m3"];
        let series: Vec<(&str, &[f64], &[f64])> = (0..3)
            .map(|i| (labels[i], s.x[i].as_slice(), s.v[i].as_slice()))
            .collect();
        let fig = Figure::new(
            format!("Configuration {name}: phase plots"),
            "x_i [m]",
            "v_i [m/s]",
        );
        images.push(lines(ctx, &format!("fig05_config{}", k + 1), &fig, &series)?);
    }
    let describe = |s: &[[bool; 2]; 3]| -> String {
        (0..3)
            .map(|i| {
                let w = match s[i] {
                    [true, true] => "both sides",
                    [true, false] => "below only",
                    [false, true] => "above only",
                    [false, false] => "no impacts",
                };
                format!("m{} {w}", i + 1)
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let expected: [[[bool; 2]; 3]; 4] = [
        [[false, true], [true, true], [true, false]],
        [[true, false], [true, true], [false, true]],
        [[true, false], [true, false], [true, false]],
        [[false, true], [false, true], [false, true]],
    ];
    let ours: Vec<String> = sides
        .iter()
        .enumerate()
        .map(|(k, s)| format!("({}) {}", k + 1, describe(s)))
        .collect();
    let matches = sides.iter().zip(&expected).filter(|(a, b)| a == b).count();
    ctx.figure(
        "5",
        "Phase plots of the four mass configurations",
        "Configurations (1) m2 = 120 g, m1 = m3 = 0.75 m2; (2) m1 = m3 = 120 g, m2 = 0.5 m1; (3) m1 = 120 g, m2 = 0.8 m1, m3 = 0.5 m1; (4) m3 = 120 g, m2 = 0.8 m3, m1 = 0.6 m3. k = 120 N/m, c = 0.02 N s/m, A = 0.08 m, μ = 0.6, δ1 = δ2 = 20 mm, Ω = 0.70, from rest; the last 20 periods.".into(),
        images,
    );
    ctx.finding(
        "5",
        "Config. (1): impacts above m1's static position, below m3's, on both sides of m2's; (2) the opposite; (3) impacts below every mass's static position; (4) the opposite.",
        format!("Sides of the static position at impacts: {}. {matches} of 4 configurations as the paper describes.", ours.join("; ")),
        Verdict::of(matches, 4),
    );

    // Fig. 6: average power of configurations (1) and (2) at three mass ratios and two
    // frequencies.
    let omegas = [0.6, 1.2];
    let mut table = String::new();
    let mut images = Vec::new();
    let mut better = 0;
    for &w in &omegas {
        let mut curves: Vec<(String, Vec<f64>)> = Vec::new();
        let mut means = [0.0; 2];
        for (c, ratios) in [[1.5, 2.0, 3.0], [0.3, 0.5, 0.7]].into_iter().enumerate() {
            let mut powers = Vec::new();
            for &r in &ratios {
                // Config. (1) keeps m2 = 120 g; config. (2) keeps m1 = m3 = 120 g.
                let loaded = if c == 0 {
                    config(&[
                        ("oscillator.masses", arr(&[0.08, 0.12, 0.08])),
                        ("mass_ratio_m2_fixed", f(r)),
                        ("omega_ratio", f(w)),
                    ])?
                } else {
                    config(&[
                        ("oscillator.masses", arr(&[0.12, 0.12 * r, 0.12])),
                        ("omega_ratio", f(w)),
                    ])?
                };
                let run = run_series(&loaded, ctx.budget.series, 1, 20, true)?;
                let curve = run.electrical.as_ref().expect("electrical").power_curve();
                powers.push(curve.last().copied().unwrap_or(f64::NAN));
                curves.push((format!("({}) R_m = {r}", c + 1), curve));
            }
            means[c] = mean(&powers);
            let _ = writeln!(
                table,
                "Ω = {w}, configuration ({}): P_a after {} periods = {} (R_m = {ratios:?})",
                c + 1,
                ctx.budget.series,
                powers.iter().map(|p| si(*p, "W")).collect::<Vec<_>>().join(", "),
            );
        }
        if means[0] > means[1] {
            better += 1;
        }
        images.push(running_power(
            ctx,
            &format!("fig06_omega{w}"),
            format!("Running average power, configurations (1) and (2), Ω = {w}"),
            Scale::Log,
            &curves,
        )?);
    }
    ctx.figure(
        "6",
        "Average power of the two symmetric configurations",
        format!("Configuration (1): m2 = 120 g, R_m ∈ {{1.5, 2, 3}}; configuration (2): m1 = m3 = 120 g, R_m ∈ {{0.3, 0.5, 0.7}}; Ω ∈ {{0.6, 1.2}} (the paper does not state its two frequencies); R = 100 kΩ, paper's V_oc; running average P_a(N) from rest.\n\n{table}"),
        images,
    );
    ctx.finding(
        "6",
        "The first symmetric configuration (m1 = m3 < m2) harvests better than the second.",
        format!("Mean power over the three mass ratios is higher for configuration (1) at {better} of 2 frequencies (Ω = 0.6, 1.2)."),
        Verdict::of(better, 2),
    );
    Ok(())
}
