//! Where the flow map is not differentiable: grazing and simultaneous impacts are reported
//! as such, and near grazing Φ stays exact but grows like 1/(closing speed), which finite
//! differences confirm only with steps below the distance to grazing.

use crate::common;

use std::f64::consts::PI;

use common::grazing_pair;

use vibrotribo::sensitivity::{
    Horizon, NonSmoothPoint, SensitivityError, SensitivityOptions, flow_map, state_from_vector, state_vector,
};
use vibrotribo::{ChainParams, ChainState, Excitation, Frequency, SimOptions, Simulator};

fn map(
    params: &ChainParams,
    state: &ChainState,
    t: f64,
) -> Result<vibrotribo::sensitivity::FlowMap, SensitivityError> {
    flow_map(
        params,
        state,
        Horizon::Time(t),
        &SimOptions::default(),
        &SensitivityOptions::default(),
    )
}

#[test]
fn an_exact_graze_is_reported() {
    let (params, initial, wn) = grazing_pair(0.0);
    match map(&params, &initial, 0.9 * PI / wn) {
        Err(SensitivityError::NonSmooth(NonSmoothPoint::Grazing { time, contact, speed })) => {
            assert_eq!(contact, 0);
            assert!((time - 0.5 * PI / wn).abs() < 1e-7, "graze at {time}");
            assert!(speed < 1e-6, "speed {speed}");
        }
        other => panic!("expected a grazing point, got {other:?}"),
    }
}

#[test]
fn near_grazing_the_stm_grows_like_the_inverse_closing_speed() {
    // Closing speeds v = δω_n√(2ε + ε²) from 1.4e-2 to 1.4e-3 m/s. The position row of the
    // upper mass after the impact carries (1+μ)·(mass ratio)·(gap rate)/v: |Φ|·v tends to a
    // constant. Central differences agree with Φ when the step moves the closing speed by
    // little (h ≪ ε δ), and not when the step is comparable with the distance to grazing.
    let mut products = Vec::new();
    for eps in [1e-4, 1e-5, 1e-6] {
        let (params, initial, wn) = grazing_pair(eps);
        let t1 = 0.9 * PI / wn;
        let m = map(&params, &initial, t1).unwrap();
        assert_eq!(m.events.len(), 1);
        let v = m.events[0].velocity_before;
        let expected = params.gaps[0] * wn * ((1.0 + eps).powi(2) - 1.0).sqrt();
        assert!((v - expected).abs() < 1e-6 * expected, "{v} vs {expected}");
        products.push(m.stm.amax() * v);
        // Step in v2 (column 3) relative to the distance to grazing in speed, ε δ ω_n.
        let distance = eps * params.gaps[0] * wn;
        let z0 = state_vector(&initial);
        let column = |h: f64| {
            let end = |s: f64| {
                let mut z = z0.clone();
                z[3] += s;
                let mut sim =
                    Simulator::new(&params, &state_from_vector(z.as_slice()), SimOptions::default()).unwrap();
                sim.run_until(t1, &mut ()).unwrap();
                state_vector(&sim.state())
            };
            (end(h) - end(-h)) / (2.0 * h)
        };
        let exact = m.stm.column(3).into_owned();
        let small = (column(1e-4 * distance) - &exact).amax() / exact.amax();
        let large = (column(0.5 * distance) - &exact).amax() / exact.amax();
        println!(
            "ε = {eps:e}: v = {v:.3e} m/s, |Φ| = {:.3e}, |Φ|·v = {:.4}, differences with h = 1e-4·distance: {small:.2e}, h = distance/2: {large:.2e}",
            m.stm.amax(),
            products.last().unwrap()
        );
        assert!(small < 1e-5, "ε = {eps}: small steps disagree by {small:e}");
        assert!(
            large > 1e-2,
            "ε = {eps}: a step half the distance to grazing should not be in the linear range ({large:e})"
        );
    }
    let spread = products.iter().fold(0.0f64, |a, p| a.max(*p))
        / products.iter().fold(f64::INFINITY, |a, p| a.min(*p));
    assert!(spread < 1.1, "|Φ|·v is not constant: {products:?}");
}

#[test]
fn simultaneous_impacts_are_reported() {
    // m1 and m3 close on m2 with equal speeds over equal gaps: both contacts at once.
    let params = ChainParams {
        masses: vec![0.1; 3],
        stiffness: vec![1e-9; 3],
        damping: vec![0.0; 3],
        gaps: vec![0.01, 0.01],
        restitution: 1.0,
        excitation: Excitation {
            amplitude: 0.0,
            frequency: Frequency::OmegaRatio(1.0),
        },
        stops: Default::default(),
        forces: Vec::new(),
    };
    let initial = ChainState {
        positions: vec![0.0; 3],
        velocities: vec![-1.0, 0.0, 1.0],
    };
    match map(&params, &initial, 0.0101) {
        Err(SensitivityError::NonSmooth(NonSmoothPoint::Simultaneous { time, contacts })) => {
            assert!((time - 0.01).abs() < 1e-12);
            assert_eq!(contacts, vec![0, 1]);
        }
        other => panic!("expected simultaneous impacts, got {other:?}"),
    }
    // Newton's cradle: m3 strikes m2, which touches m1 at rest (gap 0, open).
    let cradle = ChainParams {
        gaps: vec![0.0, 0.01],
        ..params.clone()
    };
    let initial = ChainState {
        positions: vec![0.0; 3],
        velocities: vec![0.0, 0.0, 1.0],
    };
    match map(&cradle, &initial, 0.011) {
        Err(SensitivityError::NonSmooth(NonSmoothPoint::Simultaneous { contacts, .. })) => {
            assert_eq!(contacts, vec![0, 1]);
        }
        other => panic!("expected simultaneous impacts, got {other:?}"),
    }
    // Off by a hair the two impacts come apart and the map is differentiable again.
    let apart = ChainState {
        positions: vec![0.0; 3],
        velocities: vec![-1.0, 0.0, 1.0 + 1e-3],
    };
    assert!(map(&params, &apart, 0.0101).is_ok());
}
