//! Sweep and map results as rows: one definition of the tables the command line writes as
//! `summary.csv` (`map.csv`), `orbit.csv` and `impacts.csv`, with the same column names, and
//! that front ends hand out as arrays (Python's numpy). A point's result becomes rows of
//! typed [`Cell`]s here; the command line prints each cell as CSV text ([`Cell`]'s
//! `Display`), and [`SweepColumns`] gathers the same cells into typed [`Column`]s.

use std::fmt;

use super::runner::SweepError;
use crate::study::PointResult;

/// The columns describing one sweep or map point, after its key columns: `average_power_w`,
/// `impacts_per_period`, `period` (0 = non-periodic), `chatter`, `sticking`, `grazing`,
/// `impacts_per_period_1..contacts`, `error`.
pub fn point_columns(contacts: usize) -> Vec<String> {
    let mut cols: Vec<String> = [
        "average_power_w",
        "impacts_per_period",
        "period",
        "chatter",
        "sticking",
        "grazing",
    ]
    .map(String::from)
    .to_vec();
    cols.extend((1..=contacts).map(|k| format!("impacts_per_period_{k}")));
    cols.push("error".into());
    cols
}

/// The columns describing a point's motion, after all the others of `summary.csv` and
/// `map.csv`: `motion` (`periodic`, `settling`, `quasiperiodic`, `chaotic`; empty where not
/// classified or failed), `average_power_se_w` (the power's batch-means standard error, W),
/// `settle_periods` (periods run before the recorded window), `settle_rate` (decay factor
/// of the return distances per period, where converging), `residual` (the period test's
/// relative mismatch at the detected or closest period), `settle_periods_needed` (for a
/// settling motion, periods still needed), `label_source` (for a periodic motion, `reached`
/// where the run repeats, `shot` where Newton shooting finished an approach the run was seen
/// making), `coexisting_period` (the minimal period of a stable orbit found near the run that
/// the run does not approach). See [`MotionReport`](crate::study::MotionReport).
pub const MOTION_COLUMNS: [&str; 8] = [
    "motion",
    "average_power_se_w",
    "settle_periods",
    "settle_rate",
    "residual",
    "settle_periods_needed",
    "label_source",
    "coexisting_period",
];

/// The columns `lyapunov` adds before the motion columns: the largest Lyapunov exponent over
/// the recorded periods and its batch-means standard error, 1/s.
pub const LYAPUNOV_COLUMNS: [&str; 2] = ["lyapunov_max_1_s", "lyapunov_spread_1_s"];

/// The text of a point's failure, as the `error` column holds it.
pub fn error_text(e: &SweepError) -> String {
    format!("{e:#}")
}

/// One cell of a row.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// No value (an empty CSV field; NaN, −1, false or empty text in a [`Column`]).
    Missing,
    /// A number.
    Float(f64),
    /// An integer.
    Int(i64),
    /// A flag.
    Bool(bool),
    /// Text.
    Text(String),
}

impl Cell {
    /// `x`, or [`Cell::Missing`] where `x` is `None`.
    pub fn float(x: Option<f64>) -> Self {
        x.map_or(Cell::Missing, Cell::Float)
    }

    /// `x`, or [`Cell::Missing`] where `x` is `None` or NaN.
    fn number(x: Option<f64>) -> Self {
        Cell::float(x.filter(|x| !x.is_nan()))
    }
}

impl fmt::Display for Cell {
    /// The CSV field: empty where missing, numbers in Rust's shortest round-trip form (so that
    /// reading them back gives the same bits), `true`/`false`, text quoted (quotes doubled)
    /// where it holds a comma, a quote or a line break.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Cell::Missing => Ok(()),
            Cell::Float(x) => write!(f, "{x}"),
            Cell::Int(i) => write!(f, "{i}"),
            Cell::Bool(b) => write!(f, "{b}"),
            Cell::Text(t) if t.contains([',', '"', '\n', '\r']) => {
                write!(f, "\"{}\"", t.replace('"', "\"\""))
            }
            Cell::Text(t) => f.write_str(t),
        }
    }
}

/// The columns of a point after its key columns ([`point_columns`]), with `floquet`
/// `max_abs_multiplier`, with `lyapunov` [`LYAPUNOV_COLUMNS`], and last [`MOTION_COLUMNS`]:
/// the row a point writes to `summary.csv` or `map.csv`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PointColumns {
    /// Contacts of the chain ([`ChainParams::contact_count`](crate::ChainParams::contact_count):
    /// N − 1, and one more per rigid stop).
    pub contacts: usize,
    /// Whether the largest Floquet multiplier modulus is a column.
    pub floquet: bool,
    /// Whether the largest Lyapunov exponent and its spread are columns.
    pub lyapunov: bool,
}

