//! The base motion the engine runs under ([`BaseMotion`]), and how: the chain's own
//! `y = A sin ωt` through its closed-form harmonic response, any other motion as interval
//! forces ([`Simulator::driven`](super::Simulator::driven)).
//!
//! Every spring and damper of mass i is attached to the base (docs/MODEL.md), so a base
//! displacement y(t) acts on mass i as the force `k_i y(t) + c_i y'(t)`. On each interval
//! `[t_j, t_{j+1}]` of a piecewise cubic y this force is a cubic in `t − t_j`, which the
//! engine integrates in closed form (its polynomial forcing, [`super::forces`]): the run
//! stops at every knot and sets the next interval's forces there, with the chain's own
//! harmonic amplitude set to 0. Events are found as exactly as under the harmonic forcing.
//! These forces are the engine's *base* forces; the forces a caller sets with
//! [`Simulator::set_external_forces`](super::Simulator::set_external_forces) (two-way
//! coupling's electrostatic force) add to them, so every path runs under every base motion.
//!
//! A sum of harmonics that is exactly the chain's harmonic (one harmonic at the reference
//! frequency, phase 0) runs as the harmonic run itself, bit for bit. Any other sum of
//! harmonics (a multisine, and the random-phase multisine behind a random signal) runs on
//! piecewise polynomials of degree 7 ([`HarmonicPieces`]: Chebyshev interpolants of the
//! displacement and of the velocity, with stated remainder bounds): about 8 intervals per
//! cycle of the fastest harmonic where a cubic spline within the same error needs ~1500, and
//! every interval end restarts the event search. A multisine's displacement error is at most
//! [`multisine_tolerance`]; a random signal's is `spline_tolerance` times its RMS
//! displacement, built once with the configuration ([`BaseMotion::Pieces`]); a multisine's
//! are built per run, over its length.
//!
//! Rigid stops with `frame = "base"` move as the chain's harmonic only: under any other
//! motion they are refused ([`BaseMotionError::MovingStops`]).

use std::borrow::Cow;
use std::sync::Arc;

use crate::excitation::{BaseMotion, BaseMotionError, Harmonic, HarmonicPieces, PiecewiseCubic};
use crate::model::{ChainParams, ForcePolynomial, StopFrame};

/// Bound on the displacement error of the pieces a multisine is interpolated into, relative
/// to Σ|A_j| (dimensionless).
pub const MULTISINE_RELATIVE_TOLERANCE: f64 = 1e-10;

/// The bound on the displacement error (m) of the pieces the sum `harmonics` is interpolated
/// into when it is not the chain's own harmonic: [`MULTISINE_RELATIVE_TOLERANCE`] × Σ|A_j|.
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

/// Whether `base` is the chain's own harmonic `A sin ωt` (at some amplitude).
pub fn is_chain_harmonic(base: &BaseMotion, chain: &ChainParams) -> bool {
    matches!(base, BaseMotion::Harmonics(h) if as_chain_harmonic(h, chain).is_some())
}

/// Why `base` cannot drive `chain`, if it cannot: rigid stops that move with the base
/// follow the chain's harmonic `A sin ωt`, not another base motion.
pub fn check_base_motion(chain: &ChainParams, base: &BaseMotion) -> Result<(), BaseMotionError> {
    if is_chain_harmonic(base, chain) {
        return Ok(());
    }
    let moving = [chain.stops.upper, chain.stops.lower]
        .iter()
        .flatten()
        .any(|s| s.frame == StopFrame::Base);
    if moving {
        return Err(BaseMotionError::MovingStops {
            kind: base.kind().as_str(),
        });
    }
    Ok(())
}

/// The chain the engine simulates under `base`: `chain` itself (no base motion: its own
/// harmonic); with its harmonic amplitude set to that of a one-harmonic multisine that is
/// exactly the chain's harmonic; with amplitude 0 under any other base motion (which the
/// engine applies as interval forces).
pub fn driven_chain<'a>(chain: &'a ChainParams, base: Option<&BaseMotion>) -> Cow<'a, ChainParams> {
    let Some(base) = base else {
        return Cow::Borrowed(chain);
    };
    let mut driven = chain.clone();
    driven.excitation.amplitude = match base {
        BaseMotion::Harmonics(h) => as_chain_harmonic(h, chain).unwrap_or(0.0),
        BaseMotion::Spline(_) | BaseMotion::Pieces(_) => 0.0,
    };
    Cow::Owned(driven)
}

/// A base displacement the engine runs on as interval forces, shared (cheap to clone): the
/// cubic of a [`BaseMotion::Spline`] (chirps, records), or piecewise polynomials of a sum of
/// harmonics (a random signal's, or those a multisine is interpolated into for the run).
#[derive(Debug, Clone)]
pub struct BaseDisplacement(Source);

