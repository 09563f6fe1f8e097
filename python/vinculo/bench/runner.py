"""Timed runs of one model in vinculo and in Exudyn."""

from __future__ import annotations

import contextlib
import io
import os
import time
from dataclasses import dataclass

import numpy as np

import vinculo
from vinculo.bench.models import (
    COMPARISON,
    Chain,
    Integration,
    build_exudyn,
    build_vinculo,
    exudyn_settings,
)


@dataclass
class Run:
    """Outcome of one timed run.

    Attributes:
        seconds: wall time of the integration (model building excluded, analysis included).
        steps: steps taken.
        tip: position of the last particle at ``t_end`` (None if the run failed).
        detail: the linear solver, Newton iterations, or why the run failed.
    """

    seconds: float
    steps: int
    tip: np.ndarray | None
    detail: str

    @property
    def steps_per_second(self) -> float:
        """Steps per second of wall time (NaN when the run failed)."""
        return self.steps / self.seconds if self.tip is not None else float("nan")


def run_vinculo(model: Chain, integration: Integration = COMPARISON, repeat: int = 1) -> Run:
    """Best of ``repeat`` runs of vinculo with ``integration`` (default Newton tolerance, 1e-10
    of the length scale), storing only the first and the last state."""
    system, tip = build_vinculo(model)
    best = None
    for _ in range(repeat):
        start = time.perf_counter()
        try:
            solution = vinculo.simulate(
                system,
                t_end=model.t_end,
                dt=model.dt,
                scheme="generalized-alpha",
                rho_inf=integration.rho_inf,
                save_every=model.steps,
                jacobian_reuse=integration.jacobian_reuse,
            )
        except vinculo.ConvergenceError as error:
            return Run(time.perf_counter() - start, 0, None, f"failed: {error}")
        seconds = time.perf_counter() - start
        if best is None or seconds < best.seconds:
            # Run totals (only the last state is stored): residual evaluations and
            # factorisations a step.
            best = Run(
                seconds,
                model.steps,
                solution.particle(tip)[-1],
                f"{solution.linear_solver}, "
                f"{solution.residual_evaluations / model.steps:.2f} residuals/step, "
                f"{solution.factorisations / model.steps:.2f} factorisations/step",
            )
    assert best is not None
    return best


def run_exudyn(model: Chain, exu, integration: Integration = COMPARISON, repeat: int = 1) -> Run:
    """Best of ``repeat`` runs of Exudyn (see ``exudyn_settings``); for models of at most 100
    coordinates the faster of its dense and sparse LU is kept."""

    def build():
        _, mbs, tip = build_exudyn(model, exu)
        return mbs, tip

    dense_options = (False, True) if 3 * model.n <= 100 else (False,)
    return time_exudyn(build, model, exu, integration, repeat, dense_options)


def time_exudyn(build, model, exu, integration: Integration, repeat: int, dense_options) -> Run:
    """Best of ``repeat`` Exudyn runs per linear solver of ``dense_options`` (False: sparse LU).

    Arguments:
        build: builds a fresh Exudyn model, returning ``(main system, node to report)``.
        model: the run's ``steps``, ``t_end`` and ``dt``.
        exu: the ``exudyn`` module.
        integration: the scheme parameters shared with vinculo.
        repeat: timed runs per solver.
        dense_options: which of Exudyn's LU solvers to try.

    Returns:
        The fastest :class:`Run`, the reported node's position at ``t_end`` as its ``tip``; the
        first failure ends the timing with a failed run.
    """
    best = None
    for dense in dense_options:
        for _ in range(repeat):
            mbs, node = build()
            settings = exudyn_settings(model, exu, dense=dense, rho_inf=integration.rho_inf)
            start = time.perf_counter()
            try:
                # Exudyn prints its own diagnostics; keep the table readable.
                with _quiet():
                    ok = mbs.SolveDynamic(settings)
            except Exception as error:
                ok, why = False, str(error).strip().splitlines()[-1][:60]
            else:
                why = "SolveDynamic returned False"
            seconds = time.perf_counter() - start
            if not ok:
                return Run(seconds, 0, None, f"failed: {why}")
            position = np.array(mbs.GetNodeOutput(node, exu.OutputVariableType.Position))
            if best is None or seconds < best.seconds:
                best = Run(seconds, model.steps, position, "dense LU" if dense else "sparse LU")
    assert best is not None
    return best


@contextlib.contextmanager
def _quiet():
    """Silences output written to the process's stdout and stderr (also from C++)."""
    saved = [os.dup(1), os.dup(2)]
    with open(os.devnull, "w") as null:
        os.dup2(null.fileno(), 1)
        os.dup2(null.fileno(), 2)
        try:
            with contextlib.redirect_stdout(io.StringIO()):
                yield
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