impl PointColumns {
    /// The columns of a chain with `contacts` contacts, without the optional ones.
    pub fn of_contacts(contacts: usize) -> Self {
        PointColumns {
            contacts,
            floquet: false,
            lyapunov: false,
        }
    }

    /// The columns of a file whose point columns are `width` wide (its header less its key
    /// columns), with or without the Floquet and Lyapunov columns: the contacts are what the
    /// other columns leave.
    pub fn from_width(width: usize, floquet: bool, lyapunov: bool) -> Self {
        let fixed = PointColumns {
            contacts: 0,
            floquet,
            lyapunov,
        }
        .names()
        .len();
        PointColumns {
            contacts: width.saturating_sub(fixed),
            floquet,
            lyapunov,
        }
    }

    /// The column names.
    pub fn names(&self) -> Vec<String> {
        let mut cols = point_columns(self.contacts);
        if self.floquet {
            cols.push("max_abs_multiplier".into());
        }
        if self.lyapunov {
            cols.extend(LYAPUNOV_COLUMNS.map(String::from));
        }
        cols.extend(MOTION_COLUMNS.map(String::from));
        cols
    }

    /// The kind of each column of [`names`](Self::names).
    pub fn kinds(&self) -> Vec<Kind> {
        use Kind::{Bool, Float, Int, Text};
        let mut kinds = vec![Float, Float, Int, Bool, Bool, Bool];
        kinds.extend(std::iter::repeat_n(Float, self.contacts));
        kinds.push(Text);
        if self.floquet {
            kinds.push(Float);
        }
        if self.lyapunov {
            kinds.extend([Float, Float]);
        }
        kinds.extend([Text, Float, Int, Float, Float, Float, Text, Int]);
        kinds
    }

    /// The cells of one point: its results, or missing cells and the reason it failed.
    /// `error` also holds an electrical failure of a point whose mechanics succeeded;
    /// `max_abs_multiplier` is missing where shooting failed or no period was detected, the
    /// Lyapunov columns where no spectrum was computed.
    pub fn cells(&self, result: &Result<PointResult, SweepError>) -> Vec<Cell> {
        let mut row = match result {
            Ok(p) => {
                let mut row = vec![
                    Cell::float(p.average_power_w),
                    Cell::Float(p.total_impacts_per_period()),
                    Cell::Int(p.period() as i64),
                    Cell::Bool(p.chatter),
                    Cell::Bool(p.sticking),
                    Cell::Bool(p.grazing),
                ];
                row.extend(p.impacts_per_period.iter().map(|&c| Cell::Float(c)));
                row.push(Cell::Text(
                    p.electrical_error
                        .as_ref()
                        .map_or(String::new(), ToString::to_string),
                ));
                row
            }
            Err(e) => {
                let mut row = vec![Cell::Missing; 6 + self.contacts];
                row.push(Cell::Text(error_text(e)));
                row
            }
        };
        let point = result.as_ref().ok();
        if self.floquet {
            let m = point
                .and_then(|p| p.max_abs_multiplier.as_ref())
                .and_then(|m| m.as_ref().ok());
            row.push(Cell::float(m.copied()));
        }
        if self.lyapunov {
            match point.and_then(|p| p.lyapunov.as_ref()) {
                Some(Ok(s)) => row.extend([Cell::Float(s.largest()), Cell::Float(s.largest_spread())]),
                _ => row.extend([Cell::Missing, Cell::Missing]),
            }
        }
        row.extend(motion_cells(point));
        row
    }
}

/// The cells of [`MOTION_COLUMNS`] for a point (all missing for a failed one; NaN is
/// missing).
fn motion_cells(point: Option<&PointResult>) -> [Cell; 8] {
    let Some(p) = point else {
        return std::array::from_fn(|_| Cell::Missing);
    };
    let m = p.motion.as_ref();
    [
        Cell::Text(m.map_or(String::new(), |m| m.motion.as_str().to_string())),
        Cell::number(p.average_power_se_w),
        m.map_or(Cell::Missing, |m| Cell::Int(m.settle_periods as i64)),
        Cell::number(m.and_then(|m| m.rate)),
        Cell::number(m.map(|m| m.residual)),
        Cell::number(m.and_then(|m| m.periods_needed)),
        Cell::Text(
            m.and_then(|m| m.label_source)
                .map_or(String::new(), |s| s.as_str().to_string()),
        ),
        m.and_then(|m| m.coexisting)
            .map_or(Cell::Missing, |c| Cell::Int(i64::from(c.0))),
    ]
}

