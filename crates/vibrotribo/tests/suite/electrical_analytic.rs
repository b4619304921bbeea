//! The charge solver against closed-form solutions (constant and sinusoidal gaps, exponential
//! relaxation, open- and short-circuit limits, energy conservation in the rectifier), and the
//! harvester parameters' validation.

use vibrotribo::electrical::{
    ChargeOptions, ChargeSolver, Diode, HarvesterParams, Load, LoadKind, Rectifier, TransducerMode, VocModel,
    power_curve, summarize,
};
use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator, Trajectory};

const EPS0: f64 = 8.854_187_812_8e-12;
const AREA: f64 = 0.01;
const SIGMA: f64 = 15e-6;
/// d₀ = 0.1 mm / 2 + 0.1 mm / 2.
const D0: f64 = 1e-4;

/// Freestanding capacitance and the paper's V_oc, written out from seed eqs. 12–13.
fn paper_c_voc(d1: f64, d2: f64) -> (f64, f64) {
    (EPS0 * AREA / (D0 + d1 + d2), 2.0 * SIGMA * d2 / EPS0)
}

/// Prints and checks `|got − expected| ≤ tol`.
fn check(what: &str, t: f64, expected: f64, got: f64, tol: f64) {
    assert!(
        (got - expected).abs() <= tol,
        "{what} at t = {t:e} s: expected {expected:e}, got {got:e} (difference {:e}, tolerance {tol:e})",
        got - expected
    );
}

/// Sinusoidal gaps that both close once per period (T = 0.1 s), so that C and V_oc both vary.
const OMEGA: f64 = 2.0 * std::f64::consts::PI * 10.0;
const AMP: f64 = 2.5e-3;
fn sine_gaps(t: f64, g: &mut [f64], r: &mut [f64]) {
    let (s, c) = (OMEGA * t).sin_cos();
    g[0] = AMP * (1.0 + s);
    g[1] = AMP * (1.0 - c);
    r[0] = AMP * OMEGA * c;
    r[1] = AMP * OMEGA * s;
}

/// Q_eq = C·V_oc of the sine gaps and its rate, from the formulas above (quotient rule).
fn sine_qeq(t: f64) -> (f64, f64) {
    let (mut g, mut r) = ([0.0; 2], [0.0; 2]);
    sine_gaps(t, &mut g, &mut r);
    let (c, voc) = paper_c_voc(g[0], g[1]);
    let sum = D0 + g[0] + g[1];
    let dsum = r[0] + r[1];
    // Q_eq = 2σS D₂ / sum.
    let rate = 2.0 * SIGMA * AREA * (r[1] * sum - g[1] * dsum) / (sum * sum);
    (c * voc, rate)
}

fn params(load: LoadKind, resistance: f64) -> HarvesterParams {
    let load = match load {
        LoadKind::Resistor => Load::Resistor { resistance },
        LoadKind::Rectifier => Load::Rectifier(Rectifier::default()),
        LoadKind::Open => Load::Open,
        LoadKind::Short => Load::Short,
    };
    HarvesterParams {
        load,
        ..HarvesterParams::default()
    }
}

#[test]
fn constant_gaps_stay_at_equilibrium() {
    let (d1, d2) = (3e-3, 7e-3);
    let wave = move |_t: f64, g: &mut [f64], r: &mut [f64]| {
        g.copy_from_slice(&[d1, d2]);
        r.fill(0.0);
    };
    let mut s = ChargeSolver::new(&params(LoadKind::Resistor, 1e5), 0.1, 2, ChargeOptions::default())
        .unwrap()
        .with_sampling(0.0, 1e-3)
        .unwrap();
    s.advance(0.0, 0.25, &wave).unwrap();
    let (c, voc) = paper_c_voc(d1, d2);
    let sm = s.samples().unwrap();
    assert_eq!(sm.times.len(), 251);
    for j in 0..sm.times.len() {
        let t = sm.times[j];
        check("charge", t, c * voc, sm.charge_c[j], 1e-14 * c * voc);
        check("current", t, 0.0, sm.current_a[j], 1e-20);
        check("capacitance", t, c, sm.capacitance_f[j], 1e-14 * c);
        check("voc", t, voc, sm.voc_v[j], 1e-14 * voc);
    }
    assert_eq!(s.total_energy(), 0.0);
}

