//! Certified search for the first zero of an event function.
//!
//! The search is *conservative advancement*: at the current time `t` the event function `f`
//! is bounded below by Taylor polynomials with a remainder built from the derivative bounds of
//! [`Jet`]:
//!
//! ```text
//! p₁(h) = f + f'h − B₂h²/2
//! p₂(h) = f + f'h + f''h²/2 − B₃h³/6
//! p₃(h) = f + f'h + f''h²/2 + f'''h³/6 − B₄h⁴/24
//! ```
//!
//! Each is ≤ f(t+h) for all h ≥ 0, so `f` has no zero before the first positive root of any of
//! them; the search steps to the largest of those roots and repeats. A zero can therefore
//! never be skipped, including a tangential (grazing) touch, and near a simple zero the steps
//! converge like a fourth-order Newton method from the safe side (p₃ is solved at every step;
//! p₂ and p₁ only where they can lengthen it). The last point is polished onto the zero with
//! the local Taylor model: at a jet on the zero, or, when the certified step ends within the
//! range where the quartic model is exact far below rounding, from the jet before it
//! ([`root_within_model`]), which saves the last evaluation of a search.
//!
//! The bounds' first positive roots come from [`super::polyroot`]. Several contacts' searches
//! are raced by time through [`Search`] (see `search.rs`).

use super::polyroot::{bracket_root, first_positive_root, horner, positive_roots};
use super::signal::{Jet, Signal};

/// Outcome of a search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Found {
    /// The first zero (or touch) at this time, s.
    Root(f64),
    /// No zero before the horizon.
    Clear,
}

/// The search could not separate a zero from the current time within the iteration limit.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stall {
    pub t: f64,
}

/// Iterations allowed per search before it is declared stalled.
const MAX_ITERATIONS: usize = 100_000;

/// Inflation of the derivative bounds against their own rounding.
const BOUND_SAFETY: f64 = 1.0 + 1e-9;

/// How far below the rounding noise the quartic model's truncation must stay for
/// [`root_within_model`] to place a zero from it: the noise allowance is 32 ulps of the summed
/// magnitudes, the rounding of a direct evaluation about one; 1024 keeps the model's error
/// below that.
const MODEL_MARGIN: f64 = 1024.0;

/// First zero of the function described by `eval` in `[t_start, horizon)`.
///
/// At `t_start` a function at zero (within rounding) that is leaving zero (as right after an
/// impact or a release) is not a root; one that is entering zero is.
pub(crate) fn first_root<F>(mut eval: F, t_start: f64, horizon: f64) -> Result<Found, Stall>
where
    F: FnMut(f64) -> Jet,
{
    let mut search = Search::new(t_start);
    loop {
        if let Some(found) = search.advance(&mut eval, horizon)? {
            return Ok(found);
        }
    }
}

/// One certified search, advanced an iteration at a time, so that the searches of several
/// event functions can be interleaved by time (the simulator advances the one furthest
/// behind, and none goes past the earliest zero found so far).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Search {
    /// Every time before this is certified free of zeros, s.
    t: f64,
    /// Whether no step has been taken yet (a touch at the start is not a zero).
    first: bool,
    iterations: usize,
}

impl Search {
    /// A search from `t_start`, s.
    pub(crate) fn new(t_start: f64) -> Self {
        Search {
            t: t_start,
            first: true,
            iterations: 0,
        }
    }

    /// The time the search has reached, s: no zero before it.
    pub(crate) fn time(&self) -> f64 {
        self.t
    }

