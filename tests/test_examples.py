"""The scripts in examples/ run and print the numbers their references predict."""

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
G = 9.81


def run_example(name: str, *arguments: str) -> str:
    """Run examples/NAME with this interpreter, warnings as errors; return its standard output."""
    completed = subprocess.run(
        [sys.executable, "-W", "error", str(EXAMPLES / name), *arguments],
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert completed.returncode == 0, completed.stderr
    return completed.stdout


def number_after(label: str, text: str) -> float:
    """The first number printed after ``label``."""
    match = re.search(re.escape(label) + r"\s*([-+0-9.eE]+)", text)
    assert match, f"{label!r} not found in:\n{text}"
    return float(match.group(1))


def test_pendulum(tmp_path):
    # Exact period for L = 1 m, g = 9.81, horizontal release: 2.367841947576237 s
    # (formulation.md); the example's dt = 1 ms gives ~1e-6 relative error.
    plot = tmp_path / "pendulum.png"
    out = run_example("pendulum.py", "--plot", str(plot))
    assert number_after("period:", out) == pytest.approx(2.367841947576237, rel=1e-5)
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_double_pendulum():
    # omega^2 = (2 -/+ sqrt 2) g / l for l = 1 m (formulation.md); amplitude 0.01 rad.
    out = run_example("double_pendulum.py")
    assert number_after("slow mode: omega =", out) == pytest.approx(
        np.sqrt((2 - np.sqrt(2)) * G), rel=1e-3
    )
    assert number_after("fast mode: omega =", out) == pytest.approx(
        np.sqrt((2 + np.sqrt(2)) * G), rel=1e-3
    )


def test_hanging_chain():
    # alpha = 1/2 conserves the energy of the chain to Newton tolerance (see test_energy.py).
    out = run_example("hanging_chain.py")
    assert number_after("relative energy drift:", out) < 1e-8
    assert number_after("max constraint residual:", out) < 1e-12
    # With backward Euler the energy decays.
    out = run_example("hanging_chain.py", "--alpha", "1.0", "--t-end", "2")
    initial = number_after("energy: initial", out)
    final = number_after("final", out)
    assert final < initial


def test_inclined_plane():
    # Frictionless 30 degree slope: a = g sin 30 = 4.905 m/s^2, N = m g cos 30 (m = 1 kg).
    out = run_example("inclined_plane.py")
    assert number_after("acceleration:", out) == pytest.approx(G / 2, rel=1e-9)
    assert number_after("normal force:", out) == pytest.approx(G * np.cos(np.pi / 6), rel=1e-9)


def test_result_files(tmp_path):
    # At rest each link carries the weight of the beads below it: 4 x 0.1 kg x 9.81 at the top.
    out = run_example("result_files.py", str(tmp_path / "files"), "--beads", "4")
    assert number_after("top tension from the file:", out) == pytest.approx(4 * 0.1 * G, rel=1e-9)
    assert number_after("largest tension error:", out) < 1e-9
    assert (tmp_path / "files" / "chain.nc").is_file()
    assert (tmp_path / "files" / "chain_vtk" / "state.pvd").is_file()


@pytest.mark.slow
def test_buoy_stokes_layer(tmp_path):
    # docs/buoy/stokes-layer.md: the Stokes layer's damping ratio is about 0.015, 40 % of the
    # Morison drag's 0.036 at the peak, and adding it lowers the 2-DOF model's refined peak by
    # about 18 % (harmonic balance predicts 18 %, tests/buoy/test_stokes_layer.py). A coarser
    # sweep (the peak is refined anyway) keeps the example short.
    plot = tmp_path / "stokes.png"
    out = run_example("buoy_stokes_layer.py", "--plot", str(plot), "--count", "5")
    assert number_after("damping ratio, Stokes layer:", out) == pytest.approx(0.015, abs=1e-3)
    assert number_after("damping ratio, Morison drag at the peak:", out) == pytest.approx(
        0.036, abs=2e-3
    )
    assert number_after("peak drop:", out) == pytest.approx(18.0, abs=1.5)
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
