"""The per-sample loop of Cartesian following, forced: since the fast paths
(:mod:`cartesian.batch_track`, :mod:`cartesian.lean_track`) answer every clean path, the loop of
``cartesian.follow`` and the exact trace of ``cartesian.geometry`` run only for paths with an
event or near one. Here both fast paths are switched off (their ``ENABLED`` flags) and:

* the property tests of clean plans run on the loop: q̈ = dq̇/dt on curved paths and every
  profile, q̇ = J⁺ẋ against differences, the seed's branch, the retimed laws, the peak speed
  ratio, the work cell, the rank floor's scale invariance;
* the loop's plans are the lean loop's to 1e-9 rad (the same predictions — Taylor at the second
  sample, Adams–Bashforth after — and Newton steps) and the exact closed form's within the IK
  noise, on coarse and uneven samplings where Newton corrects most predictions;
* the exact geometric trace is the lean trace: the same points (bisections included) and q.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest
import test_cartesian as basics
import test_follow_monitoring as monitoring
import test_follow_mutants as follow_mutants
import test_tracker_mutants as tracker_mutants
from conftest import cached_robot

import cartesian
import kinplan
from cartesian import batch_track, lean_track
from cartesian.geometry import MAX_JOINT_STEP, trace_geometry
from cartesian.tracker import SINGULAR_FRACTION, Tracker

STARTS = {
    "ur5": np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0]),
    "panda": np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.78]),
    "planar_2r": np.array([0.3, 1.2]),
}


@pytest.fixture
def loop_only(monkeypatch):
    """Both fast paths off: every plan and trace is the loop's."""
    monkeypatch.setattr(batch_track, "ENABLED", False)
    monkeypatch.setattr(lean_track, "ENABLED", False)


# ---------------------------------------------------------------- the properties, on the loop
@pytest.mark.parametrize(
    ("name", "profile"), [("ur5", "quintic"), ("panda", "trapezoid"), ("planar_2r", "cubic")]
)
def test_loop_joint_acceleration_is_the_time_derivative_of_the_rates(loop_only, name, profile):
    monitoring.test_joint_acceleration_is_the_time_derivative_of_the_joint_rates(name, profile)


def test_loop_steps_are_explained_by_their_rates(loop_only, planar_2r):
    monitoring.test_plans_that_pass_keep_every_step_explained_by_their_rates(planar_2r)


def test_loop_joint_rates_match_finite_differences(loop_only, planar_2r):
    basics.test_joint_rates_match_finite_differences(planar_2r)


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_loop_lines_and_arcs_at_fixed_orientation(loop_only, name):
    basics.test_lines_and_arcs_at_fixed_orientation(name)


@pytest.mark.parametrize(
    ("name", "position_only"), [("ur5", False), ("panda", False), ("panda", True)]
)
def test_loop_joint_rates_of_square_and_redundant_arms(loop_only, name, position_only):
    basics.test_joint_rates_of_square_and_redundant_arms(name, position_only)


def test_loop_weld_seam_at_constant_speed(loop_only, ur5):
    basics.test_weld_seam_function_path_at_constant_speed(ur5)


def test_loop_reachability_and_retiming(loop_only, planar_2r, ur5):
    follow_mutants.test_reachability_stays_on_the_seeds_branch(planar_2r)
    follow_mutants.test_reachability_bisects_so_no_checked_step_exceeds_a_tenth_of_a_radian(
        planar_2r
    )
    follow_mutants.test_ur5_reachability_position_only_and_held_orientation(ur5)
    follow_mutants.test_a_3_vector_path_holds_the_seeds_orientation(ur5)
    follow_mutants.test_the_offered_retime_keeps_the_seeds_branch(planar_2r)
    follow_mutants.test_retiming_keeps_the_nominal_path_acceleration_unless_joints_limit_it(
        planar_2r
    )
    follow_mutants.test_peak_speed_ratio_of_a_slow_plan_is_its_margin(planar_2r)
    follow_mutants.test_acceleration_event_names_the_first_sample_over_its_joint_limit(planar_2r)