#[derive(Debug, Clone)]
enum Source {
    /// A [`BaseMotion::Spline`]'s cubic (the motion shared, the cubic read from it).
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
                // `Source::Cubic` is only made from a spline (`BaseDrive::new`).
                BaseMotion::Harmonics(_) | BaseMotion::Pieces(_) => {
                    unreachable!("a cubic source holds a spline")
                }
            },
            Source::Pieces(p) => Piecewise::Pieces(p),
        }
    }

    /// The piecewise cubic, m, when the engine runs on one.
    pub fn cubic(&self) -> Option<&PiecewiseCubic> {
        match self.view() {
            Piecewise::Cubic(c) => Some(c),
            Piecewise::Pieces(_) => None,
        }
    }

    /// The piecewise polynomials, when the engine runs on them.
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

/// The interval forces of a base motion other than the chain's harmonic, as the simulator
/// owns them.
#[derive(Debug, Clone)]
pub(crate) struct BaseDrive {
    motion: BaseDisplacement,
    stiffness: Vec<f64>,
    damping: Vec<f64>,
    /// The interval whose forces are set (`None`: none yet).
    current: Option<usize>,
    /// The forces of interval `current`, N, one polynomial per mass.
    forces: Vec<ForcePolynomial>,
}

impl BaseDrive {
    /// The drive of `chain` under `base` over `[0, end]` (s), or `None` under the chain's own
    /// harmonic. An error if `base` cannot drive `chain` or ends before `end`.
    pub fn new(
        chain: &ChainParams,
        base: &Arc<BaseMotion>,
        end: f64,
    ) -> Result<Option<Self>, BaseMotionError> {
        check_base_motion(chain, base)?;
        let kind = base.kind().as_str();
        // A relative slack of 1e-12 for the rounding of periods·T.
        let ends_early = |motion_end: f64| {
            (end > motion_end * (1.0 + 1e-12)).then_some(BaseMotionError::EndsEarly {
                kind,
                end: motion_end,
                run_end: end,
            })
        };
        let source = match &**base {
            BaseMotion::Harmonics(h) => {
                if as_chain_harmonic(h, chain).is_some() {
                    return Ok(None);
                }
                let p = HarmonicPieces::new(h, end.max(chain.period()), multisine_tolerance(h))
                    .map_err(BaseMotionError::Multisine)?;
                Source::Pieces(Arc::new(p))
            }
            BaseMotion::Pieces(p) => {
                if let Some(e) = ends_early(p.pieces.end()) {
                    return Err(e);
                }
                Source::Pieces(p.pieces.clone())
            }
            BaseMotion::Spline(s) => {
                if let Some(e) = ends_early(s.displacement.end()) {
                    return Err(e);
                }
                Source::Cubic(base.clone())
            }
        };
        Ok(Some(BaseDrive {
            motion: BaseDisplacement(source),
            stiffness: chain.stiffness.clone(),
            damping: chain.damping.clone(),
            current: None,
            forces: vec![ForcePolynomial::zero(); chain.len()],
        }))
    }

    /// The base displacement driven.
    pub fn displacement(&self) -> &BaseDisplacement {
        &self.motion
    }

    /// Makes `self` a copy of `other`, reusing its buffers.
    pub fn assign_from(&mut self, other: &BaseDrive) {
        self.motion.clone_from(&other.motion);
        self.stiffness.clone_from(&other.stiffness);
        self.damping.clone_from(&other.damping);
        self.current = other.current;
        self.forces.clone_from(&other.forces);
    }

    /// If the interval holding `t` (s) is not the one whose forces are set: sets its forces
    /// and returns them. With the end of the stretch to run at `t` before the next knot
    /// (`t_end` if that comes first, or the interval is the last).
    pub fn at(&mut self, t: f64, t_end: f64) -> (Option<&[ForcePolynomial]>, f64) {
        let i = self.motion.interval(t);
        let knots = self.motion.knots();
        let stop = if i + 2 < knots.len() {
            knots[i + 1].min(t_end)
        } else {
            t_end
        };
        if self.current == Some(i) {
            return (None, stop);
        }
        self.set(i);
        self.current = Some(i);
        (Some(&self.forces), stop)
    }

    /// The forces `k_i y + c_i y'` of interval `i`, N, as polynomials in `t − knot_i` (a
    /// cubic) or `t − t_mid` (pieces).
    fn set(&mut self, i: usize) {
        match self.motion.view() {
            Piecewise::Pieces(p) => {
                let (mid, y, v) = p.piece(i);
                for (m, f) in self.forces.iter_mut().enumerate() {
                    let (k, c) = (self.stiffness[m], self.damping[m]);
                    f.t_ref = mid;
                    f.coefficients.clear();
                    f.coefficients.extend(y.iter().zip(v).map(|(y, v)| k * y + c * v));
                }
            }
            Piecewise::Cubic(cubic) => {
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
    }
}
