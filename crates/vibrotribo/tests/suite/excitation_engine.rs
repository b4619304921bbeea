//! The engine under base motions other than one sine, against truth from outside
//! the code: the harmonic run itself (a one-harmonic multisine must equal it bit for bit, a
//! record of it sampled 200 times a period must reproduce it within the spline's error), an
//! independent fixed-step RK4 integrator written here (two harmonics, impacts by bisection
//! and Newton's law, as in tests/suite/external_forces.rs), and the refusals' reasons.

use std::path::PathBuf;
use std::sync::Arc;

use vibrotribo::config::Config;
use vibrotribo::excitation::{BaseMotion, BaseMotionError, Harmonic};
use vibrotribo::study::{
    Mechanics, PointOptions, RunObserver, RunSpec, Sample, StudyError, run_point_driven, simulate,
};
use vibrotribo::{ChainParams, ChainState, EventKind, EventLog};

fn run_events(spec: &RunSpec) -> (EventLog, vibrotribo::study::RunOutcome) {
    let mut log = Mechanics::new(EventLog::default());
    let outcome = simulate(spec, &mut log).unwrap();
    assert!(outcome.failure().is_none(), "{:?}", outcome.ending);
    (log.inner, outcome)
}

fn impacts(log: &EventLog) -> Vec<&vibrotribo::dynamics::LoggedEvent> {
    log.events
        .iter()
        .filter(|e| e.event.kind == EventKind::Impact)
        .collect()
}

// ---------------------------------------------------------------------------------------
// (a) A multisine of one harmonic is the harmonic run.
// ---------------------------------------------------------------------------------------

/// `kind = "multisine"` with one harmonic at the reference frequency, phase 0, amplitude A
/// gives the same events, power and final state as `kind = "harmonic"` with amplitude A, to
/// the last bit (it is run as the harmonic run itself).
#[test]
fn one_harmonic_multisine_is_the_harmonic_run_bit_for_bit() {
    let harmonic = Config::from_toml_str("[excitation]\namplitude = 0.06\n[run]\nperiods = 30\n").unwrap();
    let multi = Config::from_toml_str(
        "[excitation]\nkind = \"multisine\"\nharmonics = [{amplitude = 0.06, ratio = 1}]\n[run]\nperiods = 30\n",
    )
    .unwrap();
    multi.check_runnable().unwrap();
    assert!(multi.is_periodic());
    multi.check_periodic("periodic orbits").unwrap();
    let (a, ra) = run_events(&harmonic.run_spec(false));
    let (b, rb) = run_events(&multi.run_spec(false));
    assert!(a.events.len() > 50);
    assert_eq!(a.events, b.events);
    assert_eq!(ra.final_state, rb.final_state);
    assert_eq!(ra.final_time.to_bits(), rb.final_time.to_bits());
    assert_eq!(ra.electrical, rb.electrical);
    assert_eq!(ra.stats, rb.stats);
}

// ---------------------------------------------------------------------------------------
// (b) A record of the harmonic reproduces the harmonic run.
// ---------------------------------------------------------------------------------------

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join("excitation_engine")
        .join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The default case's base displacement A sin ωt sampled 200 times a period over 11
