"""The buoy case study: its parameters, the frequency sweep, and reading both from TOML.

:class:`BuoyCase` holds the physical parameters of the tethered sphere in the shaken tank, with the
values of the study as defaults (SI units); :class:`SweepSettings` holds the frequency sweep and the
time settings of each run. Both are frozen dataclasses, validated when built, so a case that exists
can be simulated.

A case file is TOML with two optional tables, ``[case]`` (the fields of :class:`BuoyCase`) and
``[sweep]`` (the fields of :class:`SweepSettings`); a key left out keeps its default. Keys outside
these two tables are rejected, so that a forgotten ``[case]`` header or a misspelt key is reported
instead of silently ignored::

    [case]
    amplitude = 0.004       # m, X0 of the shake table
    attachment = "centre"

    [sweep]
    f_min = 0.6
    f_max = 1.4
    count = 17
"""

from __future__ import annotations

import dataclasses
import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from vinculo.errors import InvalidInputError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10 reads TOML with the tomli backport
    import tomli as tomllib

__all__ = [
    "ASSUMPTIONS",
    "ATTACHMENTS",
    "PAPER_VALUES",
    "UNITS",
    "VISCOUS_FORCES",
    "BuoyCase",
    "SweepSettings",
    "load_case",
    "load_study",
    "load_sweep",
]

#: The two readings of where the string is tied to the sphere.
ATTACHMENTS = ("bottom", "centre")

#: The viscous forces the fluid model offers beyond Morison's: none (the study's model), or the
#: Stokes-layer drag and added mass of a sphere oscillating in a viscous fluid
#: (:meth:`BuoyCase.stokes_layer`).
VISCOUS_FORCES = ("none", "stokes-layer")

#: The values the study (the paper) gives, by field of :class:`BuoyCase`; a field's value is
#: reported as the paper's only when it equals this.
PAPER_VALUES: dict[str, Any] = {
    "diameter": 0.1,
    "sphere_density": 366.69,
    "fluid_density": 1000.0,
    "string_length": 0.16,
    "drag_coefficient": 0.22,
    "added_mass_coefficient": 0.52,
    "gravity": 9.81,
    "tank_size": (0.38, 0.38, 0.40),
}

#: Fields of :class:`BuoyCase` whose defaults are assumptions, not values from the study, each with
#: the reason for the default.
ASSUMPTIONS: dict[str, str] = {
    "amplitude": "the table's displacement amplitude X0 is not reported; 5 mm keeps the string's "
    "swing moderate (parameters.csv gives the swing at the value used)",
    "attachment": "the study gives the string length but not where it is tied; 'bottom' (the "
    "sphere's lowest point) puts the centre 0.21 m above the anchor",
    "ramp_periods": "the study starts the table abruptly; a smooth C2 ramp over 10 periods avoids "
    "the strong start-up transient it reports (set 0 for the abrupt start)",
    "string_beads": "the string is massless, as in the study's model (give beads and their mass "
    "for a heavy string)",
    "string_mass": "the string is massless, as in the study's model",
    "viscous_force": "only Morison's drag and added mass, as in the study; 'stokes-layer' adds the "
    "viscous boundary-layer force of an oscillating sphere (Stokes 1851)",
    "kinematic_viscosity": "water at about 20 degC (1.0e-6 m^2/s); used only with viscous_force = "
    "'stokes-layer'",
    "tank_size": "the tank is closed and full, so the water moves with it as a rigid body (no "
    "free surface, no sloshing); an open tank would slosh (first mode near 1.43 Hz for the "
    "study's tank, inside the sweep)",
}


