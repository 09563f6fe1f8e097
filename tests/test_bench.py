"""Smoke run of the benchmark command (the full comparison is not part of the test suite)."""

import dataclasses

import numpy as np
import pytest

import vinculo
from vinculo.bench import __main__ as bench
from vinculo.bench import scaling
from vinculo.bench.buoy import (
    CENTRE_TOLERANCE,
    BuoyBench,
    model_topology,
    run_exudyn_buoy,
    run_vinculo_buoy,
)
from vinculo.bench.models import COMPARISON, Chain
from vinculo.bench.runner import run_vinculo
from vinculo.buoy.model import build_model, tank_law

# A short buoy run: 2 s of the ramped start at 0.9 Hz (the centre has moved by about 0.1 mm).
SHORT_BUOY = BuoyBench(name="buoy, 2 s", t_end=2.0)


def test_comparison_without_exudyn_says_so_and_runs_vinculo(monkeypatch):
    monkeypatch.setattr(bench, "_import_exudyn", lambda: None)
    monkeypatch.setattr(bench, "comparison_models", lambda quick: [Chain("hanging N = 10", 10)])
    monkeypatch.setattr(bench, "buoy_bench", lambda quick: SHORT_BUOY)
    lines = []
    assert bench.compare(quick=True, repeat=1, out=lines.append)
    text = "\n".join(lines)
    assert "Exudyn is not installed" in text
    assert "1 m chain N = 300" in text and "tree elimination" in text
    row = next(line for line in lines if line.startswith("buoy, 2 s"))
    assert "(no Exudyn)" in row and "dense LU" in row


def test_buoy_row_is_the_case_study_model():
    # The benchmark's buoy is the particle model of the study: same centre at t_end as the
    # study's own model built for the same case and frequency, run with the bench's scheme.
    run = run_vinculo_buoy(SHORT_BUOY)
    case, f = SHORT_BUOY.case, SHORT_BUOY.frequency
    model = build_model(case, tank_law(case, f))
    solution = vinculo.simulate(
        model.system,
        SHORT_BUOY.t_end,
        1e-3,
        scheme="generalized-alpha",
        rho_inf=COMPARISON.rho_inf,
        jacobian_reuse=COMPARISON.jacobian_reuse,
    )
    np.testing.assert_allclose(run.tip, solution.particle(model.centre)[-1], atol=1e-14)
    assert abs(run.tip[0]) > 1e-5  # the tank has moved the buoy


def test_buoy_topology_is_read_back_from_the_system():
    links, attachment, string = model_topology(SHORT_BUOY.build().system)
    assert len(links) == 15 and attachment == 6
    assert string == pytest.approx(0.16)


def test_buoy_in_exudyn_agrees_with_vinculo():
    exu = pytest.importorskip("exudyn")
    mine = run_vinculo_buoy(SHORT_BUOY)
    peer = run_exudyn_buoy(SHORT_BUOY, exu)
    assert peer.tip is not None, peer.detail
    assert abs(mine.tip[0] - peer.tip[0]) <= CENTRE_TOLERANCE
    assert abs(mine.tip[0]) > 10 * CENTRE_TOLERANCE  # the check is not trivially met at rest


def test_hanging_chain_stays_at_rest_and_scaling_reports_memory():
    # A chain hanging straight down at rest is in equilibrium: the tip stays at -N * link.
    run = run_vinculo(Chain("hanging", 50))
    np.testing.assert_allclose(run.tip, [0.0, 0.0, -5.0], atol=1e-12)
    figures = scaling.one(1_000)
    assert figures["solver"] == "tree elimination"
    assert figures["peak_mb"] > 0 and figures["seconds"] > 0


@pytest.mark.parametrize("sizes", ["1000,x", "0", ""])
def test_the_scaling_command_refuses_bad_sizes_naming_them(sizes, capsys):
    with pytest.raises(SystemExit) as stop:
        scaling.main(["swinging", "--sizes", sizes])
    assert stop.value.code == 2
    assert f"--sizes {sizes!r}" in capsys.readouterr().err


def test_the_scaling_command_refuses_a_repeat_below_one(capsys):
    with pytest.raises(SystemExit) as stop:
        scaling.main(["--sizes", "1000", "--repeat", "0"])
    assert stop.value.code == 2
    assert "--repeat 0" in capsys.readouterr().err


