"""Pendulum references shared by the scheme tests, computed independently of vinculo with scipy.

The references integrate the pendulum's angle ODE (minimal coordinates, no constraint: the index-1
form of the motion) with scipy's DOP853 at rtol = atol = 1e-12, far below the errors of the
schemes and tolerances the tests use.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

import vinculo
from vinculo import demos

GRAVITY = demos.GRAVITY


def angle_history(
    theta0: float,
    times: np.ndarray,
    pivot_acceleration: Callable[[float], float] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Angles from the downward vertical, and their rates, at ``times`` (increasing, from 0) of a
    1 m pendulum released at rest relative to its pivot:
    theta'' = -(g/L) sin theta - (x_p''(t)/L) cos theta, where x_p is the pivot's horizontal
    position (the Lagrangian in minimal coordinates, L = 1 m)."""

    def rhs(t, y):
        acc = pivot_acceleration(t) if pivot_acceleration is not None else 0.0
        return [y[1], -GRAVITY * np.sin(y[0]) - acc * np.cos(y[0])]

    times = np.asarray(times, dtype=float)
    result = solve_ivp(
        rhs,
        (0.0, float(times[-1])),
        [theta0, 0.0],
        method="DOP853",
        rtol=1e-12,
        atol=1e-12,
        t_eval=times,
    )
    assert result.success
    return result.y[0], result.y[1]


def angle_reference(
    theta0: float, t_end: float, pivot_acceleration: Callable[[float], float] | None = None
) -> float:
    """The angle of :func:`angle_history` at ``t_end`` alone."""
    return float(angle_history(theta0, np.array([t_end]), pivot_acceleration)[0][-1])


@dataclass(frozen=True)
class MovingPivot:
    """A 1 m pendulum whose pivot moves as x_p = amplitude sin(2 pi frequency t) m (a prescribed
    point of ``add_distance_to_point``), released at ``theta0`` from the downward vertical with
    the pivot's velocity (at rest relative to it: a consistent start)."""

    amplitude: float = 0.1
    frequency: float = 1.0
    theta0: float = np.pi / 6
    # The pivot's shaking may start at t_start, rising over ramp_time as the C2 quintic of
    # ``vinculo.sine`` (s = 10 u^3 - 15 u^4 + 6 u^5, u = (t - t_start)/ramp_time).
    ramp_time: float = 0.0
    t_start: float = 0.0
    phase: float = 0.0

    @property
    def omega(self) -> float:
        return 2.0 * np.pi * self.frequency

    def build(self) -> tuple[vinculo.System, vinculo.ParticleId]:
        """The model and its bob."""
        system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
        bob = system.add_particle(
            1.0,
            [np.sin(self.theta0), 0.0, -np.cos(self.theta0)],
            velocity=[float(self._pivot_derivatives(0.0)[1]), 0.0, 0.0],
        )
        law = vinculo.sine(
            self.amplitude,
            self.frequency,
            phase=self.phase,
            ramp_time=self.ramp_time,
            t_start=self.t_start,
        )
        system.add_distance_to_point(bob, (law, 0.0, 0.0), 1.0)
        return system, bob

    def _ramp(self, t):
        """The ramp s and its first two time derivatives."""
        t = np.asarray(t, dtype=float)
        if self.ramp_time <= 0.0:
            one = np.ones_like(t)
            return one, 0.0 * one, 0.0 * one
        u = np.clip((t - self.t_start) / self.ramp_time, 0.0, 1.0)
        d = self.ramp_time
        return (
            u**3 * (10.0 - 15.0 * u + 6.0 * u**2),
            30.0 * u**2 * (1.0 - u) ** 2 / d,
            60.0 * u * (1.0 - 3.0 * u + 2.0 * u**2) / d**2,
        )

    def _pivot_derivatives(self, t):
        """x_p, x_p', x_p'' at t."""
        t = np.asarray(t, dtype=float)
        w = self.omega
        arg = w * (t - self.t_start) + self.phase
        g = np.array([np.sin(arg), w * np.cos(arg), -(w**2) * np.sin(arg)])
        s = self._ramp(t)
        a = self.amplitude
        return (
            a * s[0] * g[0],
            a * (s[1] * g[0] + s[0] * g[1]),
            a * (s[2] * g[0] + 2.0 * s[1] * g[1] + s[0] * g[2]),
        )

    def pivot(self, t):
        return self._pivot_derivatives(t)[0]

    def pivot_acceleration(self, t: float) -> float:
        return float(self._pivot_derivatives(t)[2])

    def bob_states(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(len(times), 3) reference positions and velocities of the bob."""
        times = np.asarray(times, dtype=float)
        theta, rate = angle_history(self.theta0, times, self.pivot_acceleration)
        zero = np.zeros_like(theta)
        pivot_rate = self._pivot_derivatives(times)[1]
        positions = np.stack([self.pivot(times) + np.sin(theta), zero, -np.cos(theta)], axis=1)
        velocities = np.stack(
            [pivot_rate + np.cos(theta) * rate, zero, np.sin(theta) * rate], axis=1
        )
        return positions, velocities
