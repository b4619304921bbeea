//! Configuration files (TOML), `--set key=value` overrides and derived parameter keys.
//!
//! A configuration is parsed into a raw TOML table first, overrides are applied to that
//! table, and only then is it deserialized into typed sections that reject unknown keys.
//! The same key names address parameters everywhere: in files, in `--set`, and in sweeps.

use std::path::Path;

use anyhow::{Context, Result, anyhow, bail};
use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize};
use toml::{Table, Value};
use vibrotribo::electrical::{ChargeOptions, HarvesterParams};
use vibrotribo::{ChainParams, ChainState, Excitation, Frequency, SimOptions};

/// A number or an array of numbers (`stiffness = 120.0` means 120 N/m for every mass).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum OneOrMany {
    /// One value for every entry.
    One(f64),
    /// One value per entry.
    Many(Vec<f64>),
}

impl<'de> Deserialize<'de> for OneOrMany {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = OneOrMany;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or an array of numbers")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> std::result::Result<OneOrMany, E> {
                Ok(OneOrMany::One(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> std::result::Result<OneOrMany, E> {
                Ok(OneOrMany::One(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> std::result::Result<OneOrMany, E> {
                Ok(OneOrMany::One(v as f64))
            }
            fn visit_seq<A: de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> std::result::Result<OneOrMany, A::Error> {
                let mut out = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    out.push(x);
                }
                Ok(OneOrMany::Many(out))
            }
        }
        d.deserialize_any(V)
    }
}

impl OneOrMany {
    fn expand(&self, n: usize) -> Vec<f64> {
        match self {
            OneOrMany::One(x) => vec![*x; n],
            OneOrMany::Many(v) => v.clone(),
        }
    }
}

/// `[oscillator]`: the mechanical chain.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OscillatorSection {
    /// Masses, kg, top (m1) to bottom. Default `[0.048, 0.12, 0.048]`.
    pub masses: Option<Vec<f64>>,
    /// Spring stiffnesses, N/m. Default 120 for each mass.
    pub stiffness: Option<OneOrMany>,
    /// Damping coefficients, N·s/m. Default 0.02 for each mass.
    pub damping: Option<OneOrMany>,
    /// Gaps, m (N − 1 entries). Default 0.020 each.
    pub gaps: Option<OneOrMany>,
    /// Coefficient of restitution. Default 0.6.
    pub restitution: Option<f64>,
}

/// `[excitation]`: the base motion.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExcitationSection {
    /// Base amplitude A, m. Default 0.08.
    pub amplitude: Option<f64>,
    /// Ω = ω/√(k1/m1). Default 0.70 (exclusive with `frequency_hz`).
    pub omega_ratio: Option<f64>,
    /// Excitation frequency, Hz (exclusive with `omega_ratio`).
    pub frequency_hz: Option<f64>,
}

/// `[run]`: what to simulate and record.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunSection {
    /// Excitation periods simulated in all, transient included. Default 100.
    pub periods: Option<u64>,
    /// Leading periods excluded from statistics and averages. Default 50.
    pub transient_periods: Option<u64>,
    /// Trajectory samples per excitation period. Default 200.
    pub samples_per_period: Option<u64>,
    /// Initial positions, m. Default all 0.
    pub initial_positions: Option<Vec<f64>>,
    /// Initial velocities, m/s. Default all 0.
    pub initial_velocities: Option<Vec<f64>>,
}

/// `[options]`: numerical settings of the simulator.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OptionsSection {
    /// Maximum events per excitation period before a run is declared pathological.
    pub max_events_per_period: Option<usize>,
    /// Accuracy of chatter accumulation jumps, fraction of a period.
    pub chatter_tolerance: Option<f64>,
}

/// A whole configuration file.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// `[oscillator]`.
    #[serde(default)]
    pub oscillator: OscillatorSection,
    /// `[excitation]`.
    #[serde(default)]
    pub excitation: ExcitationSection,
    /// `[run]`.
    #[serde(default)]
    pub run: RunSection,
    /// `[options]`.
    #[serde(default)]
    pub options: OptionsSection,
    /// `[harvester]`: transducer and load (absent: the paper's harvester).
    #[serde(default)]
    pub harvester: Option<HarvesterParams>,
    /// `[electrical]`: charge solver settings.
    #[serde(default)]
    pub electrical: Option<ChargeOptions>,
}

