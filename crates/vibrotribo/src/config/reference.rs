//! The configuration reference: every key of the schema with its unit, default and allowed
//! values, as Markdown (the user guide's `reference/configuration.md`, written by
//! `vibrotribo config-reference`).
//!
//! The keys come from the schema ([`known_keys`]) and the defaults from the document the
//! paper's default case reads as (the library's `Default` values serialised); each key's
//! meaning, unit and allowed values are stated in [`KEY_DOCS`] beside it. The two are
//! checked against each other: a key of the schema without an entry, or an entry that is no
//! key, is listed by [`undocumented_keys`] and [`stale_entries`] (and the library's tests fail).

use serde_json::Value as Json;

use super::document::{Document, ExcitationTable, OscillatorTable};
use super::keys::{DERIVED_KEYS, PerMass, default_chain, known_keys};
use crate::excitation::ExcitationKind;
use crate::model::{ChainParams, Frequency};

/// What values a key accepts (as validation checks them).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Allowed {
    /// A finite number > 0 (every element, for an array).
    Positive,
    /// A finite number ≥ 0 (every element, for an array).
    NonNegative,
    /// A finite number in the closed interval.
    Between(f64, f64),
    /// An integer ≥ the bound.
    IntegerAtLeast(u64),
    /// One of these strings.
    OneOf(&'static [&'static str]),
    /// As the text says.
    Text(&'static str),
}

impl Allowed {
    /// The allowed values as the reference shows them.
    pub fn describe(&self) -> String {
        match self {
            Allowed::Positive => "> 0".into(),
            Allowed::NonNegative => "≥ 0".into(),
            Allowed::Between(a, b) => format!("[{a}, {b}]"),
            Allowed::IntegerAtLeast(n) => format!("integer ≥ {n}"),
            Allowed::OneOf(names) => names
                .iter()
                .map(|n| format!("`\"{n}\"`"))
                .collect::<Vec<_>>()
                .join(", "),
            Allowed::Text(t) => (*t).into(),
        }
    }
}

/// One key's entry in the reference.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeyDoc {
    /// The key, `section.name` (`oscillator.masses`).
    pub key: &'static str,
    /// Its unit (`"kg"`, `"m/s²"`; `"—"` when dimensionless or not a number).
    pub unit: &'static str,
    /// The values validation accepts.
    pub allowed: Allowed,
    /// The default when the schema's default is "absent" (an optional key), in words; empty
    /// when the schema has a value.
    pub absent: &'static str,
    /// What the key means.
    pub meaning: &'static str,
}

const fn doc(
    key: &'static str,
    unit: &'static str,
    allowed: Allowed,
    absent: &'static str,
    meaning: &'static str,
) -> KeyDoc {
    KeyDoc {
        key,
        unit,
        allowed,
        absent,
        meaning,
    }
}

use Allowed::{Between, IntegerAtLeast, NonNegative, OneOf, Positive, Text};

const KINDS: &[&str] = &["harmonic", "multisine", "chirp", "random", "record"];

