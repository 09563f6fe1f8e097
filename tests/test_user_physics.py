"""User-defined forces and constraints written in Python (System.add_force_group /
add_constraint_group).

The references are the built-in elements the Python groups imitate (same equations, same
scheme: the trajectories must agree to round-off with analytic derivatives), the scipy DOP853
solution of the moving-pivot pendulum's angle ODE (test_schemes.angle_reference), and
analytic derivatives for the finite-difference fallbacks.
"""

import warnings

import numpy as np
import pytest

import vinculo
from test_schemes import angle_reference
from vinculo import demos

GRAVITY = demos.GRAVITY
LINK = 0.1  # chain link length (m)


# --- Python elements imitating the built-in ones -------------------------------------------


def quadratic_drag(c):
    """f = -c |v| v (the built-in QuadraticDrag), and its Jacobian
    df/dv = -c (|v| I + v v^T / |v|)."""

    def force(t, q, v):
        return -c * np.linalg.norm(v, axis=1)[:, None] * v

    def jacobian(t, q, v):
        speed = np.linalg.norm(v, axis=1)
        safe = np.where(speed > 0, speed, 1.0)
        dv = -c * (
            speed[:, None, None] * np.eye(3) + v[:, :, None] * v[:, None, :] / safe[:, None, None]
        )
        return np.zeros_like(dv), dv

    return force, jacobian


def spring_damper(k, c, rest):
    """The built-in SpringDamper: with d = q_a - q_b, l = |d|, e = d/l, w = v_a - v_b and
    T = k (l - L0) + c e.w, f_a = -T e, f_b = T e. Jacobian (P = I - e e^T):
    df_a/dq_a = -(k e e^T + (c/l) e w^T P + (T/l) P), df_a/dv_a = -c e e^T, and the signs of
    the other blocks from f_b = -f_a, d = q_a - q_b."""

    def terms(q, v):
        d = q[:, 0] - q[:, 1]
        w = v[:, 0] - v[:, 1]
        length = np.linalg.norm(d, axis=1)
        e = d / length[:, None]
        tension = k * (length - rest) + c * np.einsum("ij,ij->i", e, w)
        return d, w, length, e, tension

    def force(t, q, v):
        _, _, _, e, tension = terms(q, v)
        fa = -tension[:, None] * e
        return np.stack([fa, -fa], axis=1)

    def jacobian(t, q, v):
        _, w, length, e, tension = terms(q, v)
        p = np.eye(3) - e[:, :, None] * e[:, None, :]
        wp = np.einsum("ij,ijk->ik", w, p)
        kaa = -(
            k * e[:, :, None] * e[:, None, :]
            + (c / length)[:, None, None] * e[:, :, None] * wp[:, None, :]
            + (tension / length)[:, None, None] * p
        )
        caa = -c * e[:, :, None] * e[:, None, :]
        signs = np.array([[1.0, -1.0], [-1.0, 1.0]])
        dq = np.einsum("pr,ilm->iplrm", signs, kaa).reshape(-1, 6, 6)
        dv = np.einsum("pr,ilm->iplrm", signs, caa).reshape(-1, 6, 6)
        return dq, dv

    return force, jacobian


def distance_functions(length):
    """Phi = L^2 - |q_a - q_b|^2 (the built-in Distance) with its gradient, Hessian, Phi_t = 0
    and gamma = -2 |v_a - v_b|^2 (distance.rs)."""

    def phi(t, q):
        d = q[:, 0] - q[:, 1]
        return length**2 - np.einsum("ij,ij->i", d, d)

    def gradient(t, q):
        d = q[:, 0] - q[:, 1]
        return np.stack([-2.0 * d, 2.0 * d], axis=1)

    def hessian(t, q):
        block = np.kron(np.array([[-2.0, 2.0], [2.0, -2.0]]), np.eye(3))
        return np.broadcast_to(block, (len(q), 6, 6))

    def phi_t(t, q):
        return np.zeros(len(q))

    def gamma(t, q, v):
        w = v[:, 0] - v[:, 1]
        return -2.0 * np.einsum("ij,ij->i", w, w)

    return {"phi": phi, "gradient": gradient, "hessian": hessian, "phi_t": phi_t, "gamma": gamma}


