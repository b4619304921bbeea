//! [`Param`]: a configuration key resolved once into the field of the document's types it
//! sets, so that the points of a sweep or a map set numbers directly instead of writing and
//! reading TOML again.

use toml::{Table, Value};

use super::document::{Config, Document, lenient_chain};
use super::error::ConfigError;
use super::keys::PerMass;

/// A numeric parameter of a configuration, addressed by its key (as in
/// [`Config::set`]), resolved once against a configuration's shape: the chain's scalars
/// (`excitation.omega_ratio`, `oscillator.restitution`, …), one element of its arrays
/// (`oscillator.gaps[1]`), the derived keys (`mass_ratio`, `gap_ratio`, …), and any other key
/// of the file (`harvester.load_resistance`, an integer such as `excitation.seed`), which is
/// set through the TOML tree.
///
/// ```
/// use vibrotribo::config::{Config, Param};
///
/// let base = Config::default();
/// let ratio = Param::new(&base, "mass_ratio")?;
/// let point = base.with_values(&[(&ratio, 3.0)])?;
/// assert_eq!(point.chain().masses[1], 3.0 * point.chain().masses[0]);
/// // One mass against a stop (an impact oscillator): no m2, so no mass ratio.
/// let one_mass = Config::from_toml_str(
///     "[oscillator]\nmasses = [0.05]\nstiffness = 120.0\ndamping = 0.1\n\
///      [oscillator.stops.upper]\ngap = 0.001\nrestitution = 0.8\n",
/// )?;
/// assert!(Param::new(&one_mass, "mass_ratio").is_err());
/// # Ok::<(), vibrotribo::config::ConfigError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    key: String,
    target: Target,
}

/// What a [`Param`] sets.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Target {
    /// `m2 = R·m1`.
    MassRatio,
    /// Every mass but m2 set to `m2/R`.
    MassRatioM2Fixed,
    /// `δ2 = R·δ1`.
    GapRatio,
    /// Every gap.
    Gap,
    /// A scalar of the document.
    Scalar(Scalar),
    /// One element of an array of `[oscillator]`.
    Element(Array, usize),
    /// Any other key: set through the TOML tree ([`Config::set_all`]).
    Tree,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Scalar {
    OmegaRatio,
    FrequencyHz,
    Amplitude,
    Restitution,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Array {
    Masses,
    Stiffness,
    Damping,
    Gaps,
    Forces,
}

impl Array {
    fn name(self) -> &'static str {
        match self {
            Array::Masses => "masses",
            Array::Stiffness => "stiffness",
            Array::Damping => "damping",
            Array::Gaps => "gaps",
            Array::Forces => "forces",
        }
    }
}

impl Param {
    /// The parameter `key` of configurations shaped like `config` (the same number of masses):
    /// an error naming the key if it cannot apply to them (an element beyond an array's end,
    /// `mass_ratio` on a single mass). An unknown key of the file is reported when it is set.
    pub fn new(config: &Config, key: &str) -> Result<Self, ConfigError> {
        let chain = config.chain();
        let n = chain.len();
        let needs = |what: &str, least: usize, of: &str| {
            Err(ConfigError::Malformed(format!(
                "{key} needs at least {least} {of} ({what}); this chain has {n} masses"
            )))
        };
        let target = match key {
            "mass_ratio" | "mass_ratio_m2_fixed" if n < 2 => return needs("m2/m1", 2, "masses"),
            "gap_ratio" if n < 3 => return needs("δ2/δ1", 3, "masses"),
            "mass_ratio" => Target::MassRatio,
            "mass_ratio_m2_fixed" => Target::MassRatioM2Fixed,
            "gap_ratio" => Target::GapRatio,
            "gap" => Target::Gap,
            "omega_ratio" | "excitation.omega_ratio" => Target::Scalar(Scalar::OmegaRatio),
            "frequency_hz" | "excitation.frequency_hz" => Target::Scalar(Scalar::FrequencyHz),
            "amplitude" | "excitation.amplitude" => Target::Scalar(Scalar::Amplitude),
            "restitution" | "oscillator.restitution" => Target::Scalar(Scalar::Restitution),
            _ => element(key, config)?.unwrap_or(Target::Tree),
        };
        Ok(Param {
            key: key.to_string(),
            target,
        })
    }

    /// Whether `self` and `other` set the same quantity (one key under two names, Ω as a
    /// ratio and as a frequency, the mass ratio with m1 or m2 fixed), so that setting one
    /// overwrites the other.
    pub fn overlaps(&self, other: &Param) -> bool {
        use Scalar::{FrequencyHz, OmegaRatio};
        use Target::{MassRatio, MassRatioM2Fixed};
        match (self.target, other.target) {
            (Target::Tree, Target::Tree) => self.key == other.key,
            (Target::Scalar(OmegaRatio | FrequencyHz), Target::Scalar(OmegaRatio | FrequencyHz)) => true,
            (MassRatio | MassRatioM2Fixed, MassRatio | MassRatioM2Fixed) => true,
            (a, b) => a == b,
        }
    }

    /// The key, as given.
    pub fn key(&self) -> &str {
        &self.key
    }

    /// Whether the parameter is set in the document's types directly (not through the TOML
    /// tree).
    pub(super) fn is_typed(&self) -> bool {
        self.target != Target::Tree
    }

