"""Motion programs: validation (every error with its key path), planning, failures."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import REPOSITORY

import cartesian
from kinplan import plot
from kinplan.model.planar import planar_arm_urdf
from kinplan.program import (
    MotionBuilder,
    MoveError,
    ProgramError,
    ProgramPlan,
    load_program,
    parse_program,
    plan_program,
)
from kinplan.trajectory import Trajectory

EXAMPLES = REPOSITORY / "examples" / "programs"

API_EXAMPLE = """\
robot: ur5                 # a load_robot source; a URDF path is relative to this file
tip: tool0                 # optional
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
points:                    # taught points: joints / joints_deg, or xyz (+ rpy_deg or quat_xyzw)
  a: {xyz: [0.40, -0.10, 0.20], rpy_deg: [180, 0, 90]}
  b: {xyz: [0.40,  0.10, 0.20], rpy_deg: [180, 0, 90]}
  c: {xyz: [0.50,  0.00, 0.20], rpy_deg: [180, 0, 90]}
moves:                     # ptp: joint-interpolated; lin: straight line; circ: arc through via
  - {ptp: a, duration: 2.0}
  - {lin: b, speed: 0.02}
  - {circ: a, via: c, speed: 0.02}
"""

UR5_PROGRAM = """\
robot: ur5
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
points:
  home: {joints_deg: [0, -90, 90, -90, -90, 0]}
  above: {xyz: [0.45, -0.20, 0.25], rpy_deg: [180, 0, -90]}
  pick: {xyz: [0.45, -0.20, 0.10]}
  side: {xyz: [0.45, -0.05, 0.10], quat_xyzw: [1, 0, 0, 0]}
  mid: {xyz: [0.50, -0.125, 0.10]}
moves:
  - {ptp: above}
  - {lin: pick, speed: 0.1}
  - {lin: side, duration: 2.0, profile: quintic}
  - {circ: pick, via: mid, speed: 0.05}
  - {lin: above, speed: 0.1}
  - {ptp: home, profile: cubic}
"""


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def program_errors(text: str, tmp_path: Path) -> ProgramError:
    with pytest.raises(ProgramError) as info:
        load_program(write(tmp_path, "bad.yaml", text))
    return info.value


def point_to_segment(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distances [m] of points from the segment a-b."""
    ab = b - a
    s = np.clip((points - a) @ ab / (ab @ ab), 0.0, 1.0)
    return np.linalg.norm(points - (a + s[:, None] * ab), axis=1)


# ----------------------------------------------------------------------------------------------
# Planning
# ----------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def ur5_plan(tmp_path_factory) -> ProgramPlan:
    folder = tmp_path_factory.mktemp("ur5")
    return plan_program(load_program(write(folder, "ur5.yaml", UR5_PROGRAM)))


def test_api_example_plans(tmp_path):
    plan = plan_program(load_program(write(tmp_path, "api.yaml", API_EXAMPLE)))
    assert plan.ok, plan.reason
    assert [m.status for m in plan.moves] == ["ok"] * 3
    assert plan.moves[0].duration == pytest.approx(2.0)
    np.testing.assert_allclose(plan.tool_positions[-1], [0.40, -0.10, 0.20], atol=1e-6)


def test_ur5_program_plans_continuously(ur5_plan):
    plan = ur5_plan
    assert plan.ok and plan.status == "ok" and plan.reason == ""
    assert plan.duration > 0 and plan.duration == pytest.approx(plan.t[-1])
    assert len(plan.moves) == 6
    assert np.all(np.diff(plan.t) > 0)
    for before, after in zip(plan.moves, plan.moves[1:]):
        assert after.first == before.last
        assert after.t0 == pytest.approx(before.t1, abs=1e-12)
        joint_at_join = plan.q[before.last]
        if after.cartesian_plan is not None:  # its own first sample: IK from the current q
            np.testing.assert_allclose(after.cartesian_plan.q[0], joint_at_join, atol=1e-9)
        np.testing.assert_allclose(plan.qd[before.last], 0.0, atol=1e-9)  # rest to rest
    # No sample-to-sample jump beyond what the joint speed limits allow.
    steps = np.abs(np.diff(plan.q, axis=0)) / np.diff(plan.t)[:, None]
    assert np.all(steps <= plan.robot.velocity_limit * 1.01)
    assert all(0 < m.peak_speed_ratio <= 1.0 for m in plan.moves)
    assert all(m.min_manipulability > 0 for m in plan.moves)


