"""vinculo: point masses linked by constraints, simulated as index-3 DAEs.

Build a :class:`System` of particles, constraints and forces, integrate it with :func:`simulate`
(generalised trapezoidal rule, Newton's method with the analytic Jacobian), and read the
trajectories, Lagrange multipliers and statistics from the returned :class:`Solution`.

Example:
    >>> import vinculo
    >>> system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    >>> bob = system.add_particle(mass=1.0, position=(1.0, 0.0, 0.0))
    >>> rod = system.add_distance_to_point(bob, (0.0, 0.0, 0.0), length=1.0)
    >>> solution = vinculo.simulate(system, t_end=2.0, dt=1e-3)
"""

from importlib.metadata import PackageNotFoundError, version

from vinculo._core import ConstraintId, ForceId, Law, ParticleId, Point, System, UserGroup
from vinculo.errors import (
    ConvergenceError,
    InconsistentInitialStateError,
    InstabilityError,
    InternalError,
    Interrupted,
    InvalidInputError,
    MooringFileError,
    NegativeTensionError,
    OutputTooLargeError,
    RedundantConstraintsError,
    ReentrantRunError,
    SchedulerError,
    StepSizeTooSmallError,
    UnknownHandleError,
    UserFunctionError,
    UserFunctionOutputError,
    VinculoError,
)
from vinculo.laws import constant, driven, piecewise_linear, polynomial, sine, tabulated
from vinculo.run_options import RunOptions
from vinculo.simulate import simulate
from vinculo.solution import Solution
from vinculo.stepping import Simulation, Snapshot

try:
    _installed_version = version("vinculo")
except PackageNotFoundError:  # running from a source tree that was never installed
    _installed_version = "0+unknown"

__version__ = _installed_version
"""The installed version of vinculo ("0+unknown" in a source tree that was never installed)."""

__all__ = [
    "ConstraintId",
    "ConvergenceError",
    "ForceId",
    "InconsistentInitialStateError",
    "InstabilityError",
    "InternalError",
    "Interrupted",
    "InvalidInputError",
    "Law",
    "MooringFileError",
    "NegativeTensionError",
    "OutputTooLargeError",
    "ParticleId",
    "Point",
    "RedundantConstraintsError",
    "ReentrantRunError",
    "RunOptions",
    "SchedulerError",
    "Simulation",
    "Snapshot",
    "Solution",
    "StepSizeTooSmallError",
    "System",
    "UnknownHandleError",
    "UserFunctionError",
    "UserFunctionOutputError",
    "UserGroup",
    "VinculoError",
    "__version__",
    "constant",
    "driven",
    "piecewise_linear",
    "polynomial",
    "simulate",
    "sine",
    "tabulated",
]
