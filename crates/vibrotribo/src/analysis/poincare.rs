//! Poincaré sections of a run: stroboscopic (once per excitation period) and at impacts.
//!
//! The **stroboscopic section** samples the state at `t_n = t₀ + nT`, n = 0, 1, …, with
//! `T = 2π/ω` the excitation period. It is the Poincaré map of the non-autonomous system on
//! the section `ωt ≡ ωt₀ (mod 2π)`: a period-p orbit shows as p points, a quasi-periodic one as
//! a closed curve, a chaotic one as a fractal set. The samples are evaluated from the exact
//! closed-form flow (no interpolation). With `t₀ = 0` the sample times `n·T` are the very
//! times at which the simulator breaks its flow at period boundaries.
//!
//! The **impact section** records every impact (an [`EventKind::Impact`] event, including
//! grazing touches of closing speed 0) after a transient: time, excitation phase, contact,
//! closing and opening speeds, and the state just before and just after it.

use super::{AnalysisError, check_positive, invalid};
use crate::dynamics::{Event, EventKind, Flow, Observer, Simulator, StateView};

/// Where and from when a [`StroboscopicSection`] samples.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct StroboscopicOptions {
    /// Section time t₀, s: samples are taken at `t₀ + nT`. Finite and ≥ 0. Default 0 (the
    /// excitation's zero phase, `y = 0` rising).
    pub phase_time: f64,
    /// Number of leading samples (periods) to discard as transient: samples n <
    /// `transient_periods` are not recorded. Default 0.
    pub transient_periods: u64,
}

impl Default for StroboscopicOptions {
    fn default() -> Self {
        StroboscopicOptions {
            phase_time: 0.0,
            transient_periods: 0,
        }
    }
}

/// Observer that samples positions and velocities of all masses once per excitation period,
/// at `t_n = t₀ + nT` (stroboscopic Poincaré section).
///
/// A sample time that coincides with the end of a flow interval is evaluated there: the
/// state is continuous, and the velocities are those just before an event at that time.
///
/// ```
/// use vibrotribo::analysis::{StroboscopicOptions, StroboscopicSection};
/// use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator};
///
/// let params = ChainParams::default();
/// let mut sim = Simulator::new(&params, &ChainState::at_rest(3), SimOptions::default())?;
/// let options = StroboscopicOptions { transient_periods: 5, ..Default::default() };
/// let mut section = StroboscopicSection::for_simulator(&sim, options)?;
/// sim.run_until(20.0 * params.period(), &mut section)?;
/// assert_eq!(section.len(), 16); // n = 5..=20
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct StroboscopicSection {
    masses: usize,
    period: f64,
    options: StroboscopicOptions,
    /// Index n of the next sample to take.
    next: u64,
    /// Sample indices n of the recorded samples.
    pub indices: Vec<u64>,
    /// Sample times `t₀ + nT`, s.
    pub times: Vec<f64>,
    /// Positions x_i, m, row-major: `positions[j·N + i]` is mass i in sample j.
    pub positions: Vec<f64>,
    /// Velocities x_i', m/s, flattened like `positions`.
    pub velocities: Vec<f64>,
}

impl StroboscopicSection {
    /// A section for a chain of `masses` masses driven with period `period`, s.
    pub fn new(masses: usize, period: f64, options: StroboscopicOptions) -> Result<Self, AnalysisError> {
        if masses == 0 {
            return Err(invalid("masses", 0.0, "must be positive"));
        }
        check_positive("period", period)?;
        let t0 = options.phase_time;
        if !t0.is_finite() || t0 < 0.0 {
            return Err(invalid("phase_time", t0, "must be finite and not negative"));
        }
        Ok(StroboscopicSection {
            masses,
            period,
            next: options.transient_periods,
            options,
            indices: Vec::new(),
            times: Vec::new(),
            positions: Vec::new(),
            velocities: Vec::new(),
        })
    }

    /// A section matching `sim`'s chain and excitation period.
    pub fn for_simulator(sim: &Simulator, options: StroboscopicOptions) -> Result<Self, AnalysisError> {
        Self::new(sim.params().len(), sim.period(), options)
    }