/// periods, written as a displacement record, run for 10 periods: every impact of the
/// harmonic run is there, at the same contact, its time and positions within what the
/// spline's error allows. The not-a-knot spline of sin at 200 points a period is within
/// 5/384 (ωh)⁴ A ≈ 1.3e-8 A of it; the response error is of that order relative to the
/// motion, so impact times within 1e-8 T and positions within 1e-8 m (A = 0.08 m).
#[test]
fn harmonic_record_reproduces_the_harmonic_run() {
    let harmonic = Config::from_toml_str("[run]\nperiods = 10\n").unwrap();
    let chain = harmonic.chain();
    let (a, w, period) = (chain.excitation.amplitude, chain.omega(), chain.period());
    let per = 200;
    let body: String = (0..=11 * per)
        .map(|k| {
            let t = period * k as f64 / per as f64;
            format!("{t:e},{:e}\n", a * (w * t).sin())
        })
        .collect();
    let dir = scratch("harmonic_record");
    std::fs::write(dir.join("sine.csv"), format!("time_s,displacement_m\n{body}")).unwrap();
    std::fs::write(
        dir.join("run.toml"),
        "[excitation]\nkind = \"record\"\nfile = \"sine.csv\"\nquantity = \"displacement\"\n[run]\nperiods = 10\n",
    )
    .unwrap();
    let record = Config::from_path(&dir.join("run.toml")).unwrap();
    record.check_runnable().unwrap();
    assert!(!record.is_periodic());
    let (ha, ra) = run_events(&harmonic.run_spec(true));
    let (hb, rb) = run_events(&record.run_spec(true));
    let (ia, ib) = (impacts(&ha), impacts(&hb));
    assert!(ia.len() >= 40, "{} impacts", ia.len());
    assert_eq!(ia.len(), ib.len());
    let (mut dt, mut dx, mut dv) = (0.0f64, 0.0f64, 0.0f64);
    for (p, q) in ia.iter().zip(&ib) {
        assert_eq!(p.event.contact, q.event.contact);
        dt = dt.max((p.event.time - q.event.time).abs());
        for i in 0..3 {
            dx = dx.max((p.positions[i] - q.positions[i]).abs());
            dv = dv.max((p.velocities[i] - q.velocities[i]).abs());
        }
    }
    let xf = (0..3)
        .map(|i| (ra.final_state.positions[i] - rb.final_state.positions[i]).abs())
        .fold(0.0, f64::max);
    println!(
        "record vs harmonic over 10 periods: {} impacts, max |Δt| = {dt:.3e} s ({:.3e} T), max |Δx| = {dx:.3e} m, max |Δv| = {dv:.3e} m/s, final |Δx| = {xf:.3e} m",
        ia.len(),
        dt / period
    );
    assert!(dt < 1e-8 * period, "{dt}");
    assert!(dx < 1e-8 && xf < 1e-8, "{dx} {xf}");
    assert!(dv < 1e-6, "{dv}");
}

/// The `base` column of the samples is the spline's displacement (not the harmonic's, which
/// is switched off under a spline).
#[test]
fn samples_carry_the_splines_base_displacement() {
    #[derive(Default)]
    struct Bases(Vec<(f64, f64)>);
    impl RunObserver for Bases {
        fn wants_samples(&self) -> bool {
            true
        }
        fn sample(&mut self, s: &Sample<'_>) {
            self.0.push((s.time, s.base));
        }
    }
    let c = Config::from_toml_str(
        "[excitation]\nkind = \"multisine\"\nharmonics = [{amplitude = 0.05, ratio = 1}, {amplitude = 0.01, ratio = 3.1, phase = 1}]\n[run]\nperiods = 3\nsamples_per_period = 50\n",
    )
    .unwrap();
    let spec = c.sampled_run_spec(true);
    let BaseMotion::Harmonics(h) = &**spec.base_motion.as_ref().unwrap() else {
        panic!()
    };
    let tol = vibrotribo::dynamics::multisine_tolerance(h);
    let mut bases = Bases::default();
    simulate(&spec, &mut bases).unwrap();
    assert_eq!(bases.0.len(), 151);
    for &(t, y) in &bases.0 {
        let exact = vibrotribo::excitation::evaluate_sum(h, t)[0];
        assert!((y - exact).abs() <= tol, "t = {t}: {y} vs {exact}");
    }
    assert!(bases.0.iter().any(|&(_, y)| y.abs() > 0.03));
}

// ---------------------------------------------------------------------------------------
// (c) Two harmonics against an independent integrator.
// ---------------------------------------------------------------------------------------

/// `m_i x_i'' = −c_i (x_i' − y') − k_i (x_i − y)` with y = Σ A_j sin(ω_j t + φ_j), every
/// mass free between impacts; classical RK4 with a fixed step, an impact located by
/// bisection on the step length and resolved by Newton's law with momentum conservation.
struct Reference<'a> {
    p: &'a ChainParams,
    h: &'a [Harmonic],
    step: f64,
    t: f64,
    x: Vec<f64>,
    v: Vec<f64>,
    impacts: Vec<(f64, usize, Vec<f64>)>,
}

