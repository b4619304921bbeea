//! [`PiecewiseCubic`]: a base displacement that is a cubic polynomial on each interval
//! between knots, C² across them; its construction by interpolation (not-a-knot, natural or
//! clamped cubic splines) and the error bound of the clamped spline.

use super::error::SignalError;

/// How the two free conditions of an interpolating cubic spline are chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EndCondition {
    /// The third derivative is continuous at the second and the last-but-one knot (the first
    /// two and the last two intervals are one cubic each). Needs at least 4 knots.
    NotAKnot,
    /// y'' = 0 at both ends.
    Natural,
    /// The slopes at both ends are given, m/s (the "complete" spline; with the exact slopes
    /// of a smooth function the error bounds of [`spline_error_bounds`] hold).
    Clamped {
        /// y'(t₀), m/s.
        start_slope: f64,
        /// y'(t_end), m/s.
        end_slope: f64,
    },
}

/// A piecewise cubic base displacement y(t), m.
///
/// On interval `i`, `knots[i] ≤ t ≤ knots[i+1]`, with τ = t − `knots[i]`,
/// `y(t) = c₀ + c₁ τ + c₂ τ² + c₃ τ³` where `coefficients[i] = [c₀, c₁, c₂, c₃]` are the
/// displacement, velocity, half the acceleration and a sixth of the jerk at the left knot
/// (m, m/s, m/s², m/s³). The constructors of this module make it C² (displacement, velocity
/// and acceleration continuous at the knots); [`new`](Self::new) accepts any coefficients
/// and [`continuity_defects`](Self::continuity_defects) measures the jumps.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecewiseCubic {
    knots: Vec<f64>,
    coefficients: Vec<[f64; 4]>,
}

impl PiecewiseCubic {
    /// A piecewise cubic from its knots (s, finite, strictly increasing, at least 2) and one
    /// set of coefficients per interval (`knots.len() − 1` of them, finite).
    pub fn new(knots: Vec<f64>, coefficients: Vec<[f64; 4]>) -> Result<Self, SignalError> {
        check_times(&knots, 2)?;
        if coefficients.len() + 1 != knots.len() {
            return Err(SignalError::Invalid(format!(
                "{} knots need {} sets of coefficients, got {}",
                knots.len(),
                knots.len() - 1,
                coefficients.len()
            )));
        }
        if let Some(i) = coefficients.iter().position(|c| c.iter().any(|x| !x.is_finite())) {
            return Err(SignalError::Invalid(format!(
                "the coefficients of interval {i} are not finite: {:?}",
                coefficients[i]
            )));
        }
        Ok(PiecewiseCubic { knots, coefficients })
    }

    /// The cubic spline through `(times[i], values[i])` (s, m) with the given end
    /// conditions. Uneven spacing is allowed.
    pub fn interpolate(times: &[f64], values: &[f64], ends: EndCondition) -> Result<Self, SignalError> {
        let min = if ends == EndCondition::NotAKnot { 4 } else { 2 };
        check_times(times, min)?;
        if values.len() != times.len() {
            return Err(SignalError::Invalid(format!(
                "{} times but {} values",
                times.len(),
                values.len()
            )));
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(SignalError::Invalid(format!(
                "value {i} is not finite: {}",
                values[i]
            )));
        }
        let slopes = spline_slopes(times, values, ends);
        Self::hermite(times, values, &slopes)
    }

    /// The piecewise cubic that takes `values` (m) and `slopes` (m/s) at the knots `times`
    /// (cubic Hermite; C² only if the slopes are a spline's).
    fn hermite(times: &[f64], values: &[f64], slopes: &[f64]) -> Result<Self, SignalError> {
        let coefficients = (0..times.len() - 1)
            .map(|i| {
                let h = times[i + 1] - times[i];
                let delta = (values[i + 1] - values[i]) / h;
                let (s0, s1) = (slopes[i], slopes[i + 1]);
                [
                    values[i],
                    s0,
                    (3.0 * delta - 2.0 * s0 - s1) / h,
                    (s0 + s1 - 2.0 * delta) / (h * h),
                ]
            })
            .collect();
        Self::new(times.to_vec(), coefficients)
    }

