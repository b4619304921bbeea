//! The tables of basins and attractor censuses, row by row: the one writer of the command
//! line's `basins.csv`, `attractors.csv` and `expected_power.csv` and of the columns Python
//! hands out (the rows are [`Cell`]s, printed as CSV fields or gathered into a [`Table`]).

use super::classify::{Attractor, Classification};
use super::fingerprint::Fingerprint;
use super::runs::ValueAttractors;
use crate::sweep::{Cell, Kind, Table};

/// The columns of an attractor after its number: `period`, `starts`, `fraction`,
/// `fraction_se`, `impacts_per_period`, `average_power_w`, `power_se_w` (then its state,
/// [`state_columns`]).
pub const ATTRACTOR_COLUMNS: [(&str, Kind); 7] = [
    ("period", Kind::Int),
    ("starts", Kind::Int),
    ("fraction", Kind::Float),
    ("fraction_se", Kind::Float),
    ("impacts_per_period", Kind::Float),
    ("average_power_w", Kind::Float),
    ("power_se_w", Kind::Float),
];

/// The columns of `basins.csv`: a start (`x`, `y`), its attractor (1-based), and its
/// fingerprint's period, impacts per period and average power.
pub const BASIN_COLUMNS: [(&str, Kind); 6] = [
    ("x", Kind::Float),
    ("y", Kind::Float),
    ("attractor", Kind::Int),
    ("period", Kind::Int),
    ("impacts_per_period", Kind::Float),
    ("average_power_w", Kind::Float),
];

/// The columns of the starts of a basin grid as Python hands them out: a start, its
/// fingerprint's period, impacts per period and average power, and its error.
pub const START_COLUMNS: [(&str, Kind); 6] = [
    ("x", Kind::Float),
    ("y", Kind::Float),
    ("period", Kind::Int),
    ("impacts_per_period", Kind::Float),
    ("average_power_w", Kind::Float),
    ("error", Kind::Text),
];

/// The columns of `expected_power.csv`: the value, the expected power (W) of an unknown
/// start and its standard error, the attractors with starts, the starts classified, those
/// that failed and the first failure.
pub const EXPECTED_POWER_COLUMNS: [(&str, Kind); 7] = [
    ("param", Kind::Float),
    ("expected_power_w", Kind::Float),
    ("expected_power_se_w", Kind::Float),
    ("attractors", Kind::Int),
    ("starts", Kind::Int),
    ("failed", Kind::Int),
    ("error", Kind::Text),
];

/// `x1_m … xN_m, v1_m_s … vN_m_s`: an attractor's state at t ≡ 0 (mod T).
pub fn state_columns(masses: usize) -> Vec<String> {
    let mut names: Vec<String> = (1..=masses).map(|i| format!("x{i}_m")).collect();
    names.extend((1..=masses).map(|i| format!("v{i}_m_s")));
    names
}

/// The column names and kinds of `lead` then `tail`, then the state of `masses` masses
/// (floats) when `masses` > 0.
pub fn columns(lead: &[(&str, Kind)], tail: &[(&str, Kind)], masses: usize) -> (Vec<String>, Vec<Kind>) {
    let mut names: Vec<String> = lead.iter().chain(tail).map(|(n, _)| n.to_string()).collect();
    let mut kinds: Vec<Kind> = lead.iter().chain(tail).map(|(_, k)| *k).collect();
    let state = state_columns(masses);
    kinds.extend(state.iter().map(|_| Kind::Float));
    names.extend(state);
    (names, kinds)
}

/// The columns of `attractors.csv` of a basin grid: `attractor`, [`ATTRACTOR_COLUMNS`], the
/// state.
pub fn basin_attractor_columns(masses: usize) -> (Vec<String>, Vec<Kind>) {
    columns(&[("attractor", Kind::Int)], &ATTRACTOR_COLUMNS, masses)
}

/// The columns of `attractors.csv` of a census across a parameter: `param`, `attractor`,
/// [`ATTRACTOR_COLUMNS`], the state.
pub fn census_attractor_columns(masses: usize) -> (Vec<String>, Vec<Kind>) {
    columns(
        &[("param", Kind::Float), ("attractor", Kind::Int)],
        &ATTRACTOR_COLUMNS,
        masses,
    )
}

/// A table of `rows` in the columns `(names, kinds)`.
pub fn table_of(columns: (Vec<String>, Vec<Kind>), rows: impl IntoIterator<Item = Vec<Cell>>) -> Table {
    let mut t = Table::new(columns.0, columns.1);
    for row in rows {
        t.push_row(row);
    }
    t
}

