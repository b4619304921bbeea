//! The manifests of the commands other than the grid jobs, each a serde type that its command
//! writes and `plot DIR` (and `--resume`, `merge`) reads. The fields are in the order of the
//! files' keys.

use crate::electrical::breakdown::BreakdownMargin;
use crate::electrical::{HarvesterParams, LoadPoint};
use crate::model::ChainParams;
use crate::report::BaseMotionSummary;
use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::{Kind, PeriodsRecord};

/// Where a branch of a continuation comes from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParentRecord {
    /// The parent branch (0-based).
    pub branch: usize,
    /// The bifurcation on it (0-based).
    pub bifurcation: usize,
}

/// One branch of a continuation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BranchRecord {
    /// Period of its orbits, in excitation periods.
    pub period: u32,
    /// Where it branched off.
    pub parent: Option<ParentRecord>,
    /// Points on it.
    pub points: usize,
    /// Why it ended, in words.
    pub end: String,
}

/// One bifurcation of a continuation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BifurcationRecord {
    /// Its branch (0-based).
    pub branch: usize,
    /// Its kind (`fold`, `period_doubling`, …).
    pub kind: String,
    /// Its detail, in words.
    pub detail: String,
    /// The parameter there.
    pub param: f64,
    /// How precisely the parameter is known.
    pub precision: f64,
    /// The branch it starts (0-based).
    pub child_branch: Option<usize>,
    /// At a branch point: the branch that leaves it the other way (0-based).
    #[serde(default)]
    pub other_child_branch: Option<usize>,
    /// Floquet multipliers there, `[re, im]`.
    pub multipliers: Vec<[f64; 2]>,
    /// The kind of a grazing crossing.
    pub crossing: Option<String>,
    /// Its Nordmark class.
    pub nordmark: Option<String>,
    /// Multipliers just past it.
    pub multipliers_after: Option<Vec<[f64; 2]>>,
    /// The orbit's state at t ≡ 0 (mod T) there: positions (m) then velocities (m/s).
    #[serde(default)]
    pub state: Vec<f64>,
}

/// The cascade of period doublings from the first branch.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CascadeRecord {
    /// Parameters of the doublings.
    pub period_doublings: Vec<f64>,
    /// Ratios of successive intervals.
    pub feigenbaum_ratios: Vec<f64>,
}

/// `continue.json`: the settings, branches and bifurcations of a continuation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContinueManifest {
    /// Always [`Kind::Continue`].
    pub command: Kind,
    /// Whether the continuation ran to its ends (`false`: stopped by a signal; the branches
    /// so far are written).
    #[serde(default = "finished")]
    pub complete: bool,
    /// The continued key.
    pub param: String,
    /// Start of the range.
    pub from: f64,
    /// End of the range.
    pub to: f64,
    /// Transient periods before the first orbit.
    pub transient_periods: u32,
    /// Depth of period doublings followed.
    pub doublings: u32,
    /// Most points per branch.
    pub max_points: usize,
    /// Mechanics only (no harvester).
    pub mechanics_only: bool,
    /// The branches.
    pub branches: Vec<BranchRecord>,
    /// The bifurcations, by branch.
    pub bifurcations: Vec<BifurcationRecord>,
    /// The doubling cascade.
    pub cascade: CascadeRecord,
    /// The configuration (the library's document).
    pub settings: Value,
    /// The program's version.
    pub vibrotribo_version: String,
}

/// The kinds of the manifests that earlier versions wrote without a `command`.
fn load_sweep() -> Kind {
    Kind::LoadSweep
}

fn periodic() -> Kind {
    Kind::Periodic
}

fn optimize_mass_ratio() -> Kind {
    Kind::OptimizeMassRatio
}

fn lyapunov() -> Kind {
    Kind::Lyapunov
}

/// What a manifest without a `complete` key describes: a finished job.
fn finished() -> bool {
    true
}

/// The air-breakdown margin at one load over the last period.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MarginRecord {
    /// The load, Ω.
    pub load_resistance_ohm: f64,
    /// The margin.
    pub air_breakdown: BreakdownMargin,
}

/// `load_sweep.json`: the optimal load and the sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LoadSweepManifest {
    /// Always [`Kind::LoadSweep`] (files without the key read as such).
    #[serde(default = "load_sweep")]
    pub command: Kind,
    /// The best load.
    pub optimum: LoadPoint,
    /// Whether the best grid point is at an end of the range.
    pub optimum_at_edge: bool,
    /// The configured load, Ω.
    pub configured_load_ohm: f64,
    /// Average power at the configured load, W.
    pub configured_average_power_w: f64,
    /// Configured power over optimal power.
    pub power_ratio_configured_to_optimum: f64,
    /// Air-breakdown margins at the loads of `vq_cycle.csv`.
    pub air_breakdown_last_period: Vec<MarginRecord>,
    /// Every load of the sweep.
    pub points: Vec<LoadPoint>,
    /// Periods run.
    pub periods: u64,
    /// Of which transient.
    pub transient_periods: u64,
    /// The harvester at the configured load.
    pub harvester: HarvesterParams,
    /// The configuration (the library's document).
    pub settings: Value,
    /// The base motion, when it is not the chain's own harmonic.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_motion: Option<BaseMotionSummary>,
}