#[test]
fn small_resistance_carries_the_short_circuit_current() {
    // R → 0: I = d(C·V_oc)/dt up to relative O(ωRC) ~ 1e-10. Checked to 1e-6 of the peak
    // current with rtol = 1e-7 (the default 1e-5 gives 1.7e-6 here).
    let r = 1e-3;
    let options = ChargeOptions {
        rtol: 1e-7,
        ..ChargeOptions::default()
    };
    let mut s = ChargeSolver::new(&params(LoadKind::Resistor, r), 0.1, 2, options)
        .unwrap()
        .with_sampling(0.0, 1e-3)
        .unwrap();
    s.advance(0.0, 0.3, &sine_gaps).unwrap();
    let sm = s.samples().unwrap();
    let peak = (0..300)
        .map(|j| sine_qeq(j as f64 * 1e-3).1.abs())
        .fold(0.0, f64::max);
    // Skip the initial layer (width RC ~ 1e-12 s, the first sample is at t = 0).
    for j in 1..sm.times.len() {
        let t = sm.times[j];
        let (qeq, rate) = sine_qeq(t);
        check("current", t, rate, sm.current_a[j], 1e-6 * peak);
        check("charge", t, qeq, sm.charge_c[j], 1e-9 * qeq.abs().max(1e-9));
    }
}

#[test]
fn huge_resistance_holds_the_charge() {
    // R → ∞: Q stays at Q(0) = C(0)·V_oc(0); it can move by at most
    // ∫|V| dt / R ≤ 2σ(2·2.5 mm)/ε₀ × 0.3 s / 1e20 Ω ≈ 5e-17 C.
    let drift = 2.0 * SIGMA * 2.0 * AMP / EPS0 * 0.3 / 1e20;
    let mut s = ChargeSolver::new(
        &params(LoadKind::Resistor, 1e20),
        0.1,
        2,
        ChargeOptions::default(),
    )
    .unwrap()
    .with_sampling(0.0, 1e-3)
    .unwrap();
    s.advance(0.0, 0.3, &sine_gaps).unwrap();
    let q0 = sine_qeq(0.0).0;
    let sm = s.samples().unwrap();
    for j in 0..sm.times.len() {
        let t = sm.times[j];
        check("charge", t, q0, sm.charge_c[j], drift);
        // The same drift bound, seen through 1/C.
        let expected_v = sm.voc_v[j] - q0 / sm.capacitance_f[j];
        check(
            "voltage",
            t,
            expected_v,
            sm.voltage_v[j],
            drift / sm.capacitance_f[j],
        );
    }
}

