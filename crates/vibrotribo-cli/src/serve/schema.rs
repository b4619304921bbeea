//! The configuration schema the page builds its parameter fields from: every key of the
//! library's configuration reference with its unit, allowed values, default and its value in
//! the server's configuration.

use serde::Serialize;
use vibrotribo::config::{Allowed, Config, KEY_DOCS, default_values};

/// One key of the schema.
#[derive(Debug, Serialize)]
pub struct KeyInfo {
    /// The key, `section.name`.
    pub key: &'static str,
    /// Its unit (`"—"` when dimensionless).
    pub unit: &'static str,
    /// The allowed values, in words.
    pub allowed: String,
    /// The choices of a key that takes one of a few strings.
    pub choices: Vec<&'static str>,
    /// The default in the paper's default case, as TOML writes it (absent: `absent`).
    pub default: Option<String>,
    /// What an absent value means.
    pub absent: &'static str,
    /// The value in the server's configuration (as given there, or the default).
    pub value: Option<String>,
    /// Whether the server's configuration gives the key itself.
    pub given: bool,
    /// What the key means.
    pub meaning: &'static str,
}

/// What `GET /api/schema` answers.
#[derive(Debug, Serialize)]
pub struct Schema {
    /// The configuration file the server was started with (`None`: the paper's default case).
    pub config: Option<String>,
    /// The `--set` overrides the server was started with.
    pub set: Vec<String>,
    /// Every key, in the reference's order.
    pub keys: Vec<KeyInfo>,
}

/// The text of a TOML value as a field shows it (a string without its quotes).
fn shown(value: &toml::Value) -> String {
    match value {
        toml::Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

/// The value of the dotted `key` in `config`'s tree, if the tree gives it.
fn given(config: &Config, key: &str) -> Option<String> {
    let mut parts = key.split('.');
    let mut value = config.table().get(parts.next()?)?;
    for part in parts {
        value = value.get(part)?;
    }
    Some(shown(value))
}

/// The schema for a server whose configuration is `config` (read from `path`, with `set`).
pub fn schema(config: &Config, path: Option<String>, set: Vec<String>) -> Schema {
    let defaults = default_values();
    let keys = KEY_DOCS
        .iter()
        .map(|d| {
            let default = defaults
                .iter()
                .find(|(k, _)| k == d.key)
                .and_then(|(_, v)| v.clone())
                .map(|v| v.trim_matches('"').to_string());
            let own = given(config, d.key);
            KeyInfo {
                key: d.key,
                unit: d.unit,
                allowed: d.allowed.describe(),
                choices: match d.allowed {
                    Allowed::OneOf(names) => names.to_vec(),
                    _ => Vec::new(),
                },
                given: own.is_some(),
                value: own.or_else(|| default.clone()),
                default,
                absent: d.absent,
                meaning: d.meaning,
            }
        })
        .collect();
    Schema {
        config: path,
        set,
        keys,
    }
}
