//! The chain's vector field `f(z, t)` for a given partition into clusters, in the full state
//! `z = [x₁ … x_N, v₁ … v_N]` (m, m/s).
//!
//! A cluster G (a free mass, or masses stuck together) with M = Σm_i, C = Σc_i, K = Σk_i and
//! F₀ = −Σ k_i (o_i − o_first) (o_i = Σ_{j<i} δ_j, the offsets of its members) moves as one
//! body: with its coordinate `s` (the top member's position) and velocity `V`,
//!
//! ```text
//! ẋ_i = V,   v̇_i = a_G = (−C (V − y') − K (s − y) + F₀) / M     for every i ∈ G,
//! ```
//!
//! `y = A sin ωt`. External forces (docs of [`crate::ChainParams::forces`] and
//! [`crate::Simulator::set_external_forces`]) add their sum over G to the numerator: the
//! constant ones through F₀, a time polynomial through the cluster's [`ClusterFlow`], whose
//! oscillator carries the particular solution it drives (the forcing per unit mass is
//! recovered from it). They do not depend on the state, so they leave the Jacobian of the
//! flow unchanged, but they enter the field on both sides of an event.
//!
//! Off the constraint manifold (members not rigidly offset) `s` and `V` are
//! read as the mass-weighted means `s = Σ m_i (x_i − (o_i − o_first)) / M`,
//! `V = Σ m_i v_i / M`: the extension the simulator itself uses when it merges masses.

use crate::dynamics::ClusterFlow;
use crate::dynamics::Forcing;
use crate::dynamics::poly::Poly;
use crate::model::{ChainParams, StopSide, Stops};

/// Constants of one cluster, masses `first..=last` (0-based).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Cluster {
    pub first: usize,
    pub last: usize,
    /// M, kg.
    pub mass: f64,
    /// C, N·s/m.
    pub damping: f64,
    /// K, N/m.
    pub stiffness: f64,
    /// F₀ (with the constant external forces), N.
    pub force: f64,
    /// The polynomial external force per unit mass, m/s² (zero if none).
    pub drive: Poly,
}

impl Cluster {
    /// Members of the cluster.
    pub fn members(&self) -> std::ops::RangeInclusive<usize> {
        self.first..=self.last
    }
}

/// The parameters the vector field needs, read once from a [`ChainParams`].
#[derive(Debug, Clone)]
pub(crate) struct ChainField {
    pub masses: Vec<f64>,
    pub damping: Vec<f64>,
    pub stiffness: Vec<f64>,
    pub gaps: Vec<f64>,
    /// o_i = Σ_{j<i} δ_j, m.
    pub offsets: Vec<f64>,
    /// μ.
    pub restitution: f64,
    pub forcing: Forcing,
    /// The rigid stops.
    pub stops: Stops,
    /// The constant external forces, N (empty: none).
    pub forces: Vec<f64>,
}

impl ChainField {
    pub fn new(params: &ChainParams) -> Self {
        let n = params.len();
        let mut offsets = vec![0.0; n];
        for i in 1..n {
            offsets[i] = offsets[i - 1] + params.gaps[i - 1];
        }
        ChainField {
            masses: params.masses.clone(),
            damping: params.damping.clone(),
            stiffness: params.stiffness.clone(),
            gaps: params.gaps.clone(),
            offsets,
            restitution: params.restitution,
            forcing: Forcing::new(params.excitation.amplitude, params.omega()),
            stops: params.stops,
            forces: params.forces.clone(),
        }
    }

    /// Number of masses N.
    pub fn len(&self) -> usize {
        self.masses.len()
    }

    /// The constants of the cluster of masses `first..=last`.
    pub fn cluster(&self, first: usize, last: usize) -> Cluster {
        let base = self.offsets[first];
        let mut c = Cluster {
            first,
            last,
            mass: 0.0,
            damping: 0.0,
            stiffness: 0.0,
            force: 0.0,
            drive: Poly::ZERO,
        };
        for i in first..=last {
            c.mass += self.masses[i];
            c.damping += self.damping[i];
            c.stiffness += self.stiffness[i];
            c.force -= self.stiffness[i] * (self.offsets[i] - base);
        }
        if !self.forces.is_empty() {
            c.force += self.forces[first..=last].iter().sum::<f64>();
        }
        c
    }

