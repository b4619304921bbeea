//! A run asked to stop while a chatter sequence is being jumped over (between the impact that
//! starts the jump and its accumulation time) stops there, and going on from there gives the
//! events of the uninterrupted run. The event search must not return the accumulation point
//! when it lies beyond the requested end.

use vibrotribo::{ChainParams, ChainState, EventKind, EventLog, SimOptions, Simulator};

#[test]
fn a_stop_inside_a_chatter_jump_is_honoured() {
    let params = ChainParams::paper_chatter_case();
    let start = ChainState::at_rest(params.len());
    let t_end = 20.0 * params.period();
    let mut whole = EventLog::default();
    let mut sim = Simulator::new(&params, &start, SimOptions::default()).unwrap();
    sim.run_until(t_end, &mut whole).unwrap();
    // Stop points: halfway between the event before each chatter event and that event (the
    // jump's open interval), for the first few chatter events.
    let events = &whole.events;
    let stops: Vec<f64> = events
        .windows(2)
        .filter(|w| w[1].event.kind == EventKind::Chatter && w[1].event.time > w[0].event.time)
        .map(|w| 0.5 * (w[0].event.time + w[1].event.time))
        .take(5)
        .collect();
    assert!(!stops.is_empty(), "no chatter in the chatter case");
    for &stop in &stops {
        let mut log = EventLog::default();
        let mut sim = Simulator::new(&params, &start, SimOptions::default()).unwrap();
        sim.run_until(stop, &mut log).unwrap();
        assert_eq!(sim.time(), stop, "the run did not stop at {stop} s");
        assert!(
            log.events.iter().all(|e| e.event.time <= stop),
            "events past the stop at {stop} s"
        );
        sim.run_until(t_end, &mut log).unwrap();
        assert_eq!(log.events.len(), events.len(), "stop at {stop} s: event count");
        for (a, b) in log.events.iter().zip(events) {
            assert_eq!(a.event.kind, b.event.kind, "stop at {stop} s");
            assert!(
                (a.event.time - b.event.time).abs() < 1e-9,
                "stop at {stop} s: {} against {}",
                a.event.time,
                b.event.time
            );
        }
    }
}
