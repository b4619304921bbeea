//! The `[harvester]` table (triboelectric transducer and load) and the `[electrical]` table
//! (charge solver settings) of a configuration.

use anyhow::{Result, anyhow, bail};
use toml::{Table, Value};
use vibrotribo::ChainParams;
use vibrotribo::electrical::{ChargeOptions, HarvesterParams, TransducerMode};

use crate::config::Loaded;

/// `[harvester]` and `[electrical]` keys accepted in configuration files and `--set`.
pub const HARVESTER_KEYS: &[&str] = &[
    "harvester.mode",
    "harvester.voc_model",
    "harvester.contact",
    "harvester.area",
    "harvester.charge_density",
    "harvester.dielectric_thickness",
    "harvester.relative_permittivity",
    "harvester.load",
    "harvester.load_resistance",
    "harvester.storage_capacitance",
    "harvester.storage_load_resistance",
    "harvester.storage_initial_voltage",
    "harvester.target_voltage",
    "harvester.initial_charge",
    "harvester.diode_saturation_current",
    "harvester.diode_ideality",
    "harvester.diode_series_resistance",
    "harvester.diode_thermal_voltage",
    "harvester.diode_parallel_conductance",
    "electrical.rtol",
    "electrical.atol_voltage",
    "electrical.max_steps_per_period",
];

/// The current value of an array key of `[harvester]`, defaults filled in.
pub fn materialize_array(table: &Table, name: &str) -> Result<Vec<f64>> {
    let defaults = HarvesterParams::default();
    let default = match name {
        "dielectric_thickness" => defaults.dielectric_thickness.to_vec(),
        "relative_permittivity" => defaults.relative_permittivity.to_vec(),
        _ => bail!("`harvester.{name}` is not an array parameter"),
    };
    match table.get("harvester").and_then(|h| h.get(name)) {
        None => Ok(default),
        Some(Value::Array(a)) => a
            .iter()
            .map(|v| match v {
                Value::Float(x) => Ok(*x),
                Value::Integer(i) => Ok(*i as f64),
                other => Err(anyhow!("`harvester.{name}` needs numbers, got {other}")),
            })
            .collect(),
        Some(other) => bail!("`harvester.{name}` needs an array of 2 numbers, got {other}"),
    }
}

impl Loaded {
    /// The harvester mounted on `chain`: the `[harvester]` table, or the paper's harvester.
    /// On a two-mass chain the default transducer is the contact-separation (two-plate) mode.
    pub fn harvester(&self, chain: &ChainParams) -> Result<HarvesterParams> {
        let mut h = self.config.harvester.clone().unwrap_or_default();
        let mode_given = self.table.get("harvester").and_then(|t| t.get("mode")).is_some();
        if chain.len() == 2 && !mode_given {
            h.mode = TransducerMode::ContactSeparation;
        }
        h.validate_for_gaps(chain.len() - 1)?;
        Ok(h)
    }

    /// The charge solver settings.
    pub fn charge_options(&self) -> Result<ChargeOptions> {
        let o = self.config.electrical.clone().unwrap_or_default();
        o.validate()?;
        Ok(o)
    }
}
