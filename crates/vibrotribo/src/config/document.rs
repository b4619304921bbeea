//! [`Config`]: a configuration document read into the library's types.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};
use toml::{Table, Value};

use super::error::ConfigError;
use super::keys::{self, PerMass};
use super::param::Param;
use crate::electrical::{ChargeOptions, HarvesterParams, TransducerMode};
use crate::excitation::{BaseMotion, ExcitationKind, ExcitationSpec, Harmonic, Quantity, Sweep, WorkBudget};
use crate::model::{ChainParams, ChainState, Excitation, Frequency, SimOptions, Stops};
use crate::study::{Harvester, RunSettings, RunSpec, Sampling};

/// The `[oscillator]` table: the mechanical part of [`ChainParams`]. A single number for
/// `stiffness`, `damping`, `gaps` or `forces` applies to every mass (gap); absent keys take
/// the paper's values (repeated for the chain's length). `forces` are constant external
/// forces on the masses, N, positive upward along x (docs/MODEL.md), e.g. gravity
/// `forces = [-0.47, -1.18, -0.47]` (−m_i g); absent: none ([`ChainParams::forces`]).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub(super) struct OscillatorTable {
    pub masses: Option<Vec<f64>>,
    pub stiffness: Option<PerMass>,
    pub damping: Option<PerMass>,
    pub gaps: Option<PerMass>,
    pub restitution: Option<f64>,
    pub forces: Option<PerMass>,
    /// `[oscillator.stops.upper]`, `[oscillator.stops.lower]`: rigid stops (none by default).
    #[serde(skip_serializing_if = "Stops::is_empty")]
    pub stops: Stops,
}

/// The `[excitation]` table: the kind of base motion and its keys. Every kind
/// keeps `omega_ratio` or `frequency_hz`, the reference frequency whose period T is the
/// unit in which `[run] periods`, `transient_periods` and `samples_per_period` count. A key
/// of another kind than the one given is refused, naming the key. See
/// [`crate::excitation`] for the signals these keys describe.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub(super) struct ExcitationTable {
    /// `"harmonic"` (default: y = A sin ωt), `"multisine"`, `"chirp"`, `"random"` or
    /// `"record"`.
    pub kind: Option<ExcitationKind>,
    /// Base displacement amplitude A, m (harmonic, chirp). Default 0.08.
    pub amplitude: Option<f64>,
    /// Reference frequency as Ω = ω/√(k₁/m₁) (default 0.70); or `frequency_hz`.
    pub omega_ratio: Option<f64>,
    /// Reference frequency, Hz.
    pub frequency_hz: Option<f64>,
    /// Multisine: `[{amplitude = m, ratio = multiple of the reference frequency (or
    /// frequency_hz = Hz), phase = rad (default 0)}, …]`, y = Σ A sin(ω t + φ), at most
    /// `MAX_HARMONICS` (64) of them.
    pub harmonics: Option<Vec<HarmonicEntry>>,
    /// Chirp: instantaneous frequency at t = 0, Hz.
    pub f_start_hz: Option<f64>,
    /// Chirp: instantaneous frequency at the end of `duration_s`, Hz (below `f_start_hz`:
    /// a down-sweep).
    pub f_end_hz: Option<f64>,
    /// Chirp: `"linear"` (default) or `"logarithmic"` in frequency.
    pub sweep: Option<Sweep>,
    /// Chirp, random: the signal's duration, s (at least the run's, `run.periods` × T;
    /// default exactly the run's). For random, the frequency grid is 1/duration.
    pub duration_s: Option<f64>,
    /// Chirp, random: bound on the spline's displacement error relative to the chirp's
    /// amplitude or the random signal's RMS displacement (Hall–Meyer bound
    /// 5/384 h⁴ max|y''''|; the knot spacing h follows). Default 1e-9.
    pub spline_tolerance: Option<f64>,
    /// Random: RMS base acceleration, m/s², flat one-sided PSD between `f_low_hz` and
    /// `f_high_hz`.
    pub rms_acceleration: Option<f64>,
    /// Random (flat): lower band edge, Hz.
    pub f_low_hz: Option<f64>,
    /// Random (flat): upper band edge, Hz.
    pub f_high_hz: Option<f64>,
    /// Random (table): frequencies of the PSD points, Hz, increasing (instead of
    /// `rms_acceleration`; linear interpolation, zero outside).
    pub psd_frequencies_hz: Option<Vec<f64>>,
    /// Random (table): one-sided PSD of the base acceleration at those points, (m/s²)²/Hz.
    pub psd_values: Option<Vec<f64>>,
    /// Random: seed of the phases (the same seed, the same signal). Default 0.
    pub seed: Option<u64>,
    /// Record: CSV file with a header, first column `time_s` (s), second the value; a
    /// relative path is relative to the configuration file (to the working directory for a
    /// configuration not read from a file). The first sample is the run's t = 0; uneven
    /// sampling is allowed; the record must last at least `run.periods` × T.
    pub file: Option<String>,
    /// Record: `"displacement"` (m; a not-a-knot cubic spline through the samples) or
    /// `"acceleration"` (m/s²; integrated exactly as piecewise linear, baseline-corrected by
    /// removing the least-squares cubic from the displacement).
    pub quantity: Option<Quantity>,
    /// Record: factor applied to the values. Default 1.
    pub scale: Option<f64>,
    /// Record: scale the values so that the largest |acceleration| is this, m/s² (instead
    /// of `scale`).
    pub peak_acceleration: Option<f64>,
}

