//! The tables of a frequency response, row by row as the command line writes them
//! (`response.csv`, `branches.csv`; `response.csv` and `seeds.csv` of a random-band response)
//! and as Python returns them.

use super::band::BandResponse;
use super::sweeps::FrequencyResponse;
use crate::study::{Direction, PointResult};
use crate::sweep::{Cell, Kind, SweepError, Table, error_text};

/// The rows of a file, with the names and kinds of its columns: what the command line writes
/// (each [`Cell`] as its CSV field) and Python receives ([`table`](Self::table)).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Rows {
    /// Column names, the file's header.
    pub names: Vec<String>,
    /// Column kinds.
    pub kinds: Vec<Kind>,
    /// The rows, one cell per column.
    pub rows: Vec<Vec<Cell>>,
}

impl Rows {
    fn new(names: Vec<String>, kinds: Vec<Kind>) -> Self {
        debug_assert_eq!(names.len(), kinds.len());
        Rows {
            names,
            kinds,
            rows: Vec::new(),
        }
    }

    fn push_row(&mut self, row: Vec<Cell>) {
        debug_assert_eq!(row.len(), self.names.len());
        self.rows.push(row);
    }

    /// The rows in columns (a missing cell as NaN, −1, false or empty text).
    pub fn table(&self) -> Table {
        let mut t = Table::new(self.names.clone(), self.kinds.clone());
        for row in &self.rows {
            t.push_row(row.clone());
        }
        t
    }
}

/// The columns of one sweep in `response.csv`, each followed by `_up` or `_down` (before
/// the unit): average power, W; its batch-means standard error, W; the detected period, in
/// excitation periods (0: not periodic); impacts per period, all contacts; the motion's label;
/// why the value failed.
const SWEEP_COLUMNS: [(&str, &str, Kind); 6] = [
    ("power", "_w", Kind::Float),
    ("power_se", "_w", Kind::Float),
    ("period", "", Kind::Int),
    ("impacts_per_period", "", Kind::Float),
    ("motion", "", Kind::Text),
    ("error", "", Kind::Text),
];

/// The cells of [`SWEEP_COLUMNS`] of one value (all missing where it was not reached).
fn sweep_cells(result: Option<&Result<PointResult, SweepError>>) -> [Cell; 6] {
    match result {
        None => std::array::from_fn(|_| Cell::Missing),
        Some(Err(e)) => [
            Cell::Missing,
            Cell::Missing,
            Cell::Missing,
            Cell::Missing,
            Cell::Missing,
            Cell::Text(error_text(e)),
        ],
        Some(Ok(p)) => [
            Cell::float(p.average_power_w.filter(|x| x.is_finite())),
            Cell::float(p.average_power_se_w.filter(|x| x.is_finite())),
            Cell::Int(p.period() as i64),
            Cell::Float(p.total_impacts_per_period()),
            Cell::Text(
                p.motion
                    .as_ref()
                    .map_or(String::new(), |m| m.motion.as_str().to_string()),
            ),
            Cell::Text(
                p.electrical_error
                    .as_ref()
                    .map_or(String::new(), ToString::to_string),
            ),
        ],
    }
}

/// `response.csv` of a frequency response: one row per value in increasing order, `param`
/// (the value) and then, for each quantity of a sweep, the up sweep's column beside the down
/// sweep's: `power_up_w, power_down_w, power_se_up_w, power_se_down_w, period_up,
/// period_down, impacts_per_period_up, impacts_per_period_down, motion_up, motion_down,
/// error_up, error_down`.
pub fn response_table(r: &FrequencyResponse) -> Rows {
    let mut names = vec!["param".to_string()];
    let mut kinds = vec![Kind::Float];
    for (name, unit, kind) in SWEEP_COLUMNS {
        for d in [Direction::Up, Direction::Down] {
            names.push(format!("{name}_{}{unit}", d.as_str()));
            kinds.push(kind);
        }
    }
    let mut table = Rows::new(names, kinds);
    for (j, &v) in r.values.iter().enumerate() {
        let up = sweep_cells(r.up.results.get(j).and_then(Option::as_ref));
        let down = sweep_cells(r.down.results.get(j).and_then(Option::as_ref));
        let mut row = vec![Cell::Float(v)];
        for (u, d) in up.into_iter().zip(down) {
            row.push(u);
            row.push(d);
        }
        table.push_row(row);
    }
    table
}

