"""The step predictor's lagged extrapolation on lines with unresolved stiff modes (run.rs, "The
predictor"; docs/theory/newton.md)."""

import numpy as np
import pytest

from vinculo.mooring import bench
from vinculo.mooring.analysis import run


@pytest.mark.parametrize(("case", "bound", "gap"),
                         [("hanging", 1.19, 5e-6), ("bending", 1.85, 2e-4)])
def test_alternating_accelerations_are_extrapolated_with_the_lagged_rate(case, bound, gap):
    # The benchmark's lines of 20 segments at 5 ms steps (the trapezoidal rule, modified
    # Newton): their axial and bending modes are too stiff for the step, and the trapezoidal
    # rule leaves their response alternating in sign from step to step. Extrapolating with the
    # rate of the step before the last (a_n + a_{n-1} - a_{n-2}, exact for such a part) where
    # it predicted the last step better, the runs take 1.11 (hanging chain) and 1.68 (cable)
    # residual evaluations a step over these 10 s, measured; with the last step's rate
    # (2 a_n - a_{n-1}) alone they took 1.27 and 2.03.
    model = bench.CASES[case](20)
    motion = bench.motion_for(model)
    result = run(model, motion, 10.0, dt=0.005, plots=False)
    solution = result.solution
    assert solution.residual_evaluations / solution.steps_taken < bound
    # The predictor moves only where Newton starts: the tensions are full Newton's (a new
    # matrix at every iteration) to within modified Newton's stop, which leaves up to about the
    # tolerance in the positions (docs/theory/newton.md). Measured, relative to the peak
    # tension: 4.6e-7 (hanging chain) and 9.4e-5 (cable), against 1.8e-6 and 6.1e-5 with the
    # last step's rate alone.
    full = run(model, motion, 10.0, dt=0.005, plots=False, jacobian_reuse=False)
    peak = np.abs(full.segment_tensions).max()
    assert np.abs(result.segment_tensions - full.segment_tensions).max() <= gap * peak
