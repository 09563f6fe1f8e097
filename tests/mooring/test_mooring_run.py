"""``vinculo mooring run``: the coupled point follows the recorded motion, and the outputs
(tensions over time, the NetCDF file, the plots) hold the run."""

import csv
from pathlib import Path

import numpy as np
import pytest

from vinculo import cli
from vinculo.mooring import Motion, read_moordyn

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn"
HANGING = DATA / "hanging_line.txt"
PNG = b"\x89PNG\r\n\x1a\n"


def _motion_file(tmp_path):
    """A 0.5 m surge of the fairlead of hanging_line.txt over 4 s, sampled every 0.05 s."""
    model = read_moordyn(HANGING)
    motion = Motion.harmonic([model.points[1].position], (0.5, 0.0, 0.0), period=4.0,
                             ramp_time=1.0)
    return motion, motion.to_csv(tmp_path / "motion.csv", np.arange(0.0, 4.0001, 0.05))


def test_run_moves_the_fairlead_and_writes_its_results(tmp_path, capsys):
    xarray = pytest.importorskip("xarray")
    motion, path = _motion_file(tmp_path)
    output = tmp_path / "out"
    code = cli.main(["mooring", "run", str(HANGING), "--motion", str(path), "--t-end", "2",
                     "--dt", "0.01", "--output", str(output), "--no-progress"])
    assert code == 0
    assert "line 1: end B tension" in capsys.readouterr().out
    with (output / "tensions.csv").open() as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["time"] + [f"line1_{e}_{q}" for e in "AB"
                                  for q in ("fx", "fy", "fz", "tension")]
    table = np.array(rows[1:], dtype=float)
    assert table[0, 0] == 0.0 and table[-1, 0] == pytest.approx(2.0)
    np.testing.assert_allclose(table[:, 8], np.linalg.norm(table[:, 5:8], axis=1), rtol=1e-12)
    # The fairlead (point 2) follows the recorded motion: the natural spline through samples of
    # the harmonic law, within the spline's error (0.05 s samples of a 4 s period: ~1e-6 m).
    run = xarray.open_dataset(output / "run.nc", engine="h5netcdf")
    times = run["time"].values
    np.testing.assert_allclose(times, table[:, 0], atol=1e-12)
    fairlead = run["positions"].values[:, 1, :]
    expected = np.array([motion.positions(t)[0] for t in times])
    np.testing.assert_allclose(fairlead, expected, atol=1e-5)
    run.close()
    for name in ("shapes.png", "tensions.png"):
        assert (output / name).read_bytes()[:8] == PNG


def test_run_api_returns_the_end_forces(tmp_path):
    import vinculo.mooring as mooring

    _motion, path = _motion_file(tmp_path)
    result = mooring.run(HANGING, path, 1.0, dt=0.01)
    assert result.end_forces.shape == (result.times.size, 1, 2, 3)
    statics = mooring.statics(HANGING)
    # Starting from the equilibrium, with the fairlead at rest at t = 0 (a smooth start), the
    # first stored end tensions are the static ones (1e-2: the first step's transient).
    np.testing.assert_allclose(result.end_tensions[0, 0],
                               [statics.ends[0].tension, statics.ends[1].tension], rtol=1e-2)


def test_states_stored_every_few_steps_are_the_steps_own(tmp_path):
    # output_every (MoorDyn's dtOut) stores every fifth step of 0.01 s: the same states, bit
    # for bit, as the run that stores every step (the steps do not depend on what is stored),
    # and a value that is not a whole number of steps is refused naming it.
    import vinculo.mooring as mooring
    from vinculo.errors import InvalidInputError

    _motion, path = _motion_file(tmp_path)
    every_step = mooring.run(HANGING, path, 1.0, dt=0.01, plots=False)
    fifth = mooring.run(HANGING, path, 1.0, dt=0.01, output_every=0.05, plots=False)
    np.testing.assert_allclose(fifth.times, np.arange(0.0, 1.0001, 0.05), atol=1e-12)
    np.testing.assert_array_equal(fifth.end_forces, every_step.end_forces[::5])
    with pytest.raises(InvalidInputError, match=r"output_every = 0\.015"):
        mooring.run(HANGING, path, 1.0, dt=0.01, output_every=0.015, plots=False)


def test_a_looser_newton_tolerance_changes_the_tensions_within_its_documented_bound(tmp_path):
    # --tolerance passes Newton's tolerance to the run. The benchmark's hanging chain (20
    # segments, 2 m of surge in 10 s, 0.1 s steps, 20 s): at 1e-8 its end tensions are within
    # 1e-4 of the peak tension of a run at 1e-12 (measured 7.6e-5; the guide's table, of the end
    # segments' tensions, 7.9e-5), and it takes fewer Newton iterations than the default 1e-10
    # (5.41 residuals a step against 6.85, measured). The bound is ten times below the
    # benchmark's accuracy target of 1e-3 of the peak tension (docs/guide/moorings.md, "A run
    # with moving fairleads").
    import vinculo.mooring as mooring
    from vinculo.mooring.bench import CASES, motion_for
    from vinculo.mooring.moordyn_file import write_moordyn

    model = CASES["hanging"](20)
    motion = motion_for(model)
    model_path = write_moordyn(model, tmp_path / "hanging.txt")
    motion_path = motion.to_csv(tmp_path / "motion.csv", np.arange(0.0, 20.0001, 0.02))
    output = tmp_path / "out"
    code = cli.main(["mooring", "run", str(model_path), "--motion", str(motion_path),
                     "--t-end", "20", "--dt", "0.1", "--tolerance", "1e-8", "--output",
                     str(output), "--no-progress", "--no-plots"])
    assert code == 0
    with (output / "tensions.csv").open() as handle:
        rows = list(csv.reader(handle))
    loose = np.array(rows[1:], dtype=float)[:, [4, 8]]
    run = {"plots": False}
    tight = mooring.run(model_path, motion_path, 20.0, dt=0.1, tolerance=1e-12, **run)
    default = mooring.run(model_path, motion_path, 20.0, dt=0.1, **run)
    cheap = mooring.run(model_path, motion_path, 20.0, dt=0.1, tolerance=1e-8, **run)
    reference = tight.end_tensions[:, 0, :]
    change = np.abs(loose - reference).max() / np.abs(reference).max()
    assert change < 1e-4, change
    # The CLI's run is the API's with the same tolerance.
    np.testing.assert_allclose(loose, cheap.end_tensions[:, 0, :], rtol=1e-12)
    assert (cheap.solution.residual_evaluations
            < 0.9 * default.solution.residual_evaluations)
