//! The resistor's boundary layer after a kink carried in closed form
//! (`ChargeOptions::analytic_layers`, the solver's `layer` module), against the exact
//! relaxation of a charge offset and against the same solver crossing the layers with short
//! steps at a much tighter tolerance.

use vibrotribo::electrical::{ChargeOptions, ChargeSolver, HarvesterParams, Load};
use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator, Trajectory};

/// Constant gaps with the charge off its equilibrium by δ: `u = δ e^(−t/τ)` exactly, the
/// current `−δ/τ e^(−t/τ)`, the energy `δ²/(2C)(1 − e^(−2t/τ))`. With a period of 10⁴ τ the
/// whole layer fits in the first step, which carries it in closed form: the samples inside
/// the layer (dense output) and the energy so far must follow the exact solution.
#[test]
fn a_charge_offset_relaxes_exactly_inside_one_step() {
    const EPS0: f64 = 8.854_187_812_8e-12;
    let (d1, d2, r) = (2e-3, 3e-3, 1e5);
    let params = HarvesterParams {
        load: Load::Resistor { resistance: r },
        ..HarvesterParams::default()
    };
    // The paper's freestanding capacitance (seed eq. 12, d₀ = 0.1 mm).
    let c = EPS0 * 0.01 / (1e-4 + d1 + d2);
    let tau = r * c;
    let wave = move |_t: f64, g: &mut [f64], rt: &mut [f64]| {
        g.copy_from_slice(&[d1, d2]);
        rt.fill(0.0);
    };
    let run = |analytic: bool| {
        let mut start = ChargeSolver::new(&params, 1e4 * tau, 2, ChargeOptions::default()).unwrap();
        start.advance(0.0, 0.0, &wave).unwrap();
        let q_eq = start.charge();
        let delta = 1e-9;
        let p = HarvesterParams {
            initial_charge: Some(q_eq + delta),
            ..params.clone()
        };
        let options = ChargeOptions {
            rtol: 1e-8,
            analytic_layers: analytic,
            ..ChargeOptions::default()
        };
        let mut s = ChargeSolver::new(&p, 1e4 * tau, 2, options)
            .unwrap()
            .with_sampling(0.0, tau / 8.0)
            .unwrap();
        s.advance(0.0, 200.0 * tau, &wave).unwrap();
        (s, q_eq, delta)
    };
    let (s, q_eq, delta) = run(true);
    let sm = s.samples().unwrap();
    assert!(sm.times.len() > 1500);
    let e_scale = delta * delta / (2.0 * c);
    for j in 0..sm.times.len() {
        let t = sm.times[j];
        let decay = (-t / tau).exp();
        let what = format!("t = {:.3} τ", t / tau);
        assert!(
            (sm.charge_c[j] - (q_eq + delta * decay)).abs() <= 1e-9 * delta,
            "{what}: charge {:e} against {:e}",
            sm.charge_c[j],
            q_eq + delta * decay
        );
        assert!(
            (sm.current_a[j] + delta / tau * decay).abs() <= 1e-9 * delta / tau,
            "{what}: current {:e} against {:e}",
            sm.current_a[j],
            -delta / tau * decay
        );
        let e = e_scale * (1.0 - (-2.0 * t / tau).exp());
        assert!(
            (sm.energy_j[j] - e).abs() <= 1e-10 * e_scale,
            "{what}: energy {:e} against {e:e}",
            sm.energy_j[j]
        );
    }
    // One step carried the layer; crossing it with short steps takes many.
    let (classic, _, _) = run(false);
    assert!(
        s.stats().steps < classic.stats().steps,
        "{} steps in closed form, {} with short steps",
        s.stats().steps,
        classic.stats().steps
    );
}