#: The unit (or kind of value) of every field of :class:`BuoyCase` and :class:`SweepSettings`,
#: for help texts and tables.
UNITS: dict[str, str] = {
    "diameter": "m",
    "sphere_density": "kg/m^3",
    "fluid_density": "kg/m^3",
    "string_length": "m",
    "attachment": "one of " + ", ".join(ATTACHMENTS),
    "drag_coefficient": "dimensionless",
    "added_mass_coefficient": "dimensionless",
    "gravity": "m/s^2",
    "amplitude": "m",
    "ramp_periods": "periods of the excitation",
    "string_beads": "count",
    "string_mass": "kg",
    "tank_size": "m",
    "viscous_force": "one of " + ", ".join(VISCOUS_FORCES),
    "kinematic_viscosity": "m^2/s",
    "f_min": "Hz",
    "f_max": "Hz",
    "count": "count",
    "dt": "s",
    "settle_periods": "periods of the excitation",
    "fit_periods": "whole periods",
    "amplitude_tolerance": "dimensionless",
    "phase_tolerance": "degrees",
    "max_periods": "periods of the excitation",
    "refine_rounds": "count",
    "resonance_tolerance": "Hz",
}
#: Largest whole-number settings: beyond them a run could not be held in memory (or finish).
MAX_STRING_BEADS = 10_000
MAX_COUNT = 10_000
MAX_FIT_PERIODS = 10_000
#: Most time steps one run of a sweep may take (its longest run, at f_min).
MAX_STEPS = 10**9


def _at_most(owner: str, name: str, value: int, limit: int, why: str) -> None:
    """Raise unless the whole number ``value`` is at most ``limit``."""
    if value > limit:
        raise InvalidInputError(
            f"{owner}.{name} = {value!r} is out of range: at most {limit} ({why}); give a "
            f"smaller value",
            name=name,
            value=value,
        )


def _is_number(value: Any) -> bool:
    """Whether ``value`` is a real number (an int or float, not a bool)."""
    return isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(
        value, (bool, np.bool_)
    )


def _is_integer(value: Any) -> bool:
    """Whether ``value`` is an integer (not a bool)."""
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def _whole(owner: str, name: str, value: Any, minimum: int, meaning: str = "") -> None:
    """Raise unless ``value`` is a whole number (not a bool) of at least ``minimum``; ``meaning``
    says what a smaller value would stand for."""
    if not _is_integer(value) or value < minimum:
        why = f": {meaning}" if meaning else ""
        raise InvalidInputError(
            f"{owner}.{name} must be a whole number >= {minimum}, got {value!r}{why}; give a "
            f"whole number >= {minimum}",
            name=name,
            value=value,
        )


def _positive(owner: str, name: str, value: float, unit: str) -> None:
    """Raise unless ``value`` is finite and positive."""
    if not (math.isfinite(value) and value > 0.0):
        raise InvalidInputError(
            f"{owner}.{name} must be a finite positive number ({unit}), got {value!r}; "
            f"give a value greater than 0",
            name=name,
            value=value,
        )


def _non_negative(owner: str, name: str, value: float, unit: str) -> None:
    """Raise unless ``value`` is finite and not negative."""
    if not (math.isfinite(value) and value >= 0.0):
        raise InvalidInputError(
            f"{owner}.{name} must be a finite number >= 0 ({unit}), got {value!r}; "
            f"give 0 or a positive value",
            name=name,
            value=value,
        )