def test_lin_moves_are_straight(ur5_plan):
    plan, robot = ur5_plan, ur5_plan.robot
    lin_moves = [m for m in plan.moves if m.kind == "lin"]
    assert len(lin_moves) == 3
    for move in lin_moves:
        window = range(move.first, move.last + 1)
        tool = np.array([robot.fk(plan.q[k]).translation for k in window])  # independent FK
        distance = point_to_segment(tool, tool[0], tool[-1])
        assert distance.max() < 1e-5, move.label
    pick = plan.program.points["pick"].position
    np.testing.assert_allclose(plan.tool_positions[lin_moves[0].last], pick, atol=1e-6)


def test_circ_move_passes_the_via_point(ur5_plan):
    plan = ur5_plan
    circ = next(m for m in plan.moves if m.kind == "circ")
    tool = plan.tool_positions[circ.first : circ.last + 1]
    via = plan.program.points["mid"].position
    assert np.min(np.linalg.norm(tool - via, axis=1)) < 1e-3  # sampled every dt
    np.testing.assert_allclose(tool[-1], plan.program.points["pick"].position, atol=1e-6)


def test_xyz_only_point_keeps_the_orientation_the_move_starts_with(ur5_plan):
    plan, robot = ur5_plan, ur5_plan.robot
    above = plan.moves[0]  # ptp to "above" with rpy (180, 0, -90)
    rotation_above = robot.fk(plan.q[above.last]).rotation
    np.testing.assert_allclose(rotation_above, pin.rpy.rpyToMatrix(np.pi, 0, -np.pi / 2), atol=1e-6)
    pick = plan.moves[1]  # lin to "pick": xyz only
    for k in range(pick.first, pick.last + 1):
        np.testing.assert_allclose(robot.fk(plan.q[k]).rotation, rotation_above, atol=1e-6)
    side = plan.moves[2]  # lin to "side" with a quaternion: (1, 0, 0, 0) = roll 180°
    np.testing.assert_allclose(
        robot.fk(plan.q[side.last]).rotation, np.diag([1.0, -1.0, -1.0]), atol=1e-6
    )
    circ = plan.moves[3]  # circ to "pick" (xyz only): keeps the rotation it starts with
    np.testing.assert_allclose(
        robot.fk(plan.q[circ.last]).rotation, np.diag([1.0, -1.0, -1.0]), atol=1e-6
    )


def test_xyz_only_ptp_keeps_the_start_orientation(tmp_path):
    text = """\
robot: ur5
start: {joints_deg: [10, -100, 80, -70, -90, 20]}
points:
  p: {xyz: [0.40, 0.10, 0.30]}
moves:
  - {ptp: p}
"""
    plan = plan_program(load_program(write(tmp_path, "p.yaml", text)))
    assert plan.ok, plan.reason
    robot = plan.robot
    start_rotation = robot.fk(plan.q[0]).rotation
    end = robot.fk(plan.q[-1])
    np.testing.assert_allclose(end.translation, [0.40, 0.10, 0.30], atol=1e-6)
    np.testing.assert_allclose(end.rotation, start_rotation, atol=1e-6)