    /// Sets the parameter to `value` in `doc` and, to keep the tree the configuration records
    /// as its settings the same, in `table` (the key's entry only: the tree is not read).
    pub(super) fn set(&self, doc: &mut Document, table: &mut Table, value: f64) -> Result<(), ConfigError> {
        let osc = &mut doc.oscillator;
        match self.target {
            Target::Scalar(s) => {
                let e = &mut doc.excitation;
                let (section, name) = match s {
                    Scalar::OmegaRatio => {
                        (e.omega_ratio, e.frequency_hz) = (Some(value), None);
                        ("excitation", "omega_ratio")
                    }
                    Scalar::FrequencyHz => {
                        (e.omega_ratio, e.frequency_hz) = (None, Some(value));
                        ("excitation", "frequency_hz")
                    }
                    Scalar::Amplitude => {
                        e.amplitude = Some(value);
                        ("excitation", "amplitude")
                    }
                    Scalar::Restitution => {
                        osc.restitution = Some(value);
                        ("oscillator", "restitution")
                    }
                };
                let entries = section_mut(table, section)?;
                entries.insert(name.into(), Value::Float(value));
                if section == "excitation" {
                    // omega_ratio and frequency_hz exclude each other: the later one wins.
                    match name {
                        "omega_ratio" => entries.remove("frequency_hz"),
                        "frequency_hz" => entries.remove("omega_ratio"),
                        _ => None,
                    };
                }
                Ok(())
            }
            Target::MassRatio | Target::MassRatioM2Fixed => {
                let mut m = lenient_chain(doc).map_err(ConfigError::Param)?.masses;
                if self.target == Target::MassRatio {
                    m[1] = value * m[0];
                } else {
                    let m2 = m[1];
                    for (i, mi) in m.iter_mut().enumerate() {
                        if i != 1 {
                            *mi = m2 / value;
                        }
                    }
                }
                set_array(doc, table, Array::Masses, m)
            }
            Target::GapRatio => {
                let mut g = lenient_chain(doc).map_err(ConfigError::Param)?.gaps;
                g[1] = value * g[0];
                set_array(doc, table, Array::Gaps, g)
            }
            Target::Gap => {
                let n = lenient_chain(doc).map_err(ConfigError::Param)?.len();
                set_array(doc, table, Array::Gaps, vec![value; n.saturating_sub(1)])
            }
            Target::Element(array, i) => {
                let chain = lenient_chain(doc).map_err(ConfigError::Param)?;
                let mut values = match array {
                    Array::Masses => chain.masses,
                    Array::Stiffness => chain.stiffness,
                    Array::Damping => chain.damping,
                    Array::Gaps => chain.gaps,
                    Array::Forces if chain.forces.is_empty() => vec![0.0; chain.masses.len()],
                    Array::Forces => chain.forces,
                };
                let len = values.len();
                let slot = values
                    .get_mut(i)
                    .ok_or_else(|| out_of_range(&self.key, array, i, len))?;
                *slot = value;
                set_array(doc, table, array, values)
            }
            Target::Tree => Err(ConfigError::Malformed(format!(
                "`{}` is set through the configuration's tree",
                self.key
            ))),
        }
    }
}

/// The element target of `oscillator.<array>[i]`, checked against `config`'s chain; `None`
/// for any other key.
fn element(key: &str, config: &Config) -> Result<Option<Target>, ConfigError> {
    let Some(rest) = key.strip_prefix("oscillator.") else {
        return Ok(None);
    };
    let Some((name, index)) = rest.strip_suffix(']').and_then(|r| r.split_once('[')) else {
        return Ok(None);
    };
    let array = match name {
        "masses" => Array::Masses,
        "stiffness" => Array::Stiffness,
        "damping" => Array::Damping,
        "gaps" => Array::Gaps,
        "forces" => Array::Forces,
        _ => return Ok(None),
    };
    let Ok(i) = index.parse::<usize>() else {
        return Ok(None);
    };
    let n = config.chain().len();
    let len = if array == Array::Gaps {
        n.saturating_sub(1)
    } else {
        n
    };
    if i >= len {
        return Err(out_of_range(key, array, i, len));
    }
    Ok(Some(Target::Element(array, i)))
}

fn out_of_range(key: &str, array: Array, i: usize, len: usize) -> ConfigError {
    ConfigError::Malformed(format!(
        "`{key}`: index {i} out of range (oscillator.{} has {len} entries)",
        array.name()
    ))
}

fn section_mut<'a>(table: &'a mut Table, section: &str) -> Result<&'a mut Table, ConfigError> {
    table
        .entry(section.to_string())
        .or_insert_with(|| Value::Table(Table::new()))
        .as_table_mut()
        .ok_or_else(|| ConfigError::Type {
            origin: format!("`{section}`"),
            message: "must be a table".into(),
        })
}

/// Sets the `[oscillator]` array `array` to `values` in the document and the tree.
fn set_array(
    doc: &mut Document,
    table: &mut Table,
    array: Array,
    values: Vec<f64>,
) -> Result<(), ConfigError> {
    section_mut(table, "oscillator")?.insert(
        array.name().into(),
        Value::Array(values.iter().copied().map(Value::Float).collect()),
    );
    let o = &mut doc.oscillator;
    match array {
        Array::Masses => o.masses = Some(values),
        Array::Stiffness => o.stiffness = Some(PerMass::Many(values)),
        Array::Damping => o.damping = Some(PerMass::Many(values)),
        Array::Gaps => o.gaps = Some(PerMass::Many(values)),
        Array::Forces => o.forces = Some(PerMass::Many(values)),
    }
    Ok(())
}
