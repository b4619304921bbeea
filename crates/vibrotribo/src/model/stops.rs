//! Rigid stops: obstacles of infinite mass above the top mass or below the bottom mass of the
//! chain, fixed in space or moving with the base, each with its own gap and restitution.
//!
//! # Geometry
//!
//! A stop's `gap` is its distance from the adjacent mass's static position (x = 0) with the
//! base at rest (y = 0). With `Y(t) = 0` for a stop fixed in space and `Y(t) = y(t) = A sin ωt`
//! for one moving with the base, the upper stop stands at `x₁ = gap + Y(t)` and the lower one
//! at `x_N = −gap + Y(t)`, and their gap functions are
//!
//! ```text
//! d_upper = gap − (x₁ − Y(t)) ≥ 0,        d_lower = gap − (Y(t) − x_N) ≥ 0,
//! ```
//!
//! the same form as the gap between two masses, `d_k = δ_k − (x_{k+1} − x_k)`, with the stop
//! as a body of infinite mass at position `Y(t)`. A single mass with a stop is the
//! harmonically forced impact oscillator of the textbooks (Shaw & Holmes 1983; di Bernardo et
//! al. 2008, ch. 1 and 6): with the stop fixed in space the mass obeys
//! `m x'' + c x' + k x = c y' + k y` below `x = gap`; with the stop moving with the base, in
//! the relative coordinate `z = x − y`, `m z'' + c z' + k z = −m y''` below `z = gap`.
//!
//! # Contacts
//!
//! Contact k (0-based) is the gap below mass k: contacts `0 … N−2` lie between neighbouring
//! masses. A chain with a stop has two more: contact `N − 1` is the lower stop (the gap below
//! the bottom mass, mass N − 1) and contact `N` the upper stop (above mass 0). A chain with
//! only one stop still numbers both ([`ChainParams::contact_count`] is N + 1); the absent one
//! never sees an event. In files and messages contacts are 1-based, `k + 1`
//! ([`ChainParams::contact_label`]): the masses' contacts `1 … N−1` as without stops (so no
//! existing column or number changes), the lower stop `N`, the upper stop `N + 1`.
//!
//! In the chain's spatial order the contacts read upper stop, 0, 1, …, N − 2, lower stop;
//! a stop is a neighbour of infinite mass, so it adds nothing to the Delassus matrix of the
//! sticking problem on its own side.

use crate::error::{ParamError, check, check_finite, check_non_negative};

use super::ChainParams;

/// Which end of the chain a stop bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum StopSide {
    /// Above the top mass (m₁).
    Upper,
    /// Below the bottom mass (m_N).
    Lower,
}

impl StopSide {
    /// `upper` or `lower`, as in parameter names (`stops.upper.gap`).
    pub fn as_str(self) -> &'static str {
        match self {
            StopSide::Upper => "upper",
            StopSide::Lower => "lower",
        }
    }
}

/// What a stop moves with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum StopFrame {
    /// Fixed in space: `Y(t) = 0`. The default.
    #[default]
    Fixed,
    /// Moving with the base: `Y(t) = y(t) = A sin ωt`.
    Base,
}

/// A rigid stop of infinite mass (see [`Stops`] for its geometry).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Stop {
    /// Distance from the adjacent mass's static position to the stop with the base at rest,
    /// m (≥ 0). No default.
    pub gap: f64,
    /// Newton coefficient of restitution r ∈ [0, 1] of impacts against the stop: the relative
    /// velocity after is −r times that before. Dimensionless. No default.
    pub restitution: f64,
    /// Fixed in space or moving with the base. Default [`StopFrame::Fixed`].
    #[cfg_attr(feature = "serde", serde(default))]
    pub frame: StopFrame,
}

