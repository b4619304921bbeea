//! The charge solver: integrates the circuit equations driven by a gap waveform.
//!
//! ## Equations
//!
//! With `Q` the charge moved between the electrodes, the transducer's terminal voltage is
//! `V = V_oc − Q/C` (seed eq. 11); `Q_eq = C·V_oc` is the equilibrium (short-circuit) charge.
//!
//! ```text
//! resistor R:    Q' = V/R = −(Q − Q_eq)/(R C)                power V²/R
//! rectifier:     Q' = I(V, V_s),  C_s V_s' = I_out(V, V_s) − V_s/R_L     power V_s·I_out
//! ```
//!
//! (bridge currents from [`Diode::bridge`](super::Diode::bridge)). The resistor equation is
//! linear and stiff: R·C runs from ~0.2 µs to ~90 µs against a ~0.1 s period at the paper's
//! 100 kΩ.
//!
//! ## Method
//!
//! Radau IIA collocation (L-stable, stiffly accurate) on these equations, with the stage
//! values of `Q` written as `u = Q − Q_eq = −C·V` and the exact increments `Q_eq(tᵢ) − Q_eq(t₀)`
//! of the waveform: the unknowns then hold the load voltage without cancellation when it is a
//! millionth of V_oc (small R), and `Q` stays exactly constant when nothing flows (R → ∞).
//! The delivered energy is a quadrature component of the same collocation,
//! `ΔE = h Σ bⱼ p(tⱼ, Yⱼ)` over the stage values, not a sampled sum.
//!
//! - **Resistor**: 7 stages (order 13, stage order 7). The stage system is linear,
//!   `(I + hA·diag(k)) Z = −ΔQ_eq − hA k u₀` with `k = 1/(RC)`, solved exactly by elimination
//!   without pivoting (safe for these matrices, see [`radau`](super::radau)). The high order
//!   lets a step span a good part of a flow piece: about 60 steps per period on the paper's
//!   default case, for loads from 1 kΩ to 10 GΩ.
//! - **Rectifier**: 3 stages (order 5). Its steps are short around every switching of the
//!   bridge, where a low order is cheaper; the 6 × 6 stage system is solved by Newton's
//!   method with the exact Jacobian at every iteration, started from the previous step's
//!   collocation polynomial, and given up early (RADAU5's test on the contraction rate θ)
//!   when the remaining iterations cannot converge. The diode law's constants are computed
//!   once.
//!
//! The gaps come in as a [`GapWaveform`]; the simulator's flow is first expanded into
//! piecewise Taylor polynomials accurate to the rounding of its closed form (see
//! `dynamics::taylor`), so the stage points of a step cost one Horner sweep each instead of
//! an exponential and a sine–cosine pair per cluster.
//!
//! Error control uses Hairer's embedded estimate (RADAU5's first estimate, of order S,
//! without its second, "stiffly filtered" one, which in the quasi-static regime of a small
//! load accepts steps 10⁴ times too long) on two things:
//!
//! - the load voltage `−u/C` (and the storage voltage), per step, `rtol·|V| + atol`; by
//!   default `atol = rtol × (largest |V| seen)` for the resistor, `rtol × (largest V_s seen,
//!   at least nV_T)` for the rectifier;
//! - the energy, per unit step, against `rtol × (average power)`: summed over a period the
//!   allowed error is `rtol ×` the period's energy. Without this the voltage test alone lets
//!   a stiff load take steps of a tenth of a period, far too long for the quadrature of V².
//!   Steps shorter than `T/1000` (boundary layers) are allowed `rtol × E/1000` each rather
//!   than an error proportional to their length.
//!
//! A noise allowance keeps the tests above the precision of the input (gaps are differences
//! of positions), so tight tolerances cannot drive the step to zero. The step size follows
//! RADAU5's controller with Gustafsson's predictive variant (`h ∝ err^(−1/(S+1))`). Where the
//! estimate cannot see the solution's structure, the step is shaped directly:
//!
//! - after a kink the resistor's charge crosses a boundary layer of width `RC`. By default
//!   (`ChargeOptions::analytic_layers`) one step carries it in closed form: the step integrates
//!   the slow solution, started where Hairer's estimate vanishes, and adds the layer's decaying
//!   exponential and its energy exactly (the `layer` module). Where that step does not fit
//!   (a piece shorter than ~30 R·C, charge moments being taken) the layer is crossed with short
//!   steps: its amplitude is estimated from the quasi-static charge `u ≈ −I_sc/k`, the layer is
//!   entered at `h·k = 2`, and once it has decayed below the tolerance the step returns to the
//!   size it had before the kink;
//! - a failed stiff rectifier step (the bridge switching) jumps to `h·k ≈ 2`, and a rectifier
//!   step in which a conducting junction's voltage moves by more than 4 n·V_T is retried
//!   shorter: the current changes by orders of magnitude there, which neither the collocation
//!   polynomial nor its error estimate follows;
//! - after a kink the rectifier's first step covers a sweep of 10 n·V_T of the voltage.
//!
//! Every call of [`ChargeSolver::advance`] restarts the integration (mechanical kinks such as
//! impacts fall on flow boundaries), and excitation period boundaries are step boundaries, so
//! energy is booked per period exactly. Sampled outputs come from the collocation
//! polynomial with the transducer evaluated exactly at the sample time.

mod api;
mod checkpoint;
mod layer;
mod layer_term;
mod output;
mod results;
mod state;
mod step;

pub use checkpoint::ChargeCheckpoint;
pub use results::{
    ChargeOptions, ElectricalSamples, PeriodStats, PowerSummary, SolverStats, power_curve, summarize,
};
pub use state::{ChargeMoments, ChargeSolver};