def test_agreement_tolerance_is_a_share_of_the_schemes_own_error():
    # The tolerance of the side-by-side table is AGREEMENT_SHARE (1/100) of the distance between
    # vinculo's answers at dt and dt/2 (the scheme's own error: 3/4 of it at dt for a second-order
    # scheme), never below AGREEMENT_FLOOR of the model's length. On the pendulum after 10 s it
    # sees what the fixed 1e-3 m of before could not: modified Newton's stopping rule leaves its
    # answer more than the tolerance away from full Newton's (measured 1.06e-6 m against a
    # tolerance of 9.2e-7 m, 2.8e-6 m before Newton started from the extrapolated accelerations;
    # full Newton agrees with Exudyn to 4e-8 m).
    pendulum = bench.comparison_models(quick=True)[0]
    assert pendulum.name.startswith("pendulum")
    full_newton = dataclasses.replace(COMPARISON, jacobian_reuse=False)
    full = run_vinculo(pendulum, full_newton)
    half = run_vinculo(dataclasses.replace(pendulum, dt=pendulum.dt / 2), full_newton)
    error = float(np.linalg.norm(full.tip - half.tip))
    tolerance = bench.agreement_tolerance(error, 1.0)
    assert tolerance == pytest.approx(bench.AGREEMENT_SHARE * error, rel=1e-12)
    assert bench.agreement_tolerance(0.0, 2.0) == pytest.approx(2.0 * bench.AGREEMENT_FLOOR)
    modified = run_vinculo(pendulum, dataclasses.replace(COMPARISON, jacobian_reuse=True))
    assert np.linalg.norm(modified.tip - full.tip) > tolerance
    # The headline runs vinculo's default, which stays within the tolerance of full Newton
    # (measured 4e-10 m).
    assert COMPARISON.jacobian_reuse == "auto"
    default = run_vinculo(pendulum, COMPARISON)
    assert np.linalg.norm(default.tip - full.tip) < 0.01 * tolerance


def test_python_overhead_times_the_same_run_in_rust_alone():
    # The core's timing function runs the same integration as vinculo.simulate: a run that
    # fails in one fails in the other (a step far too large for Newton, with no halving), and
    # a bad number of repeats is named.
    from vinculo import _core
    from vinculo.bench import python_overhead
    from vinculo.errors import ConvergenceError, InvalidInputError
    from vinculo.run_options import RunOptions

    system = python_overhead.pendulum()
    options = {"max_halvings": 0, "max_iterations": 2}
    settings = RunOptions.of("simulate", dict(options)).settings(1.0, 0.5, None)
    with pytest.raises(ConvergenceError):
        vinculo.simulate(system, 1.0, 0.5, **options)
    with pytest.raises(RuntimeError, match="Newton"):
        _core.time_simulate(system, settings, 1)
    with pytest.raises(InvalidInputError, match="repeats"):
        _core.time_simulate(system, settings, 0)
    rows = python_overhead.measure(steps=20, repeat=2)
    assert [r.label for r in rows] == list(python_overhead.SCHEMES)
    assert all(r.steps == 20 and r.rust > 0.0 for r in rows)


def test_a_chain_of_rigid_bodies_agrees_with_exudyn():
    # Three links hinged by revolute joints, 0.2 s: vinculo's four-particle bodies and Exudyn's
    # Euler-parameter bodies run the same generalised-alpha at the same step, on different
    # coordinates: their answers differ by less than a fifth of vinculo's own error (the distance
    # from its answer at dt/2; measured: 3.6e-7 m against 4.7e-6 m).
    exu = pytest.importorskip("exudyn")
    from dataclasses import replace

    from vinculo.bench import rigid_chain

    chain = rigid_chain.RigidChain(n=3, t_end=0.2)
    half = replace(chain, dt=chain.dt / 2)
    mine, theirs = rigid_chain.run_vinculo(chain), rigid_chain.run_exudyn(chain, exu)
    error = rigid_chain.largest_distance(mine.centres, rigid_chain.run_vinculo(half).centres)
    assert error > 1e-8
    assert rigid_chain.largest_distance(mine.centres, theirs.centres) < 0.2 * error