    /// Sample time `t₀ + nT`, s.
    pub fn time_of(&self, n: u64) -> f64 {
        self.options.phase_time + n as f64 * self.period
    }

    /// Number of masses N (the width of a sample).
    pub fn masses(&self) -> usize {
        self.masses
    }

    /// Excitation period T, s.
    pub fn period(&self) -> f64 {
        self.period
    }

    /// The options the section was built with.
    pub fn options(&self) -> &StroboscopicOptions {
        &self.options
    }

    /// Number of samples recorded.
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// Whether no sample has been recorded.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// Positions, m, of sample `j` (None past the end).
    pub fn positions_at(&self, j: usize) -> Option<&[f64]> {
        self.positions.get(j * self.masses..(j + 1) * self.masses)
    }

    /// Velocities, m/s, of sample `j` (None past the end).
    pub fn velocities_at(&self, j: usize) -> Option<&[f64]> {
        self.velocities.get(j * self.masses..(j + 1) * self.masses)
    }

    /// The series of one mass's position x_i, m, over all samples (None if `i ≥ N`).
    pub fn position_series(&self, i: usize) -> Option<Vec<f64>> {
        (i < self.masses).then(|| {
            self.positions
                .iter()
                .skip(i)
                .step_by(self.masses)
                .copied()
                .collect()
        })
    }

    /// The series of one mass's velocity x_i', m/s, over all samples (None if `i ≥ N`).
    pub fn velocity_series(&self, i: usize) -> Option<Vec<f64>> {
        (i < self.masses).then(|| {
            self.velocities
                .iter()
                .skip(i)
                .step_by(self.masses)
                .copied()
                .collect()
        })
    }
}

impl Observer for StroboscopicSection {
    fn flow(&mut self, flow: &Flow<'_>) {
        debug_assert_eq!(flow.len(), self.masses);
        let mut t = self.time_of(self.next);
        if t < flow.t_start {
            // Attached to a run already under way: skip to the first sample in this interval.
            let first = ((flow.t_start - self.options.phase_time) / self.period)
                .ceil()
                .max(0.0) as u64;
            self.next = self.next.max(first);
            t = self.time_of(self.next);
            while t < flow.t_start {
                self.next += 1;
                t = self.time_of(self.next);
            }
        }
        // A sample at an interval's end is taken there and not again at the next start.
        while t <= flow.t_end {
            let at = self.positions.len();
            self.positions.resize(at + self.masses, 0.0);
            self.velocities.resize(at + self.masses, 0.0);
            flow.state_at(t, &mut self.positions[at..], &mut self.velocities[at..]);
            self.indices.push(self.next);
            self.times.push(t);
            self.next += 1;
            t = self.time_of(self.next);
        }
    }
}

/// One impact recorded by an [`ImpactSection`]. Its state lives in the section's flattened
/// arrays, at the same index.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactPoint {
    /// Time, s.
    pub time: f64,
    /// Excitation phase at the impact, as a fraction of the period: `(t mod T)/T ∈ [0, 1)`.
    pub phase: f64,
    /// Contact index k, 0-based (between mass k and k+1).
    pub contact: usize,
    /// Closing speed `x'_{k+1} − x'_k` just before the impact, m/s (≥ 0; 0 for a grazing
    /// touch).
    pub closing_speed: f64,
    /// Opening speed just after the impact, m/s.
    pub opening_speed: f64,
}

/// Observer that records every impact after a transient time (the impact Poincaré section).
///
/// Per impact it keeps an [`ImpactPoint`] and the positions, the velocities just before and
/// the velocities just after the impact. Several contacts struck at the same instant give one
/// point each, sharing the state.
#[derive(Debug, Clone)]
pub struct ImpactSection {
    masses: usize,
    period: f64,
    transient: f64,
    /// State at the end of the latest flow interval (just before the next event).
    before: Vec<f64>,
    before_positions: Vec<f64>,
    /// The impacts in time order.
    pub points: Vec<ImpactPoint>,
    /// Positions x_i at each impact, m, row-major: `positions[j·N + i]`.
    pub positions: Vec<f64>,
    /// Velocities x_i' just before each impact, m/s, flattened like `positions`.
    pub velocities_before: Vec<f64>,
    /// Velocities x_i' just after each impact (after all simultaneous impacts at that time
    /// are resolved), m/s, flattened like `positions`.
    pub velocities_after: Vec<f64>,
}