    /// The exact double integral of the piecewise-linear acceleration through
    /// `(times[i], accelerations[i])` (s, m/s²), starting from velocity `v0` (m/s) and
    /// displacement `y0` (m) at `times[0]`: velocity piecewise quadratic, displacement
    /// piecewise cubic, C² by construction (its acceleration is the continuous
    /// piecewise-linear one).
    pub fn integrate_linear_acceleration(
        times: &[f64],
        accelerations: &[f64],
        v0: f64,
        y0: f64,
    ) -> Result<Self, SignalError> {
        check_times(times, 2)?;
        if accelerations.len() != times.len() {
            return Err(SignalError::Invalid(format!(
                "{} times but {} accelerations",
                times.len(),
                accelerations.len()
            )));
        }
        let mut coefficients = Vec::with_capacity(times.len() - 1);
        let (mut y, mut v) = (y0, v0);
        for i in 0..times.len() - 1 {
            let h = times[i + 1] - times[i];
            let (a0, a1) = (accelerations[i], accelerations[i + 1]);
            let c = [y, v, 0.5 * a0, (a1 - a0) / (6.0 * h)];
            coefficients.push(c);
            y = c[0] + h * (c[1] + h * (c[2] + h * c[3]));
            v = c[1] + h * (2.0 * c[2] + 3.0 * h * c[3]);
        }
        Self::new(times.to_vec(), coefficients)
    }

    /// The knots, s.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// The coefficients of each interval (see the type's documentation).
    pub fn coefficients(&self) -> &[[f64; 4]] {
        &self.coefficients
    }

    /// Number of intervals.
    pub fn intervals(&self) -> usize {
        self.coefficients.len()
    }

    /// The first knot, s.
    pub fn start(&self) -> f64 {
        self.knots[0]
    }

    /// The last knot, s: where the displacement ends.
    pub fn end(&self) -> f64 {
        self.knots[self.knots.len() - 1]
    }

    /// The interval holding `t` (s), by binary search: the `i` with
    /// `knots[i] ≤ t < knots[i+1]`; the last interval for `t ≥` its left knot (the end
    /// included), the first for `t <` [`start`](Self::start) (the end polynomials are
    /// extrapolated outside the knots).
    pub fn interval(&self, t: f64) -> usize {
        let after = self.knots.partition_point(|&k| k <= t);
        after.saturating_sub(1).min(self.coefficients.len() - 1)
    }

    /// The left knot (s) and the coefficients of interval `i` (panics if out of range).
    pub fn piece(&self, i: usize) -> (f64, [f64; 4]) {
        (self.knots[i], self.coefficients[i])
    }

    /// Displacement y (m), velocity y' (m/s) and acceleration y'' (m/s²) at `t` (s).
    pub fn evaluate(&self, t: f64) -> [f64; 3] {
        let (t0, c) = self.piece(self.interval(t));
        let x = t - t0;
        [
            c[0] + x * (c[1] + x * (c[2] + x * c[3])),
            c[1] + x * (2.0 * c[2] + 3.0 * x * c[3]),
            2.0 * c[2] + 6.0 * x * c[3],
        ]
    }

    /// Displacement y(t), m.
    pub fn displacement(&self, t: f64) -> f64 {
        self.evaluate(t)[0]
    }

    /// Velocity y'(t), m/s.
    pub fn velocity(&self, t: f64) -> f64 {
        self.evaluate(t)[1]
    }

    /// Acceleration y''(t), m/s².
    pub fn acceleration(&self, t: f64) -> f64 {
        self.evaluate(t)[2]
    }