    /// The cluster `cf` of a piece of flow, with its polynomial forcing.
    pub fn cluster_of_flow(&self, cf: &ClusterFlow) -> Cluster {
        let mut c = self.cluster(cf.first, cf.last);
        if !cf.oscillator.is_prescribed() {
            c.drive = cf.oscillator.driving();
        }
        c
    }

    /// The cluster of `clusters` (a partition, top to bottom) that contains mass `i`.
    pub fn cluster_of(&self, clusters: &[ClusterFlow], i: usize) -> Cluster {
        let c = &clusters[clusters.partition_point(|c| c.last < i)];
        self.cluster_of_flow(c)
    }

    /// Mass-weighted coordinate `s` and velocity `V` of cluster `c` at state (`x`, `v`).
    pub fn coordinates(&self, c: &Cluster, x: &[f64], v: &[f64]) -> (f64, f64) {
        let base = self.offsets[c.first];
        let (mut s, mut vel) = (0.0, 0.0);
        for i in c.members() {
            let m = self.masses[i];
            s += m * (x[i] - (self.offsets[i] - base));
            vel += m * v[i];
        }
        (s / c.mass, vel / c.mass)
    }

    /// Base displacement y, velocity y' and acceleration y'' at time `t`.
    pub fn base(&self, t: f64) -> (f64, f64, f64) {
        let (y, yd) = self.forcing.base(self.forcing.phase(t));
        (y, yd, -self.forcing.omega * self.forcing.omega * y)
    }

    /// Acceleration a_G, m/s², of cluster `c` with coordinate `s` and velocity `vel` at time
    /// `t` (module docs).
    pub fn accel(&self, c: &Cluster, s: f64, vel: f64, t: f64) -> f64 {
        let (y, yd, _) = self.base(t);
        let a = (-c.damping * (vel - yd) - c.stiffness * (s - y) + c.force) / c.mass;
        if c.drive.is_zero() {
            a
        } else {
            a + c.drive.value(t)
        }
    }

    /// `∂a_G/∂t` at fixed state: `(C y'' + K y' + f'(t)) / M`, m/s³.
    pub fn accel_rate(&self, c: &Cluster, t: f64) -> f64 {
        let (_, yd, ydd) = self.base(t);
        let r = (c.damping * ydd + c.stiffness * yd) / c.mass;
        if c.drive.is_zero() {
            r
        } else {
            r + c.drive.value_and_rate(t).1
        }
    }

    /// The position of the stop on `side` at time `t`, m, and its first three derivatives
    /// (zero for a fixed one).
    pub fn wall(&self, side: StopSide, t: f64) -> [f64; 4] {
        let frame = self.stops.get(side).map(|s| s.frame).unwrap_or_default();
        let (y, yd) = self.forcing.base(self.forcing.phase(t));
        ChainParams::frame_motion(frame, y, yd, self.forcing.omega)
    }

    /// Fills `f` (length 2N) with the vector field at (`x`, `v`, `t`) for the partition
    /// `clusters`. A cluster stuck to a stop moves with it: `v̇_i = Ÿ`.
    pub fn fill(&self, clusters: &[ClusterFlow], x: &[f64], v: &[f64], t: f64, f: &mut [f64]) {
        let n = self.len();
        for cf in clusters {
            if let Some(side) = cf.stop {
                let a = self.wall(side, t)[2];
                for i in cf.first..=cf.last {
                    f[i] = v[i];
                    f[n + i] = a;
                }
                continue;
            }
            let c = self.cluster_of_flow(cf);
            let (s, vel) = self.coordinates(&c, x, v);
            let a = self.accel(&c, s, vel, t);
            for i in c.members() {
                f[i] = v[i];
                f[n + i] = a;
            }
        }
    }
}