/// The rows of `orbit.csv` of a point of a chain of `masses` masses keyed by `keys`: the
/// keys, `period` (the index n of the stroboscopic sample at t = nT) and the positions
/// `x1_m … xN_m`, m, one row per recorded period.
pub fn orbit_rows<'a>(
    keys: &'a [f64],
    masses: usize,
    p: &'a PointResult,
) -> impl Iterator<Item = Vec<Cell>> + 'a {
    p.strobe_periods
        .iter()
        .zip(p.strobe.chunks_exact(masses.max(1)))
        .map(move |(&period, x)| {
            let mut row: Vec<Cell> = keys.iter().map(|&k| Cell::Float(k)).collect();
            row.push(Cell::Int(period as i64));
            row.extend(x.iter().map(|&x| Cell::Float(x)));
            row
        })
}

/// The columns of `orbit.csv` after the keys, for `masses` masses.
pub fn orbit_columns(masses: usize) -> Vec<String> {
    let mut cols = vec!["period".to_string()];
    cols.extend((1..=masses).map(|i| format!("x{i}_m")));
    cols
}

/// The columns of `impacts.csv` after the keys.
pub const IMPACT_COLUMNS: [&str; 3] = ["time_s", "contact", "rel_velocity_m_s"];

/// The rows of `impacts.csv` of a point keyed by `keys`: the keys, `time_s` (from the start
/// of the point's run), `contact` (1-based: contact k is the gap between masses k and k+1;
/// with rigid stops N is the lower stop and N + 1 the upper) and `rel_velocity_m_s` (the
/// closing speed), one row per impact after the transient.
pub fn impact_rows<'a>(keys: &'a [f64], p: &'a PointResult) -> impl Iterator<Item = Vec<Cell>> + 'a {
    p.impacts.iter().map(move |i| {
        let mut row: Vec<Cell> = keys.iter().map(|&k| Cell::Float(k)).collect();
        row.extend([
            Cell::Float(i.time),
            Cell::Int(i.contact as i64 + 1),
            Cell::Float(i.closing_speed),
        ]);
        row
    })
}

/// The kind of a [`Column`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Numbers.
    Float,
    /// Integers.
    Int,
    /// Flags.
    Bool,
    /// Text.
    Text,
}

/// One column of a [`Table`].
#[derive(Debug, Clone, PartialEq)]
pub enum Column {
    /// Numbers (NaN where a value is missing).
    Float(Vec<f64>),
    /// Integers (−1 where a value is missing).
    Int(Vec<i64>),
    /// Flags (false where a value is missing).
    Bool(Vec<bool>),
    /// Text (empty where there is none).
    Text(Vec<String>),
}

impl Column {
    /// An empty column of `kind`.
    pub fn new(kind: Kind) -> Self {
        match kind {
            Kind::Float => Column::Float(Vec::new()),
            Kind::Int => Column::Int(Vec::new()),
            Kind::Bool => Column::Bool(Vec::new()),
            Kind::Text => Column::Text(Vec::new()),
        }
    }

    /// Adds `cell` at the end (a missing cell as NaN, −1, false or empty text).
    pub fn push(&mut self, cell: Cell) {
        match (self, cell) {
            (Column::Float(v), Cell::Float(x)) => v.push(x),
            (Column::Float(v), Cell::Int(i)) => v.push(i as f64),
            (Column::Float(v), _) => v.push(f64::NAN),
            (Column::Int(v), Cell::Int(i)) => v.push(i),
            (Column::Int(v), _) => v.push(-1),
            (Column::Bool(v), Cell::Bool(b)) => v.push(b),
            (Column::Bool(v), _) => v.push(false),
            (Column::Text(v), Cell::Text(t)) => v.push(t),
            (Column::Text(v), Cell::Missing) => v.push(String::new()),
            (Column::Text(v), other) => v.push(other.to_string()),
        }
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        match self {
            Column::Float(v) => v.len(),
            Column::Int(v) => v.len(),
            Column::Bool(v) => v.len(),
            Column::Text(v) => v.len(),
        }
    }

    /// Whether it has no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Named columns of equal length, in the order of the corresponding CSV file's header.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    /// `(name, column)` pairs.
    pub columns: Vec<(String, Column)>,
}

impl Table {
    /// An empty table with these names and kinds.
    pub fn new(names: Vec<String>, kinds: Vec<Kind>) -> Self {
        debug_assert_eq!(names.len(), kinds.len());
        Table {
            columns: names
                .into_iter()
                .zip(kinds.into_iter().map(Column::new))
                .collect(),
        }
    }

