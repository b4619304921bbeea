//! Sweep and map results in columns: the tables the command line writes as `summary.csv`
//! (`map.csv`), `orbit.csv` and `impacts.csv`, with the same column names, for front ends
//! that hand out arrays (Python's numpy).

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

/// A point's values of [`MOTION_COLUMNS`] (NaN, −1 or empty text where missing).
#[derive(Debug, Clone, PartialEq)]
pub struct MotionCells {
    /// `motion`.
    pub motion: String,
    /// `average_power_se_w`, W.
    pub power_se: f64,
    /// `settle_periods` (−1 where missing).
    pub settle_periods: i64,
    /// `settle_rate`.
    pub rate: f64,
    /// `residual`.
    pub residual: f64,
    /// `settle_periods_needed`.
    pub needed: f64,
    /// `label_source`.
    pub label_source: String,
    /// `coexisting_period` (−1 where none).
    pub coexisting: i64,
}

impl MotionCells {
    /// The values of point `p`.
    pub fn of(p: &PointResult) -> Self {
        let m = p.motion.as_ref();
        MotionCells {
            motion: m.map_or(String::new(), |m| m.motion.as_str().to_string()),
            power_se: p.average_power_se_w.unwrap_or(f64::NAN),
            settle_periods: m.map_or(-1, |m| m.settle_periods as i64),
            rate: m.and_then(|m| m.rate).unwrap_or(f64::NAN),
            residual: m.map_or(f64::NAN, |m| m.residual),
            needed: m.and_then(|m| m.periods_needed).unwrap_or(f64::NAN),
            label_source: m
                .and_then(|m| m.label_source)
                .map_or(String::new(), |s| s.as_str().to_string()),
            coexisting: m.and_then(|m| m.coexisting).map_or(-1, |c| i64::from(c.0)),
        }
    }

    /// The values of a failed point.
    pub fn missing() -> Self {
        MotionCells {
            motion: String::new(),
            power_se: f64::NAN,
            settle_periods: -1,
            rate: f64::NAN,
            residual: f64::NAN,
            needed: f64::NAN,
            label_source: String::new(),
            coexisting: -1,
        }
    }

    /// The CSV cells, in the order of [`MOTION_COLUMNS`] (empty where missing).
    pub fn texts(&self) -> Vec<String> {
        let num = |x: f64| if x.is_nan() { String::new() } else { x.to_string() };
        vec![
            self.motion.clone(),
            num(self.power_se),
            if self.settle_periods < 0 {
                String::new()
            } else {
                self.settle_periods.to_string()
            },
            num(self.rate),
            num(self.residual),
            num(self.needed),
            self.label_source.clone(),
            if self.coexisting < 0 {
                String::new()
            } else {
                self.coexisting.to_string()
            },
        ]
    }
}

/// The text of a point's failure, as the `error` column holds it.
pub fn error_text(e: &SweepError) -> String {
    format!("{e:#}")
}

/// One column of a [`Table`].
#[derive(Debug, Clone, PartialEq)]
pub enum Column {
    /// Numbers (NaN where a value is missing).
    Float(Vec<f64>),
    /// Integers.
    Int(Vec<i64>),
    /// Flags.
    Bool(Vec<bool>),
    /// Text (empty where there is none).
    Text(Vec<String>),
}