    /// One iteration of [`first_root`] against `horizon` (which may shrink from one call to
    /// the next): `Some` when the search has ended, with a zero or clear of `horizon`.
    pub(crate) fn advance<F>(&mut self, eval: &mut F, horizon: f64) -> Result<Option<Found>, Stall>
    where
        F: FnMut(f64) -> Jet,
    {
        let t = self.t;
        if t >= horizon {
            return Ok(Some(Found::Clear));
        }
        self.iterations += 1;
        if self.iterations > MAX_ITERATIONS {
            return Err(Stall { t });
        }
        let mut jet = eval(t);
        clamp_noise(&mut jet);
        if jet.d[0] <= jet.noise[0] {
            match local_behaviour(&jet) {
                Local::Entering(h) => return Ok(Some(Found::Root(t + h))),
                // The function came down to zero within rounding without crossing: a touch.
                Local::Touch(h) if !self.first => return Ok(Some(Found::Root(t + h))),
                _ => {}
            }
        }
        let step = safe_step(&jet);
        let next = t + step;
        if next >= horizon {
            return Ok(Some(Found::Clear));
        }
        if next <= t {
            // The lower bounds admit no progress: the zero is within an ulp or two of t.
            return Ok(Some(Found::Root(match local_behaviour(&jet) {
                Local::Entering(h) => t + h,
                _ => t,
            })));
        }
        if let Some(h) = root_within_model(&jet, step) {
            return Ok(Some(Found::Root(t + h)));
        }
        self.t = next;
        self.first = false;
        Ok(None)
    }
}

/// One contact's search in the simulator's race of searches (`search.rs`).
#[derive(Debug, Clone, Copy)]
pub(super) struct Racer {
    /// The contact whose event function this is.
    pub(super) contact: usize,
    /// Its gap (open) or contact force (closed).
    pub(super) signal: Signal,
    /// The harmonic part's amplitude ([`Signal::harmonic_amplitude`]).
    pub(super) amp: f64,
    /// Where the search started, s (a zero there is an impact at the start).
    pub(super) start: f64,
    /// The search's progress.
    pub(super) search: Search,
    /// What its zero is: an impact for a gap, a release for a force.
    pub(super) gap: bool,
}

/// The first zero, from the jet at t, when the certified step ends where the local quartic
/// model `m(h) = f + f'h + f''h²/2 + f'''h³/6 + f⁗h⁴/24` is accurate far below the rounding
/// noise (`B₅h⁵/120 ≤ noise/MODEL_MARGIN`) and the model crosses zero there: what the next
/// iteration would find from a jet evaluated on the zero, without evaluating that jet.
///
/// `f` has no zero before `step` (certified), and on `[step, h_loc]` `|f − m|` is far below
/// the rounding of a direct evaluation. If `m` descends on `[step, h_loc]` (its slope at `step`
/// plus the largest change of slope over the range stays negative) and ends below `−noise`
/// (so `f` is negative there), the first zero of `f` lies in between and is the model's zero,
/// to the precision [`local_behaviour`] finds it with at a jet on the zero. Anything else (a
/// touch, a shallow dip, a model that may turn back up, a signal with a polynomial part) is
/// left to the search.
fn root_within_model(jet: &Jet, step: f64) -> Option<f64> {
    let noise = jet.noise[0];
    let b5 = jet.bound5 * BOUND_SAFETY;
    if !(b5 > 0.0 && b5.is_finite()) || jet.d[0] <= noise {
        return None;
    }
    // step < h_loc without a fifth root first: most steps are far longer.
    let reach = 120.0 * noise / (MODEL_MARGIN * b5);
    let within = step * step * step * step * step < reach;
    if !within {
        return None;
    }
    let h_loc = reach.powf(0.2);
    let [f, d1, d2, d3] = jet.d;
    let d4 = jet.d4;
    let m = [f, d1, 0.5 * d2, d3 / 6.0, d4 / 24.0];
    let slope = d1 + step * (d2 + step * (0.5 * d3 + step * d4 / 6.0));
    let curvature = d2.abs() + h_loc * (d3.abs() + 0.5 * h_loc * d4.abs());
    let descends = slope + (h_loc - step) * curvature < 0.0;
    let ends_below = horner(&m, h_loc) < -noise;
    if !(descends && ends_below) {
        return None;
    }
    Some(if horner(&m, step) <= 0.0 {
        step
    } else {
        bracket_root(&m, step, h_loc, false, 1e-12)
    })
}

