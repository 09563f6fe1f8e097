"""MoorDyn's waves summed from their components (WaveKin 7, wave_frequencies.txt): reading them,
the surface they make against MoorDyn's formula, and MoorDyn itself on a chain in a wave."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from vinculo.errors import InvalidInputError, MooringFileError
from vinculo.mooring import read_moordyn
from vinculo.mooring.analysis import run
from vinculo.mooring.model import file_water
from vinculo.mooring.moordyn_file import write_moordyn
from vinculo.mooring.wave_components import WaveComponents, read_wave_frequencies

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn" / "waves"


def test_the_components_are_read_and_written_back(tmp_path):
    waves = read_wave_frequencies(DATA / "wave_frequencies.txt")
    # The zero-frequency row of no amplitude (MoorDyn's spectra start with one) is left out.
    np.testing.assert_array_equal(waves.omegas, [0.8])
    assert waves.amplitudes[0] == complex(0.6, 0.8) and waves.directions[0] == 0.3
    model = read_moordyn(DATA / "chain_in_waves.txt")
    assert model.options.waves == waves and model.options.wave_ramp == 10.0
    again = read_moordyn(write_moordyn(model, tmp_path / "chain.txt"))
    assert dataclasses.replace(again, path=None) == dataclasses.replace(model, path=None)


def test_the_surface_is_moordyns_sum_of_components(tmp_path):
    # MoorDyn-C (Waves/SpectrumKin): eta = sum |A| sin(omega t - k (x cos b + y sin b) + arg A),
    # k the root of omega^2 = g k tanh(k h), written out here for three components; the
    # file's water (after its ramp) gives the same surface to 1e-12 m.
    (tmp_path / "wave_frequencies.txt").write_text(
        "0.0 0 0\n0.5 0.3 -0.4 0.0\n0.9 -0.2 0.1 1.1\n1.4 0.05 0.05 -0.6\n")
    text = (DATA / "chain_in_waves.txt").read_text().replace("10.0          waveKin_rampT",
                                                             "0.0  waveKin_rampT")
    (tmp_path / "m.txt").write_text(text)
    options = read_moordyn(tmp_path / "m.txt").options
    water = file_water(options)
    g, h = options.gravity, options.depth
    waves = options.waves
    xy = np.array([[0.0, 0.0], [13.0, -7.0], [-40.0, 22.0]])
    t = np.array([0.0, 3.7, 11.2])
    eta = np.asarray(water.elevation(xy, t))
    for i, time in enumerate(t):
        for j, (x, y) in enumerate(xy):
            expected = 0.0
            for w, a, b in zip(waves.omegas, waves.amplitudes, waves.directions, strict=True):
                k = _wave_number(w, g, h)
                expected += abs(a) * math.sin(w * time - k * (x * math.cos(b) + y * math.sin(b))
                                              + math.atan2(a.imag, a.real))
            assert eta[i, j] == pytest.approx(expected, abs=1e-12)


def _wave_number(omega: float, g: float, h: float) -> float:
    """omega^2 = g k tanh(k h), by bisection (independent of the core's Newton iteration)."""
    low, high = 0.0, 10.0 * omega * omega / g + 10.0 / h
    for _ in range(200):
        mid = 0.5 * (low + high)
        if g * mid * math.tanh(mid * h) < omega * omega:
            low = mid
        else:
            high = mid
    return 0.5 * (low + high)


@pytest.mark.parametrize(("rows", "line", "field"), [
    ("0.5 1.0\n", 1, "omega re im [beta]"),
    ("0.5 1.0 x\n", 1, "im"),
    ("0.0 1.0 0.0\n", 1, "omega"),
    ("0.0 0.0 0.0\n", None, "omega re im [beta]"),
])
def test_a_malformed_components_file_names_the_file_line_and_field(tmp_path, rows, line, field):
    path = tmp_path / "wave_frequencies.txt"
    path.write_text(rows)
    with pytest.raises(MooringFileError) as info:
        read_wave_frequencies(path)
    assert (info.value.file, info.value.line, info.value.field) == (str(path), line, field)
    with pytest.raises(InvalidInputError, match="> 0"):
        WaveComponents(np.array([-1.0]), np.array([1.0]), np.array([0.0]))


def test_the_equilibrium_is_in_still_water_and_the_run_then_in_the_waves(tmp_path):
    # The statics of the chain in a wave (here without a ramp: the wave is there at t = 0) is
    # the chain's in still water (MoorDyn's initial condition leaves the waves out too), to
    # round-off; the run then feels the wave.
    from vinculo.mooring.analysis import statics

    text = (DATA / "chain_in_waves.txt").read_text().replace("10.0          waveKin_rampT",
                                                             "0.0  waveKin_rampT")
    (tmp_path / "m.txt").write_text(text)
    (tmp_path / "wave_frequencies.txt").write_text((DATA / "wave_frequencies.txt").read_text())
    waves = statics(read_moordyn(tmp_path / "m.txt")).ends
    still = statics(read_moordyn(DATA.parent / "hanging_line.txt")).ends
    for a, b in zip(waves, still, strict=True):
        assert a.force == pytest.approx(b.force, rel=1e-12, abs=1e-9)
    result = run(read_moordyn(DATA / "chain_in_waves.txt"), None, 30.0, dt=0.05, plots=False)
    swing = np.ptp(result.end_tensions[result.times > 15.0, 0, 1])
    assert swing > 40.0


def test_other_wave_modes_are_refused(tmp_path):
    text = (DATA / "chain_in_waves.txt").read_text().replace("7             WaveKin",
                                                             "3             WaveKin")
    (tmp_path / "m.txt").write_text(text)
    with pytest.raises(MooringFileError, match="only waves summed") as info:
        read_moordyn(tmp_path / "m.txt")
    assert info.value.field == "WaveKin"


def test_moordyn_and_vinculo_swing_the_chain_alike_in_the_wave():
    # MoorDyn 2.7.2 on the same file (its RK2 at 2e-4 s) and vinculo (0.01 s): after the
    # 10 s ramp (linear in MoorDyn, a half cosine here) and 10 s more, their fairlead tensions
    # differ by 0.74 % of the wave's tension range (measured, 0.37 N of 50 N; 3 % asserted).
    # A wave a quarter period off would differ by about the whole range.
    from vinculo.mooring.peer import moordyn_available, run_moordyn

    if not moordyn_available():
        pytest.skip("MoorDyn's Python package is not installed")
    path = DATA / "chain_in_waves.txt"
    ours = run(read_moordyn(path), None, 40.0, dt=0.01, plots=False)
    peer = run_moordyn(path, None, 40.0, dt_output=0.1)
    grid = np.arange(20.0, 40.0, 0.1)
    a = np.interp(grid, ours.times, ours.end_tensions[:, 0, 1])
    b = np.interp(grid, peer.times, np.linalg.norm(np.asarray(peer.end_forces)[:, 0, 1],
                                                    axis=1))
    swing = b.max() - b.min()
    assert swing > 40.0
    assert np.abs(a - b).max() < 0.03 * swing