/// What a run records, with defaults applied.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunSpec {
    /// Periods in all.
    pub periods: u64,
    /// Transient periods.
    pub transient_periods: u64,
    /// Samples per period.
    pub samples_per_period: u64,
    /// Initial state.
    pub initial: ChainState,
}

/// The configuration of a command: a TOML file and `--set` overrides.
#[derive(Debug, clap::Args)]
pub struct ConfigArgs {
    /// Configuration file (TOML); the paper's default case if omitted.
    pub config: Option<std::path::PathBuf>,
    /// Override a parameter, e.g. `--set excitation.omega_ratio=0.75`,
    /// `--set oscillator.masses=[0.05,0.15,0.05]`, `--set mass_ratio=3` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

impl ConfigArgs {
    /// Reads the file and applies the overrides.
    pub fn load(&self) -> Result<Loaded> {
        Loaded::load(self.config.as_deref(), &self.set)
    }
}

/// The raw configuration tree with overrides applied, and its typed reading.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The tree (after `--set`), e.g. for recording the settings used.
    pub table: Table,
    /// Typed reading of `table`.
    pub config: Config,
}

/// Keys accepted in configuration files and `--set`, besides the derived ones.
pub const CONFIG_KEYS: &[&str] = &[
    "oscillator.masses",
    "oscillator.stiffness",
    "oscillator.damping",
    "oscillator.gaps",
    "oscillator.restitution",
    "excitation.amplitude",
    "excitation.omega_ratio",
    "excitation.frequency_hz",
    "run.periods",
    "run.transient_periods",
    "run.samples_per_period",
    "run.initial_positions",
    "run.initial_velocities",
    "options.max_events_per_period",
    "options.chatter_tolerance",
];

/// Derived scalar keys usable in `--set` and sweeps, with what they change.
pub const DERIVED_KEYS: &[(&str, &str)] = &[
    (
        "mass_ratio",
        "R_m = m2/m1 with m1 (and m3) fixed: m2 = R_m·m1 (the paper's Figs. 14-21)",
    ),
    (
        "mass_ratio_m2_fixed",
        "R_m = m2/m1 with m2 fixed: every other mass = m2/R_m (the paper's Figs. 6, 13)",
    ),
    (
        "gap_ratio",
        "R_δ = δ2/δ1 with δ1 fixed: δ2 = R_δ·δ1 (the paper's Figs. 7-11)",
    ),
    (
        "gap",
        "every gap δ_k set to the value, m (symmetric spacing, Fig. 12)",
    ),
    ("omega_ratio", "same as excitation.omega_ratio"),
    ("frequency_hz", "same as excitation.frequency_hz"),
    ("amplitude", "same as excitation.amplitude"),
    ("restitution", "same as oscillator.restitution"),
];

impl Loaded {
    /// Reads `path` (or the paper's default case if `None`) and applies `sets`
    /// (`key=value` strings).
    pub fn load(path: Option<&Path>, sets: &[String]) -> Result<Self> {
        let mut table = match path {
            Some(p) => {
                let text = std::fs::read_to_string(p)
                    .with_context(|| format!("cannot read configuration {}", p.display()))?;
                let table: Table =
                    toml::from_str(&text).with_context(|| format!("{} is not valid TOML", p.display()))?;
                // Type-check the file alone first, so its errors point at lines in it.
                let _: Config = toml::from_str(&text).with_context(|| format!("in {}", p.display()))?;
                table
            }
            None => Table::new(),
        };
        for s in sets {
            let (key, value) = s.split_once('=').ok_or_else(|| {
                anyhow!("--set {s:?}: expected key=value, e.g. --set excitation.omega_ratio=0.75")
            })?;
            let value = parse_value(value.trim());
            set_key(&mut table, key.trim(), value).with_context(|| format!("--set {s}"))?;
        }
        Self::from_table(table)
    }

    /// Reads an already-built tree.
    pub fn from_table(table: Table) -> Result<Self> {
        let config: Config = Value::Table(table.clone())
            .try_into()
            .map_err(|e| anyhow!("invalid configuration: {e}"))?;
        Ok(Loaded { table, config })
    }

    /// A copy with `key` set to a number (used by sweeps).
    pub fn with(&self, key: &str, value: f64) -> Result<Self> {
        let mut table = self.table.clone();
        set_key(&mut table, key, Value::Float(value))?;
        Self::from_table(table)
    }
}

