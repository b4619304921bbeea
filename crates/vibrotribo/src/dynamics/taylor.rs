//! Piecewise Taylor polynomials of the gaps over one piece of flow, accurate to the rounding
//! of a direct evaluation, for consumers that evaluate the gaps many times (the charge solver).
//!
//! Between events every gap is a constant plus one harmonic plus damped sinusoids
//! ([`Flow::gaps_at`] costs an exponential and a sine–cosine pair per cluster). The piece is
//! cut into sub-pieces of half-width `r ≤ SUBPIECE_RATE / Λ` (Λ from
//! `Oscillator::rate_bound`); on each, every cluster's displacement is expanded about the
//! sub-piece centre from one closed-form evaluation there and the recurrence of its ODE, with
//! as many terms as the rigorous tail bound of `Oscillator::taylor` needs to fall below a
//! quarter of the rounding of the positions. The gaps' coefficients are differences of the
//! clusters' (a gap inside a stuck cluster is constant), and the constant term is the direct
//! evaluation at the centre. An evaluation is then one Horner sweep.

use super::observer::Flow;

/// Target `Λr` of a sub-piece: about 20 terms reach rounding level.
const SUBPIECE_RATE: f64 = 1.0;

/// Most terms of one expansion; a sub-piece that would need more is split.
const MAX_TERMS: usize = 40;

/// Most sub-pieces one piece is split into.
const MAX_SPLIT: usize = 1 << 16;

/// Truncation tolerance relative to the size of a cluster's motion.
const TRUNCATION: f64 = 0.25 * f64::EPSILON;

/// Most coefficients one piece's expansion may hold (sub-pieces × terms × gaps, taking 20
/// terms a sub-piece): 2²⁶, 512 MiB.
pub(crate) const MAX_COEFFICIENTS: f64 = (1u64 << 26) as f64;

/// Terms of a typical expansion (`Λr ≤ SUBPIECE_RATE`), for the size estimate.
const TYPICAL_TERMS: f64 = 20.0;

/// A piece of flow whose expansion would exceed [`MAX_COEFFICIENTS`]: the chain's rate
/// bound Λ (a damping or a stiffness-to-mass ratio far beyond the excitation's) asks for
/// more sub-pieces than memory allows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TooFine {
    /// Start of the piece, s.
    pub t_start: f64,
    /// End of the piece, s.
    pub t_end: f64,
    /// The rate bound Λ, 1/s.
    pub rate: f64,
    /// The sub-pieces it would need.
    pub sub_pieces: f64,
}

#[derive(Debug, Clone, Copy, Default)]
struct SubPiece {
    /// Start of the sub-piece, s.
    t_lo: f64,
    /// Centre, s.
    tc: f64,
    /// 1/r, 1/s (0 for a piece of zero length).
    inv_r: f64,
    /// Terms per gap.
    terms: usize,
    /// Index of coefficient 0 of gap 0 in `coefs`.
    base: usize,
}

/// The gaps of one piece of flow as piecewise Taylor polynomials (see the module docs).
/// Buffers are reused from one piece to the next.
#[derive(Debug, Clone, Default)]
pub(crate) struct GapPolynomial {
    n_gaps: usize,
    subs: Vec<SubPiece>,
    /// `coefs[base + j·n_gaps + k]`: coefficient j of gap k, m.
    coefs: Vec<f64>,
    /// Per-cluster expansions, `MAX_TERMS` each.
    jets: Vec<f64>,
    jet_terms: Vec<usize>,
    /// Positions at a centre, m.
    positions: Vec<f64>,
}

