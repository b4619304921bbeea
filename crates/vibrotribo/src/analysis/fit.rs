//! Least-squares quadratic fit `y = a x² + b x + c`.
//!
//! The paper fits the optimal mass ratio against frequency, `R_mo = 11.43Ω² − 28.46Ω + 18.03`
//! on Ω ∈ [0.55, 0.95] (Sect. 4.3, Fig. 16). [`fit_quadratic`] minimises `Σ (y_i − a x_i² −
//! b x_i − c)²`. For conditioning it works in the centred, scaled variable
//! `u = (x − x̄)/s` (s = max |x − x̄|), solves the least-squares problem by a QR factorisation
//! (modified Gram–Schmidt, each column orthogonalised twice) rather than the normal
//! equations, and converts the coefficients back to x.

use super::{AnalysisError, Sum, check_finite};

/// Result of [`fit_quadratic`].
#[derive(Debug, Clone, PartialEq)]
pub struct QuadraticFit {
    /// Coefficient a of x², in units of y per unit of x².
    pub a: f64,
    /// Coefficient b of x, in units of y per unit of x.
    pub b: f64,
    /// Constant c, in units of y.
    pub c: f64,
    /// Residuals `y_i − ŷ_i`, in units of y, in input order.
    pub residuals: Vec<f64>,
    /// Root-mean-square residual `√(Σ r_i² / n)`, in units of y.
    pub rms_residual: f64,
    /// Coefficient of determination `R² = 1 − Σ r_i² / Σ (y_i − ȳ)²`, dimensionless; `None`
    /// when y has no variance (R² undefined).
    pub r_squared: Option<f64>,
    centre: f64,
    scale: f64,
    scaled: [f64; 3],
}

impl QuadraticFit {
    /// The fitted value `a x² + b x + c` (evaluated in the centred form, without the
    /// cancellation of the expanded one far from the origin).
    pub fn eval(&self, x: f64) -> f64 {
        let u = (x - self.centre) / self.scale;
        self.scaled[0] + u * (self.scaled[1] + u * self.scaled[2])
    }
}

