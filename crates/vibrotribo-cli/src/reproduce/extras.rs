//! Beyond the paper: the load resistance and the open-circuit voltage law.

use anyhow::Result;
use vibrotribo::ChainParams;
use vibrotribo::electrical::{ChargeOptions, HarvesterParams, Load, VocModel, load_sweep, log_spaced};
use vibrotribo::study::{Harvester, ReplayOptions, Replayed, RunSpec, record_trajectory, replay};

use super::context::Ctx;
use super::draw::lines;
use crate::output::si;
use crate::plot::{Figure, Legend, Scale};

pub(super) fn extras(ctx: &mut Ctx) -> Result<()> {
    let chain = ChainParams::default();
    let periods = if ctx.quick { 40 } else { 100 };
    let (traj, _) = record_trajectory(&RunSpec::new(chain.clone(), periods), 0, &mut ())?;
    let transient = periods as usize / 2;
    let harvester = |params: HarvesterParams| Harvester::new(params, ChargeOptions::default());
    // Power after the transient, and air breakdown over the last period, on the paper's
    // harvester with `params` changed.
    let replayed = |params: HarvesterParams| {
        replay(
            &traj,
            &chain,
            &harvester(params),
            &ReplayOptions {
                transient_periods: transient as u64,
                breakdown_from_period: Some(periods - 1),
                vq_cycle: None,
            },
        )
    };
    let average_power = |r: &Replayed| {
        r.electrical
            .power
            .as_ref()
            .map_or(f64::NAN, |s| s.average_power_w)
    };
    let breakdown_at = |r: f64| -> Result<f64> {
        let at = replayed(HarvesterParams {
            load: Load::Resistor { resistance: r },
            ..HarvesterParams::default()
        })?;
        Ok(at.electrical.breakdown.unwrap_or_default().worst_ratio)
    };
    // The paper's case (100 kΩ, the paper's V_oc) and the exact V_oc law.
    let paper = replayed(HarvesterParams::default())?;
    let exact = replayed(HarvesterParams {
        voc_model: VocModel::Exact,
        ..HarvesterParams::default()
    })?;
    let powers = [average_power(&paper), average_power(&exact)];
    let sweep = load_sweep(
        &traj,
        &HarvesterParams::default(),
        chain.period(),
        &log_spaced(1e3, 1e13, if ctx.quick { 21 } else { 41 }),
        transient,
        &ChargeOptions::default(),
    )?;
    let xs: Vec<f64> = sweep.points.iter().map(|p| p.resistance_ohm.log10()).collect();
    let ys: Vec<f64> = sweep.points.iter().map(|p| p.average_power_w).collect();
    let mut fig = Figure::new(
        "Average power against load resistance (default case)",
        "log10(R / Ω)",
        "P_a [W]",
    );
    fig.y_scale = Scale::Log;
    fig.legend = Legend::Hidden;
    let img = lines(ctx, "extra_load_sweep", &fig, &[("P_a", &xs, &ys)])?;
    let best = sweep.optimum;
    let margins = [
        paper.electrical.breakdown.unwrap_or_default().worst_ratio,
        breakdown_at(best.resistance_ohm)?,
    ];
    ctx.figure(
        "extra",
        "Average power against the load resistance",
        format!("The paper's default case (Sect. 4.1), {periods} periods, average over the second half; the paper's V_oc."),
        vec![img],
    );
    ctx.extras.push(format!(
        "**Load.** The paper's 100 kΩ delivers {} on its default case; the optimal resistive load is {} and delivers {} ({:.1e}× more). In the quasi-static regime (R·C ≪ the motion's time scale) power grows in proportion to R. Gauss's law and Paschen's law (air, 1 atm) put the largest air-gap voltage at {:.2} of breakdown at 100 kΩ and {:.2} at the optimum: the paper's σ = 15 µC/m² alone makes σ/ε0 ≈ 1.7 MV/m in the gaps, so the device runs just below breakdown whatever the load.",
        si(powers[0], "W"),
        si(best.resistance_ohm, "Ω"),
        si(best.average_power_w, "W"),
        best.average_power_w / powers[0],
        margins[0],
        margins[1]
    ));
    ctx.extras.push(format!(
        "**Open-circuit voltage model.** With the exact V_oc = σ(D2 − D1)/ε0 instead of the paper's 2σD2/ε0 the default case gives {} instead of {} ({:+.2e} relative): their difference σ(D1 + D2)/ε0 moves the equilibrium charge by σS(D1 + D2)/(d0 + D1 + D2), nearly constant unless all three plates close together.",
        si(powers[1], "W"),
        si(powers[0], "W"),
        (powers[1] - powers[0]) / powers[0]
    ));
    ctx.extras.push("**Contact force.** The paper's eqs. 9–10 carry a factor ½ that is exact only for equal masses; vibrotribo uses N_j = Σ_{i≤j} m_i (a_G − a_i) from the contact complementarity problem. The sign, which is all the sticking test uses, agrees.".into());
    Ok(())
}
