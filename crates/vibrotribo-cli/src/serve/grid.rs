//! The orbit diagram, the power map and the basins: the points of a one- or two-parameter
//! grid run by the point runner of `vibrotribo sweep` and `vibrotribo map` (same options,
//! same checks, same limits), or the starts of `vibrotribo basins` fingerprinted and, once
//! all are in, classified into attractors as `basins` classifies them; streamed as
//! newline-delimited JSON as they finish, coarse to fine.

use std::convert::Infallible;
use std::ops::ControlFlow;
use std::time::Instant;

use axum::body::Body;
use axum::http::header;
use axum::response::{IntoResponse, Response};
use serde::{Deserialize, Serialize};
use tokio::sync::mpsc;
use vibrotribo::analysis::Periodicity;
use vibrotribo::attractors::{
    AttractorOptions, Classification, DEFAULT_START_PERIODS, Fingerprint, SectionScale, StartRunner,
    classify, initial_condition_index,
};
use vibrotribo::config::Config;
use vibrotribo::study::{DEFAULT_PERIOD_TOLERANCE, DEFAULT_SETTLE_CAP, PointResult, SettleMode};
use vibrotribo::sweep::{Delivery, PointRunner, SweepError, grid, run_chunks};

use super::cancel::{Guard, Ticket};
use super::error::ApiError;
use super::request::{Overrides, configure};
use crate::job::{RunArgs, check_all, check_distinct, estimate_point_memory};
use crate::limits;

/// One axis of a grid: the key and its values, equally spaced (as `sweep --param --from --to
/// --steps`).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Axis {
    /// The parameter (any key `sweep --param` accepts).
    pub param: String,
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// Number of values.
    pub steps: usize,
}

/// `POST /api/orbit` (one axis) and `POST /api/map` (two axes).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridRequest {
    /// The overrides of the server's configuration.
    #[serde(default)]
    pub set: Overrides,
    /// The axis (orbit diagram), or the x axis (map).
    pub x: Axis,
    /// The y axis of a map.
    #[serde(default)]
    pub y: Option<Axis>,
    /// Transient periods per value (default: the configuration's, as `sweep --transient`).
    #[serde(default)]
    pub transient: Option<u64>,
    /// Recorded periods per value (default: the configuration's, as `sweep --recorded`).
    #[serde(default)]
    pub recorded: Option<u64>,
    /// Mechanics only (as `--mechanics-only`).
    #[serde(default)]
    pub mechanics_only: bool,
    /// The client's sequence number of this request (see [`super::cancel`]).
    #[serde(default)]
    pub seq: Option<u64>,
    /// Basins only: `basins --cell` (default 0.05).
    #[serde(default)]
    pub cell: Option<f64>,
    /// Basins only: `basins --section-tolerance` (default 1e-3).
    #[serde(default)]
    pub section_tolerance: Option<f64>,
    /// Basins only: `basins --match-tolerance` (default 3e-3).
    #[serde(default)]
    pub match_tolerance: Option<f64>,
}

/// What a grid computes at each of its points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GridKind {
    /// The orbit diagram: one parameter, each value run as `sweep` runs it.
    Orbit,
    /// The power map: two parameters, each point run as `map` runs it.
    Map,
    /// The basins: two initial conditions, each start fingerprinted as `basins` does.
    Basins,
}

/// The work of a grid's points.
enum Work {
    /// `sweep` and `map`: the point runner.
    Points(PointRunner),
    /// `basins`: the start runner and the settings that classify the fingerprints.
    Starts {
        starts: StartRunner,
        options: AttractorOptions,
        scale: SectionScale,
    },
}

/// What one point gave.
enum Outcome {
    Point(Box<PointResult>),
    Start(Fingerprint),
}

/// One streamed line.
#[derive(Debug, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
enum Line<'a> {
    /// First: the grid's values and the chain's size.
    Start {
        xs: &'a [f64],
        ys: &'a [f64],
        masses: usize,
    },
    /// A finished point.
    Point(Box<PointLine>),
    /// Basins, when every start has run: the classification of `basins` (grid order: x
    /// fastest, as `basins.csv`).
    Classes(ClassesLine),
    /// Last: how many points were delivered, whether all of them, and the time taken.
    End {
        done: usize,
        complete: bool,
        elapsed_s: f64,
    },
}