def test_ptp_to_a_cartesian_point_stays_on_the_branch(tmp_path):
    # The 2R arm starts elbow-down (θ2 < 0); the target is reachable on both branches.
    text = """\
robot: planar_2r
start: {joints_deg: [60, -60]}
points:
  p: {xyz: [1.2, 0.5, 0.0]}
moves:
  - {ptp: p}
"""
    plan = plan_program(load_program(write(tmp_path, "p.yaml", text)))
    assert plan.ok, plan.reason
    q_end = plan.q[-1]
    assert q_end[1] < 0, "ptp switched to the elbow-up branch"
    np.testing.assert_allclose(plan.tool_positions[-1], [1.2, 0.5, 0.0], atol=1e-6)
    # Analytic elbow-down solution of the 2R (l1 = l2 = 1 m).
    x, y = 1.2, 0.5
    theta2 = -np.arccos((x * x + y * y - 2.0) / 2.0)
    theta1 = np.arctan2(y, x) - np.arctan2(np.sin(theta2), 1.0 + np.cos(theta2))
    np.testing.assert_allclose(q_end, [theta1, theta2], atol=1e-6)


def test_ptp_to_a_cartesian_point_stays_on_the_ur5_branch(tmp_path):
    text = """\
robot: ur5
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
points:
  p: {xyz: [0.45, 0.05, 0.35], rpy_deg: [180, 0, -90]}
moves:
  - {ptp: p}
"""
    plan = plan_program(load_program(write(tmp_path, "p.yaml", text)))
    assert plan.ok, plan.reason
    q0, q1 = plan.q[0], plan.q[-1]
    assert np.all(np.abs(q1 - q0) < 0.6)  # a nearby solution: elbow, shoulder, wrist unchanged
    assert np.sign(q1[2]) == np.sign(q0[2]) and np.sign(q1[4]) == np.sign(q0[4])


def test_lecture_2r_program_is_position_only():
    plan = plan_program(load_program(EXAMPLES / "lecture_2r.yaml"))
    assert plan.ok, plan.reason
    line = plan.moves[0]
    assert line.kind == "lin" and line.duration == pytest.approx(1.0)
    assert line.cartesian_plan.position_only
    tool = plan.tool_positions[line.first : line.last + 1]
    np.testing.assert_allclose(tool[:, 1], 1.3660254, atol=1e-6)  # the straight line y = 1.366 m
    np.testing.assert_allclose(tool[-1], [-1.3660254, 1.3660254, 0.0], atol=1e-6)
    back = plan.moves[1]
    np.testing.assert_allclose(plan.q[back.last], np.radians([30.0, 30.0]), atol=1e-12)
    # The joint-interpolated move's tip path is not straight.
    assert np.max(np.abs(plan.tool_positions[back.first : back.last + 1, 1] - 1.366)) > 0.1


def test_orientation_on_a_planar_arm_is_ignored_with_a_warning(tmp_path):
    text = """\
robot: planar_2r
start: {joints_deg: [30, 30]}
points:
  p: {xyz: [1.0, 1.0, 0.0], rpy_deg: [0, 0, 45]}
moves:
  - {lin: p, speed: 0.5}
"""
    program = load_program(write(tmp_path, "p.yaml", text))
    assert any("points.p" in w and "ignored" in w for w in program.warnings)
    assert program.points["p"].rotation is None
    assert plan_program(program).ok


@pytest.fixture(scope="module")
def short_forearm_folder(tmp_path_factory) -> Path:
    """A folder with robots/short_forearm.urdf (l1 = 1 m, l2 = 0.25 m) and programs/."""
    folder = tmp_path_factory.mktemp("short")
    write(folder, "robots/short_forearm.urdf", planar_arm_urdf([1.0, 0.25], name="short_forearm"))
    return folder


SHORT_FOREARM_PROGRAM = """\
robot: ../robots/short_forearm.urdf
start: {joints_deg: [20, 60]}
points:
  a: {xyz: [0.8, 0.6, 0.0]}
  b: {xyz: [-0.8, 0.6, 0.0]}
moves:
  - {ptp: a}
  - {lin: b, speed: 0.1}
  - {ptp: a}
"""


