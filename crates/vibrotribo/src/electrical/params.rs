//! Physical parameters of the triboelectric transducer and its load (the `[harvester]` table of
//! a configuration file), and their validation.

use super::diode::Diode;
use super::transducer::{ContactSeparation, Freestanding, Transducer};
use crate::coupling::Coupling;
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

/// Which kind of load the transducer's electrodes are connected to (the name of a [`Load`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum LoadKind {
    /// A resistor (the paper's load).
    #[default]
    Resistor,
    /// A full-wave diode bridge charging a storage capacitor.
    Rectifier,
    /// Open circuit (R → ∞).
    Open,
    /// Short circuit (R → 0).
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

/// What the transducer's electrodes are connected to, with the load's own parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Load {
    /// A resistor (the paper's load): `R dQ/dt = V`.
    Resistor {
        /// Resistance R, Ω (`harvester.load_resistance`). Default 1e5 Ω.
        resistance: f64,
    },
    /// A full-wave bridge of four identical diodes charging a storage capacitor.
    Rectifier(Rectifier),
    /// Open circuit (R → ∞): the charge stays at its initial value.
    Open,
    /// Short circuit (R → 0): the charge follows `C·V_oc` exactly; nothing is dissipated.
    Short,
}

impl Default for Load {
    /// The paper's 100 kΩ resistor.
    fn default() -> Self {
        Load::Resistor { resistance: 1e5 }
    }
}

impl Load {
    /// The kind of this load.
    pub fn kind(&self) -> LoadKind {
        match self {
            Load::Resistor { .. } => LoadKind::Resistor,
            Load::Rectifier(_) => LoadKind::Rectifier,
            Load::Open => LoadKind::Open,
            Load::Short => LoadKind::Short,
        }
    }

    /// The resistance of a resistor load, Ω.
    pub fn resistance(&self) -> Option<f64> {
        match self {
            Load::Resistor { resistance } => Some(*resistance),
            _ => None,
        }
    }

    /// The rectifier, if this is one.
    pub fn rectifier(&self) -> Option<&Rectifier> {
        match self {
            Load::Rectifier(r) => Some(r),
            _ => None,
        }
    }
}

/// A full-wave diode bridge into a storage capacitor (see [`diode`](super::Diode) for the
/// diode law), optionally with a resistor across the capacitor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rectifier {
    /// Storage capacitance, F (`harvester.storage_capacitance`). Default 1e-6 F.
    pub storage_capacitance: f64,
    /// Resistor across the storage capacitor, Ω (`harvester.storage_load_resistance`);
    /// `None` (default) for none.
    pub storage_load_resistance: Option<f64>,
    /// Storage capacitor voltage at the start, V (`harvester.storage_initial_voltage`).
    /// Default 0 V.
    pub storage_initial_voltage: f64,
    /// Storage voltage whose first crossing time is reported, V (`harvester.target_voltage`);
    /// `None` (default) for none.
    pub target_voltage: Option<f64>,
    /// The bridge's diodes (`harvester.diode_*`). Default: a 1N4148 (I_s = 2.52 nA,
    /// n = 1.752, R_s = 0.568 Ω) at 27 °C, no leakage.
    pub diode: Diode,
}

impl Default for Rectifier {
    fn default() -> Self {
        Rectifier {
            storage_capacitance: 1e-6,
            storage_load_resistance: None,
            storage_initial_voltage: 0.0,
            target_voltage: None,
            diode: Diode {
                saturation_current: 2.52e-9,
                ideality: 1.752,
                thermal_voltage: BOLTZMANN_OVER_CHARGE * 300.15,
                series_resistance: 0.568,
                parallel_conductance: 0.0,
            },
        }
    }
}