#[test]
fn charge_offset_relaxes_exponentially() {
    // Constant gaps, Q(0) = C·V_oc + δ: Q = C·V_oc + δ e^{−t/RC}, I = −δ/(RC) e^{−t/RC},
    // dissipated energy δ²/(2C) (1 − e^{−2t/RC}).
    let (d1, d2, r) = (2e-3, 3e-3, 1e5);
    let (c, voc) = paper_c_voc(d1, d2);
    let tau = r * c;
    let delta = 1e-9;
    let wave = move |_t: f64, g: &mut [f64], rt: &mut [f64]| {
        g.copy_from_slice(&[d1, d2]);
        rt.fill(0.0);
    };
    let p = HarvesterParams {
        initial_charge: Some(c * voc + delta),
        ..params(LoadKind::Resistor, r)
    };
    let t_end = 12.0 * tau;
    let mut s = ChargeSolver::new(&p, 4.0 * tau, 2, ChargeOptions::default())
        .unwrap()
        .with_sampling(0.0, tau / 20.0)
        .unwrap();
    s.advance(0.0, t_end, &wave).unwrap();
    let sm = s.samples().unwrap();
    for j in 0..sm.times.len() {
        let t = sm.times[j];
        let decay = (-t / tau).exp();
        check("charge", t, c * voc + delta * decay, sm.charge_c[j], 1e-6 * delta);
        check(
            "current",
            t,
            -delta / tau * decay,
            sm.current_a[j],
            1e-6 * delta / tau,
        );
        let e = delta * delta / (2.0 * c) * (1.0 - (-2.0 * t / tau).exp());
        check("energy", t, e, sm.energy_j[j], 1e-6 * delta * delta / (2.0 * c));
    }
    let e_end = delta * delta / (2.0 * c) * (1.0 - (-2.0 * t_end / tau).exp());
    check("total energy", t_end, e_end, s.total_energy(), 1e-7 * e_end);
    // Three periods of 4τ: energy booked per period.
    let periods = s.periods();
    assert_eq!(periods.len(), 3, "{periods:?}");
    for (k, p) in periods.iter().enumerate() {
        let (a, b) = (4.0 * tau * k as f64, 4.0 * tau * (k + 1) as f64);
        let e = delta * delta / (2.0 * c) * ((-2.0 * a / tau).exp() - (-2.0 * b / tau).exp());
        check("period energy", a, e, p.energy_j, 1e-7 * e_end);
    }
}

#[test]
fn open_and_short_circuit_limits() {
    let q0 = sine_qeq(0.0).0;
    let mut open = ChargeSolver::new(&params(LoadKind::Open, 1e5), 0.1, 2, ChargeOptions::default())
        .unwrap()
        .with_sampling(0.0, 1e-3)
        .unwrap();
    open.advance(0.0, 0.2, &sine_gaps).unwrap();
    let mut short = ChargeSolver::new(&params(LoadKind::Short, 1e5), 0.1, 2, ChargeOptions::default())
        .unwrap()
        .with_sampling(0.0, 1e-3)
        .unwrap();
    short.advance(0.0, 0.2, &sine_gaps).unwrap();
    let (so, ss) = (open.samples().unwrap(), short.samples().unwrap());
    for j in 0..so.times.len() {
        let t = so.times[j];
        let (mut g, mut r) = ([0.0; 2], [0.0; 2]);
        sine_gaps(t, &mut g, &mut r);
        let (c, voc) = paper_c_voc(g[0], g[1]);
        check("open charge", t, q0, so.charge_c[j], 0.0);
        check("open current", t, 0.0, so.current_a[j], 0.0);
        check(
            "open voltage",
            t,
            voc - q0 / c,
            so.voltage_v[j],
            1e-12 * voc.abs().max(1.0),
        );
        let (qeq, rate) = sine_qeq(t);
        check("short charge", t, qeq, ss.charge_c[j], 1e-14 * SIGMA * AREA);
        check(
            "short current",
            t,
            rate,
            ss.current_a[j],
            1e-12 * rate.abs().max(1e-9),
        );
        check("short voltage", t, 0.0, ss.voltage_v[j], 0.0);
    }
    assert_eq!(open.total_energy(), 0.0);
    assert_eq!(short.total_energy(), 0.0);
}

#[test]
fn contact_separation_on_two_masses_relaxes_exponentially() {
    // Two-plate mode on the single gap of an N = 2 chain: C = ε₀S/(d₀ + D), V_oc = σD/ε₀.
    let d = 4e-3;
    let (c, voc) = (EPS0 * AREA / (D0 + d), SIGMA * d / EPS0);
    let r = 1e6;
    let tau = r * c;
    let p = HarvesterParams {
        mode: TransducerMode::ContactSeparation,
        initial_charge: Some(0.0),
        ..params(LoadKind::Resistor, r)
    };
    let wave = move |_t: f64, g: &mut [f64], rt: &mut [f64]| {
        g[0] = d;
        rt[0] = 0.0;
    };
    let mut s = ChargeSolver::new(&p, tau, 1, ChargeOptions::default()).unwrap();
    s.advance(0.0, 5.0 * tau, &wave).unwrap();
    let q = c * voc * (1.0 - (-5.0f64).exp());
    check("charge", 5.0 * tau, q, s.charge(), 1e-7 * c * voc);
    let e = (c * voc) * (c * voc) / (2.0 * c) * (1.0 - (-10.0f64).exp());
    check("energy", 5.0 * tau, e, s.total_energy(), 1e-7 * e);
}