def test_unreachable_lin_stops_with_a_one_line_reason(short_forearm_folder, monkeypatch):
    path = write(short_forearm_folder, "programs/across_the_hole.yaml", SHORT_FOREARM_PROGRAM)
    monkeypatch.chdir("/")  # the URDF path is relative to the program's folder, not the cwd
    program = load_program(path)
    assert program.robot.name == "short_forearm"
    assert program.robot.planar_reach() == pytest.approx((0.75, 1.25))
    plan = plan_program(program)
    assert not plan.ok and plan.status == "unreachable"
    assert "\n" not in plan.reason
    match = re.match(
        r"move 2 \(lin to b, moves\[1\]\): unreachable at s = (0\.\d\d): \((.+)\) m is out of "
        "reach",
        plan.reason,
    )
    assert match, plan.reason
    s = float(match.group(1))
    x, y, _ = (float(v) for v in match.group(2).split(","))
    assert np.hypot(x, y) < 0.75 + 1e-3  # inside the hole
    assert s == pytest.approx((0.8 - x) / 1.6, abs=0.01)  # the path fraction of that point
    failed = plan.moves[-1]
    assert len(plan.moves) == 2 and failed.status == "unreachable" and not failed.ok
    assert 0.0 < failed.fraction < s
    assert failed.message == plan.reason
    # Nothing partial is presented as success: the plan holds the motion up to the failure.
    assert plan.events and plan.events[0].kind == "unreachable"
    assert np.hypot(*plan.tool_positions[-1, :2]) > 0.75 - 1e-6


def test_ptp_duration_too_short_for_the_velocity_limits(tmp_path):
    text = """\
robot: ur5
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
points:
  far: {joints_deg: [170, -90, 90, -90, -90, 0]}
moves:
  - {ptp: far, duration: 0.5}
"""
    plan = plan_program(load_program(write(tmp_path, "p.yaml", text)))
    assert not plan.ok and plan.status == "velocity_limit"
    assert plan.reason.startswith("move 1 (ptp to far, moves[0]): velocity_limit: joint 0 ")
    minimum = float(re.search(r"at least ([\d.]+) s", plan.reason).group(1))
    assert minimum == pytest.approx(1.5 * np.radians(170) / 3.15, rel=1e-3)  # 1.5 Δ / v_max
    assert len(plan.t) == 1  # nothing of the failed move is appended


def test_ptp_speed_and_profiles(tmp_path):
    text = """\
robot: ur5
start: {joints_deg: [0, -90, 90, -90, -90, 0]}
points:
  a: {joints_deg: [170, -90, 90, -90, -90, 0]}
  home: {joints_deg: [0, -90, 90, -90, -90, 0]}
moves:
  - {ptp: a}
  - {ptp: home, speed: 1.0}
  - {ptp: a, profile: quintic}
  - {ptp: home, profile: cubic, speed: 0.25}
  - {ptp: home}
"""
    plan = plan_program(load_program(write(tmp_path, "p.yaml", text)))
    assert plan.ok, plan.reason
    ratios = [m.peak_speed_ratio for m in plan.moves]
    assert ratios[0] == pytest.approx(0.5, abs=1e-6)  # default: half the joint speed limits
    assert ratios[1] == pytest.approx(1.0, abs=1e-6)
    assert ratios[2] == pytest.approx(0.5, abs=1e-3)  # quintic at its minimum duration
    assert ratios[3] == pytest.approx(0.25, abs=1e-3)
    assert plan.moves[4].duration == 0.0 and plan.moves[4].ok  # already there


def test_collinear_circ_fails_cleanly(tmp_path):
    text = """\
robot: planar_2r
start: {joints_deg: [30, 30]}
points:
  a: {xyz: [1.0, 1.0, 0.0]}
  b: {xyz: [0.5, 0.5, 0.0]}
moves:
  - {ptp: a}
  - {circ: b, via: b}
"""
    plan = plan_program(load_program(write(tmp_path, "p.yaml", text)))
    assert not plan.ok and plan.status == "invalid"
    assert plan.reason.startswith("move 2 (circ to b via b, moves[1]): invalid: ")
    assert "collinear" in plan.reason


