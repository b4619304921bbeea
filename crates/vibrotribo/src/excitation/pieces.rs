//! [`HarmonicPieces`]: a sum of harmonics (a multisine, or the random-phase multisine of a
//! random signal) as piecewise polynomials of degree [`PIECE_DEGREE`] for the displacement
//! and for the velocity, each the interpolant at the Chebyshev points of its interval, with
//! the interpolation remainder as a stated bound.
//!
//! The engine takes the base motion as the forces `k_i y + c_i y'` on the masses, one
//! polynomial per interval ([`Simulator::driven`](crate::Simulator::driven)); every interval end
//! restarts the event search, so the fewer the intervals the faster the run. A cubic spline
//! within 1e-10 of a sinusoid needs ~1500 knots per cycle; degree-7 interpolants need about
//! 8, because the remainder of interpolation at the n + 1 = 8 Chebyshev points (roots of
//! T₈) of an interval of length h is at most `2 (h/4)⁸ max|f⁽⁸⁾| / 8!`, and for a sum of
//! harmonics `max|y⁽⁸⁾| ≤ Σ |A_j| ω_j⁸` and `max|y'⁽⁸⁾| ≤ Σ |A_j| ω_j⁹`. The displacement
//! and velocity polynomials are interpolated separately (the velocity's is not the
//! derivative of the displacement's; each is within its own bound), so the force
//! `k y + c y'` is within `k e_y + c e_v` of the exact one.

use std::f64::consts::PI;

use super::budget::{POLL_INTERVALS, WorkBudget};
use super::error::SignalError;
use super::harmonics::{Harmonic, MAX_KNOTS};

/// The degree of the polynomials (8 coefficients an interval).
pub const PIECE_DEGREE: usize = 7;

/// Coefficients of one interval's polynomial in `(t − t_mid)`, lowest degree first.
pub type PieceCoefficients = [f64; PIECE_DEGREE + 1];

/// What the interpolation achieved.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PieceAccuracy {
    /// Interval length h, s.
    pub spacing: f64,
    /// Intervals over the signal.
    pub intervals: usize,
    /// Bound on the displacement error, m.
    pub displacement_bound: f64,
    /// Bound on the velocity error, m/s.
    pub velocity_bound: f64,
}

/// A sum of harmonics on `[0, end]` as piecewise polynomials (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct HarmonicPieces {
    /// Interval ends, s, from 0 to the end, equally spaced.
    knots: Vec<f64>,
    /// Per interval: its middle t_mid (s), the displacement's coefficients (m/s^j) and the
    /// velocity's (m/s^(j+1)) in powers of `t − t_mid`.
    pieces: Vec<(f64, PieceCoefficients, PieceCoefficients)>,
    accuracy: PieceAccuracy,
}

/// `2 (h/4)^(n+1) / (n+1)!` with n = [`PIECE_DEGREE`]: the remainder factor of interpolation
/// at the n + 1 Chebyshev points of an interval of length `h` (s).
fn remainder_factor(h: f64) -> f64 {
    let n1 = (PIECE_DEGREE + 1) as i32;
    let factorial: f64 = (1..=PIECE_DEGREE + 1).map(|k| k as f64).product();
    2.0 * (h / 4.0).powi(n1) / factorial
}

/// Bounds on |y⁽⁸⁾| (m/s⁸) and |y'⁽⁸⁾| (m/s⁹) of the sum of `harmonics`: Σ|A|ω⁸, Σ|A|ω⁹.
fn derivative_bounds(harmonics: &[Harmonic]) -> (f64, f64) {
    let n1 = (PIECE_DEGREE + 1) as i32;
    harmonics.iter().fold((0.0, 0.0), |(y, v), h| {
        let a = h.amplitude.abs() * h.omega.abs().powi(n1);
        (y + a, v + a * h.omega.abs())
    })
}

/// The accuracy of [`HarmonicPieces::new`] for these arguments, without building the
/// pieces: equal intervals over `[0, end]` (s) short enough that the displacement error is
/// at most `tolerance` (m). An error if more than [`MAX_KNOTS`] intervals would be needed.
pub fn piece_accuracy(
    harmonics: &[Harmonic],
    end: f64,
    tolerance: f64,
) -> Result<PieceAccuracy, SignalError> {
    if !(end > 0.0 && end.is_finite() && tolerance > 0.0 && tolerance.is_finite()) {
        return Err(SignalError::Invalid(format!(
            "piecewise polynomials need a positive end time and tolerance, got end = {end} s, tolerance = {tolerance} m"
        )));
    }
    let (my, mv) = derivative_bounds(harmonics);
    let intervals = if my > 0.0 {
        // remainder_factor(h) · my ≤ tolerance, with h = end/n.
        let h = 4.0 * (tolerance * factorial_n1() / (2.0 * my)).powf(1.0 / (PIECE_DEGREE + 1) as f64);
        let n = (end / h).ceil();
        if !(n.is_finite() && n < MAX_KNOTS as f64) {
            return Err(SignalError::TooLarge(format!(
                "the harmonics would need {n:.3e} intervals (at most {MAX_KNOTS}): raise the tolerance or shorten the signal"
            )));
        }
        (n as usize).max(1)
    } else {
        1
    };
    let h = end / intervals as f64;
    let f = remainder_factor(h);
    Ok(PieceAccuracy {
        spacing: h,
        intervals,
        displacement_bound: f * my,
        velocity_bound: f * mv,
    })
}

