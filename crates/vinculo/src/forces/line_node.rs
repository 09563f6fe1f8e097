//! A node of a lumped-mass line and its unit tangent, the local frame of the node's seabed
//! friction and hydrodynamic loads.
//!
//! MoorDyn's convention (MoorDyn-F `MoorDyn_Line.f90`, `Line_GetStateDeriv`; MoorDyn-C
//! `Line.cpp`, `getStateDeriv`): at an interior node i the tangent is the direction of the
//! chord between its neighbours, t_i = (q_{i+1} - q_{i-1}) / |q_{i+1} - q_{i-1}|; at an end
//! node, the direction of its one segment (t_0 = (q_1 - q_0)/|.|, t_N = (q_N - q_{N-1})/|.|).
//! Here a tangent is the direction from a particle a to a particle b, t = d / |d| with
//! d = q_b - q_a, and its derivatives are
//!
//! ```text
//! dt/dq_b = (I - t t^T) / |d| = P / |d|,        dt/dq_a = -P / |d|
//! ```
//!
//! A node without neighbours (a lone particle) has no tangent: its loads are then isotropic.
//!
//! The elements built on a node act on the node alone (the force on its neighbours is zero),
//! but depend on the neighbours' positions through t: their Jacobian has the blocks
//! df_node/dq_neighbour.

use crate::math::{diag, norm, outer, scale, sub, Mat3, Vec3};

/// A line node: the particle that carries the loads, and the particles that give its tangent.
#[derive(Debug, Clone, PartialEq)]
pub struct LineNode {
    /// Touched particles: the node first, then the tangent's particles that are not the node;
    /// the entries past `count` hold the node.
    pub particles: [usize; 3],
    /// Number of touched particles (1, 2 or 3).
    pub count: usize,
    /// Local indices (into `particles`) of the tangent's particles (a, b): t = unit(q_b - q_a);
    /// `None` for a node without a tangent.
    pub tangent: Option<[usize; 2]>,
}

/// The tangent of the last line node asked for, at one configuration: the elements on one node
/// (its hydrodynamics, its seabed contact) share it within one evaluation of the residual
/// instead of each computing it (a square root and a division). It is kept under the two
/// particles it runs between (a tangent depends on them alone), with its unit vector and
/// 1/|d|; the local indices of a node asking for it are that node's own. A cache lives for one
/// configuration only (the assembler makes one per residual). One made for the whole
/// configuration ([`TangentCache::for_configuration`]) also keeps the greatest height of its
/// particles, which tells every node of a line deep under a free surface at once that it is
/// wet ([`LineHydro`](super::LineHydro)).
#[derive(Debug, Clone)]
pub(crate) struct TangentCache {
    /// The particles (a, b) of the last tangent computed ([`NO_KEY`]: none yet).
    key: [usize; 2],
    /// Its unit vector and 1/|d|; None where a and b coincide.
    value: Option<(Vec3, f64)>,
    /// Whether the cache serves every element of the configuration.
    whole: bool,
    /// The greatest height of the configuration's particles (NaN: not yet found).
    top: f64,
}

/// The key of an empty [`TangentCache`].
const NO_KEY: [usize; 2] = [usize::MAX; 2];

impl Default for TangentCache {
    fn default() -> Self {
        TangentCache {
            key: NO_KEY,
            value: None,
            whole: false,
            top: f64::NAN,
        }
    }
}

impl TangentCache {
    /// A cache for every element of one configuration (the assembler's residual loop).
    pub(crate) fn for_configuration() -> TangentCache {
        TangentCache {
            whole: true,
            ..TangentCache::default()
        }
    }

    /// The greatest height z of the particles at `q`, found once for a cache that serves the
    /// whole configuration; None for one made for a single element (where finding it would
    /// cost more than it saves).
    #[inline(always)]
    pub(crate) fn top(&mut self, q: &[Vec3]) -> Option<f64> {
        if !self.whole {
            return None;
        }
        if self.top.is_nan() {
            self.top = q.iter().fold(f64::NEG_INFINITY, |top, p| top.max(p[2]));
        }
        Some(self.top)
    }

    /// The tangent of `node` at `q` ([`LineNode::tangent`]), computed unless it was the last
    /// one asked for.
    #[inline(always)]
    pub(crate) fn tangent(&mut self, node: &LineNode, q: &[Vec3]) -> Option<Tangent> {
        let [a, b] = node.tangent?;
        let key = [node.particles[a], node.particles[b]];
        if key != self.key {
            self.key = key;
            self.value = unit_chord(q[key[0]], q[key[1]]);
        }
        let (t, inv_len) = self.value?;
        Some(Tangent {
            t,
            inv_len,
            ends: [a, b],
        })
    }
}