    /// Adds a row, one cell per column.
    pub fn push_row(&mut self, row: Vec<Cell>) {
        debug_assert_eq!(row.len(), self.columns.len());
        for ((_, column), cell) in self.columns.iter_mut().zip(row) {
            column.push(cell);
        }
    }

    /// The column called `name`.
    pub fn get(&self, name: &str) -> Option<&Column> {
        self.columns.iter().find(|(n, _)| n == name).map(|(_, c)| c)
    }

    /// The column names.
    pub fn names(&self) -> Vec<&str> {
        self.columns.iter().map(|(n, _)| n.as_str()).collect()
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |(_, c)| c.len())
    }
}

/// Collects the results of sweep or map points, in the order they are pushed, into the
/// columns of their three tables, row by row as the command line writes them to its files
/// ([`PointColumns::cells`], [`orbit_rows`], [`impact_rows`]):
///
/// - summary (`summary.csv`, `map.csv`): the key columns, then [`PointColumns::names`]; a
///   failed point has NaN numbers, `period` and `settle_periods` −1, false flags, no
///   motion and its error (the files leave those cells empty);
/// - orbit (`orbit.csv`): the key columns and [`orbit_columns`];
/// - impacts (`impacts.csv`): the key columns and [`IMPACT_COLUMNS`].
#[derive(Debug, Clone, PartialEq)]
pub struct SweepColumns {
    masses: usize,
    columns: PointColumns,
    orbits: bool,
    summary: Table,
    orbit: Table,
    impacts: Table,
}

impl SweepColumns {
    /// Empty tables for points keyed by `keys` (`["param"]` for a sweep, `["x", "y"]` for a
    /// map) of a chain of `masses` masses, with the point columns `columns`; the orbit and
    /// impact tables are kept only if `orbits`.
    pub fn new(keys: &[&str], masses: usize, columns: PointColumns, orbits: bool) -> Self {
        let keyed = |rest: Vec<String>, kinds: Vec<Kind>| {
            let mut names: Vec<String> = keys.iter().map(|k| k.to_string()).collect();
            names.extend(rest);
            let mut all = vec![Kind::Float; keys.len()];
            all.extend(kinds);
            Table::new(names, all)
        };
        let mut orbit_kinds = vec![Kind::Int];
        orbit_kinds.extend(std::iter::repeat_n(Kind::Float, masses));
        SweepColumns {
            masses,
            columns,
            orbits,
            summary: keyed(columns.names(), columns.kinds()),
            orbit: keyed(orbit_columns(masses), orbit_kinds),
            impacts: keyed(
                IMPACT_COLUMNS.map(String::from).to_vec(),
                vec![Kind::Float, Kind::Int, Kind::Float],
            ),
        }
    }

    /// Points pushed so far.
    pub fn len(&self) -> usize {
        self.summary.rows()
    }

    /// Whether no point was pushed.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Adds the point with key values `key_values` (one per key) and its result.
    pub fn push(&mut self, key_values: &[f64], result: &Result<PointResult, SweepError>) {
        if let (Ok(p), true) = (result, self.orbits) {
            for row in orbit_rows(key_values, self.masses, p) {
                self.orbit.push_row(row);
            }
            for row in impact_rows(key_values, p) {
                self.impacts.push_row(row);
            }
        }
        let mut row: Vec<Cell> = key_values.iter().map(|&k| Cell::Float(k)).collect();
        row.extend(self.columns.cells(result));
        self.summary.push_row(row);
    }

    /// The summary table (`summary.csv`, `map.csv`).
    pub fn summary(&self) -> Table {
        self.summary.clone()
    }

    /// The orbit table (`orbit.csv`; empty unless kept).
    pub fn orbit(&self) -> Table {
        self.orbit.clone()
    }

