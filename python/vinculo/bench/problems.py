"""The accuracy problems: smooth constrained motions with a reference computed without vinculo.

Each problem is built twice: as a vinculo System (Cartesian point masses, index-3 constraints)
and as the ordinary differential equation of the same motion in minimal coordinates (angles of
the links, no multiplier: the index-0 form), which scipy integrates for the reference (DOP853 at
rtol = atol = 1e-13, far below every tolerance measured) and, with Radau, for the peer column of
the work-precision table.

- ``pendulum``: a 1 kg bob on a 1 m link to a fixed pivot, released at rest 90 degrees from the
  downward vertical (a swing of the full half-circle, the largest nonlinearity), 2 s.
- ``chain``: three 1 kg bobs on 0.5 m links from a fixed pivot, released at rest along a line
  60 degrees from the vertical (a chaotic system: 1.5 s keeps the growth of errors moderate).
- ``moving-plane``: a two-particle mechanism with a moving constraint: a 1 kg slider held on the
  horizontal plane z = 0 and on the moving plane x = p(t) = 0.2 sin(2 pi t) (so its motion is
  prescribed through two multipliers), and a 1 kg bob on a 1 m link from it, released at rest
  relative to the slider 30 degrees from the vertical, 2 s. The bob's angle obeys the pendulum
  equation with the pivot's acceleration.

The planar chain of point masses m_i on links l_i at angles theta_i from the downward vertical
(Lagrange's equations, the masses beyond link j summed in mu_jk = sum_{i >= max(j, k)} m_i):

    sum_k mu_jk l_j l_k [cos(th_j - th_k) th_k'' + sin(th_j - th_k) th_k'^2]
        = -g l_j sin(th_j) mu_jj - l_j cos(th_j) p''(t) mu_jj

with p(t) the pivot's horizontal position (zero for a fixed pivot).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

import vinculo

#: Gravity, m/s^2 (along -z).
GRAVITY = 9.81


@dataclass(frozen=True)
class Problem:
    """A planar chain of point masses from a pivot that moves along x (or not), in minimal
    coordinates and as a vinculo System.

    Attributes:
        name: label of the tables.
        masses: the bobs' masses, kg, from the pivot outwards.
        links: the links' lengths, m.
        theta0: initial angles from the downward vertical, rad (at rest relative to the pivot).
        t_end: simulated time, s.
        amplitude: amplitude of the pivot's motion p(t) = amplitude sin(2 pi frequency t), m
            (0: fixed pivot).
        frequency: its frequency, Hz.
        slider: True: the pivot is a 1 kg particle held by two planes (z = 0 and the moving
            x = p(t)); False: the first link is a distance to a prescribed point.
    """

    name: str
    masses: tuple[float, ...]
    links: tuple[float, ...]
    theta0: tuple[float, ...]
    t_end: float
    amplitude: float = 0.0
    frequency: float = 1.0
    slider: bool = False
    _cache: dict = field(default_factory=dict, compare=False, repr=False)

    def pivot(self, t):
        """p, p', p'' of the pivot at t."""
        w = 2.0 * np.pi * self.frequency
        a = self.amplitude
        return a * np.sin(w * t), a * w * np.cos(w * t), -a * w * w * np.sin(w * t)

    def rhs(self) -> Callable[[float, np.ndarray], np.ndarray]:
        """The right-hand side of y' = f(t, y), y = (theta, theta') (module documentation)."""
        m = np.asarray(self.masses)
        ell = np.asarray(self.links)
        n = len(m)
        tail = np.cumsum(m[::-1])[::-1]
        mu = tail[np.maximum.outer(np.arange(n), np.arange(n))]
        lw = np.outer(ell, ell) * mu
        tail_l = tail * ell

        def f(t, y):
            th, om = y[:n], y[n:]
            diff = th[:, None] - th[None, :]
            mass = lw * np.cos(diff)
            force = -(lw * np.sin(diff)) @ (om * om) - tail_l * (
                GRAVITY * np.sin(th) + np.cos(th) * self.pivot(t)[2]
            )
            return np.concatenate([om, np.linalg.solve(mass, force)])

        return f

    def initial(self) -> np.ndarray:
        """y(0): the angles at rest."""
        return np.concatenate([np.asarray(self.theta0, dtype=float), np.zeros(len(self.masses))])

    def cartesian(self, t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The bobs' positions and velocities, shape (len(t), n, 3), from y of shape
        (len(t), 2n)."""
        n = len(self.masses)
        th, om = y[:, :n], y[:, n:]
        ell = np.asarray(self.links)
        p, pv, _ = self.pivot(np.asarray(t))
        x = p[:, None] + np.cumsum(ell * np.sin(th), axis=1)
        z = -np.cumsum(ell * np.cos(th), axis=1)
        vx = pv[:, None] + np.cumsum(ell * np.cos(th) * om, axis=1)
        vz = np.cumsum(ell * np.sin(th) * om, axis=1)
        zero = np.zeros_like(x)
        return np.stack([x, zero, z], axis=2), np.stack([vx, zero, vz], axis=2)

    def reference(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The bobs' positions and velocities at ``times`` (DOP853 at 1e-13; cached)."""
        times = np.asarray(times, dtype=float)
        key = (len(times), float(times[0]), float(times[-1]))
        if key not in self._cache:
            result = solve_ivp(
                self.rhs(),
                (0.0, float(times[-1])),
                self.initial(),
                method="DOP853",
                rtol=1e-13,
                atol=1e-13,
                t_eval=times,
            )
            assert result.success, result.message
            self._cache[key] = self.cartesian(times, result.y.T)
        return self._cache[key]

    def build(self) -> tuple[vinculo.System, list[vinculo.ParticleId]]:
        """The vinculo System of the same motion, and the bobs' handles (from the pivot out)."""
        system = vinculo.System(gravity=(0.0, 0.0, -GRAVITY))
        y0 = self.initial()[None, :]
        q0, v0 = self.cartesian(np.zeros(1), y0)
        _, pv0, _ = self.pivot(0.0)
        bobs = []
        if self.slider:
            prev = system.add_particle(1.0, [0.0, 0.0, 0.0], velocity=[pv0, 0.0, 0.0])
            system.add_plane(prev, (0.0, 0.0, 1.0), (0.0, 0.0, 0.0))
            law = vinculo.sine(self.amplitude, self.frequency)
            system.add_plane(prev, (1.0, 0.0, 0.0), (law, 0.0, 0.0))
        for i, (mass, link) in enumerate(zip(self.masses, self.links, strict=True)):
            bob = system.add_particle(mass, q0[0, i], velocity=v0[0, i])
            if i > 0 or self.slider:
                system.add_distance(prev, bob, link)
            elif self.amplitude != 0.0:
                law = vinculo.sine(self.amplitude, self.frequency)
                system.add_distance_to_point(bob, (law, 0.0, 0.0), link)
            else:
                system.add_distance_to_point(bob, (0.0, 0.0, 0.0), link)
            bobs.append(bob)
            prev = bob
        return system, bobs


#: The problems of the accuracy tests and of the work-precision table.
PROBLEMS = {
    "pendulum": Problem("pendulum", (1.0,), (1.0,), (np.pi / 2,), t_end=2.0),
    "chain": Problem("chain", (1.0,) * 3, (0.5,) * 3, (np.pi / 3,) * 3, t_end=1.5),
    "moving-plane": Problem(
        "moving plane",
        (1.0,),
        (1.0,),
        (np.pi / 6,),
        t_end=2.0,
        amplitude=0.2,
        frequency=1.0,
        slider=True,
    ),
}


def max_error(problem: Problem, solution: vinculo.Solution, bobs) -> tuple[float, float]:
    """The largest position (m) and velocity (m/s) errors of the bobs over the stored times,
    against the reference."""
    positions, velocities = problem.reference(solution.times)
    q = np.stack([solution.particle(b) for b in bobs], axis=1)
    v = np.stack([solution.particle_velocity(b) for b in bobs], axis=1)
    return float(np.max(np.abs(q - positions))), float(np.max(np.abs(v - velocities)))
