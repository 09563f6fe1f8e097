//! Redundant constraints: equations whose gradients are linear combinations of others.
//!
//! A redundant set makes Phi_q rank-deficient, so the multipliers are not unique and the KKT
//! matrix of every solve is singular. To name the culprits, the scaled gradient rows
//! g_k = s_k dPhi_k/dq (restricted to the free particles) are orthonormalised in order by modified
//! Gram-Schmidt with one re-orthogonalisation pass. Each new orthonormal vector is kept together
//! with its expression in the original rows, q_j = sum_i T_ji g_i. A row whose remainder after
//! projection is below `RANK_TOLERANCE` of its norm is redundant; with d_j = q_j . g_k its
//! combination is g_k = sum_j d_j q_j = sum_i (sum_j d_j T_ji) g_i, and the rows with non-zero
//! coefficients are the constraints it depends on.
//!
//! The rows are unit-scaled (s_k Phi is a length, so |g_k| is of order one), which makes one
//! relative tolerance meaningful for every constraint kind. The analysis is dense: O(m^2 n) for m
//! equations on n free coordinates. It runs on small sets (a rigid body) and, for whole systems,
//! only after a factorisation has failed, up to [`MAX_ENTRIES`].

use crate::error::Error;
use crate::math::Vec3;
use crate::model::System;

/// Relative size of a remainder below which a gradient counts as dependent.
pub const RANK_TOLERANCE: f64 = 1e-8;
/// Largest m x n dense analysis attempted (above it, no diagnosis is made).
pub const MAX_ENTRIES: usize = 20_000_000;

/// Looks for a constraint among `subset` (all constraints if None) whose gradient at (q, t) is a
/// combination of earlier ones, and returns the error naming it and those it depends on.
pub fn find_redundant(
    system: &System,
    q: &[Vec3],
    t: f64,
    subset: Option<&[usize]>,
) -> Option<Error> {
    let all: Vec<usize>;
    let rows = match subset {
        Some(s) => s,
        None => {
            all = (0..system.constraints().len()).collect();
            &all
        }
    };
    // Columns: the coordinates of the free particles touched by these constraints.
    let mut column = vec![usize::MAX; system.particles().len()];
    let mut n = 0;
    for &c in rows {
        for &p in system.constraints()[c].particles() {
            if !system.particles()[p].fixed && column[p] == usize::MAX {
                column[p] = n;
                n += 3;
            }
        }
    }
    let m = rows.len();
    if m == 0 || m.saturating_mul(n.max(m)) > MAX_ENTRIES {
        return None;
    }
    let mut basis: Vec<Vec<f64>> = Vec::with_capacity(m); // orthonormal q_j
    let mut combos: Vec<Vec<f64>> = Vec::with_capacity(m); // T_j over the m rows
    for (r, &c) in rows.iter().enumerate() {
        let con = &system.constraints()[c];
        let grad = con.gradient(q, t);
        let mut g = vec![0.0; n];
        for (x, &p) in con.particles().iter().enumerate() {
            if column[p] != usize::MAX {
                for k in 0..3 {
                    g[column[p] + k] += con.scale() * grad[x][k];
                }
            }
        }
        let norm0 = g.iter().map(|x| x * x).sum::<f64>().sqrt();
        let mut d = vec![0.0; basis.len()];
        let mut w = g.clone();
        for _pass in 0..2 {
            for (j, b) in basis.iter().enumerate() {
                let p: f64 = b.iter().zip(&w).map(|(x, y)| x * y).sum();
                d[j] += p;
                w.iter_mut().zip(b).for_each(|(x, y)| *x -= p * y);
            }
        }
        let rest = w.iter().map(|x| x * x).sum::<f64>().sqrt();
        if rest <= RANK_TOLERANCE * norm0.max(f64::MIN_POSITIVE) {
            let mut coefficient = vec![0.0; m];
            for (j, dj) in d.iter().enumerate() {
                for (i, tji) in combos[j].iter().enumerate() {
                    coefficient[i] += dj * tji;
                }
            }
            let big = coefficient.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
            let depends_on_indices: Vec<usize> = (0..r)
                .filter(|&i| coefficient[i].abs() > 1e-6 * big && big > 0.0)
                .map(|i| rows[i])
                .collect();
            let mut depends_on: Vec<String> = depends_on_indices
                .iter()
                .map(|&i| system.constraints()[i].name(i))
                .collect();
            if depends_on.is_empty() {
                depends_on.push("nothing: its gradient vanishes at this configuration".into());
            }
            return Some(Error::RedundantConstraints {
                constraint: con.name(c),
                index: c,
                depends_on,
                depends_on_indices,
            });
        }
        // New orthonormal vector q = (g - sum_j d_j q_j) / rest, i.e. T_new = (e_r - sum d_j T_j) / rest.
        let mut combo = vec![0.0; m];
        combo[r] = 1.0;
        for (j, dj) in d.iter().enumerate() {
            for (i, tji) in combos[j].iter().enumerate() {
                combo[i] -= dj * tji;
            }
        }
        combo.iter_mut().for_each(|x| *x /= rest);
        w.iter_mut().for_each(|x| *x /= rest);
        basis.push(w);
        combos.push(combo);
    }
    None
}

