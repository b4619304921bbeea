//! Going back in time: a saved solver state to return to after a trial advance (two-way
//! coupling advances the charge over a window, and redoes it when the window's force was not
//! yet consistent with the charge; see `crate::coupling`).

use super::state::ChargeSolver;

/// A state of a [`ChargeSolver`] to return to with [`ChargeSolver::rewind`]. It holds the
/// solver's scalars and buffers, and the lengths of what the solver appends to (per-period
/// figures, samples), which a rewind truncates instead of copying.
#[derive(Debug, Clone)]
pub struct ChargeCheckpoint {
    saved: Box<ChargeSolver>,
    periods: usize,
    /// The period being booked (updated in place as the solver advances).
    open_period: Option<super::PeriodStats>,
    samples: Option<usize>,
    vq: Option<usize>,
}

impl ChargeCheckpoint {
    /// Time of the saved state, s.
    pub fn time(&self) -> f64 {
        self.saved.t
    }
}

impl ChargeSolver {
    /// Saves the current state (see [`ChargeCheckpoint`]). Its cost does not grow with the
    /// length of the run.
    pub fn checkpoint(&mut self) -> ChargeCheckpoint {
        let periods = std::mem::take(&mut self.periods);
        let samples = self.sampler.as_mut().map(|g| std::mem::take(&mut g.data));
        let vq = self.vq.as_mut().map(|g| std::mem::take(&mut g.data));
        // The expansion of the current piece is scratch, rebuilt for every piece: not saved.
        let poly = std::mem::take(&mut self.poly);
        let saved = Box::new(self.clone());
        self.poly = poly;
        let cp = ChargeCheckpoint {
            saved,
            periods: periods.len(),
            open_period: periods.last().cloned(),
            samples: samples.as_ref().map(|s| s.times.len()),
            vq: vq.as_ref().map(|s| s.times.len()),
        };
        self.periods = periods;
        if let (Some(g), Some(d)) = (self.sampler.as_mut(), samples) {
            g.data = d;
        }
        if let (Some(g), Some(d)) = (self.vq.as_mut(), vq) {
            g.data = d;
        }
        cp
    }

    /// Returns to the state saved in `cp`: everything recorded since (periods, samples, the
    /// energy, the breakdown ratio) is dropped. Samples taken out with
    /// [`take_samples`](Self::take_samples) after the checkpoint are not put back, so take
    /// them only once a trial is accepted.
    pub fn rewind(&mut self, cp: &ChargeCheckpoint) {
        let mut periods = std::mem::take(&mut self.periods);
        periods.truncate(cp.periods);
        if let (Some(last), Some(open)) = (periods.last_mut(), &cp.open_period) {
            *last = open.clone();
        }
        let mut samples = self.sampler.as_mut().map(|g| std::mem::take(&mut g.data));
        let mut vq = self.vq.as_mut().map(|g| std::mem::take(&mut g.data));
        let poly = std::mem::take(&mut self.poly);
        *self = (*cp.saved).clone();
        self.poly = poly;
        self.periods = periods;
        if let (Some(g), Some(mut d), Some(n)) = (self.sampler.as_mut(), samples.take(), cp.samples) {
            d.truncate(n);
            g.data = d;
        }
        if let (Some(g), Some(mut d), Some(n)) = (self.vq.as_mut(), vq.take(), cp.vq) {
            d.truncate(n);
            g.data = d;
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::ChainParams;
    use crate::electrical::{ChargeOptions, ChargeSolver, HarvesterParams};
    use crate::{ChainState, SimOptions, Simulator};

    /// Advancing, rewinding and advancing again gives the same numbers as advancing once.
    #[test]
    fn a_rewound_solver_repeats_itself_exactly() {
        let chain = ChainParams::default();
        let t = chain.period();
        let run = |split: bool| {
            let mut sim = Simulator::new(&chain, &ChainState::at_rest(3), SimOptions::default()).unwrap();
            let mut s =
                ChargeSolver::for_chain(&HarvesterParams::default(), &chain, ChargeOptions::default())
                    .unwrap()
                    .with_periodic_sampling(16)
                    .unwrap();
            sim.run_until(2.5 * t, &mut s).unwrap();
            if split {
                let cp = s.checkpoint();
                let mut trial = sim.clone();
                trial.run_until(3.7 * t, &mut s).unwrap();
                assert!(s.periods().len() > cp_periods(&cp));
                s.rewind(&cp);
                assert_eq!(s.time(), cp.time());
            }
            sim.run_until(4.0 * t, &mut s).unwrap();
            (
                s.charge(),
                s.total_energy(),
                s.periods().to_vec(),
                s.take_samples(),
            )
        };
        let (a, b) = (run(false), run(true));
        assert_eq!(a.0.to_bits(), b.0.to_bits());
        assert_eq!(a.1.to_bits(), b.1.to_bits());
        assert_eq!(a.2, b.2);
        assert_eq!(a.3, b.3);
    }

    fn cp_periods(cp: &super::ChargeCheckpoint) -> usize {
        cp.periods
    }
}
