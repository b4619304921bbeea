//! The closed-form flow against an independent high-accuracy integrator (Dop853 at
//! rtol 1e-13), in every damping regime, for free masses and for a stuck cluster.

use crate::common;

use common::{ClusterOde, integrate};
use vibrotribo::{ChainParams, ChainState, Excitation, Frequency, SimOptions, Simulator, Trajectory};

/// Compares the simulator's trajectory with the integrator on a grid; returns the largest
/// position and velocity errors relative to the motion's scale.
fn compare(
    params: &ChainParams,
    initial: &ChainState,
    clusters: &[(usize, usize)],
    periods: f64,
) -> (f64, f64) {
    let mut sim = Simulator::new(params, initial, SimOptions::default()).unwrap();
    let mut traj = Trajectory::new(&sim);
    let t_end = periods * params.period();
    sim.run_until(t_end, &mut traj).unwrap();
    // Every segment must have kept the cluster structure (no events in these set-ups).
    for seg in traj.segments() {
        let got: Vec<_> = seg.clusters.iter().map(|c| (c.first, c.last)).collect();
        assert_eq!(got, clusters, "cluster structure changed at t = {}", seg.t_start);
    }
    let y0: Vec<f64> = clusters
        .iter()
        .flat_map(|&(f, _)| [initial.positions[f], initial.velocities[f]])
        .collect();
    let (ts, ys) = integrate(ClusterOde::new(params, clusters), 0.0, t_end, t_end / 400.0, &y0);
    let n = params.len();
    let (mut x, mut v) = (vec![0.0; n], vec![0.0; n]);
    let (mut ex, mut ev, mut xscale, mut vscale) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for (t, y) in ts.iter().zip(&ys) {
        assert!(traj.state_at(*t, &mut x, &mut v), "t = {t} not recorded");
        for (c, &(first, _)) in clusters.iter().enumerate() {
            ex = ex.max((x[first] - y[2 * c]).abs());
            ev = ev.max((v[first] - y[2 * c + 1]).abs());
            xscale = xscale.max(y[2 * c].abs());
            vscale = vscale.max(y[2 * c + 1].abs());
        }
    }
    (ex / xscale, ev / vscale)
}

fn free_pair(c2: f64) -> ChainParams {
    ChainParams {
        masses: vec![0.048, 0.12],
        stiffness: vec![120.0, 120.0],
        damping: vec![0.02, c2],
        gaps: vec![1e3], // never closes
        restitution: 0.6,
        excitation: Excitation {
            amplitude: 0.08,
            frequency: Frequency::OmegaRatio(0.7),
        },
        stops: Default::default(),
        forces: Vec::new(),
    }
}

#[test]
fn free_masses_in_every_damping_regime() {
    let critical = 2.0 * (0.12f64 * 120.0).sqrt();
    let initial = ChainState {
        positions: vec![0.01, -0.03],
        velocities: vec![-0.5, 0.8],
    };
    for (regime, c2) in [
        ("undamped", 0.0),
        ("under-damped", 0.02),
        ("lightly under-damped", 0.9 * critical),
        ("critically damped", critical),
        ("near-critical over-damped", critical * (1.0 + 1e-9)),
        ("over-damped", 5.0 * critical),
        ("heavily over-damped", 20.0 * critical),
    ] {
        let (ex, ev) = compare(&free_pair(c2), &initial, &[(0, 0), (1, 1)], 5.0);
        println!("{regime:>28}: position error {ex:.2e}, velocity error {ev:.2e} (relative)");
        assert!(ex < 1e-12 && ev < 1e-12, "{regime}: errors {ex:e}, {ev:e}");
    }
}

#[test]
fn stuck_cluster_flow() {
    // Two masses pressed together with no base motion and no relative velocity: the lower,
    // softer mass is pushed up into the stiffer upper one, so they stay stuck for a while.
    let params = ChainParams {
        masses: vec![0.05, 0.15],
        stiffness: vec![240.0, 30.0],
        damping: vec![0.01, 0.03],
        gaps: vec![0.005],
        restitution: 0.6,
        excitation: Excitation {
            amplitude: 0.0,
            frequency: Frequency::OmegaRatio(0.7),
        },
        stops: Default::default(),
        forces: Vec::new(),
    };
    // Contact force N = m1 m2/(m1+m2) (a2 − a1) with a_i = −k_i x_i/m_i: at x1 = 0.01,
    // x2 = 0.015, a1 = −48, a2 = −3 → compressive.
    let initial = ChainState {
        positions: vec![0.01, 0.015],
        velocities: vec![0.0, 0.0],
    };
    let sim = Simulator::new(&params, &initial, SimOptions::default()).unwrap();
    assert_eq!(sim.contact_status(), vec![vibrotribo::ContactStatus::Stuck]);
    // Within the first 4 ms the cluster stays stuck (the force only falls to zero later).
    let t_end = 0.004 / params.period();
    let (ex, ev) = compare(&params, &initial, &[(0, 1)], t_end);
    assert!(ex < 1e-12 && ev < 1e-12, "errors {ex:e}, {ev:e}");
}
