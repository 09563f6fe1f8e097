"""Smoke run of the benchmark command (the full comparison is not part of the test suite)."""

import numpy as np

from vinculo.bench import __main__ as bench
from vinculo.bench import scaling
from vinculo.bench.models import Chain
from vinculo.bench.runner import run_vinculo


def test_comparison_without_exudyn_says_so_and_runs_vinculo(monkeypatch):
    monkeypatch.setattr(bench, "_import_exudyn", lambda: None)
    monkeypatch.setattr(bench, "comparison_models", lambda quick: [Chain("hanging N = 10", 10)])
    lines = []
    assert bench.compare(quick=True, repeat=1, out=lines.append)
    text = "\n".join(lines)
    assert "Exudyn is not installed" in text
    assert "buoy model: not available yet" in text
    assert "1 m chain N = 300" in text and "tree elimination" in text


def test_hanging_chain_stays_at_rest_and_scaling_reports_memory():
    # A chain hanging straight down at rest is in equilibrium: the tip stays at -N * link.
    run = run_vinculo(Chain("hanging", 50))
    np.testing.assert_allclose(run.tip, [0.0, 0.0, -5.0], atol=1e-12)
    figures = scaling.one(1_000)
    assert figures["solver"] == "tree elimination"
    assert figures["peak_mb"] > 0 and figures["seconds_per_step"] > 0
