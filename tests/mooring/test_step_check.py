"""The time-step check of a mooring run: the change of its end tensions when the step is halved
estimates its time-step error.

Reference, Richardson's: a run whose error is e(dt) = C dt^p changes by
e(dt) - e(dt / 2) = (1 - 2^-p) e(dt) when its step is halved, so its error is 4/3 of that change
for the trapezoidal rule's second order, twice it where the run is first order. Over a run, the
largest difference (a peak shifted in time) follows that loosely: the error against a run at
dt / 16 is asserted between 0.8 and 2.5 times the largest change.
"""

import numpy as np
import pytest

from vinculo.mooring import bench
from vinculo.mooring.analysis import check_step, run


@pytest.mark.parametrize(("case", "dt"), [("hanging", 0.1), ("chain", 0.02)])
def test_the_change_when_the_step_halves_is_about_the_error(case, dt):
    model = bench.CASES[case](20)
    motion = bench.motion_for(model)
    result = run(model, motion, 20.0, dt=dt, plots=False)
    check = check_step(result)
    reference = run(model, motion, 20.0, dt=dt / 16, plots=False, t_eval=result.times)
    error = np.abs(result.end_tensions - reference.end_tensions).max()
    # Measured: 1.04 (hanging chain) and 1.35 (chain on the seabed, with its touchdowns).
    assert 0.8 <= error / check.change.max() <= 2.5
    assert check.relative == pytest.approx(check.change.max() / check.peak)
    # Where and when: the line end and time of the largest change.
    k = [row.id for row in model.lines].index(check.line)
    at = np.flatnonzero(result.times == check.time)[0]
    half = run(model, motion, 20.0, dt=dt / 2, plots=False, t_eval=result.times)
    assert abs(result.end_tensions[at, k, "AB".index(check.end)]
               - half.end_tensions[at, k, "AB".index(check.end)]) == check.change.max()


def test_the_command_prints_the_check(tmp_path, capsys):
    from vinculo.cli import main
    from vinculo.mooring import write_moordyn

    model = bench.CASES["hanging"](20)
    path = write_moordyn(model, tmp_path / "hanging.txt")
    argv = ["mooring", "run", str(path), "--t-end", "2", "--dt", "0.1", "--check-step",
            "--no-plots", "--no-progress", "--output", str(tmp_path / "out")]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "time-step check: the end tensions change by up to " in out
    assert "when the step is halved to 0.05 s" in out
