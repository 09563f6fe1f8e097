//! User force and constraint groups (written here in Rust against the same traits the Python
//! bindings implement) reproduce the built-in elements they imitate, call their functions once
//! per evaluation point, and stop a run with a typed error when they fail.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;
use vinculo::constraints::{ConstraintCall, ConstraintGroup};
use vinculo::forces::ForceGroup;
use vinculo::integrators::Scheme;
use vinculo::model::System;
use vinculo::user::{GroupElements, UserFailure};
use vinculo::{simulate, Error, SimulationOptions};

/// Spring-damper f_a = -(k (|d| - L0) + c u.(v_a - v_b)) u, f_b = -f_a, u = d/|d|, d = q_a - q_b
/// (the built-in SpringDamper's law), with its Jacobian when `jacobian` is set.
struct Spring {
    k: f64,
    c: f64,
    rest: f64,
    jacobian: bool,
}

fn spring_terms(s: &Spring, q: &[f64], v: &[f64]) -> ([f64; 3], f64, [f64; 3], f64, f64) {
    let d: [f64; 3] = std::array::from_fn(|i| q[i] - q[3 + i]);
    let w: [f64; 3] = std::array::from_fn(|i| v[i] - v[3 + i]);
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    let u = d.map(|x| x / l);
    let rate = u[0] * w[0] + u[1] * w[1] + u[2] * w[2];
    (u, l, w, rate, s.k * (l - s.rest) + s.c * rate)
}

impl ForceGroup for Spring {
    fn force(&self, _t: f64, q: &[f64], v: &[f64], f: &mut [f64]) -> Result<(), UserFailure> {
        for e in 0..q.len() / 6 {
            let (u, _, _, _, tension) = spring_terms(self, &q[6 * e..], &v[6 * e..]);
            for i in 0..3 {
                f[6 * e + i] = -tension * u[i];
                f[6 * e + 3 + i] = tension * u[i];
            }
        }
        Ok(())
    }

    fn has_jacobian(&self) -> bool {
        self.jacobian
    }

    fn jacobian(
        &self,
        _t: f64,
        q: &[f64],
        v: &[f64],
        dq: &mut [f64],
        dv: &mut [f64],
    ) -> Result<(), UserFailure> {
        // With P = I - u u^T: du/dd = P/l, d(rate)/dd = w^T P / l, d(rate)/dw = u^T, so
        // df_a/dq_a = -(k u u^T + (c/l) u w^T P + (T/l) P), df_a/dv_a = -c u u^T, and the
        // other blocks follow from f_b = -f_a and d = q_a - q_b.
        for e in 0..q.len() / 6 {
            let (u, l, w, _, tension) = spring_terms(self, &q[6 * e..], &v[6 * e..]);
            let p = |i: usize, j: usize| f64::from(u8::from(i == j)) - u[i] * u[j];
            let pw: [f64; 3] = std::array::from_fn(|j| (0..3).map(|i| w[i] * p(i, j)).sum());
            for i in 0..3 {
                for j in 0..3 {
                    let a =
                        -(self.k * u[i] * u[j] + tension * p(i, j) / l + self.c * u[i] * pw[j] / l);
                    let b = -self.c * u[i] * u[j];
                    for (blk_r, blk_c, sign) in
                        [(0, 0, 1.0), (0, 1, -1.0), (1, 0, -1.0), (1, 1, 1.0)]
                    {
                        let at = 36 * e + (3 * blk_r + i) * 6 + 3 * blk_c + j;
                        dq[at] = sign * a;
                        dv[at] = sign * b;
                    }
                }
            }
        }
        Ok(())
    }
}

/// Phi = L^2 - |q_a - q_b|^2 (the built-in Distance), Phi only: every other term by finite
/// differences. Counts its calls.
struct Link {
    length: f64,
    calls: Arc<AtomicUsize>,
    fail_after: usize,
}

impl ConstraintGroup for Link {
    fn supplies(&self, call: ConstraintCall) -> bool {
        call == ConstraintCall::Phi
    }

    fn evaluate(
        &self,
        _call: ConstraintCall,
        _t: f64,
        q: &[f64],
        _v: &[f64],
        out: &mut [f64],
    ) -> Result<(), UserFailure> {
        if self.calls.fetch_add(1, Ordering::Relaxed) >= self.fail_after {
            return Err(UserFailure::Raised("link broke".into()));
        }
        for (e, o) in out.iter_mut().enumerate() {
            let d: f64 = (0..3)
                .map(|i| (q[6 * e + i] - q[6 * e + 3 + i]).powi(2))
                .sum();
            *o = self.length * self.length - d;
        }
        Ok(())
    }
}

/// A hanging chain of `n` links (0.1 m, 0.1 kg particles) from a fixed anchor, started
/// horizontal with a sideways push; spring-dampers between every second particle.
fn chain(n: usize, user_links: Option<Link>, user_springs: Option<Spring>) -> System {
    let mut s = System::new([0.0, 0.0, -9.81]);
    let mut ids = vec![s.add_particle(1.0, [0.0; 3], [0.0; 3], true).unwrap()];
    for i in 1..=n {
        let x = [0.1 * i as f64, 0.0, 0.0];
        ids.push(s.add_particle(0.1, x, [0.0, 0.0, 0.0], false).unwrap());
    }
    let pairs: Vec<[usize; 2]> = (0..n).map(|i| [i, i + 1]).collect();
    match user_links {
        Some(link) => {
            let elements = GroupElements::from_rows(&pairs);
            s.add_user_constraint_group(elements, Box::new(link), 0.5 / 0.1, Some("links".into()))
                .unwrap();
        }
        None => {
            for p in &pairs {
                s.add_distance(ids[p[0]], ids[p[1]], Some(0.1)).unwrap();
            }
        }
    }
    let springs: Vec<[usize; 2]> = (0..n - 1).map(|i| [i, i + 2]).collect();
    match user_springs {
        Some(spring) => {
            s.add_user_force_group(GroupElements::from_rows(&springs), Box::new(spring), None)
                .unwrap();
        }
        None => {
            for p in &springs {
                s.add_spring_damper(ids[p[0]], ids[p[1]], 50.0, 0.3, Some(0.15))
                    .unwrap();
            }
        }
    }
    s
}

