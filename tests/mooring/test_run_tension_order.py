"""The end tensions of a mooring run converge at the time rule's order.

The trapezoidal rule is second order, but its multiplier, the segment's tension, is the tension
at the step's midpoint, where it acts (``docs/theory/moorings.md``): read as the tension at the
step's end it is off by half a step of the tension's rate, a first-order error. The run reports
the tension at the stored time from Hooke's law at the stored positions, which converges at
second order: halving the step divides the error (against a run at a 16 times smaller step) by
about 4; the midpoint multiplier's error only halves. Measured on this case (a 10-segment chain
hanging in water, its fairlead surging 2 m with a 4 s period; steps of 0.1, 0.05 and 0.025 s):
ratios 4.1 and 3.4 for the reported tension, 2.2 and 2.4 for the multiplier.
"""

import numpy as np

from vinculo.mooring.analysis import run
from vinculo.mooring.bench import hanging_line
from vinculo.mooring.motion import Motion

T_END = 4.0


def _motion(model):
    return Motion.harmonic([p.position for p in model.coupled_points()], (2.0, 0.0, 0.0),
                           period=4.0, ramp_time=2.0)


def _errors(quantity):
    model = hanging_line(10)
    motion = _motion(model)
    grid = np.arange(0.0, T_END + 1e-9, 0.2)

    def at(dt):
        r = run(model, motion, T_END, dt=dt, scheme="trapezoidal", jacobian_reuse=False)
        values = quantity(r)
        return np.column_stack([np.interp(grid, r.times, values[:, k])
                                for k in range(values.shape[1])])

    reference = at(0.1 / 16)
    scale = np.abs(reference).max()
    return [np.abs(at(dt) - reference).max() / scale for dt in (0.1, 0.05, 0.025)]


def test_reported_end_tensions_converge_at_second_order():
    errors = _errors(lambda r: r.segment_tensions.reshape(len(r.times), -1))
    ratios = [errors[k] / errors[k + 1] for k in range(2)]
    assert all(3.0 < q < 5.0 for q in ratios), (errors, ratios)


def test_the_midpoint_multiplier_is_first_order_at_the_stored_times():
    # The contrast that makes the test above meaningful: the raw multipliers of the end
    # segments, read at the stored times, converge at first order only.
    def multipliers(r):
        line = r.model.lines[0]
        m = np.asarray(r.solution.multipliers, dtype=float)
        return m[:, [line.segments[0].index, line.segments[-1].index]]

    errors = _errors(multipliers)
    ratios = [errors[k] / errors[k + 1] for k in range(2)]
    assert all(1.7 < q < 2.6 for q in ratios), (errors, ratios)
