"""vinculo and MoorDyn on the same file with the same fairlead motion: the tensions at the line's
ends (of its first and last segments) agree within the lumped-mass discretisation error,
measured as the change of MoorDyn's tensions from 20 to 40 segments, or 1e-3."""

import numpy as np
import pytest

pytest.importorskip("moordyn")

from vinculo.mooring.bench import CASES, motion_for
from vinculo.mooring.peer import run_moordyn


def _on(times, values, grid):
    return np.column_stack([np.interp(grid, times, values[:, k]) for k in range(values.shape[1])])


@pytest.mark.slow
def test_hanging_chain_agrees_with_moordyn():
    import vinculo.mooring as mooring

    t_end = 20.0
    model = CASES["hanging"](20)
    motion = motion_for(model)
    # MoorDyn called at each of its steps: its fairlead follows the motion exactly (called
    # every 0.01 s it moves at a piecewise-constant velocity, whose jumps the axial dashpots
    # feel: 0.9 % of the peak tension at the fairlead).
    coarse = run_moordyn(model, motion, t_end, time_step=2e-4, coupling_step=2e-4)
    fine = run_moordyn(CASES["hanging"](40), motion, t_end, time_step=1e-4, coupling_step=1e-4)
    scale = coarse.segment_tensions.max()
    discretisation = np.abs(coarse.segment_tensions - fine.segment_tensions).max() / scale
    ours = mooring.run(model, motion, t_end, dt=0.01)
    tensions = _on(ours.times, ours.segment_tensions[:, 0, :], coarse.times)
    difference = np.abs(tensions - coarse.segment_tensions[:, 0, :]).max() / scale
    print(f"difference {difference:.2e}, MoorDyn 20 to 40 segments {discretisation:.2e}")
    assert difference <= max(discretisation, 1e-3), (difference, discretisation)
