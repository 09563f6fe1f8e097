"""Well-posed hard problems that must run, and runs that must not report a false success.

Each test is a case where the model is well posed and the run used to stop (a false failure), or
where a run used to report success on a meaningless result; each asserts a physical or numerical
fact against an independent reference named in its comment.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import vinculo

G = 9.81


# --- Newton at round-off: the N-four-bar mechanism ------------------------------------------------


def _four_bars(n: int) -> tuple[vinculo.System, list]:
    """The N-four-bar mechanism, with point masses at the joints.

    The benchmark of the IFToMM multibody library ("N-four-bar mechanism"; Gonzalez, Dopico,
    Lugris, Cuadrado et al. 2006, "A benchmarking system for MBS simulation software", Multibody
    System Dynamics 16): n four-bar linkages in a row sharing their bars, every bar 1 m long,
    gravity 9.81 m/s^2 along -y, the cranks upright at the start and the top joints moving at
    1 m/s along +x. Here each top joint is a 1 kg particle held in the plane z = 0, the bars are
    distance constraints (massless), the ground joints fixed particles. One degree of freedom: all
    cranks share the angle theta, every top joint moving on a circle of 1 m; twice a turn
    (theta = 0, pi) every bar lies on the ground line and the constraint gradients lose rank.
    """
    system = vinculo.System(gravity=(0.0, -G, 0.0))
    top: list = []
    for i in range(n + 1):
        ground = system.add_particle(mass=1.0, position=(float(i), 0.0, 0.0), fixed=True)
        joint = system.add_particle(
            mass=1.0, position=(float(i), 1.0, 0.0), velocity=(1.0, 0.0, 0.0)
        )
        system.add_distance(ground, joint, length=1.0)
        system.add_fixed_coordinate(joint, "z")
        if top:
            system.add_distance(top[-1], joint, length=1.0)
        top.append(joint)
    return system, top


def _crank_reference(times: np.ndarray) -> np.ndarray:
    """theta(t) of the one-degree-of-freedom model: every joint at (i + cos theta, sin theta), so
    T = (n + 1) m theta'^2 / 2 and V = (n + 1) m g sin theta, theta'' = -g cos theta, from
    theta = pi/2, theta' = -1 rad/s (x' = -sin theta theta' = 1 m/s); scipy's DOP853 at 1e-12."""
    ivp = solve_ivp(
        lambda _t, y: [y[1], -G * math.cos(y[0])],
        (times[0], times[-1]),
        [math.pi / 2, -1.0],
        method="DOP853",
        rtol=1e-12,
        atol=1e-12,
        t_eval=times,
    )
    return ivp.y[0]


@pytest.mark.parametrize("scheme", ["generalized-alpha", "trapezoidal"])
def test_n_four_bar_passes_every_singular_configuration(scheme):
    # N = 40, 10 s, Newton tolerance 1e-12. It used to stop at the collinear configurations:
    # "did not converge" with residual 3.6e-15 (generalised-alpha at t = 1.30 s; the trapezoidal
    # rule at t = 6.89 s with the general sparse LU), where the multipliers of the self-stress
    # are not determined and Newton's increments bounce at round-off; or with a singular block
    # of the tree elimination.
    system, top = _four_bars(40)
    # The trapezoidal rule with the general sparse LU, generalised-alpha with the tree elimination.
    linear_solver = "sparse-lu" if scheme == "trapezoidal" else "auto"
    solution = vinculo.simulate(
        system, t_end=10.0, dt=1e-3, scheme=scheme, tolerance=1e-12, save_every=10,
        linear_solver=linear_solver,
    )
    assert solution.success
    xy = solution.particle(top[0])[:, :2]
    theta = np.unwrap(np.arctan2(xy[:, 1], xy[:, 0]))
    # Singular configurations passed: theta crossing a multiple of pi (all bars collinear).
    crossings = int(np.count_nonzero(np.diff(np.floor(theta / math.pi))))
    assert crossings >= 10, crossings
    # The crank angle follows the one-degree-of-freedom reference (measured: 1.8e-4 rad with
    # generalised-alpha, 4.4e-5 rad with the trapezoidal rule).
    reference = _crank_reference(solution.times)
    assert np.max(np.abs(theta - reference)) < 1e-3
    # The mechanism stayed on its parallelogram branch: joint i at (i + cos theta, sin theta).
    for i, joint in enumerate(top):
        expected = np.stack([i + np.cos(theta), np.sin(theta)], axis=1)
        assert np.max(np.abs(solution.particle(joint)[:, :2] - expected)) < 1e-6
    if scheme == "trapezoidal":
        # The trapezoidal rule conserves the energy of this conservative model (measured drift
        # 2e-11 of (N + 1) m g L).
        energy = solution.energy()
        assert np.max(np.abs(energy - energy[0])) < 1e-8 * 41 * G


# --- Tree elimination: singular blocks of regular matrices ----------------------------------------


def _v_chain(links_per_leg: int) -> tuple[vinculo.System, list]:
    """A chain hung from two anchors 2 m apart as a V of two straight legs, at rest.

    The end particle of a leg holds two parallel conditions (its anchor and its link) in the
    tree elimination's block: the block is singular though the matrix is not.
    """
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    left = system.add_particle(mass=1.0, position=(-1.0, 0.0, 0.0), fixed=True)
    right = system.add_particle(mass=1.0, position=(1.0, 0.0, 0.0), fixed=True)
    previous, chain = left, []
    for i in range(1, 2 * links_per_leg):
        x = -1.0 + i / links_per_leg
        joint = system.add_particle(mass=0.1, position=(x, 0.0, -(1.0 - abs(x))))
        system.add_distance(previous, joint)
        previous = joint
        chain.append(joint)
    system.add_distance(previous, right)
    return system, chain


def _pinned_chain(links: int, pinned: bool) -> tuple[vinculo.System, list]:
    """A chain of 1 m hanging straight down, released with a sideways speed growing along it.

    Its top is a free particle whose three coordinates are prescribed (``pinned``) or a fixed
    particle: the same mechanics.
    """
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    # The tip first and the top last: the top is not the first particle (the tree elimination
    # used to root every tree at its first particle, which hid the defect).
    chain = [
        system.add_particle(
            mass=0.1, position=(0.0, 0.0, -i / links), velocity=(0.5 * i / links, 0.0, 0.0)
        )
        for i in range(links, 0, -1)
    ][::-1]
    top = system.add_particle(mass=1.0, position=(0.0, 0.0, 0.0), fixed=not pinned)
    if pinned:
        for axis in "xyz":
            system.add_fixed_coordinate(top, axis)
    for above, below in zip([top, *chain[:-1]], chain, strict=True):
        system.add_distance(above, below)
    return system, chain


def _positions(solution: vinculo.Solution, chain: list) -> np.ndarray:
    return np.stack([solution.particle(p) for p in chain], axis=1)


def test_v_chain_runs_with_the_tree_elimination_and_agrees_with_sparse_lu():
    # Used to stop at t = 0: "singular iteration matrix, the constraints may be redundant".
    runs = {}
    for general in (False, True):
        system, chain = _v_chain(12)
        solution = vinculo.simulate(system, t_end=0.5, dt=1e-3, save_every=10,
                                    linear_solver="sparse-lu" if general else "auto")
        assert solution.success
        runs[general] = (solution, _positions(solution, chain))
    assert runs[False][0].linear_solver == "tree elimination"
    assert runs[True][0].linear_solver == "sparse LU"
    # The reference: the same steps solved with partial pivoting across the whole matrix.
    assert np.max(np.abs(runs[False][1] - runs[True][1])) < 1e-9
    # The legs sagged (a chain that stood still would agree trivially), and the trapezoidal
    # rule kept the energy (no damping in the model) to 1e-6 of the weight times the span.
    assert np.max(np.abs(runs[False][1][-1] - runs[False][1][0])) > 0.05
    energy = runs[False][0].energy()
    assert np.max(np.abs(energy - energy[0])) < 1e-6 * 2.3 * G * 2.0


def test_chain_from_a_pinned_particle_runs_and_matches_the_fixed_anchor():
    # Used to stop at t = 0 with a singular matrix: the pinned particle's block held its three
    # fixed coordinates and the link to its neighbour, four conditions on three coordinates.
    pinned, chain = _pinned_chain(20, pinned=True)
    solution = vinculo.simulate(pinned, t_end=0.5, dt=1e-3, save_every=10)
    assert solution.success
    assert solution.linear_solver == "tree elimination"
    # References: the same chain hung from a fixed particle (the same mechanics), and the
    # pinned chain solved by the general sparse LU.
    for (reference_system, reference_chain), linear_solver in (
        (_pinned_chain(20, pinned=False), "auto"),
        (_pinned_chain(20, pinned=True), "sparse-lu"),
    ):
        reference = vinculo.simulate(reference_system, t_end=0.5, dt=1e-3, save_every=10,
                                     linear_solver=linear_solver)
        gap = np.max(np.abs(_positions(solution, chain) - _positions(reference, reference_chain)))
        assert gap < 1e-9, gap
    assert np.max(np.abs(solution.particle(chain[-1])[-1, 0])) > 0.05  # the tip swung out


# --- Step halvings and the resolution of the time -------------------------------------------------


def _pendulum() -> vinculo.System:
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    pivot = system.add_particle(mass=1.0, position=(0.0, 0.0, 0.0), fixed=True)
    bob = system.add_particle(mass=1.0, position=(1.0, 0.0, 0.0))
    system.add_distance(pivot, bob, length=1.0)
    return system


def test_many_allowed_halvings_change_nothing_on_a_run_that_needs_none():
    # max_halvings = 1000 used to fail at t = 0: the grid unit dt / 2^1000 and a shift by 1000
    # bits (wrapped to 40) made the first step 2^-960 dt.
    default = vinculo.simulate(_pendulum(), t_end=1.0, dt=1e-3)
    many = vinculo.simulate(_pendulum(), t_end=1.0, dt=1e-3, max_halvings=1000)
    assert many.success
    # The reference is the default run: no step needed a halving, so the steps are the same.
    np.testing.assert_array_equal(many.times, default.times)
    np.testing.assert_array_equal(many.positions, default.positions)


def test_a_step_below_the_resolution_of_t_is_refused_up_front():
    # At t = 1e6 s doubles are 1.16e-10 s apart: a step of 1e-12 s does not advance t. It used to
    # report success with repeated times and zero step sizes.
    with pytest.raises(vinculo.InvalidInputError) as caught:
        vinculo.simulate(_pendulum(), t_start=1e6, t_end=1e6 + 1e-9, dt=1e-12)
    assert caught.value.name == "dt" and caught.value.value == 1e-12
    assert "1e6" in str(caught.value) or "1e+06" in str(caught.value).replace("e+6", "e+06")
    # A resolvable step at the same time runs, every stored time distinct.
    solution = vinculo.simulate(_pendulum(), t_start=1e6, t_end=1e6 + 1e-3, dt=1e-5)
    assert solution.success
    assert np.all(np.diff(solution.times) > 0)


def test_a_halving_below_the_resolution_of_t_stops_with_a_typed_error():
    # dt = 1e-8 s at t = 1e6 s spans 86 float spacings (the least accepted is 50). A Newton
    # tolerance of 1e-30 m cannot be met (round-off is 1e-16 m), so the step is halved, to 43
    # spacings: below the resolution, a StepSizeTooSmallError naming the step and the time
    # rather than a run of repeated times.
    with pytest.raises(vinculo.StepSizeTooSmallError) as caught:
        vinculo.simulate(
            _pendulum(), t_start=1e6, t_end=1e6 + 1e-6, dt=1e-8, tolerance=1e-30, max_iterations=3
        )
    assert 1e6 <= caught.value.time < 1e6 + 1e-6
    assert caught.value.step_size == pytest.approx(5e-9)
    assert caught.value.step_size < caught.value.h_min


# --- Mass ratios ------------------------------------------------------------------------------


def _alternating_chain(links: int, scale: float):
    """A chain of 0.1 m links released horizontally from a fixed anchor, its particles'
    masses alternating between 1e-9 kg and 1e3 kg (times ``scale``)."""
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    previous = system.add_particle(mass=1.0, position=(0.0, 0.0, 0.0), fixed=True)
    chain = []
    for i in range(1, links + 1):
        mass = (1e-9 if i % 2 else 1e3) * scale
        joint = system.add_particle(mass=mass, position=(0.1 * i, 0.0, 0.0))
        system.add_distance(previous, joint)
        previous = joint
        chain.append(joint)
    return system, chain


def test_mass_ratio_of_a_trillion_runs_and_is_scale_invariant():
    # Used to stop at t = 0: "singular iteration matrix ... the constraints may be redundant".
    runs = {}
    for scale, general in ((1.0, False), (1e-3, False), (1.0, True)):
        system, chain = _alternating_chain(10, scale)
        solution = vinculo.simulate(system, t_end=0.3, dt=1e-3, save_every=10,
                                    linear_solver="sparse-lu" if general else "auto")
        assert solution.success
        # linear_solver="sparse-lu" on 40 unknowns: the dense LU (at most 48).
        assert solution.linear_solver == ("dense LU" if general else "tree elimination")
        runs[scale, general] = _positions(solution, chain)
    # References: the motion under gravity alone does not depend on the unit of mass (every
    # mass times 1e-3), and an LU with partial pivoting across the whole matrix gives the same
    # steps.
    assert np.max(np.abs(runs[1.0, False] - runs[1e-3, False])) < 1e-9
    assert np.max(np.abs(runs[1.0, False] - runs[1.0, True])) < 1e-9
    assert np.max(np.abs(runs[1.0, False][-1] - runs[1.0, False][0])) > 0.1  # it fell


# --- Generalised-alpha must not blow up silently --------------------------------------------------


def test_unstable_generalized_alpha_raises_instead_of_reporting_success():
    # The 1 m pendulum released from the horizontal at rho_inf = 0.9 and dt = 0.05 s (47 steps a
    # period): index-3 generalised-alpha is unstable there (an independent implementation of the
    # scheme blows up the same way); its energy error used to reach 1e10 m g L with success
    # reported. The model takes in no energy, so its energy may not exceed the initial value
    # plus everything it can exchange (m g L here).
    with pytest.raises(vinculo.InstabilityError) as caught:
        vinculo.simulate(_pendulum(), t_end=20.0, dt=0.05, scheme="generalized-alpha", rho_inf=0.9)
    error = caught.value
    assert isinstance(error, vinculo.ConvergenceError)
    assert error.energy > error.energy_bound == pytest.approx(error.initial_energy + G * 1.0 * 1.0)
    assert error.rho_inf == 0.9 and error.step_size == 0.05
    assert "formulation='ggl'" in str(error)
    # The partial solution is the run up to the step that passed the bound (stored with it).
    assert error.solution.times[-1] == error.time < 20.0
    assert error.solution.energy()[-1] == pytest.approx(error.energy)
    # rho_inf = 1 blows up even at 1000 steps a period (measured: 2.4e9 m g L in 20 periods).
    with pytest.raises(vinculo.InstabilityError):
        vinculo.simulate(
            _pendulum(), t_end=20.0, dt=2.4e-3, scheme="generalized-alpha", rho_inf=1.0
        )


@pytest.mark.parametrize(
    "options",
    [
        {"scheme": "generalized-alpha", "rho_inf": 0.9, "formulation": "ggl"},
        {"scheme": "generalized-alpha", "rho_inf": 0.5},
        {"scheme": "trapezoidal"},
        # The defaults: index-3 generalised-alpha without rho_inf is the stable 0.5, GGL 0.9.
        {"scheme": "generalized-alpha"},
        {"scheme": "generalized-alpha", "formulation": "ggl"},
    ],
)
def test_the_advised_choices_are_stable_at_the_same_step(options):
    # What the error advises, at the same 47 steps a period: the stabilised index-2 form, a
    # smaller rho_inf, and the trapezoidal rule. Reference: the exact energy is constant; these
    # lose at most 0.2 m g L (measured: GGL 2e-2, rho_inf 0.5 1.6e-1, trapezoidal 1e-2 or less)
    # and never gain more than 1e-2 m g L.
    solution = vinculo.simulate(_pendulum(), t_end=20.0, dt=0.05, **options)
    assert solution.success
    energy = solution.energy() / G
    assert np.max(energy - energy[0]) < 1e-2
    assert np.min(energy - energy[0]) > -0.2


@pytest.mark.parametrize("formulation, rho_inf", [("index-3", 0.5), ("ggl", 0.9)])
def test_the_default_rho_inf_is_the_stable_choice_of_each_formulation(formulation, rho_inf):
    # The defaults come from the measured stability table of docs/theory/time-rules.md: index-3
    # generalised-alpha at 0.5 (stable from 10 steps a period), GGL at 0.9 (stable at every step).
    # A run without rho_inf is the run with that value, bit for bit.
    run = functools.partial(
        vinculo.simulate, _pendulum(), t_end=2.0, dt=0.05, scheme="generalized-alpha"
    )
    default = run(formulation=formulation)
    explicit = run(formulation=formulation, rho_inf=rho_inf)
    np.testing.assert_array_equal(default.positions, explicit.positions)


def test_an_adaptive_step_below_the_resolution_of_t_stops_with_a_typed_error():
    # Error-controlled steps at t = 1e6 s whose Newton solves cannot converge (a tolerance of
    # 1e-30 m, below round-off) shrink towards h_min = 1e-15 s; below 50 float spacings of t
    # (5.8e-9 s) t + h no longer advances t by h, and the run stops there, naming the step, the
    # time and the smallest resolved step (50 np.spacing(t), the reference), instead of taking
    # steps that repeat times.
    with pytest.raises(vinculo.StepSizeTooSmallError) as caught:
        vinculo.simulate(
            _pendulum(), t_start=1e6, t_end=1e6 + 0.01, dt=1e-6, adaptive=True, h_min=1e-15,
            tolerance=1e-30, max_iterations=3,
        )
    error = caught.value
    assert 1e6 <= error.time < 1e6 + 0.01
    assert error.h_min == pytest.approx(50 * np.spacing(error.time), rel=1e-12)
    assert error.step_size < error.h_min
    assert np.all(np.diff(error.solution.times) > 0)


@pytest.mark.parametrize("extra", [1e-10, 4e-10, 2e-9, 5e-9])
def test_an_end_a_few_float_spacings_past_the_grid_is_reached_by_a_stretched_step(extra):
    # t_end a few spacings of t (1.16e-10 s at 1e6 s) past the last grid point: the last step
    # is stretched over the remainder instead of a step the times cannot resolve. Reference:
    # the run ends exactly at t_end after 100 steps, every step within 1e-3 of dt.
    t_end = 1e6 + 1e-3 + extra
    solution = vinculo.simulate(_pendulum(), t_start=1e6, t_end=t_end, dt=1e-5)
    assert solution.success
    assert solution.times[-1] == t_end and len(solution.times) == 101
    np.testing.assert_allclose(np.diff(solution.times), 1e-5, rtol=1e-3)
