//! Triboelectric figures of merit of a run: the cycle for maximised energy output (CMEO), the
//! structural figure of merit `FOM_S`, the breakdown-limited maximum and the run's own energy
//! per cycle against them.
//!
//! ## The CMEO (Zi et al., Nat. Commun. 6:8376, 2015)
//!
//! A triboelectric transducer at state `s` (its air gaps) has the terminal voltage
//! `V = V_oc(s) − Q/C(s)` (docs/MODEL.md §2) and the short-circuit charge
//! `Q_sc(s) = C(s)·V_oc(s)`. With an ideal switch the cycle for maximised energy output runs
//! between two states `a` and `b` of the motion: open circuit from `a` to `b` (the charge stays
//! at `Q_sc(a)`), short circuit at `b` (the charge moves to `Q_sc(b)` through the load),
//! open circuit back to `a`, short circuit at `a`. Only the two switching strokes deliver
//! energy; along each, `V` is linear in `Q` and falls to zero at the stroke's end, so
//!
//! ```text
//! E(a, b) = ∮ V dQ = ½ (Q_sc(b) − Q_sc(a))² (1/C(a) + 1/C(b)).
//! ```
//!
//! The CMEO of a run is the largest `E(a, b)` over the states the run visits after its
//! transient. In contact-separation mode (`C = ε₀S/(d₀ + x)`, `V_oc = σx/ε₀`) both
//! `Q_sc = σSx/(d₀ + x)` and `1/C` grow with the gap, so the maximum is at the gap range's
//! ends:
//!
//! ```text
//! E_m = σ²S d₀² (x_max − x_min)² (2d₀ + x_min + x_max) / (2ε₀ (d₀ + x_min)² (d₀ + x_max)²),
//! ```
//!
//! which for `x_min = 0` is Zi et al.'s `σ²S x_max² (2d₀ + x_max)/(2ε₀(d₀ + x_max)²)`
//! ([`cmeo_contact_separation`]). In the freestanding mode both gaps `D₁, D₂` move, the
//! states form a set in the plane and the search runs over pairs of them
//! ([`switch_cycle_energy`] is the closed form of one pair; with `D₁ + D₂ = g` fixed and the
//! exact `V_oc = σ(D₂ − D₁)/ε₀` it is `4σ²S (ΔD₂)²/(ε₀ (d₀ + g))`).
//!
//! ## FOM_S
//!
//! Zi et al. normalise the CMEO by the charge density, the area and the stroke,
//! `FOM_S = 2ε₀ E_m / (σ² S x_max)`, dimensionless: `E_m ∝ σ²S` for a fixed motion, so
//! `FOM_S` depends on the geometry (`d₀`) and the motion only. `x_max` is the largest gap in
//! contact-separation mode (Zi et al.'s separation) and the travel of the middle plate
//! relative to the outer ones, `max − min` of `(D₂ − D₁)/2`, in the freestanding mode.
//!
//! ## The breakdown-limited maximum (Xia et al., Nat. Commun. 10:4428, 2019)
//!
//! A cycle is usable only where no air gap breaks down: Gauss's law gives each gap's voltage
//! (affine in `Q`, [`gap_voltages`](crate::electrical::breakdown::gap_voltages)) and
//! Paschen's law its breakdown voltage, so each state allows the charges of an interval. The
//! cycle between `a` and `b` passes through the states whose short-circuit charge lies
//! between `Q_sc(a)` and `Q_sc(b)`, at the charges `Q_sc(a)` and `Q_sc(b)` (and between them
//! at the switching states); the breakdown-limited maximum is the largest `E(a, b)` whose
//! cycle stays inside the breakdown boundary at all of them. It equals the CMEO where the
//! CMEO cycle does not break down.
//!
//! ## The run's own cycle
//!
//! The run delivers `energy_per_period_j` per excitation period; its cycles are counted on
//! `Q_sc` (a Schmitt trigger at ¼ and ¾ of its range, so chatter and small bounces do not
//! count), and its energy per cycle is compared with the CMEO.

mod cycle;
mod watch;

pub use cycle::{
    CycleState, MeritReport, StateSet, cmeo_contact_separation, figures_of_merit, switch_cycle_energy,
};
pub use watch::{BoundaryPoint, MeritWatch};
