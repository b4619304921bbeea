//! [`Sensitivity`]: an observer that accumulates the state-transition matrix of a run.

use nalgebra::DMatrix;

use super::error::{NonSmoothPoint, SensitivityError};
use super::field::ChainField;
use super::saltation::{
    Before, Impact, apply_impact, apply_time_shift, chatter_time_row, impact_time_row, propagate,
};
use super::stops::{
    WallImpact, apply_wall_impact, is_closed, stop_gap, wall_chatter_time_row, wall_impact_time_row,
};
use crate::dynamics::{ClusterFlow, Event, EventKind, Flow, Observer, Simulator, StateView};
use crate::model::ChainParams;

/// Settings of [`Sensitivity`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SensitivityOptions {
    /// An impact whose closing speed is below `grazing_speed` times the chain's speed scale
    /// ([`speed_scale`]) is reported as a grazing point
    /// ([`NonSmoothPoint::Grazing`]): the saltation matrix grows like 1/speed there and the
    /// flow map is not differentiable at speed 0. Dimensionless. Default 1e-8.
    pub grazing_speed: f64,
    /// At an impact, another open contact whose gap is below `contact_gap` times the chain's
    /// length scale ([`length_scale`]) makes it a simultaneous event
    /// ([`NonSmoothPoint::Simultaneous`]). Dimensionless. Default 1e-9.
    pub contact_gap: f64,
    /// Keep every event with the gradient of its time with respect to the initial state
    /// ([`Sensitivity::events`]). Default false.
    pub record_events: bool,
}

impl Default for SensitivityOptions {
    fn default() -> Self {
        SensitivityOptions {
            grazing_speed: 1e-8,
            contact_gap: 1e-9,
            record_events: false,
        }
    }
}

/// The chain's length scale `L = Σδ_k + A`, m: the size of the motion the tolerances of the
/// sensitivities and periodic orbits are relative to.
pub fn length_scale(params: &ChainParams) -> f64 {
    (params.gaps.iter().sum::<f64>() + params.excitation.amplitude).max(f64::MIN_POSITIVE)
}

/// The chain's speed scale `L·max(ω, max_i √(k_i/m_i))`, m/s (see [`length_scale`]).
pub fn speed_scale(params: &ChainParams) -> f64 {
    let wn = params
        .masses
        .iter()
        .zip(&params.stiffness)
        .map(|(m, k)| (k / m).sqrt())
        .fold(params.omega(), f64::max);
    length_scale(params) * wn
}

/// One event seen by a [`Sensitivity`] with [`SensitivityOptions::record_events`].
#[derive(Debug, Clone, PartialEq)]
pub struct EventSensitivity {
    /// The event.
    pub event: Event,
    /// Gradient of the event's time with respect to the initial state
    /// `[x₁ … x_N, v₁ … v_N]` (s/m, s/(m/s)), for impacts and chatter accumulation points;
    /// `None` for sticks and releases.
    pub time_gradient: Option<Vec<f64>>,
}

/// Observer that accumulates the state-transition matrix `Φ = ∂z(t)/∂z(t₀)` of the
/// non-smooth flow, `z = [x₁ … x_N, v₁ … v_N]` in m and m/s, from the start of the first
/// piece of flow it sees to the end of the last (see the [module docs](super) for the
/// mathematics).
///
/// ```
/// use vibrotribo::sensitivity::{Sensitivity, SensitivityOptions};
/// use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator};
///
/// let params = ChainParams::default();
/// let mut sim = Simulator::new(&params, &ChainState::at_rest(3), SimOptions::default())?;
/// let mut stm = Sensitivity::new(&params, SensitivityOptions::default());
/// sim.run_until(2.0 * params.period(), &mut stm)?;
/// let phi = stm.stm()?;
/// assert_eq!(phi.shape(), (6, 6));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct Sensitivity {
    field: ChainField,
    options: SensitivityOptions,
    grazing_speed: f64,
    contact_gap: f64,
    phi: DMatrix<f64>,
    span: Option<(f64, f64)>,
    /// Clusters of the latest piece of flow: the structure before a following event.
    last: Vec<ClusterFlow>,
    /// Events since the latest piece of flow (one simulator step) and the state after them.
    batch: Vec<Event>,
    post_x: Vec<f64>,
    post_v: Vec<f64>,
    pre_x: Vec<f64>,
    pre_v: Vec<f64>,
    f_pre: Vec<f64>,
    f_post: Vec<f64>,
    row: Vec<f64>,
    scratch: Vec<f64>,
    /// Per contact: the gradient of a scheduled chatter accumulation time with respect to the
    /// initial state (`chatter_rows[k·2N ..]`), if one is scheduled.
    chatter_rows: Vec<f64>,
    chatter_set: Vec<bool>,
    failure: Option<NonSmoothPoint>,
    events: Vec<EventSensitivity>,
    /// Number of contacts (N − 1, or N + 1 with stops).
    contacts: usize,
    /// Per contact: its restitution.
    restitutions: Vec<f64>,
}

