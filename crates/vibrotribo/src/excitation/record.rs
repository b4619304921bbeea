//! Recorded base motion: reading a CSV record, and making it a C² displacement (exact double
//! integration with a baseline correction for acceleration records, a not-a-knot cubic
//! spline for displacement records).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};

use super::error::SignalError;
use super::spline::{EndCondition, PiecewiseCubic};

/// What a record's second column holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Quantity {
    /// Base displacement, m.
    Displacement,
    /// Base acceleration, m/s².
    Acceleration,
}

/// How a record's values are scaled before use.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum RecordScaling {
    /// Multiply every value by this factor (1: as recorded).
    Factor(f64),
    /// Scale so that the largest |acceleration| at the samples is this, m/s² (for a
    /// displacement record, the largest |y''| of its spline).
    PeakAcceleration(f64),
}

/// The samples of a record file: times shifted so that the first is 0 (the run's t = 0).
#[derive(Debug, Clone, PartialEq)]
pub struct RecordSamples {
    /// The file, as named.
    pub path: String,
    /// The header of the value column.
    pub value_column: String,
    /// The time of the first sample in the file, s (subtracted from `times`).
    pub time_offset: f64,
    /// Sample times from 0, s, strictly increasing (uneven spacing allowed).
    pub times: Vec<f64>,
    /// The values (m or m/s²), as in the file.
    pub values: Vec<f64>,
}

impl RecordSamples {
    /// The record's duration, s.
    pub fn duration(&self) -> f64 {
        self.times.last().copied().unwrap_or(0.0)
    }
}

/// The fewest samples a record may have.
pub const MIN_SAMPLES: usize = 4;

/// Reads a record: a CSV file with a header line whose first column is `time_s`, then one
/// sample a line (time s, value; further columns are ignored; blank lines are skipped).
/// Errors name the file and the line: a missing file, a bad header, a non-numeric,
/// NaN or infinite cell, times not strictly increasing, fewer than [`MIN_SAMPLES`] samples.
pub fn read_record(path: &Path) -> Result<RecordSamples, SignalError> {
    let shown = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| SignalError::Io {
        path: shown.clone(),
        message: e.to_string(),
    })?;
    count_read(path);
    parse_record(&text, &shown)
}

/// The record files this process has read ([`read_record`]), by canonical path, and how
/// many times each.
static READS: Mutex<BTreeMap<PathBuf, u64>> = Mutex::new(BTreeMap::new());

fn count_read(path: &Path) {
    let key = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    let mut reads = READS.lock().unwrap_or_else(PoisonError::into_inner);
    *reads.entry(key).or_insert(0) += 1;
}

/// How many times this process has read the record file `path` with [`read_record`] (paths
/// compared once made canonical; 0 for a file never read). A configuration reads its record
/// when it is read, once, and every run made of it (every point of a sweep, every check)
/// uses those samples: this count shows it.
pub fn record_reads(path: &Path) -> u64 {
    let key = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    let reads = READS.lock().unwrap_or_else(PoisonError::into_inner);
    reads.get(&key).copied().unwrap_or(0)
}

/// [`read_record`] on the text of a file named `path`.
pub fn parse_record(text: &str, path: &str) -> Result<RecordSamples, SignalError> {
    let at = |line: usize, message: String| SignalError::Record {
        path: path.to_string(),
        line,
        message,
    };
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l));
    let (_, header) = lines
        .next()
        .ok_or_else(|| at(1, "empty file: expected a header `time_s,<value>`".into()))?;
    let names: Vec<&str> = header
        .split(',')
        .map(|c| c.trim().trim_start_matches('\u{feff}'))
        .collect();
    if names.len() < 2 || names[0] != "time_s" {
        return Err(at(
            1,
            format!("bad header {header:?}: expected `time_s,<value>` (the first column named time_s)"),
        ));
    }
    let mut times: Vec<f64> = Vec::new();
    let mut values = Vec::new();
    for (line, text) in lines {
        if text.trim().is_empty() {
            continue;
        }
        let cells: Vec<&str> = text.split(',').map(str::trim).collect();
        if cells.len() < 2 {
            return Err(at(
                line,
                format!("expected 2 cells (time_s, {}), got {text:?}", names[1]),
            ));
        }
        let number = |i: usize| -> Result<f64, SignalError> {
            let x: f64 = cells[i]
                .parse()
                .map_err(|_| at(line, format!("{} = {:?} is not a number", names[i], cells[i])))?;
            if !x.is_finite() {
                return Err(at(line, format!("{} = {x} is not finite", names[i])));
            }
            Ok(x)
        };
        let (t, v) = (number(0)?, number(1)?);
        if let Some(&last) = times.last()
            && t <= last
        {
            let what = if t == last { "repeated" } else { "out of order" };
            return Err(at(
                line,
                format!(
                    "time_s = {t} is {what}: the previous sample is at {last} (times must increase strictly)"
                ),
            ));
        }
        times.push(t);
        values.push(v);
    }
    if times.len() < MIN_SAMPLES {
        return Err(SignalError::RecordWhole {
            path: path.to_string(),
            message: format!("{} samples, at least {MIN_SAMPLES} needed", times.len()),
        });
    }
    let offset = times[0];
    for t in &mut times {
        *t -= offset;
    }
    Ok(RecordSamples {
        path: path.to_string(),
        value_column: names[1].to_string(),
        time_offset: offset,
        times,
        values,
    })
}

