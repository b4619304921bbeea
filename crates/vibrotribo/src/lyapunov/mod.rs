//! Lyapunov exponents of the non-smooth flow: all 2N of them, from the exact variational
//! equations with saltation matrices at the events (Müller 1995; de Souza & Caldas 2004).
//!
//! # Method
//!
//! The state `z = [x₁ … x_N, v₁ … v_N]` (m, m/s) moves by the exact flow; a perturbation moves
//! by its state-transition matrix Φ, which [`Sensitivity`](crate::sensitivity::Sensitivity)
//! composes from the closed-form Jacobian of every piece of flow and the saltation matrix of
//! every impact, stick, release and chatter jump (see [`sensitivity`](crate::sensitivity)).
//! A general-purpose estimate from the smooth flow alone would miss the saltation matrices,
//! which carry most of the stretching (an impact's saltation matrix grows like 1/closing
//! speed).
//!
//! [`LyapunovObserver`] carries an orthonormal basis `Q` of 2N tangent vectors (random, from
//! [`LyapunovOptions::seed`]) along the run. At the end of every excitation period it folds
//! the period's Φ into the basis by a QR decomposition (Benettin et al. 1980; Householder, as
//! nalgebra implements it),
//!
//! ```text
//! Φ(t_{k+1}, t_k) Q_k = Q_{k+1} R_k,      λ_i = Σ_k ln|R_k,ii| / Σ_k (t_{k+1} − t_k),
//! ```
//!
//! and starts Φ afresh ([`Sensitivity::restart`](crate::sensitivity::Sensitivity::restart)).
//! It folds earlier, after any piece of flow, when an entry of Φ exceeds
//! [`LyapunovOptions::max_growth`]: a block's Φ is then well enough conditioned for its
//! contracting directions to keep their digits. The basis is carried from t = 0 and aligns
//! with the Oseledets directions during the transient; the exponents average over the periods
//! after it.
//!
//! A fold waits while a chatter jump is scheduled: the jump's time depends on the state at
//! the impact that started it, which a restarted Φ could not carry (Φ of the chatter interval
//! projects that dependence away). Chatter intervals are much shorter than a period; the
//! period's boundary fold happens just after the jump.
//!
//! # Convergence
//!
//! The logarithms are filed per period. [`LyapunovSpectrum::spread`] is the batch-means
//! standard error: the periods are cut into [`LyapunovOptions::batches`] consecutive batches,
//! each gives its own exponents, and the spread is the standard deviation of those over
//! √batches. It is a fair error bar when a batch is much longer than the motion's correlation
//! time (chaotic motion); at a periodic orbit it measures how far the basis still was from
//! alignment. [`LyapunovSpectrum::running`] holds the estimate after each batch, the
//! convergence curve.
//!
//! # Sticking and chatter: −∞ exponents
//!
//! While a contact is stuck its two sides move as one cluster, and Φ projects onto the
//! constraint subspace (gap and relative velocity fixed at zero): the rank of Φ drops by 2 per
//! stuck contact, and a chatter sequence that ends in sticking does the same in finite time.
//! Perturbations in those directions vanish exactly, so their exponents are `−∞`: the
//! product Φ over the window has a kernel, and the Oseledets spectrum counts its dimension as
//! exponents `−∞`. The observer counts it structurally: `2 × (N − fewest clusters)` over the
//! averaged window, i.e. twice the largest number of contacts stuck at once (generically the
//! kernels of successive sticking episodes do not align with the images between them).
//! Those exponents are reported as `−∞` ([`LyapunovSpectrum::collapsed`] of them, last),
//! never as the `ln(rounding)`/period a naive QR would give. The finite ones are the
//! exponents of the remaining directions: the columns of the QR that precede the collapsed
//! ones are exact for a rank-deficient product.
//!
//! # Non-differentiable points
//!
//! A grazing impact (closing speed below [`SensitivityOptions::grazing_speed`] × the chain's
//! speed scale) or simultaneous events (several contacts at one instant) have no saltation
//! matrix ([`NonSmoothPoint`](crate::sensitivity::NonSmoothPoint)). The period in which one
//! occurs is left out of the average, Φ starts afresh after it, and the next period only
//! realigns the basis (also left out); both are counted in
//! [`LyapunovSpectrum::skipped_periods`], and the points themselves in
//! [`LyapunovSpectrum::non_smooth`]. With the default thresholds a chaotic run meets them
//! rarely (the closing speeds of its impacts are spread over a range 10⁸ times wider); a
//! periodic orbit that grazes every period yields [`LyapunovError::NoPeriods`].
//!
//! [`SensitivityOptions::grazing_speed`]: crate::sensitivity::SensitivityOptions::grazing_speed
//!
//! # Cost
//!
//! Φ costs O(N²) per event on top of the simulation and a QR of a 2N × 2N matrix per period.
//! [`study::lyapunov_spectrum`](crate::study::lyapunov_spectrum) runs it through the run
//! layer ([`simulate`](crate::study::simulate)),
//! with any other [`RunObserver`](crate::study::RunObserver) beside it (a progress bar, an
//! interrupt checkpoint); a sweep point attaches it with
//! [`PointOptions::lyapunov`](crate::study::PointOptions::lyapunov).

mod error;
mod observer;
mod options;
mod spectrum;

pub use error::LyapunovError;
pub use observer::LyapunovObserver;
pub use options::LyapunovOptions;
pub use spectrum::LyapunovSpectrum;
