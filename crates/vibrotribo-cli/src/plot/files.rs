//! A figure written in both formats.

use std::path::Path;

use anyhow::Result;

/// Writes `name.png` and `name.svg` in `dir` with `draw`.
pub fn both(dir: &Path, name: &str, draw: impl Fn(&Path) -> Result<()>) -> Result<()> {
    for ext in ["png", "svg"] {
        draw(&dir.join(format!("{name}.{ext}")))?;
    }
    Ok(())
}
