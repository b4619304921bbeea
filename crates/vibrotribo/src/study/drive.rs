//! [`BaseDrive`]: drives the exact mechanics with a base motion other than the chain's own
//! `y = A sin ωt` (issue 14).
//!
//! Every spring and damper of mass i is attached to the base (docs/MODEL.md), so a base
//! displacement y(t) acts on mass i as the force `k_i y(t) + c_i y'(t)`. On each interval
//! `[t_j, t_{j+1}]` of a piecewise cubic y this force is a cubic in `t − t_j`, which the
//! engine integrates in closed form ([`Simulator::set_external_forces`]): the run stops at
//! every knot and sets the next interval's forces there, with the chain's own harmonic
//! amplitude set to 0. Events are found as exactly as under the harmonic forcing.
//!
//! A sum of harmonics that is exactly the chain's harmonic (one harmonic at the reference
//! frequency, phase 0) runs as the harmonic run itself, bit for bit. Any other sum of
//! harmonics is sampled into a clamped spline ([`harmonics_to_spline`]) with displacement
//! error at most [`multisine_tolerance`] (stated in the outputs).
// TODO(issue 14): a closed-form multisine in the engine (one particular solution per
// harmonic) would remove the spline's error for multisines; this is a later step.

use std::borrow::Cow;
use std::sync::Arc;

use super::settings::RunSpec;
use super::simulate::StudyError;
use crate::dynamics::{Observer, RunEnd, Simulator};
use crate::error::SimError;
use crate::excitation::{BaseMotion, Harmonic, PiecewiseCubic, SplineMotion, harmonics_to_spline};
use crate::model::{ChainParams, ForcePolynomial, StopFrame};

/// Bound on the displacement error of the spline a multisine is sampled into, relative to
/// Σ|A_j| (dimensionless).
pub const MULTISINE_RELATIVE_TOLERANCE: f64 = 1e-10;

/// The bound on the displacement error (m) of the spline the sum `harmonics` is sampled into
/// when it is not the chain's own harmonic: [`MULTISINE_RELATIVE_TOLERANCE`] × Σ|A_j|.
pub fn multisine_tolerance(harmonics: &[Harmonic]) -> f64 {
    MULTISINE_RELATIVE_TOLERANCE * harmonics.iter().map(|h| h.amplitude.abs()).sum::<f64>()
}

/// Whether `harmonics` is exactly the harmonic excitation of `chain` at some amplitude:
/// one harmonic at the chain's ω (bit for bit) with phase 0. Returns that amplitude, m.
pub fn as_chain_harmonic(harmonics: &[Harmonic], chain: &ChainParams) -> Option<f64> {
    match harmonics {
        [h] if h.omega == chain.omega() && h.phase == 0.0 => Some(h.amplitude),
        _ => None,
    }
}

/// Why `base` cannot drive `chain`, if it cannot: rigid stops that move with the base
/// follow the chain's harmonic `A sin ωt`, not another base motion.
pub fn check_base_motion(chain: &ChainParams, base: &BaseMotion) -> Result<(), String> {
    if let BaseMotion::Harmonics(h) = base
        && as_chain_harmonic(h, chain).is_some()
    {
        return Ok(());
    }
    let moving = [chain.stops.upper, chain.stops.lower]
        .iter()
        .flatten()
        .any(|s| s.frame == StopFrame::Base);
    if moving {
        return Err(
            "rigid stops with frame = \"base\" move as the harmonic A sin ωt: they cannot \
                    follow a non-harmonic base motion (use frame = \"fixed\", or kind = \"harmonic\")"
                .into(),
        );
    }
    Ok(())
}

/// How a run is driven: the chain's own harmonic, or a spline's interval forces.
#[derive(Debug, Clone)]
pub struct BaseDrive {
    spline: Option<Spline>,
}

/// A base displacement given as a piecewise cubic, shared (cheap to clone): the one of a
/// [`BaseMotion::Spline`], or the spline a multisine was sampled into.
#[derive(Debug, Clone)]
pub struct BaseDisplacement(Source);

#[derive(Debug, Clone)]
enum Source {
    /// A [`BaseMotion::Spline`] (never [`BaseMotion::Harmonics`]).
    Given(Arc<BaseMotion>),
    Sampled(Arc<PiecewiseCubic>),
}

impl BaseDisplacement {
    /// The piecewise cubic, m.
    pub fn cubic(&self) -> &PiecewiseCubic {
        match &self.0 {
            Source::Given(b) => match &**b {
                BaseMotion::Spline(s) => &s.displacement,
                BaseMotion::Harmonics(_) => unreachable!("a harmonic base motion is sampled first"),
            },
            Source::Sampled(p) => p,
        }
    }

    /// The base displacement at `t` (s), m.
    pub fn displacement(&self, t: f64) -> f64 {
        self.cubic().displacement(t)
    }
}

