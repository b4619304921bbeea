//! Exact sensitivities of the non-smooth flow: the state-transition matrix (STM)
//! `Φ(t₁, t₀) = ∂z(t₁)/∂z(t₀)` of the simulator's flow map, `z = [x₁ … x_N, v₁ … v_N]` (m,
//! m/s), and the derivative of the flow map with respect to a parameter.
//!
//! [`Sensitivity`] is an [`Observer`](crate::Observer): attached to a run it composes the
//! Jacobian of each piece of closed-form flow with the saltation matrix of each event, and
//! reports a point where the flow map is not differentiable ([`NonSmoothPoint`]) instead of a
//! meaningless matrix. [`flow_map`] runs a chain from a state and returns the end state with
//! Φ; [`parameter_derivative`] differentiates the flow map with respect to any scalar that
//! changes [`ChainParams`](crate::ChainParams).
//!
//! # Between events
//!
//! Each cluster G (see [`Simulator`](crate::Simulator)) is a linear oscillator in its
//! coordinate `s` (top member's position) and velocity `s'`, with the closed form
//! `s(t) = s_p(t) + h(t − t₀)` of [`Oscillator`](crate::dynamics::Oscillator). The forced
//! part does not depend on the initial state, so
//!
//! ```text
//! ∂(s, s')(t) / ∂(s, s')(t₀) = [[c + αs, s], [−ω_n² s, c − αs]],   (c, s) = e^{−ατ}(cos ω_dτ, sin ω_dτ / ω_d)
//! ```
//!
//! (hyperbolic or polynomial in the other damping regimes, τ = t − t₀). In the full state a
//! cluster's members share `s` and `s'`: their rows of Φ are that 2 × 2 Jacobian applied to
//! the mass-weighted means `Σ m_i Φ_{x_i,·}/M` and `Σ m_i Φ_{v_i,·}/M`, the extension the
//! simulator uses when it merges masses. Inside a stuck cluster Φ is therefore a projection
//! onto the constrained subspace (members move rigidly): its rank drops by 2 per stuck
//! contact, and a Floquet multiplier of an orbit with a contact stuck over the whole period
//! is 0 in those directions.
//!
//! # Saltation matrices
//!
//! At an event on the surface `h(z, t) = 0` with reset `z⁺ = g(z⁻)` and fields `f⁻`, `f⁺`
//! before and after, a perturbation `δz⁻` just before (at the nominal time) maps to
//!
//! ```text
//! δz⁺ = S δz⁻,    S = G + (f⁺ − G f⁻) ∇hᵀ / (∇h·f⁻ + ∂h/∂t),    G = ∂g/∂z,
//! ```
//!
//! from the perturbed event time `δτ = −∇h·δz⁻ / (∇h·f⁻ + ∂h/∂t)` and
//! `δz⁺ = G (δz⁻ + f⁻δτ) − f⁺δτ`.
//!
//! **Impact** at contact k between clusters U (holding mass k) and L (mass k + 1): the
//! event function is the gap `d_k = δ_k − (x_{k+1} − x_k)`, so `∇h = e_{x_k} − e_{x_{k+1}}`,
//! `∂h/∂t = 0` and `∇h·f⁻ = −v_c` with the closing speed `v_c = V_L − V_U`. Newton's law
//! with momentum conservation (seed eqs. 7–8 with cluster masses) changes only velocities:
//!
//! ```text
//! v_i⁺ = v_i + (1 + μ) M_L/(M_U + M_L) ΔV   (i ∈ U),     v_i⁺ = v_i − (1 + μ) M_U/(M_U + M_L) ΔV   (i ∈ L),
//! ΔV = Σ_{L} m_i v_i / M_L − Σ_{U} m_i v_i / M_U,
//! ```
//!
//! which is linear, so R = G is that map itself, and `S = R + (f⁺ − R f⁻) ∇d_kᵀ / (∇d_k·f⁻)`.
//! The gap perturbation after is `(∇d·δz)·ḋ⁺/ḋ⁻ = −μ ∇d·δz`.
//!
//! **Stick**: a contact closes with zero relative velocity. After an impact this is the
//! plastic case: the same formula with μ = 0 (R merges U and L into their centre-of-mass
//! velocity) and f⁺ the merged cluster's field; then `ḋ⁺ = 0`, so S maps into the
//! constrained subspace of the new cluster and the dimension of the image drops by 2 (gap
//! and relative velocity are no longer free). A stick at a chatter accumulation point needs
//! nothing: the two sides already move as one cluster (below).
//!
//! **Release**: the contact force `N_j(z, t)` of a stuck contact reaches zero. The force is
//! exactly what holds the two sub-clusters together, so at `N_j = 0` their free accelerations
//! equal the merged cluster's: `f⁺ = f⁻`, no reset (G = I), and `S = I`. The release time
//! still depends on the state, but to first order it does not matter when the constraint is
//! dropped; the dimension returns through the flow after it (perturbations of gap and
//! relative velocity grow from zero at second order).
//!
//! **Rigid stops** ([`Stops`](crate::Stops)): an impact against a stop, or against a cluster
//! stuck to one, changes the free cluster only, and the stop's gap depends on time
//! explicitly; a cluster stuck to a stop follows the stop (its rows of Φ are zero). The
//! saltation matrices for these, sticking to a stop and chatter jumps against one included,
//! are derived in `stops.rs`.
//!
//! **Chatter accumulation point**, as [`Simulator`](crate::Simulator) implements it: at the
//! impact that starts a jump (a rebound `u = μ v_c` under a closing acceleration `a`) the
//! simulator applies Newton's law and then merges the two sides momentum-conservingly, so the
//! map at the impact is the *plastic* one (momentum is the same before and after Newton's
//! law): the impact formula with μ = 0 and f⁺ the merged field. The merged cluster moves as
//! one until
//!
//! ```text
//! t_acc = τ + 2u / ((1 − μ) a),     a = a_L⁺ − a_U⁺,
//! ```
//!
//! (Budd & Dux), where a_U⁺, a_L⁺ are the two sides' free accelerations with the velocities
//! just after Newton's law, all at the impact time τ. There the contact sticks (state and
//! field continuous: nothing to add) or releases. On release the state is continuous but the
//! field jumps from the merged `f_m` to the split `f_s`, at a time that depends on the state
//! at the impact:
//!
//! ```text
//! δz(t_acc⁺) = δz(t_acc⁻) + (f_m − f_s) δt_acc,
//! δt_acc = δτ + (t_acc − τ)(δv_c / v_c − δa / a),    δτ = (δx_k − δx_{k+1}) / v_c,
//! ```
//!
//! where `δv_c` and `δa` are taken on the state at the perturbed impact time,
//! `δz⁻ + f⁻ δτ`, and δa includes the impulse's dependence on v_c
//! (`(1+μ) m_red (C_L/M_L² + C_U/M_U²) δv_c`) and the forcing's explicit time dependence
//! (`∂a_X/∂t = (C_X y'' + K_X y')/M_X`). The observer stores `∇t_acc·Φ(τ⁻)` when the jump is
//! scheduled and adds the rank-one term at t_acc if the sides release. A chatter interval
//! ended early by a release (force zero) is an ordinary release.
//!
//! # Non-differentiable points
//!
//! [`NonSmoothPoint::Grazing`]: an impact with closing speed below
//! [`SensitivityOptions::grazing_speed`] (S carries 1/v_c; at v_c = 0 the map has a
//! square-root singularity: a nearby trajectory misses the contact or hits it with speed ∝
//! √distance). Near grazing Φ is exact but large, and finite differences agree with it only
//! for steps much smaller than the distance to grazing.
//! [`NonSmoothPoint::Simultaneous`]: several contacts struck at one instant (the pairwise
//! resolution depends on the order), an impact while another contact touches, or several
//! closures changing at once. A touch at exactly zero gap that changes nothing is not seen.
//!
//! # Parameters
//!
//! [`parameter_derivative`] takes a family `Fn(f64) -> ChainParams` and differentiates the
//! flow map (to a fixed time or to a number of excitation periods, whose length may depend
//! on the parameter) by central differences of the exact flow map, with a Richardson error
//! estimate: every parameter (frequency, amplitude, masses, gaps, restitution, …) enters the
//! closed form, the event surfaces and the resets, and the differences of the exact map are
//! accurate to ~1e-10 relative away from grazing.

mod error;
mod field;
mod flow_map;
mod saltation;
mod stm;
mod stops;

pub use error::{NonSmoothPoint, SensitivityError};
pub(crate) use flow_map::EventRecorder;
pub use flow_map::{
    DerivativeOptions, FlowMap, Horizon, ParameterDerivative, flow_map, parameter_derivative,
    state_from_vector, state_vector,
};
pub use stm::{EventSensitivity, Sensitivity, SensitivityOptions, length_scale, speed_scale};