/// The paper's default and chatter cases with impacts (a layer after each): the energy per
/// period, the samples and the peaks with the layers in closed form agree with the solver
/// crossing them with short steps at a much tighter tolerance, as closely as the short-step
/// solver at the same tolerance does, and the closed form takes no more steps and waveform
/// evaluations.
#[test]
fn layers_in_closed_form_match_short_steps_on_the_paper_cases() {
    for (name, chain, periods, resistances) in [
        ("default", ChainParams::default(), 20.0, [1e3, 1e5, 1e8]),
        ("chatter", ChainParams::paper_chatter_case(), 8.0, [1e3, 1e5, 1e8]),
    ] {
        let mut sim =
            Simulator::new(&chain, &ChainState::at_rest(chain.len()), SimOptions::default()).unwrap();
        let mut traj = Trajectory::new(&sim);
        sim.run_until(periods * chain.period(), &mut traj).unwrap();
        for r in resistances {
            let params = HarvesterParams {
                load: Load::Resistor { resistance: r },
                ..HarvesterParams::default()
            };
            let run = |rtol: f64, analytic: bool| {
                let options = ChargeOptions {
                    rtol,
                    analytic_layers: analytic,
                    ..ChargeOptions::default()
                };
                let mut s = ChargeSolver::for_chain(&params, &chain, options)
                    .unwrap()
                    .with_periodic_sampling(64)
                    .unwrap();
                s.run_trajectory(&traj).unwrap();
                s
            };
            let reference = run(1e-12, false);
            for rtol in [1e-6, 1e-10] {
                let closed = run(rtol, true);
                let short = run(rtol, false);
                let what = format!("{name}, R = {r:e} Ω, rtol {rtol:e}");
                let v_ref = &reference.samples().unwrap().voltage_v;
                let v_max = v_ref.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                let dev = |s: &ChargeSolver| {
                    let v = &s.samples().unwrap().voltage_v;
                    assert_eq!(v.len(), v_ref.len());
                    v.iter()
                        .zip(v_ref)
                        .map(|(a, b)| (a - b).abs())
                        .fold(0.0, f64::max)
                        / v_max
                };
                let (dev_closed, dev_short) = (dev(&closed), dev(&short));
                // Samples: within 3× the short-step solver's deviation or 10·rtol of the peak.
                assert!(
                    dev_closed <= (3.0 * dev_short).max(10.0 * rtol),
                    "{what}: samples off by {dev_closed:e} of the peak voltage (short steps {dev_short:e})"
                );
                // Energy of every period: within rtol (the solver's per-period target).
                for ((a, b), p) in closed
                    .periods()
                    .iter()
                    .zip(short.periods())
                    .zip(reference.periods())
                {
                    let scale = p.energy_j.abs().max(1e-300);
                    assert!(
                        (a.energy_j - p.energy_j).abs() <= rtol * scale,
                        "{what}: period {} energy {:e} against {:e} (short steps {:e})",
                        p.index,
                        a.energy_j,
                        p.energy_j,
                        b.energy_j
                    );
                    // Peaks are the largest values at the points a step observes (stages,
                    // samples): both solvers observe different points.
                    let (dp_closed, dp_short) = (
                        (a.peak_voltage_v - p.peak_voltage_v).abs(),
                        (b.peak_voltage_v - p.peak_voltage_v).abs(),
                    );
                    assert!(
                        dp_closed <= (3.0 * dp_short).max(10.0 * rtol * v_max).max(1e-6 * v_max),
                        "{what}: period {} peak voltage {:e} against {:e} (short steps {:e})",
                        p.index,
                        a.peak_voltage_v,
                        p.peak_voltage_v,
                        b.peak_voltage_v
                    );
                }
                let total = reference.total_energy();
                assert!(
                    (closed.total_energy() - total).abs() <= rtol * total,
                    "{what}: energy {:e} against {total:e}",
                    closed.total_energy()
                );
                // Steps, and the waveform evaluations (a layer step checked by step doubling
                // evaluates three sets of nodes).
                assert!(
                    closed.stats().steps + closed.stats().rejected
                        <= short.stats().steps + short.stats().rejected
                        && closed.stats().waveform_evaluations <= short.stats().waveform_evaluations,
                    "{what}: {:?} in closed form against {:?} with short steps",
                    closed.stats(),
                    short.stats()
                );
            }
        }
    }
}
