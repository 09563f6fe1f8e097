//! An elastic segment between two particles: a compliant distance whose multiplier is the
//! tension (`docs/theory/moorings.md`).
//!
//! With d = q_i - q_j, u = d/|d| and the unstretched length L(t) (a law: a winch; a segment's
//! share of its line's law):
//! - Phi = L(t) - |d|
//! - Phi_q: dPhi/dq_i = -u^T, dPhi/dq_j = +u^T
//! - Hessian: d2Phi/dq_i2 = d2Phi/dq_j2 = -(I - u u^T)/|d|, d2Phi/dq_i dq_j = +(I - u u^T)/|d|
//! - Phi_t = L'(t)
//! - Phi'' = L'' - u.(a_i - a_j) - (|w|^2 - (u.w)^2)/|d| with w = v_i - v_j, so
//!   gamma = L'' - (|w|^2 - (u.w)^2)/|d|
//! - scale 1 (Phi is a length).
//!
//! The constraint force on i is Phi_q^T lambda = -lambda u: lambda > 0 pulls i towards j, and the
//! multiplier is the tension T itself (N).
//!
//! Hooke's law T = EA (|d| - L)/L, multiplied by the compliance c = L/EA, is the constraint
//! equation `Phi + c T = 0`: the iteration matrix gets `c` (scaled) on the diagonal of the
//! tension's row, and EA = infinity (c = 0) is the exact distance |d| = L. The compliance is a
//! length per newton, so the matrix stays bounded as EA grows: its only entry that depends on EA
//! tends to zero, whereas a penalty spring's stiffness EA/L would grow without bound.
//!
//! A segment that can go slack (MoorDyn's segments, `slack`) carries no compression: its
//! tension is T = max(0, EA (|d| - L)/L), so its equation is `c T - max(0, Phi) = 0` (`Phi`
//! here the stretch measure of the row, `assembly/parallel.rs`): `Phi + c T = 0` while
//! stretched, `c T = 0` (T = 0, no force, no dependence on q) while shorter than L. The
//! switch is where T = 0, so the tension is continuous; its derivative jumps there (the step
//! that crosses it is first order locally, as MoorDyn's is).
//!
//! Internal axial damping (MoorDyn's BA, `damping` = BA / l in N s/m,
//! [`crate::model::System::set_axial_damping`]): the segment also carries the tension
//! T_d = c u.w, w = v_i - v_j (c times the rate of its length), a force -T_d u on i and +T_d u
//! on j along the same line as the multiplier's, slack or not (MoorDyn applies it whether the
//! segment is stretched or not). It is a force, evaluated where the forces are (q_e, v_e),
//! placed with the multiplier's column: the dynamics rows get -(lambda + T_d) Phi_q^T, one
//! gather of the two particles' rows for both. With P = I - u u^T and |d| = l:
//!
//! ```text
//! d(f_i)/dq_i = -(c / l) (u (P w)^T + (u.w) P)      d(f_i)/dv_i = -c u u^T
//! ```
//!
//! and the blocks (i, j), (j, i) the negatives, (j, j) the same (as a spring-damper of zero
//! stiffness, `forces/spring_damper.rs`, whose numbers they are).

use std::sync::Arc;

use super::strain_curve::StrainCurve;
use super::Hessian;
use crate::laws::Law;
use crate::math::{dot, norm, outer, scale_mat, sub, Mat3, Vec3};

/// |q_i - q_j| = L(t) + (L(t)/EA) T, the multiplier T being the tension.
#[derive(Debug, Clone, PartialEq)]
pub struct ElasticDistance {
    /// The two particles.
    pub particles: [usize; 2],
    /// The unstretched length L(t) > 0 (m) is `share` times this law: a constant, or a law for a
    /// winch (the law of a whole line, of which each of its n segments has the share 1/n).
    pub length: Law,
    /// The segment's share of `length` (1 for a segment of its own).
    pub share: f64,
    /// The axial stiffness EA (N); infinity: inextensible. With a `curve`, its stiffest
    /// piece's (the scale of [`ElasticDistance::compliance`]).
    pub ea: f64,
    /// The tension-strain curve of a nonlinear line (MoorDyn's EA table,
    /// `strain_curve.rs`); None: Hooke's law with `ea`.
    pub curve: Option<Arc<StrainCurve>>,
    /// Whether the segment goes slack (tension 0) instead of pushing when shorter than L.
    pub slack: bool,
    /// Internal axial damping c (N s/m; 0: none): the tension c u.(v_i - v_j) along the segment.
    pub damping: f64,
}

/// The unit vector u, the length |d| and the projector I - u u^T over |d|.
#[inline(always)]
fn geometry(q: &[Vec3], particles: [usize; 2]) -> (Vec3, f64) {
    let d = sub(q[particles[0]], q[particles[1]]);
    let l = norm(d);
    // One division and three products: the divider, which also takes the square root, is
    // what a line's residual waits on.
    let inv = 1.0 / l;
    ([d[0] * inv, d[1] * inv, d[2] * inv], l)
}