impl Reference<'_> {
    fn accel(&self, t: f64, x: &[f64], v: &[f64]) -> Vec<f64> {
        let (mut y, mut yd) = (0.0, 0.0);
        for h in self.h {
            let ph = h.omega * t + h.phase;
            y += h.amplitude * ph.sin();
            yd += h.amplitude * h.omega * ph.cos();
        }
        let p = self.p;
        (0..x.len())
            .map(|i| (-p.damping[i] * (v[i] - yd) - p.stiffness[i] * (x[i] - y)) / p.masses[i])
            .collect()
    }

    fn rk4(&self, t: f64, x: &[f64], v: &[f64], h: f64) -> (Vec<f64>, Vec<f64>) {
        let n = x.len();
        let comb = |a: &[f64], b: &[f64], s: f64| -> Vec<f64> { (0..n).map(|i| a[i] + s * b[i]).collect() };
        let a1 = self.accel(t, x, v);
        let (x2, v2) = (comb(x, v, 0.5 * h), comb(v, &a1, 0.5 * h));
        let a2 = self.accel(t + 0.5 * h, &x2, &v2);
        let (x3, v3) = (comb(x, &v2, 0.5 * h), comb(v, &a2, 0.5 * h));
        let a3 = self.accel(t + 0.5 * h, &x3, &v3);
        let (x4, v4) = (comb(x, &v3, h), comb(v, &a3, h));
        let a4 = self.accel(t + h, &x4, &v4);
        (
            (0..n)
                .map(|i| x[i] + h / 6.0 * (v[i] + 2.0 * v2[i] + 2.0 * v3[i] + v4[i]))
                .collect(),
            (0..n)
                .map(|i| v[i] + h / 6.0 * (a1[i] + 2.0 * a2[i] + 2.0 * a3[i] + a4[i]))
                .collect(),
        )
    }

    fn min_gap(&self, x: &[f64]) -> (f64, usize) {
        (0..x.len() - 1)
            .map(|k| (self.p.gaps[k] - (x[k + 1] - x[k]), k))
            .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a })
    }

    fn advance_to(&mut self, t_end: f64) {
        let (mut base, mut steps) = (self.t, 0u64);
        while self.t < t_end {
            let target = (base + (steps + 1) as f64 * self.step).min(t_end);
            let hs = target - self.t;
            let (xn, vn) = self.rk4(self.t, &self.x, &self.v, hs);
            if self.min_gap(&xn).0 >= 0.0 {
                (self.t, self.x, self.v) = (target, xn, vn);
                steps += 1;
                continue;
            }
            let (mut lo, mut hi) = (0.0, hs);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if self.min_gap(&self.rk4(self.t, &self.x, &self.v, mid).0).0 < 0.0 {
                    hi = mid
                } else {
                    lo = mid
                }
            }
            let (xi, mut vi) = self.rk4(self.t, &self.x, &self.v, lo);
            let k = self.min_gap(&self.rk4(self.t, &self.x, &self.v, hi).0).1;
            let vc = vi[k + 1] - vi[k];
            assert!(vc > 0.0, "reference: a touch without closing speed");
            let (m1, m2) = (self.p.masses[k], self.p.masses[k + 1]);
            let impulse = (1.0 + self.p.restitution) * vc * m1 * m2 / (m1 + m2);
            vi[k] += impulse / m1;
            vi[k + 1] -= impulse / m2;
            self.t += lo;
            (base, steps) = (self.t, 0);
            (self.x, self.v) = (xi, vi);
            self.impacts.push((self.t, k, self.x.clone()));
        }
    }
}