/// One event of a periodic orbit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OrbitEventRecord {
    /// Time from the section, s.
    pub time_s: f64,
    /// `impact`, `stick`, `release`, ….
    pub kind: String,
    /// The contact (1-based).
    pub contact: usize,
    /// Relative velocity before, m/s.
    pub rel_velocity_m_s: f64,
    /// Relative velocity after, m/s.
    pub rel_velocity_after_m_s: f64,
}

/// `periodic.json`: a periodic orbit, its stability and power.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PeriodicManifest {
    /// Always [`Kind::Periodic`] (files without the key read as such).
    #[serde(default = "periodic")]
    pub command: Kind,
    /// Period in excitation periods.
    pub period: u32,
    /// State at t ≡ 0 (mod T): positions (m) then velocities (m/s).
    pub state: Vec<f64>,
    /// Names of the state's components.
    pub state_names: Vec<String>,
    /// Floquet multipliers, `[re, im]`.
    pub multipliers: Vec<[f64; 2]>,
    /// Their moduli.
    pub multiplier_moduli: Vec<f64>,
    /// Whether every multiplier is inside the unit circle.
    pub stable: bool,
    /// Multipliers outside it.
    pub unstable_dimension: usize,
    /// Impacts per excitation period, all contacts.
    pub impacts_per_period: f64,
    /// Impacts per excitation period by contact.
    pub impacts_per_period_by_contact: Vec<f64>,
    /// Impacts per orbit.
    pub impacts_per_orbit: usize,
    /// Slowest impact, m/s.
    pub min_closing_speed_m_s: Option<f64>,
    /// Its contact (1-based).
    pub min_closing_speed_contact: Option<usize>,
    /// Whether a contact sticks.
    pub sticks: bool,
    /// Average power, W.
    pub average_power_w: Option<f64>,
    /// Energy per excitation period, J.
    pub energy_per_period_j: Option<f64>,
    /// Final Newton residual.
    pub residual: f64,
    /// Residual of each Newton iteration.
    pub residual_history: Vec<f64>,
    /// The events along the orbit.
    pub events: Vec<OrbitEventRecord>,
    /// Excitation period T, s.
    pub excitation_period_s: f64,
    /// Ω.
    pub omega_ratio: f64,
    /// The chain's parameters.
    pub parameters: ChainParams,
    /// The configuration (the library's document).
    pub settings: Value,
}

/// A quadratic fit R_mo(Ω) = a Ω² + b Ω + c to the optima.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitRecord {
    /// a.
    pub a: f64,
    /// b.
    pub b: f64,
    /// c.
    pub c: f64,
    /// Coefficient of determination (`None`: the optima have no variance).
    pub r_squared: Option<f64>,
    /// RMS residual.
    pub rms_residual: f64,
}

/// The paper's quadratic fit R_mo(Ω) = a Ω² + b Ω + c.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PaperFitRecord {
    /// a.
    pub a: f64,
    /// b.
    pub b: f64,
    /// c.
    pub c: f64,
}

/// `fit.json` (`optimize-mass-ratio`): the optima and their quadratic fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitManifest {
    /// Always [`Kind::OptimizeMassRatio`] (files without the key read as such).
    #[serde(default = "optimize_mass_ratio")]
    pub command: Kind,
    /// The fit to the optima.
    pub fit: Option<FitRecord>,
    /// The paper's fit.
    pub paper_fit: PaperFitRecord,
    /// Ω of each optimum.
    pub omega_ratio: Vec<f64>,
    /// The optimal mass ratio there.
    pub optimal_mass_ratio: Vec<f64>,
    /// Transient and recorded periods per point.
    #[serde(flatten)]
    pub periods: PeriodsRecord,
    /// The configuration (the library's document).
    pub settings: Value,
}

/// `x`, or `None` where it is not finite (written `null`, as −∞ exponents are).
pub fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// [`finite`] of each of `xs`.
pub fn finite_all(xs: &[f64]) -> Vec<Option<f64>> {
    xs.iter().copied().map(finite).collect()
}

/// The exponents after a number of periods.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunningRecord {
    /// Periods averaged.
    pub periods: u64,
    /// The exponents then, 1/s (`null`: −∞).
    pub exponents: Vec<Option<f64>>,
}