impl Sensitivity {
    /// An observer for a chain with parameters `params` (those of the simulator it watches).
    pub fn new(params: &ChainParams, options: SensitivityOptions) -> Self {
        let field = ChainField::new(params);
        let n = field.len();
        let dim = 2 * n;
        Sensitivity {
            grazing_speed: options.grazing_speed * speed_scale(params),
            contact_gap: options.contact_gap * length_scale(params),
            field,
            options,
            phi: DMatrix::identity(dim, dim),
            span: None,
            last: Vec::with_capacity(n),
            batch: Vec::new(),
            post_x: vec![0.0; n],
            post_v: vec![0.0; n],
            pre_x: vec![0.0; n],
            pre_v: vec![0.0; n],
            f_pre: vec![0.0; dim],
            f_post: vec![0.0; dim],
            row: vec![0.0; dim],
            scratch: vec![0.0; 3 * dim],
            chatter_rows: vec![0.0; params.contact_count() * dim],
            chatter_set: vec![false; params.contact_count()],
            failure: None,
            events: Vec::new(),
            contacts: params.contact_count(),
            restitutions: (0..params.contact_count())
                .map(|k| params.contact_restitution(k))
                .collect(),
        }
    }

    /// An observer for the chain `sim` simulates.
    pub fn for_simulator(sim: &Simulator, options: SensitivityOptions) -> Self {
        Self::new(sim.params(), options)
    }

    /// Starts over: Φ = I from the next piece of flow on.
    pub fn reset(&mut self) {
        self.span = None;
        self.batch.clear();
        self.chatter_set.fill(false);
        self.failure = None;
        self.events.clear();
    }

    /// Starts a new product at the end of the latest piece of flow: Φ ← I, so that from
    /// there on [`stm`](Self::stm) is `∂z(t)/∂z(t₁)` with `t₁` the restart time (products of
    /// Φ over consecutive intervals, as a Lyapunov spectrum's re-orthonormalisation needs).
    /// Unlike [`reset`](Self::reset), events reported after the restart are applied as usual.
    ///
    /// Refuses (returns false, changes nothing) where Φ over the interval so far cannot be
    /// split there: right after an event (call it after a piece of flow), while a chatter jump
    /// is scheduled (its time depends on the state at the impact that started it, which no
    /// matrix at `t₁` carries; see [`chatter_pending`](Self::chatter_pending)), after a
    /// non-differentiable point, or before anything was observed.
    pub fn restart(&mut self) -> bool {
        if self.failure.is_some() || !self.batch.is_empty() || self.chatter_pending() {
            return false;
        }
        let Some(span) = &mut self.span else {
            return false;
        };
        span.0 = span.1;
        self.phi.fill_with_identity();
        true
    }

    /// Whether a chatter accumulation-point jump started by an observed impact is still to
    /// come (its time's gradient is held until then).
    pub fn chatter_pending(&self) -> bool {
        self.chatter_set.iter().any(|&s| s)
    }

    /// The time interval `(t₀, t)` observed so far, s.
    pub fn span(&self) -> Option<(f64, f64)> {
        self.span
    }

    /// The first non-differentiable point met, if any.
    pub fn non_smooth(&self) -> Option<&NonSmoothPoint> {
        self.failure.as_ref()
    }

    /// The events seen, with the gradients of their times (empty unless
    /// [`SensitivityOptions::record_events`]).
    pub fn events(&self) -> &[EventSensitivity] {
        &self.events
    }

    /// The state-transition matrix `∂z(t)/∂z(t₀)` over [`span`](Self::span), 2N × 2N.
    ///
    /// Errors if the run met a non-differentiable point, observed nothing, or ended right
    /// after an event.
    pub fn stm(&self) -> Result<&DMatrix<f64>, SensitivityError> {
        if let Some(p) = &self.failure {
            return Err(p.clone().into());
        }
        if let Some(e) = self.batch.first() {
            return Err(SensitivityError::Unfinished { time: e.time });
        }
        if self.span.is_none() {
            return Err(SensitivityError::Empty);
        }
        Ok(&self.phi)
    }