/// One harmonic of `excitation.harmonics`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub(super) struct HarmonicEntry {
    /// Displacement amplitude, m.
    pub amplitude: Option<f64>,
    /// Frequency as a multiple of the reference frequency (or `frequency_hz`).
    pub ratio: Option<f64>,
    /// Frequency, Hz.
    pub frequency_hz: Option<f64>,
    /// Phase at t = 0, rad. Default 0.
    pub phase: Option<f64>,
}

/// A whole configuration file. The `[run]`, `[options]`, `[harvester]` and `[electrical]`
/// tables are the library's [`RunSettings`], [`SimOptions`], [`HarvesterParams`] and
/// [`ChargeOptions`] themselves.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub(super) struct Document {
    pub oscillator: OscillatorTable,
    pub excitation: ExcitationTable,
    pub run: RunSettings,
    pub options: SimOptions,
    pub harvester: Option<HarvesterParams>,
    pub electrical: ChargeOptions,
}

/// A configuration: the TOML tree it was read from (with overrides applied) and its reading
/// in the library's types, all validated.
///
/// The same keys address parameters everywhere: in files, in overrides
/// ([`set`](Self::set), the command line's `--set`, Python keyword arguments) and in sweeps,
/// which also accept the derived keys of [`DERIVED_KEYS`](super::DERIVED_KEYS)
/// (`mass_ratio`, `gap_ratio`, …).
///
/// ```
/// use vibrotribo::config::Config;
///
/// let mut c = Config::from_toml_str("[oscillator]\nmasses = [0.05, 0.15, 0.05]\n")?;
/// c.set("excitation.omega_ratio", 0.6.into())?;
/// c.set("oscillator.gaps[1]", 0.03.into())?;
/// assert_eq!(c.chain().gaps, vec![0.02, 0.03]);
/// let err = c.set("oscillator.masses[1]", (-1.0).into()).unwrap_err();
/// assert!(err.to_string().contains("oscillator.masses[1] = -1"));
/// # Ok::<(), vibrotribo::config::ConfigError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Config {
    table: Table,
    /// The tree read into the document's types (what a [`Param`](super::Param) sets).
    doc: Document,
    chain: ChainParams,
    run: RunSettings,
    initial: ChainState,
    options: SimOptions,
    harvester: HarvesterParams,
    electrical: ChargeOptions,
    excitation: ExcitationSpec,
    /// The base motion built, for every kind but `harmonic` (shared: configurations are
    /// cloned often).
    base: Option<Arc<BaseMotion>>,
    /// How much work building the base motion may do, and its stop flag (kept for the
    /// configurations derived from this one).
    budget: WorkBudget,
}

