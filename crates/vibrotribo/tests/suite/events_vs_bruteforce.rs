//! Event location against a brute-force search: from the state at the start of every
//! interval of flow, an independent integrator (Dop853) is sampled on a fine grid for gap
//! sign changes, and crossings are refined by bisection. Checks that (a) no open gap goes
//! negative anywhere the simulator saw no event (nothing missed), and (b) every impact the
//! simulator reports is where the brute-force search finds the gap crossing.

use crate::common;

use common::{ClusterOde, integrate, integrate_to};
use vibrotribo::{ChainParams, ChainState, EventKind, EventLog, SimOptions, Simulator, Trajectory};

/// Gap k of the integrator's state `y` (per cluster: top position, velocity).
fn gap(params: &ChainParams, clusters: &[(usize, usize)], y: &[f64], k: usize) -> f64 {
    let pos = |i: usize| {
        let c = clusters.iter().position(|&(f, l)| f <= i && i <= l).unwrap();
        let offset: f64 = params.gaps[clusters[c].0..i].iter().sum();
        y[2 * c] + offset
    };
    params.gaps[k] - (pos(k + 1) - pos(k))
}

struct Outcome {
    impacts_checked: usize,
    worst_dt: f64,
    worst_gap: f64,
}

fn check(params: &ChainParams, initial: &ChainState, periods: f64, grid: usize) -> Outcome {
    let mut sim = Simulator::new(params, initial, SimOptions::default()).unwrap();
    let mut traj = Trajectory::new(&sim);
    let mut log = EventLog::default();
    sim.run_until(periods * params.period(), &mut (&mut traj, &mut log))
        .unwrap();
    let n = params.len();
    let (mut x, mut v) = (vec![0.0; n], vec![0.0; n]);
    let mut out = Outcome {
        impacts_checked: 0,
        worst_dt: 0.0,
        worst_gap: 0.0,
    };
    for seg in traj.segments() {
        let clusters: Vec<_> = seg.clusters.iter().map(|c| (c.first, c.last)).collect();
        let open: Vec<usize> = (0..n - 1)
            .filter(|&k| clusters.iter().any(|&(_, l)| l == k))
            .collect();
        let len = seg.t_end - seg.t_start;
        if len <= 0.0 {
            continue;
        }
        traj.state_at(seg.t_start, &mut x, &mut v);
        let y0: Vec<f64> = clusters.iter().flat_map(|&(f, _)| [x[f], v[f]]).collect();
        let ode = ClusterOde::new(params, &clusters);
        // (a) Nothing missed: sample the open gaps on a fine grid up to the interval's end.
        let (ts, ys) = integrate(ode.clone(), seg.t_start, seg.t_end, len / grid as f64, &y0);
        for k in &open {
            for (t, y) in ts.iter().zip(&ys) {
                let g = gap(params, &clusters, y, *k);
                out.worst_gap = out.worst_gap.min(g / params.gaps[*k].max(1e-300));
                assert!(
                    g >= -1e-12 * params.gaps[*k],
                    "gap {} = {g:e} m at t = {t} inside an interval [{}, {}] with no event",
                    k + 1,
                    seg.t_start,
                    seg.t_end
                );
            }
        }
        // (b) Impacts at the interval's end: find the crossing by bisection on the integrator.
        for e in log
            .events
            .iter()
            .filter(|e| e.event.time == seg.t_end && e.event.kind == EventKind::Impact)
        {
            let k = e.event.contact;
            if e.event.velocity_before < 1e-3 || !open.contains(&k) {
                continue; // grazing-slow impacts are ill-conditioned in time; (a) covers them
            }
            let g_at = |t: f64| {
                gap(
                    params,
                    &clusters,
                    &integrate_to(ode.clone(), seg.t_start, t, &y0),
                    k,
                )
            };
            // Bracket: the gap is positive a little before the end and negative a little after.
            let h = (len * 1e-3).min(1e-5);
            let (mut lo, mut hi) = (seg.t_end - h, seg.t_end + h);
            assert!(
                g_at(lo) > 0.0 && g_at(hi) < 0.0,
                "no crossing of gap {} near {}",
                k + 1,
                seg.t_end
            );
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if g_at(mid) > 0.0 { lo = mid } else { hi = mid }
            }
            let dt = (0.5 * (lo + hi) - seg.t_end).abs();
            out.worst_dt = out.worst_dt.max(dt);
            out.impacts_checked += 1;
            assert!(
                dt < 1e-11,
                "impact at contact {} at t = {}: brute force says {}",
                k + 1,
                seg.t_end,
                lo
            );
        }
    }
    out
}

#[test]
fn default_case() {
    let params = ChainParams::default();
    let out = check(&params, &ChainState::at_rest(3), 15.0, 400);
    println!(
        "default: {} impacts, max |Δt| {:.1e} s, min gap/δ {:.1e}",
        out.impacts_checked, out.worst_dt, out.worst_gap
    );
    assert!(out.impacts_checked > 80);
}

#[test]
fn chatter_case() {
    let params = ChainParams::paper_chatter_case();
    let out = check(&params, &ChainState::at_rest(3), 6.0, 200);
    println!(
        "chatter: {} impacts, max |Δt| {:.1e} s, min gap/δ {:.1e}",
        out.impacts_checked, out.worst_dt, out.worst_gap
    );
    assert!(out.impacts_checked > 50);
}

#[test]
fn four_mass_stack_with_sticking() {
    let params = common::four_mass_stack();
    let out = check(&params, &ChainState::at_rest(4), 8.0, 200);
    println!(
        "4 masses: {} impacts, max |Δt| {:.1e} s, min gap/δ {:.1e}",
        out.impacts_checked, out.worst_dt, out.worst_gap
    );
    assert!(out.impacts_checked > 20);
}
