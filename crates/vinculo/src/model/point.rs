//! Points of the system that are not particles: points fixed in a rigid body, and points fixed
//! in the ground.
//!
//! A point fixed in a body is an affine combination of the body's particles,
//! x = sum_k w_k q_k with sum_k w_k = 1 (natural coordinates). The weights are the point's
//! barycentric coordinates in a frame of the body's particles at the initial configuration:
//! four non-coplanar particles in space, or three non-collinear ones for a point in their plane
//! (a planar body). Because the body moves rigidly, the combination stays the point for all
//! time, exactly, and it is linear in q with constant weights, so that
//! x' = sum w_k v_k and x'' = sum w_k a_k: an element written for particles acts on points
//! without a new term ([`PointMap`]). A ground point has no particle, only a constant position.
//!
//! An element over m points touches the union of their particles. With g_j the element's
//! gradient (or force) at point j and H_jl its Hessian (or Jacobian) blocks, the chain rule
//! gives, for a particle p of weight w_jp in point j,
//!
//! g_p = sum_j w_jp g_j,    H_pr = sum_j sum_l w_jp w_lr H_jl,
//!
//! and every time derivative (Phi_t, gamma) is the element's own at the points' positions and
//! velocities.

use crate::error::{Error, Result};
use crate::local::Blocks;
use crate::math::{cross, dot, norm, sub, Mat3, Vec3};

/// A point: `offset + sum_k weights[k] q[particles[k]]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// The particles it is a combination of (none for a ground point).
    pub particles: Vec<usize>,
    /// One weight per particle (summing to 1 for a point of a body).
    pub weights: Vec<f64>,
    /// A constant position added (a ground point's position; 0 for a point of a body).
    pub offset: Vec3,
}

impl Point {
    /// A particle as a point.
    pub fn particle(index: usize) -> Point {
        Point {
            particles: vec![index],
            weights: vec![1.0],
            offset: [0.0; 3],
        }
    }

    /// A point fixed in the ground at `position`.
    pub fn ground(position: Vec3) -> Point {
        Point {
            particles: Vec::new(),
            weights: Vec::new(),
            offset: position,
        }
    }

    /// The point at world position `at` of the body framed by `frame` (particle indices) at
    /// positions `positions` (of those particles, now): its barycentric coordinates in the
    /// frame. Four particles frame a body in space, three a planar body (the point must lie in
    /// their plane).
    pub fn in_frame(frame: &[usize], positions: &[Vec3], at: Vec3) -> Result<Point> {
        let weights = barycentric(positions, at)?;
        Ok(Point {
            particles: frame.to_vec(),
            weights,
            offset: [0.0; 3],
        })
    }

    /// Its position for the particle positions `q`.
    #[inline]
    pub fn position(&self, q: &[Vec3]) -> Vec3 {
        let mut x = self.offset;
        for (&p, &w) in self.particles.iter().zip(&self.weights) {
            for k in 0..3 {
                x[k] += w * q[p][k];
            }
        }
        x
    }

    /// Its velocity for the particle velocities `v` (the offset does not move).
    #[inline]
    pub fn velocity(&self, v: &[Vec3]) -> Vec3 {
        let mut x = [0.0; 3];
        for (&p, &w) in self.particles.iter().zip(&self.weights) {
            for k in 0..3 {
                x[k] += w * v[p][k];
            }
        }
        x
    }
}