/// A finished point: its indices and values, the stroboscopic positions of its recorded
/// periods (`x[j·N + i]`, m), its motion (as `summary.json` states it), the average power
/// (W) and impacts per period, or the error that stopped it.
#[derive(Debug, Serialize)]
struct PointLine {
    i: usize,
    j: usize,
    x: f64,
    y: Option<f64>,
    strobe: Vec<f64>,
    motion: Option<vibrotribo::report::MotionRecord>,
    period: Option<usize>,
    average_power_w: Option<f64>,
    impacts_per_period: Option<f64>,
    error: Option<String>,
}

/// The attractors of a basin grid and each start's: the numbers of `basins.csv` and
/// `attractors.csv`.
#[derive(Debug, Serialize)]
struct ClassesLine {
    /// The attractor of each start (1-based, as `basins.csv`'s `attractor`; null: the start
    /// failed), x fastest.
    labels: Vec<Option<usize>>,
    /// The attractors in the order of their first start (`attractors.csv`'s rows).
    attractors: Vec<AttractorLine>,
}

/// One attractor: `attractors.csv`'s columns.
#[derive(Debug, Serialize)]
struct AttractorLine {
    attractor: usize,
    period: usize,
    starts: usize,
    fraction: f64,
    fraction_se: f64,
    impacts_per_period: f64,
    average_power_w: Option<f64>,
    power_se_w: Option<f64>,
    /// Positions then velocities on the section, m and m/s.
    state: Vec<f64>,
}

impl ClassesLine {
    fn new(c: &Classification, masses: usize) -> Self {
        ClassesLine {
            labels: c.labels.iter().map(|l| l.map(|a| a + 1)).collect(),
            attractors: c
                .attractors
                .iter()
                .enumerate()
                .map(|(a, at)| {
                    let (fraction, fraction_se) = c.fraction(a);
                    AttractorLine {
                        attractor: a + 1,
                        period: at.period,
                        starts: at.starts,
                        fraction,
                        fraction_se,
                        impacts_per_period: at.impacts_per_period,
                        average_power_w: at.power_w,
                        power_se_w: at.power_se,
                        state: at.points[..2 * masses].to_vec(),
                    }
                })
                .collect(),
        }
    }
}

impl PointLine {
    fn new((i, j): (usize, usize), (x, y): (f64, Option<f64>), r: &Result<Outcome, SweepError>) -> Self {
        match r {
            Ok(Outcome::Start(f)) => PointLine {
                i,
                j,
                x,
                y,
                strobe: Vec::new(),
                motion: None,
                period: Some(f.period),
                average_power_w: f.power_w,
                impacts_per_period: Some(f.impacts_per_period),
                error: None,
            },
            Ok(Outcome::Point(p)) => PointLine {
                i,
                j,
                x,
                y,
                motion: p.motion.as_ref().map(vibrotribo::report::MotionRecord::of),
                period: match p.periodicity {
                    Some(Periodicity::Periodic { period, .. }) => Some(period),
                    _ => None,
                },
                average_power_w: p.average_power_w,
                impacts_per_period: Some(p.impacts_per_period.iter().sum()),
                strobe: p.strobe.clone(),
                error: p.electrical_error.as_ref().map(ToString::to_string),
            },
            Err(e) => PointLine {
                i,
                j,
                x,
                y,
                strobe: Vec::new(),
                motion: None,
                period: None,
                average_power_w: None,
                impacts_per_period: None,
                error: Some(e.to_string()),
            },
        }
    }
}

/// The rank of index `k` in a coarse-to-fine order: indices divisible by a higher power of
/// two come first.
fn coarseness(k: usize) -> u32 {
    if k == 0 { u32::MAX } else { k.trailing_zeros() }
}

/// A checked grid job, ready to stream.
pub struct GridJob {
    work: Work,
    keys: Vec<String>,
    xs: Vec<f64>,
    ys: Vec<f64>,
    /// (i, j) in the order computed: coarse to fine.
    order: Vec<(usize, usize)>,
}

/// The run settings of `vibrotribo sweep`, `map` and `basins` with their default options.
fn run_args(request: &GridRequest) -> Result<RunArgs, ApiError> {
    Ok(RunArgs {
        transient: request.transient,
        recorded: request.recorded,
        mechanics_only: request.mechanics_only,
        period_tolerance: DEFAULT_PERIOD_TOLERANCE,
        floquet: false,
        settle: "auto".parse::<SettleMode>().map_err(ApiError::bad)?,
        settle_cap: DEFAULT_SETTLE_CAP,
        threads: None,
        quiet: true,
        allow_large: false,
        force: false,
    })
}

