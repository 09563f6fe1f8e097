"""Frequency-dependent added mass and radiation damping from a BEM code (Capytaine), and their
time-domain model: a state-space approximation of the radiation memory (docs/theory/ocean.md,
"Radiation from a BEM code").

For a body heaving with velocity ``x'`` the linear radiation force is Cummins' (1962)

    F_r(t) = -A_inf x'' - int_0^t K(t - s) x'(s) ds,

whose kernel has the transform ``K(i w) = B(w) + i w (A(w) - A_inf)``, with ``A(w)`` and
``B(w)`` the added mass and damping that :func:`heave_coefficients` gets from Capytaine and
``A_inf`` their infinite-frequency limit. :func:`fit_radiation` approximates ``K(i w)`` by a
strictly proper rational function of order n, ``c (sI - A)^-1 b`` (Sanathanan-Koerner
iterations of linear least squares on the frequency samples, unstable poles reflected), so that
the memory becomes the linear system ``z' = A z + b x'``, ``F = -c . z`` (Perez and Fossen 2008).
:func:`add_heave_radiation` puts it into a model: ``A_inf`` joins the body's added mass, and the
states are the velocities of auxiliary particles of mass ``mu`` whose equations
``mu z' = mu (A z + b x')`` and the force ``-c . z`` on the body make one linear velocity
coupling (``System.add_damping_matrix``). The wave excitation (Froude-Krylov and diffraction,
``X(w)``) is an applied force: :func:`excitation_law`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from vinculo.errors import InvalidInputError

__all__ = ["HeaveCoefficients", "RadiationModel", "add_heave_radiation", "excitation_law",
           "fit_radiation", "heave_coefficients", "response"]


@dataclass(frozen=True)
class HeaveCoefficients:
    """Heave hydrodynamic coefficients of a body from Capytaine.

    Arguments:
        omegas: angular frequencies (rad/s).
        added_mass: A(w) (kg).
        damping: B(w) (N s/m).
        excitation: X(w), the complex heave force per metre of wave amplitude (N/m), with
            Capytaine's convention: the force is Re(X a e^{-i w t}) for the elevation
            a cos(w t) at the body's origin.
        added_mass_infinite: A_inf (kg).
        stiffness: the hydrostatic heave stiffness rho g A_wp (N/m).
    """

    omegas: np.ndarray
    added_mass: np.ndarray
    damping: np.ndarray
    excitation: np.ndarray
    added_mass_infinite: float
    stiffness: float


def heave_coefficients(radius: float, draft: float, omegas: Any, *, depth: float = math.inf,
                       density: float = 1025.0, g: float = 9.80665,
                       resolution: tuple[int, int, int] = (4, 24, 12)) -> HeaveCoefficients:
    """A(w), B(w), X(w) and A_inf of a floating vertical cylinder in heave, from Capytaine.

    Arguments:
        radius: its radius (m).
        draft: its draft (m).
        omegas: the angular frequencies (rad/s, > 0).
        depth: the water depth (m; inf: deep water).
        density: water density (kg/m^3).
        g: gravity (m/s^2).
        resolution: Capytaine's mesh resolution (radial, angular, vertical panels) of the
            cylinder from -draft to +draft, of which the immersed half is kept; a lid on the
            waterplane removes the irregular frequencies.

    Returns:
        The coefficients.

    Raises:
        InvalidInputError: Capytaine is not installed, or a bad value.
    """
    try:
        import capytaine as cpt
    except ImportError as e:  # pragma: no cover - a dependency of the test set-up
        raise InvalidInputError("the BEM option needs Capytaine: pip install capytaine",
                                name="capytaine", value=None) from e
    import logging

    logging.getLogger("capytaine").setLevel(logging.WARNING)
    omegas = np.asarray(omegas, dtype=float)
    if not (radius > 0 and draft > 0 and np.all(omegas > 0)):
        raise InvalidInputError(f"radius {radius}, draft {draft}, omegas from {omegas.min()}: "
                                "give positive values", name="omegas", value=omegas.min())
    mesh = cpt.mesh_vertical_cylinder(length=2 * draft, radius=radius, center=(0, 0, 0),
                                      resolution=resolution).immersed_part()
    centre = (0.0, 0.0, -draft / 2)
    # A lid on the waterplane removes the irregular frequencies of the hull's interior.
    body = cpt.FloatingBody(mesh=mesh, lid_mesh=mesh.generate_lid(),
                            dofs=cpt.rigid_body_dofs(rotation_center=centre),
                            center_of_mass=centre).with_only_dofs(["Heave"])
    problems = [cpt.RadiationProblem(body=body, radiating_dof="Heave", omega=w,
                                     water_depth=depth, rho=density, g=g) for w in omegas]
    problems += [cpt.DiffractionProblem(body=body, wave_direction=0.0, omega=w,
                                        water_depth=depth, rho=density, g=g) for w in omegas]
    problems.append(cpt.RadiationProblem(body=body, radiating_dof="Heave", omega=np.inf,
                                         water_depth=depth, rho=density, g=g))
    solver = cpt.BEMSolver()
    results = solver.solve_all(problems, progress_bar=False)
    data = cpt.assemble_dataset(results[:-1])
    pair = {"radiating_dof": "Heave", "influenced_dof": "Heave"}
    excitation = (data["diffraction_force"] + data["Froude_Krylov_force"]).sel(
        influenced_dof="Heave").values.ravel()
    return HeaveCoefficients(
        omegas=omegas, added_mass=data["added_mass"].sel(**pair).values.ravel(),
        damping=data["radiation_damping"].sel(**pair).values.ravel(),
        excitation=np.asarray(excitation, dtype=complex),
        added_mass_infinite=float(results[-1].added_masses["Heave"]),
        stiffness=density * g * math.pi * radius**2)


@dataclass(frozen=True)
class RadiationModel:
    """The radiation memory as a linear system z' = A z + b x', F = -c . z.

    Arguments:
        a: A (n, n) (1/s).
        b: b (n,).
        c: c (n,) (N s/m per state unit).
        added_mass_infinite: A_inf (kg).
        fit_error: the largest |K_fit(i w) - K(i w)| over the samples, relative to max |K|.
    """

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    added_mass_infinite: float
    fit_error: float

    def kernel(self, omegas: Any) -> np.ndarray:
        """The model's K(i w) = c (i w I - A)^-1 b.

        Arguments:
            omegas: angular frequencies (rad/s).

        Returns:
            K at each.
        """
        n = len(self.b)
        return np.array([self.c @ np.linalg.solve(1j * w * np.eye(n) - self.a, self.b)
                         for w in np.atleast_1d(omegas)])

    def coefficients(self, omegas: Any) -> tuple[np.ndarray, np.ndarray]:
        """The added mass and damping the model gives: B = Re K, A = A_inf + Im K / w.

        Arguments:
            omegas: angular frequencies (rad/s).

        Returns:
            (A(w), B(w)).
        """
        w = np.atleast_1d(np.asarray(omegas, dtype=float))
        k = self.kernel(w)
        return self.added_mass_infinite + k.imag / w, k.real


def fit_radiation(coefficients: HeaveCoefficients, order: int = 4,
                  iterations: int = 20) -> RadiationModel:
    """Fit the radiation kernel's transform K(i w) = B + i w (A - A_inf) by a strictly proper
    rational function of ``order`` with a zero at s = 0 (K(0) = 0), by Sanathanan-Koerner
    iterations: linear least squares on P(i w) - K(i w) Q(i w) = 0 weighted by the last
    1 / |Q(i w)|, Q monic; unstable poles are reflected into the left half-plane.

    Arguments:
        coefficients: the samples (:func:`heave_coefficients`).
        order: n, the number of states (2 to 8).
        iterations: the Sanathanan-Koerner iterations.

    Returns:
        The state-space model (controllable canonical form).
    """
    if not 2 <= order <= 8:
        raise InvalidInputError(f"order = {order}: give 2 to 8", name="order", value=order)
    w = coefficients.omegas
    k = coefficients.damping + 1j * w * (coefficients.added_mass
                                         - coefficients.added_mass_infinite)
    s = 1j * w
    n = order
    weight = np.ones_like(w)
    scale = float(np.max(np.abs(w)))
    sn = s / scale  # frequencies scaled to order one for the conditioning
    for _ in range(iterations):
        # Unknowns: p_1 .. p_{n-1} (P = sum p_j s^j, p_0 = 0) and q_0 .. q_{n-1}.
        columns = [sn**j for j in range(1, n)] + [-k * sn**j for j in range(n)]
        rows = np.column_stack(columns) * weight[:, None]
        rhs = k * sn**n * weight
        real = np.vstack([rows.real, rows.imag])
        x, *_ = np.linalg.lstsq(real, np.concatenate([rhs.real, rhs.imag]), rcond=None)
        p = np.concatenate([[0.0], x[: n - 1]])
        q = np.concatenate([x[n - 1:], [1.0]])
        weight = 1.0 / np.abs(np.polyval(q[::-1], sn))
    poles = np.roots(q[::-1])
    poles = np.where(poles.real > 0, -poles.real + 1j * poles.imag, poles)
    q = np.real(np.poly(poles))[::-1]  # monic, ascending
    # P again for the reflected poles (linear least squares).
    columns = [sn**j for j in range(1, n)]
    qv = np.polyval(q[::-1], sn)
    rows = np.column_stack(columns)
    rhs = k * qv
    x, *_ = np.linalg.lstsq(np.vstack([rows.real, rows.imag]),
                            np.concatenate([rhs.real, rhs.imag]), rcond=None)
    p = np.concatenate([[0.0], x])
    # Controllable canonical form in the scaled variable s' = s / scale: z' = scale A' z + ...
    a = np.zeros((n, n))
    a[:-1, 1:] = np.eye(n - 1)
    a[-1, :] = -q[:n]
    b = np.zeros(n)
    b[-1] = 1.0
    model = RadiationModel(a=scale * a, b=scale * b, c=p.copy(),
                           added_mass_infinite=coefficients.added_mass_infinite,
                           fit_error=0.0)
    error = float(np.max(np.abs(model.kernel(w) - k)) / np.max(np.abs(k)))
    return dataclasses.replace(model, fit_error=error)


def add_heave_radiation(system: Any, body: dict[str, Any], model: RadiationModel,
                        state_mass: float = 1.0) -> Any:
    """Put the radiation memory into a model: auxiliary particles whose velocities are the
    states, and one linear velocity coupling over them and the body's centre. The body's
    A_inf is not added here: give it to ``System.add_floating_body(..., added_mass=)``.

    Arguments:
        system: the :class:`vinculo.System`.
        body: the rigid body (``add_rigid_body``'s dict, with a centre particle).
        model: the state-space model (:func:`fit_radiation`).
        state_mass: mu, the auxiliary particles' mass (any positive value: it scales their
            rows).

    Returns:
        The coupling's handle.
    """
    n = len(model.b)
    count = (n + 2) // 3
    gravity = np.asarray(system.gravity, dtype=float)
    centre = body["centre"]
    far = np.asarray(system.initial_positions())[centre.index] + np.array([0.0, 0.0, -1e3])
    states = []
    for k in range(count):
        spot = far + np.array([float(k), 0.0, 0.0])
        particle = system.add_particle(state_mass, tuple(float(c) for c in spot))
        system.add_force(particle, tuple(float(c) for c in -state_mass * gravity))
        states.append(particle)
    size = 3 * (1 + count)
    d = np.zeros((size, size))
    heave = 2  # the centre's z velocity
    for i in range(n):
        row = 3 + i
        d[heave, row] = model.c[i]  # f_z = -c . z
        d[row, 3:3 + n] = -state_mass * model.a[i]  # f_i = mu (A z + b x')_i
        d[row, heave] = -state_mass * model.b[i]
    return system.add_damping_matrix([centre, *states], d)


def excitation_law(coefficients: HeaveCoefficients, omega: float, amplitude: float,
                   t_end: float, ramp: float = 0.0, dt: float = 0.01) -> Any:
    """The heave excitation of regular waves of amplitude ``amplitude`` and frequency
    ``omega``, ``s(t) Re(X a e^{-i w t})`` with X interpolated at ``omega`` and the ramp
    ``s = (1 - cos(pi t / ramp)) / 2`` up to ``ramp``: a tabulated law for
    ``System.add_force``.

    Arguments:
        coefficients: the coefficients.
        omega: the wave frequency (rad/s).
        amplitude: the wave amplitude (m).
        t_end: the law's end (s).
        ramp: the ramp time (s).
        dt: the table's spacing (s).

    Returns:
        The law (N), vertical component.
    """
    from vinculo import laws

    x = complex(np.interp(omega, coefficients.omegas, coefficients.excitation.real)
                + 1j * np.interp(omega, coefficients.omegas, coefficients.excitation.imag))
    t = np.arange(0.0, t_end + dt, dt)
    s = np.where(t < ramp, 0.5 * (1 - np.cos(np.pi * t / max(ramp, 1e-300))), 1.0)
    force = s * amplitude * (x * np.exp(-1j * omega * t)).real
    return laws.tabulated(t, force)


def response(coefficients: HeaveCoefficients, mass: float) -> np.ndarray:
    """Capytaine's frequency-domain heave response per metre of wave amplitude,
    ``X / (C - (m + A) w^2 - i w B)`` (complex, at the coefficients' frequencies).

    Arguments:
        coefficients: the coefficients.
        mass: the body's mass (kg).

    Returns:
        The complex response (m/m).
    """
    w = coefficients.omegas
    return coefficients.excitation / (coefficients.stiffness
                                      - (mass + coefficients.added_mass) * w**2
                                      - 1j * w * coefficients.damping)
