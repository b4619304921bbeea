//! The `[excitation]` table read into an [`ExcitationSpec`]: which keys belong to which
//! kind, defaults, validation (every error names its key), and a record read from its file.

use std::path::PathBuf;
use std::sync::Arc;

use super::document::{Document, ExcitationTable, HarmonicEntry};
use super::error::ConfigError;
use crate::error::ParamError;
use crate::excitation::{
    Chirp, ExcitationKind, ExcitationSpec, Harmonic, Psd, RandomSpec, RecordScaling, RecordSpec, SignalError,
    Sweep, read_record, record_displacement,
};
use crate::model::ChainParams;

/// The most harmonics a multisine may have.
pub const MAX_HARMONICS: usize = 64;

/// The default `excitation.spline_tolerance` (relative).
pub const DEFAULT_SPLINE_TOLERANCE: f64 = 1e-9;

use ExcitationKind::{
    Chirp as K_CHIRP, Harmonic as K_HARMONIC, Multisine as K_MULTI, Random as K_RANDOM, Record as K_RECORD,
};

/// The kind-specific keys of `t` that are given, with the kinds they belong to.
fn given_keys(t: &ExcitationTable) -> Vec<(&'static str, &'static [ExcitationKind])> {
    let keys: [(&'static str, bool, &'static [ExcitationKind]); 17] = [
        ("amplitude", t.amplitude.is_some(), &[K_HARMONIC, K_CHIRP]),
        ("harmonics", t.harmonics.is_some(), &[K_MULTI]),
        ("f_start_hz", t.f_start_hz.is_some(), &[K_CHIRP]),
        ("f_end_hz", t.f_end_hz.is_some(), &[K_CHIRP]),
        ("sweep", t.sweep.is_some(), &[K_CHIRP]),
        ("duration_s", t.duration_s.is_some(), &[K_CHIRP, K_RANDOM]),
        (
            "spline_tolerance",
            t.spline_tolerance.is_some(),
            &[K_CHIRP, K_RANDOM],
        ),
        ("rms_acceleration", t.rms_acceleration.is_some(), &[K_RANDOM]),
        ("f_low_hz", t.f_low_hz.is_some(), &[K_RANDOM]),
        ("f_high_hz", t.f_high_hz.is_some(), &[K_RANDOM]),
        ("psd_frequencies_hz", t.psd_frequencies_hz.is_some(), &[K_RANDOM]),
        ("psd_values", t.psd_values.is_some(), &[K_RANDOM]),
        ("seed", t.seed.is_some(), &[K_RANDOM]),
        ("file", t.file.is_some(), &[K_RECORD]),
        ("quantity", t.quantity.is_some(), &[K_RECORD]),
        ("scale", t.scale.is_some(), &[K_RECORD]),
        ("peak_acceleration", t.peak_acceleration.is_some(), &[K_RECORD]),
    ];
    keys.into_iter()
        .filter(|(_, given, _)| *given)
        .map(|(k, _, kinds)| (k, kinds))
        .collect()
}

fn conflict(key: &str, message: String) -> ConfigError {
    ConfigError::Param(ParamError::Conflict {
        name: format!("excitation.{key}"),
        message,
    })
}

fn invalid(key: &str, value: f64, reason: &'static str) -> ConfigError {
    ConfigError::Param(ParamError::Invalid {
        name: format!("excitation.{key}"),
        value,
        reason,
    })
}

fn required<T: Copy>(value: Option<T>, key: &str, kind: ExcitationKind) -> Result<T, ConfigError> {
    value.ok_or_else(|| {
        conflict(
            key,
            format!("kind = \"{}\" needs excitation.{key}", kind.as_str()),
        )
    })
}

fn positive(value: f64, key: &str) -> Result<f64, ConfigError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(invalid(key, value, "must be finite and > 0"))
    }
}

fn non_negative(value: f64, key: &str) -> Result<f64, ConfigError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(invalid(key, value, "must be finite and ≥ 0"))
    }
}

/// A signal error in terms of the keys of `kind` (the record's errors name `excitation.file`).
pub(super) fn named(kind: ExcitationKind, e: SignalError) -> ConfigError {
    let key = if kind == K_RECORD { "file" } else { "kind" };
    conflict(key, format!("kind = \"{}\": {e}", kind.as_str()))
}

