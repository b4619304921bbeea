//! [`Config`]: a configuration document read into the library's types.

use std::path::Path;

use serde::{Deserialize, Serialize};
use toml::{Table, Value};

use super::error::ConfigError;
use super::keys::{self, PerMass};
use crate::electrical::{ChargeOptions, HarvesterParams, TransducerMode};
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

/// The `[excitation]` table: [`Excitation`] with its frequency as one of two keys.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub(super) struct ExcitationTable {
    pub amplitude: Option<f64>,
    pub omega_ratio: Option<f64>,
    pub frequency_hz: Option<f64>,
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
    chain: ChainParams,
    run: RunSettings,
    initial: ChainState,
    options: SimOptions,
    harvester: HarvesterParams,
    electrical: ChargeOptions,
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
        Self::parse(&text, &path.display().to_string())
    }

    /// Reads a configuration from TOML text.
    pub fn from_toml_str(text: &str) -> Result<Self, ConfigError> {
        Self::parse(text, "the configuration")
    }

    fn parse(text: &str, origin: &str) -> Result<Self, ConfigError> {
        let table: Table = toml::from_str(text).map_err(|e| ConfigError::Syntax {
            origin: origin.to_string(),
            message: e.to_string(),
        })?;
        // Type-check the text itself, so that errors point at its lines.
        toml::from_str::<Document>(text).map_err(|e| ConfigError::Type {
            origin: format!("in {origin}"),
            message: e.to_string(),
        })?;
        Self::from_table(table)
    }

    /// Reads a configuration from a TOML tree (as parsed, or built from a Python dict).
    pub fn from_table(table: Table) -> Result<Self, ConfigError> {
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
        Ok(Config {
            table,
            chain,
            run: doc.run,
            initial,
            options: doc.options,
            harvester,
            electrical: doc.electrical,
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
        *self = Self::from_table(table).map_err(|e| tell(&set, e))?;
        Ok(())
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