/// The baseline correction of an acceleration record.
///
/// The record's piecewise-linear acceleration a(t) is integrated exactly from rest,
/// y_raw(0) = y_raw'(0) = 0; then the least-squares cubic q(t) of y_raw over the record
/// (L² on [0, L], L the duration) is subtracted: y = y_raw − q. So the displacement has no
/// mean, no linear, quadratic or cubic trend (it is orthogonal to the cubics), and is the
/// exact double integral of the corrected acceleration a − q'' (q'' linear in t, so the
/// corrected acceleration stays piecewise linear through the samples) from the initial
/// velocity −q'(0) and displacement −q(0).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BaselineCorrection {
    /// q''(0): the acceleration subtracted at the start, m/s².
    pub acceleration_offset: f64,
    /// q''': the slope of the subtracted acceleration, m/s³.
    pub acceleration_slope: f64,
    /// The largest |q''| over the record relative to the largest |a| of the (scaled) samples.
    pub relative_size: f64,
    /// The largest |q| at the samples: the drift removed from the displacement, m.
    pub removed_displacement: f64,
    /// The initial velocity of the corrected motion, −q'(0), m/s.
    pub initial_velocity: f64,
    /// The initial displacement of the corrected motion, −q(0), m.
    pub initial_displacement: f64,
}

/// What was done to a record.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct RecordReport {
    /// The factor the values were multiplied by.
    pub scale_factor: f64,
    /// The largest |y''| at the samples after scaling (and correction), m/s².
    pub peak_acceleration: f64,
    /// The baseline correction (acceleration records only).
    pub baseline: Option<BaselineCorrection>,
}

/// The C² base displacement of a record (times from 0): for an acceleration record the exact
/// double integral of its piecewise-linear acceleration with the baseline correction of
/// [`BaselineCorrection`]; for a displacement record its not-a-knot cubic spline (the
/// third derivative continuous at the second and last-but-one samples).
pub fn record_displacement(
    samples: &RecordSamples,
    quantity: Quantity,
    scaling: RecordScaling,
) -> Result<(PiecewiseCubic, RecordReport), SignalError> {
    let whole = |message: String| SignalError::RecordWhole {
        path: samples.path.clone(),
        message,
    };
    let t = &samples.times;
    let mut spline = match quantity {
        Quantity::Displacement => PiecewiseCubic::interpolate(t, &samples.values, EndCondition::NotAKnot)?,
        Quantity::Acceleration => {
            PiecewiseCubic::integrate_linear_acceleration(t, &samples.values, 0.0, 0.0)?
        }
    };
    let peak = peak_acceleration(&spline);
    let factor = match scaling {
        RecordScaling::Factor(f) => f,
        RecordScaling::PeakAcceleration(p) => {
            if peak == 0.0 {
                return Err(whole(
                    "the acceleration is zero throughout: it cannot be scaled to a peak".into(),
                ));
            }
            p / peak
        }
    };
    if !factor.is_finite() {
        return Err(whole(format!("scale factor {factor} is not finite")));
    }
    spline.scale(factor);
    let baseline =
        (quantity == Quantity::Acceleration).then(|| correct_baseline(&mut spline, peak * factor.abs()));
    Ok((
        spline.clone(),
        RecordReport {
            scale_factor: factor,
            peak_acceleration: peak_acceleration(&spline),
            baseline,
        },
    ))
}

/// The largest |y''| at the knots (y'' of a C² piecewise cubic is piecewise linear, so this
/// is its maximum), m/s².
fn peak_acceleration(s: &PiecewiseCubic) -> f64 {
    let peak = s
        .coefficients()
        .iter()
        .map(|c| (2.0 * c[2]).abs())
        .fold(0.0, f64::max);
    peak.max(s.acceleration(s.end()).abs())
}