/// The default three-mass chain under two harmonics (0.06 m at the reference frequency, 0.015
/// m at 2.3 times it, phase 0.4) for 4 periods: the engine (the multisine sampled into a
/// spline within 1e-10 of Σ|A|, exact per-interval forces) against RK4 with a 1 µs step
/// (its error ~(ω_max h)⁴ ω_max t ≈ 1e-14 relative): the same impacts, times within 1e-9 s,
/// positions within 1e-9 m, the final state within 1e-8.
#[test]
fn two_harmonics_match_an_independent_integrator() {
    let chain = ChainParams::default();
    let w = chain.omega();
    let h = vec![
        Harmonic {
            amplitude: 0.06,
            omega: w,
            phase: 0.0,
        },
        Harmonic {
            amplitude: 0.015,
            omega: 2.3 * w,
            phase: 0.4,
        },
    ];
    let periods = 4;
    let spec = RunSpec {
        base_motion: Some(Arc::new(BaseMotion::Harmonics(h.clone()))),
        ..RunSpec::new(chain.clone(), periods)
    };
    let (log, outcome) = run_events(&spec);
    let engine: Vec<_> = impacts(&log);
    let mut r = Reference {
        p: &chain,
        h: &h,
        step: 1e-6,
        t: 0.0,
        x: vec![0.0; 3],
        v: vec![0.0; 3],
        impacts: Vec::new(),
    };
    r.advance_to(periods as f64 * chain.period());
    assert!(engine.len() >= 8, "{} impacts", engine.len());
    assert_eq!(engine.len(), r.impacts.len());
    let (mut dt, mut dx) = (0.0f64, 0.0f64);
    for (e, (t, k, x)) in engine.iter().zip(&r.impacts) {
        assert_eq!(e.event.contact, *k);
        dt = dt.max((e.event.time - t).abs());
        for (a, b) in e.positions.iter().zip(x) {
            dx = dx.max((a - b).abs());
        }
    }
    let mut fx = 0.0f64;
    let mut fv = 0.0f64;
    for i in 0..3 {
        fx = fx.max((outcome.final_state.positions[i] - r.x[i]).abs());
        fv = fv.max((outcome.final_state.velocities[i] - r.v[i]).abs());
    }
    println!(
        "two harmonics vs RK4: {} impacts, max |Δt| = {dt:.3e} s, max |Δx| = {dx:.3e} m; final |Δx| = {fx:.3e} m, |Δv| = {fv:.3e} m/s",
        engine.len()
    );
    assert!(dt < 1e-9 && dx < 1e-9, "{dt} {dx}");
    assert!(fx < 1e-8 && fv < 1e-8, "{fx} {fv}");
}

// ---------------------------------------------------------------------------------------
// (e) Refusals name their reason.
// ---------------------------------------------------------------------------------------

const TWO: &str = "[excitation]\nkind = \"multisine\"\nharmonics = [{amplitude = 0.05, ratio = 1}, {amplitude = 0.01, ratio = 2}]\n";

#[test]
fn stops_moving_with_the_base_are_refused_under_other_base_motion() {
    let text = format!(
        "{TWO}[oscillator]\nmasses = [0.05]\nstiffness = 120.0\ndamping = 0.05\n[oscillator.stops.upper]\ngap = 0.01\nrestitution = 0.8\nframe = \"base\"\n"
    );
    let c = Config::from_toml_str(&text).unwrap();
    let e = c.check_runnable().unwrap_err().to_string();
    assert!(e.contains("frame = \"base\"") && e.contains("multisine"), "{e}");
    // The library refuses it too, with the same reason.
    let err = simulate(&c.run_spec(true), &mut ()).unwrap_err();
    assert!(
        matches!(
            &err,
            StudyError::BaseMotion(BaseMotionError::MovingStops { kind: "multisine" })
        ),
        "{err}"
    );
    // Fixed stops are fine.
    let fixed = Config::from_toml_str(&text.replace("frame = \"base\"", "frame = \"fixed\"")).unwrap();
    fixed.check_runnable().unwrap();
    simulate(&fixed.run_spec(true), &mut ()).unwrap();
}

#[test]
fn periodic_tools_are_refused_under_non_periodic_input() {
    let c = Config::from_toml_str(TWO).unwrap();
    let e = c.check_periodic("periodic orbits").unwrap_err().to_string();
    assert!(
        e.contains("periodic orbits") && e.contains("periodic with the reference period"),
        "{e}"
    );
    let spec = c.run_spec(true);
    let base = spec.base_motion.as_ref();
    for (options, what) in [
        (
            PointOptions {
                floquet: true,
                ..PointOptions::default()
            },
            "Floquet",
        ),
        (
            PointOptions {
                lyapunov: Some(Default::default()),
                ..PointOptions::default()
            },
            "Lyapunov",
        ),
    ] {
        let e = run_point_driven(
            c.chain(),
            &ChainState::at_rest(3),
            c.sim_options(),
            None,
            &options,
            base,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains(what) && e.contains("periodic"), "{e}");
    }
    // A plain point runs, with no period claimed.
    let options = PointOptions {
        transient_periods: 4,
        recorded_periods: 6,
        ..PointOptions::default()
    };
    let r = run_point_driven(
        c.chain(),
        &ChainState::at_rest(3),
        c.sim_options(),
        None,
        &options,
        base,
    )
    .unwrap();
    assert!(r.periodicity.is_none());
    assert_eq!(r.strobe.len(), 3 * 6);
}