def test_program_plan_is_a_trajectory(ur5_plan):
    plan = ur5_plan
    assert isinstance(plan, Trajectory)
    q, qd, qdd = plan.sample(plan.t)
    np.testing.assert_allclose(q, plan.q, atol=1e-9)
    np.testing.assert_allclose(qd, plan.qd, atol=1e-9)
    middle = 0.5 * (plan.t[:-1] + plan.t[1:])  # between samples: close to the neighbours
    q_mid = plan.sample(middle)[0]
    assert np.max(np.abs(q_mid - plan.q[:-1])) < 0.05
    np.testing.assert_allclose(plan.knots, [0.0] + [m.t1 for m in plan.moves], atol=1e-12)
    figure = plot.plot_trajectory(plan, dt=0.05)
    assert len(figure.axes) == 3
    assert plan.tool_quaternions.shape == (len(plan.t), 4)
    np.testing.assert_allclose(np.linalg.norm(plan.tool_quaternions, axis=1), 1.0, atol=1e-12)


def test_motion_builder_follows_a_path_and_refuses_after_a_failure(planar_2r):
    builder = MotionBuilder(planar_2r, np.radians([30.0, 30.0]), dt=0.01)
    builder.lin(np.array([0.0, 1.366, 0.0]), speed=0.5)
    with pytest.raises(MoveError, match=r"^move 2 \(lin\): (unreachable|singular|velocity_limit)"):
        builder.lin(np.array([0.0, 2.5, 0.0]), speed=0.5)
    with pytest.raises(Exception, match="planning stopped"):
        builder.ptp_joints(np.zeros(2))
    plan = builder.finish()
    assert not plan.ok and len(plan.moves) == 2 and plan.moves[0].ok


def test_motion_builder_refuses_a_path_that_starts_elsewhere(ur5):
    home = np.radians([0, -90, 90, -90, -90, 0])
    here = ur5.fk(home)
    builder = MotionBuilder(ur5, home)
    away = cartesian.Line(here.translation + [0, 0, -0.1], here.translation + [0.1, 0, -0.1])
    with pytest.raises(MoveError, match=r"invalid: the path starts at .*0.1000 m away"):
        builder.follow(away)
    builder = MotionBuilder(ur5, home)
    turned = pin.SE3(np.eye(3), here.translation)
    with pytest.raises(MoveError, match="tool orientation 3.142 rad away"):
        builder.follow(cartesian.Line(turned, pin.SE3(np.eye(3), here.translation + 0.1)))
    builder = MotionBuilder(ur5, home)
    seam = cartesian.Circle(here.translation - [0.05, 0, 0], 0.05, rotation=here.rotation)
    report = builder.follow(seam, speed=0.05, label="circle")
    assert report.ok and report.kind == "path" and builder.finish().ok


# ----------------------------------------------------------------------------------------------
# Validation
# ----------------------------------------------------------------------------------------------


BAD_PROGRAM = """\
robot: ur5
start: {joints_deg: [0, -90, 90, -90, -90]}
colour: red
points:
  a: {xyz: [0.40, -0.10, 0.20], rpy_deg: [180, 0, 90]}
  b: {xyz: [0.40, 0.10], rpy_deg: [180, 0, 90]}
  c: {joints_deg: [0, -90, 200, -90, -90, 0]}
  e: {joints: [0, 0, 0, 0, 0, 0], xyz: [1, 2, 3]}
  f: {xyz: [0.4, 0, 0.2], rpy_deg: [180, 0, 0], quat_xyzw: [0, 0, 0, 1]}
  far: {xyz: [2.0, 0.0, 0.2]}
moves:
  - {ptp: a, duration: -2.0}
  - {lin: d, speed: 0.02}
  - {circ: a, speed: fast}
  - {lin: b, via: c, profile: jerky}
  - {ptp: a, speed: 2}
  - {move: a}
  - 3
  - {lin: a, speed: 0.1, duration: 1}
"""