/// `lyapunov.json`: exponents (1/s, largest first; `null` for −∞), their spread, the
/// convergence and the settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LyapunovManifest {
    /// Always [`Kind::Lyapunov`] (files without the key read as such).
    #[serde(default = "lyapunov")]
    pub command: Kind,
    /// The exponents, 1/s, largest first.
    pub exponents: Vec<Option<f64>>,
    /// Their batch-means standard errors, 1/s.
    pub spread: Vec<Option<f64>>,
    /// Periods averaged.
    pub periods: u64,
    /// Time averaged, s.
    pub time_s: f64,
    /// The largest exponent, 1/s.
    pub largest: Option<f64>,
    /// Its spread, 1/s.
    pub largest_spread: Option<f64>,
    /// Sum of the exponents, 1/s.
    pub sum: Option<f64>,
    /// Kaplan–Yorke dimension.
    pub kaplan_yorke_dimension: Option<f64>,
    /// Directions collapsed by sticking.
    pub collapsed: usize,
    /// Periods skipped at non-differentiable points.
    pub skipped_periods: u64,
    /// Non-differentiable points met.
    pub non_smooth_count: u64,
    /// The first of them, in words.
    pub non_smooth: Vec<String>,
    /// Re-orthonormalisations.
    pub reorthonormalisations: u64,
    /// The exponents of each batch, 1/s.
    pub batches: Vec<Vec<Option<f64>>>,
    /// The exponents after each batch.
    pub running: Vec<RunningRecord>,
    /// Transient periods.
    pub transient_periods: u64,
    /// Seed of the initial directions.
    pub seed: u64,
    /// Whether the run was stopped early.
    pub interrupted: bool,
    /// The configuration (the library's document).
    pub settings: Value,
}

#[cfg(test)]
mod tests {
    use super::super::round_trips;
    use super::*;

    #[test]
    fn continue_manifest_round_trips_byte_for_byte() {
        round_trips::<ContinueManifest>(
            r#"{"command":"continue","complete":true,"param":"omega_ratio","from":0.7,"to":1.0,"transient_periods":200,"doublings":0,"max_points":2000,"mechanics_only":true,"branches":[{"period":1,"parent":null,"points":445,"end":"range end at 0.7"}],"bifurcations":[{"branch":0,"kind":"fold","detail":"","param":0.800850586304854,"precision":2.7024081030575457e-10,"child_branch":null,"other_child_branch":null,"multipliers":[[1.0671300722619446,0.0],[1.000010318521307,0.0],[0.8584749550410304,-0.07662192062756869],[0.8584749550410304,0.07662192062756869],[0.1302838658389211,0.0],[0.018015857594404754,0.0]],"crossing":null,"nordmark":null,"multipliers_after":null,"state":[0.01,-0.02,0.5,-0.25]}],"cascade":{"period_doublings":[],"feigenbaum_ratios":[]},"settings":{},"vibrotribo_version":"0.1.0"}"#,
        );
    }

    #[test]
    fn lyapunov_manifest_round_trips_byte_for_byte() {
        let m = round_trips::<LyapunovManifest>(
            r#"{"command":"lyapunov","exponents":[-3.1202438773260632,null],"spread":[1.6395797461760684,1.6395797461762882],"periods":20,"time_s":1.0260398641294914,"largest":-3.1202438773260632,"largest_spread":1.6395797461760684,"sum":-10.658815658780885,"kaplan_yorke_dimension":0.0,"collapsed":0,"skipped_periods":0,"non_smooth_count":0,"non_smooth":[],"reorthonormalisations":30,"batches":[[1.4302536848834018,-12.089069343665027]],"running":[{"periods":5,"exponents":[1.4302536848834018,-12.089069343665027]}],"transient_periods":10,"seed":1,"interrupted":false,"settings":{}}"#,
        );
        // A −∞ exponent (a direction collapsed by sticking) is written null.
        assert_eq!(m.exponents, [Some(-3.1202438773260632), None]);
        assert_eq!(finite_all(&[1.0, f64::NEG_INFINITY]), [Some(1.0), None]);
    }

