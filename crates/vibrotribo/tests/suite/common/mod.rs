//! Test helpers: an independent integrator of the chain's equations of motion (Dop853 from
//! `ode_solvers`, not the closed form under test) and reference-data loading.
#![allow(dead_code)]

pub mod balance;
pub mod base_motion;
pub mod default_case;
pub mod electrostatics;
pub mod fd;
pub mod impact_oscillator;
pub mod quadrature;

use ode_solvers::{DVector, Dop853, OutputType, System};
use vibrotribo::{ChainParams, ChainState, Excitation, Frequency};

/// What an event did to masses `m` whose velocities went from `before` to `after`: the change
/// of momentum relative to the summed |m v| before and after (≈ 0 for an exchange inside the
/// chain), and the gain of kinetic energy relative to Σ m v² before (≤ 0 for an impact or a
/// stick).
pub fn event_jumps(m: &[f64], before: &[f64], after: &[f64]) -> (f64, f64) {
    let momentum = |v: &[f64]| m.iter().zip(v).map(|(m, v)| m * v).sum::<f64>();
    let energy = |v: &[f64]| m.iter().zip(v).map(|(m, v)| 0.5 * m * v * v).sum::<f64>();
    let size = |v: &[f64]| m.iter().zip(v).map(|(m, v)| (m * v).abs()).sum::<f64>();
    let p_scale = size(before).max(size(after)) + f64::MIN_POSITIVE;
    let dp = (momentum(after) - momentum(before)).abs() / p_scale;
    let e0 = energy(before);
    let de = (energy(after) - e0) / (2.0 * e0 + f64::MIN_POSITIVE);
    (dp, de)
}

/// The equations of motion of a chain partitioned into clusters (each a contiguous range of
/// masses moving as one body), integrated numerically. State: [s_c, v_c] per cluster, where
/// s_c is the position of the cluster's top mass.
#[derive(Clone)]
pub struct ClusterOde {
    pub masses: Vec<f64>,
    pub damping: Vec<f64>,
    pub stiffness: Vec<f64>,
    /// Constant force F0 = −Σ k_i o_i per cluster, N.
    pub force: Vec<f64>,
    pub amplitude: f64,
    pub omega: f64,
}

impl ClusterOde {
    pub fn new(params: &ChainParams, clusters: &[(usize, usize)]) -> Self {
        let mut ode = ClusterOde {
            masses: vec![],
            damping: vec![],
            stiffness: vec![],
            force: vec![],
            amplitude: params.excitation.amplitude,
            omega: params.omega(),
        };
        for &(first, last) in clusters {
            let mut offset = 0.0;
            let (mut m, mut c, mut k, mut f) = (0.0, 0.0, 0.0, 0.0);
            for i in first..=last {
                if i > first {
                    offset += params.gaps[i - 1];
                }
                m += params.masses[i];
                c += params.damping[i];
                k += params.stiffness[i];
                f -= params.stiffness[i] * offset;
            }
            ode.masses.push(m);
            ode.damping.push(c);
            ode.stiffness.push(k);
            ode.force.push(f);
        }
        ode
    }
}

/// The system is integrated in autonomous form, with time as the last state component:
/// ode_solvers 0.6.2's DOP853 tableau has c₁₂ = 0 where the method needs c₁₂ = 1, so it
/// evaluates its last stage at the wrong time for non-autonomous systems (measured here: 5e-7
/// error at rtol 1e-11 on a forced oscillator, with collapsing steps). With t as a state,
/// stage times follow from the (correct) a-coefficients.
impl System<f64, DVector<f64>> for ClusterOde {
    fn system(&self, _t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) {
        let t = y[y.len() - 1];
        dy[y.len() - 1] = 1.0;
        let yb = self.amplitude * (self.omega * t).sin();
        let ybd = self.amplitude * self.omega * (self.omega * t).cos();
        for c in 0..self.masses.len() {
            let s = y[2 * c];
            let v = y[2 * c + 1];
            dy[2 * c] = v;
            dy[2 * c + 1] = (-self.damping[c] * (v - ybd) - self.stiffness[c] * (s - yb) + self.force[c])
                / self.masses[c];
        }
    }
}