# --- Models --------------------------------------------------------------------------------


def chain(n, *, drag=None, springs=None, links=None):
    """A chain of n particles (0.1 kg, 0.1 m links) hanging from a fixed anchor, released
    horizontal with a sideways push; quadratic drag on every particle and spring-dampers between
    particles i and i + 2. Each of drag / springs / links is None (built-in elements) or the
    keyword arguments of a user group imitating them. Returns (system, groups)."""
    system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
    ids = [system.add_particle(1.0, (0.0, 0.0, 0.0), fixed=True)]
    for i in range(1, n + 1):
        ids.append(system.add_particle(0.1, (LINK * i, 0.0, 0.0), velocity=(0.0, 0.3 * i, 0.0)))
    groups = {}
    pairs = np.array([[i, i + 1] for i in range(n)])
    if links is None:
        for a, b in pairs:
            system.add_distance(ids[a], ids[b], LINK)
    else:
        groups["links"] = system.add_constraint_group(
            pairs, **links, scale=0.5 / LINK, name="links"
        )
    movers = np.arange(1, n + 1)
    if drag is None:
        for i in movers:
            system.add_quadratic_drag(ids[i], 0.05)
    else:
        groups["drag"] = system.add_force_group(movers, **drag, name="drag")
    spring_pairs = np.array([[i, i + 2] for i in range(n - 1)])
    if springs is None:
        for a, b in spring_pairs:
            system.add_spring_damper(ids[a], ids[b], 40.0, 0.2, 0.15)
    else:
        groups["springs"] = system.add_force_group(spring_pairs, **springs, name="springs")
    return system, groups


def user_drag(analytic):
    force, jacobian = quadratic_drag(0.05)
    return {"force": force, "jacobian": jacobian if analytic else None}


def user_springs(analytic):
    force, jacobian = spring_damper(40.0, 0.2, 0.15)
    return {"force": force, "jacobian": jacobian if analytic else None}