    /// Applies the pending event batch; `post` are the clusters after it.
    fn finish_batch(&mut self, post: &[ClusterFlow]) {
        let t = self.batch[0].time;
        let n = self.field.len();
        let ph = self.field.forcing.phase(t);
        for c in &self.last {
            let (s, v) = c.oscillator.state(t, ph);
            let base = self.field.offsets[c.first];
            for i in c.first..=c.last {
                self.pre_x[i] = s + (self.field.offsets[i] - base);
                self.pre_v[i] = v;
            }
        }
        self.field
            .fill(&self.last, &self.pre_x, &self.pre_v, t, &mut self.f_pre);
        self.field
            .fill(post, &self.post_x, &self.post_v, t, &mut self.f_post);
        let outcome = self.apply_batch(post, t);
        if let Err(p) = outcome {
            self.failure = Some(p);
        }
        if self.options.record_events {
            // Impacts and chatter ends wrote their gradient into `row`; see apply_batch.
            for e in &self.batch {
                let gradient = match e.kind {
                    EventKind::Impact | EventKind::Chatter if self.failure.is_none() => {
                        Some(self.row.clone())
                    }
                    _ => None,
                };
                self.events.push(EventSensitivity {
                    event: *e,
                    time_gradient: gradient,
                });
            }
        }
        self.batch.clear();
        debug_assert_eq!(self.phi.nrows(), 2 * n);
    }

    /// Classifies the batch and applies its saltation to Φ (module docs); leaves the
    /// gradient of the event time in `row` for impacts and chatter ends.
    fn apply_batch(&mut self, post: &[ClusterFlow], t: f64) -> Result<(), NonSmoothPoint> {
        let dim = 2 * self.field.len();
        let simultaneous = |batch: &[Event]| {
            let mut contacts: Vec<usize> = batch.iter().map(|e| e.contact).collect();
            contacts.sort_unstable();
            contacts.dedup();
            NonSmoothPoint::Simultaneous { time: t, contacts }
        };
        let count = |kind: EventKind| self.batch.iter().filter(|e| e.kind == kind).count();
        let impacts = count(EventKind::Impact);
        if impacts > 1 {
            return Err(simultaneous(&self.batch));
        }
        if impacts == 1 {
            let e = *self
                .batch
                .iter()
                .find(|e| e.kind == EventKind::Impact)
                .expect("one impact");
            let k = e.contact;
            if e.velocity_before < self.grazing_speed {
                return Err(NonSmoothPoint::Grazing {
                    time: t,
                    contact: k,
                    speed: e.velocity_before,
                });
            }
            let stuck = self
                .batch
                .iter()
                .any(|b| b.kind == EventKind::Stick && b.contact == k);
            let others = self
                .batch
                .iter()
                .any(|b| b.contact != k || !matches!(b.kind, EventKind::Impact | EventKind::Stick));
            if others || !self.same_closures(post, Some(k)) {
                return Err(simultaneous(&self.batch));
            }
            let n = self.field.len();
            for j in 0..self.contacts {
                let gap = if j + 1 < n {
                    self.field.gaps[j] - (self.pre_x[j + 1] - self.pre_x[j])
                } else {
                    stop_gap(&self.field, j, &self.pre_x, t)
                };
                if j != k && !is_closed(&self.last, n, j) && gap < self.contact_gap {
                    return Err(NonSmoothPoint::Simultaneous {
                        time: t,
                        contacts: vec![k.min(j), k.max(j)],
                    });
                }
            }
            let merged = is_closed(post, n, k);
            if let Some(wall) = WallImpact::classify(&self.field, &self.last, k, &self.pre_v, t) {
                let r = self.restitutions[k];
                if merged && !stuck {
                    wall_chatter_time_row(
                        &self.field,
                        &wall,
                        r,
                        t,
                        &self.pre_x,
                        &self.pre_v,
                        &self.f_pre,
                        &mut self.row,
                        &mut self.scratch,
                    );
                    row_times(
                        &self.row,
                        &self.phi,
                        &mut self.chatter_rows[k * dim..(k + 1) * dim],
                    );
                    self.chatter_set[k] = true;
                }
                wall_impact_time_row(&wall, &self.f_pre, &mut self.scratch[..dim]);
                row_times(&self.scratch[..dim], &self.phi, &mut self.row);
                let r = if merged { 0.0 } else { r };
                apply_wall_impact(
                    &mut self.phi,
                    &self.field,
                    &wall,
                    r,
                    t,
                    &self.f_pre,
                    &self.f_post,
                    &mut self.scratch,
                );
                return Ok(());
            }
            let upper = self.field.cluster_of(&self.last, k);
            let lower = self.field.cluster_of(&self.last, k + 1);
            let (_, v_u) = self.field.coordinates(&upper, &self.pre_x, &self.pre_v);
            let (_, v_l) = self.field.coordinates(&lower, &self.pre_x, &self.pre_v);
            let imp = Impact {
                k,
                upper,
                lower,
                closing: v_l - v_u,
            };
            // After the impact the two sides either move on apart (Newton's law with μ), or
            // merge: stuck (plastic) or jumping over a chatter tail (plastic until t_acc).
            if merged && !stuck {
                let pre = Before {
                    t,
                    x: &self.pre_x,
                    v: &self.pre_v,
                    f: &self.f_pre,
                };
                chatter_time_row(&self.field, &imp, &pre, &mut self.row, &mut self.scratch);
                row_times(
                    &self.row,
                    &self.phi,
                    &mut self.chatter_rows[k * dim..(k + 1) * dim],
                );
                self.chatter_set[k] = true;
            }
            impact_time_row(&imp, &mut self.scratch[..dim]);
            row_times(&self.scratch[..dim], &self.phi, &mut self.row);
            let mu = if merged { 0.0 } else { self.field.restitution };
            apply_impact(
                &mut self.phi,
                &self.field,
                &imp,
                mu,
                &self.f_pre,
                &self.f_post,
                &mut self.scratch,
            );
            return Ok(());
        }
        if let Some(e) = self.batch.iter().find(|e| e.kind == EventKind::Chatter) {
            // The accumulation point: [Chatter(j), Stick(j)] or [Chatter(j), Release(j)].
            let j = e.contact;
            let released = self
                .batch
                .iter()
                .any(|b| b.kind == EventKind::Release && b.contact == j);
            if self.batch.len() != 2 || self.batch.iter().any(|b| b.contact != j) {
                return Err(simultaneous(&self.batch));
            }
            let row = &self.chatter_rows[j * dim..(j + 1) * dim];
            if self.chatter_set[j] {
                self.row.copy_from_slice(row);
            } else {
                // Scheduled before the observation began: t_acc does not depend on z(t₀).
                self.row.fill(0.0);
            }
            if released {
                apply_time_shift(&mut self.phi, &self.f_pre, &self.f_post, &self.row);
            }
            self.chatter_set[j] = false;
            return Ok(());
        }
        // A release: the contact force passed zero, the field is continuous, S = I.
        let releases = count(EventKind::Release);
        if releases == 1 && self.batch.len() == 1 {
            let j = self.batch[0].contact;
            if !self.same_closures(post, Some(j)) {
                return Err(simultaneous(&self.batch));
            }
            self.chatter_set[j] = false;
            return Ok(());
        }
        Err(simultaneous(&self.batch))
    }

