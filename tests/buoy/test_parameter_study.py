"""Parameter studies: grids, resumable results files, local processes and a Dask cluster.

Reference for every number: :func:`vinculo.buoy.study.run_task` run directly in this process
with the same case and settings (the study must reproduce it exactly, wherever it runs).
"""

from __future__ import annotations

import dataclasses
import socket

import numpy as np
import pytest

from vinculo.buoy import BuoyCase, SweepSettings
from vinculo.buoy.parameter_study import grid, parse_axis, run_parameter_study
from vinculo.buoy.study import run_task
from vinculo.cli import main
from vinculo.errors import InvalidInputError, SchedulerError

# Short runs: what is tested is the bookkeeping and the equality with the direct run.
SETTINGS = SweepSettings(settle_periods=8, fit_periods=3, dt=5e-3)


def _direct(point: dict, model: str = "particle") -> float:
    case_fields = {k: v for k, v in point.items() if k != "frequency"}
    case = dataclasses.replace(BuoyCase(), **case_fields)
    return run_task(case, SETTINGS, model, point["frequency"]).response.relative_amplitude


def test_parse_axis_ranges_lists_and_types():
    assert parse_axis("drag_coefficient=0.1:0.4:4") == (
        "drag_coefficient", pytest.approx([0.1, 0.2, 0.3, 0.4])
    )
    assert parse_axis("string-beads=0,2") == ("string_beads", [0, 2])
    assert parse_axis("attachment=bottom,centre") == ("attachment", ["bottom", "centre"])
    with pytest.raises(InvalidInputError, match="unknown study parameter 'cd'"):
        parse_axis("cd=0.1")
    with pytest.raises(InvalidInputError, match="has no points"):
        parse_axis("amplitude=0.001:0.01:0")
    with pytest.raises(InvalidInputError, match="whole numbers"):
        parse_axis("string_beads=1.5")
    with pytest.raises(InvalidInputError, match="no values"):
        parse_axis("amplitude=")
    with pytest.raises(InvalidInputError, match="grid has no points"):
        grid({"amplitude": []})


def test_study_equals_direct_runs_and_resumes_without_recomputing(tmp_path):
    points = grid({"drag_coefficient": [0.1, 0.4], "frequency": [0.8, 1.0]})
    first = run_parameter_study(points, settings=SETTINGS, output=tmp_path, workers=2,
                                progress=False)
    assert first.computed == 4 and first.reused == 0 and not first.failures()
    for row in first.rows:
        assert row.results["relative_amplitude"] == pytest.approx(
            _direct(row.parameters), rel=1e-12
        )
    # Interrupt simulation: drop the last row and cut the one before in the middle.
    path = tmp_path / "study.csv"
    lines = path.read_text().splitlines(keepends=True)
    path.write_text("".join(lines[:-2]) + lines[-2][:20])
    again = run_parameter_study(points, settings=SETTINGS, output=tmp_path, workers=1,
                                progress=False)
    assert again.reused == 2 and again.computed == 2
    assert len(path.read_text().splitlines()) == 1 + 4  # header and the four runs, once each
    amplitudes = {tuple(r.parameters.values()): r.results["relative_amplitude"]
                  for r in again.rows}
    for row in first.rows:  # values read back from the file equal the computed ones
        assert amplitudes[tuple(row.parameters.values())] == row.results["relative_amplitude"]


def test_failed_run_is_recorded_and_the_others_kept(tmp_path):
    # A sphere denser than water pulls the string down: the particle run stops with a negative
    # tension (NegativeTensionError); the other density runs normally.
    points = grid({"sphere_density": [366.69, 1500.0], "frequency": [0.9]})
    study = run_parameter_study(points, settings=SETTINGS, output=tmp_path, workers=1,
                                progress=False)
    failed = study.failures()
    assert len(failed) == 1 and failed[0].parameters["sphere_density"] == 1500.0
    assert "NegativeTensionError" in failed[0].error
    ok = [r for r in study.rows if r.status == "ok"]
    assert ok[0].results["relative_amplitude"] == pytest.approx(
        _direct(ok[0].parameters), rel=1e-12
    )
    text = (tmp_path / "study.csv").read_text()
    assert "failed" in text and "NegativeTensionError" in text