@dataclass(frozen=True)
class BuoyCase:
    """Parameters of the buoy study: a sphere tethered to the floor of a shaken water tank.

    The defaults are the study's values (:data:`PAPER_VALUES`), except the fields listed in
    :data:`ASSUMPTIONS` (``amplitude``, ``attachment``, ``ramp_periods``, the massless string,
    the fluid model's viscous option, and the closed tank), which the study does not give.

    Arguments:
        diameter: sphere diameter D, in m.
        sphere_density: density of the sphere, in kg/m^3.
        fluid_density: density of the water, in kg/m^3.
        string_length: length of the string, in m.
        attachment: ``"bottom"``: the string is tied to the sphere's lowest point, so at rest the
            centre is ``string_length + R`` above the anchor and the sphere can turn about the
            attachment; ``"centre"``: the string reaches the centre (``string_length`` to it).
        drag_coefficient: Cd of the sphere (drag ``1/2 rho Cd A |u| u``).
        added_mass_coefficient: Ca (added mass ``Ca rho V``, on the translation of the centre).
        gravity: g, in m/s^2.
        amplitude: displacement amplitude X0 of the shake table, in m (an assumption).
        ramp_periods: the table's motion rises smoothly from rest over this many periods
            (0: the abrupt start of the study).
        string_beads: number of small masses along the string (0: a massless string).
        string_mass: total mass of those beads, in kg (must be positive when there are beads, and
            0 when there are none).
        tank_size: inner length, width and height of the tank, in m. The fluid is modelled as
            moving rigidly with the tank, whatever its size: the tank is taken as closed and full
            (no free surface). The size gives the first sloshing frequency an open tank would
            have (:meth:`sloshing_frequency`) and the walls of the animation.
        viscous_force: ``"none"`` (Morison's drag and added mass only, the study's model) or
            ``"stokes-layer"``: add the viscous force of the oscillatory boundary layer,
            :meth:`stokes_layer`, on the sphere's motion relative to the fluid.
        kinematic_viscosity: nu of the water, in m^2/s (only used by the Stokes-layer force).

    Raises:
        InvalidInputError: if a field is out of its domain (the message names the field and value).
    """

    diameter: float = 0.1
    sphere_density: float = 366.69
    fluid_density: float = 1000.0
    string_length: float = 0.16
    attachment: str = "bottom"
    drag_coefficient: float = 0.22
    added_mass_coefficient: float = 0.52
    gravity: float = 9.81
    amplitude: float = 0.005
    ramp_periods: float = 10.0
    string_beads: int = 0
    string_mass: float = 0.0
    tank_size: tuple[float, float, float] = (0.38, 0.38, 0.40)
    viscous_force: str = "none"
    kinematic_viscosity: float = 1.0e-6

    #: Fields whose defaults are assumptions (see the module's :data:`ASSUMPTIONS`).
    ASSUMPTIONS: ClassVar[dict[str, str]] = ASSUMPTIONS

    def __post_init__(self) -> None:
        owner = "BuoyCase"
        for name, unit in (
            ("diameter", "m"),
            ("sphere_density", "kg/m^3"),
            ("fluid_density", "kg/m^3"),
            ("string_length", "m"),
            ("gravity", "m/s^2"),
            ("amplitude", "m"),
            ("kinematic_viscosity", "m^2/s"),
        ):
            _positive(owner, name, getattr(self, name), unit)
        for name, unit in (
            ("drag_coefficient", "dimensionless"),
            ("added_mass_coefficient", "dimensionless"),
            ("ramp_periods", "periods"),
            ("string_mass", "kg"),
        ):
            _non_negative(owner, name, getattr(self, name), unit)
        if self.attachment not in ATTACHMENTS:
            raise InvalidInputError(
                f"BuoyCase.attachment must be one of {', '.join(map(repr, ATTACHMENTS))}, "
                f"got {self.attachment!r}",
                name="attachment",
                value=self.attachment,
            )
        if self.viscous_force not in VISCOUS_FORCES:
            raise InvalidInputError(
                f"BuoyCase.viscous_force must be one of {', '.join(map(repr, VISCOUS_FORCES))}, "
                f"got {self.viscous_force!r}",
                name="viscous_force",
                value=self.viscous_force,
            )
        _whole(owner, "string_beads", self.string_beads, 0)
        _at_most(owner, "string_beads", self.string_beads, MAX_STRING_BEADS,
                 "each bead is a particle of the model")
        if self.string_beads > 0 and self.string_mass == 0.0:
            raise InvalidInputError(
                f"BuoyCase.string_mass is 0 but string_beads is {self.string_beads}: beads must "
                f"have mass; give string_mass > 0, or string_beads = 0 for a massless string",
                name="string_mass",
                value=self.string_mass,
            )
        if self.string_beads == 0 and self.string_mass > 0.0:
            raise InvalidInputError(
                f"BuoyCase.string_mass is {self.string_mass!r} kg but string_beads is 0, so the "
                f"mass would be ignored; give string_beads >= 1 to carry it, or string_mass = 0",
                name="string_mass",
                value=self.string_mass,
            )
        size = tuple(self.tank_size)
        if len(size) != 3 or not all(_is_number(v) and math.isfinite(v) and v > 0.0 for v in size):
            raise InvalidInputError(
                f"BuoyCase.tank_size must be three finite positive lengths (m), got "
                f"{self.tank_size!r}",
                name="tank_size",
                value=self.tank_size,
            )
        object.__setattr__(self, "tank_size", tuple(float(v) for v in size))

    # ---- derived quantities ------------------------------------------------------------------

    @property
    def radius(self) -> float:
        """Sphere radius R = D / 2, in m."""
        return 0.5 * self.diameter

    @property
    def volume(self) -> float:
        """Sphere volume V = pi D^3 / 6, in m^3."""
        return math.pi * self.diameter**3 / 6.0

    @property
    def frontal_area(self) -> float:
        """Frontal area A = pi R^2 seen by the drag, in m^2."""
        return math.pi * self.radius**2

    @property
    def sphere_mass(self) -> float:
        """Sphere mass m_s = rho_s V, in kg."""
        return self.sphere_density * self.volume

    @property
    def displaced_mass(self) -> float:
        """Mass of the displaced fluid m_f = rho_f V, in kg."""
        return self.fluid_density * self.volume

    @property
    def added_mass(self) -> float:
        """Added mass m_a = Ca m_f, in kg (translation of the centre only)."""
        return self.added_mass_coefficient * self.displaced_mass

    @property
    def centre_inertia(self) -> float:
        """Moment of inertia of the sphere about its centre, I_c = 2/5 m_s R^2, in kg m^2."""
        return 0.4 * self.sphere_mass * self.radius**2

    @property
    def pendulum_length(self) -> float:
        """Anchor-to-centre distance at rest, in m: ``string_length + R`` ("bottom") or
        ``string_length`` ("centre")."""
        if self.attachment == "bottom":
            return self.string_length + self.radius
        return self.string_length

    def sloshing_frequency(self, mode: int = 1) -> float:
        """Natural frequency of an open tank's sloshing mode along the shaking, in Hz.

        Linear water waves standing between two walls a length L apart in water of depth h
        (the tank full: h = ``tank_size[2]``) have wavenumbers ``k = n pi / L`` and frequencies
        ``f = sqrt(g k tanh(k h)) / (2 pi)`` (the dispersion relation of linear waves, e.g.
        Ibrahim, *Liquid Sloshing Dynamics*, 2005, eq. 2.32; Lamb, *Hydrodynamics*, art. 257). The
        study's model has no free surface (closed tank); this tells where that assumption would
        fail for an open one: 1.431 Hz for the first mode of the study's tank.

        Arguments:
            mode: n >= 1, the number of half-waves along the tank's length.

        Returns:
            The frequency, in Hz.

        Raises:
            InvalidInputError: if ``mode`` is not a whole number >= 1.
        """
        if not _is_integer(mode) or mode < 1:
            raise InvalidInputError(
                f"mode must be a whole number >= 1 (half-waves along the tank), got {mode!r}",
                name="mode",
                value=mode,
            )
        length, _, depth = self.tank_size
        k = mode * math.pi / length
        return math.sqrt(self.gravity * k * math.tanh(k * depth)) / (2.0 * math.pi)

    def stokes_layer(self, frequency: float) -> tuple[float, float]:
        """Damping and added mass of the Stokes layer of the sphere oscillating at ``frequency``.

        A sphere of radius R oscillating with velocity ``u e^{-i w t}`` in a viscous fluid at rest
        (density rho, viscosity mu = rho nu) feels the force (Stokes 1851; Landau and Lifshitz,
        *Fluid Mechanics*, 2nd ed., par. 24, problem 5)::

            F = -6 pi mu R (1 + R / delta) u
                - 3 pi R^2 sqrt(2 mu rho / w) (1 + 2 R / (9 delta)) du/dt

        with the thickness of the oscillatory boundary layer ``delta = sqrt(2 nu / w)``. Since
        ``sqrt(2 mu rho / w) = rho delta``, the part ``3 pi R^2 rho delta 2 R / (9 delta) du/dt =
        1/2 rho V du/dt`` is the inviscid added mass (Ca = 1/2), which the Morison term already
        carries with the case's Ca. What the boundary layer adds is therefore::

            F_v = -c u - m_v du/dt,   c = 6 pi mu R (1 + R / delta),   m_v = 3 pi R^2 rho delta

        The fluid of the closed tank moves rigidly with it, so in the tank's frame it is at rest
        (the frame's acceleration is balanced by the pressure gradient that gives the
        Froude-Krylov force) and u is the sphere centre's velocity relative to the tank. The
        result is linear: it holds for displacements small against R, a single frequency, and
        attached flow; at the amplitudes of the study (relative motion near R at resonance) the
        flow separates, which is what Morison's quadratic drag models, so adding both may count
        part of the dissipation twice. See ``docs/buoy/stokes-layer.md``.

        Arguments:
            frequency: the oscillation's frequency, in Hz (> 0).

        Returns:
            ``(c, m_v)``: the damping coefficient in N s/m and the added mass in kg.

        Raises:
            InvalidInputError: if ``frequency`` is not finite and positive.
        """
        _positive("BuoyCase.stokes_layer", "frequency", frequency, "Hz")
        omega = 2.0 * math.pi * frequency
        delta = math.sqrt(2.0 * self.kinematic_viscosity / omega)
        viscosity = self.fluid_density * self.kinematic_viscosity
        radius = self.radius
        damping = 6.0 * math.pi * viscosity * radius * (1.0 + radius / delta)
        added_mass = 3.0 * math.pi * radius**2 * self.fluid_density * delta
        return damping, added_mass

    # ---- conversion --------------------------------------------------------------------------

    def to_dict(self) -> dict[str, Any]:
        """The fields as a plain dict (``tank_size`` as a list), ready for TOML or JSON.

        Returns:
            ``{field: value}`` for every field; :meth:`from_mapping` rebuilds an equal case.
        """
        data = dataclasses.asdict(self)
        data["tank_size"] = list(self.tank_size)
        return data

    @classmethod
    def from_mapping(cls, mapping: Mapping[str, Any], source: str | None = None) -> BuoyCase:
        """Build a case from a mapping of field names to values (missing fields keep defaults).

        Arguments:
            mapping: for example the ``[case]`` table of a parsed TOML file.
            source: where the mapping came from (a file name), quoted in error messages.

        Returns:
            The validated case.

        Raises:
            InvalidInputError: for an unknown key (the message lists the valid ones), a value of
                the wrong type, or a value out of its domain.
        """
        return _build(cls, mapping, source, "case")