    /// Whether every contact but `except` is closed after the event exactly when it was
    /// closed before it.
    fn same_closures(&self, post: &[ClusterFlow], except: Option<usize>) -> bool {
        let n = self.field.len();
        (0..self.contacts).all(|j| Some(j) == except || is_closed(&self.last, n, j) == is_closed(post, n, j))
    }
}

/// `out = rowᵀ Φ`.
fn row_times(row: &[f64], phi: &DMatrix<f64>, out: &mut [f64]) {
    let dim = row.len();
    for (col, o) in out.iter_mut().enumerate() {
        let column = &phi.as_slice()[col * dim..(col + 1) * dim];
        *o = row.iter().zip(column).map(|(r, p)| r * p).sum();
    }
}

impl Observer for Sensitivity {
    fn flow(&mut self, flow: &Flow<'_>) {
        if self.failure.is_some() {
            if let Some(span) = &mut self.span {
                span.1 = flow.t_end;
            }
            self.batch.clear();
            return;
        }
        match &mut self.span {
            None => {
                self.phi.fill_with_identity();
                self.chatter_set.fill(false);
                self.span = Some((flow.t_start, flow.t_end));
            }
            Some(span) => span.1 = flow.t_end,
        }
        if !self.batch.is_empty() {
            self.finish_batch(flow.clusters);
        }
        if self.failure.is_none() {
            propagate(
                &mut self.phi,
                &self.field,
                flow.clusters,
                flow.t_start,
                flow.t_end,
            );
        }
        self.last.clear();
        self.last.extend_from_slice(flow.clusters);
    }

    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        if self.span.is_none() || self.failure.is_some() {
            return;
        }
        if self.batch.is_empty() {
            self.post_x.copy_from_slice(state.positions);
            self.post_v.copy_from_slice(state.velocities);
        }
        self.batch.push(*event);
    }
}
