//! Parameters and state of the vibro-impact chain, and their validation.
//!
//! The chain (seed paper Sect. 2, generalised to N ≥ 2 masses): masses `m_1` (top) to `m_N`
//! (bottom), each tied to a common base by a spring `k_i` and a dashpot `c_i`. The base moves
//! as `y(t) = A sin(ω t)`. Displacements `x_i` are measured upward from each mass's static
//! position; away from contact (seed eq. 1)
//!
//! ```text
//! m_i x_i'' + c_i (x_i' − y') + k_i (x_i − y) = 0
//! ```
//!
//! Gap `k` (between mass `k` and `k+1`, seed eq. 2): `d_k = δ_k − (x_{k+1} − x_k) ≥ 0`.
//!
//! Optional rigid stops above the top mass and below the bottom one ([`Stops`], in
//! `stops.rs`: geometry and contact numbering) make a chain of a single mass possible.
//!
//! Physical inputs live in [`ChainParams`]; numerical settings in
//! [`SimOptions`]. Validate once with [`ChainParams::validate`].

use crate::error::{ParamError, check, check_finite, check_non_negative, check_positive};

mod forces;
mod stops;

pub use forces::{ForcePolynomial, MAX_FORCE_DEGREE};
pub use stops::{Contact, Stop, StopFrame, StopSide, Stops};

/// How the excitation frequency is given.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Frequency {
    /// Ω = ω / Ω₁ with Ω₁ = √(k₁/m₁), the paper's nondimensional frequency (relative to the
    /// *top* mass's natural frequency). Dimensionless.
    OmegaRatio(f64),
    /// Excitation frequency f = ω / 2π, Hz.
    Hertz(f64),
}

impl Default for Frequency {
    /// The paper's default Ω = 0.70.
    fn default() -> Self {
        Frequency::OmegaRatio(0.70)
    }
}

/// Harmonic base excitation `y(t) = A sin(ω t)`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Excitation {
    /// Base displacement amplitude A, m. Default 0.08 m (paper Sect. 4.1).
    pub amplitude: f64,
    /// Excitation frequency. Default Ω = 0.70.
    pub frequency: Frequency,
}

impl Default for Excitation {
    fn default() -> Self {
        Excitation {
            amplitude: 0.08,
            frequency: Frequency::default(),
        }
    }
}

/// Largest ratio of the heaviest to the lightest mass of a chain: 10¹².
pub const MAX_MASS_SPREAD: f64 = 1e12;

/// Physical parameters of an N-mass vibro-impact chain.
///
/// [`Default`] is the paper's default case (Sect. 4.1, configuration (1), m₂ = 120 g,
/// R_m = 2.5, Ω = 0.70).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ChainParams {
    /// Masses m₁ (top) … m_N (bottom), kg. Default `[0.048, 0.12, 0.048]`.
    pub masses: Vec<f64>,
    /// Spring stiffnesses k_i to the base, N/m. Default 120 N/m each.
    pub stiffness: Vec<f64>,
    /// Damping coefficients c_i to the base, N·s/m. Default 0.02 N·s/m each.
    pub damping: Vec<f64>,
    /// Initial gaps δ_k between mass k and k+1 (length N − 1), m. Default 20 mm each.
    pub gaps: Vec<f64>,
    /// Newton coefficient of restitution μ ∈ [0, 1], dimensionless. Default 0.6.
    pub restitution: f64,
    /// Base excitation.
    pub excitation: Excitation,
    /// Rigid stops above the top mass and below the bottom mass (see [`Stops`]). Default
    /// none.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Stops::is_empty"))]
    pub stops: Stops,
    /// Constant external forces F_i on the masses, N, positive along x (upward, docs/MODEL.md):
    /// one per mass, or empty for none. They add to the spring and dashpot forces,
    /// `m_i x_i'' + c_i (x_i' − y') + k_i (x_i − y) = F_i`, e.g. gravity `F_i = −m_i g` on a
    /// vertical stack (see also [`Simulator::set_external_forces`](crate::Simulator::set_external_forces)
    /// for forces that vary in time). Default none.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Vec::is_empty"))]
    pub forces: Vec<f64>,
}