impl ElasticDistance {
    pub(crate) fn particles(&self) -> &[usize] {
        &self.particles
    }

    pub(crate) fn residual(&self, q: &[Vec3], t: f64) -> f64 {
        let d = sub(q[self.particles[0]], q[self.particles[1]]);
        self.share * self.length.value(t) - norm(d)
    }

    /// [`ElasticDistance::residual`] and [`ElasticDistance::gradient`] from one difference
    /// and one norm (the same numbers).
    #[inline(always)]
    pub(crate) fn residual_and_gradient(&self, q: &[Vec3], t: f64) -> (f64, [Vec3; 2]) {
        let (u, l) = geometry(q, self.particles);
        let phi = self.share * self.length.value(t) - l;
        (phi, [[-u[0], -u[1], -u[2]], u])
    }

    pub(crate) fn gradient(&self, q: &[Vec3], _t: f64) -> [Vec3; 2] {
        let (u, _) = geometry(q, self.particles);
        [[-u[0], -u[1], -u[2]], u]
    }

    /// `w` times the Hessian blocks (i, i), (i, j), (j, i), (j, j).
    #[inline(always)]
    pub(crate) fn hessian(&self, q: &[Vec3], w: f64) -> [Mat3; 4] {
        let (u, l) = geometry(q, self.particles);
        let mut p = outer(-1.0, u, u);
        for (r, row) in p.iter_mut().enumerate() {
            row[r] += 1.0;
        }
        let same = scale_mat(-w / l, p);
        let other = scale_mat(w / l, p);
        [same, other, other, same]
    }

    pub(crate) fn add_hessian(&self, q: &[Vec3], _t: f64, w: f64, out: &mut Hessian) {
        for (o, h) in out.as_mut_slice().iter_mut().zip(self.hessian(q, w)) {
            for r in 0..3 {
                for c in 0..3 {
                    o[r][c] += h[r][c];
                }
            }
        }
    }

    pub(crate) fn phi_t(&self, _q: &[Vec3], t: f64) -> f64 {
        self.share * self.length.eval(t).1
    }

    pub(crate) fn gamma(&self, q: &[Vec3], v: &[Vec3], t: f64) -> f64 {
        let (u, l) = geometry(q, self.particles);
        let w = sub(v[self.particles[0]], v[self.particles[1]]);
        let uw = dot(u, w);
        self.share * self.length.eval(t).2 - (dot(w, w) - uw * uw) / l
    }

    pub(crate) fn scale(&self) -> f64 {
        1.0
    }

    /// The damping's tension T_d = c u.(v_i - v_j) from the gradient [-u, u] at the positions
    /// the forces use and the velocities there: -c (grad_i . v_i + grad_j . v_j).
    #[inline(always)]
    pub(crate) fn damping_tension(&self, grad: &[Vec3], v: &[Vec3]) -> f64 {
        let [i, j] = self.particles;
        -self.damping * (dot(grad[0], v[i]) + dot(grad[1], v[j]))
    }

    /// `wq` d(f)/dq + `wv` d(f)/dv of the damping force (module documentation): the blocks
    /// (i, i), (i, j), (j, i), (j, j).
    pub(crate) fn damping_blocks(&self, q: &[Vec3], v: &[Vec3], (wq, wv): (f64, f64)) -> [Mat3; 4] {
        let [i, j] = self.particles;
        let (u, l) = geometry(q, self.particles);
        let w = sub(v[i], v[j]);
        let uw = dot(u, w);
        // P w = w - (u.w) u.
        let pw = [w[0] - uw * u[0], w[1] - uw * u[1], w[2] - uw * u[2]];
        let c = self.damping;
        let mut same = [[0.0; 3]; 3];
        for (r, row) in same.iter_mut().enumerate() {
            for (k, x) in row.iter_mut().enumerate() {
                let p = if r == k { 1.0 } else { 0.0 } - u[r] * u[k];
                let dq = -(c / l) * (u[r] * pw[k] + uw * p);
                let dv = -c * u[r] * u[k];
                *x = wq * dq + wv * dv;
            }
        }
        let other = scale_mat(-1.0, same);
        [same, other, other, same]
    }

    /// The compliance c(t) = L(t)/EA (m/N) of the constraint equation Phi + c T = 0; 0 when
    /// inextensible (with a curve, its stiffest piece's: a scale).
    #[inline]
    pub(crate) fn compliance(&self, t: f64) -> f64 {
        if self.ea.is_finite() {
            self.share * self.length.value(t) / self.ea
        } else {
            0.0
        }
    }

    /// The stretch |d| - L that the tension `lambda` gives the segment at time `t`, and its
    /// derivative in `lambda`: c(t) lambda and c(t) (Hooke's law), or L e(lambda) and
    /// L e'(lambda) along its curve (`strain_curve.rs`).
    #[inline(always)]
    pub(crate) fn stretch(&self, t: f64, lambda: f64) -> (f64, f64) {
        match &self.curve {
            None => {
                let c = self.compliance(t);
                (c * lambda, c)
            }
            Some(curve) => {
                let l = self.share * self.length.value(t);
                let (e, de) = curve.strain(lambda);
                (l * e, l * de)
            }
        }
    }