/// Barycentric coordinates of `at` in the simplex `frame` (4 points in space, 3 in a plane).
fn barycentric(frame: &[Vec3], at: Vec3) -> Result<Vec<f64>> {
    let size = frame
        .iter()
        .skip(1)
        .map(|p| norm(sub(*p, frame[0])))
        .fold(0.0, f64::max);
    let degenerate = |what: &str, value: f64| {
        Error::InvalidParameter {
        name: "frame of the body's particles".into(),
        value,
        expected: format!("{what}: frame a body with 4 non-coplanar particles, or 3 non-collinear ones for a planar body"),
    }
    };
    match frame.len() {
        4 => {
            // Solve [e1 e2 e3] (w1, w2, w3) = at - p0, w0 = 1 - w1 - w2 - w3 (Cramer).
            let e: Vec<Vec3> = frame[1..].iter().map(|p| sub(*p, frame[0])).collect();
            let r = sub(at, frame[0]);
            let det = dot(e[0], cross(e[1], e[2]));
            if det.abs() <= 1e-9 * size.powi(3) {
                return Err(degenerate("the 4 particles are coplanar", det));
            }
            let w1 = dot(r, cross(e[1], e[2])) / det;
            let w2 = dot(e[0], cross(r, e[2])) / det;
            let w3 = dot(e[0], cross(e[1], r)) / det;
            Ok(vec![1.0 - w1 - w2 - w3, w1, w2, w3])
        }
        3 => {
            // Least squares in the plane: [e1 e2] (w1, w2) = at - p0 (Gram system), then the
            // point must lie in the plane.
            let (e1, e2) = (sub(frame[1], frame[0]), sub(frame[2], frame[0]));
            let r = sub(at, frame[0]);
            let (a, b, c) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
            let det = a * c - b * b;
            if det <= 1e-12 * size.powi(4) {
                return Err(degenerate("the 3 particles are collinear", det));
            }
            let (r1, r2) = (dot(r, e1), dot(r, e2));
            let w1 = (c * r1 - b * r2) / det;
            let w2 = (a * r2 - b * r1) / det;
            let off: Vec3 = std::array::from_fn(|k| r[k] - w1 * e1[k] - w2 * e2[k]);
            let gap = norm(off);
            if gap > 1e-9 * size.max(norm(r)) {
                return Err(Error::InvalidVector {
                    name: "point of a planar body".into(),
                    value: at.to_vec(),
                    expected: format!(
                        "must lie in the plane of the body's 3 particles (it is {gap:.3e} m off)"
                    ),
                });
            }
            Ok(vec![1.0 - w1 - w2, w1, w2])
        }
        n => Err(degenerate(&format!("{n} particles given"), n as f64)),
    }
}

/// The positions or velocities of an element's points.
pub type Points = smallvec::SmallVec<[Vec3; 8]>;

/// How an element over m points reaches the particles: the union of their particles, and each
/// point's (index in the union, weight) terms. Module doc for the chain rule.
#[derive(Debug, Clone, PartialEq)]
pub struct PointMap {
    /// The union of the points' particles, in order of first appearance.
    pub particles: Vec<usize>,
    terms: Vec<Vec<(usize, f64)>>,
    offsets: Vec<Vec3>,
}

impl PointMap {
    /// The map of `points` (element point j is `points[j]`).
    pub fn new(points: &[Point]) -> PointMap {
        let all: Vec<usize> = (0..points.len()).collect();
        PointMap::for_points(points, &all)
    }

    /// The map of `points` for an element that touches only the points `used` (its particles
    /// are then those of the used points alone).
    pub fn for_points(points: &[Point], used: &[usize]) -> PointMap {
        let mut particles: Vec<usize> = Vec::new();
        let terms = points
            .iter()
            .enumerate()
            .map(|(j, point)| {
                if !used.contains(&j) {
                    return Vec::new();
                }
                point
                    .particles
                    .iter()
                    .zip(&point.weights)
                    .map(|(&p, &w)| {
                        let u = particles.iter().position(|&x| x == p).unwrap_or_else(|| {
                            particles.push(p);
                            particles.len() - 1
                        });
                        (u, w)
                    })
                    .collect()
            })
            .collect();
        PointMap {
            particles,
            terms,
            offsets: points.iter().map(|p| p.offset).collect(),
        }
    }

    /// Number of points.
    pub fn points(&self) -> usize {
        self.terms.len()
    }

    /// The points' positions for the particle positions `q` (all of the system's), on the
    /// stack for up to 8 points (a joint's).
    #[inline]
    pub fn positions(&self, q: &[Vec3]) -> Points {
        self.combine(q, true)
    }

    /// The points' velocities for the particle velocities `v`.
    #[inline]
    pub fn velocities(&self, v: &[Vec3]) -> Points {
        self.combine(v, false)
    }

    fn combine(&self, x: &[Vec3], offsets: bool) -> Points {
        // A loop into storage of the right length (a collect through the iterator adapters
        // was a tenth of a rigid-body chain's step).
        let mut out: Points = smallvec::smallvec![[0.0; 3]; self.terms.len()];
        for ((y, terms), offset) in out.iter_mut().zip(&self.terms).zip(&self.offsets) {
            if offsets {
                *y = *offset;
            }
            for &(u, w) in terms {
                let p = self.particles[u];
                for k in 0..3 {
                    y[k] += w * x[p][k];
                }
            }
        }
        out
    }