@dataclass(frozen=True)
class SweepSettings:
    """A frequency sweep and the time settings of each run in it.

    Each run simulates ``settle_periods`` periods for the transient to die out, then
    ``fit_periods`` periods over which amplitude and phase are fitted, so it ends at
    ``(settle_periods + fit_periods) / f``. The transient dies out slowly: the only damping is
    quadratic drag, weak at millimetre amplitudes, so the free oscillation at the natural
    frequency that the start leaves behind lingers. Each run therefore checks its steady state:
    the relative motion's amplitude and phase fitted over the last window and over the window
    before it must agree within ``amplitude_tolerance`` (relative) and ``phase_tolerance``
    (degrees); when they do not, the run is continued from its last state by ``fit_periods``
    periods at a time, up to ``max_periods`` periods in all, and a run that still does not meet
    them is reported as not converged
    (:attr:`vinculo.buoy.harmonic.SteadyResponse.converged`, in ``sweep.csv`` and the summary).

    Arguments:
        f_min: lowest excitation frequency, in Hz.
        f_max: highest excitation frequency, in Hz (>= f_min).
        count: number of frequencies, evenly spaced from f_min to f_max (1 when they are equal).
        dt: time step of the particle model, in s (at least 20 steps per period of f_max). The
            default 2 ms is 333 steps per period at 1.5 Hz; halving it changes the fitted
            amplitudes by less than 1e-4 relative (second-order rule).
        settle_periods: periods simulated before the fit window (the ramp-up counts among them).
        fit_periods: whole periods in the fit window (>= 1).
        amplitude_tolerance: largest relative change of the fitted relative amplitude between
            the last two windows of ``fit_periods`` periods for the run to count as steady.
        phase_tolerance: largest change of the fitted relative phase between those windows, in
            degrees.
        max_periods: longest run, in periods, that the steady-state check may extend a run to
            (``settle_periods + fit_periods`` or less: no extension).
        refine_rounds: most rounds of the resonance's refinement (three fresh runs per model and
            round, :mod:`vinculo.buoy.resonance`); 0: report the sweep's own estimate.
        resonance_tolerance: the refinement stops when a round moves the peak's frequency by
            less than this, in Hz.

    Raises:
        InvalidInputError: if a field is out of its domain, or the range has no points.
    """

    f_min: float = 0.5
    f_max: float = 1.5
    count: int = 21
    dt: float = 2e-3
    settle_periods: float = 30.0
    fit_periods: int = 10
    amplitude_tolerance: float = 1e-3
    phase_tolerance: float = 0.1
    max_periods: float = 100.0
    refine_rounds: int = 4
    resonance_tolerance: float = 1e-4

    def __post_init__(self) -> None:
        owner = "SweepSettings"
        _positive(owner, "f_min", self.f_min, "Hz")
        _positive(owner, "amplitude_tolerance", self.amplitude_tolerance, "relative")
        _positive(owner, "phase_tolerance", self.phase_tolerance, "degrees")
        _positive(owner, "max_periods", self.max_periods, "periods")
        _positive(owner, "resonance_tolerance", self.resonance_tolerance, "Hz")
        _whole(owner, "refine_rounds", self.refine_rounds, 0)
        _positive(owner, "f_max", self.f_max, "Hz")
        _positive(owner, "dt", self.dt, "s")
        _non_negative(owner, "settle_periods", self.settle_periods, "periods")
        _whole(owner, "count", self.count, 1, "a frequency range with no points")
        _at_most(owner, "count", self.count, MAX_COUNT, "frequencies in one sweep")
        if self.f_max < self.f_min:
            raise InvalidInputError(
                f"SweepSettings.f_max = {self.f_max!r} Hz is below f_min = {self.f_min!r} Hz; "
                f"give f_max >= f_min",
                name="f_max",
                value=self.f_max,
            )
        if self.count == 1 and self.f_max != self.f_min:
            raise InvalidInputError(
                f"SweepSettings.count is 1 but f_min = {self.f_min!r} and f_max = {self.f_max!r} "
                f"differ; give count >= 2 to cover the range, or f_max = f_min for one frequency",
                name="count",
                value=self.count,
            )
        if self.count > 1 and self.f_max == self.f_min:
            raise InvalidInputError(
                f"SweepSettings.count is {self.count} but f_min = f_max = {self.f_min!r} Hz, "
                f"which repeats one frequency; give count = 1 or a wider range",
                name="count",
                value=self.count,
            )
        _whole(owner, "fit_periods", self.fit_periods, 1)
        _at_most(owner, "fit_periods", self.fit_periods, MAX_FIT_PERIODS,
                 "periods in one fit window")
        longest = (self.settle_periods + self.fit_periods) / (self.f_min * self.dt)
        if not longest <= MAX_STEPS:
            raise InvalidInputError(
                f"SweepSettings: the run at f_min = {self.f_min!r} Hz would take {longest:.3g} "
                f"steps of dt = {self.dt!r} s over settle_periods + fit_periods = "
                f"{self.settle_periods!r} + {self.fit_periods!r} periods, more than "
                f"{MAX_STEPS:.0e}; give fewer periods, a larger dt or a higher f_min",
                name="settle_periods",
                value=self.settle_periods,
            )
        steps_per_period = 1.0 / (self.f_max * self.dt)
        if steps_per_period < 20.0:
            raise InvalidInputError(
                f"SweepSettings.dt = {self.dt!r} s gives only {steps_per_period:.3g} steps per "
                f"period at f_max = {self.f_max!r} Hz; give dt <= "
                f"{1.0 / (20.0 * self.f_max):.3g} s",
                name="dt",
                value=self.dt,
            )

    @property
    def frequencies(self) -> np.ndarray:
        """The excitation frequencies, in Hz: ``np.linspace(f_min, f_max, count)``.

        Each is rounded to 12 significant digits, far below any physical resolution, so that
        grid points are the decimal numbers they stand for (0.85, not 0.8500000000000001).
        """
        grid = np.linspace(self.f_min, self.f_max, self.count)
        return np.array([float(f"{f:.12g}") for f in grid])

    def t_end(self, frequency: float, extension: int = 0) -> float:
        """Duration of the run at ``frequency``: ``(settle_periods + fit_periods) / frequency``.

        Arguments:
            frequency: excitation frequency, in Hz (> 0).
            extension: how many times the steady-state check has extended the run, each time by
                ``fit_periods`` periods (one window), the whole run at most ``max_periods``
                periods.

        Returns:
            The end time, in s.

        Raises:
            InvalidInputError: if ``frequency`` is not finite and positive.
        """
        _positive("SweepSettings.t_end", "frequency", frequency, "Hz")
        return self.run_periods(extension) / frequency

    def run_periods(self, extension: int = 0) -> float:
        """Periods simulated by a run after ``extension`` extensions (see :meth:`t_end`).

        Arguments:
            extension: number of extensions (0: the first run).

        Returns:
            The number of periods (not always whole).
        """
        base = self.settle_periods + self.fit_periods
        return max(min(base + extension * self.fit_periods, self.max_periods), base)

    def can_extend(self, extension: int) -> bool:
        """Whether the steady-state check may extend a run once more after ``extension``.

        Arguments:
            extension: extensions made so far.

        Returns:
            True when the next extension runs longer than the current run.
        """
        return self.run_periods(extension + 1) > self.run_periods(extension) + 1e-9

    def to_dict(self) -> dict[str, Any]:
        """The fields as a plain dict.

        Returns:
            ``{field: value}``; :meth:`from_mapping` rebuilds equal settings.
        """
        return dataclasses.asdict(self)

    @classmethod
    def from_mapping(cls, mapping: Mapping[str, Any], source: str | None = None) -> SweepSettings:
        """Build settings from a mapping of field names to values (missing fields keep defaults).

        Arguments:
            mapping: for example the ``[sweep]`` table of a parsed TOML file.
            source: where the mapping came from (a file name), quoted in error messages.

        Returns:
            The validated settings.

        Raises:
            InvalidInputError: for an unknown key, a value of the wrong type, or a value out of
                its domain.
        """
        return _build(cls, mapping, source, "sweep")