/// Integrates `ode` from `t0` with state `y0` and returns the states on the grid t0, t0+dx,
/// ..., t1 (t1 always included).
///
/// ode_solvers 0.6's dense output extrapolates its last point past the current step (and can
/// spin), so the grid is produced by chaining integrations with sparse output, each of which
/// ends exactly at its `x_end`.
///
/// Any system in the same autonomous form (time as the last state component, appended here)
/// can be integrated: [`ClusterOde`], or the coupled equations of tests/suite/coupling_events.rs.
pub fn integrate<O: System<f64, DVector<f64>> + Clone>(
    ode: O,
    t0: f64,
    t1: f64,
    dx: f64,
    y0: &[f64],
) -> (Vec<f64>, Vec<Vec<f64>>) {
    let steps = ((t1 - t0) / dx).round().max(1.0) as usize;
    let dx = (t1 - t0) / steps as f64;
    let mut xs = vec![t0];
    let mut ys = vec![y0.to_vec()];
    for k in 1..=steps {
        let ta = *xs.last().unwrap();
        let tb = if k == steps { t1 } else { t0 + k as f64 * dx };
        let y = integrate_segment(ode.clone(), ta, tb, ys.last().unwrap());
        xs.push(tb);
        ys.push(y);
    }
    (xs, ys)
}

fn integrate_segment<O: System<f64, DVector<f64>>>(ode: O, ta: f64, tb: f64, y0: &[f64]) -> Vec<f64> {
    // Stiffness detection off: these problems are not stiff and the heuristic misfires at
    // this tolerance.
    let mut state = y0.to_vec();
    state.push(ta);
    let mut stepper = Dop853::from_param(
        ode,
        ta,
        tb,
        0.0,
        DVector::from_vec(state),
        1e-13,
        1e-15,
        0.9,
        0.0,
        0.333,
        6.0,
        tb - ta,
        0.0,
        10_000_000,
        u32::MAX,
        OutputType::Sparse,
    );
    stepper.integrate().expect("Dop853 failed");
    let x_last = *stepper.x_out().last().unwrap();
    assert!(
        (x_last - tb).abs() <= 1e-12 * tb.abs().max(1.0),
        "integrator ended at {x_last}, not {tb}"
    );
    let y = stepper.y_out().last().unwrap();
    y.iter().take(y.len() - 1).copied().collect()
}

/// State at `t1` only.
pub fn integrate_to<O: System<f64, DVector<f64>>>(ode: O, t0: f64, t1: f64, y0: &[f64]) -> Vec<f64> {
    integrate_segment(ode, t0, t1, y0)
}

/// Directory of the reference data of the paper's default case (`tests/data/reference/`; see its README).
pub fn reference_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/reference")
}

/// Reads a CSV file of numbers with one header line.
pub fn read_csv(path: &std::path::Path) -> Vec<Vec<f64>> {
    let text =
        std::fs::read_to_string(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    text.lines()
        .skip(1)
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            l.trim()
                .split(',')
                .map(|x| x.trim().parse::<f64>().expect("number"))
                .collect()
        })
        .collect()
}

/// Energy statistics per period of the charge solver replaying `traj` (a run of `chain`) for
/// the harvester `params` at relative tolerance `rtol`.
pub fn period_stats(
    chain: &ChainParams,
    traj: &vibrotribo::Trajectory,
    params: &vibrotribo::electrical::HarvesterParams,
    rtol: f64,
) -> Vec<vibrotribo::electrical::PeriodStats> {
    use vibrotribo::electrical::{ChargeOptions, ChargeSolver};
    let options = ChargeOptions {
        rtol,
        ..ChargeOptions::default()
    };
    let mut s = ChargeSolver::for_chain(params, chain, options).unwrap();
    s.run_trajectory(traj).unwrap();
    s.periods().to_vec()
}

/// A fixed-seed generator (64-bit LCG, Knuth's constants), uniform in [0, 1).
pub struct Lcg(pub u64);

impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
}