    /// Per-particle rows g_p = sum_j w_jp g_j from per-point rows: `rows[a]` belongs to point
    /// `at[a]`.
    pub fn rows(&self, at: &[usize], rows: &[Vec3]) -> Vec<Vec3> {
        self.rows_on_stack(at, rows).into_vec()
    }

    /// [`PointMap::rows`] on the stack for up to 8 particles (a joint's two bodies).
    pub fn rows_on_stack(&self, at: &[usize], rows: &[Vec3]) -> Points {
        let mut out: Points = smallvec::smallvec![[0.0; 3]; self.particles.len()];
        for (&j, g) in at.iter().zip(rows) {
            for &(u, w) in &self.terms[j] {
                for k in 0..3 {
                    out[u][k] += w * g[k];
                }
            }
        }
        out
    }

    /// Adds the particle blocks H_pr = sum_jl w_jp w_lr H_jl of the per-point blocks `blocks`
    /// (over the points `at`) to `out` (over the union).
    pub fn add_blocks(&self, at: &[usize], blocks: &Blocks, out: &mut Blocks) {
        for (a, &j) in at.iter().enumerate() {
            for (b, &l) in at.iter().enumerate() {
                let h: &Mat3 = &blocks[a][b];
                if *h == crate::math::ZERO3 {
                    continue;
                }
                for &(u, wu) in &self.terms[j] {
                    for &(v, wv) in &self.terms[l] {
                        let o = &mut out.as_mut_slice()[u * self.particles.len() + v];
                        for r in 0..3 {
                            for c in 0..3 {
                                o[r][c] += wu * wv * h[r][c];
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Positions and velocities of `n` particles in a general configuration, for the tests of
/// elements over points (particles 0..3 frame one body, 4..7 another).
#[cfg(test)]
pub(crate) fn test_state(n: usize) -> (Vec<Vec3>, Vec<Vec3>) {
    let q = (0..n)
        .map(|i| {
            let s = i as f64;
            [
                0.3 * s.sin() + 0.1 * s,
                (1.7 * s).cos(),
                0.2 * s * s - 0.5 * (s % 3.0),
            ]
        })
        .collect();
    let v = (0..n)
        .map(|i| [0.1 * i as f64, -0.3, 0.05 * (i * i) as f64])
        .collect();
    (q, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentric_weights_rebuild_the_point_and_follow_a_rigid_motion() {
        // A tetrahedron frame and a point outside it: the weights sum to 1 and give the point;
        // after a rotation and a translation of the frame they give the moved point.
        let frame = [
            [0.1, 0.0, 0.0],
            [1.0, 0.2, 0.0],
            [0.0, 1.1, 0.3],
            [0.2, 0.1, 0.9],
        ];
        let at = [0.7, -0.4, 1.3];
        let p = Point::in_frame(&[0, 1, 2, 3], &frame, at).unwrap();
        assert!((p.weights.iter().sum::<f64>() - 1.0).abs() < 1e-14);
        let x = p.position(&frame);
        assert!((0..3).all(|k| (x[k] - at[k]).abs() < 1e-14));
        let (c, s) = (0.6f64.cos(), 0.6f64.sin());
        let moved = |y: Vec3| [c * y[0] - s * y[2] + 1.0, y[1] - 2.0, s * y[0] + c * y[2]];
        let frame2: Vec<Vec3> = frame.iter().map(|&y| moved(y)).collect();
        let x2 = p.position(&frame2);
        let expected = moved(at);
        assert!((0..3).all(|k| (x2[k] - expected[k]).abs() < 1e-13));
        // A planar frame: the point must be in its plane.
        let plane = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        let q = Point::in_frame(&[0, 1, 2], &plane, [0.3, 0.5, 0.0]).unwrap();
        assert_eq!(q.position(&plane), [0.3, 0.5, 0.0]);
        assert!(Point::in_frame(&[0, 1, 2], &plane, [0.3, 0.5, 0.1]).is_err());
        let flat = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]];
        assert!(Point::in_frame(&[0, 1, 2, 3], &flat, at).is_err());
    }
}
