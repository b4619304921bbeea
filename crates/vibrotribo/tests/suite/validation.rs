//! Bad input gets a clear error that names the problem.

use vibrotribo::{ChainParams, ChainState, Frequency, ParamError, SimError, SimOptions, Simulator};

fn err_of(params: &ChainParams) -> String {
    params.validate().expect_err("should be rejected").to_string()
}

fn with(f: impl FnOnce(&mut ChainParams)) -> ChainParams {
    let mut p = ChainParams::default();
    f(&mut p);
    p
}

#[test]
fn default_parameters_are_valid() {
    assert!(ChainParams::default().validate().is_ok());
    assert!(ChainParams::paper_chatter_case().validate().is_ok());
}

#[test]
fn non_positive_mass() {
    assert_eq!(
        err_of(&with(|p| p.masses[1] = -0.1)),
        "invalid masses[1] = -0.1: must be positive"
    );
    assert_eq!(
        err_of(&with(|p| p.masses[0] = 0.0)),
        "invalid masses[0] = 0: must be positive"
    );
}

#[test]
fn non_positive_stiffness() {
    assert_eq!(
        err_of(&with(|p| p.stiffness[2] = 0.0)),
        "invalid stiffness[2] = 0: must be positive"
    );
}

#[test]
fn negative_damping_or_gap() {
    assert_eq!(
        err_of(&with(|p| p.damping[0] = -0.01)),
        "invalid damping[0] = -0.01: must not be negative"
    );
    assert_eq!(
        err_of(&with(|p| p.gaps[1] = -0.001)),
        "invalid gaps[1] = -0.001: must not be negative"
    );
}

#[test]
fn restitution_outside_unit_interval() {
    assert_eq!(
        err_of(&with(|p| p.restitution = 1.5)),
        "invalid restitution = 1.5: must lie in [0, 1]"
    );
    assert_eq!(
        err_of(&with(|p| p.restitution = -0.1)),
        "invalid restitution = -0.1: must lie in [0, 1]"
    );
}

#[test]
fn nan_and_infinity() {
    assert_eq!(
        err_of(&with(|p| p.excitation.amplitude = f64::NAN)),
        "invalid excitation.amplitude = NaN: must be a finite number"
    );
    assert_eq!(
        err_of(&with(|p| p.masses[2] = f64::INFINITY)),
        "invalid masses[2] = inf: must be a finite number"
    );
    assert_eq!(
        err_of(&with(|p| p.excitation.frequency = Frequency::OmegaRatio(f64::NAN))),
        "invalid excitation.omega_ratio = NaN: must be a finite number"
    );
    assert_eq!(
        err_of(&with(|p| p.excitation.frequency = Frequency::Hertz(-2.0))),
        "invalid excitation.frequency_hz = -2: must be positive"
    );
}

#[test]
fn wrong_array_lengths() {
    assert_eq!(
        err_of(&with(|p| p.stiffness.pop().map(|_| ()).unwrap_or(()))),
        "stiffness has 2 entries, expected 3"
    );
    assert_eq!(
        err_of(&with(|p| p.gaps.push(0.01))),
        "gaps has 3 entries, expected 2"
    );
    assert_eq!(
        err_of(&with(|p| {
            p.masses.truncate(1);
        })),
        "the chain needs at least 2 masses, got 1"
    );
}

#[test]
fn interpenetrating_initial_state() {
    let params = ChainParams::default();
    let state = ChainState {
        positions: vec![0.0, 0.021, 0.0],
        velocities: vec![0.0; 3],
    };
    let err = Simulator::new(&params, &state, SimOptions::default()).unwrap_err();
    assert_eq!(
        err.to_string(),
        "initial positions interpenetrate at contact 1 (between masses 1 and 2): gap = -1.000e-3 m"
    );
    assert!(matches!(
        err,
        SimError::Param(ParamError::Interpenetration { contact: 1, .. })
    ));
    let short = ChainState {
        positions: vec![0.0; 2],
        velocities: vec![0.0; 3],
    };
    assert_eq!(
        Simulator::new(&params, &short, SimOptions::default())
            .unwrap_err()
            .to_string(),
        "positions has 2 entries, expected 3"
    );
    let nan = ChainState {
        positions: vec![0.0; 3],
        velocities: vec![0.0, f64::NAN, 0.0],
    };
    assert_eq!(
        Simulator::new(&params, &nan, SimOptions::default())
            .unwrap_err()
            .to_string(),
        "invalid velocities[1] = NaN: must be a finite number"
    );
}

#[test]
fn bad_options_and_backwards_time() {
    let options = SimOptions {
        max_events_per_period: 0,
        ..SimOptions::default()
    };
    let err = Simulator::new(&ChainParams::default(), &ChainState::at_rest(3), options).unwrap_err();
    assert_eq!(
        err.to_string(),
        "invalid max_events_per_period = 0: must be positive"
    );
    let mut sim = Simulator::new(
        &ChainParams::default(),
        &ChainState::at_rest(3),
        SimOptions::default(),
    )
    .unwrap();
    sim.run_until(0.1, &mut ()).unwrap();
    let err = sim.run_until(0.05, &mut ()).unwrap_err();
    assert!(err.to_string().starts_with("cannot run backwards"), "{err}");
    assert!(sim.run_until(f64::NAN, &mut ()).is_err());
}

#[test]
fn event_limit_stops_a_pathological_run() {
    // A tiny limit must end the run with a clear error, not a hang.
    let options = SimOptions {
        max_events_per_period: 3,
        ..SimOptions::default()
    };
    let params = ChainParams::paper_chatter_case();
    let mut sim = Simulator::new(&params, &ChainState::at_rest(3), options).unwrap();
    let err = sim.run_until(10.0 * params.period(), &mut ()).unwrap_err();
    assert!(matches!(err, SimError::EventLimit { limit: 3, .. }), "{err}");
    assert!(err.to_string().contains("event limit reached"), "{err}");
}
