"""The linear solver is chosen from the constraint graph, and the Solution says which."""

import vinculo


def _chain(n, close_loop=False):
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    prev = system.add_particle(mass=1.0, position=(0.0, 0.0, 0.0), fixed=True)
    first = None
    for i in range(1, n + 1):
        p = system.add_particle(mass=0.1, position=(0.0, 0.0, -0.1 * i))
        system.add_distance(prev, p, length=0.1)
        first = first or p
        prev = p
    if close_loop:
        system.add_spring_damper(first, prev, stiffness=10.0)
    return system


def _fork(n):
    """Two legs of ``n`` beads from a hub held at the origin, their ends joined by a spring: a
    loop across two branches of the tree (the legs' ends are cousins)."""
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    hub = system.add_particle(mass=1.0, position=(0.0, 0.0, 0.0))
    for axis in range(3):
        system.add_fixed_coordinate(hub, axis)
    ends = []
    for side in (-1.0, 1.0):
        prev = hub
        for i in range(1, n + 1):
            p = system.add_particle(mass=0.1, position=(0.05 * side * i, 0.0, -0.1 * i))
            system.add_distance(prev, p)
            prev = p
        ends.append(prev)
    system.add_spring_damper(ends[0], ends[1], stiffness=10.0)
    return system


def _triangle():
    """Three free particles held at each other's distances: a loop of constraints."""
    system = vinculo.System(gravity=(0.0, 0.0, -9.81))
    corners = [system.add_particle(mass=1.0, position=x)
               for x in ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0))]
    for k in range(3):
        system.add_distance(corners[k], corners[(k + 1) % 3])
    return system


def test_each_graph_gets_its_solver_and_the_summary_names_it():
    cases = [
        (_chain(1), "tree elimination"),  # a pendulum is a tree too (3x faster than dense LU)
        (_chain(30), "tree elimination"),  # 120 unknowns, a chain: linear-cost elimination
        # A spring from the first bead to the last couples a bead with an ancestor in the tree:
        # the elimination takes it (each bead is then coupled with its parent and the first).
        (_chain(30, close_loop=True), "tree elimination"),
        (_triangle(), "dense LU"),  # a small loop: 12 unknowns, dense LU
        (_fork(15), "sparse LU"),  # a loop across branches, 126 unknowns
    ]
    for system, expected in cases:
        solution = vinculo.simulate(system, t_end=0.01, dt=1e-3)
        assert solution.success
        assert solution.linear_solver == expected
        assert f"linear solver: {expected}" in solution.summary()