/// The stops of a chain: none by default.
///
/// Rigid stops: obstacles of infinite mass above the top mass or below the bottom mass of the
/// chain, fixed in space or moving with the base, each with its own gap and restitution.
///
/// # Geometry
///
/// A stop's `gap` is its distance from the adjacent mass's static position (x = 0) with the
/// base at rest (y = 0). With `Y(t) = 0` for a stop fixed in space and `Y(t) = y(t) = A sin ωt`
/// for one moving with the base, the upper stop stands at `x₁ = gap + Y(t)` and the lower one
/// at `x_N = −gap + Y(t)`, and their gap functions are
///
/// ```text
/// d_upper = gap − (x₁ − Y(t)) ≥ 0,        d_lower = gap − (Y(t) − x_N) ≥ 0,
/// ```
///
/// the same form as the gap between two masses, `d_k = δ_k − (x_{k+1} − x_k)`, with the stop
/// as a body of infinite mass at position `Y(t)`. A single mass with a stop is the
/// harmonically forced impact oscillator of the textbooks (Shaw & Holmes 1983; di Bernardo et
/// al. 2008, ch. 1 and 6): with the stop fixed in space the mass obeys
/// `m x'' + c x' + k x = c y' + k y` below `x = gap`; with the stop moving with the base, in
/// the relative coordinate `z = x − y`, `m z'' + c z' + k z = −m y''` below `z = gap`.
///
/// # Contacts
///
/// Contact k (0-based) is the gap below mass k: contacts `0 … N−2` lie between neighbouring
/// masses. A chain with a stop has two more: contact `N − 1` is the lower stop (the gap below
/// the bottom mass, mass N − 1) and contact `N` the upper stop (above mass 0). A chain with
/// only one stop still numbers both ([`ChainParams::contact_count`] is N + 1); the absent one
/// never sees an event. In files and messages contacts are 1-based, `k + 1`
/// ([`ChainParams::contact_label`]): the masses' contacts `1 … N−1` as without stops (so no
/// existing column or number changes), the lower stop `N`, the upper stop `N + 1`.
///
/// In the chain's spatial order the contacts read upper stop, 0, 1, …, N − 2, lower stop;
/// a stop is a neighbour of infinite mass, so it adds nothing to the Delassus matrix of the
/// sticking problem on its own side.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct Stops {
    /// A stop above the top mass, if any.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub upper: Option<Stop>,
    /// A stop below the bottom mass, if any.
    #[cfg_attr(feature = "serde", serde(skip_serializing_if = "Option::is_none"))]
    pub lower: Option<Stop>,
}

impl Stops {
    /// No stop at all.
    pub fn is_empty(&self) -> bool {
        self.upper.is_none() && self.lower.is_none()
    }

    /// The stop on `side`, if any.
    pub fn get(&self, side: StopSide) -> Option<&Stop> {
        match side {
            StopSide::Upper => self.upper.as_ref(),
            StopSide::Lower => self.lower.as_ref(),
        }
    }
}

/// What a contact index of a chain designates (see [`Stops`] for the numbering).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Contact {
    /// The gap between mass `k` and mass `k + 1` (0-based).
    Masses(usize),
    /// A stop.
    Stop(StopSide),
}

impl ChainParams {
    /// Number of contact indices: N − 1 between masses, and two more (lower stop N − 1, upper
    /// stop N) if the chain has a stop.
    pub fn contact_count(&self) -> usize {
        let n = self.len();
        if self.stops.is_empty() {
            n.saturating_sub(1)
        } else {
            n + 1
        }
    }

    /// What contact `k` designates (`k < contact_count()`).
    pub fn contact(&self, k: usize) -> Contact {
        let n = self.len();
        if k + 1 < n {
            Contact::Masses(k)
        } else if k + 1 == n {
            Contact::Stop(StopSide::Lower)
        } else {
            Contact::Stop(StopSide::Upper)
        }
    }

    /// The contact index of the stop on `side`: N − 1 below, N above.
    pub fn stop_contact(&self, side: StopSide) -> usize {
        match side {
            StopSide::Lower => self.len() - 1,
            StopSide::Upper => self.len(),
        }
    }

    /// The 1-based number of contact `k` in files and messages, `k + 1`: the masses' contacts
    /// 1 … N − 1 (contact k between mass k and k + 1, 1-based), the lower stop N, the upper
    /// stop N + 1.
    pub fn contact_label(&self, k: usize) -> usize {
        k + 1
    }