/// Parses the right-hand side of `--set`: any TOML value (`0.7`, `[1, 2]`, `"exact"`), or a
/// bare word as a string (`--set harvester.load=rectifier`).
pub fn parse_value(text: &str) -> Value {
    let doc = format!("v = {text}");
    match toml::from_str::<Table>(&doc) {
        Ok(mut t) => t.remove("v").unwrap_or(Value::String(text.to_string())),
        Err(_) => Value::String(text.to_string()),
    }
}

/// Splits `a.b[2]` into (["a", "b"], Some(2)).
fn split_key(key: &str) -> Result<(Vec<&str>, Option<usize>)> {
    let (path, index) = match key.find('[') {
        Some(open) => {
            let close = key
                .strip_suffix(']')
                .ok_or_else(|| anyhow!("key `{key}`: missing closing `]`"))?;
            let idx: usize = close[open + 1..]
                .parse()
                .map_err(|_| anyhow!("key `{key}`: the index must be a non-negative integer"))?;
            (&key[..open], Some(idx))
        }
        None => (key, None),
    };
    Ok((path.split('.').collect(), index))
}

fn known_keys_hint() -> String {
    let mut keys: Vec<&str> = CONFIG_KEYS.to_vec();
    keys.extend(DERIVED_KEYS.iter().map(|(k, _)| *k));
    keys.extend(crate::harvester::HARVESTER_KEYS);
    keys.join(", ")
}

/// Number of masses described by a tree (default 3).
fn chain_len(table: &Table) -> usize {
    table
        .get("oscillator")
        .and_then(|o| o.get("masses"))
        .and_then(Value::as_array)
        .map_or(3, Vec::len)
}

/// The paper's chain ([`ChainParams::default`]) with its stiffness and damping repeated for
/// `n` masses and its spacing for the `n − 1` gaps; masses (the paper's three), restitution
/// and excitation as they are: the defaults of the `[oscillator]` and `[excitation]` keys.
fn default_chain(n: usize) -> ChainParams {
    let paper = ChainParams::default();
    ChainParams {
        stiffness: vec![paper.stiffness[0]; n],
        damping: vec![paper.damping[0]; n],
        gaps: vec![paper.gaps[0]; n.saturating_sub(1)],
        ..paper
    }
}

/// The current value of an array key, with the default filled in if absent and a scalar
/// broadcast (so that one element of it can be set).
fn materialize_array(table: &Table, section: &str, name: &str) -> Result<Vec<f64>> {
    let n = chain_len(table);
    let current = table.get(section).and_then(|s| s.get(name));
    let chain = default_chain(n);
    let defaults: Vec<f64> = match (section, name) {
        ("oscillator", "masses") => chain.masses,
        ("oscillator", "stiffness") => chain.stiffness,
        ("oscillator", "damping") => chain.damping,
        ("oscillator", "gaps") => chain.gaps,
        ("run", "initial_positions") | ("run", "initial_velocities") => vec![0.0; n],
        _ => bail!("`{section}.{name}` is not an array parameter"),
    };
    match current {
        None => Ok(defaults),
        Some(v) => {
            let parsed = OneOrMany::deserialize(v.clone()).map_err(|e| anyhow!("`{section}.{name}`: {e}"))?;
            let len = if name == "gaps" { n - 1 } else { n };
            Ok(parsed.expand(len))
        }
    }
}

fn section_mut<'a>(table: &'a mut Table, section: &str) -> Result<&'a mut Table> {
    table
        .entry(section.to_string())
        .or_insert_with(|| Value::Table(Table::new()))
        .as_table_mut()
        .ok_or_else(|| anyhow!("`{section}` must be a table"))
}

fn number(value: &Value, key: &str) -> Result<f64> {
    match value {
        Value::Float(x) => Ok(*x),
        Value::Integer(i) => Ok(*i as f64),
        other => bail!("`{key}` needs a number, got {other}"),
    }
}