#[test]
fn exact_voc_model_sets_gauss_law_equilibrium() {
    // V_oc = σ(D₂ − D₁)/ε₀ (docs/MODEL.md §2).
    let (d1, d2) = (6e-3, 2e-3);
    let p = HarvesterParams {
        voc_model: VocModel::Exact,
        ..params(LoadKind::Resistor, 1e5)
    };
    let wave = move |_t: f64, g: &mut [f64], r: &mut [f64]| {
        g.copy_from_slice(&[d1, d2]);
        r.fill(0.0);
    };
    let mut s = ChargeSolver::new(&p, 0.1, 2, ChargeOptions::default()).unwrap();
    s.advance(0.0, 0.01, &wave).unwrap();
    let c = EPS0 * AREA / (D0 + d1 + d2);
    let q = c * SIGMA * (d2 - d1) / EPS0;
    check("charge", 0.01, q, s.charge(), 1e-14 * q.abs());
}

#[test]
fn rectifier_conserves_energy_and_reaches_target() {
    // Energy delivered through the bridge equals ½ C_s V_s² (no resistor across C_s).
    let cs = 1e-7;
    let p = HarvesterParams {
        load: Load::Rectifier(Rectifier {
            storage_capacitance: cs,
            target_voltage: Some(10.0),
            ..Rectifier::default()
        }),
        ..HarvesterParams::default()
    };
    let mut s = ChargeSolver::new(&p, 0.1, 2, ChargeOptions::default()).unwrap();
    s.advance(0.0, 0.5, &sine_gaps).unwrap();
    let vs = s.storage_voltage().unwrap();
    let stored = 0.5 * cs * vs * vs;
    check("stored energy", 0.5, stored, s.total_energy(), 1e-6 * stored);
    assert!(vs > 10.0, "storage voltage {vs} V");
    // Stopping exactly at the reported crossing time gives the target voltage.
    let t_target = s.time_to_target().expect("10 V reached");
    let mut again = ChargeSolver::new(&p, 0.1, 2, ChargeOptions::default()).unwrap();
    again.advance(0.0, t_target, &sine_gaps).unwrap();
    check(
        "storage voltage at target time",
        t_target,
        10.0,
        again.storage_voltage().unwrap(),
        1e-5,
    );
    // Periods record the storage voltage.
    let last = s.periods().last().unwrap();
    check(
        "period storage voltage",
        last.t_end,
        vs,
        last.storage_voltage_v.unwrap(),
        0.0,
    );
}

#[test]
fn live_observer_equals_replay_and_summaries_add_up() {
    let chain = ChainParams::default();
    let mut sim = Simulator::new(&chain, &ChainState::at_rest(3), SimOptions::default()).unwrap();
    let mut live =
        ChargeSolver::for_chain(&HarvesterParams::default(), &chain, ChargeOptions::default()).unwrap();
    let mut trajectory = Trajectory::new(&sim);
    sim.run_until(6.0 * chain.period(), &mut (&mut live, &mut trajectory))
        .unwrap();
    live.status().unwrap();
    let mut replay =
        ChargeSolver::for_chain(&HarvesterParams::default(), &chain, ChargeOptions::default()).unwrap();
    replay.run_trajectory(&trajectory).unwrap();
    assert_eq!(live.periods(), replay.periods());
    let periods = live.periods();
    assert_eq!(periods.len(), 6);
    let t = chain.period();
    // Eq. 14 by hand.
    let summary = summarize(periods, t, 2).unwrap();
    let e: f64 = periods[2..].iter().map(|p| p.energy_j).sum();
    check(
        "average power",
        0.0,
        e / (4.0 * t),
        summary.average_power_w,
        1e-15 * e,
    );
    let curve = power_curve(periods, t);
    assert_eq!(curve.len(), 6);
    let e3: f64 = periods[..3].iter().map(|p| p.energy_j).sum();
    check("P_a(3)", 0.0, e3 / (3.0 * t), curve[2], 1e-15 * e3);
    assert!(summary.average_power_w > 0.0);
}