fn options(scheme: Scheme) -> SimulationOptions {
    SimulationOptions {
        t_end: 0.2,
        dt: 5e-3,
        scheme,
        ..Default::default()
    }
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn user_spring_group_reproduces_the_built_in_spring_damper() {
    let spring = |jacobian| Spring {
        k: 50.0,
        c: 0.3,
        rest: 0.15,
        jacobian,
    };
    for scheme in [
        Scheme::GeneralizedTrapezoidal { alpha: 0.5 },
        Scheme::GeneralizedAlpha { rho_inf: 0.8 },
    ] {
        let reference = simulate(&chain(6, None, None), &options(scheme)).unwrap();
        assert!(reference.status.is_ok());
        for jacobian in [true, false] {
            let s = chain(6, None, Some(spring(jacobian)));
            let sol = simulate(&s, &options(scheme)).unwrap();
            assert!(sol.status.is_ok(), "{:?}", sol.status);
            // Same equations, same scheme: the user Jacobian is the built-in one, so the
            // trajectories agree to round-off; the forward-difference Jacobian (error ~1e-8)
            // changes only Newton's rate, so they agree to the Newton tolerance (1e-10 L).
            let tol = if jacobian { 1e-12 } else { 1e-10 };
            let d = max_difference(&sol.positions, &reference.positions);
            assert!(
                d < tol,
                "{scheme:?} jacobian {jacobian}: positions differ by {d}"
            );
            // One force call per residual evaluation (iterations + 1 per step, one at the start)
            // and one Jacobian call per iteration matrix assembled (one a factorisation: every
            // iteration in full Newton, fewer where a matrix is kept); finite differences add
            // 6 arity = 12 force calls per Jacobian.
            let iterations: usize = sol.stats.iter().map(|s| s.newton_iterations).sum();
            let steps = sol.stats.len() - 1;
            let counts = s.user_force_groups()[0].counts();
            let matrices = sol.factorisations;
            let fd = if jacobian { 0 } else { 12 * matrices };
            // A Newton iterate whose increment is below the positions' round-off is the previous
            // evaluation point bit for bit and is served from the group's cache: at most one
            // such repeat per step (its last iteration).
            let evaluations = 1 + iterations + steps + fd;
            let calls = counts[0].calls;
            assert!(
                calls <= evaluations && calls + steps >= evaluations,
                "{scheme:?} jacobian {jacobian}: {calls} force calls for {evaluations} evaluations"
            );
            assert_eq!(counts[1].calls, if jacobian { matrices } else { 0 });
        }
    }
}

#[test]
fn user_link_group_with_finite_differences_reproduces_the_built_in_distance() {
    let reference = simulate(
        &chain(5, None, None),
        &options(Scheme::GeneralizedTrapezoidal { alpha: 0.5 }),
    )
    .unwrap();
    let calls = Arc::new(AtomicUsize::new(0));
    let link = Link {
        length: 0.1,
        calls: calls.clone(),
        fail_after: usize::MAX,
    };
    let sol = simulate(
        &chain(5, Some(link), None),
        &options(Scheme::GeneralizedTrapezoidal { alpha: 0.5 }),
    )
    .unwrap();
    assert!(sol.status.is_ok(), "{:?}", sol.status);
    // Finite-difference gradient (~1e-8), Hessian (~1e-5), gamma: the converged states satisfy
    // the same exact residual to the Newton tolerance 1e-10 L (L = 0.5 m here); the multipliers
    // start from the finite-difference gamma (error ~1e-8 relative).
    let d = max_difference(&sol.positions, &reference.positions);
    assert!(d < 1e-9, "positions differ by {d}");
    let d = max_difference(&sol.multipliers, &reference.multipliers);
    let scale = reference
        .multipliers
        .iter()
        .fold(0.0_f64, |m, x| m.max(x.abs()));
    assert!(
        d < 1e-6 * scale,
        "multipliers differ by {d} (scale {scale})"
    );
}

#[test]
fn a_failing_user_function_stops_the_run_and_keeps_the_states() {
    let calls = Arc::new(AtomicUsize::new(0));
    let link = Link {
        length: 0.1,
        calls: calls.clone(),
        fail_after: 400,
    };
    let sol = simulate(
        &chain(3, Some(link), None),
        &options(Scheme::GeneralizedTrapezoidal { alpha: 0.5 }),
    )
    .unwrap();
    match &sol.status {
        Err(Error::UserFunction { group, message, .. }) => {
            assert_eq!(group, "links");
            assert_eq!(message, "link broke");
        }
        other => panic!("expected a UserFunction error, got {other:?}"),
    }
    // States computed before the failure are kept, and the failing function is not called again.
    assert!(sol.times.len() > 2 && *sol.times.last().unwrap() < 0.2);
    assert_eq!(calls.load(Ordering::Relaxed), 401);
}
