//! [`BaseDrive`]: drives the exact mechanics with a base motion other than the chain's own
//! `y = A sin ωt`.
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
//! harmonics (a multisine, and the random-phase multisine behind a random signal) runs on
//! piecewise polynomials of degree 7 ([`HarmonicPieces`]: Chebyshev interpolants of the
//! displacement and of the velocity, with stated remainder bounds): about 8 intervals per
//! cycle of the fastest harmonic where a cubic spline within the same error needs ~1500, and
//! every interval end restarts the event search. A multisine's displacement error is at most
//! [`multisine_tolerance`]; a random signal's is `spline_tolerance` times its RMS displacement, built
//! once with the configuration ([`BaseMotion::Pieces`]); a multisine's are built per run.
// A closed-form multisine in the engine (one particular solution per harmonic, no intervals
// at all) would remove the remaining interpolation error; it is not implemented.

use std::borrow::Cow;
use std::sync::Arc;

use super::settings::RunSpec;
use super::simulate::StudyError;
use crate::dynamics::{Observer, RunEnd, Simulator};
use crate::error::SimError;
use crate::excitation::{BaseMotion, Harmonic, HarmonicPieces, PiecewiseCubic, SplineMotion};
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

/// A base displacement the drive runs on, shared (cheap to clone): the cubic of a
/// [`BaseMotion::Spline`] (chirps, records), or piecewise polynomials of a sum of harmonics
/// (a random signal's, or those a multisine is interpolated into for the run).
#[derive(Debug, Clone)]
pub struct BaseDisplacement(Source);

#[derive(Debug, Clone)]
enum Source {
    /// A [`BaseMotion::Spline`] (no other variant), run on its cubic.
    Cubic(Arc<BaseMotion>),
    /// A sum of harmonics as piecewise polynomials.
    Pieces(Arc<HarmonicPieces>),
}

/// What a [`BaseDisplacement`] runs on, borrowed.
enum Piecewise<'a> {
    Cubic(&'a PiecewiseCubic),
    Pieces(&'a HarmonicPieces),
}

impl BaseDisplacement {
    fn view(&self) -> Piecewise<'_> {
        match &self.0 {
            Source::Cubic(b) => match &**b {
                BaseMotion::Spline(s) => Piecewise::Cubic(&s.displacement),
                _ => unreachable!("Source::Cubic holds a spline"),
            },
            Source::Pieces(p) => Piecewise::Pieces(p),
        }
    }

    /// The piecewise cubic, m, when the drive runs on one.
    pub fn cubic(&self) -> Option<&PiecewiseCubic> {
        match self.view() {
            Piecewise::Cubic(c) => Some(c),
            Piecewise::Pieces(_) => None,
        }
    }

    /// The piecewise polynomials, when the drive runs on them.
    pub fn pieces(&self) -> Option<&HarmonicPieces> {
        match self.view() {
            Piecewise::Pieces(p) => Some(p),
            Piecewise::Cubic(_) => None,
        }
    }

    /// The base displacement at `t` (s), m.
    pub fn displacement(&self, t: f64) -> f64 {
        match self.view() {
            Piecewise::Cubic(c) => c.displacement(t),
            Piecewise::Pieces(p) => p.evaluate(t)[0],
        }
    }

    /// The interval ends, s.
    fn knots(&self) -> &[f64] {
        match self.view() {
            Piecewise::Cubic(c) => c.knots(),
            Piecewise::Pieces(p) => p.knots(),
        }
    }

    /// The interval holding `t` (s).
    fn interval(&self, t: f64) -> usize {
        match self.view() {
            Piecewise::Cubic(c) => c.interval(t),
            Piecewise::Pieces(p) => p.interval(t),
        }
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
        BaseMotion::Spline(_) | BaseMotion::Pieces(_) => 0.0,
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
                let p = HarmonicPieces::new(h, end.max(spec.chain.period()), multisine_tolerance(h))
                    .map_err(|e| fail(format!("multisine: {e}")))?;
                Source::Pieces(Arc::new(p))
            }
            BaseMotion::Pieces(p) => {
                if end > p.pieces.end() * (1.0 + 1e-12) {
                    return Err(fail(format!(
                        "the base motion ends at t = {} s, before the run's end at {} s",
                        p.pieces.end(),
                        end
                    )));
                }
                Source::Pieces(p.pieces.clone())
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
                Source::Cubic(base.clone())
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
            let i = s.motion.interval(sim.time());
            if s.current != Some(i) {
                s.set(i);
                sim.set_external_forces(&s.forces)?;
                s.current = Some(i);
            }
            let knots = s.motion.knots();
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
    /// The forces `k_i y + c_i y'` of interval `i`, N, as polynomials in `t − knot_i` (a
    /// cubic) or `t − t_mid` (pieces).
    fn set(&mut self, i: usize) {
        if let Some(p) = self.motion.pieces() {
            let (mid, y, v) = p.piece(i);
            for (m, f) in self.forces.iter_mut().enumerate() {
                let (k, c) = (self.stiffness[m], self.damping[m]);
                f.t_ref = mid;
                f.coefficients.clear();
                f.coefficients.extend(y.iter().zip(v).map(|(y, v)| k * y + c * v));
            }
            return;
        }
        let cubic = self.motion.cubic().expect("a drive runs on a cubic or on pieces");
        let (t0, [c0, c1, c2, c3]) = cubic.piece(i);
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