def test_without_frequency_axis_each_point_is_swept():
    settings = dataclasses.replace(SETTINGS, f_min=0.8, f_max=1.0, count=2)
    study = run_parameter_study(grid({"amplitude": [0.004]}), settings=settings, workers=1,
                                progress=False)
    assert sorted(r.parameters["frequency"] for r in study.rows) == [0.8, 1.0]


def test_results_file_of_another_study_is_refused(tmp_path):
    run_parameter_study(grid({"amplitude": [0.004], "frequency": [1.0]}), settings=SETTINGS,
                        output=tmp_path, workers=1, progress=False)
    with pytest.raises(InvalidInputError, match="choose another --output"):
        run_parameter_study(grid({"drag_coefficient": [0.3], "frequency": [1.0]}),
                            settings=SETTINGS, output=tmp_path, workers=1, progress=False)


def test_unreachable_scheduler_is_a_typed_error_and_writes_nothing(tmp_path):
    with pytest.raises(SchedulerError, match="cannot reach the Dask scheduler"):
        run_parameter_study(grid({"amplitude": [0.004], "frequency": [1.0]}),
                            settings=SETTINGS, output=tmp_path, scheduler="tcp://127.0.0.1:9",
                            scheduler_timeout=1.0, progress=False)
    assert not (tmp_path / "study.csv").exists()


def _occupy(port: int) -> socket.socket | None:
    """Listen on ``port`` (None if something else already does: it is occupied either way)."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        sock.bind(("", port))
        sock.listen(1)
    except OSError:
        sock.close()
        return None
    return sock


def test_dask_local_cluster_gives_the_same_results(tmp_path):
    distributed = pytest.importorskip("distributed")
    points = grid({"drag_coefficient": [0.2, 0.3], "frequency": [0.9]})
    # Dask's default dashboard port, 8787, taken first: the cluster must not need it (Dask reads
    # dashboard_address=None as 8787 and warns, an error under pytest; ":0" takes a free port).
    blocker = _occupy(8787)
    try:
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                      dashboard_address=":0") as cluster:
            study = run_parameter_study(points, settings=SETTINGS, output=tmp_path,
                                        scheduler=cluster.scheduler_address, progress=False)
    finally:
        if blocker is not None:
            blocker.close()
    assert study.workers.startswith("dask tcp://") and study.computed == 2
    for row in study.rows:
        assert row.results["relative_amplitude"] == pytest.approx(
            _direct(row.parameters), rel=1e-12
        )


def test_cli_sweep_writes_table_and_plot(tmp_path, capsys):
    code = main([
        "buoy", "sweep", "-p", "drag_coefficient=0.1,0.4", "-p", "frequency=0.9",
        "--settle-periods", "8", "--fit-periods", "3", "--dt", "5e-3", "-o", str(tmp_path),
        "--workers", "1", "--no-progress",
    ])
    assert code == 0
    assert (tmp_path / "study.png").is_file()
    rows = (tmp_path / "study.csv").read_text().splitlines()
    assert len(rows) == 3
    # less drag, larger resonant amplitude (drag is the only damping)
    amplitude = {float(r.split(",")[0]): float(r.split(",")[7]) for r in rows[1:]}
    assert amplitude[0.1] > amplitude[0.4]
    assert np.isclose(amplitude[0.1], _direct({"drag_coefficient": 0.1, "frequency": 0.9}))
    assert main(["buoy", "sweep", "-p", "cd=1", "-o", str(tmp_path)]) == 2  # a bad argument
    assert "unknown study parameter 'cd'" in capsys.readouterr().err