impl Column {
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
/// columns of its three tables:
///
/// - summary (`summary.csv`, `map.csv`): the key columns, then [`point_columns`], then
///   [`MOTION_COLUMNS`]; a failed point has NaN numbers, `period` and `settle_periods` −1,
///   false flags, no motion and its error (the files leave those cells empty);
/// - orbit (`orbit.csv`): the key columns, `period` (the index n of the stroboscopic sample
///   at t = nT) and the positions `x1_m … xN_m`, m, one row per recorded period;
/// - impacts (`impacts.csv`): the key columns, `time_s` (from the start of the point's run),
///   `contact` (1-based: contact k is the gap between masses k and k+1; with rigid stops N is the lower stop and N + 1 the upper) and
///   `rel_velocity_m_s` (the closing speed), one row per impact after the transient.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepColumns {
    keys: Vec<String>,
    masses: usize,
    orbits: bool,
    summary_keys: Vec<Vec<f64>>,
    power: Vec<f64>,
    impacts_per_period: Vec<f64>,
    period: Vec<i64>,
    chatter: Vec<bool>,
    sticking: Vec<bool>,
    grazing: Vec<bool>,
    by_contact: Vec<Vec<f64>>,
    error: Vec<String>,
    motion: Vec<MotionCells>,
    orbit_keys: Vec<Vec<f64>>,
    orbit_period: Vec<i64>,
    orbit_x: Vec<Vec<f64>>,
    impact_keys: Vec<Vec<f64>>,
    impact_time: Vec<f64>,
    impact_contact: Vec<i64>,
    impact_speed: Vec<f64>,
}

impl SweepColumns {
    /// Empty tables for points keyed by `keys` (`["param"]` for a sweep, `["x", "y"]` for a
    /// map) of a chain of `masses` masses and `contacts` contacts
    /// ([`ChainParams::contact_count`](crate::ChainParams::contact_count): N − 1, and one more
    /// per rigid stop); the orbit and impact tables are kept only if `orbits`.
    pub fn new(keys: &[&str], masses: usize, contacts: usize, orbits: bool) -> Self {
        let k = keys.len();
        SweepColumns {
            keys: keys.iter().map(|s| s.to_string()).collect(),
            masses,
            orbits,
            summary_keys: vec![Vec::new(); k],
            power: Vec::new(),
            impacts_per_period: Vec::new(),
            period: Vec::new(),
            chatter: Vec::new(),
            sticking: Vec::new(),
            grazing: Vec::new(),
            by_contact: vec![Vec::new(); contacts],
            error: Vec::new(),
            motion: Vec::new(),
            orbit_keys: vec![Vec::new(); k],
            orbit_period: Vec::new(),
            orbit_x: vec![Vec::new(); masses],
            impact_keys: vec![Vec::new(); k],
            impact_time: Vec::new(),
            impact_contact: Vec::new(),
            impact_speed: Vec::new(),
        }
    }

    /// Points pushed so far.
    pub fn len(&self) -> usize {
        self.power.len()
    }

    /// Whether no point was pushed.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Adds the point with key values `key_values` (one per key) and its result.
    pub fn push(&mut self, key_values: &[f64], result: &Result<PointResult, SweepError>) {
        debug_assert_eq!(key_values.len(), self.keys.len());
        for (col, &v) in self.summary_keys.iter_mut().zip(key_values) {
            col.push(v);
        }
        match result {
            Ok(p) => {
                self.power.push(p.average_power_w.unwrap_or(f64::NAN));
                self.impacts_per_period.push(p.total_impacts_per_period());
                self.period.push(p.period() as i64);
                self.chatter.push(p.chatter);
                self.sticking.push(p.sticking);
                self.grazing.push(p.grazing);
                for (col, &c) in self.by_contact.iter_mut().zip(&p.impacts_per_period) {
                    col.push(c);
                }
                self.error.push(p.electrical_error.clone().unwrap_or_default());
                self.motion.push(MotionCells::of(p));
                if self.orbits {
                    self.push_orbit(key_values, p);
                }
            }
            Err(e) => {
                self.power.push(f64::NAN);
                self.impacts_per_period.push(f64::NAN);
                self.period.push(-1);
                self.chatter.push(false);
                self.sticking.push(false);
                self.grazing.push(false);
                for col in &mut self.by_contact {
                    col.push(f64::NAN);
                }
                self.error.push(error_text(e));
                self.motion.push(MotionCells::missing());
            }
        }
    }

