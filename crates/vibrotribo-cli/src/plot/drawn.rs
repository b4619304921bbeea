//! The pictures a command drew: every file [`write`](super::xy) finishes is recorded, and
//! the command lists them when it ends ([`report`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The files drawn by this process, in the order they were written.
static DRAWN: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Records that `path` was written.
pub(super) fn record(path: &Path) {
    if let Ok(mut drawn) = DRAWN.lock() {
        drawn.push(path.to_path_buf());
    }
}

/// Takes the list of the files drawn so far (the list is empty afterwards).
pub fn take() -> Vec<PathBuf> {
    DRAWN
        .lock()
        .map(|mut d| std::mem::take(&mut *d))
        .unwrap_or_default()
}

/// The lines that tell what was drawn: per directory, the pictures' names without their
/// extension, with the extensions written (`drew 3 pictures in out/: a, b, c (.png, .svg)`).
/// Long lists are shortened to their first names and a count.
pub fn summary(files: &[PathBuf]) -> Vec<String> {
    let mut by_dir: BTreeMap<PathBuf, (Vec<String>, Vec<String>)> = BTreeMap::new();
    for f in files {
        let dir = f.parent().map(Path::to_path_buf).unwrap_or_default();
        let (stems, exts) = by_dir.entry(dir).or_default();
        let stem = f
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let ext = f
            .extension()
            .map(|e| format!(".{}", e.to_string_lossy()))
            .unwrap_or_default();
        if !stems.contains(&stem) {
            stems.push(stem);
        }
        if !exts.contains(&ext) {
            exts.push(ext);
        }
    }
    const SHOWN: usize = 24;
    by_dir
        .into_iter()
        .map(|(dir, (stems, exts))| {
            let n = stems.len();
            let mut names = stems.iter().take(SHOWN).cloned().collect::<Vec<_>>().join(", ");
            if n > SHOWN {
                names.push_str(&format!(", … ({} more)", n - SHOWN));
            }
            format!(
                "  drew {n} picture{} in {}: {names} ({})",
                if n == 1 { "" } else { "s" },
                dir.display(),
                exts.join(", ")
            )
        })
        .collect()
}

/// Prints what [`take`] returns, one line per directory (nothing if nothing was drawn).
pub fn report() {
    for line in summary(&take()) {
        println!("{line}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_groups_by_directory_and_extension() {
        let files: Vec<PathBuf> = [
            "out/a.png",
            "out/a.svg",
            "out/b.png",
            "out/b.svg",
            "out/sub/c.png",
        ]
        .iter()
        .map(PathBuf::from)
        .collect();
        assert_eq!(
            summary(&files),
            vec![
                "  drew 2 pictures in out: a, b (.png, .svg)".to_string(),
                "  drew 1 picture in out/sub: c (.png)".to_string(),
            ]
        );
        let many: Vec<PathBuf> = (0..30).map(|i| PathBuf::from(format!("d/p{i:02}.png"))).collect();
        let line = &summary(&many)[0];
        assert!(line.starts_with("  drew 30 pictures in d: p00, p01"), "{line}");
        assert!(line.contains("p23, … (6 more)"), "{line}");
    }
}
