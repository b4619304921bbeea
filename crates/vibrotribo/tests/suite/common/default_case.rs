//! The paper's default case as the continuation tests use it: its chain at a frequency ratio,
//! the stable period-1 orbit at Ω = 0.7 a transient from rest settles on, and the size of a
//! state deviation in the scales of the chain.

use nalgebra::DVector;
use vibrotribo::orbits::{
    BifurcationKind, Branch, PeriodicOrbit, ShootingOptions, periodic_orbit_from_transient,
};
use vibrotribo::sensitivity::{length_scale, speed_scale};
use vibrotribo::{ChainParams, ChainState, Frequency};

/// The default chain at the frequency ratio `omega`.
pub fn chain(omega: f64) -> ChainParams {
    let mut p = ChainParams::default();
    p.excitation.frequency = Frequency::OmegaRatio(omega);
    p
}

/// The period-1 orbit at Ω = 0.7, after 300 periods from rest.
pub fn start_orbit() -> PeriodicOrbit {
    periodic_orbit_from_transient(
        &chain(0.7),
        &ChainState::at_rest(3),
        300,
        Some(1),
        &ShootingOptions::default(),
    )
    .expect("the default case's period-1 orbit at Ω = 0.7")
}

/// The size of a state deviation, positions over the length scale and velocities over the
/// speed scale.
pub fn size(params: &ChainParams, d: &DVector<f64>) -> f64 {
    let n = d.len() / 2;
    let (lx, lv) = (length_scale(params), speed_scale(params));
    (0..d.len())
        .map(|i| d[i] / if i < n { lx } else { lv })
        .map(|x| x * x)
        .sum::<f64>()
        .sqrt()
}

/// The branches born at a branch point of the first branch (its pitchfork's two branches).
pub fn pitchfork_branches(branches: &[Branch]) -> Vec<usize> {
    (0..branches.len())
        .filter(|&i| {
            branches[i].parent.is_some_and(|(b, k)| {
                b == 0 && matches!(branches[0].bifurcations[k].kind, BifurcationKind::BranchPoint)
            })
        })
        .collect()
}
