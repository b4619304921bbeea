//! Physical parameters of the triboelectric transducer and its load (the `[harvester]` table of
//! a configuration file), and their validation.

use super::diode::Diode;
use super::transducer::{ContactSeparation, Freestanding, Transducer};
use crate::error::{ParamError, check_finite, check_non_negative, check_positive};

/// Vacuum permittivity ε₀, F/m (CODATA 2018).
pub const EPSILON_0: f64 = 8.854_187_812_8e-12;

/// Boltzmann constant over the elementary charge as ngspice 39 uses them
/// (`CONSTboltz = 1.38064852e-23` J/K, `CHARGE = 1.6021766208e-19` C), V/K.
pub const BOLTZMANN_OVER_CHARGE: f64 = 1.380_648_52e-23 / 1.602_176_620_8e-19;

/// Which triboelectric transducer converts the gaps into charge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum TransducerMode {
    /// The paper's freestanding contact mode (seed eqs. 12–13): dielectric films with their
    /// electrodes on the masses either side of a freestanding aluminium layer; the two gaps
    /// are contacts `contact` and `contact + 1`. Needs at least 3 masses.
    #[default]
    Freestanding,
    /// Two-plate contact-separation mode on the single contact `contact`: works for N = 2.
    ContactSeparation,
}

impl TransducerMode {
    /// The name used in configuration files.
    pub fn as_str(self) -> &'static str {
        match self {
            TransducerMode::Freestanding => "freestanding",
            TransducerMode::ContactSeparation => "contact_separation",
        }
    }
}

/// Open-circuit voltage law of the freestanding mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum VocModel {
    /// The paper's eq. 13, `V_oc = 2σD₂/ε₀` (exact only when the outer plates are fixed).
    #[default]
    Paper,
    /// Gauss's law with moving outer plates (docs/MODEL.md §2), `V_oc = σ(D₂ − D₁)/ε₀`.
    Exact,
}

impl VocModel {
    /// Name as written in configuration files: `paper` or `exact`.
    pub fn as_str(self) -> &'static str {
        match self {
            VocModel::Paper => "paper",
            VocModel::Exact => "exact",
        }
    }
}

/// What the transducer's electrodes are connected to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum LoadKind {
    /// A resistor of `load_resistance` (the paper's load).
    #[default]
    Resistor,
    /// A full-wave bridge of four identical diodes charging a storage capacitor of
    /// `storage_capacitance`, optionally with a resistor `storage_load_resistance` across it.
    Rectifier,
    /// Open circuit (R → ∞): the charge stays at its initial value.
    Open,
    /// Short circuit (R → 0): the charge follows `C·V_oc` exactly; nothing is dissipated.
    Short,
}

impl LoadKind {
    /// The name used in configuration files.
    pub fn as_str(self) -> &'static str {
        match self {
            LoadKind::Resistor => "resistor",
            LoadKind::Rectifier => "rectifier",
            LoadKind::Open => "open",
            LoadKind::Short => "short",
        }
    }
}

