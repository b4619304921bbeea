//! Average harvested power from the energy harvested in each excitation period.
//!
//! Given the energy `E_n`, J, delivered to the load during period n = 1, 2, … (period T, s),
//! the paper's running average power (seed eq. 14, plotted against N in its power figures) is
//!
//! ```text
//! P_a(N) = (1 / (N T)) Σ_{n=1}^{N} E_n,    W,
//! ```
//!
//! which settles to the mean power of the steady state. [`mean_power`] gives that mean over
//! the periods after a transient directly. Sums are compensated, so long runs lose no
//! accuracy.

use super::{AnalysisError, Sum, check_finite, check_positive};

fn check_energies(energies: &[f64], period: f64) -> Result<(), AnalysisError> {
    check_positive("period", period)?;
    if energies.is_empty() {
        return Err(AnalysisError::Empty {
            what: "energy per period",
        });
    }
    check_finite("energy per period", energies, 0)
}

/// Running average power `P_a(N) = Σ_{n≤N} E_n / (N T)`, W, for N = 1, …, `energies.len()`,
/// from the energy per period `energies[n−1] = E_n`, J, and the period `period` = T, s.
///
/// ```
/// use vibrotribo::analysis::running_average_power;
///
/// // 2 J, 4 J, 0 J in periods of 0.5 s: P_a = 2/0.5, 6/1.0, 6/1.5 W.
/// let p = running_average_power(&[2.0, 4.0, 0.0], 0.5)?;
/// for (got, want) in p.iter().zip([4.0, 6.0, 4.0]) {
///     assert!((got - want).abs() < 1e-12);
/// }
/// # Ok::<(), vibrotribo::analysis::AnalysisError>(())
/// ```
pub fn running_average_power(energies: &[f64], period: f64) -> Result<Vec<f64>, AnalysisError> {
    check_energies(energies, period)?;
    let mut sum = Sum::default();
    Ok(energies
        .iter()
        .enumerate()
        .map(|(i, &e)| {
            sum.add(e);
            sum.value() / ((i + 1) as f64 * period)
        })
        .collect())
}

/// Mean power over the periods after a transient, W: `Σ_{n>K} E_n / ((M − K) T)` for
/// M = `energies.len()` periods of which the first K = `transient_periods` are skipped.
pub fn mean_power(energies: &[f64], period: f64, transient_periods: usize) -> Result<f64, AnalysisError> {
    check_energies(energies, period)?;
    if transient_periods >= energies.len() {
        return Err(AnalysisError::TooShort {
            what: "energy per period after the transient",
            needed: transient_periods + 1,
            got: energies.len(),
        });
    }
    let mut sum = Sum::default();
    energies[transient_periods..].iter().for_each(|&e| sum.add(e));
    Ok(sum.value() / ((energies.len() - transient_periods) as f64 * period))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn running_average_of_closed_form_sequences() {
        let t = 0.2;
        // Constant E: P_a(N) = E/T for all N.
        let p = running_average_power(&[3e-6; 50], t).unwrap();
        assert!(p.iter().all(|v| (v - 3e-6 / t).abs() <= 1e-15 * 3e-6 / t));
        // E_n = n: P_a(N) = (N + 1) / (2T).
        let e: Vec<f64> = (1..=1000).map(|n| n as f64).collect();
        let p = running_average_power(&e, t).unwrap();
        for (i, v) in p.iter().enumerate() {
            let big_n = (i + 1) as f64;
            assert_relative_eq!(*v, (big_n + 1.0) / (2.0 * t), max_relative = 1e-15);
        }
        // A decaying transient on top of a steady level: E_n = E∞ + D qⁿ gives
        // P_a(N) = (N E∞ + D q (1 − q^N)/(1 − q)) / (N T), tending to E∞/T.
        let (e_inf, d, q) = (1e-5, 4e-5, 0.9f64);
        let e: Vec<f64> = (1..=400).map(|n| e_inf + d * q.powi(n)).collect();
        let p = running_average_power(&e, t).unwrap();
        for big_n in [1usize, 10, 100, 400] {
            let nf = big_n as f64;
            let want = (nf * e_inf + d * q * (1.0 - q.powi(big_n as i32)) / (1.0 - q)) / (nf * t);
            assert_relative_eq!(p[big_n - 1], want, max_relative = 1e-13);
        }
    }

    #[test]
    fn mean_after_the_transient_skips_it() {
        let t = 0.5;
        let mut e = vec![100.0; 10];
        e.extend([1.0, 3.0, 1.0, 3.0]);
        assert_relative_eq!(mean_power(&e, t, 10).unwrap(), 2.0 / t, max_relative = 1e-15);
        assert_relative_eq!(
            mean_power(&e, t, 0).unwrap(),
            1008.0 / (14.0 * t),
            max_relative = 1e-15
        );
        // With no transient it is the last running average.
        let last = *running_average_power(&e, t).unwrap().last().unwrap();
        assert_relative_eq!(mean_power(&e, t, 0).unwrap(), last, max_relative = 1e-15);
    }

    #[test]
    fn compensated_sum_keeps_tiny_energies_next_to_a_large_one() {
        // 1 followed by 10⁶ copies of 1e-16: a naive sum stays at 1 exactly.
        let mut e = vec![1.0];
        e.extend(std::iter::repeat_n(1e-16, 1_000_000));
        let want = (1.0 + 1e-10) / (e.len() as f64);
        assert_relative_eq!(mean_power(&e, 1.0, 0).unwrap(), want, max_relative = 1e-15);
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        assert!(matches!(
            running_average_power(&[], 1.0),
            Err(AnalysisError::Empty { .. })
        ));
        assert!(running_average_power(&[1.0], 0.0).is_err());
        assert!(running_average_power(&[1.0], f64::NAN).is_err());
        assert!(matches!(
            running_average_power(&[1.0, f64::NAN], 1.0),
            Err(AnalysisError::NonFinite { index: 1, .. })
        ));
        assert!(matches!(
            mean_power(&[1.0, 2.0], 1.0, 2),
            Err(AnalysisError::TooShort { .. })
        ));
        assert!(mean_power(&[], 1.0, 0).is_err());
    }
}