/// Meaning, unit and allowed values of every key, in the schema's order.
#[rustfmt::skip]
pub const KEY_DOCS: &[KeyDoc] = &[
    // [oscillator]
    doc("oscillator.masses", "kg", Positive, "", "Masses m₁ … m_N, top to bottom; their number is the chain's length N (N ≥ 2, or N ≥ 1 with a stop)."),
    doc("oscillator.stiffness", "N/m", Positive, "", "Spring stiffnesses k_i to the base; one number applies to every mass."),
    doc("oscillator.damping", "N·s/m", NonNegative, "", "Viscous damping c_i to the base; one number applies to every mass."),
    doc("oscillator.gaps", "m", NonNegative, "", "Gaps δ_k between masses k and k + 1 at rest (N − 1 of them); one number applies to every gap."),
    doc("oscillator.restitution", "—", Between(0.0, 1.0), "", "Newton's coefficient of restitution μ of impacts between masses."),
    doc("oscillator.forces", "N", Text("finite"), "none", "Constant external force on each mass, positive upward (gravity: −m_i g); one number applies to every mass."),
    doc("oscillator.stops.upper.gap", "m", NonNegative, "no stop", "A rigid stop above m₁: its distance from m₁'s static position with the base at rest."),
    doc("oscillator.stops.upper.restitution", "—", Between(0.0, 1.0), "required with a stop", "Restitution of impacts against the upper stop."),
    doc("oscillator.stops.upper.frame", "—", OneOf(&["fixed", "base"]), "`\"fixed\"`", "Whether the upper stop is fixed in space or moves with the base (sine only)."),
    doc("oscillator.stops.lower.gap", "m", NonNegative, "no stop", "A rigid stop below m_N: its distance from m_N's static position with the base at rest."),
    doc("oscillator.stops.lower.restitution", "—", Between(0.0, 1.0), "required with a stop", "Restitution of impacts against the lower stop."),
    doc("oscillator.stops.lower.frame", "—", OneOf(&["fixed", "base"]), "`\"fixed\"`", "Whether the lower stop is fixed in space or moves with the base (sine only)."),
    // [excitation]
    doc("excitation.kind", "—", OneOf(KINDS), "", "The base motion: the sine y = A sin ωt, a sum of harmonics, a chirp, band-limited noise or a recorded signal. Each kind takes only its own keys."),
    doc("excitation.amplitude", "m", NonNegative, "", "Base displacement amplitude A (harmonic, chirp)."),
    doc("excitation.omega_ratio", "—", Positive, "", "Reference frequency as Ω = ω/√(k₁/m₁); its period T is the unit of `[run]`. Give this or `frequency_hz`."),
    doc("excitation.frequency_hz", "Hz", Positive, "from `omega_ratio`", "Reference frequency in hertz (instead of `omega_ratio`)."),
    doc("excitation.harmonics", "m, —, rad", Text("1 to 64 tables `{amplitude, ratio or frequency_hz, phase}`"), "required for `multisine`", "Multisine: y = Σ A_j sin(r_j ω t + φ_j)."),
    doc("excitation.f_start_hz", "Hz", Positive, "required for `chirp`", "Chirp: frequency at t = 0."),
    doc("excitation.f_end_hz", "Hz", Positive, "required for `chirp`", "Chirp: frequency at the end of `duration_s` (below `f_start_hz`: a down-sweep)."),
    doc("excitation.sweep", "—", OneOf(&["linear", "logarithmic"]), "`\"linear\"`", "Chirp: how the frequency moves."),
    doc("excitation.duration_s", "s", Text("≥ the run's length"), "the run's length", "Chirp, random: the signal's duration."),
    doc("excitation.spline_tolerance", "—", Positive, "1e-9", "Chirp, random, record: bound on the interpolant's displacement error, relative to the signal's size."),
    doc("excitation.rms_acceleration", "m/s²", Positive, "—", "Random: RMS base acceleration of a flat one-sided PSD between `f_low_hz` and `f_high_hz`."),
    doc("excitation.f_low_hz", "Hz", NonNegative, "—", "Random (flat PSD): lower band edge."),
    doc("excitation.f_high_hz", "Hz", Text("> `f_low_hz`"), "—", "Random (flat PSD): upper band edge."),
    doc("excitation.psd_frequencies_hz", "Hz", Text("increasing"), "—", "Random (tabulated PSD): frequencies of the PSD points (linear interpolation, zero outside)."),
    doc("excitation.psd_values", "(m/s²)²/Hz", NonNegative, "—", "Random (tabulated PSD): one-sided PSD of the base acceleration at those frequencies."),
    doc("excitation.seed", "—", IntegerAtLeast(0), "0", "Random: seed of the random phases (the same seed, the same signal)."),
    doc("excitation.file", "—", Text("a CSV file, first column `time_s`"), "required for `record`", "Record: the signal's file; a relative path is relative to the configuration file."),
    doc("excitation.quantity", "—", OneOf(&["displacement", "acceleration"]), "required for `record`", "Record: what the file's second column holds (m or m/s²)."),
    doc("excitation.scale", "—", Text("finite"), "1", "Record: factor applied to the values."),
    doc("excitation.peak_acceleration", "m/s²", Positive, "—", "Record: scale the values so that the largest |acceleration| is this (instead of `scale`)."),
    // [run]
    doc("run.periods", "periods of T", IntegerAtLeast(1), "", "Excitation periods simulated in all, transient included."),
    doc("run.transient_periods", "periods of T", Text("integer < `periods`"), "50, or `periods` − 1 if that is less", "Leading periods left out of statistics and averages."),
    doc("run.samples_per_period", "1/T", IntegerAtLeast(1), "", "Samples per period of `trajectory.csv`."),
    doc("run.initial_positions", "m", Text("N finite numbers, no overlapping masses"), "all 0", "Initial positions x_i."),
    doc("run.initial_velocities", "m/s", Text("N finite numbers"), "all 0", "Initial velocities x_i'."),
    doc("run.start_relative_to_base", "—", OneOf(&["true", "false"]), "", "Whether the initial state is relative to the base's y(0), y'(0)."),
    // [options]
    doc("options.max_events_per_period", "—", IntegerAtLeast(1), "", "Events allowed in one period before a run stops with an error (a guard against pathological motion)."),
    doc("options.chatter_tolerance", "fraction of T", Text("> 0 and < 1e-2"), "", "Accuracy of a chatter accumulation-point jump."),
    doc("options.max_impact_iterations", "—", IntegerAtLeast(1), "", "Pairwise impacts allowed when resolving one simultaneous impact."),
    // [harvester]
    doc("harvester.mode", "—", OneOf(&["freestanding", "contact_separation"]), "", "Transducer: freestanding (three plates, two gaps; needs N ≥ 3) or contact-separation (one gap; the default for N = 2)."),
    doc("harvester.voc_model", "—", OneOf(&["paper", "exact"]), "", "Freestanding open-circuit voltage: the paper's 2σD₂/ε₀ or Gauss's law σ(D₂ − D₁)/ε₀."),
    doc("harvester.contact", "—", Text("integer; the contact (and, freestanding, the next) must exist"), "", "First contact used, 0-based (0: between m₁ and m₂)."),
    doc("harvester.area", "m²", Positive, "", "Electrode area S."),
    doc("harvester.charge_density", "C/m²", Text("finite"), "", "Triboelectric surface charge density σ."),
    doc("harvester.dielectric_thickness", "m", NonNegative, "", "Film thicknesses d₁, d₂ (at least one > 0)."),
    doc("harvester.relative_permittivity", "—", Positive, "", "Relative permittivities ε_r1, ε_r2 of the films."),
    doc("harvester.load", "—", OneOf(&["resistor", "rectifier", "open", "short"]), "", "The load: a resistor, a full-wave diode bridge into a storage capacitor, open or short circuit."),
    doc("harvester.load_resistance", "Ω", Positive, "", "Resistor load R."),
    doc("harvester.storage_capacitance", "F", Positive, "", "Rectifier: storage capacitance."),
    doc("harvester.storage_load_resistance", "Ω", Positive, "none", "Rectifier: resistor across the storage capacitor."),
    doc("harvester.storage_initial_voltage", "V", Text("finite"), "", "Rectifier: storage voltage at t = 0."),
    doc("harvester.target_voltage", "V", Text("finite"), "none", "Rectifier: storage voltage whose first crossing is reported (`time_to_target_s`)."),
    doc("harvester.initial_charge", "C", Text("finite"), "electrostatic equilibrium Q(0) = C(0)·V_oc(0)", "Charge transferred between the electrodes at t = 0."),
    doc("harvester.coupling", "—", OneOf(&["one_way", "two_way"]), "", "Whether the electrostatic force of the charges acts back on the masses (`two_way` needs `voc_model = \"exact\"` in freestanding mode)."),
    doc("harvester.coupling_tolerance", "m", Positive, "", "Two-way coupling: the displacement error one window's charge representation may cause."),
    doc("harvester.diode_saturation_current", "A", Positive, "", "Rectifier diodes: saturation current I_s."),
    doc("harvester.diode_ideality", "—", Positive, "", "Rectifier diodes: ideality factor n."),
    doc("harvester.diode_series_resistance", "Ω", Positive, "", "Rectifier diodes: series resistance."),
    doc("harvester.diode_thermal_voltage", "V", Positive, "", "Rectifier diodes: thermal voltage V_T."),
    doc("harvester.diode_parallel_conductance", "S", NonNegative, "", "Rectifier diodes: leakage conductance."),
    // [electrical]
    doc("electrical.rtol", "—", Between(1e-12, 1e-2), "", "Relative tolerance of the charge solver (local error per step and energy per period)."),
    doc("electrical.atol_voltage", "V", Positive, "`rtol` × the largest voltage seen", "Absolute voltage tolerance of the charge solver."),
    doc("electrical.max_steps_per_period", "—", IntegerAtLeast(1), "", "Charge-solver steps allowed in one period (a guard)."),
    doc("electrical.analytic_layers", "—", OneOf(&["true", "false"]), "", "Resistor: carry the R·C layer after an impact in closed form within one step."),
];