/// What the structure of the matrix says of a singular-matrix error `e` at (q, t): the
/// constraints named by [`find_redundant`] when their gradients are linearly dependent (the
/// KKT matrix `[A, G^T; G, 0]` is singular whenever G loses row rank, whatever A); otherwise G
/// has full rank, so the singular part is the block A = M/(beta h^2) + K + D/(gamma h) of the
/// mass, the forces' stiffness K and damping D, restricted to the motions the constraints allow,
/// and the error says so instead of suspecting the constraints. Other errors pass unchanged.
pub fn explain_singular(system: &System, q: &[Vec3], t: f64, e: Error) -> Error {
    let Error::SingularMatrix {
        t: at,
        equation,
        detail,
    } = e
    else {
        return e;
    };
    if let Some(redundant) = find_redundant(system, q, t, None) {
        return redundant;
    }
    let m = system.constraints().len();
    let free = system.particles().iter().filter(|p| !p.fixed).count();
    if m.saturating_mul((3 * free).max(m)) > MAX_ENTRIES {
        return Error::SingularMatrix {
            t: at,
            equation,
            detail,
        };
    }
    let reported = detail
        .split("; the constraints may be redundant")
        .next()
        .unwrap_or(&detail)
        .to_string();
    Error::SingularMatrix {
        t: at,
        equation,
        detail: format!(
            "{reported}; the constraint gradients have full rank at this configuration (no \
             constraint is redundant), so the singular part is the mass and force block on the \
             motions the constraints allow: look for a force whose stiffness or damping cancels \
             the inertia (a user force's Jacobian, a negative or huge stiffness), or a step too \
             large for it"
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_with_a_repeated_side_names_both_copies() {
        // Three particles linked in a triangle, then the first side again: the fourth equation
        // equals the first, so it is a combination of exactly that one.
        let mut s = System::new([0.0, 0.0, -9.81]);
        let a = s
            .add_particle(1.0, [0.0, 0.0, 0.0], [0.0; 3], false)
            .unwrap();
        let b = s
            .add_particle(1.0, [1.0, 0.0, 0.0], [0.0; 3], false)
            .unwrap();
        let c = s
            .add_particle(1.0, [0.0, 1.0, 0.0], [0.0; 3], false)
            .unwrap();
        s.add_distance(a, b, None).unwrap();
        s.add_distance(b, c, None).unwrap();
        s.add_distance(c, a, None).unwrap();
        assert!(find_redundant(&s, &s.initial_positions(), 0.0, None).is_none());
        s.add_distance(b, a, None).unwrap();
        match find_redundant(&s, &s.initial_positions(), 0.0, None) {
            Some(Error::RedundantConstraints {
                index,
                depends_on_indices,
                ..
            }) => {
                assert_eq!(index, 3);
                assert_eq!(depends_on_indices, vec![0]);
            }
            other => panic!("expected a redundancy, got {other:?}"),
        }
    }

    #[test]
    fn a_planar_square_with_both_diagonals_is_redundant_in_the_plane() {
        // Four particles held in the plane z = 0 (4 equations), a square of 4 sides and 2
        // diagonals: 8 planar coordinates minus 3 rigid motions allow only 5 independent
        // distances, so the 6th (the second diagonal) depends on the 5 other distances.
        let mut s = System::new([0.0, 0.0, -9.81]);
        let corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let p: Vec<_> = corners
            .iter()
            .map(|c| {
                s.add_particle(1.0, [c[0], c[1], 0.0], [0.0; 3], false)
                    .unwrap()
            })
            .collect();
        for &x in &p {
            s.add_fixed_coordinate(x, 2, None).unwrap();
        }
        for k in 0..4 {
            s.add_distance(p[k], p[(k + 1) % 4], None).unwrap();
        }
        s.add_distance(p[0], p[2], None).unwrap();
        assert!(find_redundant(&s, &s.initial_positions(), 0.0, None).is_none());
        s.add_distance(p[1], p[3], None).unwrap();
        match find_redundant(&s, &s.initial_positions(), 0.0, None) {
            Some(Error::RedundantConstraints {
                index,
                depends_on_indices,
                ..
            }) => {
                assert_eq!(index, 9);
                assert_eq!(depends_on_indices, vec![4, 5, 6, 7, 8]);
            }
            other => panic!("expected a redundancy, got {other:?}"),
        }
    }
}

#[cfg(test)]
mod explain_tests {
    use super::*;

    fn singular() -> Error {
        Error::SingularMatrix {
            t: 0.5,
            equation: "dynamics of particle 1 (x)".into(),
            detail: "zero pivot; the constraints may be redundant or leave the model \
                     under-determined"
                .into(),
        }
    }

    /// The structure decides the culprit: a repeated distance (G loses rank) is named as
    /// redundant; a pendulum's single distance has a gradient of full rank, so the error points
    /// at the mass and force block and no longer suspects the constraint.
    #[test]
    fn a_singular_matrix_is_blamed_on_what_its_structure_shows() {
        let mut s = crate::integrators::fixtures::pendulum();
        let (a, b) = (s.particle_id(0).unwrap(), s.particle_id(1).unwrap());
        let q = s.initial_positions();
        match explain_singular(&s, &q, 0.5, singular()) {
            Error::SingularMatrix { detail, .. } => {
                assert!(detail.contains("full rank"), "{detail}");
                assert!(!detail.contains("may be redundant"), "{detail}");
            }
            other => panic!("expected a singular matrix, got {other:?}"),
        }
        s.add_distance(b, a, None).unwrap();
        assert!(matches!(
            explain_singular(&s, &q, 0.5, singular()),
            Error::RedundantConstraints { index: 1, .. }
        ));
    }
}
