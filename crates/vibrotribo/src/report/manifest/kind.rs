//! What an output directory holds ([`Kind`]): the command that wrote it, named by the
//! `command` of its manifest, and the file name of each kind's manifest.

use serde::{Deserialize, Serialize};

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

    /// Every kind with its manifest's file name, in the order a directory is searched for
    /// them, and, for a manifest that earlier versions of the program wrote without a
    /// `command`, the file that sits beside it in such a directory (which tells it from a
    /// stray file of that name; `None`: a manifest without its `command` is not one).
    pub fn searched() -> impl Iterator<Item = (Kind, &'static str, Option<&'static str>)> {
        MANIFESTS.iter().map(|e| (e.kind, e.file, e.unnamed_beside))
    }
}
