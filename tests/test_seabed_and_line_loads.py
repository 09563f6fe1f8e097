"""Seabed contact, friction and line hydrodynamics from Python, against closed forms
(MoorDyn's conventions, docs/theory/seabed-and-line-loads.md), and their typed errors."""

import itertools
import math

import numpy as np
import pytest

import vinculo
from vinculo.errors import InvalidInputError, UnknownHandleError

G = 9.80665
RHO = 1025.0
DEPTH = 20.0


def chain_on_seabed(segments: int, friction: float):
    """A chain of `segments` rigid links (1 m, 0.1 m diameter, 30 kg/m) laid 0.2 m above the
    seabed between two fixed anchors 0.5 m lower, with buoyancy, drag and seabed contact at every
    node (MoorDyn's node lengths: half a segment at the ends)."""
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    d, length, w = 0.1, 1.0, 30.0
    x = np.linspace(0.0, segments * length, segments + 1)
    nodes = []
    for k, xk in enumerate(x):
        end = k in (0, segments)
        z = -DEPTH - 0.3 if end else -DEPTH + 0.2
        node_length = 0.5 * length if end else length
        nodes.append(system.add_particle(w * node_length, (xk, 0.0, z), fixed=end))
    for a, b in itertools.pairwise(nodes):
        system.add_distance(a, b, None)
    for k in range(1, segments):
        tangent = (nodes[k - 1], nodes[k + 1])
        system.add_line_hydrodynamics(
            nodes[k], diameter=d, length=length, cd=1.2, cdax=0.05, ca=1.0, tangent=tangent
        )
        system.add_seabed_contact(
            nodes[k], depth=DEPTH, diameter=d, length=length, tangent=tangent, friction=friction
        )
    return system, nodes, (w - RHO * math.pi * d * d / 4) * G


def test_chain_settles_on_the_seabed_at_its_contact_penetration():
    # A chain dropped onto the seabed lies on it, each interior node sunk by the penetration
    # that carries its submerged weight: p = w l / (kBot d l) (MoorDyn's normal force
    # kBot p d l), up to the links' sag between the nodes (the chain is slightly longer than
    # the straight distance, and gravity pulls every node down alike: they share p).
    system, nodes, weight = chain_on_seabed(10, friction=0.5)
    solution = vinculo.simulate(system, 4.0, 5e-3)
    z = solution.particle(nodes[5])[-1, 2]
    expected = weight / (3.0e6 * 0.1)
    assert -DEPTH - z == pytest.approx(expected, rel=1e-3)
    # The middle of the chain is at rest. (The two nodes next to each anchor hang from it and
    # still swing, damped by the water alone; the touchdown nodes creep at a few um/s: MoorDyn's
    # friction is viscous, slope mu FricDamp, below its Coulomb limit, so a steady pull creeps.)
    speeds = [np.linalg.norm(solution.particle_velocity(n)[-1]) for n in nodes[4:-4]]
    assert max(speeds) < 1e-7


def test_tangent_defaults_and_bad_values_raise_typed_errors():
    system = vinculo.System(gravity=(0.0, 0.0, -G))
    a = system.add_particle(1.0, (0.0, 0.0, -DEPTH), fixed=True)
    n = system.add_particle(1.0, (1.0, 0.0, -DEPTH))
    with pytest.raises(InvalidInputError, match="diameter"):
        system.add_seabed_contact(n, depth=DEPTH, diameter=0.0, length=1.0)
    with pytest.raises(InvalidInputError, match="kBot"):
        system.add_seabed_contact(n, depth=DEPTH, diameter=0.1, length=1.0, kbot=-1.0)
    with pytest.raises(InvalidInputError, match="static/dynamic"):
        system.add_seabed_contact(
            n, depth=DEPTH, diameter=0.1, length=1.0, friction=0.3, static_dynamic_scale=0.5
        )
    with pytest.raises(InvalidInputError, match="tangent"):
        system.add_seabed_contact(n, depth=DEPTH, diameter=0.1, length=1.0, tangent=(a, a))
    with pytest.raises(InvalidInputError, match="tangent"):
        system.add_line_hydrodynamics(n, diameter=0.1, length=1.0, tangent=(a,))
    with pytest.raises(InvalidInputError, match="CdAx"):
        system.add_line_hydrodynamics(n, diameter=0.1, length=1.0, cdax=float("nan"))
    other = vinculo.System().add_particle(1.0, (0.0, 0.0, 0.0))
    with pytest.raises(UnknownHandleError):
        system.add_seabed_contact(n, depth=DEPTH, diameter=0.1, length=1.0, tangent=(a, other))