#[test]
fn bad_parameters_are_rejected_naming_the_key() {
    let cases: Vec<(HarvesterParams, &str)> = vec![
        (
            HarvesterParams {
                area: -0.01,
                ..HarvesterParams::default()
            },
            "invalid area = -0.01",
        ),
        (
            HarvesterParams {
                relative_permittivity: [2.0, 0.0],
                ..HarvesterParams::default()
            },
            "invalid relative_permittivity[1] = 0",
        ),
        (
            HarvesterParams {
                load: Load::Resistor { resistance: -5.0 },
                ..HarvesterParams::default()
            },
            "invalid load_resistance = -5",
        ),
        (
            HarvesterParams {
                charge_density: f64::NAN,
                ..HarvesterParams::default()
            },
            "invalid charge_density = NaN",
        ),
        (
            HarvesterParams {
                dielectric_thickness: [0.0, 0.0],
                ..HarvesterParams::default()
            },
            "invalid dielectric_thickness = 0",
        ),
        (
            HarvesterParams {
                load: Load::Rectifier(Rectifier {
                    diode: Diode {
                        series_resistance: 0.0,
                        ..Rectifier::default().diode
                    },
                    ..Rectifier::default()
                }),
                ..HarvesterParams::default()
            },
            "invalid diode_series_resistance = 0",
        ),
        (
            HarvesterParams {
                load: Load::Rectifier(Rectifier {
                    storage_capacitance: f64::INFINITY,
                    ..Rectifier::default()
                }),
                ..HarvesterParams::default()
            },
            "invalid storage_capacitance = inf",
        ),
    ];
    for (p, key) in cases {
        let msg = p.validate().unwrap_err().to_string();
        assert!(msg.contains(key), "error `{msg}` does not name `{key}`");
    }
    // Freestanding mode needs two gaps; contacts must exist.
    let msg = HarvesterParams::default()
        .validate_for_gaps(1)
        .unwrap_err()
        .to_string();
    assert!(
        msg.starts_with("mode: ") && msg.contains("contact_separation"),
        "{msg}"
    );
    assert!(
        HarvesterParams::default()
            .validate_for_gaps(1)
            .unwrap_err()
            .within("harvester")
            .to_string()
            .starts_with("harvester.mode: ")
    );
    let p = HarvesterParams {
        mode: TransducerMode::ContactSeparation,
        contact: 2,
        ..HarvesterParams::default()
    };
    let msg = p.validate_for_gaps(2).unwrap_err().to_string();
    assert!(msg.contains("invalid contact = 2"), "{msg}");
    // The solver refuses them too, and bad options.
    let msg = ChargeSolver::new(
        &HarvesterParams::default(),
        0.1,
        2,
        ChargeOptions {
            rtol: 0.5,
            ..ChargeOptions::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(msg.contains("invalid rtol = 0.5"), "{msg}");
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Config {
    harvester: HarvesterParams,
}

#[test]
fn toml_harvester_table_deserializes_and_reports_bad_input() {
    let text = r#"
        [harvester]
        mode = "freestanding"
        voc_model = "exact"
        area = 0.02
        dielectric_thickness = [1e-4, 2e-4]
        load = "rectifier"
        storage_capacitance = 4.7e-6
        diode_saturation_current = 1e-8
    "#;
    let c: Config = toml::from_str(text).unwrap();
    assert_eq!(c.harvester.voc_model, VocModel::Exact);
    assert_eq!(c.harvester.load.kind(), LoadKind::Rectifier);
    assert_eq!(c.harvester.area, 0.02);
    let r = c.harvester.load.rectifier().unwrap();
    assert_eq!(r.storage_capacitance, 4.7e-6);
    assert_eq!(r.diode.saturation_current, 1e-8);
    assert_eq!(c.harvester.charge_density, 15e-6, "defaults fill the rest");
    c.harvester.validate().unwrap();

    let err = toml::from_str::<Config>("[harvester]\nmode = \"sideways\"\n")
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("mode") && err.contains("sideways"), "{err}");
    let err = toml::from_str::<Config>("[harvester]\nload = \"battery\"\n")
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("load") && err.contains("battery"), "{err}");
    let err = toml::from_str::<Config>("[harvester]\nareaa = 0.1\n")
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("areaa"), "{err}");
    let c: Config = toml::from_str("[harvester]\narea = -1.0\n").unwrap();
    let err = c.harvester.validate().unwrap_err().to_string();
    assert!(err.contains("invalid area = -1"), "{err}");
}