    /// The largest jumps of y (m), y' (m/s) and y'' (m/s²) across the interior knots, each
    /// relative to the largest |y|, |y'|, |y''| at the knots (0 for a C² function up to
    /// rounding).
    pub fn continuity_defects(&self) -> [f64; 3] {
        let mut jump = [0.0f64; 3];
        let mut scale = [0.0f64; 3];
        for i in 0..self.coefficients.len() {
            let h = self.knots[i + 1] - self.knots[i];
            let c = self.coefficients[i];
            let right = [
                c[0] + h * (c[1] + h * (c[2] + h * c[3])),
                c[1] + h * (2.0 * c[2] + 3.0 * h * c[3]),
                2.0 * c[2] + 6.0 * h * c[3],
            ];
            let left = [c[0], c[1], 2.0 * c[2]];
            for d in 0..3 {
                scale[d] = scale[d].max(left[d].abs()).max(right[d].abs());
                if let Some(next) = self.coefficients.get(i + 1) {
                    let next = [next[0], next[1], 2.0 * next[2]];
                    jump[d] = jump[d].max((next[d] - right[d]).abs());
                }
            }
        }
        std::array::from_fn(|d| {
            if scale[d] > 0.0 {
                jump[d] / scale[d]
            } else {
                jump[d]
            }
        })
    }

    /// Multiplies the displacement by `factor`.
    pub(crate) fn scale(&mut self, factor: f64) {
        for c in &mut self.coefficients {
            for x in c.iter_mut() {
                *x *= factor;
            }
        }
    }

    /// Subtracts the cubic polynomial `q(t) = Σ b_k ((t − t₀)/L)^k` (m; `L` in s) from the
    /// displacement: still C², the acceleration changed by a linear function of t.
    pub(crate) fn subtract_cubic(&mut self, b: [f64; 4], t0: f64, length: f64) {
        for (i, c) in self.coefficients.iter_mut().enumerate() {
            let u = (self.knots[i] - t0) / length;
            let q = b[0] + u * (b[1] + u * (b[2] + u * b[3]));
            let dq = (b[1] + u * (2.0 * b[2] + 3.0 * u * b[3])) / length;
            let ddq = (2.0 * b[2] + 6.0 * u * b[3]) / (length * length);
            let dddq = 6.0 * b[3] / (length * length * length);
            c[0] -= q;
            c[1] -= dq;
            c[2] -= ddq / 2.0;
            c[3] -= dddq / 6.0;
        }
    }
}

/// The knot spacing h (s) at which the clamped cubic spline of a function whose fourth
/// derivative is bounded by `fourth_derivative_bound` (m/s⁴) interpolates it within
/// `tolerance` (m): h = (384 tolerance / (5 M₄))^{1/4}, from the bound of
/// [`spline_error_bounds`].
pub fn knot_spacing(tolerance: f64, fourth_derivative_bound: f64) -> f64 {
    (384.0 * tolerance / (5.0 * fourth_derivative_bound)).powf(0.25)
}

/// Bounds on the errors of the clamped ("complete") cubic spline of a function f with
/// |f''''| ≤ `fourth_derivative_bound` (m/s⁴) on knots at most `h` (s) apart, given the
/// exact end slopes (Hall & Meyer, J. Approx. Theory 16 (1976) 105–122):
/// `[5/384 h⁴ M₄, 1/24 h³ M₄, 3/8 h² M₄]` for the displacement (m), velocity (m/s) and
/// acceleration (m/s²).
pub fn spline_error_bounds(h: f64, fourth_derivative_bound: f64) -> [f64; 3] {
    let m = fourth_derivative_bound;
    [
        5.0 / 384.0 * h.powi(4) * m,
        h.powi(3) * m / 24.0,
        3.0 / 8.0 * h * h * m,
    ]
}

