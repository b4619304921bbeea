//! A map's results as rows: the one definition of the tables the command line writes as
//! `curves.csv`, `codim2.csv` and `located.csv`, and that Python hands out as arrays, with
//! the keys' canonical names as column names.

use super::types::{BifurcationMap, MapCurve};
use crate::orbits::curve::{Codim2Kind, CurvePoint};
use crate::sweep::{Cell, Kind, Table};

/// Named, typed columns and their rows of cells.
#[derive(Debug, Clone, PartialEq)]
pub struct Rows {
    /// Column names.
    pub names: Vec<String>,
    /// Column kinds.
    pub kinds: Vec<Kind>,
    /// The rows, one cell per column.
    pub rows: Vec<Vec<Cell>>,
}

impl Rows {
    /// The same as columns.
    pub fn table(&self) -> Table {
        let mut t = Table::new(self.names.clone(), self.kinds.clone());
        for r in &self.rows {
            t.push_row(r.clone());
        }
        t
    }
}

fn contact_cell(contact: Option<usize>) -> Cell {
    contact.map_or(Cell::Missing, |k| Cell::Int(k as i64 + 1))
}

/// `curves.csv`: one row per point of every curve: `curve` (its index), the two keys by name,
/// `kind`, `period`, `contact` (grazing: 1-based), `condition` (zero to the tolerance),
/// `gap_minimum_m` (grazing), `arclength` (signed: negative on the half towards the second
/// key's first end), `max_abs_multiplier`, `multiplier_K_re`/`_im` (K = 1 … 2N, largest
/// modulus first), the section state `x1_m … xN_m`, `v1_m_s … vN_m_s` at t ≡ 0 and
/// `impacts_per_period_K` per contact, for a chain of `masses` masses and `contacts`
/// contacts.
pub fn curve_rows(map: &BifurcationMap, masses: usize, contacts: usize) -> Rows {
    let mut names: Vec<String> = vec!["curve".into(), map.x.clone(), map.y.clone()];
    names.extend(
        [
            "kind",
            "period",
            "contact",
            "condition",
            "gap_minimum_m",
            "arclength",
            "max_abs_multiplier",
        ]
        .map(String::from),
    );
    let mut kinds = vec![
        Kind::Int,
        Kind::Float,
        Kind::Float,
        Kind::Text,
        Kind::Int,
        Kind::Int,
        Kind::Float,
        Kind::Float,
        Kind::Float,
        Kind::Float,
    ];
    for k in 1..=2 * masses {
        names.push(format!("multiplier_{k}_re"));
        names.push(format!("multiplier_{k}_im"));
    }
    names.extend((1..=masses).map(|i| format!("x{i}_m")));
    names.extend((1..=masses).map(|i| format!("v{i}_m_s")));
    names.extend((1..=contacts).map(|k| format!("impacts_per_period_{k}")));
    kinds.resize(names.len(), Kind::Float);
    let rows = map
        .curves
        .iter()
        .enumerate()
        .flat_map(|(i, c)| c.points.iter().map(move |p| point_row(i, c, p, masses, contacts)))
        .collect();
    Rows { names, kinds, rows }
}

fn point_row(i: usize, c: &MapCurve, p: &CurvePoint, masses: usize, contacts: usize) -> Vec<Cell> {
    let mut row = vec![
        Cell::Int(i as i64),
        Cell::Float(p.parameter),
        Cell::Float(p.parameter2),
        Cell::Text(c.kind.name().into()),
        Cell::Int(i64::from(c.period)),
        contact_cell(c.contact),
        Cell::Float(p.condition),
        Cell::float(p.gap_minimum),
        Cell::Float(p.arclength),
        Cell::float(p.multipliers.first().map(|m| m.norm())),
    ];
    for k in 0..2 * masses {
        let m = p.multipliers.get(k);
        row.push(Cell::float(m.map(|m| m.re)));
        row.push(Cell::float(m.map(|m| m.im)));
    }
    let state = |v: &[f64]| {
        (0..masses)
            .map(|j| Cell::float(v.get(j).copied()))
            .collect::<Vec<_>>()
    };
    row.extend(state(&p.state.positions));
    row.extend(state(&p.state.velocities));
    row.extend((0..contacts).map(|k| Cell::float(p.impacts_per_period.get(k).copied())));
    row
}

/// `codim2.csv`: the codimension-two points of every curve: `curve`, `kind` (`grazing`,
/// `sequence_change`, `meets_KIND`), the two keys, `precision` (the bracket's width in the
/// scaled parameters), `contact` (grazing: 1-based), `max_abs_multiplier`.
pub fn codim2_rows(map: &BifurcationMap) -> Rows {
    let names: Vec<String> = [
        "curve",
        "kind",
        map.x.as_str(),
        map.y.as_str(),
        "precision",
        "contact",
        "max_abs_multiplier",
    ]
    .map(String::from)
    .to_vec();
    let kinds = vec![
        Kind::Int,
        Kind::Text,
        Kind::Float,
        Kind::Float,
        Kind::Float,
        Kind::Int,
        Kind::Float,
    ];
    let rows = map
        .curves
        .iter()
        .enumerate()
        .flat_map(|(i, c)| {
            c.codim2.iter().map(move |q| {
                let contact = match q.kind {
                    Codim2Kind::Grazing { contact } => Some(contact),
                    _ => None,
                };
                vec![
                    Cell::Int(i as i64),
                    Cell::Text(q.kind.name()),
                    Cell::Float(q.point.parameter),
                    Cell::Float(q.point.parameter2),
                    Cell::Float(q.precision),
                    contact_cell(contact),
                    Cell::float(q.point.multipliers.first().map(|m| m.norm())),
                ]
            })
        })
        .collect();
    Rows { names, kinds, rows }
}

/// `located.csv`: the bifurcations located on the seed branches: `seed` (its index), the two
/// keys, `kind`, `period`, `contact` (grazing: 1-based), `curve` (the curve it lies on;
/// empty where it was not followed).
pub fn located_rows(map: &BifurcationMap) -> Rows {
    let names: Vec<String> = [
        "seed",
        map.x.as_str(),
        map.y.as_str(),
        "kind",
        "period",
        "contact",
        "curve",
    ]
    .map(String::from)
    .to_vec();
    let kinds = vec![
        Kind::Int,
        Kind::Float,
        Kind::Float,
        Kind::Text,
        Kind::Int,
        Kind::Int,
        Kind::Int,
    ];
    let rows = map
        .located
        .iter()
        .map(|l| {
            vec![
                Cell::Int(l.seed as i64),
                Cell::Float(l.x),
                Cell::Float(l.y),
                Cell::Text(l.kind.name().into()),
                Cell::Int(i64::from(l.period)),
                contact_cell(l.contact),
                l.curve.map_or(Cell::Missing, |c| Cell::Int(c as i64)),
            ]
        })
        .collect();
    Rows { names, kinds, rows }
}
