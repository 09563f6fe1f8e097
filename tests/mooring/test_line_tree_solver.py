"""A mooring line with bending stiffness is solved by the tree elimination.

The bending of a line at node i couples nodes i - 1 and i + 1, which in the tree of the line's
segments are a node and its grandparent: the tree elimination takes such couplings to ancestors
(``crates/vinculo/src/linear/tree_elimination.rs``), where it used to hand the line to the
general sparse LU. The reference is the same run with the general sparse LU
(``linear_solver="sparse-lu"``: partial pivoting across the whole matrix, faer). Both runs solve
Newton to its round-off floor (a tolerance of 1e-13 of the length scale, a fresh matrix at every
iteration), so that the two solutions differ only by the linear solves' round-off. The end
tensions follow from the positions by Hooke's law, EA / l times the stretch, so one round-off of
a coordinate (2.2e-16 of about 15 m) moves them by EA / l x 3.3e-15 m, 3e-10 of the cable's
tension (EA = 5e8 N, l = 1.5 m, T = 4000 N). Each step starts from the state the last one left,
round-off included, so the two runs' differences add up over the 40 steps as a random walk
(about sqrt(40) = 6 round-offs, 2e-9): measured, the runs differ by 1.1e-9 of the tension at
most (6e-10 in the median step; 3e-11 for the chain), within the 2e-9 asked; a wrong solve
would differ by orders of magnitude more.
"""

import numpy as np
import pytest

import vinculo
from vinculo.mooring.analysis import run
from vinculo.mooring.bench import bending_line, hanging_line, motion_for


def _run(model, linear_solver):
    return run(model, motion_for(model), 2.0, dt=0.05, plots=False, jacobian_reuse=False,
               tolerance=1e-13, linear_solver=linear_solver)


@pytest.mark.parametrize("case", [bending_line, hanging_line])
def test_line_end_tensions_agree_with_the_sparse_lu(case):
    model = case(20)
    tree, lu = _run(model, "auto"), _run(model, "sparse-lu")
    assert tree.solution.linear_solver == "tree elimination"
    assert lu.solution.linear_solver == "sparse LU"
    assert tree.segment_tensions.shape == lu.segment_tensions.shape
    scale = np.abs(lu.segment_tensions).max()
    gap = np.abs(tree.segment_tensions - lu.segment_tensions).max() / scale
    assert gap < 2e-9, gap
    # The fairlead moved the line: the end tensions changed by more than a percent (two runs
    # that stood still would agree trivially).
    change = np.abs(lu.segment_tensions - lu.segment_tensions[0]).max() / scale
    assert change > 1e-2, change


def test_an_unknown_linear_solver_is_refused_by_name():
    system = vinculo.System()
    system.add_particle(1.0, (0.0, 0.0, 0.0))
    with pytest.raises(vinculo.InvalidInputError, match="linear_solver"):
        vinculo.simulate(system, 0.1, 0.01, linear_solver="cholesky")
