//! External forces on the masses: constant ones ([`ChainParams::forces`]) and polynomials in
//! time set on a running [`Simulator`](crate::Simulator) ([`ForcePolynomial`],
//! [`Simulator::set_external_forces`](crate::Simulator::set_external_forces)).
//!
//! An external force acts on one mass along the x axis of docs/MODEL.md (upward positive),
//! next to its spring and dashpot: `m_i x_i'' + c_i (x_i' − y') + k_i (x_i − y) = F_i + f_i(t)`.
//! Uses: gravity on a vertical stack (`F_i = −m_i g`), the electrostatic force between the
//! plates of a triboelectric transducer.

use crate::error::{ParamError, check, check_finite};

use super::ChainParams;

/// Highest degree of a [`ForcePolynomial`].
pub const MAX_FORCE_DEGREE: usize = crate::dynamics::poly::MAX_DEGREE;

// The validation message spells the limit out (it said "degree 8" long after the limit had
// become 12): change it with the limit.
const _: () = assert!(
    MAX_FORCE_DEGREE == 12,
    "update the message in ForcePolynomial::validate"
);

/// An external force on one mass as a polynomial in time,
/// `f(t) = Σ_j c_j (t − t_ref)^j`, N, of degree at most [`MAX_FORCE_DEGREE`].
///
/// ```
/// use vibrotribo::ForcePolynomial;
///
/// // 0.1 N rising by 2 N/s from t = 1 s.
/// let f = ForcePolynomial::new(1.0, vec![0.1, 2.0]);
/// assert!((f.value(1.5) - 1.1).abs() < 1e-15);
/// ```
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ForcePolynomial {
    /// Reference time t_ref, s.
    pub t_ref: f64,
    /// Coefficients c_0, c_1, …, in N/s^j (at most [`MAX_FORCE_DEGREE`] + 1; empty: no
    /// force).
    pub coefficients: Vec<f64>,
}

impl ForcePolynomial {
    /// `Σ_j coefficients[j] (t − t_ref)^j`, N.
    pub fn new(t_ref: f64, coefficients: Vec<f64>) -> Self {
        ForcePolynomial { t_ref, coefficients }
    }

    /// No force.
    pub fn zero() -> Self {
        ForcePolynomial::default()
    }

    /// The force at time `t`, s, N.
    pub fn value(&self, t: f64) -> f64 {
        let x = t - self.t_ref;
        self.coefficients.iter().rev().fold(0.0, |acc, &c| acc * x + c)
    }

    /// Whether [`validate`](Self::validate) passes (without building names).
    pub(crate) fn is_valid(&self) -> bool {
        self.t_ref.is_finite()
            && self.coefficients.len() <= MAX_FORCE_DEGREE + 1
            && self.coefficients.iter().all(|c| c.is_finite())
    }

    /// Checks degree and finiteness; `name` is how the caller names this polynomial
    /// (`forces[1]`): errors name `forces[1].t_ref` or `forces[1].coefficients[j]`.
    pub fn validate(&self, name: &str) -> Result<(), ParamError> {
        if self.is_valid() {
            return Ok(());
        }
        let len = self.coefficients.len();
        check_finite(&format!("{name}.t_ref"), self.t_ref)?;
        check(
            format!("{name}.coefficients"),
            len as f64,
            len <= MAX_FORCE_DEGREE + 1,
            "must have at most 13 entries (degree 12)",
        )?;
        for (j, &c) in self.coefficients.iter().enumerate() {
            check_finite(&format!("{name}.coefficients[{j}]"), c)?;
        }
        Ok(())
    }
}

impl ChainParams {
    /// The constant external force on mass `i`, N (zero if [`forces`](Self::forces) is
    /// empty).
    pub fn force(&self, i: usize) -> f64 {
        self.forces.get(i).copied().unwrap_or(0.0)
    }

    /// Checks [`forces`](Self::forces): empty, or one finite value per mass.
    pub(super) fn validate_forces(&self) -> Result<(), ParamError> {
        if self.forces.is_empty() {
            return Ok(());
        }
        super::check_len("forces", &self.forces, self.len())?;
        for (i, &f) in self.forces.iter().enumerate() {
            check_finite(&format!("forces[{i}]"), f)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_degree_limit_is_the_one_the_message_names() {
        let at_limit = ForcePolynomial {
            t_ref: 0.0,
            coefficients: vec![1.0; MAX_FORCE_DEGREE + 1],
        };
        assert!(at_limit.validate("forces[0]").is_ok());
        let over = ForcePolynomial {
            t_ref: 0.0,
            coefficients: vec![1.0; MAX_FORCE_DEGREE + 2],
        };
        let message = over.validate("forces[0]").unwrap_err().to_string();
        assert!(message.contains("forces[0].coefficients"), "{message}");
        assert!(
            message.contains(&format!(
                "at most {} entries (degree {MAX_FORCE_DEGREE})",
                MAX_FORCE_DEGREE + 1
            )),
            "{message}"
        );
    }
}
