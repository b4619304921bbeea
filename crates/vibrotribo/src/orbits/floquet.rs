//! Floquet multipliers of a periodic orbit and the test functions of its bifurcations.
//!
//! The multipliers are the eigenvalues of the monodromy matrix `Φ(PT)`. A multiplier
//! crossing the unit circle at +1 is a fold (saddle-node), at −1 a period doubling (flip),
//! a complex pair crossing it a Neimark–Sacker bifurcation. Their smooth test functions,
//! which change sign at the crossing, are
//!
//! ```text
//! ψ_fold = det(Φ − I) = Π (λ_i − 1),   ψ_flip = det(Φ + I) = Π (λ_i + 1),
//! ψ_NS   = Π_{i<j} (λ_i λ_j − 1)   (the bialternate product: zero when λ_i λ_j = 1)
//! ```
//!
//! ψ_NS also vanishes at a "neutral saddle" (two real multipliers with product 1); a sign
//! change of ψ_NS is a Neimark–Sacker point only if the pair that causes it is complex.

use nalgebra::{Complex, DMatrix, DVector};

use super::error::OrbitError;

/// Iterations allowed to the Schur decomposition.
const SCHUR_ITERATIONS: usize = 10_000;

/// The Floquet multipliers (eigenvalues of the monodromy matrix), largest modulus first
/// (ties by argument), as complex numbers.
pub fn floquet_multipliers(monodromy: &DMatrix<f64>) -> Result<Vec<Complex<f64>>, OrbitError> {
    if !monodromy.is_square() || monodromy.iter().any(|v| !v.is_finite()) {
        return Err(OrbitError::Eigenvalues);
    }
    let schur = nalgebra::Schur::try_new(monodromy.clone(), f64::EPSILON, SCHUR_ITERATIONS)
        .ok_or(OrbitError::Eigenvalues)?;
    let mut values: Vec<Complex<f64>> = schur.complex_eigenvalues().iter().copied().collect();
    values.sort_by(|a, b| b.norm().total_cmp(&a.norm()).then(a.arg().total_cmp(&b.arg())));
    Ok(values)
}

/// The test functions of the module docs at one orbit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TestFunctions {
    pub fold: f64,
    pub flip: f64,
    pub neimark_sacker: f64,
}

impl TestFunctions {
    pub fn of(multipliers: &[Complex<f64>]) -> Self {
        let one = Complex::new(1.0, 0.0);
        let fold = multipliers.iter().fold(one, |p, l| p * (l - one)).re;
        let flip = multipliers.iter().fold(one, |p, l| p * (l + one)).re;
        let mut ns = one;
        for (i, a) in multipliers.iter().enumerate() {
            for b in &multipliers[i + 1..] {
                ns *= a * b - one;
            }
        }
        TestFunctions {
            fold,
            flip,
            neimark_sacker: ns.re,
        }
    }
}

/// A unit vector `e` with `Φ e ≈ λ e` for a real multiplier λ: the right singular vector of
/// `Φ − λI` with the smallest singular value.
pub(crate) fn real_eigenvector(monodromy: &DMatrix<f64>, lambda: f64) -> Option<DVector<f64>> {
    let n = monodromy.nrows();
    let shifted = monodromy - DMatrix::identity(n, n) * lambda;
    let svd = nalgebra::SVD::try_new(shifted, false, true, f64::EPSILON, SCHUR_ITERATIONS)?;
    let v_t = svd.v_t?;
    let (k, _) = svd
        .singular_values
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))?;
    let e = v_t.row(k).transpose();
    Some(e.normalize())
}

/// Whether the orbit is asymptotically stable: every multiplier inside the unit circle.
pub(crate) fn is_stable(multipliers: &[Complex<f64>]) -> bool {
    multipliers.first().is_none_or(|l| l.norm() < 1.0)
}