#[test]
fn vq_cycle_encloses_the_period_energy() {
    // With a resistor, ∮ V dQ over a period is ∫ V I dt, the energy dissipated in it.
    let points = 4000;
    let mut s = ChargeSolver::new(&params(LoadKind::Resistor, 1e8), 0.1, 2, ChargeOptions::default())
        .unwrap()
        .with_vq_cycle(2, points)
        .unwrap();
    s.advance(0.0, 0.4, &sine_gaps).unwrap();
    let vq = s.vq_cycle().unwrap();
    assert_eq!(vq.times.len(), points + 1);
    check("first time", 0.0, 0.2, vq.times[0], 1e-15);
    check("last time", 0.0, 0.3, vq.times[points], 1e-15);
    let mut area = 0.0;
    for j in 0..points {
        // V = V_oc − Q/C holds at every point.
        let v = vq.voc_v[j] - vq.charge_c[j] / vq.capacitance_f[j];
        check(
            "V = Voc - Q/C",
            vq.times[j],
            v,
            vq.voltage_v[j],
            1e-9 * v.abs().max(1.0),
        );
        area += 0.5 * (vq.voltage_v[j] + vq.voltage_v[j + 1]) * (vq.charge_c[j + 1] - vq.charge_c[j]);
    }
    let e = s.periods()[2].energy_j;
    println!("V-Q loop area {area:.9e} J, period energy {e:.9e} J");
    check("loop area", 0.2, e, area, 1e-5 * e);
}

#[test]
fn rectifier_with_load_resistor_balances_energy() {
    // Energy through the bridge = ½ C_s V_s² + ∫ V_s²/R_L dt (the integral by the trapezoid
    // rule on a fine sample grid).
    let (cs, rl) = (1e-7, 2e5);
    let p = HarvesterParams {
        load: Load::Rectifier(Rectifier {
            storage_capacitance: cs,
            storage_load_resistance: Some(rl),
            ..Rectifier::default()
        }),
        ..HarvesterParams::default()
    };
    let dt = 2e-6;
    let mut s = ChargeSolver::new(&p, 0.1, 2, ChargeOptions::default())
        .unwrap()
        .with_sampling(0.0, dt)
        .unwrap();
    s.advance(0.0, 0.3, &sine_gaps).unwrap();
    let sm = s.samples().unwrap();
    let vs = &sm.storage_voltage_v;
    let mut dissipated = 0.0;
    for j in 0..vs.len() - 1 {
        dissipated += 0.5 * (vs[j] * vs[j] + vs[j + 1] * vs[j + 1]) / rl * dt;
    }
    let v_end = s.storage_voltage().unwrap();
    let balance = 0.5 * cs * v_end * v_end + dissipated;
    println!(
        "delivered {:.9e} J = stored {:.9e} J + dissipated {dissipated:.9e} J ({balance:.9e})",
        s.total_energy(),
        0.5 * cs * v_end * v_end
    );
    assert!(dissipated > 0.2 * s.total_energy(), "the resistor must matter");
    check(
        "energy balance",
        0.3,
        s.total_energy(),
        balance,
        1e-5 * s.total_energy(),
    );
}