/// A random chain of `n` masses (30–200 g, 80–200 N/m, up to 0.05 N s/m, gaps 3–20 mm,
/// A = 20–80 mm, Ω = 0.3–1.2) with restitution `mu`, and a random admissible state
/// (neighbours up to half a gap apart beyond contact, speeds up to 0.3 of the speed scale).
pub fn random_chain(rng: &mut Lcg, n: usize, mu: f64) -> (ChainParams, vibrotribo::ChainState) {
    use vibrotribo::{ChainState, Excitation, Frequency};
    let params = ChainParams {
        masses: (0..n).map(|_| rng.range(0.03, 0.2)).collect(),
        stiffness: (0..n).map(|_| rng.range(80.0, 200.0)).collect(),
        damping: (0..n).map(|_| rng.range(0.0, 0.05)).collect(),
        gaps: (0..n - 1).map(|_| rng.range(0.003, 0.02)).collect(),
        restitution: mu,
        excitation: Excitation {
            amplitude: rng.range(0.02, 0.08),
            frequency: Frequency::OmegaRatio(rng.range(0.3, 1.2)),
        },
        stops: Default::default(),
        forces: Vec::new(),
    };
    let v = vibrotribo::sensitivity::speed_scale(&params);
    let mut x = vec![0.0; n];
    for i in 1..n {
        x[i] = x[i - 1] + rng.range(-0.5, 0.9) * params.gaps[i - 1];
    }
    let state = ChainState {
        positions: x,
        velocities: (0..n).map(|_| rng.range(-0.3, 0.3) * v).collect(),
    };
    (params, state)
}

/// Asserts that `e` is the first contact of a grazing pair at its closed-form time
/// `t_expected`, s, and closing speed `v_expected`, m/s, for an overlap `eps` ≥ 0 of the gap:
/// an exact graze (ε = 0, a double root, which rounding noise η in the gap moves by
/// √(2η/d'') ~ 1e-9 s) within 1e-7 s and slower than 1e-6 m/s; a crossing within
/// 1e-12 s + 1e-14/v and 1e-6 of its speed.
pub fn assert_grazing_contact(e: &vibrotribo::Event, eps: f64, t_expected: f64, v_expected: f64) {
    assert_eq!(e.kind, vibrotribo::EventKind::Impact);
    if eps == 0.0 {
        assert!(
            (e.time - t_expected).abs() < 1e-7,
            "graze at {} expected {t_expected}",
            e.time
        );
        assert!(e.velocity_before < 1e-6, "grazing speed {}", e.velocity_before);
    } else {
        assert!(
            (e.time - t_expected).abs() < 1e-12 + 1e-14 / v_expected,
            "ε = {eps}: t = {} expected {t_expected}",
            e.time
        );
        assert!(
            (e.velocity_before - v_expected).abs() < 1e-6 * v_expected,
            "ε = {eps}: v = {} expected {v_expected}",
            e.velocity_before
        );
    }
}

/// Two undamped masses with equal k/m: the base motion cancels in the relative coordinate
/// r = x2 − x1, which is exactly r(t) = R sin(ω_n t). With R = δ(1 + ε) the gap δ − r first
/// reaches zero at asin(1/(1+ε))/ω_n, with closing speed δ ω_n √((1+ε)² − 1).
pub fn grazing_pair(eps: f64) -> (ChainParams, ChainState, f64) {
    let (m1, m2, k1): (f64, f64, f64) = (0.05, 0.15, 120.0);
    let wn = (k1 / m1).sqrt();
    let delta = 0.02;
    let params = ChainParams {
        masses: vec![m1, m2],
        stiffness: vec![k1, k1 * m2 / m1],
        damping: vec![0.0, 0.0],
        gaps: vec![delta],
        restitution: 0.6,
        excitation: Excitation {
            amplitude: 0.05,
            frequency: Frequency::OmegaRatio(0.37),
        },
        stops: Default::default(),
        forces: Vec::new(),
    };
    let initial = ChainState {
        positions: vec![0.0, 0.0],
        velocities: vec![0.0, delta * (1.0 + eps) * wn],
    };
    (params, initial, wn)
}

/// Four masses that stick and release (tests/suite/events_vs_bruteforce.rs): 40–90 g, gaps 4–8 mm,
/// μ = 0.3, A = 50 mm, Ω = 0.55.
pub fn four_mass_stack() -> ChainParams {
    ChainParams {
        masses: vec![0.04, 0.09, 0.07, 0.05],
        stiffness: vec![150.0, 100.0, 130.0, 90.0],
        damping: vec![0.03, 0.01, 0.02, 0.04],
        gaps: vec![0.006, 0.004, 0.008],
        restitution: 0.3,
        excitation: Excitation {
            amplitude: 0.05,
            frequency: Frequency::OmegaRatio(0.55),
        },
        stops: Default::default(),
        forces: Vec::new(),
    }
}