    #[test]
    fn load_sweep_manifest_round_trips_byte_for_byte() {
        round_trips::<LoadSweepManifest>(
            r#"{"command":"load-sweep","optimum":{"resistance_ohm":13550799443.411295,"average_power_w":3.127041765618578e-6,"energy_per_period_j":5.613652250477589e-7},"optimum_at_edge":false,"configured_load_ohm":100000.0,"configured_average_power_w":5.468294720027476e-11,"power_ratio_configured_to_optimum":0.00001748711763351124,"air_breakdown_last_period":[{"load_resistance_ohm":100000.0,"air_breakdown":{"worst_ratio":0.5233797000480489,"time_s":1.045750819267165,"gap":1,"gap_voltage_v":33878.99451676965,"gap_m":0.019826468931647315}}],"points":[{"resistance_ohm":1000.0,"average_power_w":5.468303763963152e-13,"energy_per_period_j":9.81667596140803e-14}],"periods":6,"transient_periods":2,"harvester":{"mode":"freestanding","voc_model":"paper","contact":0,"area":0.01,"charge_density":0.000015,"dielectric_thickness":[0.0001,0.0001],"relative_permittivity":[2.0,2.0],"load":"resistor","load_resistance":100000.0,"storage_capacitance":1e-6,"storage_load_resistance":null,"storage_initial_voltage":0.0,"target_voltage":null,"initial_charge":null,"coupling":"one_way","coupling_tolerance":1e-11,"diode_saturation_current":2.52e-9,"diode_ideality":1.752,"diode_series_resistance":0.568,"diode_thermal_voltage":0.025864917007157463,"diode_parallel_conductance":0.0},"settings":{},"base_motion":{"kind":"record","run_as":"exact per-interval cubic forces k_i y + c_i y' of the spline","spline_intervals":"2999","duration_s":"2.999e1","record_scale_factor":"9.8e0","record_peak_acceleration_m_s2":"9.800501213296139e0","baseline_acceleration_offset_m_s2":"8.210046330600539e-4","baseline_acceleration_slope_m_s3":"-5.513643740029047e-5","baseline_relative_size":"8.495276781374053e-5","baseline_removed_displacement_m":"4.425899009433706e-2"}}"#,
        );
    }

    #[test]
    fn periodic_manifest_round_trips_byte_for_byte() {
        round_trips::<PeriodicManifest>(
            r#"{"command":"periodic","period":1,"state":[-0.005571166234713745,-0.37889805643949115],"state_names":["x1_m","v1_m_s"],"multipliers":[[-0.15564532462113567,-0.7446897601001882],[-0.15564532462113567,0.7446897601001882]],"multiplier_moduli":[0.7607813785014027,0.7607813785014027],"stable":true,"unstable_dimension":0,"impacts_per_period":1.0,"impacts_per_period_by_contact":[0.0,1.0],"impacts_per_orbit":1,"min_closing_speed_m_s":0.31634845380098503,"min_closing_speed_contact":2,"sticks":false,"average_power_w":null,"energy_per_period_j":null,"residual":7.079712701691433e-14,"residual_history":[7.079712701691433e-14],"events":[{"time_s":0.036188481991832194,"kind":"impact","contact":2,"rel_velocity_m_s":0.31634845380098503,"rel_velocity_after_m_s":0.2530787630407881}],"excitation_period_s":0.051301993206474564,"omega_ratio":2.5,"parameters":{"masses":[0.05],"stiffness":[120.0],"damping":[0.09798],"gaps":[],"restitution":0.6,"excitation":{"amplitude":0.01,"frequency":{"omega_ratio":2.5}},"stops":{"upper":{"gap":0.0,"restitution":0.8,"frame":"fixed"}}},"settings":{}}"#,
        );
    }

    /// A manifest that an earlier version wrote without its `command` reads as its kind's.
    #[test]
    fn manifests_without_a_command_read_as_their_kind() {
        let m: FitManifest = serde_json::from_str(
            r#"{"fit":null,"paper_fit":{"a":11.43,"b":-28.46,"c":18.03},"omega_ratio":[],"optimal_mass_ratio":[],"transient_periods":20,"recorded_periods":10,"settings":{}}"#,
        )
        .expect("a fit manifest");
        assert_eq!(m.command, Kind::OptimizeMassRatio);
        let m: LyapunovManifest = serde_json::from_str(
            r#"{"exponents":[],"spread":[],"periods":0,"time_s":0.0,"largest":null,"largest_spread":null,"sum":null,"kaplan_yorke_dimension":null,"collapsed":0,"skipped_periods":0,"non_smooth_count":0,"non_smooth":[],"reorthonormalisations":0,"batches":[],"running":[],"transient_periods":0,"seed":1,"interrupted":false,"settings":{}}"#,
        )
        .expect("a lyapunov manifest");
        assert_eq!(m.command, Kind::Lyapunov);
    }

    #[test]
    fn fit_manifest_round_trips_byte_for_byte() {
        round_trips::<FitManifest>(
            r#"{"command":"optimize-mass-ratio","fit":{"a":-38.248148530029624,"b":46.258965805636095,"c":-8.227063467002559,"r_squared":1.0,"rms_residual":6.409875621278547e-16},"paper_fit":{"a":11.43,"b":-28.46,"c":18.03},"omega_ratio":[0.55,0.75,0.95],"optimal_mass_ratio":[5.6453027957633335,4.9525773390828505,1.2],"transient_periods":20,"recorded_periods":10,"settings":{}}"#,
        );
    }
}