/// `branches.csv` of a frequency response: one row per point of every branch, in order along
/// each branch: `branch` (its index, 0-based, in the order the branches were found), `period`
/// (excitation periods), `param`, `stable`, `power_w` (W; empty where the charge solver
/// failed), `max_abs_multiplier`, `impacts_per_period`.
pub fn branch_table(r: &FrequencyResponse) -> Rows {
    let names = [
        "branch",
        "period",
        "param",
        "stable",
        "power_w",
        "max_abs_multiplier",
        "impacts_per_period",
    ];
    let kinds = vec![
        Kind::Int,
        Kind::Int,
        Kind::Float,
        Kind::Bool,
        Kind::Float,
        Kind::Float,
        Kind::Float,
    ];
    let mut table = Rows::new(names.map(String::from).to_vec(), kinds);
    for (i, b) in r.branches.iter().enumerate() {
        for p in &b.points {
            table.push_row(vec![
                Cell::Int(i as i64),
                Cell::Int(i64::from(b.period)),
                Cell::Float(p.value),
                Cell::Bool(p.stable),
                Cell::float(Some(p.power_w).filter(|x| x.is_finite())),
                Cell::Float(p.max_abs_multiplier),
                Cell::Float(p.impacts_per_period),
            ]);
        }
    }
    table
}

/// `response.csv` of a random-band response: one row per centre whose seeds all ran:
/// `centre_hz`, `f_low_hz`, `f_high_hz` (Hz), `power_w` (the mean over the seeds, W),
/// `power_se_w` (its standard error, W), `runs` (seeds with a power), `power_min_w`,
/// `power_max_w` (W).
pub fn band_table(r: &BandResponse) -> Rows {
    let names = [
        "centre_hz",
        "f_low_hz",
        "f_high_hz",
        "power_w",
        "power_se_w",
        "runs",
        "power_min_w",
        "power_max_w",
    ];
    let mut kinds = vec![Kind::Float; names.len()];
    kinds[5] = Kind::Int;
    let mut table = Rows::new(names.map(String::from).to_vec(), kinds);
    for p in r.points() {
        table.push_row(vec![
            Cell::Float(p.centre_hz),
            Cell::Float(p.f_low_hz),
            Cell::Float(p.f_high_hz),
            Cell::float(p.power_w),
            Cell::float(p.power_se_w),
            Cell::Int(p.runs as i64),
            Cell::float(p.power_min_w),
            Cell::float(p.power_max_w),
        ]);
    }
    table
}

/// `seeds.csv` of a random-band response: one row per run, centre by centre: `centre_hz`,
/// `seed`, `power_w` (W), `power_se_w` (the run's batch-means standard error, W), `error`.
pub fn band_seed_table(r: &BandResponse) -> Rows {
    let names = ["centre_hz", "seed", "power_w", "power_se_w", "error"];
    let kinds = vec![Kind::Float, Kind::Int, Kind::Float, Kind::Float, Kind::Text];
    let mut table = Rows::new(names.map(String::from).to_vec(), kinds);
    for (n, (i, k)) in r.plan.points().into_iter().enumerate() {
        let Some(result) = r.results.get(n) else {
            break;
        };
        let (power, se, error) = match result {
            Ok(p) => (
                Cell::float(p.average_power_w.filter(|x| x.is_finite())),
                Cell::float(p.average_power_se_w.filter(|x| x.is_finite())),
                p.electrical_error
                    .as_ref()
                    .map_or(String::new(), ToString::to_string),
            ),
            Err(e) => (Cell::Missing, Cell::Missing, error_text(e)),
        };
        table.push_row(vec![
            Cell::Float(r.plan.centres_hz[i]),
            Cell::Int(r.plan.seeds[k] as i64),
            power,
            se,
            Cell::Text(error),
        ]);
    }
    table
}
