//! [`lyapunov_spectrum`]: the Lyapunov spectrum of one run, through [`simulate`].

use super::observer::{Mechanics, RunObserver};
use super::settings::RunSpec;
use super::simulate::{RunOutcome, StudyError, simulate};
use crate::lyapunov::{LyapunovError, LyapunovObserver, LyapunovOptions, LyapunovSpectrum};

/// The spectrum of a run and the run's own results.
#[derive(Debug, Clone, PartialEq)]
pub struct LyapunovRun {
    /// The spectrum over the periods after the transient that were simulated (an error if
    /// none could be averaged: too short a run, or every period non-differentiable).
    pub spectrum: Result<LyapunovSpectrum, LyapunovError>,
    /// The run: periods done, how it ended ([`Ending`](super::Ending): an interrupt, a
    /// failure on the way), event statistics, the power with a harvester.
    pub outcome: RunOutcome,
}

/// Runs `spec` through [`simulate`] with a [`LyapunovObserver`] attached from t = 0 and
/// returns the spectrum averaged over the periods after `spec.transient_periods` (the
/// tangent vectors align during the transient; see [`lyapunov`](crate::lyapunov)).
/// `observer` watches the run too and may stop it at a period's end (an interrupt): the
/// spectrum then covers the periods done. A run that fails on the way (an event limit)
/// reports the spectrum of the periods before the failure, and the failure in
/// `outcome.ending`.
///
/// Errors if the parameters or `options` are invalid.
///
/// ```
/// use vibrotribo::lyapunov::LyapunovOptions;
/// use vibrotribo::study::{RunSpec, lyapunov_spectrum};
/// use vibrotribo::ChainParams;
///
/// let mut spec = RunSpec::new(ChainParams::default(), 80);
/// spec.transient_periods = 40;
/// let run = lyapunov_spectrum(&spec, &LyapunovOptions::default(), &mut ())?;
/// let spectrum = run.spectrum?;
/// assert_eq!(spectrum.periods, 40);
/// assert!(spectrum.largest() < 0.0); // the default case settles on a stable orbit
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn lyapunov_spectrum<O: RunObserver + ?Sized>(
    spec: &RunSpec,
    options: &LyapunovOptions,
    observer: &mut O,
) -> Result<LyapunovRun, StudyError> {
    let mut lyap = Mechanics::new(LyapunovObserver::new(
        &spec.chain,
        spec.transient_periods,
        options,
    )?);
    let outcome = simulate(spec, &mut (&mut lyap, observer))?;
    Ok(LyapunovRun {
        spectrum: lyap.inner.finish(),
        outcome,
    })
}
