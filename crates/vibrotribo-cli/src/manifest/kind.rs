//! What an output directory holds ([`Kind`]): the command that wrote it, read from the
//! `command` of its manifest.

use std::path::Path;

use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};

use super::read;

/// What an output directory holds: the command that wrote it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// `vibrotribo sweep` (`sweep.json`).
    Sweep,
    /// `vibrotribo map` (`map.json`).
    Map,
    /// `vibrotribo basins` (`basins.json`).
    Basins,
    /// `vibrotribo attractors` (`attractors.json`).
    Attractors,
    /// `vibrotribo chirp` (`chirp.json`).
    Chirp,
    /// `vibrotribo continue` (`continue.json`).
    Continue,
    /// `vibrotribo curve` (`curve.json`).
    Curve,
    /// `vibrotribo lyapunov` (`lyapunov.json`).
    Lyapunov,
    /// `vibrotribo simulate` (`summary.json` beside `trajectory.csv`).
    Simulate,
    /// `vibrotribo load-sweep` (`load_sweep.json`).
    #[serde(rename = "load-sweep")]
    LoadSweep,
    /// `vibrotribo periodic` (`periodic.json`).
    Periodic,
    /// `vibrotribo optimize-mass-ratio` (`fit.json` beside `optimum.csv`).
    #[serde(rename = "optimize-mass-ratio")]
    OptimizeMassRatio,
    /// `vibrotribo optimize` (`optimize.json`).
    Optimize,
    /// `vibrotribo response` (`response.json`).
    Response,
    /// `vibrotribo band-response` (`band_response.json`).
    #[serde(rename = "band-response")]
    BandResponse,
    /// `vibrotribo bifmap` (`bifmap.json`).
    Bifmap,
}

/// A manifest file and the kind whose manifest it is.
struct Entry {
    kind: Kind,
    file: &'static str,
    /// For a manifest that earlier versions of the program wrote without a `command`: the
    /// file that sits beside it in such a directory (which tells it from a stray file of
    /// that name). `None`: a manifest without its `command` is an error.
    unnamed_beside: Option<&'static str>,
}

const fn entry(kind: Kind, file: &'static str, unnamed_beside: Option<&'static str>) -> Entry {
    Entry {
        kind,
        file,
        unnamed_beside,
    }
}

/// Every kind's manifest, in the order a directory is searched for them.
const MANIFESTS: &[Entry] = &[
    entry(Kind::Sweep, "sweep.json", None),
    entry(Kind::Map, "map.json", None),
    entry(Kind::Basins, "basins.json", None),
    entry(Kind::Attractors, "attractors.json", None),
    entry(Kind::Chirp, "chirp.json", None),
    entry(Kind::Continue, "continue.json", None),
    entry(Kind::Curve, "curve.json", None),
    entry(Kind::Response, "response.json", None),
    entry(Kind::BandResponse, "band_response.json", None),
    entry(Kind::Bifmap, "bifmap.json", None),
    entry(Kind::Lyapunov, "lyapunov.json", Some("lyapunov.json")),
    entry(Kind::LoadSweep, "load_sweep.json", Some("load_sweep.csv")),
    entry(Kind::Periodic, "periodic.json", Some("periodic.json")),
    entry(Kind::OptimizeMassRatio, "fit.json", Some("optimum.csv")),
    entry(Kind::Optimize, "optimize.json", Some("evaluations.jsonl")),
    entry(Kind::Simulate, "summary.json", Some("trajectory.csv")),
];

impl Kind {
    /// The file name of its manifest.
    pub fn manifest(self) -> &'static str {
        MANIFESTS.iter().find(|e| e.kind == self).map_or("", |e| e.file)
    }

    /// The manifest file names of every kind, for messages.
    pub fn manifests() -> impl Iterator<Item = &'static str> {
        MANIFESTS.iter().map(|e| e.file)
    }
}

/// The kind field every manifest opens with.
#[derive(Debug, Deserialize)]
struct Head {
    command: Option<Kind>,
}

/// What `dir` holds, from the `command` of its manifest (`None`: no vibrotribo results). A
/// manifest whose command disagrees with its file name is an error, and so is one without a
/// command unless an earlier version of the program wrote that manifest without one.
pub fn kind_of(dir: &Path) -> Result<Option<Kind>> {
    for e in MANIFESTS {
        let path = dir.join(e.file);
        if !path.exists() {
            continue;
        }
        let head: Head = read(&path)?;
        match (head.command, e.unnamed_beside) {
            (Some(kind), _) if kind == e.kind => return Ok(Some(kind)),
            (Some(kind), _) => bail!(
                "{} names the command {kind:?}, not the one that writes {}",
                path.display(),
                e.file
            ),
            (None, Some(beside)) if dir.join(beside).exists() => return Ok(Some(e.kind)),
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