    fn push_orbit(&mut self, key_values: &[f64], p: &PointResult) {
        let n = self.masses;
        for (j, &period) in p.strobe_periods.iter().enumerate() {
            for (col, &v) in self.orbit_keys.iter_mut().zip(key_values) {
                col.push(v);
            }
            self.orbit_period.push(period as i64);
            for (col, &x) in self.orbit_x.iter_mut().zip(&p.strobe[j * n..(j + 1) * n]) {
                col.push(x);
            }
        }
        for i in &p.impacts {
            for (col, &v) in self.impact_keys.iter_mut().zip(key_values) {
                col.push(v);
            }
            self.impact_time.push(i.time);
            self.impact_contact.push(i.contact as i64 + 1);
            self.impact_speed.push(i.closing_speed);
        }
    }

    fn keyed(&self, keys: &[Vec<f64>]) -> Vec<(String, Column)> {
        self.keys
            .iter()
            .zip(keys)
            .map(|(k, v)| (k.clone(), Column::Float(v.clone())))
            .collect()
    }

    /// The summary table (`summary.csv`, `map.csv`).
    pub fn summary(&self) -> Table {
        let mut columns = self.keyed(&self.summary_keys);
        let mut names = point_columns(self.masses.saturating_sub(1)).into_iter();
        let mut add = |c: Column| columns.push((names.next().expect("a name per column"), c));
        add(Column::Float(self.power.clone()));
        add(Column::Float(self.impacts_per_period.clone()));
        add(Column::Int(self.period.clone()));
        add(Column::Bool(self.chatter.clone()));
        add(Column::Bool(self.sticking.clone()));
        add(Column::Bool(self.grazing.clone()));
        for c in &self.by_contact {
            add(Column::Float(c.clone()));
        }
        add(Column::Text(self.error.clone()));
        let m = &self.motion;
        let float = |f: fn(&MotionCells) -> f64| Column::Float(m.iter().map(f).collect());
        let motion = [
            Column::Text(m.iter().map(|c| c.motion.clone()).collect()),
            float(|c| c.power_se),
            Column::Int(m.iter().map(|c| c.settle_periods).collect()),
            float(|c| c.rate),
            float(|c| c.residual),
            float(|c| c.needed),
            Column::Text(m.iter().map(|c| c.label_source.clone()).collect()),
            Column::Int(m.iter().map(|c| c.coexisting).collect()),
        ];
        for (name, c) in MOTION_COLUMNS.iter().zip(motion) {
            columns.push((name.to_string(), c));
        }
        Table { columns }
    }

    /// The orbit table (`orbit.csv`; empty unless kept).
    pub fn orbit(&self) -> Table {
        let mut columns = self.keyed(&self.orbit_keys);
        columns.push(("period".into(), Column::Int(self.orbit_period.clone())));
        for (i, x) in self.orbit_x.iter().enumerate() {
            columns.push((format!("x{}_m", i + 1), Column::Float(x.clone())));
        }
        Table { columns }
    }

    /// The impact table (`impacts.csv`; empty unless kept).
    pub fn impacts(&self) -> Table {
        let mut columns = self.keyed(&self.impact_keys);
        columns.push(("time_s".into(), Column::Float(self.impact_time.clone())));
        columns.push(("contact".into(), Column::Int(self.impact_contact.clone())));
        columns.push((
            "rel_velocity_m_s".into(),
            Column::Float(self.impact_speed.clone()),
        ));
        Table { columns }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use crate::study::PointOptions;
    use crate::sweep::PointRunner;

    /// Every row of the tables is the point result it came from, in push order; a failed
    /// point is a summary row with its error and nothing in the other tables.
    #[test]
    fn columns_hold_the_points() {
        let options = PointOptions {
            transient_periods: 10,
            recorded_periods: 6,
            ..PointOptions::default()
        };
        let runner = PointRunner::new(Config::default(), options, false);
        let values = [0.75, -1.0, 0.6];
        let results: Vec<_> = values
            .iter()
            .map(|&v| runner.run(&[("omega_ratio", v)], None))
            .collect();
        let mut t = SweepColumns::new(&["param"], 3, 2, true);
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
}
