//! What an output directory holds: its [`Kind`], told by the `command` of its manifest.

use std::path::Path;

use anyhow::{Result, bail};
use serde::Deserialize;
use vibrotribo::report::manifest::Kind;

use super::read;

/// The kind field every manifest opens with.
#[derive(Debug, Deserialize)]
struct Head {
    command: Option<Kind>,
}

/// What `dir` holds, from the `command` of its manifest (`None`: no vibrotribo results). A
/// manifest whose command disagrees with its file name is an error, and so is one without a
/// command unless an earlier version of the program wrote that manifest without one.
pub fn kind_of(dir: &Path) -> Result<Option<Kind>> {
    for (own, file, unnamed_beside) in Kind::searched() {
        let path = dir.join(file);
        if !path.exists() {
            continue;
        }
        let head: Head = read(&path)?;
        match (head.command, unnamed_beside) {
            (Some(kind), _) if kind == own => return Ok(Some(kind)),
            (Some(kind), _) => bail!(
                "{} names the command {kind:?}, not the one that writes {}",
                path.display(),
                file
            ),
            (None, Some(beside)) if dir.join(beside).exists() => return Ok(Some(own)),
            (None, Some(_)) => continue,
            (None, None) => bail!(
                "{} names no command: it is not a vibrotribo manifest",
                path.display()
            ),
        }
    }
    Ok(None)
}

/// The kind of the job whose first shard is `first`, for `merge`.
pub fn shard_kind(first: &Path) -> Result<Kind> {
    match kind_of(first)? {
        Some(kind @ (Kind::Sweep | Kind::Map | Kind::Basins)) => Ok(kind),
        _ => bail!(
            "{} holds no shard of a sweep, map or basins job (no sweep.json, map.json or basins.json)",
            first.display()
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_directory_is_told_by_its_manifests_command() {
        let dir = tempfile::tempdir().expect("a temporary directory");
        assert_eq!(kind_of(dir.path()).expect("readable"), None);
        std::fs::write(dir.path().join("map.json"), r#"{"command":"map","x":{}}"#).expect("written");
        assert_eq!(kind_of(dir.path()).expect("readable"), Some(Kind::Map));
        // A file name that disagrees with its command, or no command at all, is refused.
        std::fs::write(dir.path().join("map.json"), r#"{"command":"sweep"}"#).expect("written");
        let e = kind_of(dir.path()).expect_err("a sweep manifest named map.json");
        assert!(e.to_string().contains("map.json"), "{e}");
        std::fs::write(dir.path().join("map.json"), r#"{"x":1}"#).expect("written");
        assert!(kind_of(dir.path()).is_err());
    }

    /// summary.json, lyapunov.json and curve.json name their command; a summary.json without
    /// one (as earlier versions wrote it) still tells a simulate directory when its
    /// trajectory.csv is beside it, and nothing otherwise.
    #[test]
    fn every_manifest_names_its_command_and_older_ones_are_still_read() {
        for (file, text, kind) in [
            (
                "summary.json",
                r#"{"command":"simulate","periods":1}"#,
                Kind::Simulate,
            ),
            ("lyapunov.json", r#"{"command":"lyapunov"}"#, Kind::Lyapunov),
            ("curve.json", r#"{"command":"curve"}"#, Kind::Curve),
            ("load_sweep.json", r#"{"command":"load-sweep"}"#, Kind::LoadSweep),
            (
                "fit.json",
                r#"{"command":"optimize-mass-ratio"}"#,
                Kind::OptimizeMassRatio,
            ),
        ] {
            let dir = tempfile::tempdir().expect("a temporary directory");
            std::fs::write(dir.path().join(file), text).expect("written");
            assert_eq!(kind_of(dir.path()).expect("readable"), Some(kind), "{file}");
            assert_eq!(kind.manifest(), file);
        }
        let dir = tempfile::tempdir().expect("a temporary directory");
        std::fs::write(dir.path().join("summary.json"), r#"{"periods":1}"#).expect("written");
        assert_eq!(kind_of(dir.path()).expect("readable"), None);
        std::fs::write(dir.path().join("trajectory.csv"), "t_s\n").expect("written");
        assert_eq!(kind_of(dir.path()).expect("readable"), Some(Kind::Simulate));
        std::fs::write(dir.path().join("summary.json"), r#"{"command":"lyapunov"}"#).expect("written");
        assert!(
            kind_of(dir.path()).is_err(),
            "a lyapunov manifest named summary.json"
        );
    }
}
