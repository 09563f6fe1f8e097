"""A line node's added mass is anisotropic, as MoorDyn's node mass matrix
m I + rho V (Ca (I - t t^T) + CaAx t t^T): the node oscillates along the line with the inertia
m + CaAx rho V and across it with m + Ca rho V (docs/theory/seabed-and-line-loads.md), with
both time rules, on the index-3 and the stabilised index-2 (GGL) formulations."""

import math

import numpy as np
import pytest

import vinculo

RHO = 1025.0
MASS = 5.0  # kg, the node's own mass
D = 0.1  # m, the line's diameter
SPAN = 2.0  # m, from the node to each fixed end
L0 = 1.98  # m, each segment's unstretched length
EA = 1.0e5  # N
CA, CAAX = 1.0, 0.25
RHO_V = RHO * math.pi * D * D / 4.0 * SPAN  # kg: the node stands for one segment of line
TENSION = EA * (SPAN - L0) / L0  # N, Hooke's law in each segment at rest


def taut_node(displacement, springs=False):
    """One free node at the origin between two elastic segments to fixed ends at x = +-SPAN,
    without gravity nor drag, its tangent the x axis (from one end to the other), displaced by
    ``displacement`` from rest. ``springs``: the segments as spring-dampers of the same law
    (stiffness EA/L0, rest length L0, no damping), for the GGL formulation, which runs elastic
    segments on the index-3 one only."""
    system = vinculo.System(gravity=(0.0, 0.0, 0.0))
    a = system.add_particle(1.0, (-SPAN, 0.0, 0.0), fixed=True)
    node = system.add_particle(MASS, tuple(displacement))
    b = system.add_particle(1.0, (SPAN, 0.0, 0.0), fixed=True)
    for p, r in ((a, node), (node, b)):
        if springs:
            system.add_spring_damper(p, r, EA / L0, 0.0, L0)
        else:
            system.add_elastic_distance(p, r, L0, EA)
    system.add_line_hydrodynamics(node, diameter=D, length=SPAN, ca=CA, caax=CAAX, density=RHO,
                                  tangent=(a, b))
    return system, node


def measured_period(times, x):
    """The mean period between the first and the last downward zero crossings of ``x``
    (crossing times by linear interpolation)."""
    k = np.nonzero((x[:-1] > 0.0) & (x[1:] <= 0.0))[0]
    crossings = times[k] + (times[k + 1] - times[k]) * x[k] / (x[k] - x[k + 1])
    assert crossings.size >= 5
    return (crossings[-1] - crossings[0]) / (crossings.size - 1)


SCHEMES = [
    {"scheme": "trapezoidal"},
    {"scheme": "generalized-alpha", "rho_inf": 1.0},
    {"scheme": "trapezoidal", "formulation": "ggl"},
    {"scheme": "generalized-alpha", "rho_inf": 1.0, "formulation": "ggl"},
]


def name(scheme):
    """A test id: the scheme, and the formulation when it is GGL."""
    return "-".join(str(scheme[k]) for k in ("scheme", "formulation") if k in scheme)


@pytest.mark.parametrize("scheme", SCHEMES, ids=name)
def test_axial_period_follows_the_axial_added_mass(scheme):
    # Along x, each segment's tension EA (|d| - L0)/L0 is linear in the node's x while both stay
    # taut, so the restoring force is -(2 EA/L0) x exactly: a spring-mass of stiffness 2 EA/L0
    # and the node's axial inertia m + CaAx rho V, period 2 pi sqrt((m + CaAx rho V) L0/(2 EA)).
    # (With the isotropic added mass Ca rho V it would be 1.48 times longer.)
    period = 2.0 * math.pi * math.sqrt((MASS + CAAX * RHO_V) * L0 / (2.0 * EA))
    system, node = taut_node((1e-3, 0.0, 0.0), springs="formulation" in scheme)
    # 1000 steps per period: the rules' period error (omega h)^2/12 is 3e-6.
    solution = vinculo.simulate(system, 5.5 * period, period / 1000.0, **scheme)
    x = solution.particle(node)[:, 0]
    assert np.abs(solution.particle(node)[:, 1:]).max() < 1e-12  # the motion stays axial
    assert measured_period(solution.times, x) == pytest.approx(period, rel=1e-4)


@pytest.mark.parametrize("scheme", SCHEMES, ids=name)
def test_transverse_period_follows_the_normal_added_mass(scheme):
    # Across the line, a small displacement y tilts both segments by y/SPAN: the restoring force
    # is -(2 T/SPAN) y to first order (the tension's change is second order in y; at y = 1 mm
    # it shifts the period by about 5e-6), so the period is 2 pi sqrt((m + Ca rho V) SPAN/(2 T)).
    period = 2.0 * math.pi * math.sqrt((MASS + CA * RHO_V) * SPAN / (2.0 * TENSION))
    system, node = taut_node((0.0, 1e-3, 0.0), springs="formulation" in scheme)
    solution = vinculo.simulate(system, 5.5 * period, period / 1000.0, **scheme)
    y = solution.particle(node)[:, 1]
    assert measured_period(solution.times, y) == pytest.approx(period, rel=1e-4)