/// The start runner of `vibrotribo basins` with its default options (and the request's
/// tolerances), checked as `basins` checks its axes and configuration.
fn starts(config: Config, request: &GridRequest) -> Result<Work, ApiError> {
    let masses = config.chain().len();
    config.check_uncoupled("basins").map_err(ApiError::bad)?;
    config
        .check_periodic("basins of attraction (`basins`)")
        .map_err(ApiError::bad)?;
    let y = request.y.as_ref().map_or("", |y| y.param.as_str());
    for (axis, key) in [("x", request.x.param.as_str()), ("y", y)] {
        initial_condition_index(key, masses).map_err(|e| ApiError::bad(format!("{axis}: {e}")))?;
    }
    if request.x.param == y {
        return Err(ApiError::bad("x and y are the same key"));
    }
    let d = AttractorOptions::default();
    let options = AttractorOptions {
        period_tolerance: request.section_tolerance.unwrap_or(1e-3),
        match_tolerance: request.match_tolerance.unwrap_or(3e-3),
        cell: request.cell.unwrap_or(0.05),
        ..d
    };
    let runner = run_args(request)?
        .runner_or(config, DEFAULT_START_PERIODS)
        .map_err(|e| ApiError::bad_chain(&e))?;
    let starts = StartRunner::new(runner, options.clone()).map_err(ApiError::bad)?;
    let scale = SectionScale::of(starts.point_runner().base().chain());
    Ok(Work::Starts {
        starts,
        options,
        scale,
    })
}

/// The values of `axis`, checked as `sweep` checks `--from --to --steps`.
fn axis_values(axis: &Axis) -> Result<Vec<f64>, ApiError> {
    if axis.steps == 0 {
        return Err(ApiError::bad(format!("{}: steps must be at least 1", axis.param)));
    }
    if !axis.from.is_finite() || !axis.to.is_finite() {
        return Err(ApiError::bad(format!(
            "{}: from and to must be finite numbers",
            axis.param
        )));
    }
    limits::check_grid("steps", axis.steps as f64).map_err(|e| ApiError::bad_chain(&e))?;
    let values = grid(axis.from, axis.to, axis.steps);
    check_distinct(&format!("{} from/to/steps", axis.param), &values).map_err(|e| ApiError::bad_chain(&e))?;
    Ok(values)
}

impl GridJob {
    /// The job of `request` on `base`, checked as `sweep` and `map` check theirs: the grid's
    /// size, every point's configuration, the memory of the points running at once.
    pub fn new(base: &Config, request: &GridRequest, kind: GridKind) -> Result<Self, ApiError> {
        if request.y.is_some() != (kind != GridKind::Orbit) {
            return Err(ApiError::bad(if kind == GridKind::Orbit {
                "an orbit diagram has one axis, x (a map: POST /api/map)"
            } else {
                "a map and the basins need the axes x and y"
            }));
        }
        let tolerances = [request.cell, request.section_tolerance, request.match_tolerance];
        if kind != GridKind::Basins && tolerances.iter().any(Option::is_some) {
            return Err(ApiError::bad(
                "cell, section_tolerance and match_tolerance are settings of the basins (POST /api/basins)",
            ));
        }
        let config = configure(base, &request.set)?;
        let work = match kind {
            GridKind::Basins => starts(config, request)?,
            _ => Work::Points(
                run_args(request)?
                    .runner(config)
                    .map_err(|e| ApiError::bad_chain(&e))?,
            ),
        };
        let xs = axis_values(&request.x)?;
        let (ys, mut keys) = (Vec::new(), vec![request.x.param.clone()]);
        let ys = match &request.y {
            Some(y) => {
                keys.push(y.param.clone());
                axis_values(y)?
            }
            None => ys,
        };
        let cells = xs.len() as f64 * ys.len().max(1) as f64;
        limits::check_grid("the grid", cells).map_err(|e| ApiError::bad_chain(&e))?;
        let mut order: Vec<(usize, usize)> = (0..xs.len())
            .flat_map(|i| (0..ys.len().max(1)).map(move |j| (i, j)))
            .collect();
        order.sort_by_key(|&(i, j)| std::cmp::Reverse(coarseness(i).min(coarseness(j))));
        let job = GridJob {
            work,
            keys,
            xs,
            ys,
            order,
        };
        // `basins` runs every start and counts a start that cannot run as failed.
        if let Work::Points(runner) = &job.work {
            check_all(runner, &job.order, |&p| job.point_keys(p)).map_err(|e| ApiError::bad_chain(&e))?;
        }
        let threads = rayon::current_num_threads() as f64;
        limits::check_memory(
            "one point of the grid (transient + recorded periods)",
            estimate_point_memory(job.point_runner()) * threads * 4.0,
            false,
        )
        .map_err(|e| ApiError::bad_chain(&e))?;
        Ok(job)
    }

