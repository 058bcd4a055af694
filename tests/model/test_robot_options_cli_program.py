"""Issue 13 on the command line and in programs: ``--tip``, ``--lock``, ``info --frames``; the
program keys ``locked_joints:``, ``limits:``, ``package_dirs:`` and ``base_pose:``."""

from __future__ import annotations

import io
import sys

import numpy as np
import pinocchio as pin
import pytest
from conftest import REPOSITORY, TESTS

import kinplan
from kinplan.apps.cli import main
from kinplan.model.sources import example_robot_data_dir
from kinplan.program import ProgramError, load_program, parse_program, plan_program

ROBOTS = example_robot_data_dir() / "example-robot-data" / "robots"
HERE = TESTS / "urdf"
TIAGO = str(ROBOTS / "tiago_description/robots/tiago.urdf")
EXAMPLE = REPOSITORY / "examples" / "programs" / "panda_on_table.yaml"


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def one_line_error(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("kinplan: error: "), err
    return lines[0]


# ------------------------------------------------------------------------------ command line
def test_info_frames_lists_every_frame_with_its_joint_even_without_a_tip(capsys):
    code, out, err = run(capsys, "info", str(HERE / "two_arms.urdf"), "--frames")
    assert code == 0 and err == ""
    rows = {line.split("│")[2].strip(): line for line in out.splitlines() if line.count("│") > 4}
    assert {"left_tool0", "right_gripper_base", "left_finger_b", "waist"} <= set(rows)
    assert "left_wrist_3_joint" in rows["left_tool0"] and "link" in rows["left_tool0"]
    assert "mimic: 1 ×" in rows["left_finger_b"]  # (the master's name wraps to the next line)
    assert "no tool chain shown (choose one with --tip NAME)" in out
    assert "left_tool0" in out.split("no tool chain shown")[1]


def test_info_frames_with_a_tip_shows_the_robot_too(capsys):
    code, out, _ = run(capsys, "info", "ur5", "--frames")
    assert code == 0
    assert "frames of ur5_robot.urdf" in out and "wrist_3_link" in out
    assert "robot: ur5 (6 joints)" in out and "tip frame: tool0" in out


def test_info_shows_continuous_mimic_locked_joints_and_a_held_root(capsys):
    code, out, _ = run(capsys, "info", str(ROBOTS / "kinova_description/robots/kinova.urdf"))
    assert code == 0
    assert out.count("continuous (unbounded)") == 3 and "none" in out
    code, out, _ = run(capsys, "info", str(HERE / "mimic_arm.urdf"), "--lock", "joint_1=0.25")
    assert code == 0
    assert "robot: mimic_arm (5 joints)" in out
    assert "mimic joint (not in q): joint_3_coupled = -0.5 × joint_3 +0.2" in out
    assert "locked joint (not in q): joint_1 = 0.25" in out
    code, out, _ = run(capsys, "info", str(HERE / "floating_root.urdf"))
    assert code == 0 and "held root joint (not in q): root_joint at base pose" in out
    code, out, _ = run(capsys, "info", str(HERE / "prismatic_gantry.urdf"))
    assert code == 0 and "prismatic" in out and "0.400 m" in out and "0.300 m/s" in out


def test_lock_on_fk_and_ik(capsys):
    q = ["0.3", "-0.5", "1.0", "0.2", "0.4", "-0.3", "0.1"]
    code, out, err = run(
        capsys, "fk", TIAGO, "--tip", "arm_tool_link", "--lock", "torso_lift_joint=0.2", "--q", *q
    )
    assert code == 0, err
    robot = kinplan.load_robot(TIAGO, tip="arm_tool_link", locked_joints={"torso_lift_joint": 0.2})
    expected = robot.fk(np.array(q, dtype=float)).translation
    assert f"position [m]:          [{expected[0]:.4f}, {expected[1]:.4f}" in out
    x, y, z = (f"{v:.4f}" for v in expected)
    code, out, err = run(
        capsys,
        "ik",
        TIAGO,
        "--tip",
        "arm_tool_link",
        "--lock",
        "torso_lift_joint=0.2",
        "--xyz",
        x,
        y,
        z,
        "--position-only",
    )
    assert code == 0, err
    assert "position error [m]" in out


@pytest.mark.parametrize(
    "argv, fragments",
    [
        (["info", "ur5", "--lock", "elbow_joint"], ["--lock elbow_joint: expected NAME=VALUE"]),
        (["info", "ur5", "--lock", "elbow_joint=abc"], ["radians (metres for a prismatic"]),
        (["info", "ur5", "--lock", "=0.1"], ["expected NAME=VALUE"]),
        (["info", "ur5", "--lock", "elbow_joint=inf"], ["expected NAME=VALUE"]),
        (
            ["info", "ur5", "--lock", "elbow=0.1"],
            ["locked_joints: no joint 'elbow'", "elbow_joint"],
        ),
        (
            ["fk", "ur5", "--lock", "elbow_joint=0.1", "--lock", "elbow_joint=0.2", "--q", "0"],
            ["joint 'elbow_joint' is locked twice"],
        ),
        (["fk", "ur5", "--lock", "elbow_joint=0.1", "--q", "0", "0"], ["5 joint values"]),
        (["info", str(HERE / "two_arms.urdf")], ["several kinematic chains", "left_tool0"]),
    ],
)
def test_bad_locks_and_tips_are_one_line_errors(capsys, argv, fragments):
    code, _, err = run(capsys, *argv)
    assert code == 1
    line = one_line_error(err)
    for fragment in fragments:
        assert fragment in line, (fragment, line)


def test_teach_with_a_lock_writes_it_into_the_program(capsys, tmp_path, monkeypatch):
    output = tmp_path / "taught.yaml"
    monkeypatch.setattr(sys, "stdin", io.StringIO("j 0 10\nr a\nj 1 -10\nr b\nq\n"))
    code, _, err = run(
        capsys, "teach", str(HERE / "mimic_arm.urdf"), "--lock", "joint_1=0.25", "-o", str(output)
    )
    assert code == 0, err
    assert "locked_joints: {joint_1: 0.25}" in output.read_text()
    program = load_program(output)
    assert program.robot.nq == 5 and program.robot.locked_joints == {"joint_1": 0.25}
    assert plan_program(program).ok


# ---------------------------------------------------------------------------------- programs
def test_example_program_with_every_robot_option_plans():
    program = load_program(EXAMPLE)
    robot = program.robot
    assert robot.nq == 6 and robot.locked_joints == {"panda_joint3": 0.0}
    assert robot.acceleration_limit[-1] == 5.0 and robot.velocity_limit[-1] == 1.5
    expected = pin.SE3(pin.rpy.rpyToMatrix(0, 0, np.pi), np.array([0.5, 0.2, 0.75]))
    assert robot.base_pose.isApprox(expected, 1e-12)
    plan = plan_program(program)
    assert plan.ok, plan.reason
    # taught points are world poses: the plan ends where the program says, in the world
    np.testing.assert_allclose(robot.fk(plan.q[-1]).translation, [0.10, 0.20, 1.05], atol=1e-6)


PROGRAM = """\
robot: {robot}
tip: {tip}
{options}
start: {{joints: {start}}}
points: {{a: {{joints: {start}}}}}
moves: [{{ptp: a}}]
"""


def program_text(options: str, robot: str = "two_arms.urdf", tip: str = "right_tool0") -> str:
    start = [0.0] * 6
    return PROGRAM.format(robot=robot, tip=tip, options=options, start=start)


def test_program_robot_options_load_a_urdf_relative_to_the_program(tmp_path):
    meshes = tmp_path / "meshes"
    meshes.mkdir()
    options = "\n".join(
        [
            "locked_joints: {waist: 0.3}",
            "limits: {right_elbow_joint: {lower: -2.0, upper: 2.0, acceleration: 4.0}}",
            "package_dirs: [meshes]",
            "base_pose: {xyz: [1.0, 0.0, 0.2], quat_xyzw: [0, 0, 0, 1]}",
        ]
    )
    text = program_text(options, robot=str(HERE / "two_arms.urdf"))
    program = parse_program(text, base_dir=tmp_path)
    robot = program.robot
    assert robot.nq == 6 and robot.locked_joints == {"waist": 0.3}
    k = robot.joint_names.index("right_elbow_joint")
    assert (robot.lower[k], robot.upper[k], robot.acceleration_limit[k]) == (-2.0, 2.0, 4.0)
    assert robot.package_dirs[0] == meshes
    np.testing.assert_allclose(robot.base_pose.translation, [1.0, 0.0, 0.2])


@pytest.mark.parametrize(
    "options, where, fragment",
    [
        ("locked_joints: [waist]", "locked_joints (line 3)", "expected a mapping {joint name"),
        ("locked_joints: {waist: fast}", "locked_joints.waist (line 3)", "finite number"),
        ("locked_joints: {hip: 0.1}", "locked_joints.hip (line 3)", "no joint 'hip'"),
        ("limits: {waist: 2}", "limits.waist (line 3)", "expected a mapping with any of"),
        ("limits: {waist: {speed: 1}}", "limits.waist.speed (line 3)", "unknown key 'speed'"),
        ("limits: {waist: {velocity: -1}}", "limits.waist.velocity (line 3)", "number > 0"),
        ("limits: {waist: {lower: 1, upper: 0}}", "limits.waist (line 3)", "must be below"),
        ("limits: {hip: {velocity: 1}}", "limits.hip (line 3)", "no joint 'hip'"),
        ("package_dirs: [nowhere]", "package_dirs[0] (line 3)", "no folder"),
        ("package_dirs: 3", "package_dirs (line 3)", "a list of folders"),
        ("base_pose: {rpy_deg: [0, 0, 0]}", "base_pose (line 3)", "expected {xyz: [x, y, z]}"),
        ("base_pose: {xyz: [0, 0], rpy_deg: [0, 0, 0]}", "base_pose.xyz (line 3)", "3 numbers"),
        ("base_pose: {xyz: [0, 0, 0], yaw: 1}", "base_pose.yaw (line 3)", "unknown key 'yaw'"),
    ],
)
def test_program_robot_option_errors_name_the_key_and_line(tmp_path, options, where, fragment):
    text = program_text(options, robot=str(HERE / "two_arms.urdf"))
    with pytest.raises(ProgramError) as raised:
        parse_program(text, base_dir=tmp_path)
    message = str(raised.value)
    assert where in message and fragment in message, message


def test_program_tip_error_lists_candidates():
    text = program_text("", robot=str(HERE / "two_arms.urdf"), tip="left_hand")
    with pytest.raises(ProgramError) as raised:
        parse_program(text)
    assert "tip (line 2)" in str(raised.value) and "left_tool0" in str(raised.value)