/// Physical parameters of the triboelectric harvester: transducer and load. In a
/// configuration file this is the `[harvester]` table, where the load's parameters are keys
/// of the table beside `load = "…"` (see [`HarvesterTable`](super::HarvesterTable)).
///
/// [`Default`] is the paper's case (Sect. 3): freestanding mode with eq. 13, S = 0.01 m²,
/// σ = 15 µC/m², d₁ = d₂ = 0.1 mm, ε_r = 2.0, R = 100 kΩ.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(
    feature = "serde",
    serde(try_from = "super::HarvesterTable", into = "super::HarvesterTable")
)]
pub struct HarvesterParams {
    /// Transducer (`harvester.mode`): freestanding (default) or contact-separation.
    pub mode: TransducerMode,
    /// Open-circuit voltage law of the freestanding mode (`harvester.voc_model`): the
    /// paper's eq. 13 (default) or Gauss's law. Ignored in contact-separation mode.
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
    /// The load and its parameters (`harvester.load` and the keys of that load). Default a
    /// 100 kΩ resistor.
    pub load: Load,
    /// Charge transferred between the electrodes at the start, C (`harvester.initial_charge`).
    /// `None` (default): electrostatic equilibrium `Q(0) = C(0)·V_oc(0)`.
    pub initial_charge: Option<f64>,
    /// Whether the charges act back on the masses (`harvester.coupling`): `"one_way"`
    /// (default, the paper's model) or `"two_way"` (the electrostatic force on the plates,
    /// [`crate::coupling`]; needs `voc_model = "exact"` in freestanding mode).
    pub coupling: Coupling,
    /// Two-way coupling: the displacement error, m, that the charge's representation over one
    /// window may cause (`harvester.coupling_tolerance`, see
    /// [`CouplingOptions::position_tolerance`](crate::coupling::CouplingOptions::position_tolerance)).
    /// Default 1e-11 m.
    pub coupling_tolerance: f64,
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
            load: Load::default(),
            initial_charge: None,
            coupling: Coupling::OneWay,
            coupling_tolerance: crate::coupling::CouplingOptions::default().position_tolerance,
        }
    }
}

impl HarvesterParams {
    /// Checks every parameter on its own; returns the first problem, naming the parameter by
    /// its key in the `[harvester]` table (`area`, `relative_permittivity[1]`,
    /// `load_resistance`, …; a configuration prefixes `harvester.`).
    pub fn validate(&self) -> Result<(), ParamError> {
        check_positive("area", self.area)?;
        check_finite("charge_density", self.charge_density)?;
        for (i, &d) in self.dielectric_thickness.iter().enumerate() {
            check_non_negative(&format!("dielectric_thickness[{i}]"), d)?;
        }
        for (i, &e) in self.relative_permittivity.iter().enumerate() {
            check_positive(&format!("relative_permittivity[{i}]"), e)?;
        }
        if self.effective_thickness() <= 0.0 {
            return Err(ParamError::invalid(
                "dielectric_thickness",
                0.0,
                "at least one film must have positive thickness (the capacitance at contact \
                 would be infinite)",
            ));
        }
        if let Some(q) = self.initial_charge {
            check_finite("initial_charge", q)?;
        }
        check_positive("coupling_tolerance", self.coupling_tolerance)?;
        if self.coupling == Coupling::TwoWay
            && self.mode == TransducerMode::Freestanding
            && self.voc_model == VocModel::Paper
        {
            return Err(ParamError::Conflict {
                name: "coupling".into(),
                message: super::energy::NoFieldEnergy::PaperVoc.to_string(),
            });
        }
        match &self.load {
            Load::Resistor { resistance } => check_positive("load_resistance", *resistance),
            Load::Rectifier(r) => r.validate(),
            Load::Open | Load::Short => Ok(()),
        }
    }

    /// [`validate`](Self::validate), then checks that the transducer's contacts exist in a
    /// chain with `gaps` gaps (N − 1 for N masses).
    pub fn validate_for_gaps(&self, gaps: usize) -> Result<(), ParamError> {
        self.validate()?;
        match self.mode {
            TransducerMode::Freestanding => {
                if gaps < 2 {
                    return Err(ParamError::Conflict {
                        name: "mode".into(),
                        message: format!(
                            "\"freestanding\" needs two gaps (at least 3 masses), but the chain has {} \
                             masses; use \"contact_separation\"",
                            gaps + 1
                        ),
                    });
                }
                if self.contact + 1 >= gaps {
                    return Err(ParamError::invalid(
                        "contact",
                        self.contact as f64,
                        "freestanding mode uses contacts `contact` and `contact + 1`, which must \
                         both exist in the chain",
                    ));
                }
            }
            TransducerMode::ContactSeparation => {
                if self.contact >= gaps {
                    return Err(ParamError::invalid(
                        "contact",
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
}

impl Rectifier {
    /// Checks the rectifier's parameters, naming them by their `[harvester]` keys.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_positive("storage_capacitance", self.storage_capacitance)?;
        if let Some(r) = self.storage_load_resistance {
            check_positive("storage_load_resistance", r)?;
        }
        check_finite("storage_initial_voltage", self.storage_initial_voltage)?;
        if let Some(v) = self.target_voltage {
            check_finite("target_voltage", v)?;
        }
        let d = &self.diode;
        check_positive("diode_saturation_current", d.saturation_current)?;
        check_positive("diode_ideality", d.ideality)?;
        check_positive("diode_series_resistance", d.series_resistance)?;
        check_positive("diode_thermal_voltage", d.thermal_voltage)?;
        check_non_negative("diode_parallel_conductance", d.parallel_conductance)
    }
}
