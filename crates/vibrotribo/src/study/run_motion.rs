//! The motion of one run after its transient ([`RunMotion`]): its stroboscopic samples
//! watched along the run, then classified like a sweep point ([`classify`]). `simulate` in
//! the command line and in Python use it, so both report the same `motion`.

use super::motion::{MotionReport, Window, classify};
use super::observer::Mechanics;
use super::point::PointOptions;
use super::settings::RunSpec;
use super::settle::Settled;
use crate::analysis::{AnalysisError, StroboscopicOptions, StroboscopicSection, detect_period};
use crate::excitation::WorkBudget;
use crate::model::ChainState;

/// Watches a run's stroboscopic samples after its transient (attach [`observer`](Self::observer)
/// to [`simulate`](super::simulate)), then classifies the motion ([`finish`](Self::finish)).
#[derive(Debug)]
pub struct RunMotion {
    strobe: Mechanics<StroboscopicSection>,
    options: PointOptions,
}

impl RunMotion {
    /// For a run of `spec`: the recorded window is the periods after `spec.transient_periods`.
    pub fn new(spec: &RunSpec) -> Result<Self, AnalysisError> {
        let strobe = StroboscopicSection::new(
            spec.chain.len(),
            spec.chain.period(),
            StroboscopicOptions {
                phase_time: 0.0,
                transient_periods: spec.transient_periods + 1,
            },
        )?;
        Ok(RunMotion {
            strobe: Mechanics::new(strobe),
            options: PointOptions {
                transient_periods: spec.transient_periods,
                recorded_periods: spec.periods.saturating_sub(spec.transient_periods).max(1),
                classify: true,
                ..PointOptions::default()
            },
        })
    }

    /// The settings of the classification (the period test's, and the settle mode to
    /// report); change them before the run.
    pub fn options_mut(&mut self) -> &mut PointOptions {
        &mut self.options
    }

    /// The settings of the classification.
    pub fn options(&self) -> &PointOptions {
        &self.options
    }

    /// The observer to attach to the run.
    pub fn observer(&mut self) -> &mut Mechanics<StroboscopicSection> {
        &mut self.strobe
    }

    /// The motion of a run of `spec` that ended in `final_state`, after the settling
    /// `settled` (if the run was settled first); a Lyapunov run it needs is made within the
    /// default budget ([`MAX_CLASSIFY_WORK`](super::MAX_CLASSIFY_WORK), never stopped).
    pub fn finish(
        &self,
        spec: &RunSpec,
        final_state: &ChainState,
        settled: Option<&Settled>,
    ) -> MotionReport {
        self.finish_within(spec, final_state, settled, &WorkBudget::default())
    }

    /// [`finish`](Self::finish) within `budget`: a costlier Lyapunov run is made only if it
    /// allows large jobs, and stops when its flag is set
    /// ([`MotionReport::lyapunov_skipped`](super::MotionReport::lyapunov_skipped) says which).
    pub fn finish_within(
        &self,
        spec: &RunSpec,
        final_state: &ChainState,
        settled: Option<&Settled>,
        budget: &WorkBudget,
    ) -> MotionReport {
        let strobe = &self.strobe.inner;
        let n = spec.chain.len();
        let popts = self.options.period_options();
        let periodicity = (strobe.len() >= popts.samples_needed())
            .then(|| detect_period(&strobe.positions, n, &popts).ok())
            .flatten();
        classify(
            &spec.chain,
            &spec.options,
            &self.options,
            Window {
                positions: &strobe.positions,
                velocities: &strobe.velocities,
                periodicity,
                final_state,
                coupled: spec
                    .harvester
                    .as_ref()
                    .is_some_and(|h| h.params.coupling == crate::coupling::Coupling::TwoWay),
            },
            settled,
            None,
            budget,
        )
    }
}
