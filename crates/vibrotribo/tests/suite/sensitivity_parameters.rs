//! The parameter derivative of the flow map against two exact symmetries of the chain, which
//! tie it to the state-transition matrix Φ without any finite difference of Φ itself:
//!
//! - **Lengths**: scaling the amplitude, the gaps and the state by λ scales the whole
//!   motion by λ (impacts included), so `∂z(t)/∂λ + Φ z₀ = z(t)` for the family
//!   (A, δ) → (λA, λδ) at fixed z₀.
//! - **Time**: masses m/λ², damping c/λ (stiffness fixed, so ω = Ω√(k₁/m₁) grows by λ at
//!   fixed Ω) make `x̃(t) = x(λt)`: after P periods the positions are the same and the
//!   velocities λ times larger when the initial velocities are λ times larger, so
//!   `∂z/∂λ + Φ (0, v₀) = (0, v(PT))`.

use crate::common;

use common::{Lcg, random_chain};
use nalgebra::DVector;
use vibrotribo::sensitivity::{
    DerivativeOptions, Horizon, SensitivityError, SensitivityOptions, flow_map, length_scale,
    parameter_derivative, speed_scale, state_vector,
};
use vibrotribo::{ChainParams, ChainState, SimOptions};

/// Checks one identity `derivative = want` in units of the state scales.
fn check(what: &str, params: &ChainParams, got: &DVector<f64>, want: &DVector<f64>, error: f64) -> f64 {
    let n = params.len();
    let (l, v) = (length_scale(params), speed_scale(params));
    let scaled = |z: &DVector<f64>| DVector::from_fn(2 * n, |i, _| z[i] / if i < n { l } else { v });
    let err = (scaled(got) - scaled(want)).amax();
    let tol = 1e-7 + 3.0 * error / l.min(v);
    assert!(
        err <= tol,
        "{what}: derivative {got} against {want}: error {err:e} > {tol:e}"
    );
    err
}

fn symmetries(
    params: &ChainParams,
    state: &ChainState,
    horizon: Horizon,
) -> Result<(f64, f64), SensitivityError> {
    let map = flow_map(
        params,
        state,
        horizon,
        &SimOptions::default(),
        &SensitivityOptions::default(),
    )?;
    let n = params.len();
    let z0 = state_vector(state);
    let z1 = state_vector(&map.state);
    let options = DerivativeOptions::default();

    let lengths = |lambda: f64| {
        let mut p = params.clone();
        p.excitation.amplitude *= lambda;
        p.gaps.iter_mut().for_each(|g| *g *= lambda);
        p
    };
    let d = parameter_derivative(lengths, 1.0, state, horizon, &options)?;
    let want = &z1 - &map.stm * &z0;
    let e1 = check("lengths", params, &d.derivative, &want, d.error);

    let time = |lambda: f64| {
        let mut p = params.clone();
        p.masses.iter_mut().for_each(|m| *m /= lambda * lambda);
        p.damping.iter_mut().for_each(|c| *c /= lambda);
        p
    };
    let d = parameter_derivative(time, 1.0, state, horizon, &options)?;
    let mut v0 = z0.clone();
    let mut v1 = z1.clone();
    for i in 0..n {
        v0[i] = 0.0;
        v1[i] = 0.0;
    }
    let want = v1 - &map.stm * v0;
    let e2 = check("time", params, &d.derivative, &want, d.error);
    Ok((e1, e2))
}

#[test]
fn parameter_derivatives_obey_the_length_and_time_symmetries() {
    let mut cases = vec![
        (
            ChainParams::default(),
            ChainState::at_rest(3),
            Horizon::Periods(3),
        ),
        (
            ChainParams::paper_chatter_case(),
            ChainState::at_rest(3),
            Horizon::Periods(1),
        ),
    ];
    let mut rng = Lcg(2024);
    for s in 0..12 {
        let (params, state) = random_chain(&mut rng, 2 + s % 4, 0.6);
        cases.push((params, state, Horizon::Periods(1 + (s % 2) as u32)));
    }
    let (mut worst, mut checked, mut skipped) = (0.0f64, 0, 0);
    for (c, (params, state, horizon)) in cases.iter().enumerate() {
        match symmetries(params, state, *horizon) {
            Ok((e1, e2)) => {
                worst = worst.max(e1).max(e2);
                checked += 1;
            }
            Err(SensitivityError::NonSmooth(_) | SensitivityError::SequenceChange { .. }) => skipped += 1,
            Err(e) => panic!("case {c}: {e}"),
        }
    }
    println!("{checked} cases checked (largest scaled error {worst:.2e}), {skipped} not differentiable");
    assert!(checked >= 10, "{checked} cases checked");
}