/// Subtracts the L² least-squares cubic over the knots' span from `s` (see
/// [`BaselineCorrection`]); `peak` is the largest |a| before, m/s².
fn correct_baseline(s: &mut PiecewiseCubic, peak: f64) -> BaselineCorrection {
    let (t0, length) = (s.start(), s.end() - s.start());
    // Gauss–Legendre, 4 points on [-1, 1]: exact for the degree-6 products y·P_k.
    const X: [f64; 4] = [
        -0.861_136_311_594_052_6,
        -0.339_981_043_584_856_3,
        0.339_981_043_584_856_3,
        0.861_136_311_594_052_6,
    ];
    const W: [f64; 4] = [
        0.347_854_845_137_453_9,
        0.652_145_154_862_546_1,
        0.652_145_154_862_546_1,
        0.347_854_845_137_453_9,
    ];
    let shifted_legendre = |u: f64| {
        let x = 2.0 * u - 1.0;
        [
            1.0,
            x,
            0.5 * (3.0 * x * x - 1.0),
            0.5 * (5.0 * x * x * x - 3.0 * x),
        ]
    };
    let mut moments = [0.0f64; 4];
    for i in 0..s.intervals() {
        let (a, c) = s.piece(i);
        let h = s.knots()[i + 1] - a;
        for (x, w) in X.iter().zip(W) {
            let tau = 0.5 * h * (x + 1.0);
            let y = c[0] + tau * (c[1] + tau * (c[2] + tau * c[3]));
            let p = shifted_legendre((a + tau - t0) / length);
            for k in 0..4 {
                moments[k] += 0.5 * h * w * y * p[k];
            }
        }
    }
    let coef: [f64; 4] = std::array::from_fn(|k| (2 * k + 1) as f64 / length * moments[k]);
    // Σ c_k P_k(2u − 1) in powers of u.
    let b = [
        coef[0] - coef[1] + coef[2] - coef[3],
        2.0 * coef[1] - 6.0 * coef[2] + 12.0 * coef[3],
        6.0 * coef[2] - 30.0 * coef[3],
        20.0 * coef[3],
    ];
    let q = |u: f64| b[0] + u * (b[1] + u * (b[2] + u * b[3]));
    let removed = s
        .knots()
        .iter()
        .map(|&t| q((t - t0) / length).abs())
        .fold(0.0, f64::max);
    s.subtract_cubic(b, t0, length);
    let l2 = length * length;
    let offset = 2.0 * b[2] / l2;
    let slope = 6.0 * b[3] / (l2 * length);
    let largest = offset.abs().max((offset + slope * length).abs());
    BaselineCorrection {
        acceleration_offset: offset,
        acceleration_slope: slope,
        relative_size: if peak > 0.0 { largest / peak } else { 0.0 },
        removed_displacement: removed,
        initial_velocity: -b[1] / length,
        initial_displacement: -b[0],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse_record(text, "r.csv").unwrap_err().to_string()
    }

    #[test]
    fn bad_records_are_named() {
        assert!(err("t,a\n0,1\n").contains("line 1: bad header"));
        assert!(err("time_s\n0\n").contains("bad header"));
        let e = err("time_s,a\n0,1\n0.1,x\n");
        assert!(
            e.contains("r.csv, line 3") && e.contains("a = \"x\" is not a number"),
            "{e}"
        );
        let e = err("time_s,a\n0,1\n0.1,nan\n");
        assert!(e.contains("line 3") && e.contains("not finite"), "{e}");
        let e = err("time_s,a\n0,1\ninf,1\n");
        assert!(
            e.contains("line 3") && e.contains("time_s = inf is not finite"),
            "{e}"
        );
        let e = err("time_s,a\n0,1\n0.2,1\n0.1,1\n0.3,1\n");
        assert!(e.contains("line 4") && e.contains("out of order"), "{e}");
        let e = err("time_s,a\n0,1\n0.2,1\n0.2,1\n0.3,1\n");
        assert!(e.contains("line 4") && e.contains("repeated"), "{e}");
        let e = err("time_s,a\n0,1\n0.2,1\n0.3,1\n");
        assert!(e.contains("r.csv: 3 samples, at least 4"), "{e}");
        let e = err("time_s,a\n0\n");
        assert!(e.contains("line 2") && e.contains("expected 2 cells"), "{e}");
    }

    #[test]
    fn times_start_at_zero_and_uneven_spacing_is_kept() {
        let r = parse_record("time_s,acc\n1.5,0\n1.6,1\n\n1.8,0\n2.5,-1\n", "r.csv").unwrap();
        assert_eq!(r.time_offset, 1.5);
        assert_eq!(r.value_column, "acc");
        assert!((r.times[3] - 1.0).abs() < 1e-15 && (r.duration() - 1.0).abs() < 1e-15);
        assert_eq!(r.values, vec![0.0, 1.0, 0.0, -1.0]);
    }
}
