"""The buoy case study: a buoyant sphere tethered to the floor of a shaken water tank.

- :mod:`vinculo.buoy.study`: the sweep, every model at every frequency in parallel
  (:func:`run_study`, also here);
- :mod:`vinculo.buoy.model`: the particle model (:func:`run_particle_model`, also here);
- :mod:`vinculo.buoy.case`: the study's parameters (:class:`BuoyCase`), the frequency sweep
  (:class:`SweepSettings`) and reading both from a TOML file;
- :mod:`vinculo.buoy.reference`: the reference models integrated with scipy (the rigid pendulum of
  the study's eq. 31, corrected, and the string + sphere 2-DOF model);
- :mod:`vinculo.buoy.tank`: the tank's motion, harmonic or a measured displacement record read
  from CSV and smoothed by a spline;
- :mod:`vinculo.buoy.harmonic`: steady-state amplitude and phase by least squares over
  whole periods;
- :mod:`vinculo.buoy.resonance`: each model's resonance, refined by fresh runs near the peak;
- :mod:`vinculo.buoy.data`: reading measured amplitude and phase curves from CSV;
- :mod:`vinculo.buoy.parameter_study`: any parameters over a grid, in parallel (local processes
  or a Dask cluster), resumable;
- :mod:`vinculo.buoy.calibration`: fitting Cd and Ca (and more) to measured curves.
"""

from vinculo.buoy.calibration import CALIBRATABLE, Calibration, calibrate
from vinculo.buoy.case import (
    ASSUMPTIONS,
    ATTACHMENTS,
    PAPER_VALUES,
    VISCOUS_FORCES,
    BuoyCase,
    SweepSettings,
    load_case,
    load_study,
    load_sweep,
)
from vinculo.buoy.data import COLUMNS, MOTIONS, Measurements, read_measurements
from vinculo.buoy.harmonic import (
    PHASE_CONVENTION,
    HarmonicFit,
    SteadyResponse,
    fit_harmonic,
    steady_response,
    steady_window,
    wrap_phase,
)
from vinculo.buoy.model import run_particle_model
from vinculo.buoy.parameter_study import (
    ParameterStudy,
    grid,
    parse_axis,
    run_parameter_study,
)
from vinculo.buoy.reference import (
    OneDofModel,
    ReferenceRun,
    TwoDofModel,
    antiresonance_frequency,
    high_frequency_ratio,
)
from vinculo.buoy.study import MODELS, StudyResult, run_study
from vinculo.buoy.tank import (
    MOTION_COLUMNS,
    MeasuredTankMotion,
    TankMotion,
    read_tank_motion,
    tank_motion,
)

__all__ = [
    "ASSUMPTIONS",
    "ATTACHMENTS",
    "CALIBRATABLE",
    "COLUMNS",
    "MODELS",
    "MOTIONS",
    "MOTION_COLUMNS",
    "PAPER_VALUES",
    "PHASE_CONVENTION",
    "VISCOUS_FORCES",
    "BuoyCase",
    "Calibration",
    "HarmonicFit",
    "MeasuredTankMotion",
    "Measurements",
    "OneDofModel",
    "ParameterStudy",
    "ReferenceRun",
    "SteadyResponse",
    "StudyResult",
    "SweepSettings",
    "TankMotion",
    "TwoDofModel",
    "antiresonance_frequency",
    "calibrate",
    "fit_harmonic",
    "grid",
    "high_frequency_ratio",
    "load_case",
    "load_study",
    "load_sweep",
    "parse_axis",
    "read_measurements",
    "read_tank_motion",
    "run_parameter_study",
    "run_particle_model",
    "run_study",
    "steady_response",
    "steady_window",
    "tank_motion",
    "wrap_phase",
]