/// A node's tangent at a configuration: t, and 1/|d|, the scale of its derivative
/// dt/dq_b = (I - t t^T) / |d|.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tangent {
    /// Unit tangent t.
    pub t: Vec3,
    /// 1 / |d|.
    pub inv_len: f64,
    /// Local indices (a, b) of the particles the tangent depends on.
    pub ends: [usize; 2],
}

impl LineNode {
    /// A node whose tangent runs from particle `a` to particle `b` (either may be the node
    /// itself, as at the ends of a line), or a node without a tangent (`None`).
    /// The caller checks that a != b.
    pub fn new(node: usize, tangent: Option<[usize; 2]>) -> LineNode {
        let mut particles = [node; 3];
        let mut count = 1;
        let mut local = |p: usize| -> usize {
            if let Some(k) = particles[..count].iter().position(|&x| x == p) {
                k
            } else {
                particles[count] = p;
                count += 1;
                count - 1
            }
        };
        let tangent = tangent.map(|[a, b]| [local(a), local(b)]);
        LineNode {
            particles,
            count,
            tangent,
        }
    }

    /// The touched particles, the node first.
    #[inline]
    pub fn particles(&self) -> &[usize] {
        &self.particles[..self.count]
    }

    /// The node's particle.
    #[inline]
    pub fn node(&self) -> usize {
        self.particles[0]
    }

    /// The unit tangent at positions `q` (None without a tangent, or where its two particles
    /// coincide).
    #[inline]
    pub(crate) fn tangent(&self, q: &[Vec3]) -> Option<Tangent> {
        let [a, b] = self.tangent?;
        let (t, inv_len) = unit_chord(q[self.particles[a]], q[self.particles[b]])?;
        Some(Tangent {
            t,
            inv_len,
            ends: [a, b],
        })
    }

    /// A node force, placed as the element's local rows (zero on the neighbours).
    #[inline]
    pub(crate) fn rows(&self, f: Vec3) -> crate::local::Rows {
        match self.count {
            1 => [f].into(),
            2 => [f, [0.0; 3]].into(),
            _ => [f, [0.0; 3], [0.0; 3]].into(),
        }
    }
}

/// The unit vector from `a` to `b` and 1 / |b - a| (None where they coincide): a line node's
/// tangent.
#[inline(always)]
pub(crate) fn unit_chord(a: Vec3, b: Vec3) -> Option<(Vec3, f64)> {
    let d = sub(b, a);
    let len = norm(d);
    if len == 0.0 {
        return None;
    }
    let inv_len = 1.0 / len;
    Some((scale(inv_len, d), inv_len))
}

/// The matrix product a b.
#[inline]
pub(crate) fn mul(a: Mat3, b: Mat3) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for (row, a_row) in m.iter_mut().zip(&a) {
        for (c, x) in row.iter_mut().enumerate() {
            *x = a_row[0] * b[0][c] + a_row[1] * b[1][c] + a_row[2] * b[2][c];
        }
    }
    m
}

impl Tangent {
    /// Adds (df/dt) (dt/dq) into the node's row of `dq`, for a force f on the node whose
    /// derivative with respect to the tangent is `df_dt`: with dt/dq_b = (I - t t^T) / |d|,
    /// J = (df/dt - (df/dt t) t^T) / |d| (a product with a vector, not a matrix) goes to the
    /// block of b, -J to the block of a.
    #[inline]
    pub(crate) fn add_chain(&self, df_dt: Mat3, dq: &mut crate::local::Blocks) {
        let t = self.t;
        let mut j = [[0.0; 3]; 3];
        for (row, d) in j.iter_mut().zip(&df_dt) {
            let along = crate::math::dot(*d, t);
            for c in 0..3 {
                row[c] = (d[c] - along * t[c]) * self.inv_len;
            }
        }
        let [a, b] = self.ends;
        dq[0][b] = crate::math::add_mat(dq[0][b], j);
        dq[0][a] = crate::math::add_mat(dq[0][a], crate::math::scale_mat(-1.0, j));
    }
}

/// d(w)/dt for the axial part w = t (t . x) of a vector x: t x^T + (t . x) I.
#[inline]
pub(crate) fn axial_part_by_tangent(t: Vec3, x: Vec3) -> Mat3 {
    crate::math::add_mat(outer(1.0, t, x), diag(crate::math::dot(t, x)))
}