impl Default for Config {
    /// The paper's default case.
    fn default() -> Self {
        Config::from_table(Table::new()).expect("the defaults are valid")
    }
}

impl Config {
    /// Reads the TOML file at `path`.
    pub fn from_path(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|e| ConfigError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        let dir = path.parent().map(Path::to_path_buf);
        Self::parse(&text, &path.display().to_string(), dir, &WorkBudget::default())
    }

    /// [`from_path`](Self::from_path) with the base motion built within `budget` (a random
    /// signal costlier than [`MAX_PIECE_EVALUATIONS`](crate::excitation::MAX_PIECE_EVALUATIONS)
    /// harmonic evaluations is refused unless it allows large builds; a set stop flag stops
    /// the build). The configurations derived from this one keep the budget.
    pub fn from_path_within(path: &Path, budget: &WorkBudget) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|e| ConfigError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        let dir = path.parent().map(Path::to_path_buf);
        Self::parse(&text, &path.display().to_string(), dir, budget)
    }

    /// The budget future base-motion builds of this configuration and those derived from it
    /// (by [`set`](Self::set), [`with_values`](Self::with_values)) are held to.
    pub fn set_budget(&mut self, budget: WorkBudget) {
        self.budget = budget;
    }

    /// The budget this configuration's base-motion builds are held to
    /// ([`set_budget`](Self::set_budget)).
    pub fn budget(&self) -> &WorkBudget {
        &self.budget
    }

    /// Reads a configuration from TOML text (a record's relative path is relative to the
    /// working directory).
    pub fn from_toml_str(text: &str) -> Result<Self, ConfigError> {
        Self::parse(text, "the configuration", None, &WorkBudget::default())
    }

    /// [`from_toml_str`](Self::from_toml_str) with the base motion built within `budget` (see
    /// [`from_path_within`](Self::from_path_within)).
    pub fn from_toml_str_within(text: &str, budget: &WorkBudget) -> Result<Self, ConfigError> {
        Self::parse(text, "the configuration", None, budget)
    }

    fn parse(
        text: &str,
        origin: &str,
        base_dir: Option<PathBuf>,
        budget: &WorkBudget,
    ) -> Result<Self, ConfigError> {
        let mut table: Table = toml::from_str(text).map_err(|e| ConfigError::Syntax {
            origin: origin.to_string(),
            message: e.to_string(),
        })?;
        // Type-check the text itself, so that errors point at its lines.
        toml::from_str::<Document>(text).map_err(|e| ConfigError::Type {
            origin: format!("in {origin}"),
            message: e.to_string(),
        })?;
        if let Some(dir) = base_dir.as_deref() {
            resolve_record_path(&mut table, dir);
        }
        Self::read_table(table, None, budget)
    }

    /// Reads a configuration from a TOML tree (as parsed, or built from a Python dict); a
    /// record's relative path is relative to the working directory.
    pub fn from_table(table: Table) -> Result<Self, ConfigError> {
        Self::from_table_in(table, None)
    }

    /// [`from_table`](Self::from_table) with the base motion built within `budget` (see
    /// [`from_path_within`](Self::from_path_within)); the configurations derived from this one
    /// keep the budget.
    pub fn from_table_within(table: Table, budget: &WorkBudget) -> Result<Self, ConfigError> {
        Self::read_table(table, None, budget)
    }

    /// [`from_table`](Self::from_table) with relative record paths relative to `base_dir`.
    /// The path is stored resolved (absolute) in the configuration's tree, so that the tree
    /// alone (`to_toml`, a pickled Python `Config` sent to another process) reads the same
    /// record wherever it is read again.
    pub fn from_table_in(mut table: Table, base_dir: Option<PathBuf>) -> Result<Self, ConfigError> {
        if let Some(dir) = base_dir.as_deref() {
            resolve_record_path(&mut table, dir);
        }
        Self::read_table(table, None, &WorkBudget::default())
    }

    /// The tree `table` read into the document's types and resolved; what `previous` (a
    /// configuration this one is derived from) already read or built is reused where its
    /// inputs are the same (a record's samples, a base motion's spline).
    fn read_table(table: Table, previous: Option<&Config>, budget: &WorkBudget) -> Result<Self, ConfigError> {
        let doc: Document = serde_path_to_error::deserialize(Value::Table(table.clone())).map_err(|e| {
            // A key the schema lacks is named as one (the deserialiser calls it a field).
            if let Some(key) = keys::unknown_key_in(&table) {
                return keys::unknown(&key);
            }
            let path = e.path().to_string();
            ConfigError::Type {
                origin: if path == "." {
                    "invalid configuration".into()
                } else {
                    format!("invalid `{path}`")
                },
                message: e.into_inner().message().trim().to_string(),
            }
        })?;
        Self::resolve(table, doc, previous, budget)
    }

    /// The configuration of the document `doc` read from `table`: the chain, the initial
    /// state and the base motion derived, everything validated (see
    /// [`read_table`](Self::read_table) for `previous`); the base motion is built within
    /// `budget`.
    pub(super) fn resolve(
        table: Table,
        doc: Document,
        previous: Option<&Config>,
        budget: &WorkBudget,
    ) -> Result<Self, ConfigError> {
        let chain = chain_of(&doc).map_err(|e| e.renamed(keys::chain_key))?;
        let mut harvester = doc.harvester.clone().unwrap_or_default();
        let mode_given = table.get("harvester").and_then(|h| h.get("mode")).is_some();
        if chain.len() == 2 && !mode_given {
            harvester.mode = TransducerMode::ContactSeparation;
        }
        doc.run.validate().map_err(|e| e.within("run"))?;
        let initial = doc
            .run
            .initial_state(&chain)
            .map_err(|e| e.renamed(keys::state_key))?;
        doc.options.validate().map_err(|e| e.within("options"))?;
        // A single mass (against a stop) has no gap between masses to harvest from: its runs
        // are mechanics-only and its harvester is not checked.
        if chain.len() > 1 {
            harvester
                .validate_for_gaps(chain.len() - 1)
                .map_err(|e| e.within("harvester"))?;
        }
        doc.electrical.validate().map_err(|e| e.within("electrical"))?;
        // The same record file: its samples as read before.
        let same_record = previous.filter(|p| p.doc.excitation.file == doc.excitation.file);
        let excitation = super::excitation::excitation_of(&doc, &chain, same_record.map(|p| &p.excitation))?;
        let base = match (excitation.kind(), previous) {
            (ExcitationKind::Harmonic, _) => None,
            (_, Some(p)) if p.excitation == excitation && p.base.is_some() => p.base.clone(),
            (kind, _) => Some(Arc::new(
                excitation
                    .build_within(chain_harmonic(&chain), budget)
                    .map_err(|e| super::excitation::named(kind, e))?,
            )),
        };
        let initial = if doc.run.start_relative_to_base {
            // The base's displacement and velocity at t = 0 (the sine A sin ωt: 0 and Aω).
            let [y0, v0, _] = match &base {
                Some(b) => b.evaluate(0.0),
                None => [0.0, chain.excitation.amplitude * chain.omega(), 0.0],
            };
            let positions: Vec<f64> = initial.positions.iter().map(|x| x + y0).collect();
            let velocities: Vec<f64> = initial.velocities.iter().map(|v| v + v0).collect();
            crate::dynamics::initial_state(&chain, Some(&positions), Some(&velocities)).map_err(|e| {
                ConfigError::Param(crate::error::ParamError::Conflict {
                    name: "run.start_relative_to_base".into(),
                    message: format!(
                        "true shifts the initial state (run.initial_positions, run.initial_velocities) by the \
                         base's y(0) = {y0:e} m, y'(0) = {v0:e} m/s: {}",
                        e.renamed(keys::state_key)
                    ),
                })
            })?
        } else {
            initial
        };
        Ok(Config {
            table,
            chain,
            run: doc.run.clone(),
            initial,
            options: doc.options.clone(),
            harvester,
            electrical: doc.electrical.clone(),
            excitation,
            base,
            doc,
            budget: budget.clone(),
        })
    }

    /// A copy with `key` set to `value` (see [`set`](Self::set)).
    pub fn with(&self, key: &str, value: Value) -> Result<Self, ConfigError> {
        let mut c = self.clone();
        c.set(key, value)?;
        Ok(c)
    }

    /// Sets `key` to `value` and reads the configuration again: a key of the file
    /// (`excitation.omega_ratio`, `harvester.load`), one element of an array key
    /// (`oscillator.gaps[1]`), or a derived key (`mass_ratio`, see
    /// [`DERIVED_KEYS`](super::DERIVED_KEYS)). An unknown key or a bad value is an error that
    /// names the key; the configuration is then unchanged.
    pub fn set(&mut self, key: &str, value: Value) -> Result<(), ConfigError> {
        self.set_all([(key, value)])
    }

    /// Sets several keys (see [`set`](Self::set)) in order and reads the configuration once
    /// they are all set, so that a combination that is only valid as a whole can be given
    /// (`run.periods = 20` with `run.transient_periods = 10`). On error the configuration is
    /// unchanged.
    pub fn set_all<'k>(
        &mut self,
        keys: impl IntoIterator<Item = (&'k str, Value)>,
    ) -> Result<(), ConfigError> {
        let mut table = self.table.clone();
        let mut set = Vec::new();
        for (key, value) in keys {
            let shown = format!("{key} = {value}");
            keys::set_key(&mut table, key, value).map_err(|e| tell(&[(shown.clone(), key)], e))?;
            set.push((shown, key));
        }
        *self = Self::read_table(table, Some(self), &self.budget).map_err(|e| tell(&set, e))?;
        Ok(())
    }

    /// A copy with each parameter of `values` set to its value, in order, validated once
    /// they are all set (see [`set_all`](Self::set_all)): a sweep's or a map's point. The
    /// parameters of the document's types are set there directly, without writing and
    /// reading TOML again; a record file is not read again.
    pub fn with_values(&self, values: &[(&Param, f64)]) -> Result<Self, ConfigError> {
        if values.iter().any(|(p, _)| !p.is_typed()) {
            return self.with_values_in_tree(values);
        }
        let (mut doc, mut table) = (self.doc.clone(), self.table.clone());
        let mut set = Vec::new();
        for &(param, value) in values {
            let shown = format!("{} = {}", param.key(), Value::Float(value));
            param
                .set(&mut doc, &mut table, value)
                .map_err(|e| tell(&[(shown.clone(), param.key())], e))?;
            set.push((shown, param.key()));
        }
        Self::resolve(table, doc, Some(self), &self.budget).map_err(|e| tell(&set, e))
    }

    /// [`with_values`](Self::with_values) through the TOML tree ([`set_all`](Self::set_all)):
    /// each value as a float, or, if that is refused, a whole value as an integer (for the
    /// integer keys, such as `excitation.seed`).
    fn with_values_in_tree(&self, values: &[(&Param, f64)]) -> Result<Self, ConfigError> {
        let mut config = self.clone();
        let floats = values.iter().map(|&(p, v)| (p.key(), Value::Float(v)));
        let Err(error) = config.set_all(floats) else {
            return Ok(config);
        };
        let whole = |v: f64| v.is_finite() && v.fract() == 0.0 && v.abs() <= 2f64.powi(53);
        if !values.iter().any(|&(_, v)| whole(v)) {
            return Err(error);
        }
        let mixed = values.iter().map(|&(p, v)| {
            let value = if whole(v) && !p.is_typed() {
                Value::Integer(v as i64)
            } else {
                Value::Float(v)
            };
            (p.key(), value)
        });
        let mut config = self.clone();
        match config.set_all(mixed) {
            Ok(()) => Ok(config),
            Err(_) => Err(error),
        }
    }

    /// The effective settings: every key of the schema with its value (the defaults filled
    /// in where the file and the overrides leave it out: the chain, the harmonic amplitude,
    /// the reference frequency as `omega_ratio`, the transient, the initial state, the
    /// harvester), shaped like the file, as JSON (`null` for an optional key left absent).
    pub fn effective(&self) -> serde_json::Value {
        let mut doc = self.doc.clone();
        let c = &self.chain;
        let o = &mut doc.oscillator;
        o.masses.get_or_insert_with(|| c.masses.clone());
        o.stiffness
            .get_or_insert_with(|| PerMass::Many(c.stiffness.clone()));
        o.damping.get_or_insert_with(|| PerMass::Many(c.damping.clone()));
        o.gaps.get_or_insert_with(|| PerMass::Many(c.gaps.clone()));
        o.restitution.get_or_insert(c.restitution);
        let e = &mut doc.excitation;
        if matches!(e.kind, None | Some(ExcitationKind::Harmonic)) {
            e.amplitude.get_or_insert(c.excitation.amplitude);
        }
        if e.omega_ratio.is_none() && e.frequency_hz.is_none() {
            e.omega_ratio = Some(c.omega_ratio());
        }
        let r = &mut doc.run;
        r.transient_periods.get_or_insert(self.run.transient());
        if !r.start_relative_to_base {
            r.initial_positions
                .get_or_insert_with(|| self.initial.positions.clone());
            r.initial_velocities
                .get_or_insert_with(|| self.initial.velocities.clone());
        }
        doc.harvester.get_or_insert_with(|| self.harvester.clone());
        serde_json::to_value(&doc).unwrap_or(serde_json::Value::Null)
    }

    /// The TOML tree: the file with the overrides applied (what a run records as its
    /// settings).
    pub fn table(&self) -> &Table {
        &self.table
    }

    /// The chain (`[oscillator]` and `[excitation]`).
    pub fn chain(&self) -> &ChainParams {
        &self.chain
    }

    /// The `[run]` table.
    pub fn run(&self) -> &RunSettings {
        &self.run
    }

    /// The initial state (`run.initial_positions`, `run.initial_velocities`).
    pub fn initial_state(&self) -> &ChainState {
        &self.initial
    }

    /// The simulator's settings (`[options]`).
    pub fn sim_options(&self) -> &SimOptions {
        &self.options
    }

    /// The harvester (`[harvester]`, or the paper's; on a two-mass chain the default
    /// transducer is the contact-separation mode).
    pub fn harvester(&self) -> &HarvesterParams {
        &self.harvester
    }

    /// The base motion `[excitation]` describes (kind and signal parameters, a record's
    /// samples read).
    pub fn excitation(&self) -> &ExcitationSpec {
        &self.excitation
    }

    /// `excitation.spline_tolerance`: the bound on a spline base motion's displacement error,
    /// relative to the signal's size (dimensionless; default
    /// [`DEFAULT_SPLINE_TOLERANCE`](super::DEFAULT_SPLINE_TOLERANCE)).
    pub fn spline_tolerance(&self) -> f64 {
        self.doc
            .excitation
            .spline_tolerance
            .unwrap_or(super::DEFAULT_SPLINE_TOLERANCE)
    }

    /// The base motion built ([`ExcitationSpec::build`]; chirps, random signals and records
    /// are sampled into splines when the configuration is read).
    pub fn base_motion(&self) -> Result<BaseMotion, ConfigError> {
        match &self.base {
            Some(b) => Ok((**b).clone()),
            None => self
                .excitation
                .build(chain_harmonic(&self.chain))
                .map_err(|e| super::excitation::named(self.excitation.kind(), e)),
        }
    }

    /// Whether the base motion is periodic with the reference period T: the harmonic kind,
    /// or a multisine of one harmonic that is exactly it.
    pub fn is_periodic(&self) -> bool {
        match (self.excitation.kind(), self.base.as_deref()) {
            (ExcitationKind::Harmonic, _) => true,
            (_, Some(BaseMotion::Harmonics(h))) => {
                crate::dynamics::as_chain_harmonic(h, &self.chain).is_some()
            }
            _ => false,
        }
    }

    /// An error if `tool` (a command that follows the mechanics on its own: periodic orbits,
    /// continuation, Lyapunov exponents, basins, attractors) would ignore
    /// `harvester.coupling = "two_way"`.
    pub fn check_uncoupled(&self, tool: &str) -> Result<(), ConfigError> {
        if self.harvester().coupling == crate::coupling::Coupling::TwoWay {
            return Err(ConfigError::Unsupported(format!(
                "{tool} follows the uncoupled mechanics: harvester.coupling = \"two_way\" is not \
                 supported by it yet (simulate, sweep, map and load-sweep take it)"
            )));
        }
        Ok(())
    }

    /// Whether the engine can run this configuration: an error naming the reason if its
    /// base motion cannot drive its chain (rigid stops with `frame = "base"` follow the
    /// harmonic A sin ωt only) or ends before `run.periods` × T. The command line and the
    /// Python package call it on every configuration they run.
    pub fn check_runnable(&self) -> Result<(), ConfigError> {
        let Some(base) = &self.base else {
            return Ok(());
        };
        let kind = self.excitation.kind().as_str();
        crate::dynamics::check_base_motion(&self.chain, base)
            .map_err(|m| ConfigError::Unsupported(format!("excitation kind {kind}: {m}")))?;
        if let Some(end) = base.end() {
            let run_end = self.run.periods as f64 * self.chain.period();
            if run_end > end * (1.0 + 1e-12) {
                return Err(ConfigError::Unsupported(format!(
                    "excitation kind {kind}: the base motion ends at t = {end} s, before the run's end at {run_end} s \
                     (run.periods = {} of T = {} s): shorten the run or lengthen the signal",
                    self.run.periods,
                    self.chain.period()
                )));
            }
        }
        Ok(())
    }

    /// Whether `tool` (a stroboscopic or periodic-orbit tool: periodic orbits, continuation,
    /// Floquet multipliers, Lyapunov exponents, basins, attractors) can run: it needs a base
    /// motion periodic with the reference period T; an error naming the tool and the reason
    /// otherwise.
    pub fn check_periodic(&self, tool: &str) -> Result<(), ConfigError> {
        if self.is_periodic() {
            return Ok(());
        }
        Err(ConfigError::Unsupported(format!(
            "{tool} needs a base motion periodic with the reference period T (a stroboscopic map); \
             excitation kind {} is not periodic (use kind = \"harmonic\")",
            self.excitation.kind().as_str()
        )))
    }

    /// The charge solver's settings (`[electrical]`).
    pub fn charge_options(&self) -> &ChargeOptions {
        &self.electrical
    }

    /// The run this configuration describes: the chain from its initial state over
    /// `run.periods`, with the harvester unless `mechanics_only`, nothing sampled.
    pub fn run_spec(&self, mechanics_only: bool) -> RunSpec {
        RunSpec {
            chain: self.chain.clone(),
            initial: self.initial.clone(),
            options: self.options.clone(),
            harvester: (!mechanics_only && self.chain.len() > 1)
                .then(|| Harvester::new(self.harvester.clone(), self.electrical.clone())),
            periods: self.run.periods,
            transient_periods: self.run.transient(),
            sampling: None,
            breakdown_check: false,
            base_motion: self.base.clone(),
        }
    }

    /// [`run_spec`](Self::run_spec) sampled `run.samples_per_period` times per period.
    pub fn sampled_run_spec(&self, mechanics_only: bool) -> RunSpec {
        RunSpec {
            sampling: Some(Sampling::PerPeriod(self.run.samples_per_period)),
            ..self.run_spec(mechanics_only)
        }
    }
}

