"""A refusal whose path is out of reach ahead says so (cartesian.geometry.unreachable_stretch).

Independent answers: the lecture's annulus of a planar 2R arm (r_min = |l1 - l2|), and the UR
family's wrist condition from its closed-form derivation (Hawkins, "Analytic inverse kinematics
for the Universal Robots UR-5/UR-10 arms", 2013): the wrist point p05 = p06 - d6 z6 must lie at
least d4 from the base axis, so a tool pointing straight down (z6 = -z0) cannot come within
d4 = 0.10915 m (UR5 data sheet) of that axis.
"""

from __future__ import annotations

import numpy as np
import pytest

import cartesian
import kinplan
from cartesian.geometry import unreachable_stretch

UR5_D4 = 0.10915  # [m], Universal Robots' DH parameters of the UR5
DOWN = np.diag([1.0, -1.0, -1.0])  # tool z along the world's -z
GRID = 0.005  # unreachable_stretch's default spacing [m]


@pytest.fixture(scope="module")
def ur5():
    return kinplan.load_robot("ur5")


@pytest.fixture(scope="module")
def short_forearm():
    return kinplan.planar_arm([1.0, 0.25])


def _posed_line(start, end) -> cartesian.Path:
    import pinocchio as pin

    return cartesian.Line(pin.SE3(DOWN, np.asarray(start)), pin.SE3(DOWN, np.asarray(end)))


def test_the_hole_of_the_short_forearm_is_where_the_lecture_puts_it(short_forearm):
    line = cartesian.Line([0.8, 0.6, 0.0], [-0.8, 0.6, 0.0])
    stretch = unreachable_stretch(short_forearm, line, True)
    x_in = np.sqrt(0.75**2 - 0.6**2)  # the line enters r < 0.75 m at |x| = 0.45 m
    s_in, s_out = (0.8 - x_in) / 1.6, (0.8 + x_in) / 1.6
    step = GRID / line.length
    assert s_in <= stretch.start <= s_in + step + 1e-9
    assert s_out - step - 1e-9 <= stretch.end <= s_out
    assert "inside the hole r < 0.7500 m" in stretch.why
    # from a fraction past the hole, nothing is left to find
    assert unreachable_stretch(short_forearm, line, True, start=s_out + step) is None


def test_the_column_above_a_ur5_is_where_its_closed_form_derivation_puts_it(ur5):
    line = _posed_line([0.3, 0.0, 0.3], [-0.3, 0.0, 0.3])
    stretch = unreachable_stretch(ur5, line, False)
    s_in, s_out = (0.3 - UR5_D4) / 0.6, (0.3 + UR5_D4) / 0.6
    step = GRID / line.length
    assert s_in <= stretch.start <= s_in + step + 1e-9
    assert s_out - step - 1e-9 <= stretch.end <= s_out
    assert np.hypot(*stretch.position[:2]) < UR5_D4
    assert "on any branch" in stretch.why


def test_random_ur5_lines_are_out_of_reach_exactly_when_they_cross_the_column(ur5):
    """300 seeded lines with the tool pointing down, 0.15–0.55 m from the base axis at both
    ends: a stretch is found exactly when the segment passes within d4 of the axis (lines
    within 2 mm of d4 either way are left out: the grid decides those)."""
    rng = np.random.default_rng(20261202)
    crossing = clear = 0
    for _ in range(300):
        z = rng.uniform(0.1, 0.5)
        ends = []
        for _end in range(2):
            angle, radius = rng.uniform(-np.pi, np.pi), rng.uniform(0.15, 0.55)
            ends.append(np.array([radius * np.cos(angle), radius * np.sin(angle), z]))
        a, b = ends
        u = np.clip(-a[:2] @ (b - a)[:2] / np.sum((b - a)[:2] ** 2), 0.0, 1.0)
        closest = np.linalg.norm((a + u * (b - a))[:2])
        if abs(closest - UR5_D4) < 0.002:
            continue
        stretch = unreachable_stretch(ur5, _posed_line(a, b), False)
        if closest < UR5_D4:
            crossing += 1
            assert stretch is not None, (a, b, closest)
            assert np.hypot(*stretch.position[:2]) < UR5_D4 + 1e-9
        else:
            clear += 1
            assert stretch is None, (a, b, closest, stretch)
    assert crossing > 40 and clear > 100  # both kinds well represented


def test_a_redundant_arm_is_never_called_out_of_reach(ur5):
    """The panda's closed form fixes joint 7: its "no solution" proves nothing."""
    panda = kinplan.load_robot("panda")
    far = _posed_line([0.3, 0.0, 0.3], [2.0, 0.0, 0.3])  # beyond its reach, but unproven
    assert unreachable_stretch(panda, far, False) is None
    assert unreachable_stretch(ur5, _posed_line([0.3, 0.0, 0.3], [0.9, 0.5, 0.3]), True) is None


def test_follow_says_the_hole_is_out_of_reach_instead_of_offering_a_slower_law(short_forearm):
    line = cartesian.Line([0.8, 0.6, 0.0], [-0.8, 0.6, 0.0])
    plan = cartesian.follow(short_forearm, line, duration=2.0, q_seed=[0.0, 0.5])
    assert plan.status == "velocity_limit"
    assert plan.out_of_reach is not None and plan.slowdown is None
    remedy = plan.events[0].remedy
    assert remedy.startswith("the path is out of reach from s = 0.2") and "slower" in remedy
    assert "slow the tool down" not in remedy and "retime" not in remedy
    # the remedy is true: ten times slower still fails, in the same place
    slower = cartesian.follow(short_forearm, line, duration=20.0, q_seed=[0.0, 0.5])
    assert not slower.ok and slower.fraction < plan.out_of_reach.start


def test_follow_keeps_the_slower_remedy_where_the_path_is_reachable(short_forearm):
    line = cartesian.Line([1.2, 0.0, 0.0], [0.0, 1.2, 0.0])  # outside the hole, all of it
    plan = cartesian.follow(short_forearm, line, duration=0.05, q_seed=[0.0, 0.5])
    assert plan.status == "velocity_limit" and plan.out_of_reach is None
    assert plan.events[0].remedy.startswith("slow the tool down by a factor of at least")


def test_the_ur5_demo_program_says_the_seam_is_out_of_reach():
    from pathlib import Path

    from kinplan.program import load_program, plan_program

    program = Path(__file__).parents[2] / "examples" / "programs" / "weld_unreachable.yaml"
    plan = plan_program(load_program(program))
    assert not plan.ok and plan.moves_done == 2
    assert "the path is out of reach from s = 0.3" in plan.reason
    assert "no start configuration, branch or slower motion can follow it" in plan.reason