/// Sets `key` (a configuration key, possibly with an `[index]`, or a derived key) in the
/// tree. Unknown keys are an error that names the key.
pub fn set_key(table: &mut Table, key: &str, value: Value) -> Result<()> {
    match key {
        "mass_ratio" => {
            let r = number(&value, key)?;
            let mut m = materialize_array(table, "oscillator", "masses")?;
            if m.len() < 2 {
                bail!("mass_ratio needs at least 2 masses");
            }
            m[1] = r * m[0];
            set_array(table, "oscillator", "masses", m)
        }
        "mass_ratio_m2_fixed" => {
            let r = number(&value, key)?;
            let mut m = materialize_array(table, "oscillator", "masses")?;
            if m.len() < 2 {
                bail!("mass_ratio_m2_fixed needs at least 2 masses");
            }
            let m2 = m[1];
            for (i, mi) in m.iter_mut().enumerate() {
                if i != 1 {
                    *mi = m2 / r;
                }
            }
            set_array(table, "oscillator", "masses", m)
        }
        "gap_ratio" => {
            let r = number(&value, key)?;
            let mut g = materialize_array(table, "oscillator", "gaps")?;
            if g.len() < 2 {
                bail!("gap_ratio needs at least 2 gaps (3 masses)");
            }
            g[1] = r * g[0];
            set_array(table, "oscillator", "gaps", g)
        }
        "gap" => {
            let d = number(&value, key)?;
            let n = chain_len(table);
            set_array(table, "oscillator", "gaps", vec![d; n - 1])
        }
        "omega_ratio" => set_key(table, "excitation.omega_ratio", value),
        "frequency_hz" => set_key(table, "excitation.frequency_hz", value),
        "amplitude" => set_key(table, "excitation.amplitude", value),
        "restitution" => set_key(table, "oscillator.restitution", value),
        _ => set_path(table, key, value),
    }
}

fn set_array(table: &mut Table, section: &str, name: &str, values: Vec<f64>) -> Result<()> {
    section_mut(table, section)?.insert(
        name.to_string(),
        Value::Array(values.into_iter().map(Value::Float).collect()),
    );
    Ok(())
}

fn set_path(table: &mut Table, key: &str, value: Value) -> Result<()> {
    let (path, index) = split_key(key)?;
    let plain = path.join(".");
    let known =
        CONFIG_KEYS.contains(&plain.as_str()) || crate::harvester::HARVESTER_KEYS.contains(&plain.as_str());
    if !known || path.len() != 2 {
        bail!("unknown parameter `{key}`; known keys: {}", known_keys_hint());
    }
    let (section, name) = (path[0], path[1]);
    match index {
        None => {
            let sec = section_mut(table, section)?;
            sec.insert(name.to_string(), value);
            // omega_ratio and frequency_hz exclude each other: the later one wins.
            if section == "excitation" {
                match name {
                    "omega_ratio" => sec.remove("frequency_hz"),
                    "frequency_hz" => sec.remove("omega_ratio"),
                    _ => None,
                };
            }
            Ok(())
        }
        Some(i) => {
            let mut values = if section == "harvester" {
                crate::harvester::materialize_array(table, name)?
            } else {
                materialize_array(table, section, name)?
            };
            let len = values.len();
            let slot = values
                .get_mut(i)
                .ok_or_else(|| anyhow!("`{key}`: index {i} out of range ({plain} has {len} entries)"))?;
            *slot = number(&value, key)?;
            set_array(table, section, name, values)
        }
    }
}

