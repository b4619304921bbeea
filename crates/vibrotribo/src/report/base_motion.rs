//! The base motion of a run as the engine ran it, in (name, value) lines: the `base_motion`
//! object of `summary.json`, `sweep.json`, `map.json` and the other manifests, and the lines
//! the command line prints.

use std::fmt;

use serde::de::{MapAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::study::RunSpec;

/// What a run states about its base motion when it is not the chain's own `A sin ωt`: the
/// lines of [`base_motion_lines`] in their order, written as a JSON object of strings.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BaseMotionSummary {
    /// (name, value) in the order written.
    pub lines: Vec<(String, String)>,
}

impl BaseMotionSummary {
    /// The base motion of `spec`; `None` under the chain's own harmonic.
    pub fn of(spec: &RunSpec) -> Option<Self> {
        let lines = base_motion_lines(spec);
        (!lines.is_empty()).then_some(BaseMotionSummary { lines })
    }

    /// The value of line `name`.
    pub fn get(&self, name: &str) -> Option<&str> {
        self.lines
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }
}

impl Serialize for BaseMotionSummary {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(self.lines.len()))?;
        for (k, v) in &self.lines {
            map.serialize_entry(k, v)?;
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for BaseMotionSummary {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Lines;
        impl<'de> Visitor<'de> for Lines {
            type Value = BaseMotionSummary;
            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("an object of strings")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
                let mut lines = Vec::new();
                while let Some(entry) = map.next_entry::<String, String>()? {
                    lines.push(entry);
                }
                Ok(BaseMotionSummary { lines })
            }
        }
        d.deserialize_map(Lines)
    }
}

/// What a run of `spec` states about its base motion when it is not
/// the chain's own `A sin ωt` (empty then), as (name, value) lines: `kind`, `run_as` (how
/// the engine ran it), the lines of [`BaseMotion::summary`](crate::excitation::BaseMotion::summary)
/// (spline knots and error bounds, record scaling and baseline correction) and, for a
/// multisine or a random signal, what the engine ran on: `piece_degree`, `piece_intervals`,
/// `piece_displacement_error_bound_m`, `piece_velocity_error_bound_m_s`.
pub fn base_motion_lines(spec: &RunSpec) -> Vec<(String, String)> {
    use crate::excitation::BaseMotion;
    let Some(b) = &spec.base_motion else {
        return Vec::new();
    };
    let mut out = vec![("kind".to_string(), b.kind().as_str().to_string())];
    let on_pieces = "exact per-interval forces k_i y + c_i y' of degree-7 Chebyshev interpolants of the \
                     harmonics' displacement and velocity";
    let run_as = match &**b {
        BaseMotion::Harmonics(h) if crate::dynamics::as_chain_harmonic(h, &spec.chain).is_some() => {
            "the harmonic excitation A sin ωt (closed form)".to_string()
        }
        BaseMotion::Harmonics(h) => {
            // The pieces of a multisine are built for the run's length (as the engine does).
            let end = (spec.periods as f64 * spec.chain.period()).max(spec.chain.period());
            if let Ok(a) = crate::excitation::piece_accuracy(h, end, crate::dynamics::multisine_tolerance(h))
            {
                out.extend(crate::excitation::pieces_summary(&a));
            }
            on_pieces.to_string()
        }
        BaseMotion::Pieces(_) => on_pieces.to_string(),
        BaseMotion::Spline(_) => "exact per-interval cubic forces k_i y + c_i y' of the spline".to_string(),
    };
    out.push(("run_as".into(), run_as));
    out.extend(b.summary());
    out
}