impl Default for ChainParams {
    fn default() -> Self {
        ChainParams {
            masses: vec![0.048, 0.12, 0.048],
            stiffness: vec![120.0; 3],
            damping: vec![0.02; 3],
            gaps: vec![0.020; 2],
            restitution: 0.6,
            excitation: Excitation::default(),
            stops: Stops::default(),
            forces: Vec::new(),
        }
    }
}

impl ChainParams {
    /// The paper's chatter case (Sect. 4.4, Figs. 20–25): m₁ = m₃ = 50 g, R_m = 3 (m₂ = 150 g),
    /// δ₁ = δ₂ = 5 mm, Ω = 0.60, other parameters as [`Default`].
    pub fn paper_chatter_case() -> Self {
        ChainParams {
            masses: vec![0.05, 0.15, 0.05],
            gaps: vec![0.005, 0.005],
            excitation: Excitation {
                frequency: Frequency::OmegaRatio(0.60),
                ..Excitation::default()
            },
            ..ChainParams::default()
        }
    }
}

fn check_len(name: &str, v: &[f64], expected: usize) -> Result<(), ParamError> {
    if v.len() == expected {
        Ok(())
    } else {
        Err(ParamError::Length {
            name: name.to_string(),
            expected,
            got: v.len(),
        })
    }
}

impl ChainParams {
    /// Number of masses N.
    pub fn len(&self) -> usize {
        self.masses.len()
    }

    /// Always false for a valid chain (N ≥ 1); provided for API completeness.
    pub fn is_empty(&self) -> bool {
        self.masses.is_empty()
    }