def _checked_fields(
    cls: type, mapping: Mapping[str, Any], source: str | None, table: str
) -> dict[str, Any]:
    """Check the keys and value types of ``mapping`` against the fields of dataclass ``cls``."""
    where = f" in {source}" if source else ""
    if not isinstance(mapping, Mapping):
        raise InvalidInputError(
            f"the [{table}] settings{where} must be a table of key = value pairs, got "
            f"{type(mapping).__name__}",
            name=table,
            value=mapping,
            source=source,
        )
    defaults = {field.name: field.default for field in dataclasses.fields(cls)}
    values: dict[str, Any] = {}
    for key, value in mapping.items():
        if key not in defaults:
            raise InvalidInputError(
                f"unknown key {key!r} in [{table}]{where}; valid keys are: {', '.join(defaults)}",
                name=key,
                value=value,
                source=source,
            )
        default = defaults[key]
        if isinstance(default, str):
            ok, expected = isinstance(value, str), "a string"
        elif isinstance(default, bool):  # pragma: no cover - no boolean fields yet
            ok, expected = isinstance(value, bool), "true or false"
        elif isinstance(default, int):
            ok, expected = _is_integer(value), "a whole number"
        elif isinstance(default, float):
            ok, expected = _is_number(value), "a number"
        else:  # a tuple of numbers
            ok = isinstance(value, (list, tuple)) and all(_is_number(v) for v in value)
            expected = f"a list of {len(default)} numbers"
        if not ok:
            raise InvalidInputError(
                f"[{table}] {key}{where} must be {expected}, got {value!r} "
                f"({type(value).__name__})",
                name=key,
                value=value,
                source=source,
            )
        values[key] = float(value) if isinstance(default, float) else value
    return values