impl GapPolynomial {
    /// Expands the gaps of `flow` over `[flow.t_start, flow.t_end]`; an error, before
    /// anything is allocated, if the expansion would hold more than [`MAX_COEFFICIENTS`].
    pub(crate) fn build(&mut self, flow: &Flow<'_>) -> Result<(), TooFine> {
        let n_masses = flow.len();
        let clusters = flow.clusters();
        let rate = clusters
            .iter()
            .map(|c| c.oscillator.rate_bound())
            .fold(0.0, f64::max);
        let length = (flow.t_end - flow.t_start).max(0.0);
        let wanted = if rate > 0.0 {
            (length * rate / (2.0 * SUBPIECE_RATE)).ceil().max(1.0)
        } else {
            1.0
        };
        let coefficients = wanted * TYPICAL_TERMS * n_masses.saturating_sub(1).max(1) as f64;
        // A NaN estimate (a rate that is not finite) is refused too.
        if coefficients.is_nan() || coefficients > MAX_COEFFICIENTS {
            return Err(TooFine {
                t_start: flow.t_start,
                t_end: flow.t_end,
                rate,
                sub_pieces: wanted,
            });
        }
        self.n_gaps = n_masses.saturating_sub(1);
        self.jets.resize(clusters.len() * MAX_TERMS, 0.0);
        self.jet_terms.resize(clusters.len(), 0);
        self.positions.resize(n_masses, 0.0);
        let mut count = wanted as usize;
        // Λr ≤ SUBPIECE_RATE needs about 20 terms; split further in the unlikely case
        // that MAX_TERMS do not reach the tolerance (a bound is only ever loose).
        while !self.try_build(flow, count) && count < MAX_SPLIT {
            count *= 2;
        }
        Ok(())
    }

    /// Expands `flow` on `count` equal sub-pieces; false if some expansion did not reach
    /// its tolerance within `MAX_TERMS` terms.
    fn try_build(&mut self, flow: &Flow<'_>, count: usize) -> bool {
        let clusters = flow.clusters();
        let n_gaps = self.n_gaps;
        let length = (flow.t_end - flow.t_start).max(0.0);
        let r = 0.5 * length / count as f64;
        let mut converged = true;
        self.subs.clear();
        self.coefs.clear();
        for i in 0..count {
            let t_lo = flow.t_start + 2.0 * r * i as f64;
            let tc = if i + 1 == count {
                // The last centre from the end, so that the end is exactly at x = 1.
                flow.t_end - r
            } else {
                t_lo + r
            };
            let ph = flow.forcing.phase(tc);
            let mut terms = 1;
            for (c, cl) in clusters.iter().enumerate() {
                let jet = &mut self.jets[c * MAX_TERMS..(c + 1) * MAX_TERMS];
                let (n, tail, tol) = cl.oscillator.taylor(tc, ph, r, TRUNCATION, jet);
                converged &= tail <= tol;
                self.jet_terms[c] = n;
                terms = terms.max(n);
                let base = flow.offsets[cl.first];
                for m in cl.first..=cl.last {
                    self.positions[m] = jet[0] + (flow.offsets[m] - base);
                }
            }
            let base = self.coefs.len();
            self.coefs.resize(base + terms * n_gaps, 0.0);
            let mut owner = 0;
            for k in 0..n_gaps {
                // Gap k lies between masses k and k + 1.
                while clusters[owner].last < k {
                    owner += 1;
                }
                let upper = owner;
                let lower = if clusters[owner].last == k {
                    owner + 1
                } else {
                    owner
                };
                self.coefs[base + k] = flow.gaps[k] - (self.positions[k + 1] - self.positions[k]);
                if upper != lower {
                    let (ju, jl) = (upper * MAX_TERMS, lower * MAX_TERMS);
                    let (nu, nl) = (self.jet_terms[upper], self.jet_terms[lower]);
                    for j in 1..terms {
                        let a = if j < nu { self.jets[ju + j] } else { 0.0 };
                        let b = if j < nl { self.jets[jl + j] } else { 0.0 };
                        self.coefs[base + j * n_gaps + k] = a - b;
                    }
                }
            }
            self.subs.push(SubPiece {
                t_lo,
                tc,
                inv_r: if r > 0.0 { 1.0 / r } else { 0.0 },
                terms,
                base,
            });
        }
        converged
    }