#[test]
fn a_signal_shorter_than_the_run_is_refused() {
    let dir = scratch("short");
    let body: String = (0..=100)
        .map(|k| format!("{},{}\n", k as f64 * 0.01, 0.001 * (k as f64 * 0.3).sin()))
        .collect();
    std::fs::write(dir.join("short.csv"), format!("time_s,displacement_m\n{body}")).unwrap();
    std::fs::write(
        dir.join("run.toml"),
        "[excitation]\nkind = \"record\"\nfile = \"short.csv\"\nquantity = \"displacement\"\n[run]\nperiods = 10\n",
    )
    .unwrap();
    // The configuration refuses it when read, naming the key and both durations.
    let e = Config::from_path(&dir.join("run.toml")).unwrap_err().to_string();
    assert!(
        e.contains("excitation.file") && e.contains("shorter than the run"),
        "{e}"
    );
    // A run of the library longer than the signal is refused too.
    let text = std::fs::read_to_string(dir.join("run.toml")).unwrap();
    std::fs::write(dir.join("run.toml"), text.replace("periods = 10", "periods = 5")).unwrap();
    let c = Config::from_path(&dir.join("run.toml")).unwrap();
    c.check_runnable().unwrap();
    let spec = RunSpec {
        periods: 10,
        ..c.run_spec(true)
    };
    let err = simulate(&spec, &mut ()).unwrap_err().to_string();
    assert!(err.contains("ends at t = 1 s, before the run's end"), "{err}");
}

/// `run.start_relative_to_base`: the initial state is the base's y(0), y'(0) plus the given
/// offsets — for a random signal (y from its spline, evaluated here independently of the
/// configuration's state) and for the sine (y(0) = 0, y'(0) = Aω in closed form) — and a
/// state that would then lie beyond a rigid stop is refused, naming the key.
#[test]
fn a_run_can_start_at_rest_relative_to_the_base() {
    let random = "[excitation]\nkind = \"random\"\nrms_acceleration = 20.0\nf_low_hz = 2.0\nf_high_hz = 12.0\nseed = 3\n\
                  [run]\nperiods = 10\nstart_relative_to_base = true\ninitial_positions = [0.001, 0.0, -0.002]\n";
    let c = Config::from_toml_str(random).unwrap();
    let [y0, v0, _] = c.base_motion().unwrap().evaluate(0.0);
    assert!(
        y0.abs() > 1e-4 && v0.abs() > 1e-3,
        "a signal that does not start at rest: {y0} {v0}"
    );
    let s = c.initial_state();
    for (i, dx) in [0.001, 0.0, -0.002].iter().enumerate() {
        assert_eq!(s.positions[i], y0 + dx);
        assert_eq!(s.velocities[i], v0);
    }
    let absolute = Config::from_toml_str(&random.replace("start_relative_to_base = true\n", "")).unwrap();
    assert_eq!(absolute.initial_state().positions, vec![0.001, 0.0, -0.002]);
    let sine = Config::from_toml_str("[run]\nstart_relative_to_base = true\n").unwrap();
    let chain = sine.chain();
    let aw = chain.excitation.amplitude * chain.omega();
    assert_eq!(sine.initial_state().positions, vec![0.0; 3]);
    assert_eq!(sine.initial_state().velocities, vec![aw; 3]);
    // A fixed stop at half the base's y(0) on its side (above m1 for y(0) > 0, below m3
    // otherwise): the start at rest is valid, the start shifted by y(0) lies beyond it.
    let side = if y0 > 0.0 { "upper" } else { "lower" };
    let stop = format!(
        "[oscillator.stops.{side}]\ngap = {:e}\nrestitution = 0.8\n",
        y0.abs() / 2.0
    );
    let shifted = format!(
        "{stop}{}",
        random.replace("initial_positions = [0.001, 0.0, -0.002]\n", "")
    );
    let e = Config::from_toml_str(&shifted).unwrap_err().to_string();
    assert!(
        e.contains("run.start_relative_to_base") && e.contains("stop"),
        "{e}"
    );
    Config::from_toml_str(&shifted.replace("start_relative_to_base = true\n", "")).unwrap();
}