def _build(cls: type, mapping: Mapping[str, Any], source: str | None, table: str) -> Any:
    """Build ``cls`` from ``mapping``; an out-of-domain value's message also names ``source``."""
    values = _checked_fields(cls, mapping, source, table)
    try:
        return cls(**values)
    except InvalidInputError as error:
        if source is None:
            raise
        details = {**error.details, "source": source}
        raise InvalidInputError(f"{error.message} (in {source})", **details) from None


def _read_toml(path: str | Path) -> dict[str, Any]:
    """Parse a case file and check that it holds only the ``[case]`` and ``[sweep]`` tables."""
    path = Path(path)
    try:
        with path.open("rb") as stream:
            data = tomllib.load(stream)
    except FileNotFoundError:
        raise InvalidInputError(
            f"case file {str(path)!r} does not exist; check the path",
            name="path",
            value=str(path),
        ) from None
    except OSError as error:
        raise InvalidInputError(
            f"cannot read case file {str(path)!r}: {error.strerror or error}",
            name="path",
            value=str(path),
        ) from None
    except tomllib.TOMLDecodeError as error:
        raise InvalidInputError(
            f"case file {str(path)!r} is not valid TOML: {error}",
            name="path",
            value=str(path),
        ) from None
    except UnicodeDecodeError as error:
        raise InvalidInputError(
            f"case file {str(path)!r} is not UTF-8 text (byte {error.start} is "
            f"{error.object[error.start : error.start + 1]!r}): it is binary or in another "
            f"encoding such as UTF-16; save it as UTF-8 TOML",
            name="path",
            value=str(path),
        ) from None
    for key, value in data.items():
        if key not in ("case", "sweep"):
            hint = (
                "; put case parameters under a [case] header"
                if key in {f.name for f in dataclasses.fields(BuoyCase)}
                else ""
            )
            raise InvalidInputError(
                f"unexpected top-level key {key!r} in case file {str(path)!r}: only the tables "
                f"[case] and [sweep] are read{hint}",
                name=key,
                value=value,
                source=str(path),
            )
    return data


