"""`cartesian.follow(..., cell=, clearance=)`: plans checked against a work cell (issue 16)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import cartesian
import kinplan

UR5_START = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])


@pytest.fixture(scope="module")
def seam(ur5):
    start = ur5.fk(UR5_START)
    return cartesian.Line(start, pin.SE3(start.rotation, start.translation + [0.0, 0.3, 0.0]))


def _obstacle_distance(cell, q) -> float:
    """Smallest robot–obstacle distance at q [m] (the cell's own pair distances)."""
    return min(p.distance for p in cell.pair_distances(q) if p.kind == "obstacle")


def test_a_wall_across_the_seam_stops_the_plan_at_the_first_colliding_sample(ur5, seam):
    """A thin wall across the line: a collision event naming the link and the wall, at the
    first sample whose configuration collides (checked independently with cell.collisions),
    with every sample before it free; the same motion without the cell is ok."""
    middle = seam.position(np.array([0.5]))[0]
    cell = kinplan.WorkCell(ur5)
    cell.add_box("wall", [0.3, 0.004, 0.4], pin.SE3(np.eye(3), middle))
    assert cartesian.follow(ur5, seam, speed=0.2, q_seed=UR5_START).ok
    plan = cartesian.follow(ur5, seam, speed=0.2, q_seed=UR5_START, cell=cell)
    assert plan.status == "collision", plan
    event = plan.events[0]
    assert "wall" in event.message and event.remedy
    assert all(_obstacle_distance(cell, q) > 0 for q in plan.q)  # the samples kept are free
    assert plan.min_clearance >= -1e-6 or plan.min_clearance == pytest.approx(event.value)
    timing_t = cartesian.follow(ur5, seam, speed=0.2, q_seed=UR5_START).t
    assert event.t == timing_t[event.index] and len(plan.t) == event.index


def test_the_plan_reports_what_the_cell_finds_on_its_samples(ur5, seam):
    """follow's collision event is check_motion's verdict on the same samples (index, bodies,
    at or between samples), for walls crossing the seam at several places (the detection
    between samples itself is tested in test_cell.py with a fin crossed between two samples)."""
    free = cartesian.follow(ur5, seam, speed=0.2, q_seed=UR5_START)
    for s in (0.2, 0.5, 0.8):
        cell = kinplan.WorkCell(ur5)
        where = seam.position(np.array([s]))[0]
        cell.add_box("wall", [0.3, 0.002, 0.4], pin.SE3(np.eye(3), where))
        expected = cell.check_motion(free.q)
        plan = cartesian.follow(ur5, seam, speed=0.2, q_seed=UR5_START, cell=cell)
        assert plan.status == "collision" and expected.index is not None
        event = plan.events[0]
        assert event.index == expected.index and len(plan.q) == expected.index
        assert all(name in event.message for name in expected.bodies)
        assert ("between samples" in event.message) == expected.between


def test_clearance_turns_near_misses_into_failures_and_is_reported(ur5, seam):
    """A ball 3 cm from the motion: ok with its min_clearance reported, a failure with a 5 cm
    clearance margin."""
    free = cartesian.follow(ur5, seam, speed=0.2, q_seed=UR5_START)
    cell = kinplan.WorkCell(ur5)
    ball = seam.position(np.array([0.5]))[0] + [0.0, 0.0, 0.25]
    cell.add_sphere("ball", 0.02, pin.SE3(np.eye(3), ball))
    distances_far = min(_obstacle_distance(cell, q) for q in free.q)
    plan = cartesian.follow(ur5, seam, speed=0.2, q_seed=UR5_START, cell=cell)
    assert plan.ok and plan.min_clearance == pytest.approx(distances_far, abs=1e-6)
    assert np.isfinite(plan.min_self_clearance) and plan.min_self_clearance > 0
    margin = plan.min_clearance + 0.01
    tight = cartesian.follow(ur5, seam, speed=0.2, q_seed=UR5_START, cell=cell, clearance=margin)
    assert tight.status == "collision" and "clearance" in tight.events[0].message


def test_bad_cell_arguments(ur5, seam):
    with pytest.raises(kinplan.InputError, match="cell"):
        cartesian.follow(ur5, seam, speed=0.2, q_seed=UR5_START, cell="table")
    with pytest.raises(kinplan.InputError, match="clearance"):
        cartesian.follow(
            ur5, seam, speed=0.2, q_seed=UR5_START, cell=kinplan.WorkCell(ur5), clearance=-1.0
        )
