//! Configuration files: the TOML document (and overrides of its keys) read into the library's
//! own types.
//!
//! A file has the tables `[oscillator]` and `[excitation]` (the [`ChainParams`](crate::ChainParams),
//! with scalars broadcast over the chain and the frequency as `omega_ratio` or
//! `frequency_hz`), and `[run]`, `[options]`, `[harvester]`, `[electrical]`, which are
//! [`RunSettings`](crate::study::RunSettings), [`SimOptions`](crate::SimOptions),
//! [`HarvesterParams`](crate::electrical::HarvesterParams) and
//! [`ChargeOptions`](crate::electrical::ChargeOptions) deserialised directly: every field of
//! those types is a key, and unknown keys are refused. [`Config`] reads a file, applies
//! overrides ([`Config::set`], [`apply_overrides`]) including the derived keys of
//! [`DERIVED_KEYS`], validates everything, and names the key at fault in every error
//! (the library's field names mapped to keys, `masses[1]` → `oscillator.masses[1]`). A
//! [`Param`] is a key resolved once, which the points of a sweep set directly
//! ([`Config::with_values`]). [`reference_markdown`] writes every key with its unit, default
//! and allowed values (the user guide's configuration reference).

mod document;
mod error;
mod excitation;
mod keys;
mod param;
mod reference;

pub use document::Config;
pub use error::ConfigError;
pub use excitation::{DEFAULT_SPLINE_TOLERANCE, MAX_HARMONICS};
pub use keys::{
    DERIVED_KEYS, apply_overrides, did_you_mean, known_keys, parse_override, parse_value, similar_keys,
};
pub use param::Param;
pub use reference::{
    Allowed, KEY_DOCS, KeyDoc, default_values, reference_markdown, stale_entries, undocumented_keys,
};