/// Checks that `times` are finite and strictly increasing, at least `min` of them.
pub(crate) fn check_times(times: &[f64], min: usize) -> Result<(), SignalError> {
    if times.len() < min {
        return Err(SignalError::Invalid(format!(
            "needs at least {min} knots, got {}",
            times.len()
        )));
    }
    if let Some(i) = times.iter().position(|t| !t.is_finite()) {
        return Err(SignalError::Invalid(format!(
            "knot {i} is not finite: {}",
            times[i]
        )));
    }
    if let Some(i) = times.windows(2).position(|w| w[1] <= w[0]) {
        return Err(SignalError::Invalid(format!(
            "knots must increase strictly: knot {} = {} after knot {i} = {}",
            i + 1,
            times[i + 1],
            times[i]
        )));
    }
    Ok(())
}

/// The slopes of the interpolating cubic spline at the knots (the tridiagonal system of the
/// slope formulation; the not-a-knot rows as in de Boor, "A Practical Guide to Splines",
/// ch. IV).
fn spline_slopes(x: &[f64], y: &[f64], ends: EndCondition) -> Vec<f64> {
    let n = x.len();
    let dx: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    let delta: Vec<f64> = (0..n - 1).map(|i| (y[i + 1] - y[i]) / dx[i]).collect();
    // Row i: lower[i] s[i-1] + diag[i] s[i] + upper[i] s[i+1] = rhs[i].
    let mut lower = vec![0.0; n];
    let mut diag = vec![0.0; n];
    let mut upper = vec![0.0; n];
    let mut rhs = vec![0.0; n];
    for i in 1..n - 1 {
        lower[i] = dx[i];
        diag[i] = 2.0 * (dx[i - 1] + dx[i]);
        upper[i] = dx[i - 1];
        rhs[i] = 3.0 * (dx[i] * delta[i - 1] + dx[i - 1] * delta[i]);
    }
    match ends {
        EndCondition::Clamped {
            start_slope,
            end_slope,
        } => {
            diag[0] = 1.0;
            rhs[0] = start_slope;
            diag[n - 1] = 1.0;
            rhs[n - 1] = end_slope;
        }
        EndCondition::Natural => {
            diag[0] = 2.0;
            upper[0] = 1.0;
            rhs[0] = 3.0 * delta[0];
            lower[n - 1] = 1.0;
            diag[n - 1] = 2.0;
            rhs[n - 1] = 3.0 * delta[n - 2];
        }
        EndCondition::NotAKnot => {
            let d = x[2] - x[0];
            diag[0] = dx[1];
            upper[0] = d;
            rhs[0] = ((dx[0] + 2.0 * d) * dx[1] * delta[0] + dx[0] * dx[0] * delta[1]) / d;
            let d = x[n - 1] - x[n - 3];
            let (h_last, h_prev) = (dx[n - 2], dx[n - 3]);
            lower[n - 1] = d;
            diag[n - 1] = h_prev;
            rhs[n - 1] = (h_last * h_last * delta[n - 3] + (2.0 * d + h_last) * h_prev * delta[n - 2]) / d;
        }
    }
    solve_tridiagonal(&lower, &mut diag, &upper, &mut rhs);
    rhs
}