fn factorial_n1() -> f64 {
    (1..=PIECE_DEGREE + 1).map(|k| k as f64).product()
}

impl HarmonicPieces {
    /// The sum of `harmonics` on `[0, end]` (s) within `tolerance` (m) in displacement (see
    /// [`piece_accuracy`]), whatever its cost.
    pub fn new(harmonics: &[Harmonic], end: f64, tolerance: f64) -> Result<Self, SignalError> {
        Self::new_within(harmonics, end, tolerance, &WorkBudget::unlimited())
    }

    /// [`new`](Self::new) within `budget`: refused before it starts if harmonics × intervals
    /// exceed what it allows ([`WorkBudget::check`]), stopped ([`SignalError::Stopped`]) when
    /// its stop flag is set (read every 64 intervals).
    pub fn new_within(
        harmonics: &[Harmonic],
        end: f64,
        tolerance: f64,
        budget: &WorkBudget,
    ) -> Result<Self, SignalError> {
        let accuracy = piece_accuracy(harmonics, end, tolerance)?;
        let n = accuracy.intervals;
        budget.check(harmonics.len(), n)?;
        let knots: Vec<f64> = (0..=n).map(|k| end * k as f64 / n as f64).collect();
        // Chebyshev points (roots of T₈) on [−1, 1], and the matrix taking values at them
        // to monomial coefficients in z (from the Chebyshev series by the DCT, then each
        // T_k expanded in powers of z).
        const M: usize = PIECE_DEGREE + 1;
        let nodes: [f64; M] = std::array::from_fn(|i| ((2 * i + 1) as f64 * PI / (2 * M) as f64).cos());
        let to_monomial = monomial_matrix(&nodes);
        let mut pieces = Vec::with_capacity(n);
        let h = end / n as f64;
        let half = 0.5 * h;
        // sin and cos of ω_j t + φ_j at node i of interval m, advanced from interval to
        // interval by the rotation through ω_j h (a random signal has hundreds of harmonics
        // and thousands of intervals), recomputed exactly every RESYNC intervals so that
        // rounding cannot build up.
        const RESYNC: usize = 64;
        let rotation: Vec<(f64, f64)> = harmonics.iter().map(|hm| (hm.omega * h).sin_cos()).collect();
        let mut phase = vec![(0.0, 0.0); harmonics.len() * M];
        for m in 0..n {
            let mid = (m as f64 + 0.5) * h;
            if m % POLL_INTERVALS == 0 && budget.stopped() {
                return Err(SignalError::Stopped {
                    done: m,
                    intervals: n,
                });
            }
            if m % RESYNC == 0 {
                for (j, hm) in harmonics.iter().enumerate() {
                    for (i, z) in nodes.iter().enumerate() {
                        phase[j * M + i] = (hm.omega * (mid + half * z) + hm.phase).sin_cos();
                    }
                }
            } else {
                for (j, &(sr, cr)) in rotation.iter().enumerate() {
                    for p in &mut phase[j * M..(j + 1) * M] {
                        let (s, c) = *p;
                        *p = (s * cr + c * sr, c * cr - s * sr);
                    }
                }
            }
            let mut ys = [0.0; M];
            let mut vs = [0.0; M];
            for (j, hm) in harmonics.iter().enumerate() {
                let (a, aw) = (hm.amplitude, hm.amplitude * hm.omega);
                for i in 0..M {
                    let (s, c) = phase[j * M + i];
                    ys[i] += a * s;
                    vs[i] += aw * c;
                }
            }
            let mut y = [0.0; M];
            let mut v = [0.0; M];
            let mut scale = 1.0;
            for j in 0..M {
                let (mut cy, mut cv) = (0.0, 0.0);
                for i in 0..M {
                    cy += to_monomial[j][i] * ys[i];
                    cv += to_monomial[j][i] * vs[i];
                }
                // Powers of z = (t − t_mid)/half into powers of t − t_mid.
                y[j] = cy / scale;
                v[j] = cv / scale;
                scale *= half;
            }
            pieces.push((mid, y, v));
        }
        Ok(HarmonicPieces {
            knots,
            pieces,
            accuracy,
        })
    }

    /// Interval ends, s.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The accuracy achieved.
    pub fn accuracy(&self) -> PieceAccuracy {
        self.accuracy
    }

    /// The last knot, s.
    pub fn end(&self) -> f64 {
        self.knots[self.knots.len() - 1]
    }

    /// The interval holding `t` (s): `knots[i] ≤ t < knots[i+1]`, the last one from its left
    /// knot on, the first before 0.
    pub fn interval(&self, t: f64) -> usize {
        let after = self.knots.partition_point(|&k| k <= t);
        after.saturating_sub(1).min(self.pieces.len() - 1)
    }