/// Derivatives smaller than their rounding noise are zero.
fn clamp_noise(jet: &mut Jet) {
    for n in 1..4 {
        if jet.d[n].abs() <= jet.noise[n] {
            jet.d[n] = 0.0;
        }
    }
}

/// What a function at zero (within rounding) does next.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Local {
    /// It crosses into negative values beyond rounding; the crossing is h ahead.
    Entering(f64),
    /// It comes closest to zero h ahead and turns back up without a real crossing.
    Touch(f64),
    /// It moves away from zero.
    Leaving,
}

/// Decides, for `f` at zero within rounding, what it does next, from the local cubic Taylor
/// model `m(h) = f + f'h + f''h²/2 + f'''h³/6` on the range `h ≤ h_loc` where the model is
/// accurate to the rounding noise (`B₄h⁴/24 ≤ noise`).
///
/// It enters negative values if it is descending at h = 0⁺ (first nonzero derivative
/// negative) and its first descending piece reaches below `−noise`: a dip shallower than
/// rounding (as right after a release, where f'' is at rounding level and f''' > 0 takes over
/// at once) is not a crossing. A function rising at 0⁺ is leaving, whatever it does later:
/// a later zero (the next bounce) is for the certified stepping to find.
fn local_behaviour(jet: &Jet) -> Local {
    let noise = jet.noise[0];
    let [f, d1, d2, d3] = jet.d;
    let lead = [d1, d2, d3].into_iter().find(|&x| x != 0.0).unwrap_or(0.0);
    if lead >= 0.0 {
        return Local::Leaving;
    }
    let m = [f, d1, 0.5 * d2, d3 / 6.0];
    let b4 = jet.bound[4] * BOUND_SAFETY;
    let h_loc = if b4 > 0.0 {
        (24.0 * noise.max(f64::MIN_POSITIVE) / b4).powf(0.25)
    } else {
        f64::INFINITY
    };
    // End of the first descending piece: the first critical point of m, or the model's range.
    let mut points = [0.0; 4];
    let found = positive_roots(&[d1, d2, 0.5 * d3], &mut points);
    let first_crit = points[..found].iter().copied().fold(f64::INFINITY, f64::min);
    let h_end = first_crit.min(h_loc);
    let h_end = if h_end.is_finite() { h_end } else { 1.0 };
    let m_end = horner(&m, h_end);
    if m_end < -noise {
        return Local::Entering(if f <= 0.0 {
            0.0
        } else {
            bracket_root(&m, 0.0, h_end, false, 1e-12)
        });
    }
    // A minimum within rounding of zero: a touch there; or still descending over the whole
    // local range, too slowly to leave the rounding band: a touch here.
    Local::Touch(if first_crit < h_loc { first_crit } else { 0.0 })
}