    /// Index of the sub-piece holding `t` (the nearest one outside the span).
    #[inline]
    fn index_at(&self, t: f64) -> usize {
        self.subs[1..].partition_point(|s| s.t_lo <= t)
    }

    /// The sub-piece holding `t` (the nearest one outside the span).
    #[inline]
    fn sub_at(&self, t: f64) -> &SubPiece {
        &self.subs[self.index_at(t)]
    }

    /// Gaps, m, at `t`, s (within the piece).
    #[inline]
    pub(crate) fn values(&self, t: f64, gaps: &mut [f64]) {
        match self.n_gaps {
            1 => self.values_n::<1>(t, gaps),
            2 => self.values_n::<2>(t, gaps),
            3 => self.values_n::<3>(t, gaps),
            4 => self.values_n::<4>(t, gaps),
            _ => self.values_any(t, gaps),
        }
    }

    /// [`values`](Self::values) for `N` gaps, with the sums in registers.
    #[inline]
    fn values_n<const N: usize>(&self, t: f64, gaps: &mut [f64]) {
        let s = self.sub_at(t);
        let x = (t - s.tc) * s.inv_r;
        let c = &self.coefs[s.base..s.base + s.terms * N];
        let mut acc = [0.0; N];
        for row in c.chunks_exact(N).rev() {
            for (g, a) in acc.iter_mut().zip(row) {
                *g = *g * x + a;
            }
        }
        gaps[..N].copy_from_slice(&acc);
    }

    /// Gaps, m, at several times, s (within the piece): `gaps[i·n + k]` is gap k at
    /// `times[i]`. Times in one sub-piece are evaluated together, eight at a time.
    pub(crate) fn values_many(&self, times: &[f64], gaps: &mut [f64]) {
        match self.n_gaps {
            1 => self.values_many_n::<1>(times, gaps),
            2 => self.values_many_n::<2>(times, gaps),
            3 => self.values_many_n::<3>(times, gaps),
            4 => self.values_many_n::<4>(times, gaps),
            n => {
                for (t, g) in times.iter().zip(gaps.chunks_exact_mut(n)) {
                    self.values_any(*t, g);
                }
            }
        }
    }

    fn values_many_n<const N: usize>(&self, times: &[f64], gaps: &mut [f64]) {
        const LANES: usize = 8;
        for (ts, out) in times.chunks(LANES).zip(gaps.chunks_mut(LANES * N)) {
            let i = self.index_at(ts[0]);
            let s = self.subs[i];
            let lo = if i == 0 { f64::NEG_INFINITY } else { s.t_lo };
            let hi = self.subs.get(i + 1).map_or(f64::INFINITY, |n| n.t_lo);
            if !ts.iter().all(|&t| t >= lo && t < hi) {
                for (t, g) in ts.iter().zip(out.chunks_exact_mut(N)) {
                    self.values_n::<N>(*t, g);
                }
                continue;
            }
            let mut xs = [0.0; LANES];
            for (x, t) in xs.iter_mut().zip(ts) {
                *x = (t - s.tc) * s.inv_r;
            }
            let c = &self.coefs[s.base..s.base + s.terms * N];
            let mut acc = [[0.0; N]; LANES];
            for row in c.chunks_exact(N).rev() {
                for (a, x) in acc.iter_mut().zip(&xs) {
                    for (g, r) in a.iter_mut().zip(row) {
                        *g = *g * x + r;
                    }
                }
            }
            for (a, g) in acc.iter().zip(out.chunks_exact_mut(N)) {
                g.copy_from_slice(a);
            }
        }
    }

    fn values_any(&self, t: f64, gaps: &mut [f64]) {
        let s = self.sub_at(t);
        let x = (t - s.tc) * s.inv_r;
        let n = self.n_gaps;
        let c = &self.coefs[s.base..s.base + s.terms * n];
        gaps[..n].fill(0.0);
        for row in c.chunks_exact(n).rev() {
            for (g, a) in gaps[..n].iter_mut().zip(row) {
                *g = *g * x + a;
            }
        }
    }