def test_loop_seed_clearance_and_cells(loop_only, planar_2r, ur5):
    follow_mutants.test_seed_and_clearance_are_used(planar_2r)
    follow_mutants.test_a_cell_built_for_another_robot_is_checked_with_the_planned_one(ur5)


def test_loop_rank_floor_and_mimic_accelerations(loop_only, planar_2r):
    tracker_mutants.test_the_rank_floor_scales_with_the_arm(planar_2r)
    tracker_mutants.test_joint_accelerations_of_an_arm_with_a_mimic_joint()


# ---------------------------------------------------------------------------- loop = lean = exact
def line(robot: kinplan.Robot, q0: np.ndarray, offset) -> cartesian.Line:
    start = robot.fk(q0)
    if robot.nq < 6:
        return cartesian.Line(start.translation, start.translation + np.array(offset))
    return cartesian.Line(start, pin.SE3(start.rotation, start.translation + np.array(offset)))


OFFSETS = {
    "ur5": (0.1, 0.2, -0.1),
    "panda": (0.1, 0.15, -0.1),
    "planar_2r": (-0.6, 0.5, 0.0),
}


def plan_with(robot, path, monkeypatch, batch: bool, lean: bool, **options):
    with monkeypatch.context() as patch:
        patch.setattr(batch_track, "ENABLED", batch)
        patch.setattr(lean_track, "ENABLED", lean)
        return cartesian.follow(robot, path, **options)


