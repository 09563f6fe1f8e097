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


def test_each_graph_gets_its_solver_and_the_summary_names_it():
    cases = [
        (_chain(1), "tree elimination"),  # a pendulum is a tree too (3x faster than dense LU)
        (_chain(30), "tree elimination"),  # 120 unknowns, a chain: linear-cost elimination
        (_chain(3, close_loop=True), "dense LU"),  # a small loop: 12 unknowns, dense LU
        (_chain(30, close_loop=True), "sparse LU"),  # a spring closes a loop
    ]
    for system, expected in cases:
        solution = vinculo.simulate(system, t_end=0.01, dt=1e-3)
        assert solution.success
        assert solution.linear_solver == expected
        assert f"linear solver: {expected}" in solution.summary()