    /// Interval `i`: its middle (s) and the coefficients of the displacement (m/s^j) and
    /// the velocity (m/s^(j+1)) in powers of `t − t_mid` (panics if out of range).
    pub fn piece(&self, i: usize) -> (f64, &PieceCoefficients, &PieceCoefficients) {
        let (mid, y, v) = &self.pieces[i];
        (*mid, y, v)
    }

    /// Displacement (m) and velocity (m/s) at `t` (s).
    pub fn evaluate(&self, t: f64) -> [f64; 2] {
        let (mid, y, v) = self.piece(self.interval(t));
        let x = t - mid;
        let horner = |c: &PieceCoefficients| c.iter().rev().fold(0.0, |acc, &k| acc * x + k);
        [horner(y), horner(v)]
    }
}

/// The matrix taking values at the Chebyshev `nodes` (roots of T_M) to the monomial
/// coefficients (in z ∈ [−1, 1]) of their interpolant: the discrete cosine transform gives
/// the Chebyshev coefficients, and T_k = Σ_j t_kj z^j converts them.
fn monomial_matrix<const M: usize>(nodes: &[f64; M]) -> [[f64; M]; M] {
    // Chebyshev coefficients: a_k = (2 − δ_k0)/M Σ_i f_i T_k(z_i).
    let mut cheb = [[0.0; M]; M];
    for (k, row) in cheb.iter_mut().enumerate() {
        for (i, z) in nodes.iter().enumerate() {
            let tk = (k as f64 * z.acos()).cos();
            row[i] = if k == 0 { 1.0 } else { 2.0 } * tk / M as f64;
        }
    }
    // Monomial coefficients of T_k: T_0 = 1, T_1 = z, T_{k+1} = 2z T_k − T_{k−1}.
    let mut t = [[0.0; M]; M];
    t[0][0] = 1.0;
    if M > 1 {
        t[1][1] = 1.0;
    }
    for k in 1..M - 1 {
        for j in 0..M {
            let up = if j > 0 { 2.0 * t[k][j - 1] } else { 0.0 };
            t[k + 1][j] = up - t[k - 1][j];
        }
    }
    let mut out = [[0.0; M]; M];
    for (j, row) in out.iter_mut().enumerate() {
        for (i, cell) in row.iter_mut().enumerate() {
            *cell = (0..M).map(|k| t[k][j] * cheb[k][i]).sum();
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two harmonics on a fine grid: the displacement and the velocity within their stated
    /// bounds of the exact sum, and the bounds within the tolerance.
    #[test]
    fn pieces_of_two_harmonics_meet_their_bounds() {
        let h = [
            Harmonic {
                amplitude: 0.06,
                omega: 35.0,
                phase: 0.0,
            },
            Harmonic {
                amplitude: 0.015,
                omega: 80.5,
                phase: 0.4,
            },
        ];
        let tol = 1e-10 * 0.075;
        let p = HarmonicPieces::new(&h, 3.0, tol).unwrap();
        let acc = p.accuracy();
        assert!(acc.displacement_bound <= tol * (1.0 + 1e-12), "{acc:?}");
        // About 8 intervals per cycle of the faster harmonic, far fewer than a spline needs.
        let per_cycle = acc.intervals as f64 / (3.0 * 80.5 / (2.0 * PI));
        assert!(per_cycle < 12.0, "{per_cycle} intervals per cycle");
        let (mut ey, mut ev) = (0.0f64, 0.0f64);
        for k in 0..=200_000 {
            let t = 3.0 * k as f64 / 200_000.0;
            let [y, v] = p.evaluate(t);
            let [ye, ve, _] = super::super::harmonics::evaluate_sum(&h, t);
            ey = ey.max((y - ye).abs());
            ev = ev.max((v - ve).abs());
        }
        println!("errors {ey:.3e} m, {ev:.3e} m/s; bounds {acc:?}");
        // Rounding of the coefficients adds a few 1e-17 m on top of the remainder.
        assert!(ey <= acc.displacement_bound + 1e-15, "{ey} vs {acc:?}");
        assert!(ev <= acc.velocity_bound + 1e-13, "{ev} vs {acc:?}");
        assert!(ey > 0.0 && ev > 0.0);
    }

    /// A cubic is reproduced exactly (to rounding) by degree-7 interpolation.
    #[test]
    fn the_monomial_matrix_reproduces_polynomials() {
        const M: usize = PIECE_DEGREE + 1;
        let nodes: [f64; M] = std::array::from_fn(|i| ((2 * i + 1) as f64 * PI / (2 * M) as f64).cos());
        let a = monomial_matrix(&nodes);
        let f = |z: f64| 0.3 - 1.2 * z + 0.5 * z * z * z + 2.0 * z.powi(7);
        let values: [f64; M] = std::array::from_fn(|i| f(nodes[i]));
        let c: Vec<f64> = (0..M)
            .map(|j| (0..M).map(|i| a[j][i] * values[i]).sum())
            .collect();
        let expect = [0.3, -1.2, 0.0, 0.5, 0.0, 0.0, 0.0, 2.0];
        for (got, want) in c.iter().zip(expect) {
            assert!((got - want).abs() < 1e-13, "{c:?}");
        }
    }
}
