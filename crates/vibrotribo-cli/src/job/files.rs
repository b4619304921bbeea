//! What a grid job's files hold: the point columns, and the width of a finished file.

use std::path::Path;

use anyhow::{Context, Result};

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

/// The number of columns of the CSV file `path` (from its header).
pub fn header_len(path: &Path) -> Result<usize> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    Ok(text.lines().next().unwrap_or("").split(',').count())
}