    fn point_runner(&self) -> &PointRunner {
        match &self.work {
            Work::Points(runner) => runner,
            Work::Starts { starts, .. } => starts.point_runner(),
        }
    }

    /// Runs the point at `(i, j)`.
    fn run_point(&self, p: (usize, usize)) -> Result<Outcome, SweepError> {
        let keys = self.point_keys(p);
        match &self.work {
            Work::Points(runner) => runner.run(&keys, None).map(|p| Outcome::Point(Box::new(p))),
            Work::Starts { starts, .. } => starts.run(&keys, None).map(Outcome::Start),
        }
    }

    fn point_keys(&self, (i, j): (usize, usize)) -> Vec<(&str, f64)> {
        let mut keys = vec![(self.keys[0].as_str(), self.xs[i])];
        if let (Some(key), Some(&y)) = (self.keys.get(1), self.ys.get(j)) {
            keys.push((key.as_str(), y));
        }
        keys
    }

    /// Runs the points on the rayon pool (called on a blocking thread), sending each line
    /// to `tx`; stops when the ticket is stopped or nobody receives.
    fn produce(&self, tx: &mpsc::Sender<String>, ticket: &Ticket) {
        let started = Instant::now();
        let send = |line: &Line<'_>| match serde_json::to_string(line) {
            Ok(mut text) => {
                text.push('\n');
                tx.blocking_send(text).is_ok()
            }
            Err(_) => false,
        };
        let start = Line::Start {
            xs: &self.xs,
            ys: &self.ys,
            masses: self.point_runner().masses(),
        };
        if !send(&start) {
            return;
        }
        // The first chunk holds one point per thread, so that the first points arrive after
        // one point's time; the later ones are larger, so that few threads wait for the
        // slowest point of a chunk.
        let threads = rayon::current_num_threads();
        let (head, tail) = self.order.split_at(threads.min(self.order.len()));
        let mut done = 0;
        // Basins: each start's fingerprint in grid order (x fastest), classified at the end.
        let nx = self.xs.len();
        let mut fingerprints: Vec<Option<Fingerprint>> = vec![None; self.order.len()];
        for (k, (points, chunk)) in [(head, threads), (tail, 8 * threads)].into_iter().enumerate() {
            // The head stopped early (superseded, client gone): the tail is not started.
            if k == 1 && done < head.len() {
                break;
            }
            done += run_chunks(
                points,
                chunk,
                |&p| {
                    if ticket.stopped() {
                        return Err(None);
                    }
                    self.run_point(p).map_err(Some)
                },
                |d| match d {
                    Delivery::Point(&(i, j), r) => {
                        let r = match r {
                            Err(None) => return ControlFlow::Break(()),
                            Ok(p) => Ok(p),
                            Err(Some(e)) => Err(e),
                        };
                        let line = PointLine::new((i, j), (self.xs[i], self.ys.get(j).copied()), &r);
                        if let Ok(Outcome::Start(f)) = r {
                            fingerprints[j * nx + i] = Some(f);
                        }
                        if !send(&Line::Point(Box::new(line))) || ticket.stopped() {
                            ControlFlow::Break(())
                        } else {
                            ControlFlow::Continue(())
                        }
                    }
                    Delivery::Chunk(_) if ticket.stopped() => ControlFlow::Break(()),
                    Delivery::Chunk(_) => ControlFlow::Continue(()),
                },
            );
        }
        let complete = done == self.order.len() && !ticket.stopped();
        if let (true, Work::Starts { options, scale, .. }) = (complete, &self.work) {
            let classes = classify(&fingerprints, scale, options);
            if !send(&Line::Classes(ClassesLine::new(&classes, scale.masses))) {
                return;
            }
        }
        send(&Line::End {
            done,
            complete,
            elapsed_s: started.elapsed().as_secs_f64(),
        });
    }

    /// The streamed answer: `application/x-ndjson`, one [`Line`] a line; the work stops when
    /// the response is dropped (the guard goes with it) or the ticket is superseded.
    pub fn stream(self, ticket: Ticket, guard: Guard) -> Response {
        let (tx, rx) = mpsc::channel::<String>(256);
        tokio::task::spawn_blocking(move || self.produce(&tx, &ticket));
        let lines = futures_util::stream::unfold((rx, guard), |(mut rx, guard)| async move {
            let line = rx.recv().await?;
            Some((Ok::<_, Infallible>(line), (rx, guard)))
        });
        (
            [(header::CONTENT_TYPE, "application/x-ndjson")],
            Body::from_stream(lines),
        )
            .into_response()
    }
}