    /// Checks every parameter (masses within a factor [`MAX_MASS_SPREAD`] of each other);
    /// returns the first problem found, naming the parameter by its
    /// field (`masses[1]`, `excitation.amplitude`, `excitation.omega_ratio`, …).
    pub fn validate(&self) -> Result<(), ParamError> {
        let n = self.masses.len();
        if n < 2 && (n == 0 || self.stops.is_empty()) {
            return Err(ParamError::TooFewMasses(n));
        }
        check_len("stiffness", &self.stiffness, n)?;
        check_len("damping", &self.damping, n)?;
        check_len("gaps", &self.gaps, n - 1)?;
        for (i, &m) in self.masses.iter().enumerate() {
            check_positive(&format!("masses[{i}]"), m)?;
        }
        // Beyond this spread the impact law loses the light mass's momentum to rounding
        // (masses of 1e300 and 0.1 kg interpenetrate by centimetres).
        let (lightest, heaviest) = self
            .masses
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), &m| (lo.min(m), hi.max(m)));
        if heaviest / lightest > MAX_MASS_SPREAD {
            return Err(ParamError::Invalid {
                name: "masses".into(),
                value: heaviest / lightest,
                reason: "the heaviest mass is more than 1e12 times the lightest (beyond what the impact law resolves in double precision)",
            });
        }
        for (i, &k) in self.stiffness.iter().enumerate() {
            check_positive(&format!("stiffness[{i}]"), k)?;
        }
        for (i, &c) in self.damping.iter().enumerate() {
            check_non_negative(&format!("damping[{i}]"), c)?;
        }
        for (i, &d) in self.gaps.iter().enumerate() {
            check_non_negative(&format!("gaps[{i}]"), d)?;
        }
        let mu = self.restitution;
        check_finite("restitution", mu)?;
        check("restitution", mu, (0.0..=1.0).contains(&mu), "must lie in [0, 1]")?;
        check_non_negative("excitation.amplitude", self.excitation.amplitude)?;
        match self.excitation.frequency {
            Frequency::OmegaRatio(w) => check_positive("excitation.omega_ratio", w)?,
            Frequency::Hertz(f) => check_positive("excitation.frequency_hz", f)?,
        }
        self.validate_forces()?;
        self.validate_stops()
    }

    /// Natural frequency of the top mass Ω₁ = √(k₁/m₁), rad/s (the paper's frequency unit).
    pub fn omega1(&self) -> f64 {
        (self.stiffness[0] / self.masses[0]).sqrt()
    }

    /// Excitation angular frequency ω, rad/s.
    pub fn omega(&self) -> f64 {
        match self.excitation.frequency {
            Frequency::OmegaRatio(r) => r * self.omega1(),
            Frequency::Hertz(f) => 2.0 * std::f64::consts::PI * f,
        }
    }

    /// Nondimensional excitation frequency Ω = ω/Ω₁.
    pub fn omega_ratio(&self) -> f64 {
        self.omega() / self.omega1()
    }

    /// Excitation period T = 2π/ω, s.
    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.omega()
    }

    /// The paper's nondimensional groups (seed eqs. 3–6). A single mass with a stop takes the
    /// stop's gap for δ₁ (the upper stop's if it has both) and has R_m = NaN.
    pub fn nondimensional(&self) -> NondimGroups {
        let w1 = self.omega1();
        let first_gap = match (self.gaps.first(), self.stops.upper, self.stops.lower) {
            (Some(&g), _, _) => g,
            (None, Some(s), _) | (None, None, Some(s)) => s.gap,
            (None, None, None) => f64::NAN,
        };
        NondimGroups {
            damping_ratios: (0..self.len())
                .map(|i| self.damping[i] / (2.0 * (self.masses[i] * self.stiffness[i]).sqrt()))
                .collect(),
            frequency_ratios: (0..self.len())
                .map(|i| (self.stiffness[i] / self.masses[i]).sqrt() / w1)
                .collect(),
            amplitude_ratio: self.excitation.amplitude / first_gap,
            omega_ratio: self.omega_ratio(),
            mass_ratio: self.masses.get(1).map_or(f64::NAN, |m| m / self.masses[0]),
            gap_ratio: if self.gaps.len() > 1 {
                Some(self.gaps[1] / self.gaps[0])
            } else {
                None
            },
            time_scale: 1.0 / w1,
            length_scale: first_gap,
        }
    }

    /// Checks an initial state against the chain: lengths, finiteness, no interpenetration
    /// (and no mass beyond a stop, with the base at its position of time 0).
    pub fn validate_state(&self, state: &ChainState) -> Result<(), ParamError> {
        self.validate_state_at(state, 0.0)
    }

    /// [`validate_state`](Self::validate_state) for a state at time `t`, s (where a stop
    /// that moves with the base stands).
    pub fn validate_state_at(&self, state: &ChainState, t: f64) -> Result<(), ParamError> {
        let n = self.len();
        check_len("positions", &state.positions, n)?;
        check_len("velocities", &state.velocities, n)?;
        for (i, &x) in state.positions.iter().enumerate() {
            check_finite(&format!("positions[{i}]"), x)?;
        }
        for (i, &v) in state.velocities.iter().enumerate() {
            check_finite(&format!("velocities[{i}]"), v)?;
        }
        for k in 0..n - 1 {
            let gap = self.gaps[k] - (state.positions[k + 1] - state.positions[k]);
            // A gap closed to rounding is contact, not interpenetration.
            let tol = 1e-12 * self.gaps[k].max(self.excitation.amplitude).max(1e-9);
            if gap < -tol {
                return Err(ParamError::Interpenetration { contact: k + 1, gap });
            }
        }
        if self.stops.is_empty() {
            Ok(())
        } else {
            self.validate_state_stops(&state.positions, t)
        }
    }
}

