//! The contact laws of the chain, applied by the [`Simulator`](super::Simulator) at its events:
//!
//! - **Impact** (gap reaches zero while closing): Newton's restitution law between the two
//!   clusters that meet, with momentum conserved (seed eqs. 7–8 with m_p, m_q the cluster
//!   masses). *Simultaneous impacts* (several contacts closed and approaching at the same
//!   instant, or a cluster struck while touching a third body) are resolved by applying
//!   pairwise impacts, always to the contact with the largest closing speed (ties: lowest
//!   index), until no closed contact approaches. This is deterministic, converges for μ < 1
//!   and reproduces Newton's cradle for μ = 1.
//! - **Chatter**: after an impact with rebound speed u under a closing relative acceleration
//!   a, the remaining geometric sequence of impacts lasts `T∞ = 2u / ((1 − μ) a)` (Budd & Dux
//!   1994). Once the error of assuming a constant over that time is below
//!   [`SimOptions::chatter_tolerance`](crate::SimOptions::chatter_tolerance) periods, the two sides are merged and the simulator
//!   jumps to the accumulation time, where they stick or release.
//! - **Sticking**: contacts at zero gap with zero relative velocity carry forces λ ≥ 0 given
//!   by the linear complementarity problem `w = q + Wλ ≥ 0, λ ≥ 0, wᵀλ = 0` (q: gap
//!   accelerations of the free masses; W: the tridiagonal Delassus matrix of the chain, an
//!   M-matrix), solved exactly by Chandrasekaran's monotone active-set method. Inside a
//!   cluster this gives the corrected contact force of docs/MODEL.md §1,
//!   `N_j = Σ_{i≤j} m_i (a_G − a_i)`, not the paper's eqs. 9–10 (whose factor ½ is exact only
//!   for equal masses).
//! - **Release**: a closed contact opens when its force falls to zero.
//! - **Resting**: a contact at zero gap and zero relative velocity whose LCP force and gap
//!   acceleration are both zero to within rounding (`|w| ≤` the acceleration tolerance) is
//!   *resting*: touching with no force, as in a resting stack, Newton's cradle or masses with
//!   equal k/m that travel together. It is neither a stick nor an impact, so it logs no event;
//!   its two sides move as one cluster (their relative motion is then zero by construction,
//!   not by cancellation of two flows), and its force is watched instead of its gap: it
//!   becomes an ordinary stuck contact (a `Stick`) when the force rises above a band of a few
//!   times the rounding level, and parts silently when the force falls below minus that band
//!   (the hysteresis keeps the two decisions apart). An impact passes through resting contacts
//!   pairwise, as through open touching ones. Any touching contact that stays open has its
//!   rounding-level relative velocity removed (momentum-conserving), so that the exact flow
//!   does not carry the rounding of an impact elsewhere into a slow, spurious approach.
//!
//! The rooms: [`closure`] (the state of each contact, the clusters it makes, tolerances and
//! overlap removal), [`impact`] (Newton impacts and chatter jumps), [`sticking`] (the contact
//! LCP: stick, release, rest), [`stops`] (rigid stops: contacts with a body of infinite mass
//! and prescribed motion) and [`surfaces`] (the event functions the simulator searches).

mod closure;
mod impact;
mod sticking;
mod stops;
mod surfaces;

pub(super) use closure::Closure;