def test_every_validation_error_is_reported_with_its_key_path(tmp_path):
    error = program_errors(BAD_PROGRAM, tmp_path)
    by_path: dict[str, list[str]] = {}
    for issue in error.issues:
        by_path.setdefault(issue.path, []).append(issue.message)
    expected = {
        "start.joints_deg": "expected 6 numbers",
        "colour": "unknown key 'colour'",
        "points.b.xyz": "expected 3 numbers (tool position [m]), got 2",
        "points.c.joints_deg": "joint 2 (elbow_joint) = 200 deg is beyond its limits",
        "points.e": "give exactly one of joints, joints_deg or xyz",
        "points.f": "give rpy_deg or quat_xyzw, not both",
        "points.far": "out of reach of ur5",
        "moves[0].duration": "expected a number > 0",
        "moves[1].lin": "unknown point 'd'; known points: a, b, c, e, f, far",
        "moves[2]": "a circ move needs via",
        "moves[2].speed": "expected a number > 0 (tool speed [m/s]), got 'fast'",
        "moves[3].via": "via only goes with circ",
        "moves[3].profile": "unknown profile 'jerky'; expected one of trapezoid, quintic, cubic",
        "moves[4].speed": "0 < speed ≤ 1",
        "moves[5].move": "unknown key 'move'",
        "moves[6]": "expected a mapping",
        "moves[7]": "give duration or speed, not both",
    }
    for path, fragment in expected.items():
        assert path in by_path, f"no error for {path}; got {sorted(by_path)}"
        assert any(fragment in message for message in by_path[path]), (path, by_path[path])
    assert "moves[0]" not in by_path  # a valid part gets no error
    lines = {issue.path: issue.line for issue in error.issues}
    assert lines["moves[1].lin"] == 13 and lines["colour"] == 3 and lines["points.b.xyz"] == 6
    text = str(error)
    assert text.splitlines()[0].endswith(f"{len(error.issues)} errors in the program:")
    assert "moves[1].lin (line 13): unknown point 'd'; known points: a, b, c, e, f, far" in text
    assert "\n" not in error.one_line()


TOO_LONG_NAME_PROGRAM = (
    "robot: ur5\nstart: {joints: [0, 0, 0, 0, 0, 0]}\npoints: {p: {joints: [0, 0, 0, 0, 0, 0]}}\n"
    "moves: [{ptp: p}]\n"
)


