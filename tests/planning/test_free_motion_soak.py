"""Soak (``make soak``): many seeded start/goal pairs per arm, every returned motion re-checked
independently with Pinocchio + coal at ≤ 0.5° joint steps; pose goals; determinism."""

from __future__ import annotations

import numpy as np
import pytest
from free_motion_cells import colliding_pairs, panda_cell, ur5_cell
from independent import Recheck, obstacles_of

from kinplan.planning import free_motion

pytestmark = pytest.mark.slow


@pytest.mark.parametrize(("name", "count", "least"), [("ur5", 40, 39), ("panda", 30, 28)])
def test_many_pairs_are_solved_and_none_collides(name, count, least):
    cell = ur5_cell() if name == "ur5" else panda_cell()
    recheck = Recheck(cell.robot, obstacles_of(cell), str(cell.srdf_path))
    solved = 0
    for k, (start, goal) in enumerate(colliding_pairs(cell, count, seed=100)):
        plan = free_motion(cell.robot, start, goal, cell, seed=k, time_limit=2.0)
        if not plan.ok:
            assert plan.status == "no_path", plan.summary()
            continue
        solved += 1
        np.testing.assert_allclose(plan.q[0], start, atol=1e-12)
        np.testing.assert_allclose(plan.q[-1], goal, atol=1e-12)
        assert recheck.motion(plan.trajectory) == [], (k, plan.summary())
    assert solved >= least


def test_pose_goals_are_reached_without_collision():
    cell = ur5_cell()
    robot = cell.robot
    recheck = Recheck(robot, obstacles_of(cell), str(cell.srdf_path))
    rng = np.random.default_rng(7)
    pairs = colliding_pairs(cell, 10, seed=101)
    for k, (start, goal) in enumerate(pairs):
        target = robot.fk(goal)
        plan = free_motion(robot, start, target, cell, seed=int(rng.integers(1000)))
        assert plan.ok, plan.summary()
        end = plan.q[-1]
        np.testing.assert_allclose(robot.fk(end).translation, target.translation, atol=1e-6)
        assert recheck.motion(plan.trajectory) == [], k


def test_clearance_soak():
    cell = ur5_cell()
    recheck = Recheck(cell.robot, obstacles_of(cell), str(cell.srdf_path))
    for k, (start, goal) in enumerate(colliding_pairs(cell, 10, seed=102, clearance=0.015)):
        plan = free_motion(cell.robot, start, goal, cell, seed=k, clearance=0.015, time_limit=3)
        if plan.ok:
            assert recheck.motion(plan.trajectory, clearance=0.015 - 1e-6) == [], k


def test_every_seed_is_deterministic():
    cell = ur5_cell()
    for k, (start, goal) in enumerate(colliding_pairs(cell, 5, seed=103)):
        first = free_motion(cell.robot, start, goal, cell, seed=k, time_limit=5.0)
        again = free_motion(cell.robot, start, goal, cell, seed=k, time_limit=5.0)
        np.testing.assert_array_equal(first.waypoints, again.waypoints)
        np.testing.assert_array_equal(first.q, again.q)