def relative_difference(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


RUNS = [
    ({"scheme": "trapezoidal"}, "trapezoidal"),
    ({"scheme": "generalized-alpha", "rho_inf": 0.7}, "generalised-alpha"),
    ({"scheme": "trapezoidal", "jacobian_reuse": True}, "modified Newton"),
]


@pytest.mark.parametrize(("kwargs", "label"), RUNS, ids=[r[1] for r in RUNS])
@pytest.mark.parametrize("analytic", [True, False], ids=["user Jacobian", "finite differences"])
def test_python_forces_reproduce_the_built_in_ones(kwargs, label, analytic):
    # Same model, same scheme, the built-in quadratic drag and spring-dampers replaced by Python
    # groups. With the user Jacobian (the built-in one) the Newton iterates are the same up to
    # round-off: agreement to 1e-12 relative. With the forward-difference Jacobian (error
    # ~1e-8 relative) only Newton's rate changes: the residual is exact and full Newton stops
    # far below its tolerance, so the trajectories still agree to round-off (measured 2e-14;
    # bound 1e-11, the Newton tolerance 1e-10 L being the most they could differ by).
    t_end, dt = 0.3, 5e-3
    reference = vinculo.simulate(chain(8)[0], t_end, dt, **kwargs)
    system, _ = chain(8, drag=user_drag(analytic), springs=user_springs(analytic))
    solution = vinculo.simulate(system, t_end, dt, **kwargs)
    tolerance = 1e-12 if analytic else 1e-11
    assert relative_difference(solution.positions, reference.positions) < tolerance
    assert relative_difference(solution.multipliers, reference.multipliers) < 100 * tolerance


def newton_counts(solution, dt):
    """Residual and Jacobian evaluations of a run stored every step, none rejected (every step
    of size dt): one residual at the start (consistent accelerations) and Newton's, iterations
    + 1 per step or iterations where Newton stops on its last increment
    (``Solution.residual_evaluations``); one Jacobian per iteration matrix assembled, which is
    one factorisation (every iteration in full Newton, fewer where the default keeps a
    matrix)."""
    assert np.allclose(solution.step_sizes[1:], dt, rtol=1e-9)
    iterations = int(np.sum(solution.newton_iterations))
    steps = len(solution.times) - 1
    assert solution.factorisations <= iterations
    assert iterations <= solution.residual_evaluations <= iterations + steps
    return 1 + solution.residual_evaluations, solution.factorisations


@pytest.mark.parametrize("analytic", [True, False], ids=["user Jacobian", "finite differences"])
def test_one_force_call_per_residual_evaluation(analytic):
    system, groups = chain(6, drag=user_drag(analytic), springs=user_springs(analytic))
    solution = vinculo.simulate(system, 0.1, 5e-3)
    residuals, jacobians = newton_counts(solution, 5e-3)
    for group in groups.values():
        # Finite differences: 3 arity coordinates of q, then of v, one call each per Jacobian.
        fd_calls = 0 if analytic else 6 * group.arity * jacobians
        assert group.calls["force"] == residuals + fd_calls
        assert group.calls["jacobian"] == (jacobians if analytic else 0)
        assert group.seconds["force"] > 0.0


def test_finite_difference_jacobian_matches_the_user_jacobian():
    # The core's forward-difference Jacobian against the analytic one at a generic state. With
    # the step h = sqrt(eps) max(|x|, s) (s the largest |x| of the perturbed array) the error of
    # df/dx is about h |f''| / 2 + 2 eps |f| / h ~ sqrt(eps) (|f''| s + |f| / s): bounded here
    # by 10 sqrt(eps) (max |J| + max |f| / s) (f'' ~ J / s for these smooth laws).
    rng = np.random.default_rng(3)
    _, groups = chain(6, drag=user_drag(True), springs=user_springs(True))
    for name, shape in [("drag", (6, 3)), ("springs", (5, 2, 3))]:
        q = rng.normal(size=shape)
        v = rng.normal(size=shape)
        group = groups[name]
        f = group.evaluate("force", 0.2, q, v)
        exact = group.evaluate("jacobian", 0.2, q, v)
        approx = group.evaluate("jacobian", 0.2, q, v, finite_differences=True)
        for a, b, x in zip(approx, exact, (q, v), strict=True):
            bound = (
                10
                * np.sqrt(np.finfo(float).eps)
                * (np.max(np.abs(b)) + np.max(np.abs(f)) / np.max(np.abs(x)))
            )
            assert np.max(np.abs(a - b)) < bound, name
            # and even the smallest block (the dashpot's df/dv, c = 0.2) is resolved to 1e-3
            assert np.max(np.abs(a - b)) <= 1e-3 * np.max(np.abs(b)), name


def test_python_distance_group_reproduces_the_built_in_chain():
    # The built-in Distance links replaced by one Python group with every derivative supplied:
    # the same equations, so the same trajectory and multipliers to round-off.
    t_end, dt = 0.3, 5e-3
    reference = vinculo.simulate(chain(5)[0], t_end, dt)
    system, groups = chain(5, links=distance_functions(LINK))
    solution = vinculo.simulate(system, t_end, dt)
    assert relative_difference(solution.positions, reference.positions) < 1e-12
    columns = groups["links"].constraint_indices
    assert relative_difference(solution.multipliers[:, columns], reference.multipliers) < 1e-10


def test_python_distance_group_with_only_phi():
    # Only Phi supplied: gradient by central differences (~4e-11 relative, and it enters the
    # residual through Phi_q^T lambda), Hessian by second differences (~1e-5, Newton's rate
    # only), gamma by a second difference along the path (~1e-8, the initial multipliers only).
    # The gradient error moves the solution by about its own size (measured 1e-12 in the
    # positions, 3e-12 in the multipliers after the start); bounds 1e-10 and 1e-9.
    t_end, dt = 0.3, 5e-3
    reference = vinculo.simulate(chain(5)[0], t_end, dt)
    system, groups = chain(5, links={"phi": distance_functions(LINK)["phi"]})
    solution = vinculo.simulate(system, t_end, dt)
    assert relative_difference(solution.positions, reference.positions) < 1e-10
    assert relative_difference(solution.multipliers[1:], reference.multipliers[1:]) < 1e-9
    # Finite differences call phi: 6 arity calls per gradient, more per Hessian.
    assert groups["links"].calls["gradient"] == 0
    assert groups["links"].calls["phi"] > 0


def test_finite_difference_constraint_terms_match_the_analytic_ones():
    # Error bounds of each fallback (constraints/user.rs): gradient ~4e-11, Hessian from the
    # gradient ~1e-8, Phi_t ~1e-10, gamma ~1e-8, all relative to the scale of the term; bounds
    # with a margin of 10-100.
    rng = np.random.default_rng(5)
    functions = distance_functions(0.7)
    system = vinculo.System()
    for i in range(4):
        system.add_particle(1.0, (i, 0.0, 0.0))
    group = system.add_constraint_group([[0, 1], [2, 3]], **functions)
    q = rng.normal(size=(2, 2, 3))
    v = rng.normal(size=(2, 2, 3))
    for call, bound in [("gradient", 1e-9), ("hessian", 1e-6), ("phi_t", 1e-9), ("gamma", 1e-6)]:
        exact = group.evaluate(call, 0.4, q, v)
        approx = group.evaluate(call, 0.4, q, v, finite_differences=True)
        scale = max(float(np.max(np.abs(exact))), 1.0)
        assert np.max(np.abs(approx - exact)) < bound * scale, call
    # Without a gradient the Hessian comes from second differences of phi (~1e-5).
    only_phi = system.add_constraint_group([[0, 1], [2, 3]], functions["phi"])
    approx = only_phi.evaluate("hessian", 0.4, q)
    assert np.max(np.abs(approx - group.evaluate("hessian", 0.4, q))) < 1e-4


def moving_pivot(user, derivatives=True):
    """A 1 m pendulum whose pivot moves as x_p = A sin(2 pi t) (A = 0.1 m), released at 30
    degrees at rest relative to the pivot (as test_schemes.moving_pivot_error); the pivot
    constraint built in (add_distance_to_point with a sine law) or a Python group."""
    amplitude, omega, theta0 = 0.1, 2.0 * np.pi, np.pi / 6
    system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
    bob = system.add_particle(
        1.0, [np.sin(theta0), 0.0, -np.cos(theta0)], velocity=[amplitude * omega, 0.0, 0.0]
    )
    if not user:
        system.add_distance_to_point(bob, (vinculo.sine(amplitude, 1.0), 0.0, 0.0), 1.0)
        return system, bob

    def pivot(t):
        """p, p', p'' at t (each (3,))."""
        s, c = np.sin(omega * t), np.cos(omega * t)
        return (
            np.array([amplitude * s, 0.0, 0.0]),
            np.array([amplitude * omega * c, 0.0, 0.0]),
            np.array([-amplitude * omega**2 * s, 0.0, 0.0]),
        )

    # Phi = 1 - |q - p(t)|^2; Phi_q = -2 d; Hessian -2 I; Phi_t = 2 d.p';
    # gamma = 2 d.p'' - 2 |v - p'|^2 (point_distance.rs).
    def phi(t, q):
        d = q - pivot(t)[0]
        return 1.0 - np.einsum("ij,ij->i", d, d)

    def gradient(t, q):
        return -2.0 * (q - pivot(t)[0])

    def hessian(t, q):
        return np.broadcast_to(-2.0 * np.eye(3), (len(q), 3, 3))

    def phi_t(t, q):
        p, p1, _ = pivot(t)
        return 2.0 * (q - p) @ p1

    def gamma(t, q, v):
        p, p1, p2 = pivot(t)
        w = v - p1
        return 2.0 * (q - p) @ p2 - 2.0 * np.einsum("ij,ij->i", w, w)

    extra = {"gradient": gradient, "hessian": hessian, "phi_t": phi_t, "gamma": gamma}
    system.add_constraint_group([bob.index], phi, **(extra if derivatives else {}), scale=0.5)
    return system, bob


@pytest.mark.parametrize("derivatives", [True, False], ids=["all derivatives", "only phi"])
def test_time_dependent_python_constraint_matches_the_moving_pivot(derivatives):
    # Against the built-in point distance with a sine law (same equations: round-off with the
    # derivatives supplied; with finite differences in q and t, measured 5e-13, bound 1e-10 as
    # in the chain test), and
    # both against the scipy angle-ODE reference (the trapezoidal rule's error at dt = 1 ms,
    # ~1e-5 m after 1 s, test_schemes).
    t_end, dt = 1.0, 1e-3
    built_in, bob = moving_pivot(user=False)
    reference = vinculo.simulate(built_in, t_end, dt)
    system, bob = moving_pivot(user=True, derivatives=derivatives)
    solution = vinculo.simulate(system, t_end, dt)
    tolerance = 1e-11 if derivatives else 1e-10
    assert relative_difference(solution.positions, reference.positions) < tolerance
    theta = angle_reference(
        np.pi / 6, t_end, lambda t: -0.1 * (2 * np.pi) ** 2 * np.sin(2 * np.pi * t)
    )
    exact = np.array([0.1 * np.sin(2 * np.pi * t_end) + np.sin(theta), 0.0, -np.cos(theta)])
    assert np.max(np.abs(solution.particle(bob)[-1] - exact)) < 1e-4


def test_a_python_constraint_duplicating_a_built_in_one_is_named_redundant():
    # The same link twice (built-in and Python): the gradients are equal up to the scale, so the
    # run refuses the model and names the Python equation as depending on the built-in one.
    system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
    a = system.add_particle(1.0, (0.0, 0.0, 0.0), fixed=True)
    b = system.add_particle(1.0, (1.0, 0.0, 0.0))
    system.add_distance(a, b, 1.0)
    system.add_constraint_group([[a.index, b.index]], distance_functions(1.0)["phi"])
    with pytest.raises(vinculo.RedundantConstraintsError) as info:
        vinculo.simulate(system, 0.01, 1e-3)
    assert "user constraint" in info.value.constraint


# --- Errors --------------------------------------------------------------------------------


def failing_after(calls, exception):
    force, _ = quadratic_drag(0.05)
    count = {"n": 0}

    def flaky(t, q, v):
        count["n"] += 1
        if count["n"] > calls:
            raise exception
        return force(t, q, v)

    return flaky


def test_an_exception_in_a_user_function_stops_the_run_with_the_partial_solution():
    system, groups = chain(3, drag={"force": failing_after(40, KeyError("no such sea state"))})
    with pytest.raises(vinculo.UserFunctionError) as info:
        vinculo.simulate(system, 1.0, 5e-3)
    error = info.value
    assert error.group == "drag" and error.call == "force"
    assert "KeyError" in str(error) and "drag" in str(error)
    # The user's exception is chained, with its traceback (the line that raised).
    assert isinstance(error.__cause__, KeyError)
    assert error.__cause__.__traceback__ is not None
    # Steps before the failure are kept; the function is not called after it failed.
    assert 1 < len(error.solution.times) and error.solution.times[-1] < 1.0
    assert groups["drag"].calls["force"] == 41


@pytest.mark.parametrize(
    ("bad", "expected"),
    [
        (lambda t, q, v: np.zeros((len(q), 2)), "shape (3, 2), expected (3, 3)"),
        (
            lambda t, q, v: np.full(q.shape, np.nan),
            "non-finite value (NaN or infinity) for element 0",
        ),
        (lambda t, q, v: "north", "not an array of floats"),
    ],
    ids=["wrong shape", "NaN", "not an array"],
)
def test_a_bad_result_is_a_typed_error_naming_the_shapes(bad, expected):
    system, _ = chain(3, drag={"force": bad})
    with pytest.raises(vinculo.UserFunctionOutputError) as info:
        vinculo.simulate(system, 0.1, 5e-3)
    assert expected in str(info.value)
    assert "'drag'" in str(info.value) and "force()" in str(info.value)


def test_bad_groups_are_refused_when_added():
    system = vinculo.System()
    for i in range(3):
        system.add_particle(1.0, (i, 0.0, 0.0))
    force, _ = quadratic_drag(1.0)
    with pytest.raises(vinculo.UnknownHandleError):
        system.add_force_group([0, 7], force)
    with pytest.raises(vinculo.InvalidInputError, match="particles"):
        system.add_force_group(np.zeros((2, 2, 3), dtype=int), force)
    with pytest.raises(vinculo.InvalidInputError, match="itself"):
        system.add_force_group([[0, 1, 0]], force)
    with pytest.raises(vinculo.InvalidInputError, match="integer"):
        system.add_force_group([0.5, 1.0], force)
    with pytest.raises(vinculo.InvalidInputError, match="itself"):
        system.add_force_group([[1, 1]], force)
    with pytest.raises(vinculo.InvalidInputError, match="jacobian"):
        system.add_force_group([0, 1], force, jacobian=3.0)
    with pytest.raises(vinculo.InvalidInputError, match="scale"):
        system.add_constraint_group([[0, 1]], distance_functions(1.0)["phi"], scale=-1.0)


def test_benchmark_smoke_run_agrees_with_the_built_in_drag():
    # The benchmark's three variants on a small chain: the Python drag (user Jacobian and finite
    # differences) ends where the built-in one does (same equations: round-off), and the core
    # timed every call it counted.
    from vinculo.bench import user_physics as bench

    lines = []
    rows = bench.table((5,), 5, out=lines.append)
    built_in = rows[0]
    for row in rows[1:]:
        assert np.max(np.abs(row.tip - built_in.tip)) < 1e-12
        assert row.force_calls > 0 and row.force_per_call > 0.0
    assert rows[1].jacobian_calls > 0 and rows[2].jacobian_calls == 0
    assert any("Python, finite diff." in line for line in lines)


def test_a_run_stopped_by_a_user_function_is_saved_with_its_status(tmp_path):
    # Solution I/O with user groups: the partial solution of a failed run goes to a NetCDF file
    # with its arrays exactly and the failure's facts; user equations are of kind 'other'.
    pytest.importorskip("xarray")
    from vinculo.io import load_netcdf, save_netcdf

    drag = {"force": failing_after(30, RuntimeError("sensor offline"))}
    system, _ = chain(3, drag=drag, links=distance_functions(LINK))
    with pytest.raises(vinculo.UserFunctionError) as info:
        vinculo.simulate(system, 1.0, 5e-3)
    partial = info.value.solution
    data = load_netcdf(save_netcdf(partial, tmp_path / "failed.nc"))
    assert data.attrs["status"] == "failed"
    assert "sensor offline" in data.attrs["error_message"]
    assert np.array_equal(data["positions"].values, partial.positions)
    assert np.array_equal(data["multipliers"].values, partial.multipliers)
    assert list(data["constraint_kinds"].values) == ["other"] * 3


@pytest.mark.parametrize("part", ["force", "phi"])
def test_a_complex_valued_result_is_refused_not_made_real(part):
    # numpy.asarray(z, dtype=float) drops the imaginary part with only a ComplexWarning, which a
    # user's script does not turn into an error: the warning is silenced here as there, and the
    # run must still stop with the typed error instead of using Re(z).
    if part == "force":
        force, _ = quadratic_drag(0.05)
        system, _ = chain(3, drag={"force": lambda t, q, v: force(t, q, v) + 1e-3j})
        group, call = "'drag'", "force()"
    else:
        functions = distance_functions(LINK)
        phi = functions.pop("phi")
        links = {"phi": lambda t, q: phi(t, q).astype(complex) * (1.0 + 1e-9j), **functions}
        system, _ = chain(3, links=links)
        group, call = "'links'", "phi()"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(vinculo.UserFunctionOutputError) as info:
            vinculo.simulate(system, 0.1, 5e-3)
    message = str(info.value)
    assert "complex-valued" in message and group in message and call in message
    assert "real floats of shape (3" in message
