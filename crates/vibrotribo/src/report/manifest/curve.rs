//! `curve.json`, the manifest of `vibrotribo curve`: the settings of a bifurcation curve and
//! what it found.

use serde::{Deserialize, Serialize};

use super::Kind;

/// `curve.json`: the settings of a curve and what it found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CurveManifest {
    /// Always [`Kind::Curve`].
    pub command: Kind,
    /// `fold`, `period_doubling`, `neimark_sacker` or `grazing`.
    pub kind: String,
    /// The first key, canonical.
    pub param: String,
    /// The value the bifurcation was searched near.
    pub near: f64,
    /// The second key, canonical.
    pub param2: String,
    /// The second key's range.
    pub from2: f64,
    /// The second key's range.
    pub to2: f64,
    /// Period of the orbits, in excitation periods.
    pub period: u32,
    /// Grazing curves: the contact, 1-based.
    pub contact: Option<usize>,
    /// Where the bifurcation was located on the branch at `from2`.
    pub located: f64,
    /// The width of that location's bracket.
    pub located_precision: f64,
    /// Points on the curve.
    pub points: usize,
    /// Why the curve ended.
    pub end: String,
    /// The codimension-two points (also in codim2.csv).
    pub codim2: Vec<Codim2Record>,
    /// Search window, relative.
    pub window: f64,
    /// Transient periods at `near`.
    pub transient_periods: u32,
    /// Most points.
    pub max_points: usize,
    /// Whether the power was left out.
    pub mechanics_only: bool,
    /// The configuration.
    pub settings: serde_json::Value,
    /// The program's version.
    pub vibrotribo_version: String,
}

/// One codimension-two point in `curve.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Codim2Record {
    /// `grazing`, `sequence_change` or `meets_KIND`.
    pub kind: String,
    /// The first parameter.
    pub param: f64,
    /// The second parameter.
    pub param2: f64,
    /// Width of the bracket, scaled parameters.
    pub precision: f64,
    /// Grazing: the contact, 1-based.
    pub contact: Option<usize>,
    /// Multipliers as [re, im].
    pub multipliers: Vec<[f64; 2]>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `curve.json` as the program wrote it (its settings emptied) reads and writes back
    /// byte for byte, and its command is the kind's.
    #[test]
    fn curve_manifest_round_trips_byte_for_byte() {
        let text = r#"{"command":"curve","kind":"period_doubling","param":"excitation.omega_ratio","near":2.45,"param2":"oscillator.stops.upper.gap","from2":0.001,"to2":0.0012,"period":1,"contact":null,"located":2.456810787299044,"located_precision":3.3549777101757677e-32,"points":5,"end":"point limit reached","codim2":[{"kind":"grazing","param":2.5,"param2":0.0011,"precision":1e-9,"contact":2,"multipliers":[[-1.0,0.0],[0.5,0.25]]}],"window":0.05,"transient_periods":200,"max_points":5,"mechanics_only":true,"settings":{},"vibrotribo_version":"0.1.0"}"#;
        let m: CurveManifest = serde_json::from_str(text).expect("a curve manifest");
        assert_eq!(m.command, Kind::Curve);
        assert_eq!(m.codim2[0].contact, Some(2));
        assert_eq!(serde_json::to_string(&m).expect("serialises"), text);
    }
}
