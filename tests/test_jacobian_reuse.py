"""The default reuse of Newton's iteration matrix (docs/theory/newton.md): the answer of full
Newton at fewer factorisations, and its option's values."""

import numpy as np
import pytest

import vinculo
from vinculo import demos
from vinculo.bench.models import Chain, build_vinculo


def pendulum_bob(**options) -> tuple[np.ndarray, int]:
    """The 1 m pendulum released horizontally, 10 s of generalised-alpha (rho_inf = 0.9) at
    dt = 1 ms (the benchmark's pendulum): the bob's path and the factorisations made."""
    model = demos.build_pendulum()
    solution = vinculo.simulate(model.system, 10.0, 1e-3, scheme="generalized-alpha",
                                rho_inf=0.9, **options)
    return solution.particle(model.bob), solution.factorisations


def test_the_default_stays_with_full_newton_where_modified_newton_drifts():
    # Reference: full Newton, whose per-step error is far below the tolerance (quadratic
    # convergence). Modified Newton stops each step with an error near the tolerance (1e-10 m),
    # always on the predictor's side: over 10^4 steps it drifts by 4.5e-6 m (1e-4 m when the
    # predictor kept the last multipliers instead of extrapolating them). The default stops an
    # iteration made with a kept matrix at a thousandth of the tolerance: measured 4e-10 m from
    # full Newton, at fewer than half its factorisations.
    full, full_factorisations = pendulum_bob(jacobian_reuse=False)
    default, factorisations = pendulum_bob()
    modified, _ = pendulum_bob(jacobian_reuse=True)
    assert np.max(np.abs(default - full)) < 1e-8
    assert np.max(np.abs(modified - full)) > 1e-6
    # The predictor extrapolates the multipliers over the step (run.rs): each step's first
    # increment is smaller, and so is modified Newton's one-signed stopping error (4.5e-6 m
    # over the run; 1e-4 m when the predictor kept the last multipliers).
    assert np.max(np.abs(modified - full)) < 1e-5
    assert factorisations < full_factorisations / 2


def test_a_chain_at_rest_keeps_one_matrix_for_the_whole_run():
    # A chain hanging at rest: every step's iteration matrix is the same up to round-off, so the
    # default factorises once (the first step) where full Newton factorises every step, and
    # each step takes one iteration as in full Newton (the kept matrix was assembled within the
    # tolerance of every step's start); the chain stays at rest (positions to round-off of the
    # 1 m chain).
    model = demos.build_hanging_chain(num_links=20, length=1.0, mass=1.0, angle=0.0)
    default = vinculo.simulate(model.system, 0.5, 1e-3)
    full = vinculo.simulate(model.system, 0.5, 1e-3, jacobian_reuse=False)
    assert default.factorisations == 1
    assert full.factorisations == 500
    assert np.all(default.newton_iterations[1:] == 1)
    assert np.max(np.abs(default.positions - default.positions[0])) < 1e-12
    assert np.max(np.abs(default.positions - full.positions)) < 1e-12


@pytest.mark.parametrize("value", ["full", 2, None])
def test_jacobian_reuse_takes_auto_true_or_false(value):
    model = demos.build_pendulum()
    with pytest.raises(vinculo.InvalidInputError, match="jacobian_reuse must be 'auto'"):
        vinculo.simulate(model.system, 0.1, 1e-3, jacobian_reuse=value)


def test_a_long_chain_at_rest_iterates_as_full_newton_does():
    # A chain of 1,000 links at rest at a tight tolerance (1e-12 of its 100 m): the trapezoidal
    # rule does not damp the round-off its multipliers carry from step to step, so that within
    # a few hundred steps each step's predictor is farther than the tolerance from the point
    # the kept matrix was assembled at, and its first increment is no longer Newton's. The
    # second increment, made at a distance delta from that point, differs from Newton's by
    # about L delta |dx| and counts as Newton's when delta |dx| <= tolerance^2
    # (docs/theory/newton.md): the default then takes the residuals full Newton takes (1.98 a
    # step, measured), where stopping only below a thousandth of the tolerance took 2.48.
    # Reference: full Newton on the same run, whose stop leaves about the increment squared.
    model = Chain("chain at rest", 1000, hanging=True, t_end=3.0)
    system, _ = build_vinculo(model)
    runs = [vinculo.simulate(system, model.t_end, model.dt, save_every=model.steps,
                             tolerance=1e-12, jacobian_reuse=reuse) for reuse in ("auto", False)]
    default, full = runs
    assert default.factorisations == 1
    assert default.residual_evaluations <= 1.02 * full.residual_evaluations
    # Tensions (the top one is 4,905 N) agree with full Newton's to 1e-8 of it (2.3e-9
    # measured), positions to round-off of the 100 m chain.
    top = full.multipliers[-1, 0]
    assert np.max(np.abs(default.multipliers[-1] - full.multipliers[-1])) < 1e-8 * top
    assert np.max(np.abs(default.positions[-1] - full.positions[-1])) < 1e-12