def load_study(path: str | Path) -> tuple[BuoyCase, SweepSettings]:
    """Read a case and its sweep from a TOML file with optional ``[case]`` and ``[sweep]`` tables.

    Arguments:
        path: the TOML file.

    Returns:
        ``(case, sweep)``; a missing table or key keeps the defaults.

    Raises:
        InvalidInputError: if the file is missing, unreadable or not TOML, has a key outside the
            two tables, or a table has an unknown key or a bad value (the message names the file).
    """
    data = _read_toml(path)
    source = str(path)
    case = BuoyCase.from_mapping(data.get("case", {}), source=source)
    sweep = SweepSettings.from_mapping(data.get("sweep", {}), source=source)
    return case, sweep


def load_case(path: str | Path) -> BuoyCase:
    """Read the ``[case]`` table of a TOML file (see :func:`load_study`).

    Arguments:
        path: the TOML file.

    Returns:
        The case; keys left out keep their defaults.

    Raises:
        InvalidInputError: as :func:`load_study`.
    """
    return load_study(path)[0]


def load_sweep(path: str | Path) -> SweepSettings:
    """Read the ``[sweep]`` table of a TOML file (see :func:`load_study`).

    Arguments:
        path: the TOML file.

    Returns:
        The sweep settings; keys left out keep their defaults.

    Raises:
        InvalidInputError: as :func:`load_study`.
    """
    return load_study(path)[1]