/// The largest step certified free of zeros by the Taylor lower bounds. Above the noise
/// level the step ends where a bound reaches the noise level, not zero, so that a touch
/// (where bound and function reach zero together) is sampled within rounding of zero.
fn safe_step(jet: &Jet) -> f64 {
    let level = if jet.d[0] > jet.noise[0] {
        jet.noise[0]
    } else {
        0.0
    };
    let f = (jet.d[0] - level).max(0.0);
    let [_, d1, d2, d3] = jet.d;
    let b = jet.bound.map(|x| x * BOUND_SAFETY);
    let p1 = [f, d1, -0.5 * b[2]];
    let p2 = [f, d1, 0.5 * d2, -b[3] / 6.0];
    // The quartic bound goes first: it gives the longest step nearly always (higher order
    // near a zero, and the only progress at zero with vanishing slope and curvature, as after
    // a release). The others are solved only where they could lengthen the step; the result
    // is the largest of the three roots, as if each had been solved.
    // p3 − p2 = (f''' + B₃)h³/6 − B₄h⁴/24 ≥ 0 for h ≤ 4(f''' + B₃)/B₄: there p2 ≤ p3, so p2
    // reaches zero no later than p3 and cannot lengthen a step shorter than that.
    let mut step = first_positive_root(&[f, d1, 0.5 * d2, d3 / 6.0, -b[4] / 24.0]);
    if step == 0.0 || (b[4] * step >= 4.0 * (d3 + b[3]) && horner(&p2, step) > 0.0) {
        step = step.max(first_positive_root(&p2));
    }
    // A bound that is already ≤ 0 at the step found so far has its first root before it and
    // cannot lengthen the step (a root is returned at or below the true one): skip its solve.
    if step == 0.0 || horner(&p1, step) > 0.0 {
        step = step.max(first_positive_root(&p1));
    }
    step
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn finds_tangent_zero_of_cosine() {
        // f(t) = 1 + cos t touches zero at t = π without changing sign.
        let eval = |t: f64| Jet {
            d: [1.0 + t.cos(), -t.sin(), -t.cos(), t.sin()],
            bound: [0.0, 1.0, 1.0, 1.0, 1.0],
            noise: [1e-15; 4],
            d4: t.cos(),
            bound5: 1.0,
        };
        match first_root(eval, 0.0, 10.0).unwrap() {
            Found::Root(t) => assert!((t - std::f64::consts::PI).abs() < 1e-6, "{t}"),
            Found::Clear => panic!("tangent zero missed"),
        }
    }

    #[test]
    fn simple_zero_to_machine_precision() {
        // f(t) = cos t − 0.3 from 0: first zero at acos(0.3).
        let eval = |t: f64| Jet {
            d: [t.cos() - 0.3, -t.sin(), -t.cos(), t.sin()],
            bound: [0.0, 1.0, 1.0, 1.0, 1.0],
            noise: [4e-16; 4],
            d4: t.cos(),
            bound5: 1.0,
        };
        let Found::Root(t) = first_root(eval, 0.0, 10.0).unwrap() else {
            panic!("missed")
        };
        assert!((t - 0.3f64.acos()).abs() < 2e-15, "{t}");
    }

    #[test]
    fn zero_placed_from_the_quartic_model_as_precisely() {
        // f(t) = 0.7 cos 3t + 0.2 sin t − 0.1 from 0: the zero is placed from the jet before it
        // (the last jet evaluated is short of it), to the precision of a jet on it. Reference:
        // Newton on f to convergence from the found zero.
        let f = |t: f64| 0.7 * (3.0 * t).cos() + 0.2 * t.sin() - 0.1;
        let last = std::cell::Cell::new(0.0);
        let eval = |t: f64| {
            last.set(t);
            let (s3, c3) = (3.0 * t).sin_cos();
            let (s1, c1) = t.sin_cos();
            Jet {
                d: [
                    f(t),
                    -2.1 * s3 + 0.2 * c1,
                    -6.3 * c3 - 0.2 * s1,
                    18.9 * s3 - 0.2 * c1,
                ],
                bound: [0.0, 2.3, 6.5, 19.1, 56.9],
                noise: [1e-15, 3e-15, 9e-15, 3e-14],
                d4: 56.7 * c3 + 0.2 * s1,
                bound5: 170.3,
            }
        };
        let Found::Root(t) = first_root(eval, 0.0, 10.0).unwrap() else {
            panic!("missed")
        };
        let mut r = t;
        for _ in 0..5 {
            r -= f(r) / (-2.1 * (3.0 * r).sin() + 0.2 * r.cos());
        }
        assert!((t - r).abs() < 4e-15, "{t} against {r}");
        assert!(
            last.get() < t - 1e-9,
            "last jet at {} for the zero at {t}",
            last.get()
        );
    }
}