@pytest.mark.parametrize(
    ("text", "path", "fragment"),
    [
        ("robot: [1]\nstart: {joints: [0, 0]}\nmoves: [{ptp: a}]\n", "robot", "robot name"),
        ("robot: nosuch\nstart: {joints: [0]}\nmoves: []\n", "robot", "unknown robot 'nosuch'"),
        ("robot: ur5\ntip: nosuch\nstart: {joints: [0]}\n", "tip", "no frame 'nosuch'"),
        ("start: {joints: [0, 0]}\nmoves: [{ptp: a}]\n", "robot", "missing"),
        ("robot: planar_2r\nmoves: [{ptp: a}]\n", "start", "missing"),
        ("robot: planar_2r\nstart: [0, 0]\n", "start", "expected {joints"),
        ("robot: planar_2r\nstart: {joints: [0, 0]}\n", "moves", "missing"),
        ("robot: planar_2r\nstart: {joints: [0, 0]}\nmoves: []\n", "moves", "non-empty list"),
        ("robot: planar_2r\nstart: {joints: [0, .nan]}\nmoves: []\n", "start.joints", "finite"),
        ("robot: planar_2r\nstart: {joints: [0, 0]}\npoints: [1]\n", "points", "mapping"),
        ("- 1\n- 2\n", "program", "expected a mapping"),
        ("robot: ur5\n  bad: indent\n", "program", "not valid YAML"),
        ("robot: planar_2r\nstart: {joints: [0, 0]}\na: 1\na: 2\n", "a", "duplicate key"),
        (
            "robot: planar_2r\nstart: {joints: [0, 0]}\npoints: {p: {xyz: [1, 0, 0], "
            "quat_xyzw: [0, 0, 0, 0]}}\nmoves: [{ptp: p}]\n",
            "points.p.quat_xyzw",
            "zero",
        ),
        (
            "robot: planar_2r\nstart: {joints: [0, 0]}\npoints: {p: {joints: [0, 0], "
            "rpy_deg: [0, 0, 0]}}\nmoves: [{ptp: p}]\n",
            "points.p.rpy_deg",
            "only goes with xyz",
        ),
        (
            "robot: planar_2r\nstart: {joints: [0, 0]}\npoints: {p: {joints: [0, 0]}}\n"
            "moves: [{ptp: p, lin: p}]\n",
            "moves[0]",
            "exactly one of ptp, lin, circ",
        ),
        (  # a name longer than the file system allows: Path.is_file raises OSError for it
            TOO_LONG_NAME_PROGRAM + "tool: {xyz: [0, 0, 0.1], body: {mesh: " + "a" * 300 + "}}\n",
            "tool.body.mesh",
            "no file",
        ),
        (
            TOO_LONG_NAME_PROGRAM + "obstacles: {part: {mesh: " + "b" * 300 + ".stl}}\n",
            "obstacles.part.mesh",
            "no file",
        ),
    ],
)
def test_validation_errors(tmp_path, text, path, fragment):
    error = program_errors(text, tmp_path)
    assert any(issue.path == path and fragment in issue.message for issue in error.issues), [
        str(issue) for issue in error.issues
    ]


def test_missing_file_is_a_program_error(tmp_path):
    with pytest.raises(ProgramError, match="cannot read the file"):
        load_program(tmp_path / "nope.yaml")


def test_parse_program_from_text():
    program = parse_program(API_EXAMPLE, source="api")
    assert program.source == "api"
    assert list(program.points) == ["a", "b", "c"]
    assert [m.label for m in program.moves] == ["ptp to a", "lin to b", "circ to a via c"]
    np.testing.assert_allclose(program.start, np.radians([0, -90, 90, -90, -90, 0]))


def test_every_example_program_is_tested():
    names = {path.stem for path in EXAMPLES.glob("*.yaml")}
    assert names == set(EXAMPLE_PROGRAMS)


EXAMPLE_PROGRAMS = (
    "ur5_pick_place", "weld_seam", "weld_cell", "lecture_2r", "weld_unreachable",
    "weld_collision", "panda_on_table", "weld_native",
)  # fmt: skip


@pytest.mark.parametrize("name", EXAMPLE_PROGRAMS)
def test_example_programs(name):
    plan = plan_program(load_program(EXAMPLES / f"{name}.yaml"))
    if name == "weld_unreachable":
        assert not plan.ok
        assert plan.reason.startswith("move 3 (weld across the base: lin to seam_end, moves[2]): ")
        assert " at s = " in plan.reason
    elif name == "weld_collision":
        assert not plan.ok and plan.moves[-1].status == "collision"
        assert plan.reason.startswith("move 2 (approach through the web: lin to fillet_start, ")
        assert "tool comes within" in plan.reason and "of web" in plan.reason
    else:
        assert plan.ok, plan.reason


# ----------------------------------------------------------------------------------------------
# Tool speeds of Cartesian moves, and where a path may start
# ----------------------------------------------------------------------------------------------

SPEED_PROGRAM = """\
robot: ur5
start: {{joints_deg: [0, -90, 90, -90, -90, 0]}}
points:
  a: {{xyz: [0.45, -0.10, 0.20], rpy_deg: [180, 0, 90]}}
  b: {{xyz: [0.45, 0.10, 0.20], rpy_deg: [180, 0, 90]}}
moves:
  - {{ptp: a, duration: 2.0}}
  - {move}
"""