    /// The tension of the stretch `stretch` (m) at time `t`: the inverse of
    /// [`ElasticDistance::stretch`].
    pub fn tension_of(&self, t: f64, stretch: f64) -> f64 {
        match &self.curve {
            None => stretch / self.compliance(t),
            Some(curve) => curve.tension(stretch / (self.share * self.length.value(t))),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{fd, Constraint};
    use super::*;
    use crate::math::scale as scale_vec;

    /// Gradient, Hessian, Phi_t and gamma against finite differences, for a segment whose
    /// length is paid out by a winch (a polynomial law).
    #[test]
    fn derivatives_match_finite_differences() {
        let c = Constraint::ElasticDistance(Box::new(ElasticDistance {
            particles: [0, 2],
            length: Law::polynomial(vec![1.4, 0.4, -0.6]).unwrap(),
            share: 0.5,
            ea: 1e5,
            slack: false,
            damping: 0.0,
            curve: None,
        }));
        let q = [[0.1, 0.2, -0.3], [9.0, 9.0, 9.0], [0.5, -0.4, 0.25]];
        let v = [[0.3, -1.0, 0.2], [0.0; 3], [-0.6, 0.1, 0.9]];
        fd::check(&c, &q, &v, 0.3);
    }

    /// The damping force's derivatives against central differences of the force
    /// f_i = -T_d u, f_j = +T_d u (T_d from the gradient and the velocities), on a segment that
    /// stretches and turns, and against the spring-damper of zero stiffness that is the same
    /// force (`forces/spring_damper.rs`).
    #[test]
    fn damping_blocks_match_finite_differences_and_the_spring_damper() {
        use crate::forces::{Force, Jacobian, SpringDamper};
        let e = ElasticDistance {
            particles: [0, 2],
            length: Law::Constant(0.7),
            share: 1.0,
            ea: 1e5,
            slack: true,
            damping: 3.5,
            curve: None,
        };
        let force = |q: &[Vec3], v: &[Vec3]| -> [Vec3; 2] {
            let grad = e.gradient(q, 0.0);
            let td = e.damping_tension(&grad, v);
            [scale_vec(td, grad[0]), scale_vec(-td, grad[0])]
        };
        let q = [[0.1, 0.2, -0.3], [9.0, 9.0, 9.0], [0.5, -0.4, 0.25]];
        let v = [[0.3, -1.0, 0.2], [0.0; 3], [-0.6, 0.1, 0.9]];
        let h = 1e-6;
        for (which, weights) in [(0, (1.0, 0.0)), (1, (0.0, 1.0))] {
            let blocks = e.damping_blocks(&q, &v, weights);
            for (y, &py) in e.particles.iter().enumerate() {
                for k in 0..3 {
                    let (mut xp, mut xm) = if which == 0 {
                        (q.to_vec(), q.to_vec())
                    } else {
                        (v.to_vec(), v.to_vec())
                    };
                    xp[py][k] += h;
                    xm[py][k] -= h;
                    let (fp, fm) = if which == 0 {
                        (force(&xp, &v), force(&xm, &v))
                    } else {
                        (force(&q, &xp), force(&q, &xm))
                    };
                    for x in 0..2 {
                        for r in 0..3 {
                            let fd = (fp[x][r] - fm[x][r]) / (2.0 * h);
                            let an = blocks[2 * x + y][r][k];
                            assert!((fd - an).abs() < 1e-6 * (1.0 + fd.abs()), "{fd} vs {an}");
                        }
                    }
                }
            }
        }
        // The spring-damper of zero stiffness between the same particles: the same blocks.
        let spring = Force::SpringDamper(SpringDamper {
            particles: [0, 2],
            stiffness: 0.0,
            damping: 3.5,
            rest_length: 0.7,
        });
        let (mut dq, mut dv) = (Jacobian::zeros(2), Jacobian::zeros(2));
        spring.add_jacobian(&q, &v, 0.0, &mut dq, &mut dv);
        let mine = e.damping_blocks(&q, &v, (0.3, -0.8));
        for x in 0..2 {
            for y in 0..2 {
                for r in 0..3 {
                    for k in 0..3 {
                        let theirs = 0.3 * dq[x][y][r][k] - 0.8 * dv[x][y][r][k];
                        let diff = (mine[2 * x + y][r][k] - theirs).abs();
                        assert!(diff < 1e-12 * (1.0 + theirs.abs()), "{x}{y}{r}{k}");
                    }
                }
            }
        }
    }

    /// The compliance is L/EA, and zero for an inextensible segment.
    #[test]
    fn compliance_is_length_over_ea() {
        let mut e = ElasticDistance {
            particles: [0, 1],
            length: Law::Constant(4.0),
            share: 0.5,
            ea: 4e6,
            slack: false,
            damping: 0.0,
            curve: None,
        };
        assert_eq!(e.compliance(0.0), 2.0 / 4e6);
        e.ea = f64::INFINITY;
        assert_eq!(e.compliance(0.0), 0.0);
    }
}
