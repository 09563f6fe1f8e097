"""The mooring benchmark's cases are the example files that MoorDyn runs in the tests, and the
axial-wave estimate of MoorDyn's step is the time a wave takes to cross a segment."""

import dataclasses
import math
from pathlib import Path

import pytest

from vinculo.mooring import read_moordyn
from vinculo.mooring.bench import CASES, wave_step

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn"
FILES = {"chain": "chain_on_seabed", "hanging": "hanging_line", "bending": "bending_line"}


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_benchmark_cases_are_the_example_files(name):
    built = CASES[name](read_moordyn(DATA / f"{FILES[name]}.txt").lines[0].segments)
    stored = read_moordyn(DATA / f"{FILES[name]}.txt")
    assert built.line_types == stored.line_types
    assert built.points == stored.points
    assert built.lines == stored.lines
    keep = ("depth", "density", "gravity", "kbot", "cbot", "friction", "time_step")
    assert {k: getattr(built.options, k) for k in keep} == {
        k: getattr(stored.options, k) for k in keep}
    assert dataclasses.replace(built.options, settings=()) == dataclasses.replace(
        stored.options, settings=())


def test_wave_step_is_a_segment_over_the_axial_wave_speed():
    # hanging_line: 100 m in 20 segments, EA = 1e8 N, 20 kg/m: 5 m / sqrt(5e6 m^2/s^2).
    assert wave_step(CASES["hanging"](20)) == pytest.approx(5.0 / math.sqrt(1e8 / 20.0),
                                                            rel=1e-15)


@pytest.mark.parametrize("value", ["fast", "0", "-0.01", "nan"])
def test_a_bad_per_step_value_is_refused_with_its_name(value, capsys):
    from vinculo.mooring.bench import main

    with pytest.raises(SystemExit) as stop:
        main(["--per-step", value, "--cases", "hanging"])
    assert stop.value.code == 2
    assert f"--per-step {value!r}" in capsys.readouterr().err


@pytest.mark.parametrize(("dt", "every"), [(0.005, 0.1), (0.02, 0.1), (0.07, 0.07), (0.03, 0.03)])
def test_a_timed_run_stores_as_moordyn_does_where_its_steps_allow(dt, every):
    # Both codes store their state every OUTPUT_INTERVAL (0.1 s, MoorDyn's output interval);
    # vinculo where that is a whole number of its steps, else at every step (its tensions are
    # then its steps' own, not interpolated between them).
    from vinculo.mooring.bench import OUTPUT_INTERVAL, motion_for, vinculo_run

    assert OUTPUT_INTERVAL == 0.1
    model = CASES["hanging"](5)
    result = vinculo_run(model, motion_for(model), 0.42, dt)
    times = result.times
    assert times[-1] == pytest.approx(0.42)
    spacing = times[1:-1] - times[:-2]
    assert spacing == pytest.approx(every, rel=1e-9)
