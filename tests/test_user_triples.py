"""Elements over three particles: the built-in bending force (System.add_bending) and user groups
whose elements touch three particles (System.add_force_group and
add_constraint_group with a (k, 3) array of particles): the core places elements of any size.

References: the closed-form frequency of a bent cantilever (bending energy EI (1 - cos theta) / l,
derived in crates/vinculo/src/forces/bending.rs) and scipy's DOP853 solution of a compound
pendulum's angle equation, a one-degree-of-freedom model derived below.
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import vinculo

GRAVITY = 9.81


def bending(stiffness, analytic):
    """Bending on triples (a, b, c): d = q_a - 2 q_b + q_c, f = -k (1, -2, 1) d, and its
    constant Jacobian df_x/dq_y = -k w_x w_y I (forces/bending.rs)."""
    w = np.array([1.0, -2.0, 1.0])

    def force(t, q, v):
        d = q[:, 0] - 2.0 * q[:, 1] + q[:, 2]
        return -stiffness * w[None, :, None] * d[:, None, :]

    def jacobian(t, q, v):
        block = -stiffness * np.kron(np.outer(w, w), np.eye(3))
        dq = np.broadcast_to(block, (len(q), 9, 9)).copy()
        return dq, np.zeros_like(dq)

    return {"force": force, "jacobian": jacobian if analytic else None}


@pytest.mark.parametrize(
    "analytic", [True, False, "built-in"], ids=["user Jacobian", "finite differences", "built-in"]
)
def test_bending_on_a_triple_swings_at_the_closed_form_frequency(analytic):
    # A cantilever of two segments: a and b fixed (the clamp), the tip c held at distance l from b
    # by a rigid link and bent by the force on the triple. For a small angle theta of the free
    # segment, m l^2 theta'' = -(EI / l) sin theta: omega_0^2 = EI / (m l^3), and the period at
    # amplitude theta_0 is (2 pi / omega_0)(1 + theta_0^2 / 16), exact to 1e-9 at theta_0 = 0.01.
    length, mass, ei, theta0 = 0.5, 0.2, 0.8, 0.01
    system = vinculo.System(gravity=(0.0, 0.0, 0.0))
    a = system.add_particle(1.0, (-length, 0.0, 0.0), fixed=True)
    b = system.add_particle(1.0, (0.0, 0.0, 0.0), fixed=True)
    tip = (length * np.cos(theta0), length * np.sin(theta0), 0.0)
    c = system.add_particle(mass, tip)
    system.add_distance(b, c)
    if analytic == "built-in":
        system.add_bending(a, b, c, ei, spacing=length)
    else:
        triples = np.array([[a.index, b.index, c.index]])
        system.add_force_group(triples, **bending(ei / length**3, analytic), name="bending")

    omega = np.sqrt(ei / (mass * length**3))
    period = 2 * np.pi / omega * (1 + theta0**2 / 16)
    solution = vinculo.simulate(system, 3.2 * period, period / 2000)
    y = solution.positions[:, c.index, 1]
    t = solution.times
    down = np.nonzero((y[:-1] > 0) & (y[1:] <= 0))[0]
    crossings = t[down] + (t[down + 1] - t[down]) * y[down] / (y[down] - y[down + 1])
    assert len(crossings) == 3
    measured = (crossings[2] - crossings[0]) / 2
    # Trapezoidal rule at 2000 steps per period: relative period error ~ (omega h)^2 / 12 ~ 1e-6.
    assert abs(measured - period) / period < 1e-5


def midpoint_functions():
    """Three equations over the triple (A, B, C), one per axis e: q_C[e] - (q_A[e] + q_B[e]) / 2.
    Linear: constant gradient, zero Hessian, Phi_t and gamma."""
    axes = np.arange(3)
    coefficients = np.array([-0.5, -0.5, 1.0])

    def phi(t, q):
        k = np.arange(len(q))
        return q[k, 2, axes[k]] - 0.5 * (q[k, 0, axes[k]] + q[k, 1, axes[k]])

    def gradient(t, q):
        g = np.zeros((len(q), 3, 3))
        for e in range(len(q)):
            g[e, :, axes[e]] = coefficients
        return g

    def hessian(t, q):
        return np.zeros((len(q), 9, 9))

    def zero(t, q, *v):
        return np.zeros(len(q))

    return {"phi": phi, "gradient": gradient, "hessian": hessian, "phi_t": zero, "gamma": zero}


@pytest.mark.parametrize("derivatives", [True, False], ids=["analytic", "phi only"])
def test_a_midpoint_held_by_triples_swings_as_a_compound_pendulum(derivatives):
    # A rod from a fixed pivot A to a bob B (a distance constraint); a second bob C held at the
    # rod's midpoint by three equations over (A, B, C). The system is a compound pendulum of
    # point masses m_B at L and m_C at L/2: I theta'' = -g (m_B L + m_C L / 2) sin theta,
    # I = m_B L^2 + m_C L^2 / 4, integrated by scipy (DOP853, rtol 1e-12) as the reference.
    length, m_b, m_c, theta0 = 0.8, 0.3, 0.5, 0.6
    system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
    a = system.add_particle(1.0, (0.0, 0.0, 0.0), fixed=True)
    tip = np.array([length * np.sin(theta0), 0.0, -length * np.cos(theta0)])
    b = system.add_particle(m_b, tuple(tip))
    c = system.add_particle(m_c, tuple(0.5 * tip))
    system.add_distance(a, b)
    functions = midpoint_functions()
    if not derivatives:
        functions = {"phi": functions["phi"]}
    triples = np.array([[a.index, b.index, c.index]] * 3)
    group = system.add_constraint_group(triples, **functions, name="midpoint")

    omega2 = GRAVITY * (m_b + m_c / 2) / (length * (m_b + m_c / 4))
    t_end, dt = 2.0, 1e-3
    solution = vinculo.simulate(system, t_end, dt)
    reference = solve_ivp(
        lambda t, y: [y[1], -omega2 * np.sin(y[0])],
        (0.0, t_end),
        [theta0, 0.0],
        method="DOP853",
        t_eval=solution.times,
        rtol=1e-12,
        atol=1e-12,
    )
    q_b = solution.positions[:, b.index]
    theta = np.arctan2(q_b[:, 0], -q_b[:, 2])
    # Trapezoidal phase error ~ omega^3 h^2 t / 12 ~ 1e-5 rad at t = 2 s (omega ~ 4 rad/s);
    # finite-difference gradients (~4e-11) add nothing visible.
    assert np.max(np.abs(theta - reference.y[0])) < 5e-5
    # C stays at the midpoint to the Newton tolerance.
    assert np.max(np.abs(solution.positions[:, c.index] - 0.5 * q_b)) < 1e-9
    # The multipliers of the group's equations are columns of Solution.multipliers.
    assert solution.multipliers[:, group.constraint_indices].shape == (len(solution.times), 3)
