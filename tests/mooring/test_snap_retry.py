"""A step whose modified-Newton iterations fail is tried with full Newton before it is halved
(`crates/vinculo/src/run.rs`, module documentation).

The S-mooring of `tests/data/moordyn/s_mooring.txt` with its fairlead jerked by 12 m of surge and
4 m of heave in 6 s: the rope snaps taut every period (2.8 MN, from near zero), its segments going
slack and taut within a step. Reference: the same run with full Newton (a new matrix at every
iterate), which converges every step; the default's steps must then be the same steps, and its
tensions the same to Newton's tolerance. Before the full-Newton retry, the default halved 80 of
the 1,000 steps (and its peak tension was 36 N off full Newton's).
"""

from pathlib import Path

import numpy as np

from vinculo.mooring.analysis import run
from vinculo.mooring.motion import Motion

FILE = Path(__file__).parent.parent / "data" / "moordyn" / "s_mooring.txt"


def test_a_line_snapping_taut_takes_its_steps_whole():
    motion = Motion.harmonic([(0.0, 0.0, -15.0)], (12.0, 0.0, 4.0), 6.0, ramp_time=6.0)
    default = run(FILE, motion, 20.0, dt=0.02, plots=False)
    full = run(FILE, motion, 20.0, dt=0.02, plots=False, jacobian_reuse=False)
    assert full.solution.steps_rejected == 0
    assert default.solution.steps_rejected == 0
    peak = np.abs(full.end_tensions).max()
    assert peak > 2.5e6  # the snaps
    # Modified Newton stops within its tolerance of full Newton's iterate: 5e-6 of the peak
    # tension on the benchmark's lines (`vinculo.mooring.run`); measured here 4.5e-7.
    np.testing.assert_allclose(default.end_tensions, full.end_tensions, rtol=0, atol=5e-6 * peak)
