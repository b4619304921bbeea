//! What the charge solver is told (its options) and what it reports: per-period energy and
//! peaks, samples, work counters, and the power summary of seed eq. 14.

use super::state::Row;
use crate::error::ParamError;

/// Numerical settings of the charge solver.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct ChargeOptions {
    /// Relative tolerance of the local error on the load voltage (and storage voltage) per
    /// step and of the delivered energy per period (`electrical.rtol`), dimensionless.
    /// Default 1e-5, which keeps the energy per period within 1e-7 relative of a converged
    /// solution on the paper's default and chatter cases for loads from 1 kΩ to 10 GΩ and for
    /// the rectifier.
    pub rtol: f64,
    /// Absolute voltage tolerance, V (`electrical.atol_voltage`). Absent (default): `rtol`
    /// times the largest load voltage seen so far (resistor) or the largest storage voltage,
    /// at least nV_T (rectifier).
    pub atol_voltage: Option<f64>,
    /// Guard against runaway step counts (`electrical.max_steps_per_period`): at most this
    /// many steps, accepted or rejected, within one excitation period. Default 10 000 000.
    pub max_steps_per_period: u64,
    /// Resistor: carry the boundary layer after a kink (width R·C) in closed form within one
    /// step instead of crossing it with short steps (`electrical.analytic_layers`, default
    /// true; see the solver's `layer` module). Same results within the tolerance, fewer steps.
    pub analytic_layers: bool,
}

impl Default for ChargeOptions {
    fn default() -> Self {
        ChargeOptions {
            rtol: 1e-5,
            atol_voltage: None,
            max_steps_per_period: 10_000_000,
            analytic_layers: true,
        }
    }
}

impl ChargeOptions {
    /// Checks the options, naming the offending key.
    pub fn validate(&self) -> Result<(), ParamError> {
        let bad = |name: &str, value: f64, reason| ParamError::Invalid {
            name: name.into(),
            value,
            reason,
        };
        if !(self.rtol.is_finite() && self.rtol >= 1e-12 && self.rtol <= 1e-2) {
            return Err(bad("rtol", self.rtol, "must lie in [1e-12, 1e-2]"));
        }
        if let Some(a) = self.atol_voltage
            && !(a.is_finite() && a > 0.0)
        {
            return Err(bad("atol_voltage", a, "must be positive"));
        }
        if self.max_steps_per_period == 0 {
            return Err(bad("max_steps_per_period", 0.0, "must be positive"));
        }
        Ok(())
    }
}

/// What one excitation period `[kT, (k+1)T)` delivered.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PeriodStats {
    /// Period index k (time `kT` to `(k+1)T`).
    pub index: i64,
    /// Start of the part of the period covered, s.
    pub t_start: f64,
    /// End of the part of the period covered, s.
    pub t_end: f64,
    /// Energy delivered to the load in the period, J: `∫ V²/R dt` for the resistor (seed
    /// eq. 14's numerator), `∫ V_s I_out dt` (into storage capacitor and its resistor) for the
    /// rectifier, 0 for open and short circuit.
    pub energy_j: f64,
    /// Largest |current| seen in the period (at solver nodes and sample times), A.
    pub peak_current_a: f64,
    /// Largest |terminal voltage| seen in the period (at solver nodes and sample times), V.
    pub peak_voltage_v: f64,
    /// Storage capacitor voltage at the end of the covered part, V (rectifier only).
    pub storage_voltage_v: Option<f64>,
}

impl PeriodStats {
    /// Whether the whole period `period`, s, was covered.
    pub fn is_complete(&self, period: f64) -> bool {
        self.t_end - self.t_start >= period * (1.0 - 1e-9)
    }
}

/// Electrical quantities sampled at given times.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ElectricalSamples {
    /// Sample times, s.
    pub times: Vec<f64>,
    /// Charge moved between the electrodes Q, C.
    pub charge_c: Vec<f64>,
    /// Current out of the transducer I = dQ/dt, A.
    pub current_a: Vec<f64>,
    /// Terminal (load) voltage V = V_oc − Q/C, V.
    pub voltage_v: Vec<f64>,
    /// Transducer capacitance C, F.
    pub capacitance_f: Vec<f64>,
    /// Open-circuit voltage V_oc, V.
    pub voc_v: Vec<f64>,
    /// Storage capacitor voltage, V (rectifier only; empty otherwise).
    pub storage_voltage_v: Vec<f64>,
    /// Energy delivered to the load since the solver started, J.
    pub energy_j: Vec<f64>,
}

