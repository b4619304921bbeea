//! Near resonance a chain rattled at μ = 0.992 in flights about 3e-14 m high, never jumping to
//! the accumulation point, until the event limit (20 001 events in 4.7 ms). The jump is taken
//! once resolving the next bounce cannot time it better than the rounding of the gap; that
//! rounding, like every contact tolerance, was scaled by the size of the displacements
//! (≈ 0.1 m here), while the closed forms sum them from terms a hundred times larger (the top
//! mass is driven at 0.997 of its natural frequency with 0.36 % damping: an 8 m forced
//! amplitude, cancelled by the free motion early on). The tolerances now scale with the size
//! of the terms. Found by a stress variant of `tests/suite/reliability.rs` (zero or light damping,
//! μ up to 1).

use vibrotribo::{
    ChainParams, ChainState, EventKind, EventLog, Excitation, Frequency, SimOptions, Simulator,
};

#[test]
fn rattle_at_rounding_level_jumps_to_its_accumulation_point() {
    let params = ChainParams {
        masses: vec![
            0.12371326993673018,
            0.15036626343438786,
            0.20090016945845796,
            0.03859800491249877,
            0.2247536538327554,
            0.12405418360064392,
        ],
        stiffness: vec![
            60.16342038215732,
            262.79575235907043,
            284.42423079324817,
            244.63939347159192,
            210.92885360480489,
            260.62604459174844,
        ],
        damping: vec![
            0.019594483429268603,
            0.020225552018952868,
            0.033051350759401486,
            0.03387928237516455,
            0.013995396011350093,
            0.021420889725463504,
        ],
        gaps: vec![
            0.0,
            0.002902541448174183,
            0.0011859968585367718,
            0.0006135051084468572,
            0.00031463970298191315,
        ],
        restitution: 0.9919677234379082,
        excitation: Excitation {
            amplitude: 0.07139772183692365,
            frequency: Frequency::OmegaRatio(0.9973142543387674),
        },
        stops: Default::default(),
        forces: Vec::new(),
    };
    // The forced amplitude of the top mass, A·|H| with H = (k + icω)/(k − mω² + icω).
    let (m, k, c, w) = (
        params.masses[0],
        params.stiffness[0],
        params.damping[0],
        params.omega(),
    );
    let forced = params.excitation.amplitude * (k.hypot(c * w) / (k - m * w * w).hypot(c * w));
    println!("forced amplitude of the top mass: {forced:.2} m");
    assert!(forced > 5.0);
    let mut sim = Simulator::new(&params, &ChainState::at_rest(6), SimOptions::default()).unwrap();
    let mut log = EventLog::default();
    sim.run_until(20.0 * params.period(), &mut log)
        .unwrap_or_else(|e| panic!("{e}"));
    let first = log
        .events
        .iter()
        .find(|e| e.event.kind == EventKind::Chatter)
        .expect("no chatter jump");
    println!(
        "{} events in 20 periods; first chatter jump at {:.6e} s after {} bounces",
        log.events.len(),
        first.event.time,
        first.event.sequence_impacts
    );
    // The rattle at the top contact ends with a jump within its first 5 ms.
    assert_eq!(first.event.contact, 0);
    assert!(first.event.time < 5e-3, "first jump at {}", first.event.time);
}