/// The paper's nondimensional groups derived from a [`ChainParams`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct NondimGroups {
    /// ζ_i = c_i / (2√(m_i k_i)), dimensionless.
    pub damping_ratios: Vec<f64>,
    /// Ω_i/Ω₁ with Ω_i = √(k_i/m_i), dimensionless.
    pub frequency_ratios: Vec<f64>,
    /// A/δ₁, dimensionless.
    #[cfg_attr(feature = "serde", serde(deserialize_with = "null_as_nan"))]
    pub amplitude_ratio: f64,
    /// Ω = ω/Ω₁, dimensionless.
    #[cfg_attr(feature = "serde", serde(deserialize_with = "null_as_nan"))]
    pub omega_ratio: f64,
    /// R_m = m₂/m₁, dimensionless.
    #[cfg_attr(feature = "serde", serde(deserialize_with = "null_as_nan"))]
    pub mass_ratio: f64,
    /// R_δ = δ₂/δ₁ (None for N = 2), dimensionless.
    pub gap_ratio: Option<f64>,
    /// t_c = √(m₁/k₁), s (τ = t/t_c).
    #[cfg_attr(feature = "serde", serde(deserialize_with = "null_as_nan"))]
    pub time_scale: f64,
    /// x_c = δ₁, m (X_i = x_i/δ₁).
    #[cfg_attr(feature = "serde", serde(deserialize_with = "null_as_nan"))]
    pub length_scale: f64,
}

/// A number written `null` where it is not finite (serde_json writes NaN and ±∞ so), read
/// back as NaN.
#[cfg(feature = "serde")]
fn null_as_nan<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    <Option<f64> as serde::Deserialize>::deserialize(d).map(|x| x.unwrap_or(f64::NAN))
}

/// Positions and velocities of all masses.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ChainState {
    /// Displacements x_i from static equilibrium, m (upward positive).
    pub positions: Vec<f64>,
    /// Velocities x_i', m/s.
    pub velocities: Vec<f64>,
}

impl ChainState {
    /// All masses at rest at their static positions.
    pub fn at_rest(n: usize) -> Self {
        ChainState {
            positions: vec![0.0; n],
            velocities: vec![0.0; n],
        }
    }
}

/// Numerical settings of the event-driven simulator (the `[options]` table of a
/// configuration).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct SimOptions {
    /// Guard against pathological motion: at most this many events (impacts, sticks,
    /// releases) within one excitation period before the run stops with
    /// [`SimError::EventLimit`](crate::SimError::EventLimit). Default 20 000.
    pub max_events_per_period: usize,
    /// Accuracy of a chatter accumulation-point jump, as a fraction of the excitation period.
    /// A geometric impact sequence is replaced by its limit (Budd & Dux) once the estimated
    /// error of the constant-acceleration approximation is below `chatter_tolerance · T`, or
    /// below the rounding error with which the next tiny bounce could be timed if resolved
    /// individually (gap rounding / rebound speed), whichever is larger. Default 1e-12.
    pub chatter_tolerance: f64,
    /// Upper bound on pairwise impacts applied when resolving one simultaneous impact.
    /// Default 10 000.
    pub max_impact_iterations: usize,
}

impl Default for SimOptions {
    fn default() -> Self {
        SimOptions {
            max_events_per_period: 20_000,
            chatter_tolerance: 1e-12,
            max_impact_iterations: 10_000,
        }
    }
}

impl SimOptions {
    /// Checks the options.
    pub fn validate(&self) -> Result<(), ParamError> {
        check(
            "max_events_per_period",
            self.max_events_per_period as f64,
            self.max_events_per_period > 0,
            "must be positive",
        )?;
        check_positive("chatter_tolerance", self.chatter_tolerance)?;
        check(
            "chatter_tolerance",
            self.chatter_tolerance,
            self.chatter_tolerance < 1e-2,
            "must be below 1e-2",
        )?;
        check(
            "max_impact_iterations",
            self.max_impact_iterations as f64,
            self.max_impact_iterations > 0,
            "must be positive",
        )
    }
}
