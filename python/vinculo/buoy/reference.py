"""Reference models of the buoy, integrated with scipy: the rigid pendulum and the string + sphere.

Both models work in the frame of the tank, whose floor carries the anchor at ``(X_t(t), 0)``; z is
up and angles are measured from the upward vertical, positive towards +x. The fluid moves rigidly
with the tank (no sloshing), so the fluid velocity and acceleration are ``X_t'`` and ``X_t''``.

Forces on the sphere (mass m_s, displaced mass m_f = rho_f V, added mass m_a = Ca m_f), with b the
absolute position of its centre and ``r = b - (X_t, 0)`` its position relative to the anchor::

    gravity                    m_s (0, -g)
    buoyancy + Froude-Krylov   m_f (X_t'', g)
    added mass                 m_a ((X_t'', 0) - b'') = -m_a r''
    drag                       1/2 rho_f Cd A |u_f - b'| (u_f - b') = -k |r'| r'

with ``k = 1/2 rho_f Cd A``. With ``viscous_force = "stokes-layer"`` the Stokes layer adds
``-c r' - m_v r''`` (:meth:`vinculo.buoy.case.BuoyCase.stokes_layer`, evaluated at the excitation
frequency, or at the lowest non-zero natural frequency for a tank at rest): ``m_v`` joins the
translating mass and ``-c r'`` the applied force.

Newton's law for the centre, ``m_s b'' = sum of forces + string force``, with ``b'' = (X_t'', 0) +
r''``, becomes in the tank frame::

    (m_s + m_a) r'' = (m_f - m_s) (X_t'', g) - k |r'| r' + string force

so the sphere behaves like a body of mass ``m = m_s + m_a`` (translation) pushed by the force
``mu (a_t, g)``, ``mu = m_f - m_s``: the pseudo-force of the accelerating frame and the
Froude-Krylov force combine to ``mu a_t``. Added mass acts on the translation of the centre only:
a sphere's rotation displaces no fluid.

The string is inextensible and massless in both models (a case's ``string_beads`` and
``string_mass`` are for the particle model and are not used here).

The tank's motion is ``X_t(t) = X0 s(t) sin(2 pi f t)``, with the C2 quintic ramp ``s`` of
:func:`tank_motion`, the same ramp as :func:`vinculo.sine` with ``ramp_time = ramp_periods / f``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np
from scipy.integrate import solve_ivp

from vinculo.buoy.case import BuoyCase
from vinculo.buoy.tank import MeasuredTankMotion, TankMotion, tank_motion
from vinculo.errors import ConvergenceError, InvalidInputError

__all__ = [
    "OneDofModel",
    "ReferenceRun",
    "TwoDofModel",
    "antiresonance_frequency",
    "high_frequency_ratio",
]

#: Relative and absolute tolerances of the integration (angles in rad, rates in rad/s).
RTOL = 1e-9
ATOL = 1e-11
#: Largest integration step, as a fraction of the shortest period in the problem.
STEP_FRACTION = 0.5


_TANK_AT_REST = TankMotion(0.0, 1.0, 0.0)


def high_frequency_ratio(case: BuoyCase, include_inertia: bool = False) -> float:
    """Ratio of relative to tank amplitude as the frequency goes to infinity.

    At high frequency the restoring force no longer matters and the centre follows
    ``(m_s + m_a) r_x'' = (m_f - m_s) X_t''`` (point mass, or the 2-DOF string + sphere, whose
    sphere then translates without turning), in phase with the tank. A rigid pendulum of length L
    also has to spin the sphere, which lowers the ratio: ``(m_f - m_s) L^2 / ((m_s + m_a) L^2 +
    I_c)``.

    Arguments:
        case: the buoy case.
        include_inertia: include the sphere's rotational inertia I_c (rigid-pendulum reading,
            L = ``case.pendulum_length``).

    Returns:
        ``(m_f - m_s) / (m_s + m_a)`` without inertia (0.714 for the default case), or the rigid-
        pendulum value with it.
    """
    mu = case.displaced_mass - case.sphere_mass
    mass = case.sphere_mass + case.added_mass
    length = case.pendulum_length
    inertia = case.centre_inertia if include_inertia else 0.0
    return mu * length**2 / (mass * length**2 + inertia)


def antiresonance_frequency(case: BuoyCase, include_inertia: bool = False) -> float:
    """Frequency at which the linear, undamped pendulum's absolute displacement vanishes.

    With ``x_rel = H X_t`` and ``H = mu L^2 w^2 / ((m L^2 + I) w^2 - mu g L)``, the absolute
    motion ``(1 + H) X_t`` is zero at ``w^2 = mu g L / ((m_f + m_a) L^2 + I)``: the point-mass
    value ``mu g / ((m_f + m_a) L)`` when ``I = 0``.

    Arguments:
        case: the buoy case (L = ``case.pendulum_length``).
        include_inertia: include I_c (rigid-pendulum reading).

    Returns:
        The frequency, in Hz.
    """
    mu = case.displaced_mass - case.sphere_mass
    length = case.pendulum_length
    inertia = case.centre_inertia if include_inertia else 0.0
    denominator = (case.displaced_mass + case.added_mass) * length**2 + inertia
    return math.sqrt(mu * case.gravity * length / denominator) / (2.0 * math.pi)


@dataclass(frozen=True)
class ReferenceRun:
    """A time history of a reference model.

    Attributes:
        model: which model produced it (``"1-DOF"``, ``"2-DOF"``, ``"2-DOF rigid"``).
        frequency: excitation frequency, in Hz (``None``: the tank stood still).
        times: sample times, in s, shape (n,).
        x_tank: tank displacement X_t, in m.
        x_rel: horizontal position of the sphere's centre relative to the anchor, in m.
        z_rel: height of the centre above the anchor, in m.
        x_abs: horizontal displacement of the centre in the laboratory, ``X_t + x_rel``, in m.
        tension: string (rod) tension, in N (positive when pulling).
        angles: generalised coordinates, in rad, shape (n, dof).
        rates: their time derivatives, in rad/s, shape (n, dof).
    """

    model: str
    frequency: float | None
    times: np.ndarray
    x_tank: np.ndarray
    x_rel: np.ndarray
    z_rel: np.ndarray
    x_abs: np.ndarray
    tension: np.ndarray
    angles: np.ndarray
    rates: np.ndarray


class _PendulumModel:
    """Shared integration and sampling of the reference models."""

    name = ""
    dof = 1

    def __init__(self, case: BuoyCase) -> None:
        if not isinstance(case, BuoyCase):
            raise InvalidInputError(
                f"case must be a BuoyCase, got {type(case).__name__}", name="case", value=case
            )
        self.case = case
        self._mass = case.sphere_mass + case.added_mass
        self._mu = case.displaced_mass - case.sphere_mass
        self._drag = 0.5 * case.fluid_density * case.drag_coefficient * case.frontal_area
        self._viscous = 0.0  # Stokes-layer damping c, N s/m (set per run)
        self._viscous_mass = 0.0  # Stokes-layer added mass m_v, kg (set per run)

    def _swing_frequency(self) -> float:
        """The lowest non-zero linear natural frequency (Hz), without the Stokes layer."""
        raise NotImplementedError

    def viscous_terms(self, frequency: float | None) -> tuple[float, float]:
        """The Stokes-layer damping and added mass the model uses at ``frequency``.

        Arguments:
            frequency: the excitation frequency, in Hz; None (a tank at rest): the lowest non-zero
                natural frequency, the frequency of the free swing.

        Returns:
            ``(c, m_v)`` in N s/m and kg (both 0 unless ``case.viscous_force`` is
            ``"stokes-layer"``).
        """
        if self.case.viscous_force != "stokes-layer":
            return 0.0, 0.0
        if frequency is None:
            frequency = self._swing_frequency()
        return self.case.stokes_layer(frequency)

    # subclasses: shortest free period, rest state for a tank velocity, and the dynamics
    def _shortest_period(self) -> float:
        raise NotImplementedError

    def _rest_state(self, tank_velocity: float) -> np.ndarray:
        raise NotImplementedError

    def _dynamics(self, angles: Any, rates: Any, a_t: Any, xp: ModuleType) -> tuple[Any, ...]:
        """Accelerations, centre position (x, z) and tension; ``xp`` is math or numpy."""
        raise NotImplementedError

    def simulate(
        self,
        frequency: float | None,
        t_end: float,
        *,
        initial: Any = None,
        sample_dt: float = 1e-3,
        tank: TankMotion | MeasuredTankMotion | None = None,
        t_start: float = 0.0,
    ) -> ReferenceRun:
        """Integrate the model with the tank shaken at ``frequency`` from ``t = 0`` to ``t_end``.

        DOP853 with relative tolerance 1e-9, absolute tolerance 1e-11 and steps no longer than
        half the shortest period (excitation or free mode).

        Arguments:
            frequency: excitation frequency, in Hz; ``None`` keeps the tank still (free motion).
            t_end: end time, in s.
            initial: initial angles and rates (see the model's class docstring); default: upright
                and at rest in the laboratory (zero relative rates with the default ramp; with the
                abrupt start, the relative rates that cancel the tank's initial velocity).
            sample_dt: spacing of the stored samples, in s (samples at ``k * sample_dt``, plus
                ``t_end``).
            tank: a tank motion to use instead of the harmonic one at ``frequency``, such as a
                measured record (:func:`vinculo.buoy.tank.read_tank_motion`); ``frequency`` is
                then ignored and the run is labelled with the motion's frequency.
            t_start: the time at which the run starts, in s (samples at ``t_start + k *
                sample_dt``); with ``initial``, continue an earlier run from its last state.

        Returns:
            The time history.

        Raises:
            InvalidInputError: for a bad frequency, ``t_end``, ``sample_dt`` or ``initial``, or a
                ``t_end`` beyond the end of a measured ``tank`` record.
            ConvergenceError: if the integrator fails.
        """
        if tank is None:
            tank = _TANK_AT_REST if frequency is None else tank_motion(self.case, frequency)
            frequency = None if frequency is None else tank.frequency
        else:
            frequency = tank.frequency
        if not (math.isfinite(t_start) and t_start >= 0.0):
            raise InvalidInputError(
                f"t_start must be a finite time >= 0 in s, got {t_start!r}",
                name="t_start",
                value=t_start,
            )
        if not (math.isfinite(t_end) and t_end > t_start):
            raise InvalidInputError(
                f"t_end must be a finite time in s after t_start = {t_start!r}, got {t_end!r}",
                name="t_end",
                value=t_end,
            )
        if t_end > tank.duration * (1.0 + 1e-12):
            raise InvalidInputError(
                f"t_end = {t_end!r} s goes beyond the tank motion record ({tank.duration:g} s)",
                name="t_end",
                value=t_end,
            )
        if not (math.isfinite(sample_dt) and 0.0 < sample_dt <= t_end - t_start):
            raise InvalidInputError(
                f"sample_dt must be positive and at most the run's duration "
                f"{t_end - t_start!r} s, got {sample_dt!r}",
                name="sample_dt",
                value=sample_dt,
            )
        if initial is None:
            y0 = self._rest_state(tank.at(t_start)[1])
        else:
            y0 = np.asarray(initial, dtype=np.float64).reshape(-1)
            if y0.shape != (2 * self.dof,) or not np.all(np.isfinite(y0)):
                raise InvalidInputError(
                    f"initial must be {2 * self.dof} finite numbers (angles in rad, then rates in "
                    f"rad/s), got {initial!r}",
                    name="initial",
                    value=initial,
                )
        count = math.floor((t_end - t_start) / sample_dt + 1e-9)
        times = t_start + np.arange(count + 1) * sample_dt
        if times[-1] < t_end * (1.0 - 1e-12):
            times = np.append(times, t_end)
        times[-1] = min(times[-1], t_end)
        period = self._shortest_period()
        if frequency is not None:
            period = min(period, 1.0 / frequency)
        max_step = STEP_FRACTION * period
        knots = getattr(tank, "times", None)
        if knots is not None:
            # A measured motion's acceleration has a kink at every sample: steps that span one
            # sample at most are not rejected at the kinks (about 9 times fewer evaluations).
            max_step = min(max_step, float(np.max(np.diff(knots))))
        dof = self.dof
        self._viscous, self._viscous_mass = self.viscous_terms(frequency)

        def rhs(t: float, y: np.ndarray) -> list[float]:
            a_t = tank.at(t)[2]
            accelerations = self._dynamics(y[:dof], y[dof:], a_t, math)[0]
            return [*y[dof:], *accelerations]

        result = solve_ivp(
            rhs,
            (float(times[0]), float(times[-1])),
            y0,
            method="DOP853",
            t_eval=times,
            rtol=RTOL,
            atol=ATOL,
            max_step=max_step,
        )
        if result.status != 0:
            raise ConvergenceError(
                f"the {self.name} reference model failed at t = {result.t[-1]:.6g} s: "
                f"{result.message}",
                time=float(result.t[-1]),
            )
        angles, rates = result.y[:dof].T, result.y[dof:].T
        x_tank, _, a_tank = tank(times)
        _, x_rel, z_rel, tension = self._dynamics(angles.T, rates.T, a_tank, np)
        return ReferenceRun(
            model=self.name,
            frequency=frequency,
            times=times,
            x_tank=x_tank,
            x_rel=x_rel,
            z_rel=z_rel,
            x_abs=x_tank + x_rel,
            tension=tension,
            angles=angles.copy(),
            rates=rates.copy(),
        )


class OneDofModel(_PendulumModel):
    """The rigid pendulum: the corrected eq. 31 of the study.

    One angle theta of the anchor-to-centre line from the upward vertical, L the anchor-to-centre
    distance (``case.pendulum_length``), ``m = m_s + m_a``, ``mu = m_f - m_s``::

        (m L^2 + I) theta'' = -mu g L sin(theta) + mu a_t L cos(theta) - k L^3 |theta'| theta'

    ``I = I_c = 2/5 m_s R^2`` when the sphere turns with the string (rigid-pendulum reading) and 0
    for a point mass. With ``attachment = "centre"`` the string pulls through the centre, which
    exerts no moment on the sphere, so its rotation decouples: the point mass (``I = 0``) is then
    the natural reading and the default. The rod tension is the force along the rod,
    ``T = mu (a_t sin(theta) + g cos(theta)) + m L theta'^2`` (drag is normal to the rod).

    ``initial`` for :meth:`simulate` is ``(theta, theta')``.

    Arguments:
        case: the buoy case.
        include_inertia: include I_c; default (``None``): yes for ``attachment = "bottom"``, no
            for ``"centre"``.

    Raises:
        InvalidInputError: if ``case`` is not a :class:`BuoyCase`.
    """

    name = "1-DOF"
    dof = 1

    def __init__(self, case: BuoyCase, include_inertia: bool | None = None) -> None:
        super().__init__(case)
        if include_inertia is None:
            include_inertia = case.attachment == "bottom"
        self.include_inertia = bool(include_inertia)
        self.length = case.pendulum_length
        self.inertia = case.centre_inertia if self.include_inertia else 0.0

    def natural_frequency(self) -> float:
        """The linear natural frequency ``sqrt(mu g L / (m L^2 + I)) / (2 pi)``.

        Returns:
            The frequency, in Hz.
        """
        length = self.length
        omega2 = self._mu * self.case.gravity * length / (self._mass * length**2 + self.inertia)
        return math.sqrt(omega2) / (2.0 * math.pi)

    def _shortest_period(self) -> float:
        return 1.0 / self.natural_frequency()

    def _swing_frequency(self) -> float:
        return self.natural_frequency()

    def _rest_state(self, tank_velocity: float) -> np.ndarray:
        return np.array([0.0, -tank_velocity / self.length])

    def _dynamics(self, angles: Any, rates: Any, a_t: Any, xp: ModuleType) -> tuple[Any, ...]:
        theta, rate = angles[0], rates[0]
        length, mu, g = self.length, self._mu, self.case.gravity
        sine, cosine = xp.sin(theta), xp.cos(theta)
        mass = self._mass + self._viscous_mass
        moment = (
            -mu * g * length * sine
            + mu * a_t * length * cosine
            - self._drag * length**3 * abs(rate) * rate
            - self._viscous * length**2 * rate
        )
        acceleration = moment / (mass * length**2 + self.inertia)
        tension = mu * (a_t * sine + g * cosine) + mass * length * rate**2
        return (acceleration,), length * sine, length * cosine, tension


class TwoDofModel(_PendulumModel):
    """The string + sphere: two angles, the sphere turning freely about the attachment point.

    theta1 is the string's angle and theta2 the angle of the attachment-to-centre line, both from
    the upward vertical. With l the string length and R the radius (``R = 0`` in the geometry for
    ``attachment = "centre"``), the centre relative to the anchor is
    ``r = (l sin th1 + R sin th2, l cos th1 + R cos th2)``; the sphere's angular velocity is th2'.

    Derivation (Lagrange, tank frame). With ``m = m_s + m_a`` and ``d = th1 - th2``::

        T = 1/2 m |r'|^2 + 1/2 I_c th2'^2
          = 1/2 m (l^2 th1'^2 + 2 l R cos(d) th1' th2' + R^2 th2'^2) + 1/2 I_c th2'^2

    The applied force on the centre is ``F = mu (a_t, g) - k |r'| r'`` (see the module docstring),
    with generalised forces ``Q_j = F . dr/dth_j``, ``dr/dth1 = l (cos th1, -sin th1)``,
    ``dr/dth2 = R (cos th2, -sin th2)``. ``d/dt dT/dth_j' - dT/dth_j = Q_j`` gives::

        m l^2 th1''        + m l R cos(d) th2''   = Q1 - m l R sin(d) th2'^2
        m l R cos(d) th1'' + (m R^2 + I_c) th2''  = Q2 + m l R sin(d) th1'^2

    solved as a 2x2 system at each evaluation. Linearised about the upright state (``Q ~ -mu g
    diag(l, R) theta``): ``M theta'' + K theta = 0`` with ``M = [[m l^2, m l R], [m l R, m R^2 +
    I_c]]``, ``K = mu g diag(l, R)``; ``det M = m l^2 I_c``.

    String tension: the massless string pulls the sphere towards the anchor along
    ``e = (sin th1, cos th1)``, so ``m r'' = F - T e`` and ``T = e . (F - m r'')`` with
    ``e . r'' = -l th1'^2 + R sin(d) th2'' - R cos(d) th2'^2``. At rest ``T = mu g``. (The sphere's
    own balance of moments, ``I_c th2'' = T R sin(d)``, then holds as well.)

    ``attachment = "centre"``: ``R = 0``, the string force passes through the centre, the second
    equation reads ``I_c th2'' = 0`` and the first is the point-mass pendulum of length l; the
    spin mode has frequency 0.

    ``rigid=True`` locks the sphere to the string (``th2 = th1 = theta``): projecting both
    equations on that motion (virtual work along ``(1, 1)``) gives ``(m (l + R)^2 + I_c) theta'' =
    Q1 + Q2``, which is eq. 31 with ``L = l + R`` and ``I = I_c`` (the gyroscopic terms vanish at
    ``d = 0``). The tension is then the force along the line, as in :class:`OneDofModel`.

    ``initial`` for :meth:`simulate` is ``(th1, th2, th1', th2')``, or ``(theta, theta')`` when
    rigid.

    Arguments:
        case: the buoy case.
        rigid: lock the sphere to the string.

    Raises:
        InvalidInputError: if ``case`` is not a :class:`BuoyCase`.
    """

    def __init__(self, case: BuoyCase, rigid: bool = False) -> None:
        super().__init__(case)
        self.rigid = bool(rigid)
        self.name = "2-DOF rigid" if self.rigid else "2-DOF"
        self.dof = 1 if self.rigid else 2
        self.string_length = case.string_length
        self.offset = case.radius if case.attachment == "bottom" else 0.0
        self.inertia = case.centre_inertia

    def matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """Mass and stiffness matrices of the linearised 2-DOF model (unlocked).

        Returns:
            ``(M, K)``, 2x2 arrays in kg m^2 and N m per rad.
        """
        m, ell, r = self._mass, self.string_length, self.offset
        mass = np.array([[m * ell**2, m * ell * r], [m * ell * r, m * r**2 + self.inertia]])
        stiffness = self._mu * self.case.gravity * np.diag([ell, r])
        return mass, stiffness

    def natural_frequencies(self) -> np.ndarray:
        """Linear natural frequencies, ascending, from the closed-form roots of det(K - w^2 M).

        ``a w^4 - b w^2 + c = 0`` with ``a = det M = m l^2 I_c``, ``b = K11 M22 + K22 M11``,
        ``c = K11 K22``; the smaller root is computed as ``2c / (b + sqrt(b^2 - 4ac))`` to avoid
        cancellation. For ``attachment = "centre"`` the lower one is the sphere's free spin, 0 Hz.

        Returns:
            Two frequencies in Hz (one when ``rigid``: ``sqrt(mu g L / (m L^2 + I_c)) / (2 pi)``
            with ``L = l + R``).
        """
        mu_g = self._mu * self.case.gravity
        if self.rigid:
            length = self.string_length + self.offset
            omega2 = mu_g * length / (self._mass * length**2 + self.inertia)
            return np.array([math.sqrt(omega2) / (2.0 * math.pi)])
        mass, stiffness = self.matrices()
        a = mass[0, 0] * mass[1, 1] - mass[0, 1] ** 2
        b = stiffness[0, 0] * mass[1, 1] + stiffness[1, 1] * mass[0, 0]
        c = stiffness[0, 0] * stiffness[1, 1]
        root = math.sqrt(b * b - 4.0 * a * c)
        omega2 = np.array([2.0 * c / (b + root), (b + root) / (2.0 * a)])
        return np.sqrt(omega2) / (2.0 * math.pi)

    def mode_shapes(self) -> np.ndarray:
        """Mode shapes of the linearised 2-DOF model (unlocked), one row per mode.

        Returns:
            Array (2, 2): row k is ``(th1, th2)`` of mode k (same order as
            :meth:`natural_frequencies`), scaled so that its largest component is +1. Mode 1 has
            both angles of one sign (the sphere leans with the string); mode 2 has opposite signs.
        """
        if self.rigid:
            return np.array([[1.0, 1.0]])
        mass, stiffness = self.matrices()
        shapes = np.empty((2, 2))
        for k, frequency in enumerate(self.natural_frequencies()):
            omega2 = (2.0 * math.pi * frequency) ** 2
            matrix = stiffness - omega2 * mass
            # (K - w^2 M) is singular: the shape is orthogonal to its larger row.
            row = matrix[0] if np.abs(matrix[0]).sum() >= np.abs(matrix[1]).sum() else matrix[1]
            shape = np.array([-row[1], row[0]])
            shapes[k] = shape / shape[np.argmax(np.abs(shape))] + 0.0  # no -0.0
        return shapes

    def _shortest_period(self) -> float:
        frequencies = self.natural_frequencies()
        return 1.0 / float(frequencies.max())

    def _swing_frequency(self) -> float:
        frequencies = self.natural_frequencies()
        return float(frequencies[frequencies > 0.0].min())

    def _rest_state(self, tank_velocity: float) -> np.ndarray:
        if self.rigid:
            return np.array([0.0, -tank_velocity / (self.string_length + self.offset)])
        # Upright, the sphere not turning in the laboratory; the string takes up the tank's motion.
        return np.array([0.0, 0.0, -tank_velocity / self.string_length, 0.0])

    def _dynamics(self, angles: Any, rates: Any, a_t: Any, xp: ModuleType) -> tuple[Any, ...]:
        if self.rigid:
            th1 = th2 = angles[0]
            w1 = w2 = rates[0]
        else:
            th1, th2 = angles[0], angles[1]
            w1, w2 = rates[0], rates[1]
        m, mu, g = self._mass + self._viscous_mass, self._mu, self.case.gravity
        ell, r = self.string_length, self.offset
        s1, c1, s2, c2 = xp.sin(th1), xp.cos(th1), xp.sin(th2), xp.cos(th2)
        vx = ell * w1 * c1 + r * w2 * c2
        vz = -ell * w1 * s1 - r * w2 * s2
        speed = xp.sqrt(vx * vx + vz * vz)
        fx = mu * a_t - (self._drag * speed + self._viscous) * vx
        fz = mu * g - (self._drag * speed + self._viscous) * vz
        q1 = ell * (fx * c1 - fz * s1)
        q2 = r * (fx * c2 - fz * s2)
        along_string = fx * s1 + fz * c1
        if self.rigid:
            length = ell + r
            acceleration = (q1 + q2) / (m * length**2 + self.inertia)
            tension = along_string + m * length * w1**2
            return (acceleration,), length * s1, length * c1, tension
        sin_d = s1 * c2 - c1 * s2
        cos_d = c1 * c2 + s1 * s2
        m11, m12, m22 = m * ell**2, m * ell * r * cos_d, m * r**2 + self.inertia
        rhs1 = q1 - m * ell * r * sin_d * w2**2
        rhs2 = q2 + m * ell * r * sin_d * w1**2
        det = m11 * m22 - m12 * m12
        acc1 = (m22 * rhs1 - m12 * rhs2) / det
        acc2 = (m11 * rhs2 - m12 * rhs1) / det
        tension = along_string - m * (-ell * w1**2 + r * sin_d * acc2 - r * cos_d * w2**2)
        return (acc1, acc2), ell * s1 + r * s2, ell * c1 + r * c2, tension
