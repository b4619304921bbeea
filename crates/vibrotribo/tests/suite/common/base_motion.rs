//! The base displacement a test evaluates on its own: the sine, or the spline or piecewise
//! polynomials the engine is driven by, read piece by piece (the signal, not the engine).

use vibrotribo::excitation::{HarmonicPieces, PiecewiseCubic};

/// The base displacement as this test evaluates it.
pub enum Base<'a> {
    /// y = A sin ωt (the chain's own harmonic).
    Sine { amplitude: f64, omega: f64 },
    /// The spline the engine is driven by.
    Spline(&'a PiecewiseCubic),
    /// The piecewise polynomials the engine is driven by (a random signal's harmonics).
    Pieces(&'a HarmonicPieces),
}

impl Base<'_> {
    /// y (m) and y' (m/s) at `t` on the spline's interval `piece` (ignored for a sine).
    pub fn at(&self, t: f64, piece: usize) -> (f64, f64) {
        match self {
            Base::Sine { amplitude, omega } => {
                let (s, c) = (omega * t).sin_cos();
                (amplitude * s, amplitude * omega * c)
            }
            Base::Spline(s) => {
                let (t0, [c0, c1, c2, c3]) = s.piece(piece);
                let x = t - t0;
                (
                    c0 + x * (c1 + x * (c2 + x * c3)),
                    c1 + x * (2.0 * c2 + 3.0 * x * c3),
                )
            }
            Base::Pieces(p) => {
                let (mid, y, v) = p.piece(piece);
                let x = t - mid;
                let horner = |c: &[f64]| c.iter().rev().fold(0.0, |acc, &k| acc * x + k);
                (horner(y), horner(v))
            }
        }
    }

    /// y and y' at `t` (continuous across knots).
    pub fn value(&self, t: f64) -> (f64, f64) {
        match self {
            Base::Sine { .. } => self.at(t, 0),
            Base::Spline(s) => self.at(t, s.interval(t)),
            Base::Pieces(p) => self.at(t, p.interval(t)),
        }
    }

    /// `[a, b]` split at the knots strictly inside it, each part with its spline interval.
    pub fn parts(&self, a: f64, b: f64) -> Vec<(f64, f64, usize)> {
        match self {
            Base::Sine { .. } => vec![(a, b, 0)],
            Base::Spline(_) | Base::Pieces(_) => {
                let (knots, mut i) = match self {
                    Base::Spline(s) => (s.knots(), s.interval(a)),
                    Base::Pieces(p) => (p.knots(), p.interval(a)),
                    Base::Sine { .. } => unreachable!(),
                };
                let mut out = Vec::new();
                let mut from = a;
                while i + 1 < knots.len() - 1 && knots[i + 1] < b {
                    out.push((from, knots[i + 1], i));
                    from = knots[i + 1];
                    i += 1;
                }
                out.push((from, b, i));
                out
            }
        }
    }
}