/// The document the paper's default case reads as: every table filled with the values the
/// library's `Default`s give.
fn default_document() -> Document {
    let chain: ChainParams = default_chain(ChainParams::default().len());
    let omega_ratio = match chain.excitation.frequency {
        Frequency::OmegaRatio(w) => Some(w),
        Frequency::Hertz(_) => None,
    };
    Document {
        oscillator: OscillatorTable {
            masses: Some(chain.masses.clone()),
            stiffness: Some(PerMass::Many(chain.stiffness.clone())),
            damping: Some(PerMass::Many(chain.damping.clone())),
            gaps: Some(PerMass::Many(chain.gaps.clone())),
            restitution: Some(chain.restitution),
            forces: None,
            stops: Default::default(),
        },
        excitation: ExcitationTable {
            kind: Some(ExcitationKind::default()),
            amplitude: Some(chain.excitation.amplitude),
            omega_ratio,
            ..Default::default()
        },
        harvester: Some(Default::default()),
        ..Document::default()
    }
}

/// The default of `key` (`section.name`) in the default document, as TOML writes it; `None`
/// when the key is absent by default.
fn default_of(defaults: &Json, key: &str) -> Option<String> {
    let mut v = defaults;
    for part in key.split('.') {
        v = v.get(part)?;
    }
    let toml_value: toml::Value = match v {
        Json::Null => return None,
        other => serde_json::from_value(other.clone()).ok()?,
    };
    Some(toml_value.to_string())
}