/// Solves a tridiagonal system in place (Thomas algorithm); the solution is left in `rhs`.
fn solve_tridiagonal(lower: &[f64], diag: &mut [f64], upper: &[f64], rhs: &mut [f64]) {
    let n = diag.len();
    for i in 1..n {
        let m = lower[i] / diag[i - 1];
        diag[i] -= m * upper[i - 1];
        rhs[i] -= m * rhs[i - 1];
    }
    rhs[n - 1] /= diag[n - 1];
    for i in (0..n - 1).rev() {
        rhs[i] = (rhs[i] - upper[i] * rhs[i + 1]) / diag[i];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cubic polynomial is reproduced exactly by every spline whose end conditions it
    /// satisfies (not-a-knot always; clamped with its slopes), on uneven knots.
    #[test]
    fn cubics_are_reproduced() {
        let p = |t: f64| 0.3 - 1.2 * t + 0.7 * t * t - 0.25 * t * t * t;
        let dp = |t: f64| -1.2 + 1.4 * t - 0.75 * t * t;
        let ddp = |t: f64| 1.4 - 1.5 * t;
        let times = [0.0, 0.1, 0.35, 0.4, 0.9, 1.3, 1.31, 2.0];
        let values: Vec<f64> = times.iter().map(|&t| p(t)).collect();
        for ends in [
            EndCondition::NotAKnot,
            EndCondition::Clamped {
                start_slope: dp(0.0),
                end_slope: dp(2.0),
            },
        ] {
            let s = PiecewiseCubic::interpolate(&times, &values, ends).unwrap();
            for k in 0..=200 {
                let t = 2.0 * k as f64 / 200.0;
                let [y, v, a] = s.evaluate(t);
                assert!((y - p(t)).abs() < 1e-13, "{ends:?} t={t}");
                assert!((v - dp(t)).abs() < 1e-12, "{ends:?} t={t}");
                assert!((a - ddp(t)).abs() < 1e-11, "{ends:?} t={t}");
            }
            assert!(s.continuity_defects().iter().all(|&d| d < 1e-12));
        }
    }

    /// The natural spline has y'' = 0 at both ends and is C².
    #[test]
    fn natural_ends() {
        let times = [0.0, 0.5, 1.5, 2.0, 3.0];
        let values = [0.0, 1.0, -1.0, 0.5, 0.2];
        let s = PiecewiseCubic::interpolate(&times, &values, EndCondition::Natural).unwrap();
        assert!(s.acceleration(0.0).abs() < 1e-13);
        assert!(s.acceleration(3.0).abs() < 1e-12);
        for (t, y) in times.iter().zip(values) {
            assert!((s.displacement(*t) - y).abs() < 1e-14);
        }
        assert!(s.continuity_defects().iter().all(|&d| d < 1e-13));
    }

    #[test]
    fn interval_search() {
        let s = PiecewiseCubic::new(vec![0.0, 1.0, 2.0, 4.0], vec![[0.0; 4]; 3]).unwrap();
        assert_eq!(s.interval(-1.0), 0);
        assert_eq!(s.interval(0.0), 0);
        assert_eq!(s.interval(0.999), 0);
        assert_eq!(s.interval(1.0), 1);
        assert_eq!(s.interval(3.0), 2);
        assert_eq!(s.interval(4.0), 2);
        assert_eq!(s.interval(9.0), 2);
        assert_eq!(s.end(), 4.0);
    }

    /// Integration of a constant jerk: a(t) = t gives v = t²/2, y = t³/6, exactly.
    #[test]
    fn linear_acceleration_integrates_exactly() {
        let times = [0.0, 0.2, 0.7, 1.0, 1.6];
        let s = PiecewiseCubic::integrate_linear_acceleration(&times, &times, 0.5, -0.1).unwrap();
        for k in 0..=160 {
            let t = k as f64 / 100.0;
            let [y, v, a] = s.evaluate(t);
            assert!((a - t).abs() < 1e-14);
            assert!((v - (0.5 + t * t / 2.0)).abs() < 1e-14);
            assert!((y - (-0.1 + 0.5 * t + t * t * t / 6.0)).abs() < 1e-14);
        }
    }

    #[test]
    fn bad_knots_are_refused() {
        let e = PiecewiseCubic::interpolate(&[0.0, 1.0, 1.0, 2.0], &[0.0; 4], EndCondition::NotAKnot)
            .unwrap_err()
            .to_string();
        assert!(e.contains("knot 2 = 1 after knot 1 = 1"), "{e}");
        let e = PiecewiseCubic::interpolate(&[0.0, 1.0, 2.0], &[0.0; 3], EndCondition::NotAKnot)
            .unwrap_err()
            .to_string();
        assert!(e.contains("at least 4"), "{e}");
    }
}