/// Least-squares parabola through the points `(x_i, y_i)`.
///
/// Needs at least three distinct, finite x values and finite y values of the same count.
///
/// ```
/// use vibrotribo::analysis::fit_quadratic;
///
/// let omega = [0.55, 0.65, 0.75, 0.85, 0.95];
/// let r_mo: Vec<f64> = omega.iter().map(|w| 11.43 * w * w - 28.46 * w + 18.03).collect();
/// let fit = fit_quadratic(&omega, &r_mo)?;
/// assert!((fit.a - 11.43).abs() < 1e-9 && (fit.b + 28.46).abs() < 1e-9);
/// # Ok::<(), vibrotribo::analysis::AnalysisError>(())
/// ```
pub fn fit_quadratic(x: &[f64], y: &[f64]) -> Result<QuadraticFit, AnalysisError> {
    if x.is_empty() {
        return Err(AnalysisError::Empty { what: "x" });
    }
    if y.len() != x.len() {
        return Err(AnalysisError::LengthMismatch {
            what: "y values for the x values",
            expected: x.len(),
            got: y.len(),
        });
    }
    let n = x.len();
    if n < 3 {
        return Err(AnalysisError::TooShort {
            what: "fit data",
            needed: 3,
            got: n,
        });
    }
    check_finite("x", x, 0)?;
    check_finite("y", y, 0)?;

    let centre = x.iter().sum::<f64>() / n as f64;
    let scale = x.iter().fold(0.0f64, |m, v| m.max((v - centre).abs()));
    if scale == 0.0 {
        return Err(AnalysisError::Degenerate("all x values are equal"));
    }
    let u: Vec<f64> = x.iter().map(|v| (v - centre) / scale).collect();
    let columns = [
        vec![1.0; n],
        u.clone(),
        u.iter().map(|v| v * v).collect::<Vec<f64>>(),
    ];

    // Q (n × 3) and R (3 × 3, upper) with [1 u u²] = Q R.
    let dot = |p: &[f64], q: &[f64]| p.iter().zip(q).map(|(a, b)| a * b).sum::<f64>();
    let mut q: Vec<Vec<f64>> = Vec::with_capacity(3);
    let mut r = [[0.0; 3]; 3];
    for (j, col) in columns.iter().enumerate() {
        let mut v = col.clone();
        for _pass in 0..2 {
            for (i, qi) in q.iter().enumerate() {
                let proj = dot(qi, &v);
                r[i][j] += proj;
                v.iter_mut().zip(qi).for_each(|(vk, qk)| *vk -= proj * qk);
            }
        }
        let norm = dot(&v, &v).sqrt();
        if norm <= 1e-10 * dot(col, col).sqrt() {
            return Err(AnalysisError::Degenerate(
                "fewer than three distinct x values: the parabola is not determined",
            ));
        }
        r[j][j] = norm;
        v.iter_mut().for_each(|vk| *vk /= norm);
        q.push(v);
    }
    // Qᵀy, orthogonalising y step by step (modified Gram–Schmidt), then R β = Qᵀy.
    let mut rest = y.to_vec();
    let mut qty = [0.0; 3];
    for (i, qi) in q.iter().enumerate() {
        qty[i] = dot(qi, &rest);
        rest.iter_mut().zip(qi).for_each(|(rk, qk)| *rk -= qty[i] * qk);
    }
    let mut beta = [0.0; 3];
    for i in (0..3).rev() {
        let tail: f64 = (i + 1..3).map(|k| r[i][k] * beta[k]).sum();
        beta[i] = (qty[i] - tail) / r[i][i];
    }

    let [b0, b1, b2] = beta;
    let s2 = scale * scale;
    let residuals: Vec<f64> = y
        .iter()
        .zip(&u)
        .map(|(yi, ui)| yi - (b0 + ui * (b1 + ui * b2)))
        .collect();
    let mut ss_res = Sum::default();
    residuals.iter().for_each(|r| ss_res.add(r * r));
    let y_mean = y.iter().sum::<f64>() / n as f64;
    let mut ss_tot = Sum::default();
    y.iter().for_each(|v| ss_tot.add((v - y_mean) * (v - y_mean)));
    let (ss_res, ss_tot) = (ss_res.value(), ss_tot.value());
    Ok(QuadraticFit {
        a: b2 / s2,
        b: b1 / scale - 2.0 * b2 * centre / s2,
        c: b0 - b1 * centre / scale + b2 * centre * centre / s2,
        rms_residual: (ss_res / n as f64).sqrt(),
        r_squared: (ss_tot > 0.0).then(|| 1.0 - ss_res / ss_tot),
        residuals,
        centre,
        scale,
        scaled: beta,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn recovers_the_papers_optimal_mass_ratio_fit_from_exact_data() {
        let (a, b, c) = (11.43, -28.46, 18.03);
        let omega: Vec<f64> = (0..9).map(|i| 0.55 + 0.05 * i as f64).collect();
        let r_mo: Vec<f64> = omega.iter().map(|w| a * w * w + b * w + c).collect();
        let fit = fit_quadratic(&omega, &r_mo).unwrap();
        assert_relative_eq!(fit.a, a, max_relative = 1e-10);
        assert_relative_eq!(fit.b, b, max_relative = 1e-10);
        assert_relative_eq!(fit.c, c, max_relative = 1e-10);
        assert!(fit.rms_residual < 1e-13, "rms {}", fit.rms_residual);
        assert!(fit.residuals.iter().all(|r| r.abs() < 1e-13));
        assert_relative_eq!(fit.r_squared.unwrap(), 1.0, max_relative = 1e-14);
        // The paper's curve at Ω = 0.72 (its Fig. 14–16 case): R_mo ≈ 3.48, "optimal R_m ≈ 3.5".
        assert_relative_eq!(
            fit.eval(0.72),
            a * 0.72 * 0.72 + b * 0.72 + c,
            max_relative = 1e-12
        );
        assert!((fit.eval(0.72) - 3.5).abs() < 0.05);
    }

    #[test]
    fn far_from_the_origin_exact_data_is_still_recovered() {
        let x: Vec<f64> = (0..11).map(|i| 1000.0 + i as f64).collect();
        let y: Vec<f64> = x.iter().map(|v| 2.0 * v * v - 3.0 * v + 5.0).collect();
        let fit = fit_quadratic(&x, &y).unwrap();
        assert_relative_eq!(fit.a, 2.0, max_relative = 1e-10);
        assert_relative_eq!(fit.b, -3.0, max_relative = 1e-7);
        assert_relative_eq!(fit.c, 5.0, max_relative = 1e-4);
        for (xi, yi) in x.iter().zip(&y) {
            assert_relative_eq!(fit.eval(*xi), *yi, max_relative = 1e-14);
        }
    }

    #[test]
    fn cubic_on_symmetric_points_has_the_closed_form_fit() {
        // y = x³ on x = −2..2: by symmetry a = c = 0 and b = Σx⁴/Σx² = 34/10; residuals
        // x³ − 3.4x = (−1.2, 2.4, 0, −2.4, 1.2); R² = 1 − 14.4/130.
        let x = [-2.0, -1.0, 0.0, 1.0, 2.0];
        let y: Vec<f64> = x.iter().map(|v: &f64| v.powi(3)).collect();
        let fit = fit_quadratic(&x, &y).unwrap();
        assert!(
            fit.a.abs() < 1e-14 && fit.c.abs() < 1e-14,
            "a = {}, c = {}",
            fit.a,
            fit.c
        );
        assert_relative_eq!(fit.b, 3.4, max_relative = 1e-14);
        for (got, want) in fit.residuals.iter().zip([-1.2, 2.4, 0.0, -2.4, 1.2]) {
            assert!((got - want).abs() < 1e-14, "residual {got} vs {want}");
        }
        assert_relative_eq!(fit.r_squared.unwrap(), 1.0 - 14.4 / 130.0, max_relative = 1e-14);
        assert_relative_eq!(fit.rms_residual, (14.4f64 / 5.0).sqrt(), max_relative = 1e-14);
    }

    #[test]
    fn residuals_are_orthogonal_to_the_basis() {
        // The defining property of the least-squares solution (normal equations):
        // Σ r = Σ r x = Σ r x² = 0.
        let x: Vec<f64> = (0..40)
            .map(|i| 0.3 * i as f64 + 0.01 * (i * i % 7) as f64)
            .collect();
        let y: Vec<f64> = x.iter().map(|v| (v * 1.3).sin() * 10.0 + v).collect();
        let fit = fit_quadratic(&x, &y).unwrap();
        let scale: f64 = y.iter().map(|v| v.abs()).sum();
        for power in 0..3 {
            let s: f64 = fit.residuals.iter().zip(&x).map(|(r, v)| r * v.powi(power)).sum();
            let xs: f64 = x.iter().map(|v| v.powi(power)).fold(0.0, f64::max);
            assert!(s.abs() < 1e-12 * scale * xs, "Σ r x^{power} = {s}");
        }
        let r2 = fit.r_squared.unwrap();
        assert!((0.0..1.0).contains(&r2));
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        assert!(matches!(
            fit_quadratic(&[], &[]),
            Err(AnalysisError::Empty { .. })
        ));
        assert!(matches!(
            fit_quadratic(&[1.0, 2.0, 3.0], &[1.0, 2.0]),
            Err(AnalysisError::LengthMismatch { .. })
        ));
        assert!(matches!(
            fit_quadratic(&[1.0, 2.0], &[1.0, 2.0]),
            Err(AnalysisError::TooShort { .. })
        ));
        assert!(matches!(
            fit_quadratic(&[1.0, 1.0, 2.0, 2.0], &[1.0, 2.0, 3.0, 4.0]),
            Err(AnalysisError::Degenerate(_))
        ));
        assert!(matches!(
            fit_quadratic(&[5.0; 4], &[1.0, 2.0, 3.0, 4.0]),
            Err(AnalysisError::Degenerate(_))
        ));
        assert!(matches!(
            fit_quadratic(&[1.0, 2.0, f64::NAN], &[1.0, 2.0, 3.0]),
            Err(AnalysisError::NonFinite {
                what: "x",
                index: 2,
                ..
            })
        ));
        assert!(matches!(
            fit_quadratic(&[1.0, 2.0, 3.0], &[1.0, f64::INFINITY, 3.0]),
            Err(AnalysisError::NonFinite {
                what: "y",
                index: 1,
                ..
            })
        ));
        // Constant y: an exact fit with R² undefined.
        let fit = fit_quadratic(&[1.0, 2.0, 3.0], &[4.0; 3]).unwrap();
        assert!(fit.r_squared.is_none());
        assert!(fit.a.abs() < 1e-14 && fit.b.abs() < 1e-13);
        assert_relative_eq!(fit.c, 4.0, max_relative = 1e-14);
    }
}