/// A piece an ulp long (a coupled window that ends next to an event makes them) must not
/// leave the solver a step of a few ulps for the next piece: that failed as a step-size
/// underflow at the next piece's start. The run split there delivers the energy of the run
/// in one piece (both to the solver's tolerance; the split point is a kink-free instant, so
/// only the step sequence differs).
#[test]
fn a_piece_an_ulp_long_does_not_stall_the_next() {
    let options = ChargeOptions {
        rtol: 1e-10,
        ..ChargeOptions::default()
    };
    let solver = || ChargeSolver::new(&params(LoadKind::Resistor, 1e5), 0.1, 2, options.clone()).unwrap();
    let mut whole = solver();
    whole.advance(0.0, 0.2, &sine_gaps).unwrap();
    let mut split = solver();
    // One ulp at t1, far below the solver's underflow floor 4ε·max(t, T) = 8.9e-17 s.
    let t1 = 0.0078125;
    let t2 = t1 + f64::EPSILON * t1;
    split.advance(0.0, t1, &sine_gaps).unwrap();
    split.advance(t1, t2, &sine_gaps).unwrap();
    split
        .advance(t2, 0.2, &sine_gaps)
        .unwrap_or_else(|e| panic!("the piece after one of an ulp failed: {e}"));
    let (a, b) = (whole.total_energy(), split.total_energy());
    assert!(a > 0.0);
    assert!(
        (a - b).abs() <= 1e-8 * a,
        "energy {a:e} J in one piece, {b:e} J split"
    );
}

/// The rectifier started with no transferred charge (Q = 0 where Q_eq = C·V_oc, 68 kV across
/// the bridge at the paper's rest gaps of 20 mm): the bridge conducts through its series
/// resistances (2R_s·C ~ 2.5 ps) until the transducer's voltage is down to the storage voltage plus two diode
/// drops. This stopped at t = 0 with a step-size underflow (the switching rule measured the
/// diodes' terminal voltages, kilovolts apart between stages, not their junctions). Checked at
/// constant gaps against charge conservation (everything through the bridge lands on C_s:
/// C_s·ΔV_s = |ΔQ|) and the energy identity at the terminals (∫V·I dt = e(u₀² − u₁²)/2, the
/// field energy given up), and against the end state: |V| − V_s below two diode drops.
#[test]
fn rectifier_started_kilovolts_from_equilibrium_discharges_through_the_bridge() {
    let (d1, d2) = (0.02, 0.02);
    let wave = move |_t: f64, g: &mut [f64], r: &mut [f64]| {
        g.copy_from_slice(&[d1, d2]);
        r.fill(0.0);
    };
    let cs = 1e-6;
    let rectifier = Rectifier {
        storage_capacitance: cs,
        ..Rectifier::default()
    };
    let p = HarvesterParams {
        load: Load::Rectifier(rectifier),
        initial_charge: Some(0.0),
        ..HarvesterParams::default()
    };
    let (c, voc) = paper_c_voc(d1, d2);
    let (e, q_eq) = (1.0 / c, c * voc);
    // The period of the paper's default case (0.18 s): the old rule's first step fell below
    // the rounding floor 4ε·T there.
    let mut s = ChargeSolver::new(&p, ChainParams::default().period(), 2, ChargeOptions::default()).unwrap();
    s.advance(0.0, 1e-6, &wave)
        .unwrap_or_else(|err| panic!("the kilovolt start failed: {err}"));
    let (u0, u1) = (0.0 - q_eq, s.charge() - q_eq);
    assert!(-u0 * e > 1e4, "the start has {} V across the bridge", -u0 * e);
    let vs = s.storage_voltage().unwrap();
    let moved = s.charge() - 0.0;
    check("charge on C_s", 1e-6, moved.abs(), cs * vs, 1e-6 * moved.abs());
    let released = 0.5 * e * (u0 * u0 - u1 * u1);
    check(
        "terminal energy",
        1e-6,
        released,
        s.terminal_energy(),
        1e-6 * released,
    );
    let v = -u1 * e;
    assert!(
        v.abs() > vs && v.abs() - vs < 2.0,
        "V = {v} V against V_s = {vs} V"
    );
}
