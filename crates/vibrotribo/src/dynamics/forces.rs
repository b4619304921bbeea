//! The external forces on the masses as the simulator applies them: the constant forces of
//! [`ChainParams::forces`], the time polynomials of
//! [`Simulator::set_external_forces`](super::Simulator::set_external_forces), and those of a
//! base motion other than the chain's harmonic ([`super::base`]); the two kinds of
//! polynomials add.
//!
//! In the closed form of a cluster (`M s'' + C s' + K s = F₀ + C y' + K y + f(t)`, see
//! [`super::oscillator`]) the constant forces join F₀ (so the static offset F₀/K takes them),
//! and the polynomial forcing `f(τ) = Σ f_j τ^j` of the cluster (the sum of its members')
//! adds the particular solution `p(τ)` of the same degree, found from the top coefficient
//! down: `K p_j = f_j − C (j+1) p_{j+1} − M (j+2)(j+1) p_{j+2}`.

use super::poly::Poly;
use crate::error::{ParamError, SimError};
use crate::model::{ChainParams, ForcePolynomial};

/// The external forces on the masses (module docs).
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct ExternalForces {
    /// Constant force on each mass, N; empty for none.
    constant: Vec<f64>,
    /// Polynomial force on each mass, N, all about one reference time; empty for none: the
    /// sum of `user` and `base`.
    poly: Vec<Poly>,
    /// The polynomials set by the caller ([`set_polynomials`](Self::set_polynomials)); empty
    /// for none.
    user: Vec<Poly>,
    /// The polynomials of the base motion ([`set_base`](Self::set_base)); empty for none.
    base: Vec<Poly>,
}

impl ExternalForces {
    /// The constant forces of `params` (validated), no polynomial.
    pub fn new(params: &ChainParams) -> Self {
        ExternalForces {
            constant: params.forces.clone(),
            poly: Vec::new(),
            user: Vec::new(),
            base: Vec::new(),
        }
    }

    /// Whether there is no external force at all (the engine then runs exactly as without
    /// this module).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.constant.is_empty() && self.poly.is_empty()
    }

    /// Makes `self` a copy of `other`, reusing its buffers.
    pub fn assign_from(&mut self, other: &ExternalForces) {
        self.constant.clone_from(&other.constant);
        self.poly.clone_from(&other.poly);
        self.user.clone_from(&other.user);
        self.base.clone_from(&other.base);
    }

    /// Whether time polynomials are set.
    #[inline]
    pub fn has_polynomials(&self) -> bool {
        !self.poly.is_empty()
    }

    /// Replaces the caller's polynomial forces by `forces` (one per mass of `n`, or none),
    /// each taken about the time `t_ref`, s, where they are summed with the base motion's.
    /// On an error nothing changes.
    pub fn set_polynomials(
        &mut self,
        forces: &[ForcePolynomial],
        n: usize,
        t_ref: f64,
    ) -> Result<(), SimError> {
        Self::load(&mut self.user, forces, n, t_ref)?;
        self.combine(t_ref);
        Ok(())
    }

    /// Replaces the base motion's polynomial forces by `forces` (one per mass of `n`, or
    /// none), as [`set_polynomials`](Self::set_polynomials).
    pub fn set_base(&mut self, forces: &[ForcePolynomial], n: usize, t_ref: f64) -> Result<(), SimError> {
        Self::load(&mut self.base, forces, n, t_ref)?;
        self.combine(t_ref);
        Ok(())
    }

    /// Validates `forces` and stores them in `layer` about `t_ref` (cleared if all are zero).
    fn load(layer: &mut Vec<Poly>, forces: &[ForcePolynomial], n: usize, t_ref: f64) -> Result<(), SimError> {
        if !forces.is_empty() && forces.len() != n {
            return Err(ParamError::Length {
                name: "forces".into(),
                expected: n,
                got: forces.len(),
            }
            .into());
        }
        for (i, f) in forces.iter().enumerate() {
            if !f.is_valid() {
                f.validate(&format!("forces[{i}]"))?;
            }
        }
        layer.clear();
        layer.extend(
            forces
                .iter()
                .map(|f| Poly::new(f.t_ref, &f.coefficients).shifted(t_ref)),
        );
        if layer.iter().all(Poly::is_zero) {
            layer.clear();
        }
        Ok(())
    }

    /// The applied polynomials: one layer as it is, or both summed about `t`, s.
    fn combine(&mut self, t: f64) {
        self.poly.clear();
        match (self.user.is_empty(), self.base.is_empty()) {
            (true, true) => {}
            (false, true) => self.poly.extend_from_slice(&self.user),
            (true, false) => self.poly.extend_from_slice(&self.base),
            (false, false) => {
                for (u, b) in self.user.iter().zip(&self.base) {
                    let mut p = u.shifted(t);
                    p.add_scaled(&b.shifted(t), 1.0);
                    self.poly.push(p);
                }
            }
        }
    }

    /// Σ of the constant forces on masses `first..=last`, N.
    #[inline]
    pub fn range_constant(&self, first: usize, last: usize) -> f64 {
        if self.constant.is_empty() {
            0.0
        } else {
            self.constant[first..=last].iter().sum()
        }
    }

    /// Σ of the polynomial forces on masses `first..=last`, N (zero if none).
    pub fn range_poly(&self, first: usize, last: usize) -> Poly {
        let mut p = Poly::ZERO;
        if let Some(members) = self.poly.get(first..=last) {
            for q in members {
                p.add_scaled(q, 1.0);
            }
        }
        p
    }

    /// The force on mass `i` at time `t`, N, and its rate, N/s.
    #[inline]
    pub fn at(&self, i: usize, t: f64) -> (f64, f64) {
        let c = self.constant.get(i).copied().unwrap_or(0.0);
        match self.poly.get(i) {
            Some(p) => {
                let (v, r) = p.value_and_rate(t);
                (c + v, r)
            }
            None => (c, 0.0),
        }
    }

    /// The force on masses `first..=last` at time `t`, N, and its rate, N/s.
    pub fn range_at(&self, first: usize, last: usize, t: f64) -> (f64, f64) {
        (first..=last).fold((0.0, 0.0), |(f, r), i| {
            let (fi, ri) = self.at(i, t);
            (f + fi, r + ri)
        })
    }

    /// The largest `|F_i(t)|/m_i` and the largest size of the terms of a polynomial force
    /// over its mass, `Σ_j |c_j| |t − t_ref|^j / m_i`, m/s²: the acceleration scale the forces
    /// add to the rounding of the contact decisions.
    pub fn accel_scale(&self, masses: &[f64], t: f64) -> f64 {
        let mut a = 0.0f64;
        for (i, &m) in masses.iter().enumerate() {
            let c = self.constant.get(i).copied().unwrap_or(0.0).abs();
            let p = self.poly.get(i).map_or(0.0, |p| p.magnitude_at(t));
            a = a.max((c + p) / m);
        }
        a
    }
}
