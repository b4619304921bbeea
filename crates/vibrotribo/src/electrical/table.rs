//! The `[harvester]` table of a configuration file: [`HarvesterParams`] written flat, with the
//! load's parameters as keys beside `load = "…"`.
//!
//! This is how [`HarvesterParams`] is serialised and deserialised (serde's `try_from`/`into`):
//! the keys are defined here once, next to the type. Keys of a load other than the one chosen
//! are accepted (a file may keep `storage_capacitance` while `load = "resistor"`) and do not
//! take part; a table written back from parameters holds the chosen load's values and the
//! defaults for the others.

use super::diode::Diode;
use super::params::{HarvesterParams, Load, LoadKind, Rectifier, TransducerMode, VocModel};
use crate::coupling::Coupling;
use crate::error::ParamError;

/// The flat `[harvester]` table (see the module docs). Every field is a key; defaults are
/// [`HarvesterParams::default`]'s.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct HarvesterTable {
    /// `"freestanding"` (default) or `"contact_separation"`.
    pub mode: TransducerMode,
    /// `"paper"` (default) or `"exact"`.
    pub voc_model: VocModel,
    /// First contact used, 0-based. Default 0.
    pub contact: usize,
    /// Electrode area S, m². Default 0.01.
    pub area: f64,
    /// Surface charge density σ, C/m². Default 15e-6.
    pub charge_density: f64,
    /// Film thicknesses d₁, d₂, m. Default [1e-4, 1e-4].
    pub dielectric_thickness: [f64; 2],
    /// Film permittivities ε_r1, ε_r2. Default [2, 2].
    pub relative_permittivity: [f64; 2],
    /// `"resistor"` (default), `"rectifier"`, `"open"` or `"short"`.
    pub load: LoadKind,
    /// Resistor load, Ω. Default 1e5.
    pub load_resistance: f64,
    /// Rectifier: storage capacitance, F. Default 1e-6.
    pub storage_capacitance: f64,
    /// Rectifier: resistor across the storage capacitor, Ω (absent: none).
    pub storage_load_resistance: Option<f64>,
    /// Rectifier: initial storage voltage, V. Default 0.
    pub storage_initial_voltage: f64,
    /// Rectifier: storage voltage whose first crossing is reported, V (absent: none).
    pub target_voltage: Option<f64>,
    /// Initial transferred charge, C (absent: electrostatic equilibrium).
    pub initial_charge: Option<f64>,
    /// `"one_way"` (default) or `"two_way"`: whether the electrostatic force of the charges
    /// acts on the masses.
    pub coupling: Coupling,
    /// Two-way coupling: displacement error a window's charge representation may cause, m.
    /// Default 1e-11.
    pub coupling_tolerance: f64,
    /// Rectifier diodes: saturation current, A. Default 2.52e-9.
    pub diode_saturation_current: f64,
    /// Rectifier diodes: ideality factor. Default 1.752.
    pub diode_ideality: f64,
    /// Rectifier diodes: series resistance, Ω. Default 0.568.
    pub diode_series_resistance: f64,
    /// Rectifier diodes: thermal voltage, V. Default 0.025 864 (27 °C).
    pub diode_thermal_voltage: f64,
    /// Rectifier diodes: leakage conductance, S. Default 0.
    pub diode_parallel_conductance: f64,
}

impl Default for HarvesterTable {
    fn default() -> Self {
        HarvesterParams::default().into()
    }
}

impl From<HarvesterParams> for HarvesterTable {
    fn from(h: HarvesterParams) -> Self {
        let resistance = h.load.resistance().unwrap_or(1e5);
        let r = h.load.rectifier().copied().unwrap_or_default();
        HarvesterTable {
            mode: h.mode,
            voc_model: h.voc_model,
            contact: h.contact,
            area: h.area,
            charge_density: h.charge_density,
            dielectric_thickness: h.dielectric_thickness,
            relative_permittivity: h.relative_permittivity,
            load: h.load.kind(),
            load_resistance: resistance,
            storage_capacitance: r.storage_capacitance,
            storage_load_resistance: r.storage_load_resistance,
            storage_initial_voltage: r.storage_initial_voltage,
            target_voltage: r.target_voltage,
            initial_charge: h.initial_charge,
            coupling: h.coupling,
            coupling_tolerance: h.coupling_tolerance,
            diode_saturation_current: r.diode.saturation_current,
            diode_ideality: r.diode.ideality,
            diode_series_resistance: r.diode.series_resistance,
            diode_thermal_voltage: r.diode.thermal_voltage,
            diode_parallel_conductance: r.diode.parallel_conductance,
        }
    }
}

impl TryFrom<HarvesterTable> for HarvesterParams {
    type Error = ParamError;

    /// The parameters of the table (not validated: see [`HarvesterParams::validate`]).
    fn try_from(t: HarvesterTable) -> Result<Self, ParamError> {
        let load = match t.load {
            LoadKind::Resistor => Load::Resistor {
                resistance: t.load_resistance,
            },
            LoadKind::Rectifier => Load::Rectifier(Rectifier {
                storage_capacitance: t.storage_capacitance,
                storage_load_resistance: t.storage_load_resistance,
                storage_initial_voltage: t.storage_initial_voltage,
                target_voltage: t.target_voltage,
                diode: Diode {
                    saturation_current: t.diode_saturation_current,
                    ideality: t.diode_ideality,
                    thermal_voltage: t.diode_thermal_voltage,
                    series_resistance: t.diode_series_resistance,
                    parallel_conductance: t.diode_parallel_conductance,
                },
            }),
            LoadKind::Open => Load::Open,
            LoadKind::Short => Load::Short,
        };
        Ok(HarvesterParams {
            mode: t.mode,
            voc_model: t.voc_model,
            contact: t.contact,
            area: t.area,
            charge_density: t.charge_density,
            dielectric_thickness: t.dielectric_thickness,
            relative_permittivity: t.relative_permittivity,
            load,
            initial_charge: t.initial_charge,
            coupling: t.coupling,
            coupling_tolerance: t.coupling_tolerance,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_round_trip_through_parameters() {
        let rect = HarvesterTable {
            load: LoadKind::Rectifier,
            storage_capacitance: 2e-6,
            target_voltage: Some(3.0),
            diode_ideality: 1.9,
            ..HarvesterTable::default()
        };
        let p = HarvesterParams::try_from(rect.clone()).unwrap();
        let r = p.load.rectifier().unwrap();
        assert_eq!(r.storage_capacitance, 2e-6);
        assert_eq!(r.diode.ideality, 1.9);
        assert_eq!(HarvesterTable::from(p), rect);
        let p = HarvesterParams::try_from(HarvesterTable {
            load_resistance: 7.0,
            ..HarvesterTable::default()
        })
        .unwrap();
        assert_eq!(p.load, Load::Resistor { resistance: 7.0 });
        assert_eq!(
            HarvesterTable::from(HarvesterParams::default()),
            HarvesterTable::default()
        );
    }
}