impl ImpactSection {
    /// A section for a chain of `masses` masses driven with period `period`, s, recording
    /// impacts at times `t ≥ transient`, s.
    pub fn new(masses: usize, period: f64, transient: f64) -> Result<Self, AnalysisError> {
        if masses == 0 {
            return Err(invalid("masses", 0.0, "must be positive"));
        }
        check_positive("period", period)?;
        if !transient.is_finite() || transient < 0.0 {
            return Err(invalid("transient", transient, "must be finite and not negative"));
        }
        Ok(ImpactSection {
            masses,
            period,
            transient,
            before: vec![0.0; masses],
            before_positions: vec![0.0; masses],
            points: Vec::new(),
            positions: Vec::new(),
            velocities_before: Vec::new(),
            velocities_after: Vec::new(),
        })
    }

    /// A section matching `sim`'s chain and period, recording from `transient`, s.
    pub fn for_simulator(sim: &Simulator, transient: f64) -> Result<Self, AnalysisError> {
        Self::new(sim.params().len(), sim.period(), transient)
    }

    /// Number of masses N.
    pub fn masses(&self) -> usize {
        self.masses
    }

    /// Number of impacts recorded.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether no impact has been recorded.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Positions, m, at impact `j`.
    pub fn positions_at(&self, j: usize) -> Option<&[f64]> {
        self.positions.get(j * self.masses..(j + 1) * self.masses)
    }

    /// Velocities just before impact `j`, m/s.
    pub fn velocities_before_at(&self, j: usize) -> Option<&[f64]> {
        self.velocities_before.get(j * self.masses..(j + 1) * self.masses)
    }

    /// Velocities just after impact `j`, m/s.
    pub fn velocities_after_at(&self, j: usize) -> Option<&[f64]> {
        self.velocities_after.get(j * self.masses..(j + 1) * self.masses)
    }

    /// Indices (into `points` and the state arrays) of the impacts at contact `k`.
    pub fn indices_at_contact(&self, k: usize) -> impl Iterator<Item = usize> + '_ {
        self.points
            .iter()
            .enumerate()
            .filter(move |(_, p)| p.contact == k)
            .map(|(j, _)| j)
    }
}

