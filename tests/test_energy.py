"""Energy of a chain of rigid links under gravity: conserved at alpha = 1/2, decaying above."""

import numpy as np
import pytest

from vinculo import demos

NUM_LINKS = 5
T_END = 10.0
DT = 1e-3


def run_chain(alpha: float) -> demos.HangingChainResult:
    """A 1 m, 1 kg chain of 5 links released at rest, straight and tilted 60 degrees."""
    model = demos.build_hanging_chain(num_links=NUM_LINKS, length=1.0, mass=1.0, angle=np.pi / 3)
    return demos.run_hanging_chain(t_end=T_END, dt=DT, alpha=alpha, model=model)


def test_energy_is_conserved_by_the_trapezoidal_rule():
    # Why it holds to round-off: with alpha = 1/2, q1 - q0 = dt (v0 + v1)/2, so the kinetic energy
    # change equals the work of the forces over the step at the midpoint. Gravity is constant (its
    # work is exactly -dV), and for the quadratic distance constraints Phi_q(q_mid) (q1 - q0) =
    # Phi(q1) - Phi(q0) = 0: the multipliers do no work. The only error left is the Newton
    # tolerance (1e-10, scaled) per step: even accumulating systematically over 1e4 steps it
    # stays below 1e-6; in practice Newton converges quadratically and the drift is ~1e-14.
    result = run_chain(alpha=0.5)
    assert result.solution.num_steps == round(T_END / DT)
    assert result.relative_energy_drift < 1e-8
    # The run did move: most of the potential energy became kinetic at some point.
    kinetic = result.solution.kinetic_energy()
    assert np.max(kinetic) > 0.2 * result.energy_scale


@pytest.mark.parametrize("alpha", [0.6, 1.0])
def test_energy_decays_when_alpha_exceeds_one_half(alpha):
    # With y^alpha = (1 - alpha) y0 + alpha y1 the same computation gives, per step,
    #   dE = -(alpha - 1/2) (|v1 - v0|_M^2 + 2 sum_k lambda_k |d(q_i - q_j)|^2),
    # which is negative whenever every link is in tension (lambda > 0), as it is for this chain.
    result = run_chain(alpha=alpha)
    assert np.min(result.solution.multipliers) > 0, "the derivation assumes taut links"
    energy = result.energy
    step_change = np.diff(energy) / result.energy_scale
    assert np.all(step_change < 0), f"energy rose at step {np.argmax(step_change)}"
    loss = (energy[0] - energy[-1]) / result.energy_scale
    # Observed ~1.6 % of m g L for alpha = 0.6 and ~6.6 % for alpha = 1 over 10 s.
    assert loss > {0.6: 0.005, 1.0: 0.03}[alpha]


def test_more_damping_for_larger_alpha():
    # The dissipation grows with alpha - 1/2 (see the per-step formula above).
    losses = []
    for alpha in (0.55, 0.75, 1.0):
        energy = run_chain(alpha=alpha).energy
        losses.append(energy[0] - energy[-1])
    assert losses[0] < losses[1] < losses[2]


def long_chain(num_links: int, t_end: float, **options) -> demos.HangingChainResult:
    """A 1 m, 1 kg chain of many links, released straight at 60 degrees, stepped at 1 ms."""
    model = demos.build_hanging_chain(num_links=num_links, length=1.0, mass=1.0, angle=np.pi / 3)
    return demos.run_hanging_chain(t_end=t_end, dt=1e-3, alpha=0.5, model=model, **options)


def test_long_chain_under_tension_converges():
    # docs/theory/newton.md: without the constraint Hessian term lambda . Phi_qq in the Jacobian,
    # Newton
    # diverges on a 1 m chain of 300 particles at dt = 1e-3. With it, Newton converges
    # quadratically: a handful of iterations per step, energy and lengths held to round-off.
    # Full Newton, whose rate this is about (the default keeps a matrix for more, cheaper
    # iterations).
    result = long_chain(num_links=300, t_end=0.5, jacobian_reuse=False)
    solution = result.solution
    assert solution.success
    assert np.max(solution.newton_iterations) <= 6
    np.testing.assert_allclose(solution.step_sizes[1:], 1e-3, rtol=1e-9)  # no step was halved
    assert np.max(solution.constraint_residual) < 1e-12 * (1.0 / 300)
    assert result.relative_energy_drift < 1e-8


@pytest.mark.slow
def test_long_chain_over_a_long_run():
    # The same chain for 10 s (about 15 s of computing): the conservation does not degrade.
    result = long_chain(num_links=300, t_end=10.0)
    assert result.relative_energy_drift < 1e-8
    assert np.max(result.solution.constraint_residual) < 1e-12 * (1.0 / 300)