impl ElectricalSamples {
    /// Appends `other`'s samples.
    pub fn append(&mut self, mut other: ElectricalSamples) {
        if self.times.is_empty() {
            *self = other;
            return;
        }
        self.times.append(&mut other.times);
        self.charge_c.append(&mut other.charge_c);
        self.current_a.append(&mut other.current_a);
        self.voltage_v.append(&mut other.voltage_v);
        self.capacitance_f.append(&mut other.capacitance_f);
        self.voc_v.append(&mut other.voc_v);
        self.storage_voltage_v.append(&mut other.storage_voltage_v);
        self.energy_j.append(&mut other.energy_j);
    }

    /// Drops the first `n` samples.
    pub fn drain_front(&mut self, n: usize) {
        fn cut(v: &mut Vec<f64>, n: usize) {
            v.drain(..n.min(v.len()));
        }
        cut(&mut self.times, n);
        cut(&mut self.charge_c, n);
        cut(&mut self.current_a, n);
        cut(&mut self.voltage_v, n);
        cut(&mut self.capacitance_f, n);
        cut(&mut self.voc_v, n);
        cut(&mut self.storage_voltage_v, n);
        cut(&mut self.energy_j, n);
    }

    /// Keeps the first `n` samples.
    pub(super) fn truncate(&mut self, n: usize) {
        self.times.truncate(n);
        self.charge_c.truncate(n);
        self.current_a.truncate(n);
        self.voltage_v.truncate(n);
        self.capacitance_f.truncate(n);
        self.voc_v.truncate(n);
        self.storage_voltage_v.truncate(n);
        self.energy_j.truncate(n);
    }

    pub(super) fn push(&mut self, t: f64, row: &Row, rectifier: bool) {
        self.times.push(t);
        self.charge_c.push(row.charge);
        self.current_a.push(row.current);
        self.voltage_v.push(row.voltage);
        self.capacitance_f.push(row.ts.capacitance());
        self.voc_v.push(row.ts.voc);
        if rectifier {
            self.storage_voltage_v.push(row.storage);
        }
        self.energy_j.push(row.energy);
    }
}

/// Work counters of a solver.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SolverStats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps (error test, Newton failure, or a rectifier step over a switching).
    pub rejected: u64,
    /// Newton iterations (rectifier).
    pub newton_iterations: u64,
    /// Evaluations of the gap waveform (for the simulator's flow: of its Taylor expansion,
    /// see [`GapWaveform`](crate::electrical::GapWaveform)).
    pub waveform_evaluations: u64,
    /// Smooth pieces integrated (flows, split at period boundaries).
    pub pieces: u64,
}

/// Average power and related figures over a run (seed eq. 14).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PowerSummary {
    /// Complete periods averaged over (after the transient).
    pub periods: usize,
    /// `P_a = Σ E_k / (N T)` over those periods, W (seed eq. 14).
    pub average_power_w: f64,
    /// Mean energy per period over those periods, J.
    pub energy_per_period_j: f64,
    /// Largest |current| over those periods, A.
    pub peak_current_a: f64,
    /// Largest |terminal voltage| over those periods, V.
    pub peak_voltage_v: f64,
}

/// Averages the complete periods of `periods` after the first `transient` complete ones;
/// `None` if none remain. `period` is the excitation period T, s.
pub fn summarize(periods: &[PeriodStats], period: f64, transient: usize) -> Option<PowerSummary> {
    let used: Vec<&PeriodStats> = periods
        .iter()
        .filter(|p| p.is_complete(period))
        .skip(transient)
        .collect();
    if used.is_empty() {
        return None;
    }
    let n = used.len();
    let energy: f64 = used.iter().map(|p| p.energy_j).sum();
    Some(PowerSummary {
        periods: n,
        average_power_w: energy / (n as f64 * period),
        energy_per_period_j: energy / n as f64,
        peak_current_a: used.iter().map(|p| p.peak_current_a).fold(0.0, f64::max),
        peak_voltage_v: used.iter().map(|p| p.peak_voltage_v).fold(0.0, f64::max),
    })
}

/// The paper's running average power `P_a(N) = Σ_{k<N} E_k / (N T)`, W, for N = 1, 2, … over
/// the complete periods of `periods` (from the first one recorded, transient included).
pub fn power_curve(periods: &[PeriodStats], period: f64) -> Vec<f64> {
    let mut sum = 0.0;
    periods
        .iter()
        .filter(|p| p.is_complete(period))
        .enumerate()
        .map(|(k, p)| {
            sum += p.energy_j;
            sum / ((k + 1) as f64 * period)
        })
        .collect()
}
