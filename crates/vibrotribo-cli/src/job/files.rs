//! What a grid job's manifest and files record: the point columns, the settling and base
//! motion written into a manifest, and what a finished directory's files say about its job.

use std::path::Path;

use anyhow::{Context, Result};
use serde_json::json;
use vibrotribo::study::{PointOptions, SettleMode};
use vibrotribo::sweep::PointColumns;

/// The point columns of a chain with `contacts` contacts
/// ([`ChainParams::contact_count`](vibrotribo::ChainParams::contact_count)).
pub fn point_columns(contacts: usize, floquet: bool, lyapunov: bool) -> PointColumns {
    PointColumns {
        contacts,
        floquet,
        lyapunov,
    }
}

/// Records the base motion of `config` in a manifest (`base_motion`, when it is not the
/// chain's own harmonic: kind, how it was run, spline accuracy, record scaling).
pub fn add_base_motion(settings: &mut serde_json::Value, config: &vibrotribo::config::Config) {
    if let Some(b) = vibrotribo::report::base_motion_json(config, &config.run_spec(true)) {
        settings["base_motion"] = b;
    }
}

/// Records the settling of `options` in a manifest (`sweep.json`, `map.json`): `settle`
/// (`auto` or `fixed`), and for `auto` `settle_cap_periods` and `settle_block_periods`.
pub fn add_settle_settings(settings: &mut serde_json::Value, options: &PointOptions) {
    settings["settle"] = json!(options.settle.as_str());
    if let SettleMode::Auto(a) = &options.settle {
        settings["settle_cap_periods"] = json!(a.cap_periods);
        settings["settle_block_periods"] = json!(a.block);
        settings["settle_newton"] = json!(a.shoot);
    }
}

/// Whether the job in `dir` (manifest `manifest`) has the Floquet column.
pub fn floquet_of(dir: &Path, manifest: &str) -> Result<bool> {
    Ok(crate::output::read_json(&dir.join(manifest))?["floquet"].as_bool() == Some(true))
}

/// The number of columns of the CSV file `path` (from its header).
pub fn header_len(path: &Path) -> Result<usize> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    Ok(text.lines().next().unwrap_or("").split(',').count())
}
