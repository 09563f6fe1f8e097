"""The work-precision comparison of vinculo and MoorDyn (vinculo.mooring.work_precision): each
code's errors against its own small-step reference fall with the step at the order of its
scheme, and the equal-accuracy match takes vinculo's cheapest point at least as accurate."""

import math

import numpy as np
import pytest

from vinculo.errors import InvalidInputError
from vinculo.mooring import work_precision as wp

pytest.importorskip("moordyn")


def _order(points, attribute):
    """The least-squares slope of log(error) against log(step)."""
    steps = np.log([p.step for p in points])
    errors = np.log([getattr(p, attribute) for p in points])
    return float(np.polyfit(steps, errors, 1)[0])


@pytest.fixture(scope="module")
def hanging():
    # The benchmark's hanging chain at 20 segments, 10 s (a one-period smooth start): vinculo
    # at steps that divide the 0.1 s output interval (no interpolation between steps).
    return wp.work_precision("hanging", 20, 10.0, steps=(0.1, 0.05, 0.02, 0.01, 0.005))


def test_vinculo_converges_at_second_order(hanging):
    # Reference: the trapezoidal rule is second order (its local error is h^3 x''' / 12); the
    # index-3 multipliers (the tensions) keep that order on a smooth motion. Measured 1.71
    # (2.7e-4 at 0.1 s, 1.3e-6 at 0.005 s; the slopes between neighbouring steps scatter from
    # 1.4 to 2.2, the largest difference over time falling at different times); a first-order
    # error would give 1.
    own = [p for p in hanging if p.code == "vinculo"]
    assert len(own) == 5
    assert 1.5 <= _order(own, "error") <= 2.5


def test_moordyn_is_first_order_with_a_moving_fairlead(hanging):
    # Reference: MoorDyn's RK2 is second order, but a coupled point moves at the constant
    # velocity it is given through each step (MoorDyn's Step; here the chord of the motion
    # over the step, which is the motion's velocity at the step's middle): at the step's start,
    # where RK2 evaluates its first stage, the fairlead's velocity is off by a dt / 2, and the
    # axial damping of the segments puts that O(dt) error into the forces of every step, so
    # the tensions are first order at both ends. Measured 1.08 and 1.07 (anchor 2.1e-5 and
    # fairlead 1.4e-4 at 0.9 of the largest stable step, 2.1 ms).
    own = [p for p in hanging if p.code == "moordyn"]
    assert len(own) == wp.MOORDYN_HALVINGS + 1 and own[0].largest_stable
    assert 0.8 <= _order(own, "error_end_a") <= 1.3
    assert 0.8 <= _order(own, "error_end_b") <= 1.3
    # Every MoorDyn step divides the output interval (0.1 s), so each output time ends a step.
    for p in own:
        assert 0.1 / p.step == pytest.approx(round(0.1 / p.step), rel=1e-9)


def test_the_equal_accuracy_match_is_the_cheapest_point_at_least_as_accurate():
    # Reference: the definition (module documentation), on points made for the test.
    def point(code, step, cpu, error):
        return wp.WorkPoint("hanging", 20, code, step, cpu, error, error, error)

    md = point("moordyn", 0.002, 1.0, 1e-3)
    fast_loose = point("vinculo", 0.2, 0.01, 2e-3)   # cheaper, not accurate enough
    slow = point("vinculo", 0.01, 0.5, 1e-6)          # accurate, dear
    cheap = point("vinculo", 0.1, 0.05, 9e-4)         # the match
    [match] = wp.equal_accuracy([md, fast_loose, slow, cheap])
    assert match.vinculo is cheap and match.ratio == pytest.approx(20.0)
    [none] = wp.equal_accuracy([md, fast_loose])
    assert none.vinculo is None and math.isnan(none.ratio)


def test_the_outputs(hanging, tmp_path):
    table = wp.table(hanging)
    assert table.count("\n| hanging | 20 |") == wp.MOORDYN_HALVINGS + 1
    assert "(largest)" in table
    csv = wp.write_points(hanging, tmp_path / "wp.csv").read_text().splitlines()
    assert csv[0].startswith("case,segments,code,step,cpu_time,error,error_end_a,error_end_b")
    assert len(csv) == len(hanging) + 1
    image = wp.plot(hanging, tmp_path / "wp.png")
    assert image.stat().st_size > 10_000


def test_bad_arguments():
    with pytest.raises(InvalidInputError, match="case 'sea'"):
        wp.work_precision("sea", 20, 10.0)
    with pytest.raises(InvalidInputError, match="segments 0"):
        wp.work_precision("hanging", 0, 10.0)


def test_the_front_is_the_points_no_other_beats_in_both_cpu_and_error():
    # Reference: the definition (a point is on the front when no other point is both cheaper
    # and more accurate), on points made for the test.
    def point(cpu, error):
        return wp.WorkPoint("chain", 20, "vinculo", 0.01, cpu, error, error, error)

    a, b, c, d = point(1.0, 1e-6), point(0.5, 1e-4), point(0.6, 1e-3), point(0.1, 1e-2)
    # c costs more than b and is less accurate: beaten.
    assert wp.pareto_front([c, d, a, b]) == [a, b, d]