    /// Gaps, m, and their rates, m/s, at `t`, s (within the piece).
    pub(crate) fn values_and_rates(&self, t: f64, gaps: &mut [f64], rates: &mut [f64]) {
        match self.n_gaps {
            1 => self.values_and_rates_n::<1>(t, gaps, rates),
            2 => self.values_and_rates_n::<2>(t, gaps, rates),
            3 => self.values_and_rates_n::<3>(t, gaps, rates),
            _ => self.values_and_rates_any(t, gaps, rates),
        }
    }

    /// [`values_and_rates`](Self::values_and_rates) for `N` gaps, with the sums in registers.
    #[inline]
    fn values_and_rates_n<const N: usize>(&self, t: f64, gaps: &mut [f64], rates: &mut [f64]) {
        let s = self.sub_at(t);
        let x = (t - s.tc) * s.inv_r;
        let c = &self.coefs[s.base..s.base + s.terms * N];
        let (mut g, mut d) = ([0.0; N], [0.0; N]);
        // Horner's rule for the polynomial and its derivative together.
        for row in c.as_chunks::<N>().0.iter().rev() {
            for k in 0..N {
                d[k] = d[k] * x + g[k];
                g[k] = g[k] * x + row[k];
            }
        }
        for k in 0..N {
            gaps[k] = g[k];
            rates[k] = d[k] * s.inv_r;
        }
    }

