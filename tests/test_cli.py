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
    # The pendulum line compares with the exact period (2.367841947576237 s,
    # docs/theory/formulation.md).
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


def _exit_code(arguments: list[str]) -> int:
    """The command's exit code, whether it returns it or argparse exits."""
    try:
        return cli.main(arguments)
    except SystemExit as exit_:
        return int(exit_.code)


def _hostile_files(folder):
    binary = folder / "binary.toml"
    binary.write_bytes(b"\x00\xff\xfe\x01\x89PNG not text")
    utf16 = folder / "utf16.toml"
    utf16.write_bytes("[case]\namplitude = 0.004\n".encode("utf-16"))
    return binary, utf16


# Hostile input found by trying: each one was a traceback (ZeroDivisionError, UnicodeDecodeError,
# OverflowError, ValueError from numpy) or exit code 1; each must be a one-line error naming the
# value, with the exit code 2 that `vinculo --help` promises for bad arguments.
HOSTILE = [
    (["buoy", "sweep", "-p", "frequency=0"], "frequency = 0.0 Hz"),
    (["buoy", "sweep", "-p", "frequency=nan"], "frequency = nan Hz"),
    (["buoy", "sweep", "-p", "frequency=1e-300"], "time steps"),
    (["buoy", "sweep", "-p", "frequency=0.5:1:99999999999999999999"], "more than 10000"),
    (["buoy", "sweep", "-p", "drag_coefficient=0:1:5000", "-p", "amplitude=0.001:0.01:5000"],
     "more than 1000000"),
    (["buoy", "sweep", "-p", "string_beads=1e30"], "string_beads"),
    (["buoy", "sweep", "-p", "attachment=top"], "attachment"),
    (["buoy", "sweep", "-p", "cd=1"], "unknown study parameter 'cd'"),
    (["buoy", "--case", "{binary}"], "not UTF-8 text"),
    (["buoy", "--case", "{utf16}"], "UTF-16"),
    (["buoy", "--count", "99999999999999999999999"], "--count"),
    (["buoy", "--string-beads", "100000000000000000000"], "--string-beads"),
    (["buoy", "--fit-periods", "100000000000"], "fit_periods"),
    (["buoy", "--settle-periods", "1e308"], "settle_periods"),
    (["buoy", "--dt", "1e-300"], "dt = 1e-300"),
    (["buoy", "--amplitude", "1e400"], "--amplitude"),
    (["buoy", "--workers", "0"], "--workers"),
    (["buoy", "--attachment", "top"], "--attachment"),
    (["buoy", "--models", "particle,foo"], "--models: 'particle,foo'"),
    (["buoy", "--models", ","], "give one or more of particle, two-dof, one-dof"),
    (["buoy", "sweep", "-p", "frequency=0.9", "--models", ","], "--models"),
    (["buoy", "--tank-smoothing", "nan"], "--tank-smoothing"),
    (["buoy", "--animate", "1", "--animation-frames", "10000000000000"], "--animation-frames"),
    (["buoy", "--tank-motion", "{binary}"], "binary.toml"),
    (["buoy", "calibrate", "--data", "{utf16}"], "utf16.toml"),
    (["buoy", "calibrate", "--data", "{binary}", "--max-evaluations", "99999999999999"],
     "--max-evaluations"),
]


@pytest.mark.parametrize(("arguments", "named"), HOSTILE, ids=[" ".join(a) for a, _ in HOSTILE])
def test_hostile_input_is_a_typed_error_with_exit_code_2(tmp_path, capsys, arguments, named):
    binary, utf16 = _hostile_files(tmp_path)
    arguments = [a.format(binary=binary, utf16=utf16) for a in arguments]
    code = _exit_code([*arguments, "--output", str(tmp_path / "out"), "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "error" in err and named in err
    assert "Traceback" not in err
    assert not (tmp_path / "out" / "sweep.csv").exists()  # nothing ran


def test_output_folder_that_cannot_exist_is_refused_before_the_runs(tmp_path, capsys):
    # Before the fix the whole sweep ran, then writing failed with NotADirectoryError.
    blocker = tmp_path / "file"
    blocker.write_text("")
    code = _exit_code(["buoy", "--output", str(blocker / "out"), "--count", "1",
                       "--f-max", "0.5", "--no-progress"])
    assert code == 2
    assert "cannot create the output folder" in capsys.readouterr().err


def test_buoy_help_gives_units_and_valid_values(capsys):
    with pytest.raises(SystemExit):
        cli.main(["buoy", "--help"])
    text = " ".join(capsys.readouterr().out.split())  # argparse wraps lines
    # Every case and sweep option states its unit (case.UNITS, read off the dataclass
    # docstrings), e.g. "--amplitude AMPLITUDE in m (default: 0.005)".
    from vinculo.buoy.case import UNITS

    for name, unit in UNITS.items():
        if name in ("tank_size", "attachment", "viscous_force"):
            continue
        option = "--" + name.replace("_", "-")
        stated = {"count": "a count", "dimensionless": "dimensionless"}.get(unit, f"in {unit}")
        assert re.search(rf"{option} \S+ {re.escape(stated)} \(default", text), option
    assert "{bottom,centre}" in text  # the valid --attachment values
    assert "{none,stokes-layer}" in text  # the valid --viscous-force values
    unwrapped = re.sub(r"(\w)- (\w)", r"\1-\2", text)  # argparse may break at a hyphen
    assert "from: particle, two-dof, one-dof" in unwrapped  # the valid --models values
    assert re.search(r"--animate FREQ .*\(Hz\)", text)
    assert re.search(r"--tank-smoothing LAM .*s\^3", text)