/// The chain a run of `spec` simulates: the spec's own; with its harmonic amplitude set to
/// that of a one-harmonic multisine that is exactly the chain's harmonic; with amplitude 0
/// under any other base motion (which [`BaseDrive`] applies as external forces).
pub fn driven_chain(spec: &RunSpec) -> Cow<'_, ChainParams> {
    let Some(base) = &spec.base_motion else {
        return Cow::Borrowed(&spec.chain);
    };
    let mut chain = spec.chain.clone();
    chain.excitation.amplitude = match &**base {
        BaseMotion::Harmonics(h) => as_chain_harmonic(h, &spec.chain).unwrap_or(0.0),
        BaseMotion::Spline(_) => 0.0,
    };
    Cow::Owned(chain)
}

#[derive(Debug, Clone)]
struct Spline {
    motion: BaseDisplacement,
    stiffness: Vec<f64>,
    damping: Vec<f64>,
    /// The interval whose forces are set (`None`: none yet).
    current: Option<usize>,
    forces: Vec<ForcePolynomial>,
}

impl BaseDrive {
    /// The drive of `spec` over `[0, spec.periods·T]` and the chain to simulate (the spec's
    /// own, or with its harmonic amplitude set to the one-harmonic multisine's, or to 0 under
    /// a spline). An error if the base motion cannot drive the chain or ends before the run.
    pub fn new(spec: &RunSpec) -> Result<(Cow<'_, ChainParams>, BaseDrive), StudyError> {
        let harmonic = BaseDrive { spline: None };
        let Some(base) = &spec.base_motion else {
            return Ok((Cow::Borrowed(&spec.chain), harmonic));
        };
        let fail = |m: String| StudyError::BaseMotion(m);
        check_base_motion(&spec.chain, base).map_err(fail)?;
        let end = spec.periods as f64 * spec.chain.period();
        let chain = driven_chain(spec);
        let spline = match &**base {
            BaseMotion::Harmonics(h) => {
                if as_chain_harmonic(h, &spec.chain).is_some() {
                    return Ok((chain, harmonic));
                }
                let (s, _) = harmonics_to_spline(h, end.max(spec.chain.period()), multisine_tolerance(h))
                    .map_err(|e| fail(format!("multisine: {e}")))?;
                Source::Sampled(Arc::new(s))
            }
            BaseMotion::Spline(SplineMotion { displacement, .. }) => {
                // A relative slack of 1e-12 for the rounding of periods·T.
                if end > displacement.end() * (1.0 + 1e-12) {
                    return Err(fail(format!(
                        "the base motion ends at t = {} s, before the run's end at {} s ({} periods of {} s)",
                        displacement.end(),
                        end,
                        spec.periods,
                        spec.chain.period()
                    )));
                }
                Source::Given(base.clone())
            }
        };
        let n = chain.len();
        let drive = BaseDrive {
            spline: Some(Spline {
                motion: BaseDisplacement(spline),
                stiffness: chain.stiffness.clone(),
                damping: chain.damping.clone(),
                current: None,
                forces: vec![ForcePolynomial::zero(); n],
            }),
        };
        Ok((chain, drive))
    }

    /// The base displacement at `t` (s), m, if it is not the chain's harmonic.
    pub fn base_at(&self, t: f64) -> Option<f64> {
        self.spline.as_ref().map(|s| s.motion.displacement(t))
    }

    /// The base displacement this drive follows, if it is not the chain's harmonic (m).
    pub fn spline(&self) -> Option<&BaseDisplacement> {
        self.spline.as_ref().map(|s| &s.motion)
    }

    /// Advances `sim` to `t_end` (s) as [`Simulator::run_until`] does, stopping at every knot
    /// of the spline to set the next interval's forces.
    pub fn run_until<O: Observer + ?Sized>(
        &mut self,
        sim: &mut Simulator,
        t_end: f64,
        observer: &mut O,
    ) -> Result<RunEnd, SimError> {
        let Some(s) = &mut self.spline else {
            return sim.run_until(t_end, observer);
        };
        loop {
            let i = s.motion.cubic().interval(sim.time());
            if s.current != Some(i) {
                s.set(i);
                sim.set_external_forces(&s.forces)?;
                s.current = Some(i);
            }
            let knots = s.motion.cubic().knots();
            let stop = if i + 2 < knots.len() {
                knots[i + 1].min(t_end)
            } else {
                t_end
            };
            match sim.run_until(stop, observer)? {
                RunEnd::Reached if stop < t_end => {}
                end => return Ok(end),
            }
        }
    }
}

impl Spline {
    /// The forces `k_i y + c_i y'` of interval `i`, N, as polynomials in `t − knot_i`.
    fn set(&mut self, i: usize) {
        let (t0, [c0, c1, c2, c3]) = self.motion.cubic().piece(i);
        for (m, f) in self.forces.iter_mut().enumerate() {
            let (k, c) = (self.stiffness[m], self.damping[m]);
            f.t_ref = t0;
            f.coefficients.clear();
            f.coefficients.extend_from_slice(&[
                k * c0 + c * c1,
                k * c1 + 2.0 * c * c2,
                k * c2 + 3.0 * c * c3,
                k * c3,
            ]);
        }
    }
}