    fn values_and_rates_any(&self, t: f64, gaps: &mut [f64], rates: &mut [f64]) {
        let s = self.sub_at(t);
        let x = (t - s.tc) * s.inv_r;
        let n = self.n_gaps;
        let c = &self.coefs[s.base..s.base + s.terms * n];
        gaps[..n].fill(0.0);
        rates[..n].fill(0.0);
        // Horner's rule for the polynomial and its derivative together.
        for row in c.chunks_exact(n).rev() {
            for ((g, d), a) in gaps[..n].iter_mut().zip(rates[..n].iter_mut()).zip(row) {
                *d = *d * x + *g;
                *g = *g * x + a;
            }
        }
        for d in &mut rates[..n] {
            *d *= s.inv_r;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::{Simulator, Trajectory};
    use crate::model::{ChainParams, ChainState, SimOptions};

    /// On every piece of flow of the default and the chatter case (sticking, chatter, triple
    /// closures), the expansion agrees with the closed form to the rounding of the closed form
    /// itself: a few ulps of the amplitude of the positions it subtracts.
    #[test]
    fn expansion_matches_closed_form_to_rounding() {
        for (chain, periods) in [
            (ChainParams::default(), 12.0),
            (ChainParams::paper_chatter_case(), 6.0),
        ] {
            let mut sim = Simulator::new(&chain, &ChainState::at_rest(3), SimOptions::default()).unwrap();
            let mut traj = Trajectory::new(&sim);
            sim.run_until(periods * chain.period(), &mut traj).unwrap();
            let mut poly = GapPolynomial::default();
            let (mut x, mut v) = ([0.0; 3], [0.0; 3]);
            // Amplitudes of the positions, m, and velocities, m/s, over the run.
            let (mut amp_x, mut amp_v) = ([0.0f64; 3], [0.0f64; 3]);
            for seg in traj.segments() {
                for i in 0..=40 {
                    let t = seg.t_start + (seg.t_end - seg.t_start) * i as f64 / 40.0;
                    traj.state_at(t, &mut x, &mut v);
                    for m in 0..3 {
                        amp_x[m] = amp_x[m].max(x[m].abs());
                        amp_v[m] = amp_v[m].max(v[m].abs());
                    }
                }
            }
            let (mut g1, mut r1, mut g2, mut r2) = ([0.0; 2], [0.0; 2], [0.0; 2], [0.0; 2]);
            for seg in traj.segments() {
                let flow = traj.flow_at(seg.t_start).unwrap();
                poly.build(&flow).unwrap();
                let times: Vec<f64> = (0..=40)
                    .map(|i| seg.t_start + (seg.t_end - seg.t_start) * i as f64 / 40.0)
                    .collect();
                let mut many = vec![0.0; 2 * times.len()];
                poly.values_many(&times, &mut many);
                for (i, &t) in times.iter().enumerate() {
                    flow.gaps_at(t, &mut g1, &mut r1);
                    poly.values_and_rates(t, &mut g2, &mut r2);
                    for k in 0..2 {
                        let scale = chain.gaps[k] + amp_x[k] + amp_x[k + 1];
                        let speed = amp_v[k] + amp_v[k + 1];
                        let tol = 16.0 * f64::EPSILON * scale;
                        assert!(
                            (g1[k] - g2[k]).abs() <= tol && (g1[k] - many[2 * i + k]).abs() <= tol,
                            "gap {k} at t = {t}: closed form {:e}, expansion {:e} / {:e} (tolerance {tol:e})",
                            g1[k],
                            g2[k],
                            many[2 * i + k]
                        );
                        let rtol = 64.0 * f64::EPSILON * speed;
                        assert!(
                            (r1[k] - r2[k]).abs() <= rtol,
                            "rate {k} at t = {t}: closed form {:e}, expansion {:e}",
                            r1[k],
                            r2[k]
                        );
                    }
                }
            }
        }
    }

    /// The same with polynomial external forces (degree 6, switched every 0.03 s): the
    /// polynomial part's terms are exact and the expansion still meets the closed form to its
    /// rounding.
    #[test]
    fn expansion_matches_closed_form_with_polynomial_forces() {
        use crate::model::ForcePolynomial;
        let chain = ChainParams {
            forces: vec![0.1, -0.2, 0.05],
            ..ChainParams::default()
        };
        let mut sim = Simulator::new(&chain, &ChainState::at_rest(3), SimOptions::default()).unwrap();
        let mut traj = Trajectory::new(&sim);
        let mut t = 0.0;
        let mut sign = 1.0;
        while t < 6.0 * chain.period() {
            let f: Vec<ForcePolynomial> = (0..3)
                .map(|i| {
                    let c = (0..7)
                        .map(|j| sign * 0.3 * (i + j + 1) as f64 / 0.03f64.powi(j))
                        .collect();
                    ForcePolynomial::new(t, c)
                })
                .collect();
            sim.set_external_forces(&f).unwrap();
            t += 0.03;
            sim.run_until(t, &mut traj).unwrap();
            sign = -sign;
        }
        let mut poly = GapPolynomial::default();
        let (mut g1, mut r1, mut g2, mut r2) = ([0.0; 2], [0.0; 2], [0.0; 2], [0.0; 2]);
        for seg in traj.segments() {
            let flow = traj.flow_at(seg.t_start).unwrap();
            poly.build(&flow).unwrap();
            let scale = seg
                .clusters
                .iter()
                .map(|c| {
                    c.oscillator
                        .magnitude_at(seg.t_end)
                        .max(c.oscillator.magnitude_at(seg.t_start))
                })
                .fold(0.0, f64::max);
            for i in 0..=40 {
                let t = seg.t_start + (seg.t_end - seg.t_start) * i as f64 / 40.0;
                flow.gaps_at(t, &mut g1, &mut r1);
                poly.values_and_rates(t, &mut g2, &mut r2);
                for k in 0..2 {
                    let tol = 64.0 * f64::EPSILON * (chain.gaps[k] + 2.0 * scale);
                    assert!(
                        (g1[k] - g2[k]).abs() <= tol,
                        "gap {k} at t = {t}: closed form {:e}, expansion {:e} (tolerance {tol:e})",
                        g1[k],
                        g2[k]
                    );
                }
            }
        }
    }
}