/// Replaces a relative `excitation.file` of `table` by its path under `dir`, made absolute
/// (against the working directory when `dir` is relative).
fn resolve_record_path(table: &mut Table, dir: &Path) {
    let Some(Value::Table(excitation)) = table.get_mut("excitation") else {
        return;
    };
    let Some(Value::String(file)) = excitation.get_mut("file") else {
        return;
    };
    if Path::new(file.as_str()).is_relative() {
        let joined = dir.join(file.as_str());
        let resolved = std::path::absolute(&joined).unwrap_or(joined);
        *file = resolved.display().to_string();
    }
}

/// The chain's own harmonic `A sin ωt` (phase 0).
fn chain_harmonic(chain: &ChainParams) -> Harmonic {
    Harmonic {
        amplitude: chain.excitation.amplitude,
        omega: chain.omega(),
        phase: 0.0,
    }
}

/// `e`, with what was set (`key = value` and the key) if it names none of the keys set.
fn tell(set: &[(String, &str)], e: ConfigError) -> ConfigError {
    let message = e.to_string();
    let named = set
        .iter()
        .any(|(_, key)| message.contains(key.split('[').next().unwrap_or(key)));
    if named || set.is_empty() {
        e
    } else {
        let shown: Vec<&str> = set.iter().map(|(s, _)| s.as_str()).collect();
        ConfigError::Setting {
            key: shown.join(", "),
            error: Box::new(e),
        }
    }
}

