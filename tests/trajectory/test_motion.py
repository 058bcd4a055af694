"""kinplan.trajectory.motion: the SampledMotion protocol plans provide and viewers, plots and
exports read.

Every kind of motion (a sampled joint trajectory, a Cartesian plan, a program plan) is checked
against the protocol's promises: shapes, the robot, tool positions by forward kinematics, planned
paths with how far they were reached, waypoints, moves and events. The consumers (plots, CSV
export) are run on motions they did not take before the protocol.
"""

from __future__ import annotations

import numpy as np
import pytest

import cartesian
from kinplan import export, plot, trajectory
from kinplan.errors import InputError
from kinplan.program import MotionBuilder
from kinplan.trajectory.motion import (
    JointMotion,
    PlannedPath,
    SampledMotion,
    as_sampled_motion,
    sampled,
    tool_track,
)

Q0, Q1 = np.array([0.3, 1.1]), np.array([1.5, -0.4])


@pytest.fixture(scope="module")
def arc_plan(planar_2r):
    arc = cartesian.Arc([1.2, 0.3, 0.0], [0.6, 1.3, 0.0], [-0.9, 1.5, 0.0])
    return cartesian.follow(planar_2r, arc, duration=2.0, q_seed=[0.2, 1.2])


@pytest.fixture(scope="module")
def failed_plan(planar_2r):
    line = cartesian.Line([1.5, 0.3, 0.0], [2.5, 0.3, 0.0])  # leaves the 2 m workspace
    return cartesian.follow(planar_2r, line, speed=0.2, q_seed=[0.2, 1.2])


@pytest.fixture(scope="module")
def program_plan(planar_2r):
    builder = MotionBuilder(planar_2r, Q0)
    builder.ptp_joints(Q1, duration=1.0)
    builder.lin([0.5, 1.2, 0.0], speed=0.2)
    return builder.finish()


def assert_protocol(motion: SampledMotion, nq: int) -> None:
    """The promises of :class:`SampledMotion` that hold for every motion."""
    assert isinstance(motion, SampledMotion)
    n = len(motion.t)
    for values in (motion.q, motion.qd, motion.qdd):
        assert values.shape == (n, nq)
    assert np.all(np.diff(motion.t) >= 0)
    if motion.robot is not None and n:
        np.testing.assert_allclose(
            motion.tool_positions, motion.robot.tool_positions(motion.q), atol=1e-9
        )
    assert motion.waypoints.positions.shape[1] == nq
    assert motion.ok == (not motion.events) and (motion.status == "ok") == motion.ok
    for piece in motion.planned_paths:
        assert 0.0 <= piece.reached <= 1.0
        assert piece.path.position(np.array([0.0, piece.reached])).shape == (2, 3)


def test_sampled_trajectory_is_a_motion_of_its_robot(planar_2r):
    cubic = trajectory.cubic_via([Q0, 0.5 * (Q0 + Q1) + 0.2, Q1], [0.0, 0.7, 1.5])
    motion = sampled(cubic, planar_2r, dt=0.1)
    assert_protocol(motion, 2)
    assert motion.kind == "joint" and motion.ok and not motion.moves
    np.testing.assert_allclose(motion.t, cubic.time_grid(0.1))
    np.testing.assert_allclose(motion.q, cubic.sample(motion.t)[0])
    assert motion.waypoints is cubic.waypoints
    (piece,) = motion.planned_paths  # the trajectory's own tool path, exact between samples
    np.testing.assert_allclose(
        piece.path.position(np.array([0.5])), planar_2r.tool_positions(cubic.sample([0.75])[0])
    )


def test_sampled_trajectory_without_a_robot_has_joints_only():
    motion = as_sampled_motion(trajectory.quintic([0.0, 1.0, 2.0], [1.0, 0.0, 2.5], 1.0), dt=0.25)
    assert isinstance(motion, JointMotion)
    assert_protocol(motion, 3)
    assert motion.robot is None and motion.tool_positions is None and not motion.planned_paths


def test_cartesian_plans_provide_the_protocol(planar_2r, arc_plan, failed_plan):
    assert as_sampled_motion(arc_plan) is arc_plan  # no adapter: the plan itself
    for plan in (arc_plan, failed_plan):
        assert_protocol(plan, 2)
        assert plan.kind == "cartesian" and plan.robot is planar_2r and not plan.moves
        assert len(plan.waypoints.positions) == 0
    assert arc_plan.planned_paths == [PlannedPath(arc_plan.path, 1.0)]
    assert not failed_plan.ok
    (piece,) = failed_plan.planned_paths
    assert piece.reached == pytest.approx(failed_plan.events[0].s)
    assert piece.reached < 1.0 and failed_plan.description.startswith("Cartesian path 1.000 m")


def test_program_plans_provide_the_protocol(planar_2r, program_plan):
    assert as_sampled_motion(program_plan) is program_plan
    assert_protocol(program_plan, 2)
    assert program_plan.kind == "program" and program_plan.description == "2 moves"
    assert [m.number for m in program_plan.moves] == [1, 2]
    (piece,) = program_plan.planned_paths  # the lin move's path, all of it
    assert piece.path is program_plan.moves[1].cartesian_plan.path and piece.reached == 1.0
    track = tool_track(planar_2r, program_plan.q, program_plan.qd)
    np.testing.assert_array_equal(track.positions, program_plan.tool_positions)
    np.testing.assert_array_equal(track.quaternions, program_plan.tool_quaternions)
    np.testing.assert_array_equal(track.speed, program_plan.tool_speed)


def test_planned_path_reach_is_clipped():
    line = cartesian.Line([0.0, 0.0, 0.0], [1.0, 0.0, 0.0])
    assert PlannedPath(line, 1.5).reached == 1.0
    assert PlannedPath(line, -0.2).reached == 0.0
    assert PlannedPath(line, float("nan")).reached == 1.0


@pytest.mark.parametrize("thing", [object(), "cubic", np.zeros((3, 2))])
def test_anything_else_is_an_input_error(thing):
    with pytest.raises(InputError, match=f"cannot plot a {type(thing).__name__}"):
        as_sampled_motion(thing, use="plot")


def test_consumers_take_any_motion(tmp_path, planar_2r, arc_plan, failed_plan):
    figure = plot.plot_trajectory([arc_plan, failed_plan], labels=["arc", "line"])
    np.testing.assert_allclose(figure.axes[0].get_lines()[0].get_ydata(), arc_plan.q[:, 0])
    figure = plot.plot_tip_path({"arc": arc_plan, "line": failed_plan})
    np.testing.assert_allclose(
        np.column_stack(figure.axes[0].get_lines()[0].get_data()), arc_plan.tool_positions[:, :2]
    )
    written = export.write_csv(tmp_path / "arc.csv", arc_plan, planar_2r.joint_names)
    table = np.loadtxt(written, delimiter=",", skiprows=1)
    np.testing.assert_allclose(table[:, 0], arc_plan.t)
    np.testing.assert_allclose(table[:, 7:10], arc_plan.tool_positions, atol=1e-8)
    motion = sampled(trajectory.cubic(Q0, Q1, 1.0), planar_2r, dt=0.05)
    assert len(export.plot_motion(motion).axes) == 4
    with pytest.raises(InputError, match="needs the motion's robot"):
        export.write_csv(tmp_path / "x.csv", sampled(trajectory.cubic(Q0, Q1, 1.0)), ["a", "b"])
    with pytest.raises(InputError, match="cannot plot a object"):
        plot.plot_trajectory(object())
