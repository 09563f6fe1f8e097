"""The ``vinculo`` command line."""

import re
from importlib import metadata

import pytest

from vinculo import cli

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
PLOTS = ["pendulum.png", "double_pendulum.png", "hanging_chain.png", "inclined_plane.png"]


def test_demo_writes_the_plots_and_reports_results(tmp_path, capsys):
    output = tmp_path / "plots"  # created by the command
    assert cli.main(["demo", "--output", str(output)]) == 0
    for name in PLOTS:
        data = (output / name).read_bytes()
        assert data[:8] == PNG_SIGNATURE and len(data) > 10_000, name
    out = capsys.readouterr().out
    # The pendulum line compares with the exact period (2.367841947576237 s, formulation.md).
    period = float(re.search(r"pendulum: period ([0-9.]+) s", out).group(1))
    assert period == pytest.approx(2.367841947576237, rel=1e-5)
    # The inclined-plane line: acceleration g sin 30 degrees.
    acceleration = float(re.search(r"acceleration ([0-9.]+) m/s\^2", out).group(1))
    assert acceleration == pytest.approx(9.81 / 2, rel=1e-9)
    assert out.count("plot: ") == 4


@pytest.mark.parametrize(
    "arguments",
    [[], ["frobnicate"], ["demo", "--bogus"], ["demo", "--output"]],
)
def test_bad_arguments_exit_with_code_2(arguments, capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(arguments)
    assert info.value.code == 2
    assert "usage: vinculo" in capsys.readouterr().err


def test_output_that_is_a_file_is_refused(tmp_path, capsys):
    existing = tmp_path / "a_file"
    existing.write_text("not a folder")
    with pytest.raises(SystemExit) as info:
        cli.main(["demo", "--output", str(existing)])
    assert info.value.code == 2
    assert "not a folder" in capsys.readouterr().err
    assert existing.read_text() == "not a folder"


def test_console_script_is_declared():
    # pyproject.toml declares `vinculo = "vinculo.cli:main"`; the installed package exposes it.
    scripts = metadata.entry_points(group="console_scripts")
    (entry,) = [e for e in scripts if e.name == "vinculo"]
    assert entry.value == "vinculo.cli:main"
    assert entry.load() is cli.main


def test_buoy_command_writes_tables_and_figures(tmp_path, capsys):
    # A two-frequency sweep of the particle and 2-DOF models: the files exist and the sweep table
    # holds the same amplitudes as the study (read back), within the 1 % of the study's tests.
    import csv

    out = tmp_path / "buoy"
    code = cli.main(
        ["buoy", "--output", str(out), "--f-min", "0.8", "--f-max", "1.0", "--count", "2",
         "--settle-periods", "12", "--fit-periods", "4", "--models", "particle,two-dof",
         "--workers", "1", "--no-progress"]
    )
    assert code == 0
    names = {p.name for p in out.iterdir()}
    assert {"parameters.csv", "sweep.csv", "histories.csv", "amplitude.png", "phase.png",
            "summary.txt", "history_0.80Hz.png"} <= names
    with (out / "sweep.csv").open() as f:
        rows = list(csv.DictReader(f))
    by = {(r["model"], float(r["frequency_hz"])): r for r in rows}
    for f in (0.8, 1.0):
        a = float(by[("particle", f)]["relative_amplitude"])
        b = float(by[("two-dof", f)]["relative_amplitude"])
        assert abs(a - b) < 1e-2 * b
    with (out / "parameters.csv").open() as f:
        params = {r["parameter"]: r for r in csv.DictReader(f)}
    assert params["amplitude"]["source"].startswith("ASSUMPTION")
    assert "resonance" in capsys.readouterr().out


def test_buoy_command_rejects_bad_values_by_name(tmp_path, capsys):
    # Each bad value is a clear error naming the value (exit code 2 for input errors).
    for args, word in ((["--diameter", "-0.1"], "diameter"), (["--count", "0"], "count"),
                       (["--drag-coefficient", "-1"], "drag_coefficient")):
        code = cli.main(["buoy", "--output", str(tmp_path), "--no-progress", *args])
        assert code != 0
        assert word in capsys.readouterr().err
    bad = tmp_path / "data.csv"
    bad.write_text("frequency,amplitude,phase\n0.8,0.01,10\n0.9,abc,12\n")
    code = cli.main(["buoy", "--output", str(tmp_path), "--data", str(bad), "--no-progress"])
    assert code != 0
    assert "line 3" in capsys.readouterr().err