/// The `[excitation]` of `doc` (chain already read and valid) as an [`ExcitationSpec`];
/// `same_file` is one read before from the same `excitation.file`, whose record samples are
/// used instead of reading the file again.
pub(super) fn excitation_of(
    doc: &Document,
    chain: &ChainParams,
    same_file: Option<&ExcitationSpec>,
) -> Result<ExcitationSpec, ConfigError> {
    let t = &doc.excitation;
    let kind = t.kind.unwrap_or_default();
    for (key, kinds) in given_keys(t) {
        if !kinds.contains(&kind) {
            let of: Vec<String> = kinds.iter().map(|k| format!("\"{}\"", k.as_str())).collect();
            return Err(conflict(
                key,
                format!(
                    "a key of kind = {}, not of kind = \"{}\" (excitation.kind)",
                    of.join(" or "),
                    kind.as_str()
                ),
            ));
        }
    }
    let period = chain.period();
    let run_length = doc.run.periods as f64 * period;
    let run_text = format!(
        "the run lasts run.periods = {} periods of T = {period:.6} s = {run_length:.6} s (transient included)",
        doc.run.periods
    );
    let duration = |t: &ExcitationTable| -> Result<f64, ConfigError> {
        match t.duration_s {
            None => Ok(run_length),
            Some(d) => {
                positive(d, "duration_s")?;
                if d < run_length {
                    return Err(conflict(
                        "duration_s",
                        format!("{d} s is shorter than the run: {run_text}"),
                    ));
                }
                Ok(d)
            }
        }
    };
    let tolerance = t
        .spline_tolerance
        .map(|x| positive(x, "spline_tolerance"))
        .transpose()?
        .unwrap_or(DEFAULT_SPLINE_TOLERANCE);
    Ok(match kind {
        K_HARMONIC => ExcitationSpec::Harmonic,
        K_MULTI => {
            let entries = t.harmonics.as_ref().ok_or_else(|| {
                conflict(
                    "harmonics",
                    "kind = \"multisine\" needs excitation.harmonics".into(),
                )
            })?;
            if entries.is_empty() || entries.len() > MAX_HARMONICS {
                return Err(conflict(
                    "harmonics",
                    format!("{} harmonics: give 1 to {MAX_HARMONICS}", entries.len()),
                ));
            }
            let omega = chain.omega();
            let harmonics = entries
                .iter()
                .enumerate()
                .map(|(i, e)| harmonic_of(i, e, omega))
                .collect::<Result<Vec<_>, _>>()?;
            ExcitationSpec::Multisine(harmonics)
        }
        K_CHIRP => {
            let chirp = Chirp {
                amplitude: non_negative(t.amplitude.unwrap_or(chain.excitation.amplitude), "amplitude")?,
                f_start_hz: positive(required(t.f_start_hz, "f_start_hz", kind)?, "f_start_hz")?,
                f_end_hz: positive(required(t.f_end_hz, "f_end_hz", kind)?, "f_end_hz")?,
                duration: duration(t)?,
                sweep: t.sweep.unwrap_or(Sweep::Linear),
            };
            let tolerance = tolerance * chirp.amplitude;
            if chirp.amplitude > 0.0 {
                chirp
                    .intervals_needed(tolerance)
                    .map_err(|e| conflict("spline_tolerance", e.to_string()))?;
            }
            ExcitationSpec::Chirp {
                chirp,
                tolerance: if tolerance > 0.0 {
                    tolerance
                } else {
                    f64::MIN_POSITIVE
                },
            }
        }
        K_RANDOM => {
            let psd = match (&t.psd_frequencies_hz, &t.psd_values, t.rms_acceleration) {
                (None, None, Some(rms)) => Psd::Flat {
                    rms: non_negative(rms, "rms_acceleration")?,
                    f_low_hz: positive(required(t.f_low_hz, "f_low_hz", kind)?, "f_low_hz")?,
                    f_high_hz: positive(required(t.f_high_hz, "f_high_hz", kind)?, "f_high_hz")?,
                },
                (Some(f), Some(v), None) => {
                    for key in ["f_low_hz", "f_high_hz"] {
                        let given = if key == "f_low_hz" {
                            t.f_low_hz
                        } else {
                            t.f_high_hz
                        };
                        if given.is_some() {
                            return Err(conflict(
                                key,
                                "a PSD table sets its own band (its first and last frequency): give f_low_hz and f_high_hz only with rms_acceleration".into(),
                            ));
                        }
                    }
                    Psd::Table {
                        frequencies_hz: f.clone(),
                        values: v.clone(),
                    }
                }
                (_, _, Some(_)) => {
                    return Err(conflict(
                        "rms_acceleration",
                        "give either rms_acceleration (a flat PSD) or psd_frequencies_hz with psd_values (a table), not both".into(),
                    ));
                }
                (Some(_), None, None) => {
                    return Err(conflict(
                        "psd_values",
                        "psd_frequencies_hz needs psd_values".into(),
                    ));
                }
                (None, Some(_), None) => {
                    return Err(conflict(
                        "psd_frequencies_hz",
                        "psd_values needs psd_frequencies_hz".into(),
                    ));
                }
                (None, None, None) => {
                    return Err(conflict(
                        "rms_acceleration",
                        "kind = \"random\" needs excitation.rms_acceleration (with f_low_hz, f_high_hz) or psd_frequencies_hz and psd_values".into(),
                    ));
                }
            };
            let key = if matches!(psd, Psd::Flat { .. }) {
                "f_high_hz"
            } else {
                "psd_values"
            };
            psd.validate().map_err(|e| conflict(key, e.to_string()))?;
            let spec = RandomSpec {
                psd,
                seed: t.seed.unwrap_or(0),
                duration: duration(t)?,
            };
            spec.intervals_needed(tolerance)
                .map_err(|e| conflict(key, e.to_string()))?;
            ExcitationSpec::Random {
                spec,
                relative_tolerance: tolerance,
            }
        }
        K_RECORD => {
            let file = t.file.as_ref().ok_or_else(|| {
                conflict(
                    "file",
                    "kind = \"record\" needs excitation.file (a CSV file)".into(),
                )
            })?;
            let quantity = required(t.quantity, "quantity", kind)?;
            let scaling = match (t.scale, t.peak_acceleration) {
                (Some(_), Some(_)) => {
                    return Err(conflict(
                        "peak_acceleration",
                        "give either excitation.scale or excitation.peak_acceleration, not both".into(),
                    ));
                }
                (Some(s), None) => {
                    if !s.is_finite() {
                        return Err(invalid("scale", s, "must be finite"));
                    }
                    RecordScaling::Factor(s)
                }
                (None, Some(p)) => RecordScaling::PeakAcceleration(positive(p, "peak_acceleration")?),
                (None, None) => RecordScaling::Factor(1.0),
            };
            // Relative to the working directory; a file's own relative paths were resolved
            // against its directory when it was read (`Config::from_table_in`).
            let path = PathBuf::from(file);
            let before = match same_file {
                Some(ExcitationSpec::Record(r)) => Some(r),
                _ => None,
            };
            let samples = match before {
                Some(r) => Arc::clone(&r.samples),
                None => Arc::new(read_record(&path).map_err(|e| conflict("file", e.to_string()))?),
            };
            if samples.duration() < run_length {
                return Err(conflict(
                    "file",
                    format!(
                        "the record {} lasts {:.6} s, shorter than the run: {run_text}",
                        path.display(),
                        samples.duration()
                    ),
                ));
            }
            // Build once to report a record that cannot be scaled or integrated now (done
            // already if the record was read before with the same quantity and scaling).
            if !before.is_some_and(|r| r.quantity == quantity && r.scaling == scaling) {
                record_displacement(&samples, quantity, scaling)
                    .map_err(|e| conflict("file", e.to_string()))?;
            }
            ExcitationSpec::Record(RecordSpec {
                samples,
                quantity,
                scaling,
            })
        }
    })
}

/// Harmonic `i` of `excitation.harmonics`, its frequency resolved against the reference ω
/// (rad/s).
fn harmonic_of(i: usize, e: &HarmonicEntry, omega: f64) -> Result<Harmonic, ConfigError> {
    let key = |name: &str| format!("harmonics[{i}].{name}");
    let amplitude = e
        .amplitude
        .ok_or_else(|| conflict(&key("amplitude"), "each harmonic needs an amplitude, m".into()))?;
    let amplitude = non_negative(amplitude, &key("amplitude"))?;
    let omega = match (e.ratio, e.frequency_hz) {
        (Some(r), None) => positive(r, &key("ratio"))? * omega,
        (None, Some(f)) => positive(f, &key("frequency_hz"))? * std::f64::consts::TAU,
        _ => {
            return Err(conflict(
                &key("ratio"),
                "each harmonic needs exactly one of ratio (a multiple of the reference frequency) and frequency_hz".into(),
            ));
        }
    };
    let phase = e.phase.unwrap_or(0.0);
    if !phase.is_finite() {
        return Err(invalid(&key("phase"), phase, "must be finite"));
    }
    Ok(Harmonic {
        amplitude,
        omega,
        phase,
    })
}