impl Config {
    /// The chain's parameters with defaults applied, validated.
    pub fn chain_params(&self) -> Result<ChainParams> {
        let o = &self.oscillator;
        let masses = o.masses.clone().unwrap_or_else(|| ChainParams::default().masses);
        let n = masses.len();
        let default = default_chain(n);
        let e = &self.excitation;
        let frequency = match (e.omega_ratio, e.frequency_hz) {
            (Some(_), Some(_)) => {
                bail!("give either excitation.omega_ratio or excitation.frequency_hz, not both")
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
            masses,
        };
        params.validate()?;
        Ok(params)
    }

    /// The run settings with defaults applied, validated against `params`.
    pub fn run_spec(&self, params: &ChainParams) -> Result<RunSpec> {
        let r = &self.run;
        let periods = r.periods.unwrap_or(100);
        let transient_periods = r.transient_periods.unwrap_or(50.min(periods.saturating_sub(1)));
        let samples_per_period = r.samples_per_period.unwrap_or(200);
        if periods == 0 {
            bail!("run.periods must be at least 1");
        }
        if transient_periods >= periods {
            bail!("run.transient_periods ({transient_periods}) must be less than run.periods ({periods})");
        }
        if samples_per_period == 0 {
            bail!("run.samples_per_period must be at least 1");
        }
        let initial = vibrotribo::dynamics::initial_state(
            params,
            r.initial_positions.as_deref(),
            r.initial_velocities.as_deref(),
        )?;
        Ok(RunSpec {
            periods,
            transient_periods,
            samples_per_period,
            initial,
        })
    }

    /// The simulator options with defaults applied.
    pub fn sim_options(&self) -> Result<SimOptions> {
        let d = SimOptions::default();
        let options = SimOptions {
            max_events_per_period: self
                .options
                .max_events_per_period
                .unwrap_or(d.max_events_per_period),
            chatter_tolerance: self.options.chatter_tolerance.unwrap_or(d.chatter_tolerance),
            ..d
        };
        options.validate()?;
        Ok(options)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(text: &str, sets: &[&str]) -> Result<Loaded> {
        let dir = std::env::temp_dir().join(format!("vt-config-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(format!("c{}.toml", text.len()));
        std::fs::write(&path, text).unwrap();
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        Loaded::load(Some(&path), &sets)
    }

    #[test]
    fn defaults_are_the_paper_case() {
        let l = Loaded::load(None, &[]).unwrap();
        assert_eq!(l.config.chain_params().unwrap(), ChainParams::default());
        let spec = l.config.run_spec(&ChainParams::default()).unwrap();
        assert_eq!(
            (spec.periods, spec.transient_periods, spec.samples_per_period),
            (100, 50, 200)
        );
    }

    #[test]
    fn scalars_broadcast_and_sets_apply() {
        let l = load(
            "[oscillator]\nmasses = [0.05, 0.15]\nstiffness = 100\ngaps = 0.01\n",
            &["oscillator.damping=[0.1, 0.2]", "excitation.frequency_hz=5"],
        )
        .unwrap();
        let p = l.config.chain_params().unwrap();
        assert_eq!(p.stiffness, vec![100.0, 100.0]);
        assert_eq!(p.gaps, vec![0.01]);
        assert_eq!(p.damping, vec![0.1, 0.2]);
        assert_eq!(p.excitation.frequency, Frequency::Hertz(5.0));
    }

    #[test]
    fn indexed_and_derived_sets() {
        let l = Loaded::load(None, &["oscillator.gaps[1]=0.03".into(), "mass_ratio=3".into()]).unwrap();
        let p = l.config.chain_params().unwrap();
        assert_eq!(p.gaps, vec![0.02, 0.03]);
        assert!((p.masses[1] - 3.0 * 0.048).abs() < 1e-15);
        let l = Loaded::load(None, &["mass_ratio_m2_fixed=2".into(), "gap_ratio=1.5".into()]).unwrap();
        let p = l.config.chain_params().unwrap();
        assert_eq!(p.masses, vec![0.06, 0.12, 0.06]);
        assert!((p.gaps[1] - 0.03).abs() < 1e-15);
    }

    #[test]
    fn unknown_keys_are_named() {
        let e = Loaded::load(None, &["oscillator.mases=[1,2]".into()]).unwrap_err();
        assert!(
            format!("{e:#}").contains("unknown parameter `oscillator.mases`"),
            "{e:#}"
        );
        let e = load("[oscillator]\nmases = [0.1, 0.2]\n", &[]).unwrap_err();
        assert!(format!("{e:#}").contains("unknown field `mases`"), "{e:#}");
        let e = load("[oscilator]\n", &[]).unwrap_err();
        assert!(format!("{e:#}").contains("unknown field `oscilator`"), "{e:#}");
    }

    #[test]
    fn bad_values_are_named() {
        let e = load("[oscillator]\nmasses = [0.1, -0.2, 0.1]\n", &[]).unwrap();
        let err = e.config.chain_params().unwrap_err();
        assert!(err.to_string().contains("oscillator.masses[1]"), "{err}");
        let e = load("[excitation]\nomega_ratio = 0.7\nfrequency_hz = 3\n", &[]).unwrap();
        assert!(
            e.config
                .chain_params()
                .unwrap_err()
                .to_string()
                .contains("not both")
        );
        let e = load("[run]\nperiods = 10\ntransient_periods = 10\n", &[]).unwrap();
        let p = e.config.chain_params().unwrap();
        assert!(
            e.config
                .run_spec(&p)
                .unwrap_err()
                .to_string()
                .contains("transient_periods")
        );
        let e = Loaded::load(None, &["oscillator.gaps[5]=1".into()]).unwrap_err();
        assert!(format!("{e:#}").contains("index 5 out of range"), "{e:#}");
        let e = load("[oscillator]\nmasses = \"heavy\"\n", &[]).unwrap_err();
        assert!(format!("{e:#}").contains("masses"), "{e:#}");
    }
}