@pytest.mark.parametrize(
    ("dt", "profile"), [(0.05, "trapezoid"), (0.013, "quintic"), (0.002, "cubic")]
)
@pytest.mark.parametrize("name", ["ur5", "panda", "planar_2r"])
def test_the_loop_is_the_lean_loop_and_the_closed_form(name, dt, profile, monkeypatch):
    """Coarse (Newton corrects most predictions), uneven (the last step short) and fine
    samplings, with profiles that start with and without a path acceleration (the second
    sample's Taylor prediction uses q̈ = J⁺ẍ at rest): the loop's plan is the lean loop's (q to
    1e-9 rad: the same predictions and Newton steps; q̇, q̈, manipulability, tool positions,
    peak speed ratio alike) and, on the arms with a closed form, the exact one's within the IK
    noise; the tool on the path within the tolerance; the plan's summary figures are those of
    its samples."""
    robot = cached_robot(name)
    q0 = STARTS[name]
    path = line(robot, q0, OFFSETS[name])
    options = {"duration": 1.0, "q_seed": q0, "dt": dt, "profile": profile}
    loop = plan_with(robot, path, monkeypatch, False, False, **options)
    lean = plan_with(robot, path, monkeypatch, False, True, **options)
    assert loop.ok and lean.ok, (loop, lean)
    np.testing.assert_array_equal(loop.t, lean.t)
    np.testing.assert_array_equal(loop.s, lean.s)
    np.testing.assert_allclose(loop.q, lean.q, rtol=0, atol=1e-9)
    np.testing.assert_allclose(loop.qd, lean.qd, rtol=0, atol=1e-8)
    np.testing.assert_allclose(loop.qdd, lean.qdd, rtol=0, atol=1e-6)
    np.testing.assert_allclose(loop.manipulability, lean.manipulability, rtol=1e-9)
    np.testing.assert_allclose(loop.tool_positions, lean.tool_positions, atol=1e-12)
    assert loop.peak_speed_ratio == pytest.approx(lean.peak_speed_ratio, rel=1e-9)
    # the summary figures are those of the samples
    deviation = np.linalg.norm(loop.tool_positions - path.position(loop.s), axis=1)
    assert loop.max_deviation == pytest.approx(deviation.max(), rel=1e-9, abs=1e-15)
    assert loop.max_deviation <= 1e-7
    assert loop.min_manipulability == loop.manipulability.min()
    assert loop.fraction == 1.0 and loop.status == "ok" and not loop.events
    assert loop.duration == pytest.approx(1.0) and loop.t[-1] == pytest.approx(1.0)
    for k in (0, len(loop.t) // 2, len(loop.t) - 1):
        np.testing.assert_allclose(loop.tool_positions[k], robot.fk(loop.q[k]).translation)
    if name != "panda":  # the exact closed form
        exact = plan_with(robot, path, monkeypatch, True, False, **options)
        np.testing.assert_allclose(loop.q, exact.q, rtol=0, atol=2e-5)
        assert exact.max_deviation < 1e-12


@pytest.mark.parametrize("name", ["ur5", "panda", "planar_2r"])
def test_the_exact_trace_is_the_lean_trace(name, monkeypatch):
    """The geometric trace (check_reachability's, and the one retiming makes first) on a
    coarse grid, by the exact trace and by the lean one: the same points, bisected where a
    joint steps more than 0.1 rad, the same q, dq/ds and Jacobians; dq/ds the derivative of q;
    and the retimed plans built on them alike."""
    robot = cached_robot(name)
    q0 = STARTS[name]
    path = line(robot, q0, OFFSETS[name])
    position_only = robot.default_position_only()
    threshold = SINGULAR_FRACTION * robot.reference_manipulability(position_only)
    tracker = Tracker(robot, position_only, 1e-7, 1e-7, threshold, 1.0, 0.1)
    grid = np.linspace(0.0, 1.0, 4)
    with monkeypatch.context() as patch:
        patch.setattr(lean_track, "ENABLED", False)
        exact = trace_geometry(tracker, path, grid, q0)
    lean = trace_geometry(tracker, path, grid, q0)
    assert not exact.events and not lean.events
    np.testing.assert_array_equal(exact.s, lean.s)
    assert len(exact.s) > len(grid)  # bisected
    assert np.abs(np.diff(exact.q, axis=0)).max() <= MAX_JOINT_STEP
    np.testing.assert_allclose(exact.q, lean.q, rtol=0, atol=1e-9)
    np.testing.assert_allclose(exact.dq_ds, lean.dq_ds, rtol=0, atol=1e-8)
    np.testing.assert_allclose(exact.jacobians, lean.jacobians, rtol=0, atol=1e-9)
    mid = 0.5 * (exact.dq_ds[1:] + exact.dq_ds[:-1])
    slope = np.diff(exact.q, axis=0) / np.diff(exact.s)[:, None]
    np.testing.assert_allclose(slope, mid, atol=0.02 * np.abs(mid).max())
    for k in range(0, len(exact.s), 5):
        pose = robot.fk(exact.q[k])
        np.testing.assert_allclose(pose.translation, path.position(exact.s[k : k + 1])[0],
                                   atol=1e-7)  # fmt: skip
    options = {"duration": 0.3, "q_seed": q0, "retime": True}
    loop = plan_with(robot, path, monkeypatch, False, False, **options)
    fast = plan_with(robot, path, monkeypatch, False, True, **options)
    assert loop.ok and loop.retimed and fast.retimed
    np.testing.assert_array_equal(loop.t, fast.t)
    np.testing.assert_allclose(loop.q, fast.q, rtol=0, atol=1e-9)
    assert loop.peak_speed_ratio <= 1.0 + 1e-9


def test_an_uncorrected_prediction_is_not_tested_for_a_jump(planar_2r, monkeypatch):
    """A finely sampled slow path: most predictions meet the tolerance (no Newton step) and
    the loop tests only corrected samples for a jump. With a jump tolerance far below the
    integration error of every step, the first jump is therefore reported only where the
    predictions have drifted to the tolerance (hundreds of samples in), not at the first
    step beyond the tolerance; sampled coarsely (Newton corrects at once), at the second sample."""
    path = cartesian.Line([1.2, 0.3, 0.0], [1.1, 0.4, 0.0])
    options = {"duration": 2.0, "q_seed": STARTS["planar_2r"], "jump_tolerance": 1e-13}
    fine = plan_with(planar_2r, path, monkeypatch, False, False, dt=0.001, **options)
    assert fine.status == "jump", fine
    h = np.diff(fine.t)[:, None]
    unexplained = np.abs(np.diff(fine.q, axis=0) - 0.5 * h * (fine.qd[1:] + fine.qd[:-1]))
    first_beyond = int(np.flatnonzero(unexplained.max(axis=1) > 1e-13)[0]) + 1
    assert first_beyond < 10 < 100 < fine.events[0].index
    coarse = plan_with(planar_2r, path, monkeypatch, False, False, dt=0.2, **options)
    # sampled coarsely the step is traced continuous: the sampling is what cannot explain it
    assert coarse.status == "sampling" and coarse.events[0].index == 1, coarse


@pytest.mark.parametrize("name", ["ur5", "panda", "planar_2r"])
def test_a_fast_plan_carries_what_the_loops_does(name, monkeypatch):
    """Every field of a plan made by a fast path (closed form or lean loop) is the loop's:
    the path, robot, task, threshold, cell and timing alike; the samples within the IK noise."""
    robot = cached_robot(name)
    q0 = STARTS[name]
    path = line(robot, q0, OFFSETS[name])
    cell = kinplan.WorkCell(robot)
    options = {"duration": 1.0, "q_seed": q0, "cell": cell}
    fast = plan_with(robot, path, monkeypatch, True, True, **options)
    loop = plan_with(robot, path, monkeypatch, False, False, **options)
    assert fast.ok and loop.ok
    for field in dataclasses.fields(cartesian.CartesianPlan):
        a, b = getattr(fast, field.name), getattr(loop, field.name)
        if isinstance(b, np.ndarray):
            np.testing.assert_allclose(a, b, rtol=1e-4, atol=2e-5, err_msg=field.name)
        elif isinstance(b, float):
            assert a == pytest.approx(b, rel=1e-4, abs=1e-7), field.name
        elif field.name in ("path", "robot", "cell"):
            assert a is b, field.name
        elif field.name == "cell_check":
            assert a is not None and b is not None
            assert a.index is b.index is None and a.clearance == b.clearance
        else:
            assert a == b, field.name
    assert fast.path is path and fast.robot is robot and fast.cell is cell
    assert fast.position_only is robot.default_position_only()


def test_collision_events_state_deep_penetrations_in_millimetres(ur5):
    """A block engulfing the tool at the start (15 cm deep) and a clearance 20 cm beyond the
    distance kept: the messages give the check's depth in mm to 0.1 mm, so a scale error of
    0.1 % shows."""
    q0 = STARTS["ur5"]
    start = ur5.fk(q0)
    seam = cartesian.Line(start, pin.SE3(start.rotation, start.translation + [0.0, 0.3, 0.0]))
    cell = kinplan.WorkCell(ur5)
    cell.add_box("block", [0.3, 0.3, 0.3], pin.SE3(np.eye(3), start.translation))
    plan = cartesian.follow(ur5, seam, speed=0.2, q_seed=q0, cell=cell)
    check = plan.cell_check
    assert plan.status == "collision" and check is not None and check.penetration > 0.1
    assert f"({1e3 * check.penetration:.1f} mm deep)" in plan.events[0].message
    assert f"({1.001e3 * check.penetration:.1f} mm deep)" not in plan.events[0].message
    ball = kinplan.WorkCell(ur5)
    ball.add_sphere(
        "ball", 0.02, pin.SE3(np.eye(3), seam.position(np.array([0.5]))[0] + [0, 0, 0.25])
    )
    free = cartesian.follow(ur5, seam, speed=0.2, q_seed=q0, cell=ball)
    margin = free.min_clearance + 0.2
    plan = cartesian.follow(ur5, seam, speed=0.2, q_seed=q0, cell=ball, clearance=margin)
    check = plan.cell_check
    assert plan.status == "collision" and check.penetration > 0.1
    inside = f"{1e3 * check.penetration:.1f} mm inside the clearance {1e3 * margin:.1f} mm"
    assert inside in plan.events[0].message
    assert f"{1.001e3 * check.penetration:.1f} mm inside" not in plan.events[0].message