/// The chain of a document, defaults applied, validated (names in the library's terms).
fn chain_of(doc: &Document) -> Result<ChainParams, crate::error::ParamError> {
    let params = lenient_chain(doc)?;
    params.validate()?;
    Ok(params)
}

/// The chain of a document with defaults applied, not validated.
pub(super) fn lenient_chain(doc: &Document) -> Result<ChainParams, crate::error::ParamError> {
    let o = &doc.oscillator;
    let masses = o.masses.clone().unwrap_or_else(|| ChainParams::default().masses);
    let n = masses.len();
    let default = keys::default_chain(n);
    let e = &doc.excitation;
    let frequency = match (e.omega_ratio, e.frequency_hz) {
        (Some(_), Some(_)) => {
            return Err(crate::error::ParamError::Conflict {
                name: "excitation.frequency_hz".into(),
                message: "give either excitation.omega_ratio or excitation.frequency_hz, not both".into(),
            });
        }
        (Some(w), None) => Frequency::OmegaRatio(w),
        (None, Some(f)) => Frequency::Hertz(f),
        (None, None) => default.excitation.frequency,
    };
    let params = ChainParams {
        stiffness: o.stiffness.as_ref().map_or(default.stiffness, |s| s.expand(n)),
        damping: o.damping.as_ref().map_or(default.damping, |s| s.expand(n)),
        gaps: o
            .gaps
            .as_ref()
            .map_or(default.gaps, |s| s.expand(n.saturating_sub(1))),
        restitution: o.restitution.unwrap_or(default.restitution),
        excitation: Excitation {
            amplitude: e.amplitude.unwrap_or(default.excitation.amplitude),
            frequency,
        },
        stops: o.stops,
        forces: o.forces.as_ref().map_or(Vec::new(), |s| s.expand(n)),
        masses,
    };
    Ok(params)
}
