//! A figure written in both formats.

use std::path::Path;

use anyhow::Result;

use super::xy::NothingToDraw;

/// Writes `name.png` and `name.svg` in `dir` with `draw`; a figure with nothing to draw
/// ([`NothingToDraw`]) is skipped with a note on standard output.
pub fn both(dir: &Path, name: &str, draw: impl Fn(&Path) -> Result<()>) -> Result<()> {
    for ext in ["png", "svg"] {
        if let Err(e) = draw(&dir.join(format!("{name}.{ext}"))) {
            if let Some(nothing) = e.downcast_ref::<NothingToDraw>() {
                println!("  skipped {name}: {nothing}");
                return Ok(());
            }
            return Err(e);
        }
    }
    Ok(())
}