    /// The impact table (`impacts.csv`; empty unless kept).
    pub fn impacts(&self) -> Table {
        self.impacts.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::study::PointOptions;
    use crate::sweep::PointRunner;

    fn runner(config: Config, transient: u64, recorded: u64, mechanics_only: bool) -> PointRunner {
        let options = PointOptions {
            transient_periods: transient,
            recorded_periods: recorded,
            ..PointOptions::default()
        };
        PointRunner::new(config, options, mechanics_only)
    }

    /// Every row of the tables is the point result it came from, in push order; a failed
    /// point is a summary row with its error and nothing in the other tables.
    #[test]
    fn columns_hold_the_points() {
        let runner = runner(Config::default(), 10, 6, false);
        let values = [0.75, -1.0, 0.6];
        let results: Vec<_> = values
            .iter()
            .map(|&v| runner.run(&[("omega_ratio", v)], None))
            .collect();
        let mut t = SweepColumns::new(&["param"], 3, PointColumns::of_contacts(2), true);
        for (v, r) in values.iter().zip(&results) {
            t.push(&[*v], r);
        }
        let s = t.summary();
        assert_eq!(s.names()[..3], ["param", "average_power_w", "impacts_per_period"]);
        assert_eq!(s.names()[s.names().len() - 9], "error");
        assert_eq!(s.names()[s.names().len() - 8..], MOTION_COLUMNS);
        assert_eq!(s.rows(), 3);
        let Some(Column::Float(p)) = s.get("average_power_w") else {
            panic!()
        };
        let first = results[0].as_ref().unwrap();
        assert_eq!(p[0], first.average_power_w.unwrap());
        assert!(p[1].is_nan());
        let Some(Column::Int(period)) = s.get("period") else {
            panic!()
        };
        assert_eq!(period[1], -1);
        let Some(Column::Text(err)) = s.get("error") else {
            panic!()
        };
        assert!(err[1].contains("excitation.omega_ratio"), "{}", err[1]);
        assert!(err[0].is_empty());

        let o = t.orbit();
        assert_eq!(o.names(), ["param", "period", "x1_m", "x2_m", "x3_m"]);
        assert_eq!(o.rows(), 12);
        let Some(Column::Float(x2)) = o.get("x2_m") else {
            panic!()
        };
        let expected: Vec<f64> = first.position_series(1).collect();
        assert_eq!(x2[..6], expected[..]);
        let Some(Column::Float(keys)) = o.get("param") else {
            panic!()
        };
        assert_eq!(keys[6], 0.6);

        let i = t.impacts();
        let last = results[2].as_ref().unwrap();
        assert_eq!(i.rows(), first.impacts.len() + last.impacts.len());
        let Some(Column::Int(contact)) = i.get("contact") else {
            panic!()
        };
        assert_eq!(contact[0], first.impacts[0].contact as i64 + 1);
    }

    /// A single mass below a rigid stop has no gap between masses but two stop contacts
    /// (N + 1): the summary has a column per contact, and the upper stop's impacts are
    /// counted in `impacts_per_period_2` and numbered 2 in the impact table.
    #[test]
    fn a_chain_with_a_stop_has_a_column_per_contact() {
        let text = "[oscillator]\nmasses = [0.05]\nstiffness = 120.0\ndamping = 0.09798\n\
                    [oscillator.stops.upper]\ngap = 0.0\nrestitution = 0.8\n\
                    [excitation]\namplitude = 0.01\nomega_ratio = 2.5\n";
        let config = Config::from_toml_str(text).unwrap();
        assert_eq!(config.chain().contact_count(), 2);
        let runner = runner(config, 100, 20, true);
        let r = runner.run(&[("omega_ratio", 2.5)], None);
        let p = r.as_ref().unwrap();
        let mut t = SweepColumns::new(&["param"], runner.masses(), PointColumns::of_contacts(2), true);
        t.push(&[2.5], &r);
        let s = t.summary();
        let Some(Column::Float(upper)) = s.get("impacts_per_period_2") else {
            panic!("{:?}", s.names())
        };
        // The period-1 impacting orbit: one impact per period, all on the upper stop.
        assert_eq!(upper[0], 1.0, "{:?}", p.impacts_per_period);
        let Some(Column::Int(contact)) = t.impacts().get("contact").cloned() else {
            panic!()
        };
        assert_eq!(contact.len(), 20);
        assert!(contact.iter().all(|&c| c == 2), "{contact:?}");
    }

    /// The CSV text of the cells: empty where missing, shortest round-trip numbers, quoted
    /// text.
    #[test]
    fn cells_print_as_csv_fields() {
        let row = [
            Cell::Float(1.5),
            Cell::Missing,
            Cell::Int(-1),
            Cell::Bool(true),
            Cell::Float(0.1 + 0.2),
            Cell::Text("stopped, at t = 1: \"event limit\"".into()),
        ];
        let text: Vec<String> = row.iter().map(ToString::to_string).collect();
        assert_eq!(
            text,
            [
                "1.5",
                "",
                "-1",
                "true",
                "0.30000000000000004",
                "\"stopped, at t = 1: \"\"event limit\"\"\""
            ]
        );
        let names = PointColumns {
            contacts: 3,
            floquet: true,
            lyapunov: true,
        };
        assert_eq!(names.names().len(), names.kinds().len());
        assert_eq!(PointColumns::from_width(names.names().len(), true, true), names);
    }
}