/// Physical parameters of the triboelectric harvester: transducer and load (the `[harvester]`
/// table of a configuration file; every field is a key of that table).
///
/// [`Default`] is the paper's case (Sect. 3): freestanding mode with eq. 13, S = 0.01 m²,
/// σ = 15 µC/m², d₁ = d₂ = 0.1 mm, ε_r = 2.0, R = 100 kΩ.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct HarvesterParams {
    /// Transducer (`harvester.mode`): `"freestanding"` (default) or `"contact_separation"`.
    pub mode: TransducerMode,
    /// Open-circuit voltage law of the freestanding mode (`harvester.voc_model`): `"paper"`
    /// (default, eq. 13) or `"exact"`. Ignored in contact-separation mode.
    pub voc_model: VocModel,
    /// First contact used (`harvester.contact`), 0-based (contact k is the gap between mass k
    /// and k+1). Contact-separation mode uses this contact; freestanding mode uses it as D₁
    /// and the next one as D₂. Default 0.
    pub contact: usize,
    /// Electrode (contact) area S, m² (`harvester.area`). Default 0.01 m².
    pub area: f64,
    /// Triboelectric surface charge density σ, C/m² (`harvester.charge_density`).
    /// Default 15e-6 C/m².
    pub charge_density: f64,
    /// Dielectric film thicknesses d₁, d₂, m (`harvester.dielectric_thickness`).
    /// Default [1e-4, 1e-4] m.
    pub dielectric_thickness: [f64; 2],
    /// Relative permittivities ε_r1, ε_r2 of the films (`harvester.relative_permittivity`),
    /// dimensionless. Default [2.0, 2.0] (PTFE).
    pub relative_permittivity: [f64; 2],
    /// Load (`harvester.load`): `"resistor"` (default), `"rectifier"`, `"open"`, `"short"`.
    pub load: LoadKind,
    /// Load resistance R of the resistor load, Ω (`harvester.load_resistance`).
    /// Default 1e5 Ω.
    pub load_resistance: f64,
    /// Storage capacitance behind the rectifier, F (`harvester.storage_capacitance`).
    /// Default 1e-6 F.
    pub storage_capacitance: f64,
    /// Resistor across the storage capacitor, Ω (`harvester.storage_load_resistance`);
    /// absent (default) for none.
    pub storage_load_resistance: Option<f64>,
    /// Storage capacitor voltage at the start, V (`harvester.storage_initial_voltage`).
    /// Default 0 V.
    pub storage_initial_voltage: f64,
    /// Storage voltage whose first crossing time is reported, V (`harvester.target_voltage`);
    /// absent (default) for none.
    pub target_voltage: Option<f64>,
    /// Charge transferred between the electrodes at the start, C (`harvester.initial_charge`).
    /// Absent (default): electrostatic equilibrium `Q(0) = C(0)·V_oc(0)`.
    pub initial_charge: Option<f64>,
    /// Diode saturation current I_s, A (`harvester.diode_saturation_current`).
    /// Default 2.52e-9 A (a 1N4148).
    pub diode_saturation_current: f64,
    /// Diode ideality (emission) factor n, dimensionless (`harvester.diode_ideality`).
    /// Default 1.752.
    pub diode_ideality: f64,
    /// Diode series resistance R_s, Ω (`harvester.diode_series_resistance`). Must be positive.
    /// Default 0.568 Ω.
    pub diode_series_resistance: f64,
    /// Thermal voltage V_T = kT/q, V (`harvester.diode_thermal_voltage`). Default
    /// 0.025 864 V (T = 300.15 K, ngspice's default 27 °C).
    pub diode_thermal_voltage: f64,
    /// Leakage conductance across each diode, S (`harvester.diode_parallel_conductance`).
    /// Default 0. (ngspice needs some, e.g. 1e-10 S, to solve the floating bridge robustly.)
    pub diode_parallel_conductance: f64,
}

impl Default for HarvesterParams {
    fn default() -> Self {
        HarvesterParams {
            mode: TransducerMode::default(),
            voc_model: VocModel::default(),
            contact: 0,
            area: 0.01,
            charge_density: 15e-6,
            dielectric_thickness: [1e-4, 1e-4],
            relative_permittivity: [2.0, 2.0],
            load: LoadKind::default(),
            load_resistance: 1e5,
            storage_capacitance: 1e-6,
            storage_load_resistance: None,
            storage_initial_voltage: 0.0,
            target_voltage: None,
            initial_charge: None,
            diode_saturation_current: 2.52e-9,
            diode_ideality: 1.752,
            diode_series_resistance: 0.568,
            diode_thermal_voltage: BOLTZMANN_OVER_CHARGE * 300.15,
            diode_parallel_conductance: 0.0,
        }
    }
}

