//! Continuation branches for the orbit diagram: the periodic orbits followed over the
//! diagram's parameter range by the library's continuation ([`continue_config`], what
//! `vibrotribo continue` runs, with its options and defaults), with their stability, the
//! bifurcations on the way and, for drawing, each orbit's positions at t = kT.

use serde::{Deserialize, Serialize};
use vibrotribo::branch::{BranchOptions, config_family, continue_config};
use vibrotribo::config::Config;
use vibrotribo::orbits::{Cancel, ContinuationOptions, ShootingOptions};

use super::cancel::Ticket;
use super::error::ApiError;
use super::request::{Overrides, configure};
use crate::branch_picture::section_positions;
use crate::continuation::{branch_table, describe, end_text};

/// Most points per branch a request may ask for.
pub const MAX_POINTS: usize = 20_000;

/// `POST /api/branches`: the options of `vibrotribo continue`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BranchRequest {
    /// The overrides of the server's configuration.
    #[serde(default)]
    pub set: Overrides,
    /// The parameter (`continue --param`).
    pub param: String,
    /// Start of the branch (`--from`).
    pub from: f64,
    /// The other end of the range (`--to`).
    pub to: f64,
    /// Period of the first orbit, in excitation periods (`--period`; default: detected).
    #[serde(default)]
    pub period: Option<u32>,
    /// Periods simulated at `from` before shooting (`--transient`, default 200).
    #[serde(default)]
    pub transient: Option<u32>,
    /// Period doublings followed (`--doublings`).
    #[serde(default)]
    pub doublings: Option<u32>,
    /// Most points per branch (`--max-points`, at most [`MAX_POINTS`]).
    #[serde(default)]
    pub max_points: Option<usize>,
    /// No power along the branches (`--mechanics-only`).
    #[serde(default)]
    pub mechanics_only: bool,
    /// The client's sequence number of this request (see [`super::cancel`]).
    #[serde(default)]
    pub seq: Option<u64>,
}

/// One point of a branch, for drawing.
#[derive(Debug, Serialize)]
pub struct BranchPointView {
    /// The parameter's value.
    pub param: f64,
    /// Whether the orbit is stable (every Floquet multiplier inside the unit circle).
    pub stable: bool,
    /// Positions at t = kT: `sections[mass][k]`, m, k = 0 … period − 1.
    pub sections: Vec<Vec<f64>>,
}

/// One branch.
#[derive(Debug, Serialize)]
pub struct BranchView {
    /// Period of its orbits, in excitation periods.
    pub period: u32,
    /// How it ends, in words (as `continue.json`).
    pub end: String,
    /// Its points in the order followed.
    pub points: Vec<BranchPointView>,
}

/// One bifurcation.
#[derive(Debug, Serialize)]
pub struct BifurcationView {
    /// The branch it lies on (0-based, as `bifurcations.csv`).
    pub branch: usize,
    /// Its kind (`fold`, `period_doubling`, `grazing`, … as `bifurcations.csv`).
    pub kind: &'static str,
    /// Its detail in words.
    pub detail: String,
    /// The parameter's value there.
    pub param: f64,
    /// Positions at t = kT of the orbit there: `sections[mass][k]`, m.
    pub sections: Vec<Vec<f64>>,
}

/// What `POST /api/branches` answers.
#[derive(Debug, Serialize)]
pub struct BranchesView {
    /// `branch.csv`'s header.
    pub columns: Vec<String>,
    /// `branch.csv`'s rows, each cell the text `continue` writes.
    pub rows: Vec<Vec<String>>,
    /// The branches, for drawing.
    pub branches: Vec<BranchView>,
    /// The bifurcations, for drawing.
    pub bifurcations: Vec<BifurcationView>,
}

/// The options of `request`, checked as `continue` checks its own; the continuation stops at
/// its next step once `ticket` is stopped.
fn options(request: &BranchRequest, ticket: &Ticket) -> Result<BranchOptions, ApiError> {
    if request.period == Some(0) {
        return Err(ApiError::bad("period must be at least 1"));
    }
    if !(request.from.is_finite() && request.to.is_finite()) || request.from == request.to {
        return Err(ApiError::bad("from and to must be finite and different"));
    }
    let d = BranchOptions::default();
    let max_points = request.max_points.unwrap_or(d.continuation.max_points);
    if max_points == 0 || max_points > MAX_POINTS {
        return Err(ApiError::bad(format!(
            "max_points must be between 1 and {MAX_POINTS}, got {max_points}"
        )));
    }
    Ok(BranchOptions {
        transient: request.transient.unwrap_or(d.transient),
        period: request.period,
        continuation: ContinuationOptions {
            doubling_depth: request.doublings.unwrap_or(d.continuation.doubling_depth),
            max_points,
            shooting: ShootingOptions {
                cancel: {
                    let ticket = ticket.clone();
                    Cancel::new(move || ticket.stopped())
                },
                ..d.continuation.shooting
            },
            ..d.continuation
        },
    })
}

/// The continuation of `request` on `base`, as `vibrotribo continue` computes it; 409 when
/// `ticket` is stopped (checked at every continuation step and between the later steps).
pub fn branches(base: &Config, request: &BranchRequest, ticket: &Ticket) -> Result<BranchesView, ApiError> {
    let options = options(request, ticket)?;
    let config = configure(base, &request.set)?;
    config.check_uncoupled("continue").map_err(ApiError::bad)?;
    config
        .check_periodic("continuation of periodic orbits (`continue`)")
        .map_err(ApiError::bad)?;
    if ticket.stopped() {
        return Err(ApiError::superseded());
    }
    let key = request.param.as_str();
    let result = match continue_config(&config, key, request.from, request.to, None, &options) {
        Ok(result) => result,
        Err(_) if ticket.stopped() => return Err(ApiError::superseded()),
        Err(e) => return Err(ApiError::bad(e)),
    };
    if ticket.stopped() {
        return Err(ApiError::superseded());
    }
    let power = (!request.mechanics_only).then(|| {
        vibrotribo::branch::branch_powers(&config, key, &result, || {
            if ticket.stopped() {
                std::ops::ControlFlow::Break(())
            } else {
                std::ops::ControlFlow::Continue(())
            }
        })
    });
    if ticket.stopped() {
        return Err(ApiError::superseded());
    }
    let (columns, rows) = branch_table(&config, &result, power.as_deref());
    let family = config_family(&config, key);
    let masses = config.chain().len();
    let sections = |parameter: f64, state: &vibrotribo::ChainState, period: u32| {
        (0..masses)
            .map(|m| section_positions(&family(parameter), state, period, m, &config))
            .collect::<Vec<_>>()
    };
    let mut views = Vec::with_capacity(result.branches.len());
    let mut bifurcations = Vec::new();
    for (i, b) in result.branches.iter().enumerate() {
        if ticket.stopped() {
            return Err(ApiError::superseded());
        }
        views.push(BranchView {
            period: b.period,
            end: end_text(&b.end),
            points: b
                .points
                .iter()
                .map(|p| BranchPointView {
                    param: p.parameter,
                    stable: p.stable,
                    sections: sections(p.parameter, &p.state, b.period),
                })
                .collect(),
        });
        for f in &b.bifurcations {
            let (kind, detail) = describe(&f.kind);
            bifurcations.push(BifurcationView {
                branch: i,
                kind,
                detail,
                param: f.parameter,
                sections: sections(f.parameter, &f.point.state, b.period),
            });
        }
    }
    Ok(BranchesView {
        columns,
        rows,
        branches: views,
        bifurcations,
    })
}
