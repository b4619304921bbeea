//! Keys: setting one (plain, indexed or derived), the list of keys the schema has, and the
//! mapping from the library's field names to keys.

use serde::de::{self, Deserializer, Visitor};
use serde::{Deserialize, Serialize};
use toml::{Table, Value};

use super::document::{Config, Document, lenient_chain};
use super::error::ConfigError;
use crate::model::ChainParams;

/// Derived scalar keys usable in overrides and sweeps, with what they change.
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

/// A number or an array of numbers (`stiffness = 120.0` means 120 N/m for every mass).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub(super) enum PerMass {
    /// One value for every entry.
    One(f64),
    /// One value per entry.
    Many(Vec<f64>),
}

impl<'de> Deserialize<'de> for PerMass {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = PerMass;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or an array of numbers")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<PerMass, E> {
                Ok(PerMass::One(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<PerMass, E> {
                Ok(PerMass::One(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<PerMass, E> {
                Ok(PerMass::One(v as f64))
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, mut seq: A) -> Result<PerMass, A::Error> {
                let mut out = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    out.push(x);
                }
                Ok(PerMass::Many(out))
            }
        }
        d.deserialize_any(V)
    }
}

impl PerMass {
    pub(super) fn expand(&self, n: usize) -> Vec<f64> {
        match self {
            PerMass::One(x) => vec![*x; n],
            PerMass::Many(v) => v.clone(),
        }
    }
}

/// The paper's chain ([`ChainParams::default`]) with its stiffness and damping repeated for
/// `n` masses and its spacing for the `n − 1` gaps: the defaults of `[oscillator]`.
pub(super) fn default_chain(n: usize) -> ChainParams {
    let paper = ChainParams::default();
    ChainParams {
        stiffness: vec![paper.stiffness[0]; n],
        damping: vec![paper.damping[0]; n],
        gaps: vec![paper.gaps[0]; n.saturating_sub(1)],
        ..paper
    }
}

/// The key of a [`ChainParams`] field path (`masses[1]` → `oscillator.masses[1]`).
pub(super) fn chain_key(name: &str) -> Option<String> {
    [
        "masses",
        "stiffness",
        "damping",
        "gaps",
        "restitution",
        "stops",
        "forces",
    ]
    .iter()
    .any(|f| name.starts_with(f))
    .then(|| format!("oscillator.{name}"))
}

/// The key of a [`ChainState`](crate::ChainState) field path (`positions[1]` →
/// `run.initial_positions[1]`).
pub(super) fn state_key(name: &str) -> Option<String> {
    Some(format!("run.initial_{name}"))
}

/// Every key of the configuration schema, `section.name`, in the order of the types.
pub fn known_keys() -> Vec<String> {
    // Serialised with every optional table present: JSON keeps `None` as null, so every
    // field of the types appears.
    let doc = Document {
        harvester: Some(Default::default()),
        ..Document::default()
    };
    let value = serde_json::to_value(&doc).expect("the schema serialises");
    let mut keys = Vec::new();
    if let Some(sections) = value.as_object() {
        for (section, table) in sections {
            if let Some(fields) = table.as_object() {
                keys.extend(fields.keys().map(|k| format!("{section}.{k}")));
            }
            if section == "oscillator" {
                // The stops' keys (absent from an empty `Stops` when serialised).
                for side in ["upper", "lower"] {
                    keys.extend(STOP_FIELDS.iter().map(|f| format!("oscillator.stops.{side}.{f}")));
                }
            }
        }
    }
    keys
}

/// The first key of `table` (`section.name`, `section.sub.name`, or a top-level name) that
/// the schema lacks.
pub(super) fn unknown_key_in(table: &Table) -> Option<String> {
    unknown_below("", table, &known_keys())
}

/// [`unknown_key_in`] for the keys of `table` under `prefix` (`""` or ending in `.`).
fn unknown_below(prefix: &str, table: &Table, known: &[String]) -> Option<String> {
    for (name, value) in table {
        let key = format!("{prefix}{name}");
        if known.contains(&key) {
            continue;
        }
        let inner = format!("{key}.");
        let is_section = known.iter().any(|k| k.starts_with(&inner));
        match value {
            Value::Table(fields) if is_section => {
                if let Some(k) = unknown_below(&inner, fields, known) {
                    return Some(k);
                }
            }
            // A section given a value of the wrong kind is a type error, not an unknown key.
            _ if is_section => {}
            // An unknown table is named by its first key (`oscilator.masses`).
            Value::Table(fields) => {
                return Some(fields.keys().next().map_or(key.clone(), |n| format!("{key}.{n}")));
            }
            _ => return Some(key),
        }
    }
    None
}

pub(super) fn unknown(key: &str) -> ConfigError {
    let mut known = known_keys();
    known.extend(DERIVED_KEYS.iter().map(|(k, _)| k.to_string()));
    ConfigError::UnknownKey {
        key: key.to_string(),
        known: known.join(", "),
    }
}

/// Splits `a.b[2]` into (["a", "b"], Some(2)).
fn split_key(key: &str) -> Result<(Vec<&str>, Option<usize>), ConfigError> {
    let (path, index) = match key.find('[') {
        Some(open) => {
            let close = key
                .strip_suffix(']')
                .ok_or_else(|| indexed_key_not_last(key, open))?;
            let idx: usize = close[open + 1..].parse().map_err(|_| {
                ConfigError::Malformed(format!("key `{key}`: the index must be a non-negative integer"))
            })?;
            (&key[..open], Some(idx))
        }
        None => (key, None),
    };
    Ok((path.split('.').collect(), index))
}

/// The error of a key with an index `[i]` that does not end it: a field of one element of an
/// array of tables (`excitation.harmonics[0].amplitude`) cannot be set alone; such an array
/// is set whole. Keys without a closing `]` are named as such.
fn indexed_key_not_last(key: &str, open: usize) -> ConfigError {
    let Some(close) = key[open..].find(']').map(|c| open + c) else {
        return ConfigError::Malformed(format!("key `{key}`: missing closing `]`"));
    };
    let array = &key[..open];
    let example = if array == "excitation.harmonics" {
        "--set 'excitation.harmonics=[{amplitude = 0.001, ratio = 1.0}, {amplitude = 0.0005, ratio = 2.0}]'"
            .to_string()
    } else {
        format!("--set '{array}=[...]'")
    };
    ConfigError::Malformed(format!(
        "key `{key}`: an index selects one number of an array of numbers and must end the key \
         (`oscillator.gaps[1]`); `{}` after `{}` is not supported: set the array `{array}` whole, e.g. {example}",
        &key[close + 1..],
        &key[..=close],
    ))
}

fn number(value: &Value, key: &str) -> Result<f64, ConfigError> {
    match value {
        Value::Float(x) => Ok(*x),
        Value::Integer(i) => Ok(*i as f64),
        other => Err(ConfigError::Type {
            origin: format!("`{key}`"),
            message: format!("needs a number, got {other}"),
        }),
    }
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

fn set_array(table: &mut Table, section: &str, name: &str, values: Vec<f64>) -> Result<(), ConfigError> {
    section_mut(table, section)?.insert(
        name.to_string(),
        Value::Array(values.into_iter().map(Value::Float).collect()),
    );
    Ok(())
}

/// The tree read leniently: the types checked, nothing validated (so that one element of an
/// array can be set while another key is still to be set).
fn read(table: &Table) -> Result<(Document, ChainParams), ConfigError> {
    let doc: Document = Value::Table(table.clone())
        .try_into()
        .map_err(|e: toml::de::Error| ConfigError::Type {
            origin: "invalid configuration".into(),
            message: e.message().trim().to_string(),
        })?;
    let chain = lenient_chain(&doc).map_err(ConfigError::Param)?;
    Ok((doc, chain))
}

/// The current value of an array key (defaults and broadcasting applied), so that one
/// element of it can be set.
fn current_array(table: &Table, section: &str, name: &str) -> Result<Option<Vec<f64>>, ConfigError> {
    let (doc, chain) = read(table)?;
    let n = chain.len();
    let h = doc.harvester.unwrap_or_default();
    Ok(Some(match (section, name) {
        ("oscillator", "masses") => chain.masses,
        ("oscillator", "stiffness") => chain.stiffness,
        ("oscillator", "damping") => chain.damping,
        ("oscillator", "gaps") => chain.gaps,
        ("oscillator", "forces") if chain.forces.is_empty() => vec![0.0; n],
        ("oscillator", "forces") => chain.forces,
        ("run", "initial_positions") => doc.run.initial_positions.unwrap_or(vec![0.0; n]),
        ("run", "initial_velocities") => doc.run.initial_velocities.unwrap_or(vec![0.0; n]),
        ("harvester", "dielectric_thickness") => h.dielectric_thickness.to_vec(),
        ("harvester", "relative_permittivity") => h.relative_permittivity.to_vec(),
        _ => return Ok(None),
    }))
}

/// Sets `key` in `table` (see [`Config::set`]).
pub(super) fn set_key(table: &mut Table, key: &str, value: Value) -> Result<(), ConfigError> {
    let chain = || read(table).map(|(_, c)| c);
    match key {
        "mass_ratio" => {
            let r = number(&value, key)?;
            let mut m = chain()?.masses;
            if m.len() < 2 {
                return Err(ConfigError::Malformed(
                    "mass_ratio needs at least 2 masses".into(),
                ));
            }
            m[1] = r * m[0];
            set_array(table, "oscillator", "masses", m)
        }
        "mass_ratio_m2_fixed" => {
            let r = number(&value, key)?;
            let mut m = chain()?.masses;
            if m.len() < 2 {
                return Err(ConfigError::Malformed(
                    "mass_ratio_m2_fixed needs at least 2 masses".into(),
                ));
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
            let mut g = chain()?.gaps;
            if g.len() < 2 {
                return Err(ConfigError::Malformed(
                    "gap_ratio needs at least 2 gaps (3 masses)".into(),
                ));
            }
            g[1] = r * g[0];
            set_array(table, "oscillator", "gaps", g)
        }
        "gap" => {
            let d = number(&value, key)?;
            let n = chain()?.len();
            set_array(table, "oscillator", "gaps", vec![d; n.saturating_sub(1)])
        }
        "omega_ratio" | "frequency_hz" | "amplitude" => set_key(table, &format!("excitation.{key}"), value),
        "restitution" => set_key(table, "oscillator.restitution", value),
        _ => set_path(table, key, value),
    }
}

/// The fields of a stop's table, `[oscillator.stops.upper]` / `[oscillator.stops.lower]`.
const STOP_FIELDS: [&str; 3] = ["gap", "restitution", "frame"];

fn set_path(table: &mut Table, key: &str, value: Value) -> Result<(), ConfigError> {
    let (path, index) = split_key(key)?;
    let plain = path.join(".");
    if let ["oscillator", "stops", side, field] = path[..] {
        if index.is_some() || !known_keys().contains(&plain) {
            return Err(unknown(key));
        }
        let stops = section_mut(table, "oscillator")?
            .entry("stops")
            .or_insert_with(|| Value::Table(Table::new()));
        let Value::Table(stops) = stops else {
            return Err(ConfigError::Malformed(
                "`oscillator.stops` must be a table".into(),
            ));
        };
        let stop = stops.entry(side).or_insert_with(|| Value::Table(Table::new()));
        let Value::Table(stop) = stop else {
            return Err(ConfigError::Malformed(format!(
                "`oscillator.stops.{side}` must be a table"
            )));
        };
        stop.insert(field.to_string(), value);
        return Ok(());
    }
    if path.len() != 2 || !known_keys().contains(&plain) {
        return Err(unknown(key));
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
            let mut values = current_array(table, section, name)?.ok_or_else(|| {
                ConfigError::Malformed(format!(
                    "`{plain}` is not an array parameter: `{key}` has no meaning"
                ))
            })?;
            let len = values.len();
            let slot = values.get_mut(i).ok_or_else(|| {
                ConfigError::Malformed(format!(
                    "`{key}`: index {i} out of range ({plain} has {len} entries)"
                ))
            })?;
            *slot = number(&value, key)?;
            set_array(table, section, name, values)
        }
    }
}

/// Parses the right-hand side of an override: any TOML value (`0.7`, `[1, 2]`, `"exact"`),
/// or a bare word as a string (`harvester.load=rectifier`).
pub fn parse_value(text: &str) -> Value {
    let doc = format!("v = {text}");
    match toml::from_str::<Table>(&doc) {
        Ok(mut t) => t.remove("v").unwrap_or(Value::String(text.to_string())),
        Err(_) => Value::String(text.to_string()),
    }
}

/// Splits a `key=value` override (the command line's `--set`) into the key and its value.
pub fn parse_override(assignment: &str) -> Result<(&str, Value), ConfigError> {
    let (key, value) = assignment.split_once('=').ok_or_else(|| {
        ConfigError::Malformed(format!(
            "{assignment:?}: expected key=value, e.g. excitation.omega_ratio=0.75"
        ))
    })?;
    Ok((key.trim(), parse_value(value.trim())))
}

/// Applies `key=value` overrides in order to `config`, which is read again once they are
/// all set ([`Config::set_all`]).
pub fn apply_overrides<S: AsRef<str>>(config: &mut Config, assignments: &[S]) -> Result<(), ConfigError> {
    let parsed = assignments
        .iter()
        .map(|a| parse_override(a.as_ref()))
        .collect::<Result<Vec<_>, _>>()?;
    config.set_all(parsed)
}

/// The keys (of the schema and derived) closest to `key`, best first: the "did you mean" of
/// an unknown key (at most three, none farther than a third of its length, and at least 2).
///
/// A key `section.name` is split at its last dot. A candidate's distance is the smallest of:
/// the edit distance between the whole keys; that between `key` and the candidate's name (a
/// key given without its section); 0 where the candidate ends with `.key` (a key given
/// without its leading sections); the distance between the names, or 1 where the given
/// name begins a candidate's (three letters or more: `f_low` for `f_low_hz`), plus 1 where
/// the sections differ. Ties go to the candidate whose section is closest (in edit
/// distance) to the given one, then to the longest prefix shared with `key`, then in
/// alphabetical order.
pub fn similar_keys(key: &str) -> Vec<String> {
    /// A candidate's rank, lowest first: its distance, its section's distance, and the
    /// length of the prefix it shares with `key` (longest first).
    type Rank = (usize, usize, std::cmp::Reverse<usize>);
    let mut known = known_keys();
    known.extend(DERIVED_KEYS.iter().map(|(k, _)| k.to_string()));
    let limit = (key.chars().count() / 3).max(2);
    let (section, name) = split_section(key);
    let mut scored: Vec<(Rank, String)> = known
        .into_iter()
        .filter_map(|k| {
            let (k_section, k_name) = split_section(&k);
            let moved = usize::from(!section.is_empty() && section != k_section);
            let by_name = if name.chars().count() >= 3 && k_name.starts_with(name) && name != k_name {
                1
            } else {
                edit_distance(name, k_name)
            };
            let mut d = edit_distance(key, &k).min(edit_distance(key, k_name));
            if k.strip_suffix(key).is_some_and(|head| head.ends_with('.')) {
                d = 0;
            }
            d = d.min(by_name + moved);
            let shared = key.chars().zip(k.chars()).take_while(|(a, b)| a == b).count();
            (d <= limit).then(|| {
                (
                    (d, edit_distance(section, k_section), std::cmp::Reverse(shared)),
                    k.clone(),
                )
            })
        })
        .collect();
    scored.sort();
    scored.into_iter().take(3).map(|(_, k)| k).collect()
}

/// `"; did you mean `a` or `b`?"` with the [`similar_keys`] of an unknown `key`, or nothing
/// where none is close: the hint the command line and Python give after "unknown parameter".
pub fn did_you_mean(key: &str) -> String {
    let similar = similar_keys(key);
    if similar.is_empty() {
        return String::new();
    }
    let names: Vec<String> = similar.iter().map(|k| format!("`{k}`")).collect();
    format!("; did you mean {}?", names.join(" or "))
}

/// `section.name` split at its last dot (`("", key)` without one).
fn split_section(key: &str) -> (&str, &str) {
    key.rsplit_once('.').unwrap_or(("", key))
}

/// The Levenshtein distance between `a` and `b` (in characters).
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut previous = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let substitution = previous + usize::from(ca != cb);
            previous = row[j + 1];
            row[j + 1] = substitution.min(row[j] + 1).min(previous + 1);
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn similar_keys_find_a_transposition_and_a_key_without_its_section() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(similar_keys("excitation.amplitdue")[0], "excitation.amplitude");
        assert!(similar_keys("omega_ratoi").contains(&"omega_ratio".to_string()));
        assert!(similar_keys("masses").contains(&"oscillator.masses".to_string()));
        assert!(similar_keys("completely_unrelated_words").is_empty());
    }

    /// Typos of real keys, each with the ranking a reader expects (checked against the key
    /// lists, not against the code's own order).
    #[test]
    fn typos_of_real_keys_rank_the_meant_key_first() {
        let first = |typo: &str| similar_keys(typo).into_iter().next().unwrap_or_default();
        // A transposition within a section.
        assert_eq!(first("excitation.amplitdue"), "excitation.amplitude");
        assert_eq!(first("oscillator.dampnig"), "oscillator.damping");
        // A misspelt section.
        assert_eq!(first("oscilator.masses"), "oscillator.masses");
        // A missing letter, and a name cut short: the completion in the same section wins
        // over a same-length neighbour (`rtol`).
        assert_eq!(first("run.period"), "run.periods");
        assert_eq!(first("electrical.atol"), "electrical.atol_voltage");
        assert_eq!(first("excitation.f_low"), "excitation.f_low_hz");
        // A key without its section, or without its leading sections.
        assert_eq!(first("stiffnes"), "oscillator.stiffness");
        assert_eq!(first("stops.upper.gap"), "oscillator.stops.upper.gap");
        // Equally close: the derived key named without a section before the one inside
        // `excitation` (alphabetical order put `excitation.omega_ratio` first).
        assert_eq!(
            similar_keys("omega_ratoi")[..2],
            ["omega_ratio".to_string(), "excitation.omega_ratio".to_string()]
        );
        // A key put in the wrong section: the same name elsewhere, the closest section first.
        let moved = similar_keys("harvester.restitution");
        assert_eq!(moved[0], "oscillator.restitution", "{moved:?}");
        assert!(moved.contains(&"restitution".to_string()), "{moved:?}");
        // The hint reads as a sentence.
        assert_eq!(did_you_mean("run.period"), "; did you mean `run.periods`?");
        assert_eq!(did_you_mean("completely_unrelated_words"), "");
    }
}