    /// A short name of contact `k` for messages, with 1-based masses: `m1–m2`,
    /// `m1–upper stop`, `m3–lower stop`.
    pub fn contact_name(&self, k: usize) -> String {
        match self.contact(k) {
            Contact::Masses(j) => format!("m{}–m{}", j + 1, j + 2),
            Contact::Stop(StopSide::Upper) => "m1–upper stop".to_string(),
            Contact::Stop(StopSide::Lower) => format!("m{}–lower stop", self.len()),
        }
    }

    /// Whether contact `k` is a stop that exists.
    pub fn is_stop(&self, k: usize) -> bool {
        match self.contact(k) {
            Contact::Masses(_) => false,
            Contact::Stop(side) => self.stops.get(side).is_some(),
        }
    }

    /// Restitution of contact `k`: the chain's μ between masses, the stop's own r at a stop.
    pub fn contact_restitution(&self, k: usize) -> f64 {
        match self.contact(k) {
            Contact::Masses(_) => self.restitution,
            Contact::Stop(side) => self.stops.get(side).map_or(self.restitution, |s| s.restitution),
        }
    }

    /// Position `Y(t)` of the stop's frame, m, and its first three derivatives, at base
    /// displacement `y`, velocity `yd` (ω the excitation frequency): zero for a stop fixed in
    /// space, the base motion for one that moves with it.
    pub(crate) fn frame_motion(frame: StopFrame, y: f64, yd: f64, omega: f64) -> [f64; 4] {
        match frame {
            StopFrame::Fixed => [0.0; 4],
            StopFrame::Base => [y, yd, -omega * omega * y, -omega * omega * yd],
        }
    }

    /// Checks the stops (called by [`validate`](Self::validate)): gaps and restitutions in
    /// range, and room for the chain between two stops at all times.
    pub(super) fn validate_stops(&self) -> Result<(), ParamError> {
        for side in [StopSide::Upper, StopSide::Lower] {
            if let Some(stop) = self.stops.get(side) {
                let name = |field: &str| format!("stops.{}.{field}", side.as_str());
                check_non_negative(&name("gap"), stop.gap)?;
                let r = stop.restitution;
                check_finite(&name("restitution"), r)?;
                check(
                    name("restitution"),
                    r,
                    (0.0..=1.0).contains(&r),
                    "must lie in [0, 1]",
                )?;
            }
        }
        if let (Some(up), Some(low)) = (self.stops.upper, self.stops.lower) {
            let room = up.gap + low.gap + self.gaps.iter().sum::<f64>();
            check(
                "stops.lower.gap",
                low.gap,
                room > 0.0,
                "leaves no room between the stops (the stops' gaps and the chain's gaps are all zero)",
            )?;
            if up.frame != low.frame && self.excitation.amplitude >= room {
                return Err(ParamError::Conflict {
                    name: "stops.lower.frame".into(),
                    message: format!(
                        "one stop moves with the base and the other does not, and the base amplitude \
                         {} m would close the room between them ({room} m: the stops' gaps plus the \
                         chain's): the chain would be crushed",
                        self.excitation.amplitude
                    ),
                });
            }
        }
        Ok(())
    }

    /// Checks that the initial positions at time `t`, s, leave every stop's gap open (to
    /// rounding).
    pub(super) fn validate_state_stops(&self, positions: &[f64], t: f64) -> Result<(), ParamError> {
        let n = self.len();
        let (sin, _) = (self.omega() * t.rem_euclid(self.period())).sin_cos();
        let y = self.excitation.amplitude * sin;
        for side in [StopSide::Upper, StopSide::Lower] {
            let Some(stop) = self.stops.get(side) else {
                continue;
            };
            let wall = Self::frame_motion(stop.frame, y, 0.0, 0.0)[0];
            let gap = match side {
                StopSide::Upper => stop.gap - (positions[0] - wall),
                StopSide::Lower => stop.gap - (wall - positions[n - 1]),
            };
            let tol = 1e-12 * stop.gap.max(self.excitation.amplitude).max(1e-9);
            if gap < -tol {
                return Err(ParamError::BeyondStop { side, gap });
            }
        }
        Ok(())
    }
}
