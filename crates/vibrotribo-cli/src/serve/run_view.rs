//! The run view: one run of a configuration through the library's run layer, as
//! `vibrotribo simulate` runs it (the sampled run with the air-breakdown check, the motion
//! classified after the transient), with its summary (the same object as `summary.json`)
//! and the samples and events the page plots.

use std::ops::ControlFlow;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use vibrotribo::study::{Ending, RunMotion, RunObserver, Sample, SettleMode, simulate};
use vibrotribo::{Event, StateView};

use super::cancel::Ticket;
use super::error::ApiError;
use super::request::{Overrides, configure};
use vibrotribo::config::Config;

/// Most samples a run view sends (a longer run is sent at every k-th sample).
pub const MAX_SAMPLES: u64 = 4000;

/// Most events a run view sends (the count of all of them is in the summary).
pub const MAX_EVENTS: usize = 20_000;

/// `POST /api/run`: the overrides of the run.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunRequest {
    /// The overrides of the server's configuration.
    #[serde(default)]
    pub set: Overrides,
    /// The client's sequence number of this request (see [`super::cancel`]).
    #[serde(default)]
    pub seq: Option<u64>,
}

/// The samples of a run (every `stride`-th sample of its grid, and its last): time, s; positions x_i, m;
/// velocities, m/s; gaps d_k, m; base displacement y, m; load voltage V, V; and the power
/// delivered to the load V·I, W (empty without a harvester).
#[derive(Debug, Default, Serialize)]
pub struct Samples {
    /// Every how many samples of the run's grid one is kept.
    pub stride: u64,
    /// Time, s.
    pub t: Vec<f64>,
    /// Positions x_i, m, one array per mass.
    pub x: Vec<Vec<f64>>,
    /// Velocities, m/s, one array per mass.
    pub v: Vec<Vec<f64>>,
    /// Gaps d_k, m, one array per gap.
    pub gaps: Vec<Vec<f64>>,
    /// Base displacement y, m.
    pub base: Vec<f64>,
    /// Load voltage V, V (NaN as null where the charge is not solved).
    pub voltage: Vec<Option<f64>>,
    /// Power into the load V·I, W.
    pub power: Vec<Option<f64>>,
}

/// The events of a run (at most [`MAX_EVENTS`]).
#[derive(Debug, Default, Serialize)]
pub struct Events {
    /// Time, s.
    pub t: Vec<f64>,
    /// Kind (`impact`, `stick`, `release`, …).
    pub kind: Vec<&'static str>,
    /// Contact, 1-based.
    pub contact: Vec<usize>,
    /// Whether more events happened than are listed.
    pub truncated: bool,
}

/// What `POST /api/run` answers.
#[derive(Debug, Serialize)]
pub struct RunView {
    /// The run's summary: the object `simulate --out` writes as `summary.json`.
    pub summary: vibrotribo::report::RunSummary,
    /// The average power after the transient, W (`summary.average_power_w`).
    pub average_power_w: Option<f64>,
    /// The samples.
    pub samples: Samples,
    /// The events.
    pub events: Events,
}

/// Records the samples and events of a run and stops it when its ticket is stopped.
struct Recorder {
    samples: Samples,
    /// Index of the grid's last sample (always kept, so the samples reach the run's end).
    last: u64,
    events: Events,
    ticket: Ticket,
}

impl RunObserver for Recorder {
    fn wants_samples(&self) -> bool {
        true
    }

    fn sample(&mut self, s: &Sample<'_>) {
        if !s.index.is_multiple_of(self.samples.stride) && s.index != self.last {
            return;
        }
        let d = &mut self.samples;
        d.t.push(s.time);
        for (column, &x) in d.x.iter_mut().zip(s.positions) {
            column.push(x);
        }
        for (column, &v) in d.v.iter_mut().zip(s.velocities) {
            column.push(v);
        }
        for (column, &g) in d.gaps.iter_mut().zip(s.gaps) {
            column.push(g);
        }
        d.base.push(s.base);
        let finite = |x: f64| x.is_finite().then_some(x);
        d.voltage.push(s.electrical.and_then(|e| finite(e.voltage_v)));
        d.power
            .push(s.electrical.and_then(|e| finite(e.voltage_v * e.current_a)));
    }

    fn event(&mut self, e: &Event, _state: &StateView<'_>) {
        if self.events.t.len() >= MAX_EVENTS {
            self.events.truncated = true;
            return;
        }
        self.events.t.push(e.time);
        self.events.kind.push(e.kind.as_str());
        self.events.contact.push(e.contact + 1);
    }

    fn period(&mut self, _periods: u64, _state: &StateView<'_>) -> ControlFlow<()> {
        if self.ticket.stopped() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// Runs the configuration of `request` on `base` as `vibrotribo simulate` does; stops (409)
/// when `ticket` is stopped.
pub fn run_view(base: &Config, request: &RunRequest, ticket: Ticket) -> Result<RunView, ApiError> {
    if ticket.stopped() {
        return Err(ApiError::superseded());
    }
    let config = configure(base, &request.set)?;
    let mut spec = config.sampled_run_spec(false);
    spec.breakdown_check = true;
    crate::simulate::check_size(&config, &spec, false, false).map_err(|e| ApiError::bad_chain(&e))?;
    let n = spec.chain.len();
    let grid = spec.periods.saturating_mul(config.run().samples_per_period) + 1;
    let mut recorder = Recorder {
        samples: Samples {
            stride: grid.div_ceil(MAX_SAMPLES).max(1),
            x: vec![Vec::new(); n],
            v: vec![Vec::new(); n],
            gaps: vec![Vec::new(); n.saturating_sub(1)],
            ..Samples::default()
        },
        last: grid - 1,
        events: Events::default(),
        ticket,
    };
    let started = Instant::now();
    let mut run_motion = RunMotion::new(&spec).map_err(ApiError::bad)?;
    run_motion.options_mut().settle = SettleMode::Fixed;
    let outcome = simulate(&spec, &mut (&mut recorder, run_motion.observer())).map_err(ApiError::failed)?;
    if outcome.ending == Ending::Stopped {
        return Err(ApiError::superseded());
    }
    let motion = (outcome.ending == Ending::Completed && config.is_periodic())
        .then(|| run_motion.finish(&spec, &outcome.final_state, None));
    let elapsed = started.elapsed().as_secs_f64();
    let mut summary = vibrotribo::report::RunSummary::new(&config, &spec, &outcome, elapsed);
    summary.set_motion(motion.as_ref());
    let average_power_w = outcome
        .electrical
        .as_ref()
        .and_then(|e| e.power.as_ref())
        .map(|p| p.average_power_w);
    Ok(RunView {
        summary,
        average_power_w,
        samples: recorder.samples,
        events: recorder.events,
    })
}