/// The default of every key of the schema in the paper's default case, as TOML writes it, in
/// the schema's order; `None` for a key absent by default (its [`KeyDoc::absent`] says what
/// absent means).
pub fn default_values() -> Vec<(String, Option<String>)> {
    let defaults = serde_json::to_value(default_document()).unwrap_or(Json::Null);
    known_keys()
        .into_iter()
        .map(|key| {
            let value = default_of(&defaults, &key);
            (key, value)
        })
        .collect()
}

/// Keys of the schema that [`KEY_DOCS`] lacks.
pub fn undocumented_keys() -> Vec<String> {
    known_keys()
        .into_iter()
        .filter(|k| !KEY_DOCS.iter().any(|d| d.key == k))
        .collect()
}

/// Entries of [`KEY_DOCS`] that are no key of the schema.
pub fn stale_entries() -> Vec<&'static str> {
    let known = known_keys();
    KEY_DOCS
        .iter()
        .map(|d| d.key)
        .filter(|k| !known.iter().any(|n| n == k))
        .collect()
}

/// Escapes a table cell (`|` would end it).
fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// The configuration reference as Markdown: one table per section, a row per key (unit,
/// default, allowed values, meaning), then the derived keys of overrides and sweeps.
pub fn reference_markdown() -> String {
    let defaults = serde_json::to_value(default_document()).unwrap_or(Json::Null);
    let mut out = String::new();
    out.push_str(
        "# Configuration reference\n\n\
         <!-- Generated by `vibrotribo config-reference` from the library's types; do not edit. \
         A test fails when this page and the library disagree. -->\n\n\
         Every key is optional: an absent key takes its default, and the defaults are the \
         paper's default case. The same keys work in files, in `--set KEY=VALUE`, as sweep \
         parameters and as Python keyword arguments (`excitation__omega_ratio=0.6`). A key \
         given to an array (`oscillator.gaps[1]`) sets one element. An unknown key or a value \
         outside its allowed range is an error naming the key.\n",
    );
    let mut section = "";
    let undocumented = undocumented_keys();
    for key in known_keys() {
        let (sec, _) = key.split_once('.').unwrap_or((key.as_str(), ""));
        if sec != section {
            section = match sec {
                "oscillator" => "oscillator",
                "excitation" => "excitation",
                "run" => "run",
                "options" => "options",
                "harvester" => "harvester",
                "electrical" => "electrical",
                _ => "other",
            };
            out.push_str(&format!(
                "\n## `[{sec}]`\n\n| key | unit | default | allowed | meaning |\n|---|---|---|---|---|\n"
            ));
        }
        let name = key.strip_prefix(&format!("{sec}.")).unwrap_or(&key);
        match KEY_DOCS.iter().find(|d| d.key == key) {
            Some(d) => {
                let default = match default_of(&defaults, &key) {
                    Some(v) => format!("`{v}`"),
                    None if d.absent.is_empty() => "—".into(),
                    None => d.absent.to_string(),
                };
                out.push_str(&format!(
                    "| `{name}` | {} | {} | {} | {} |\n",
                    cell(d.unit),
                    cell(&default),
                    cell(&d.allowed.describe()),
                    cell(d.meaning)
                ));
            }
            None if undocumented.contains(&key) => {
                out.push_str(&format!("| `{name}` | ? | ? | ? | (undocumented) |\n"));
            }
            None => {}
        }
    }
    out.push_str(
        "\n## Derived keys\n\n\
         Accepted by `--set`, by sweeps (`--param`, `--x`, `--y`) and by Python; each sets \
         the keys it names.\n\n| key | what it sets |\n|---|---|\n",
    );
    for (key, what) in DERIVED_KEYS {
        out.push_str(&format!("| `{key}` | {} |\n", cell(what)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;

    #[test]
    fn every_key_is_documented_and_every_entry_is_a_key() {
        assert!(
            undocumented_keys().is_empty(),
            "keys without an entry in KEY_DOCS: {:?}",
            undocumented_keys()
        );
        assert!(
            stale_entries().is_empty(),
            "KEY_DOCS entries that are no key: {:?}",
            stale_entries()
        );
    }

    /// The defaults the reference shows are the values the default configuration reads.
    #[test]
    fn shown_defaults_are_the_default_configuration() {
        let config = Config::default();
        let defaults = serde_json::to_value(default_document()).unwrap();
        let chain = config.chain();
        assert_eq!(
            default_of(&defaults, "oscillator.masses"),
            Some(toml::Value::try_from(&chain.masses).unwrap().to_string())
        );
        assert_eq!(
            default_of(&defaults, "oscillator.gaps"),
            Some(toml::Value::try_from(&chain.gaps).unwrap().to_string())
        );
        assert_eq!(
            default_of(&defaults, "excitation.amplitude"),
            Some(chain.excitation.amplitude.to_string())
        );
        assert_eq!(
            default_of(&defaults, "excitation.omega_ratio").map(|v| v.parse::<f64>().unwrap()),
            Some(chain.omega_ratio()).map(|w| (w * 1e12).round() / 1e12)
        );
        assert_eq!(default_of(&defaults, "run.periods"), Some("100".into()));
        assert_eq!(
            default_of(&defaults, "harvester.load_resistance"),
            Some("100000.0".into())
        );
        assert_eq!(default_of(&defaults, "run.transient_periods"), None);
        // A configuration written from the shown defaults reads as the default one.
        let mut text = String::new();
        for key in [
            "oscillator.masses",
            "oscillator.stiffness",
            "oscillator.damping",
            "oscillator.gaps",
            "oscillator.restitution",
        ] {
            let (_, name) = key.split_once('.').unwrap();
            if text.is_empty() {
                text.push_str("[oscillator]\n");
            }
            text.push_str(&format!("{name} = {}\n", default_of(&defaults, key).unwrap()));
        }
        let written = Config::from_toml_str(&text).unwrap();
        assert_eq!(written.chain(), config.chain());
    }
}
