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
    # MoorDyn called at each of its steps: its fairlead follows the motion at the chord
    # velocity through each step (called every 0.01 s it moves at one velocity through several
    # steps, whose jumps the axial dashpots feel: 0.8 % of the peak tension at the fairlead).
    # Measured: the two codes 5.5e-5 apart, MoorDyn's change from 20 to 40 segments 1.8e-2.
    coarse = run_moordyn(model, motion, t_end, time_step=2e-4, coupling_step=2e-4)
    fine = run_moordyn(CASES["hanging"](40), motion, t_end, time_step=1e-4, coupling_step=1e-4)
    scale = coarse.segment_tensions.max()
    discretisation = np.abs(coarse.segment_tensions - fine.segment_tensions).max() / scale
    ours = mooring.run(model, motion, t_end, dt=0.01)
    tensions = _on(ours.times, ours.segment_tensions[:, 0, :], coarse.times)
    difference = np.abs(tensions - coarse.segment_tensions[:, 0, :]).max() / scale
    print(f"difference {difference:.2e}, MoorDyn 20 to 40 segments {discretisation:.2e}")
    assert difference <= max(discretisation, 1e-3), (difference, discretisation)


def test_s_mooring_buoy_settles_where_moordyn_does():
    # tests/data/moordyn/s_mooring.txt: the file puts the buoy 120 m deep; its buoyancy lifts it
    # and the chain's upper part until it floats just under the surface. MoorDyn 2.7.2 from its
    # dynamic relaxation (ICgenDynamic 1; its default solver left the buoy where the file put
    # it, with the chain at 35 kN), run 100 s without motion: the buoy swings slowly about its
    # equilibrium (the anchor tension within a range of 1.2 kN), so the reference is the mean
    # over the last 80 s. Measured: vinculo's statics within 5e-5 of those means, the buoy's
    # depth within 1 mm.
    from pathlib import Path

    from vinculo.mooring.model import build_model

    path = Path(__file__).parent.parent / "data" / "moordyn" / "s_mooring.txt"
    model = build_model(path)
    ours = np.array([np.linalg.norm(line.end_forces(model.statics), axis=-1).ravel()
                     for line in model.lines])
    theirs = run_moordyn(path, None, 100.0, dt_output=0.5, store_shapes=True)
    later = theirs.times >= 20.0
    tension = np.linalg.norm(theirs.end_forces, axis=-1)[later].mean(axis=0)
    depth = np.mean([shape[-1, 2] for shape in np.asarray(theirs.node_positions[0])[later]])
    np.testing.assert_allclose(ours, tension, rtol=1e-3)
    assert abs(model.statics.positions[model.points[1].index][2] - depth) < 0.01