impl Observer for ImpactSection {
    fn flow(&mut self, flow: &Flow<'_>) {
        debug_assert_eq!(flow.len(), self.masses);
        if flow.t_end >= self.transient {
            flow.state_at(flow.t_end, &mut self.before_positions, &mut self.before);
        }
    }

    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        if event.kind != EventKind::Impact || event.time < self.transient {
            return;
        }
        let phase = (event.time / self.period).rem_euclid(1.0);
        self.points.push(ImpactPoint {
            time: event.time,
            // rem_euclid can round up to exactly 1.0 for tiny negative remainders.
            phase: if phase >= 1.0 { 0.0 } else { phase },
            contact: event.contact,
            closing_speed: event.velocity_before,
            opening_speed: event.velocity_after,
        });
        self.positions.extend_from_slice(state.positions);
        self.velocities_before.extend_from_slice(&self.before);
        self.velocities_after.extend_from_slice(state.velocities);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ChainParams, ChainState, Excitation, Frequency, SimOptions};
    use approx::assert_relative_eq;

    /// Steady harmonic response of a free mass under base motion y = A sin ωt:
    /// x(t) = Im(X e^{iωt}) with X = A (k + icω)/(k − mω² + icω). Returns (x, x') at t.
    fn steady_state(m: f64, k: f64, c: f64, a: f64, w: f64, t: f64) -> (f64, f64) {
        let (nr, ni) = (k, c * w);
        let (dr, di) = (k - m * w * w, c * w);
        let den = dr * dr + di * di;
        let xr = a * (nr * dr + ni * di) / den;
        let xi = a * (ni * dr - nr * di) / den;
        let (s, co) = (w * t).sin_cos();
        // X e^{iωt} = (xr + i xi)(co + i s)
        let im = xr * s + xi * co;
        let re = xr * co - xi * s;
        (im, w * re)
    }

    /// A chain whose gaps are far wider than the motion: three independent linear
    /// oscillators, heavily damped so the transient dies within a few periods.
    fn linear_chain() -> ChainParams {
        ChainParams {
            masses: vec![0.05, 0.12, 0.08],
            stiffness: vec![120.0, 150.0, 90.0],
            damping: vec![2.0, 3.0, 2.5],
            gaps: vec![10.0, 10.0],
            restitution: 0.6,
            excitation: Excitation {
                amplitude: 0.01,
                frequency: Frequency::OmegaRatio(0.8),
            },
            stops: Default::default(),
            forces: Vec::new(),
        }
    }

    #[test]
    fn stroboscopic_samples_match_the_steady_harmonic_response() {
        let p = linear_chain();
        let w = p.omega();
        let mut sim = Simulator::new(&p, &ChainState::at_rest(3), SimOptions::default()).unwrap();
        let t0 = 0.3 * p.period();
        let options = StroboscopicOptions {
            phase_time: t0,
            transient_periods: 60,
        };
        let mut section = StroboscopicSection::for_simulator(&sim, options).unwrap();
        sim.run_until(80.5 * p.period(), &mut section).unwrap();
        assert_eq!(section.len(), 21, "samples n = 60..=80");
        assert_eq!(section.indices.first(), Some(&60));
        for j in 0..section.len() {
            let t = section.times[j];
            assert_relative_eq!(t, t0 + (60 + j) as f64 * p.period(), max_relative = 1e-15);
            for i in 0..3 {
                let (x, v) = steady_state(p.masses[i], p.stiffness[i], p.damping[i], 0.01, w, t);
                let got_x = section.positions_at(j).unwrap()[i];
                let got_v = section.velocities_at(j).unwrap()[i];
                assert!(
                    (got_x - x).abs() <= 1e-9 * 0.01 && (got_v - v).abs() <= 1e-9 * 0.01 * w,
                    "sample {j} mass {i}: t = {t}, x = {got_x} vs {x}, v = {got_v} vs {v}"
                );
            }
        }
        let series = section.position_series(1).unwrap();
        assert_eq!(series.len(), section.len());
        assert!(section.position_series(3).is_none());
    }

    #[test]
    fn stroboscopic_first_sample_is_the_initial_state_and_times_are_period_boundaries() {
        let p = linear_chain();
        let init = ChainState {
            positions: vec![0.001, -0.002, 0.003],
            velocities: vec![0.01, 0.02, -0.03],
        };
        let mut sim = Simulator::new(&p, &init, SimOptions::default()).unwrap();
        let mut section = StroboscopicSection::for_simulator(&sim, StroboscopicOptions::default()).unwrap();
        sim.run_until(3.0 * p.period(), &mut section).unwrap();
        assert_eq!(section.len(), 4);
        for i in 0..3 {
            // Evaluated from the closed form at its start time: equal up to rounding.
            assert_relative_eq!(
                section.positions_at(0).unwrap()[i],
                init.positions[i],
                max_relative = 1e-14
            );
            assert_relative_eq!(
                section.velocities_at(0).unwrap()[i],
                init.velocities[i],
                max_relative = 1e-14
            );
        }
        // With t₀ = 0 the sample times are exactly the simulator's period boundaries n·T.
        for (n, &t) in section.times.iter().enumerate() {
            assert_eq!(t.to_bits(), (n as f64 * sim.period()).to_bits(), "sample {n}");
        }
        // The last sample, at the run's end, is the simulator's final state.
        let end = sim.state();
        for i in 0..3 {
            assert_relative_eq!(
                section.positions_at(3).unwrap()[i],
                end.positions[i],
                max_relative = 1e-12
            );
            assert_relative_eq!(
                section.velocities_at(3).unwrap()[i],
                end.velocities[i],
                max_relative = 1e-12
            );
        }
    }

    /// The paper's default case from rest, sampled at t = nT, n = 0..=40, against an
    /// independent adaptive integration (Dormand–Prince 8(5,3), rtol 1e-11, event location;
    /// `tests/data/reference/default-case-strobe.csv`).
    #[test]
    fn stroboscopic_section_of_the_default_case_matches_the_reference_integration() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/data/reference/default-case-strobe.csv"
        );
        let reference = std::fs::read_to_string(path).expect("tests/data/reference/default-case-strobe.csv");
        let p = ChainParams::default();
        let mut sim = Simulator::new(&p, &ChainState::at_rest(3), SimOptions::default()).unwrap();
        let mut section = StroboscopicSection::for_simulator(&sim, StroboscopicOptions::default()).unwrap();
        sim.run_until(40.0 * p.period(), &mut section).unwrap();
        assert_eq!(section.len(), 41);
        let mut worst = (0.0f64, 0usize);
        for (j, line) in reference.lines().skip(1).enumerate() {
            let cols: Vec<f64> = line.trim().split(',').map(|c| c.parse().unwrap()).collect();
            assert_eq!(cols[0] as usize, j);
            let got = section.positions_at(j).unwrap();
            for i in 0..3 {
                let err = (got[i] - cols[1 + i]).abs();
                if err > worst.0 {
                    worst = (err, j);
                }
            }
        }
        // Positions are of order 0.1 m, printed to 13 significant digits; the two methods
        // agree to ~1e-13 m. At speeds of order 1 m/s a sample taken 1e-10 s off its time
        // would already break this bound.
        assert!(
            worst.0 < 1e-10,
            "largest deviation {} m at n = {}",
            worst.0,
            worst.1
        );
    }

    #[test]
    fn stroboscopic_section_attached_mid_run_starts_at_the_next_section_time() {
        let p = linear_chain();
        let mut sim = Simulator::new(&p, &ChainState::at_rest(3), SimOptions::default()).unwrap();
        sim.run_until(10.25 * p.period(), &mut ()).unwrap();
        let mut section = StroboscopicSection::for_simulator(&sim, StroboscopicOptions::default()).unwrap();
        sim.run_until(13.0 * p.period(), &mut section).unwrap();
        assert_eq!(section.indices, vec![11, 12, 13]);
    }

    #[test]
    fn stroboscopic_section_rejects_bad_options() {
        assert!(StroboscopicSection::new(0, 1.0, StroboscopicOptions::default()).is_err());
        assert!(StroboscopicSection::new(3, 0.0, StroboscopicOptions::default()).is_err());
        assert!(StroboscopicSection::new(3, f64::NAN, StroboscopicOptions::default()).is_err());
        let bad = StroboscopicOptions {
            phase_time: f64::NAN,
            ..Default::default()
        };
        assert!(StroboscopicSection::new(3, 1.0, bad).is_err());
    }

    /// Two equal undamped, unforced masses; the lower one is launched upward at speed V.
    /// It moves as x₂ = (V/ωₙ) sin ωₙt while the upper one rests, so it strikes after
    /// t* = asin(δωₙ/V)/ωₙ with closing speed √(V² − (δωₙ)²), and Newton's law for equal
    /// masses gives the upper mass (1+μ)/2 and the lower (1−μ)/2 of that speed.
    #[test]
    fn impact_section_records_the_closed_form_first_impact() {
        let (m, k, delta, v0, mu) = (0.1, 40.0, 0.01, 0.5, 0.6);
        let p = ChainParams {
            masses: vec![m, m],
            stiffness: vec![k, k],
            damping: vec![0.0, 0.0],
            gaps: vec![delta],
            restitution: mu,
            excitation: Excitation {
                amplitude: 0.0,
                frequency: Frequency::Hertz(1.0),
            },
            stops: Default::default(),
            forces: Vec::new(),
        };
        let wn = (k / m).sqrt();
        let t_star = (delta * wn / v0).asin() / wn;
        let vc = (v0 * v0 - (delta * wn).powi(2)).sqrt();
        let init = ChainState {
            positions: vec![0.0, 0.0],
            velocities: vec![0.0, v0],
        };
        let mut sim = Simulator::new(&p, &init, SimOptions::default()).unwrap();
        let mut section = ImpactSection::for_simulator(&sim, 0.0).unwrap();
        let mut late = ImpactSection::for_simulator(&sim, t_star * 1.001).unwrap();
        sim.run_until(t_star * 1.0005, &mut (&mut section, &mut late))
            .unwrap();
        assert_eq!(section.len(), 1, "{:?}", section.points);
        assert!(
            late.is_empty(),
            "an impact before the transient was recorded: {:?}",
            late.points
        );
        let pt = section.points[0];
        assert_relative_eq!(pt.time, t_star, max_relative = 1e-12);
        assert_relative_eq!(pt.phase, t_star / 1.0, max_relative = 1e-12);
        assert_eq!(pt.contact, 0);
        assert_relative_eq!(pt.closing_speed, vc, max_relative = 1e-10);
        assert_relative_eq!(pt.opening_speed, mu * vc, max_relative = 1e-10);
        let x = section.positions_at(0).unwrap();
        assert!(
            x[0].abs() < 1e-15 && (x[1] - delta).abs() < 1e-12 * delta,
            "positions {x:?}"
        );
        let before = section.velocities_before_at(0).unwrap();
        assert!(
            before[0].abs() < 1e-15,
            "upper mass moved before the impact: {before:?}"
        );
        assert_relative_eq!(before[1], vc, max_relative = 1e-10);
        let after = section.velocities_after_at(0).unwrap();
        assert_relative_eq!(after[0], 0.5 * (1.0 + mu) * vc, max_relative = 1e-10);
        assert_relative_eq!(after[1], 0.5 * (1.0 - mu) * vc, max_relative = 1e-10);
        assert_eq!(section.indices_at_contact(0).collect::<Vec<_>>(), vec![0]);
        assert_eq!(section.indices_at_contact(1).count(), 0);
    }

    #[test]
    fn impact_section_phase_is_a_fraction_of_the_period() {
        let p = ChainParams::default();
        let mut sim = Simulator::new(&p, &ChainState::at_rest(3), SimOptions::default()).unwrap();
        let transient = 10.0 * p.period();
        let mut section = ImpactSection::for_simulator(&sim, transient).unwrap();
        sim.run_until(20.0 * p.period(), &mut section).unwrap();
        assert!(!section.is_empty());
        for pt in &section.points {
            assert!(pt.time >= transient);
            assert!((0.0..1.0).contains(&pt.phase), "phase {}", pt.phase);
            let back = (pt.time / p.period()).floor() * p.period() + pt.phase * p.period();
            assert_relative_eq!(back, pt.time, max_relative = 1e-12);
            assert!(pt.closing_speed >= 0.0);
        }
        // An isolated impact's closing speed is the difference of the recorded
        // pre-impact velocities (the state comes from the flow, the speed from the event).
        for (j, pt) in section.points.iter().enumerate() {
            let simultaneous = section.points.iter().filter(|q| q.time == pt.time).count() > 1;
            if simultaneous {
                continue;
            }
            let v = section.velocities_before_at(j).unwrap();
            let closing = v[pt.contact + 1] - v[pt.contact];
            assert!(
                (closing - pt.closing_speed).abs() <= 1e-9 * (1.0 + pt.closing_speed),
                "impact {j} at t = {}: state gives {closing}, event {}",
                pt.time,
                pt.closing_speed
            );
        }
        assert_eq!(section.positions.len(), 3 * section.len());
        assert_eq!(section.velocities_before.len(), 3 * section.len());
    }
}
