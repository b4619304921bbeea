//! The boundary layer term `δ·φ(t)` of a step (see `layer.rs`, which builds it), and the
//! layer's energy: its decay `K(θ) = ∫k dt` and its energy `∫ G e²(2wδφ + δ²φ²) dt`, from the
//! step's interpolants, in closed form and by Gauss–Laguerre quadrature in the layer's own
//! scaled time.

/// Terms of a polynomial in θ of degree ≤ 8 (an interpolant on the 7-stage nodes and its
/// integral).
pub(super) const MONO_TERMS: usize = 9;

/// Nodes of 10-point Gauss–Laguerre quadrature, `∫₀^∞ e^(−s) f(s) ds ≈ Σ wᵢ f(xᵢ)` (numpy's
/// `laggauss(10)`; exact for polynomials of degree ≤ 19). Each term of the layer's energy is
/// taken in its own scaled time, where its integrand is smooth and nearly constant.
const LAGUERRE_X: [f64; 10] = [
    0.1377934705404926,
    0.729454549503171,
    1.8083429017403159,
    3.4014336978548996,
    5.552496140063804,
    8.330152746764497,
    11.843785837900066,
    16.279257831378104,
    21.99658581198076,
    29.92069701227389,
];

/// Weights of the same quadrature.
const LAGUERRE_W: [f64; 10] = [
    0.3084411157650173,
    0.4011199291552761,
    0.2180682876118096,
    0.062087456098677773,
    0.0095015169751811,
    0.0007530083885875384,
    2.8259233495995642e-05,
    4.249313984962698e-07,
    1.839564823979633e-09,
    9.91182721960906e-13,
];

/// Beyond this `∫k dt` the layer's remaining energy is taken as zero (`e^(−60)`).
const NEGLIGIBLE_DECAY: f64 = 60.0;

/// Coefficients of a polynomial in θ ∈ [0, 1] (θ = (t − t₀)/h), lowest first; degree ≤ 8.
pub(super) type Mono = [f64; MONO_TERMS];

/// The layer term `δ·φ(t)` of a step and what its outputs need (the method: `layer.rs`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct LayerTerm {
    /// Layer amplitude δ = u(t₀) − w₀, C.
    pub(super) delta: f64,
    /// Load conductance G = 1/R, S.
    conductance: f64,
    /// Step length, s.
    h: f64,
    /// Elastance interpolant e(θ), 1/F.
    elastance: Mono,
    /// Slow charge interpolant w(θ), C.
    slow: Mono,
    /// `K(θ) = ∫_{t₀}^{t₀+θh} k dt` (dimensionless).
    decay: Mono,
    /// The layer's energy over the whole step, J.
    pub(super) energy: f64,
}

impl LayerTerm {
    /// The layer of amplitude `delta` (C) of a step of length `h` (s) into a load of
    /// conductance `conductance` (S), with the step's interpolants of the elastance (1/F) and
    /// of the slow charge (C): its decay `K` and its energy over the step follow.
    pub(super) fn new(delta: f64, conductance: f64, h: f64, elastance: Mono, slow: Mono) -> Self {
        let decay = integral(&elastance.map(|e| e * (conductance * h)));
        let mut layer = LayerTerm {
            delta,
            conductance,
            h,
            elastance,
            slow,
            decay,
            energy: 0.0,
        };
        layer.energy = layer.energy_after(0.0);
        layer
    }

    /// `φ(θ) = exp(−K(θ))`.
    pub(super) fn phi(&self, theta: f64) -> f64 {
        (-horner(&self.decay, theta)).exp()
    }

    /// The layer's energy `∫ G e²(2wδφ + δ²φ²) dt` from `t₀ + θh` to the layer's end, J.
    pub(super) fn energy_after(&self, theta: f64) -> f64 {
        let k_theta = horner(&self.decay, theta);
        if k_theta > NEGLIGIBLE_DECAY {
            return 0.0;
        }
        let phi0 = (-k_theta).exp();
        let rate = self.conductance * horner(&self.elastance, theta) * self.h; // dK/dθ
        if rate.is_nan() || rate <= 0.0 {
            return 0.0;
        }
        // Each term in its own scaled time s = m·(K(θ') − K(θ)) ≈ m·rate·(θ' − θ), m = 1, 2.
        let mut total = 0.0;
        for (m, weight) in [
            (1.0, 2.0 * self.delta * phi0),
            (2.0, self.delta * self.delta * phi0 * phi0),
        ] {
            let mut sum = 0.0;
            for (x, w) in LAGUERRE_X.iter().zip(&LAGUERRE_W) {
                let dtheta = x / (m * rate);
                let t = theta + dtheta;
                let e = horner(&self.elastance, t);
                let decay = horner(&self.decay, t) - k_theta;
                // φ(θ')^m / φ(θ)^m · e^{s}, s = x.
                let excess = (-(m * decay) + x).exp();
                let slow = if m == 1.0 { horner(&self.slow, t) } else { 1.0 };
                sum += w * self.conductance * e * e * slow * excess;
            }
            total += weight * sum * self.h / (m * rate);
        }
        total
    }

    /// The layer's energy from `t₀` to `t₀ + θh`, J.
    pub(super) fn energy_until(&self, theta: f64) -> f64 {
        self.energy - self.energy_after(theta)
    }
}

/// `Σ cⱼ θʲ`.
fn horner(c: &Mono, theta: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, cj| acc * theta + cj)
}

/// `∫₀^θ p` as monomial coefficients.
fn integral(p: &Mono) -> Mono {
    let mut q = [0.0; MONO_TERMS];
    for j in 0..q.len() - 1 {
        q[j + 1] = p[j] / (j + 1) as f64;
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layer_energy_of_constant_coefficients_is_the_closed_form() {
        // e, w constant: ∫₀^∞ G e² (2wδ e^(−kt) + δ² e^(−2kt)) dt = G e² (2wδ/k + δ²/(2k)).
        let (g, e, w, delta, h) = (1e-5, 2e10, 3e-12, -7e-11, 1e-3);
        let k = g * e;
        let mut elastance = [0.0; MONO_TERMS];
        elastance[0] = e;
        let mut slow = [0.0; MONO_TERMS];
        slow[0] = w;
        let layer = LayerTerm::new(delta, g, h, elastance, slow);
        let exact = g * e * e * (2.0 * w * delta / k + delta * delta / (2.0 * k));
        let got = layer.energy_after(0.0);
        assert!(
            (got - exact).abs() <= 1e-13 * exact.abs(),
            "{got:e} against {exact:e}"
        );
        // From θ: the tail e^(−kθh) (first term) and e^(−2kθh) (second).
        let theta = 0.3 / (k * h);
        let tail = g
            * e
            * e
            * (2.0 * w * delta / k * (-0.3_f64).exp() + delta * delta / (2.0 * k) * (-0.6_f64).exp());
        let got = layer.energy_after(theta);
        assert!(
            (got - tail).abs() <= 1e-13 * exact.abs(),
            "{got:e} against {tail:e}"
        );
        assert!((layer.phi(theta) - (-0.3_f64).exp()).abs() < 1e-15);
    }
}