def lin_tool_speed(tmp_path: Path, move: str) -> tuple[np.ndarray, np.ndarray, ProgramPlan]:
    """Times [s] and tool speeds [m/s] of the second move (a 0.2 m lin from a to b), the speed
    from the FK of the planned joint positions (central differences), not from the plan's own
    rates."""
    text = SPEED_PROGRAM.format(move=move)
    plan = plan_program(load_program(write(tmp_path, "speed.yaml", text)))
    assert plan.ok, plan.reason
    lin = plan.moves[1]
    window = slice(lin.first, lin.last + 1)
    t = plan.t[window]
    tool = np.array([plan.robot.fk(q).translation for q in plan.q[window]])
    np.testing.assert_allclose(tool[[0, -1], 1], [-0.10, 0.10], atol=1e-6)
    speed = np.linalg.norm(np.gradient(tool, t, axis=0), axis=1)
    return t - t[0], speed, plan


def test_default_lin_speed_is_5_cm_per_second(tmp_path):
    """A lin move without speed or duration cruises at 0.05 m/s: the tool's own speed (FK)
    holds 0.05 m/s over the cruise, and the move lasts L/v plus the 0.25 s ramp."""
    t, speed, plan = lin_tool_speed(tmp_path, "{lin: b}")
    assert t[-1] == pytest.approx(0.2 / 0.05 + 0.25, abs=1e-9)
    cruise = (t > 0.3) & (t < t[-1] - 0.3)
    np.testing.assert_allclose(speed[cruise], 0.05, rtol=1e-4)
    assert speed.max() <= 0.05 * (1 + 1e-4)


@pytest.mark.parametrize(("profile", "peak_factor"), [("quintic", 1.875), ("cubic", 1.5)])
def test_speed_of_a_polynomial_lin_is_its_peak_not_its_average(tmp_path, profile, peak_factor):
    """``speed`` of a quintic or cubic lin is the tool's peak speed: the FK speed peaks at it
    mid-move, and the move lasts k·L/v (1.875 for the quintic, 1.5 for the cubic), so the
    average speed is v/k, below the requested speed."""
    t, speed, _ = lin_tool_speed(tmp_path, f"{{lin: b, speed: 0.04, profile: {profile}}}")
    assert t[-1] == pytest.approx(peak_factor * 0.2 / 0.04, rel=1e-3)
    assert speed.max() == pytest.approx(0.04, rel=1e-3)
    assert abs(t[np.argmax(speed)] - 0.5 * t[-1]) < 0.02
    assert 0.2 / t[-1] == pytest.approx(0.04 / peak_factor, rel=1e-3)


@pytest.mark.parametrize("gap", [1e-3, 3e-4])
def test_a_path_starting_a_fraction_of_a_millimetre_away_is_refused(ur5, gap):
    """A path must start at the tool (within 0.1 mm): 1 mm and 0.3 mm away it is refused with
    the distance, before anything is planned; a path starting exactly there is followed."""
    home = np.radians([0, -90, 90, -90, -90, 0])
    here = ur5.fk(home)
    offset = gap * np.array([0.6, 0.0, 0.8])
    builder = MotionBuilder(ur5, home)
    away = cartesian.Line(
        pin.SE3(here.rotation, here.translation + offset),
        pin.SE3(here.rotation, here.translation + [0.05, 0.0, 0.0]),
    )
    with pytest.raises(MoveError, match=rf"invalid: the path starts at .*{gap:.4f} m away"):
        builder.follow(away)
    assert builder.finish().moves[0].status == "invalid"
    builder = MotionBuilder(ur5, home)
    there = cartesian.Line(here, pin.SE3(here.rotation, here.translation + [0.05, 0.0, 0.0]))
    assert builder.follow(there).ok