impl HarvesterParams {
    /// Checks every parameter on its own; returns the first problem, naming its key
    /// (`harvester.area`, `harvester.relative_permittivity[1]`, …).
    pub fn validate(&self) -> Result<(), ParamError> {
        check_positive("harvester.area", self.area)?;
        check_finite("harvester.charge_density", self.charge_density)?;
        for (i, &d) in self.dielectric_thickness.iter().enumerate() {
            check_non_negative(&format!("harvester.dielectric_thickness[{i}]"), d)?;
        }
        for (i, &e) in self.relative_permittivity.iter().enumerate() {
            check_positive(&format!("harvester.relative_permittivity[{i}]"), e)?;
        }
        if self.effective_thickness() <= 0.0 {
            return Err(ParamError::invalid(
                "harvester.dielectric_thickness",
                0.0,
                "at least one film must have positive thickness (the capacitance at contact \
                 would be infinite)",
            ));
        }
        check_positive("harvester.load_resistance", self.load_resistance)?;
        check_positive("harvester.storage_capacitance", self.storage_capacitance)?;
        if let Some(r) = self.storage_load_resistance {
            check_positive("harvester.storage_load_resistance", r)?;
        }
        check_finite("harvester.storage_initial_voltage", self.storage_initial_voltage)?;
        if let Some(v) = self.target_voltage {
            check_finite("harvester.target_voltage", v)?;
        }
        if let Some(q) = self.initial_charge {
            check_finite("harvester.initial_charge", q)?;
        }
        check_positive(
            "harvester.diode_saturation_current",
            self.diode_saturation_current,
        )?;
        check_positive("harvester.diode_ideality", self.diode_ideality)?;
        check_positive("harvester.diode_series_resistance", self.diode_series_resistance)?;
        check_positive("harvester.diode_thermal_voltage", self.diode_thermal_voltage)?;
        check_non_negative(
            "harvester.diode_parallel_conductance",
            self.diode_parallel_conductance,
        )?;
        Ok(())
    }

    /// [`validate`](Self::validate), then checks that the transducer's contacts exist in a
    /// chain with `gaps` gaps (N − 1 for N masses).
    pub fn validate_for_gaps(&self, gaps: usize) -> Result<(), ParamError> {
        self.validate()?;
        match self.mode {
            TransducerMode::Freestanding => {
                if gaps < 2 {
                    return Err(ParamError::Conflict(format!(
                        "harvester.mode = \"freestanding\" needs two gaps (at least 3 masses), but the \
                         chain has {} masses; use harvester.mode = \"contact_separation\"",
                        gaps + 1
                    )));
                }
                if self.contact + 1 >= gaps {
                    return Err(ParamError::invalid(
                        "harvester.contact",
                        self.contact as f64,
                        "freestanding mode uses contacts `contact` and `contact + 1`, which must \
                         both exist in the chain",
                    ));
                }
            }
            TransducerMode::ContactSeparation => {
                if self.contact >= gaps {
                    return Err(ParamError::invalid(
                        "harvester.contact",
                        self.contact as f64,
                        "no such contact in the chain (0-based, at most N − 2)",
                    ));
                }
            }
        }
        Ok(())
    }

    /// d₀ = d₁/ε_r1 + d₂/ε_r2, m: the films' thickness in vacuum-equivalent units.
    pub fn effective_thickness(&self) -> f64 {
        self.dielectric_thickness[0] / self.relative_permittivity[0]
            + self.dielectric_thickness[1] / self.relative_permittivity[1]
    }

    /// The transducer these parameters describe (not validated; call
    /// [`validate`](Self::validate) first).
    pub fn transducer(&self) -> Transducer {
        let eps_area = EPSILON_0 * self.area;
        let d0 = self.effective_thickness();
        match self.mode {
            TransducerMode::Freestanding => Transducer::Freestanding(Freestanding {
                eps_area,
                d0,
                charge_density: self.charge_density,
                voc_model: self.voc_model,
                contacts: [self.contact, self.contact + 1],
            }),
            TransducerMode::ContactSeparation => Transducer::ContactSeparation(ContactSeparation {
                eps_area,
                d0,
                charge_density: self.charge_density,
                contact: self.contact,
            }),
        }
    }

    /// The bridge diodes these parameters describe.
    pub fn diode(&self) -> Diode {
        Diode {
            saturation_current: self.diode_saturation_current,
            ideality: self.diode_ideality,
            thermal_voltage: self.diode_thermal_voltage,
            series_resistance: self.diode_series_resistance,
            parallel_conductance: self.diode_parallel_conductance,
        }
    }
}