/// Attractor `a` of `c` after its number: [`ATTRACTOR_COLUMNS`] and its state (the first of
/// its section points) of a chain of `masses` masses.
pub fn attractor_cells(c: &Classification, a: usize, at: &Attractor, masses: usize) -> Vec<Cell> {
    let (f, se) = c.fraction(a);
    let mut row = vec![
        Cell::Int(at.period as i64),
        Cell::Int(at.starts as i64),
        Cell::Float(f),
        Cell::Float(se),
        Cell::Float(at.impacts_per_period),
        Cell::float(at.power_w),
        Cell::float(at.power_se),
    ];
    row.extend(at.points[..2 * masses].iter().map(|&x| Cell::Float(x)));
    row
}

/// The rows of a basin grid's `attractors.csv`: each attractor of `c`, numbered from 1.
pub fn basin_attractor_rows(c: &Classification, masses: usize) -> impl Iterator<Item = Vec<Cell>> + '_ {
    c.attractors.iter().enumerate().map(move |(a, at)| {
        let mut row = vec![Cell::Int(a as i64 + 1)];
        row.extend(attractor_cells(c, a, at, masses));
        row
    })
}

/// A fingerprint's period, impacts per period and average power (missing for a start that
/// did not run).
fn fingerprint_cells(f: Option<&Fingerprint>) -> [Cell; 3] {
    match f {
        Some(f) => [
            Cell::Int(f.period as i64),
            Cell::Float(f.impacts_per_period),
            Cell::float(f.power_w),
        ],
        None => [Cell::Missing, Cell::Missing, Cell::Missing],
    }
}

/// The rows of `basins.csv` ([`BASIN_COLUMNS`]): each start at `points` with its fingerprint
/// (`None`: it did not run) and its attractor in `c` (classified in that order).
pub fn basin_rows<'a>(
    points: &'a [(f64, f64)],
    fingerprints: &'a [Option<Fingerprint>],
    c: &'a Classification,
) -> impl Iterator<Item = Vec<Cell>> + 'a {
    points
        .iter()
        .zip(fingerprints)
        .zip(&c.labels)
        .map(|((&(x, y), f), label)| {
            let mut row = vec![
                Cell::Float(x),
                Cell::Float(y),
                label.map_or(Cell::Missing, |a| Cell::Int(a as i64 + 1)),
            ];
            row.extend(fingerprint_cells(f.as_ref()));
            row
        })
}

/// The rows of the starts ([`START_COLUMNS`]): each start at `points` with its fingerprint or
/// the error that stopped it.
pub fn start_rows<'a>(
    points: &'a [(f64, f64)],
    results: &'a [Result<Fingerprint, String>],
) -> impl Iterator<Item = Vec<Cell>> + 'a {
    points.iter().zip(results).map(|(&(x, y), r)| {
        let mut row = vec![Cell::Float(x), Cell::Float(y)];
        row.extend(fingerprint_cells(r.as_ref().ok()));
        row.push(Cell::Text(r.as_ref().err().cloned().unwrap_or_default()));
        row
    })
}

/// The rows of a census's `attractors.csv` for one value: its attractors in the order of
/// their global identities, each with the value and its identity (1-based).
pub fn census_attractor_rows(v: &ValueAttractors, masses: usize) -> Vec<Vec<Cell>> {
    let c = &v.classification;
    let mut order: Vec<usize> = (0..c.attractors.len()).collect();
    order.sort_by_key(|&k| v.ids[k]);
    order
        .into_iter()
        .map(|k| {
            let mut row = vec![Cell::Float(v.value), Cell::Int(v.ids[k] as i64 + 1)];
            row.extend(attractor_cells(c, k, &c.attractors[k], masses));
            row
        })
        .collect()
}

/// The row of `expected_power.csv` for one value
/// ([`EXPECTED_POWER_COLUMNS`]).
pub fn expected_power_row(v: &ValueAttractors) -> Vec<Cell> {
    let c = &v.classification;
    vec![
        Cell::Float(v.value),
        Cell::float(v.expected_power.map(|p| p.0)),
        Cell::float(v.expected_power.map(|p| p.1)),
        Cell::Int(c.attractors.iter().filter(|a| a.starts > 0).count() as i64),
        Cell::Int(c.classified() as i64),
        Cell::Int(v.failed as i64),
        Cell::Text(v.first_error.clone().unwrap_or_default()),
    ]
}
