"""Exports a controller can run (issue 17): URScript for UR arms and ROS JointTrajectory files.

Every file is parsed back and compared with the plan: the servoj targets with the plan evaluated
at k · period, the trajectory points with the plan's samples.
"""

from __future__ import annotations

import json
import math
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import yaml
from conftest import REPOSITORY
from hypothesis import given, settings
from hypothesis import strategies as st

import kinplan
from kinplan import export, trajectory
from kinplan.apps.cli import main
from kinplan.errors import InputError
from kinplan.model.planar import planar_arm_urdf
from kinplan.program import load_program, plan_program
from kinplan.trajectory.motion import sampled

EXAMPLES = REPOSITORY / "examples" / "programs"
UR_PROGRAM = EXAMPLES / "ur5_pick_place.yaml"
PLANAR_PROGRAM = EXAMPLES / "lecture_2r.yaml"
FAILING_PLANAR = (  # move 2 runs into the unreachable hole of a short-forearm arm
    "robot: short.urdf\nstart: {joints_deg: [20, 60]}\npoints:\n"
    "  a: {xyz: [0.8, 0.6, 0.0]}\n  b: {xyz: [-0.8, 0.6, 0.0]}\n"
    "moves:\n  - {ptp: a}\n  - {lin: b, speed: 0.1}\n"
)

NUMBER = r"-?\d+(?:\.\d+)?"
SERVOJ = re.compile(r"^\s*servoj\(\[([^\]]*)\], t=(" + NUMBER + r"), lookahead_time=", re.M)
MOVEJ = re.compile(r"^\s*movej\(\[([^\]]*)\], a=(" + NUMBER + r"), v=(" + NUMBER + r")\)", re.M)


def vector(text: str) -> list[float]:
    return [float(x) for x in text.split(",")]


@pytest.fixture(scope="module")
def ur_plan():
    plan = plan_program(load_program(UR_PROGRAM))
    assert plan.ok
    return plan


@pytest.fixture(scope="module")
def failed_plan(tmp_path_factory):
    folder = tmp_path_factory.mktemp("failing")
    (folder / "short.urdf").write_text(planar_arm_urdf([1.0, 0.25], name="short_forearm"))
    (folder / "across.yaml").write_text(FAILING_PLANAR)
    plan = plan_program(load_program(folder / "across.yaml"))
    assert not plan.ok and plan.moves[-1].number == 2
    return plan


@pytest.fixture(scope="module")
def planar_plan():
    return plan_program(load_program(PLANAR_PROGRAM))


# ----------------------------------------------------------------------------------------------
# URScript
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("period", [0.008, 0.002, 0.0123])
def test_urscript_replays_the_plan_at_the_controller_period(ur_plan, period):
    script = export.urscript(ur_plan, style="servo", period=period)
    script.encode("ascii")  # plain ASCII: the controller's reader
    targets = SERVOJ.findall(script)
    # k · period for k = 0 .. ceil(duration / period), the last at the end (a remainder below
    # 1e-6 period is rounding: a program lasts whole periods of its dt)
    count = math.ceil(ur_plan.duration / period - 1e-6) + 1
    assert len(targets) == count, (len(targets), count)
    q = np.array([vector(values) for values, _ in targets])
    assert {float(t) for _, t in targets} == {period}
    times = np.minimum(np.arange(count) * period, ur_plan.duration)
    np.testing.assert_allclose(q, ur_plan.sample(times)[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(q[-1], ur_plan.q[-1], rtol=0, atol=1e-10)
    # the resampled stream ends on the plan's end exactly (the text rounds to 1e-10)
    _, servo = export.servo_samples(ur_plan, period)
    assert np.array_equal(servo[-1], ur_plan.q[-1]) and np.array_equal(servo[0], ur_plan.q[0])
    (start, acceleration, speed), *others = MOVEJ.findall(script)
    assert others == []
    np.testing.assert_allclose(vector(start), ur_plan.q[0], rtol=0, atol=1e-10)
    assert (float(acceleration), float(speed)) == (1.0, 0.5)
    # the interpolation makes no jumps: the stream keeps the joint speed limits
    speeds = np.abs(np.diff(servo, axis=0)) / period
    assert np.all(speeds <= 1.001 * ur_plan.robot.velocity_limit), speeds.max(axis=0)


def test_urscript_program_structure(ur_plan):
    script = export.urscript(ur_plan, style="servo", lookahead_time=0.05, gain=500)
    lines = script.splitlines()
    header = [line for line in lines if line.startswith("#")]
    assert lines[: len(header)] == header and len(header) >= 3
    assert f"kinplan {kinplan.__version__}" in header[0] and "ur5" in header[0]
    assert f"duration {ur_plan.duration:.6f} s" in header[1]
    assert f"{len(ur_plan.t)} plan samples" in header[1]
    assert "shoulder_pan_joint, shoulder_lift_joint, elbow_joint" in header[2]
    code = lines[len(header) :]
    assert code[0] == "def kinplan_motion():"
    motion = [line.lstrip() for line in code if line.lstrip().startswith(("movej(", "servoj("))]
    assert motion[0].startswith("movej(")  # to the start, after set_tcp / set_payload
    assert code[-2:] == ["end", "kinplan_motion()"]
    openers = sum(bool(re.match(r"\s*(def|while|if)\b.*:$", line)) for line in code)
    assert openers == sum(line.strip() == "end" for line in code) == 2
    assert all("lookahead_time=0.05, gain=500.0" in line for line in code if "servoj(" in line)
    # the end is held 2 · lookahead (0.1 s = 13 periods of 0.008 s) after the stream
    assert "while kinplan_hold < 13:" in script
    end = re.search(r"kinplan_end = \[([^\]]*)\]", script).group(1)
    np.testing.assert_allclose(vector(end), ur_plan.q[-1], rtol=0, atol=1e-10)
    assert not re.search(r"\d[eE][-+]?\d", "\n".join(code)), "URScript has no exponents"


def test_urscript_of_a_sampled_quintic_is_the_quintic(tmp_path):
    """A quintic Hermite through samples of a quintic is that quintic: the servo targets equal
    the trajectory itself (an independent answer, not the interpolation under test)."""
    robot = kinplan.load_robot("ur5")
    q0 = np.radians([0, -90, 90, -90, -90, 0])
    motion = trajectory.quintic(q0, q0 + 0.3, 1.234)
    path = tmp_path / "sub" / "q.script"
    assert export.write_urscript(path, sampled(motion, robot), period=0.002) == path
    targets = SERVOJ.findall(path.read_text())
    assert len(targets) == math.ceil(1.234 / 0.002) + 1
    q = np.array([vector(values) for values, _ in targets])
    times = np.minimum(np.arange(len(q)) * 0.002, 1.234)
    np.testing.assert_allclose(q, motion.sample(times)[0], rtol=0, atol=1e-9)


def test_urscript_refuses_an_arm_that_is_not_a_ur(planar_plan):
    with pytest.raises(InputError) as info:
        export.urscript(planar_plan)
    message = str(info.value)
    assert "URScript export needs a Universal Robots arm (6 joints named shoulder_pan_joint" in (
        message
    )
    assert "planar_2r has 2 joints (joint1, joint2)" in message
    assert "write_joint_trajectory or write_csv" in message and "\n" not in message


def test_ur_arm_names_with_a_prefix_order_and_locks():
    def arm(names, locked=None):
        return SimpleNamespace(name="arm", joint_names=names, locked_joints=locked or {})

    assert export.ur_arm_problem(arm(list(export.UR_JOINT_NAMES))) == ""
    assert export.ur_arm_problem(arm([f"left_{n}" for n in export.UR_JOINT_NAMES])) == ""
    mixed = [f"left_{n}" for n in export.UR_JOINT_NAMES[:5]] + ["right_wrist_3_joint"]
    assert "arm has 6 joints" in export.ur_arm_problem(arm(mixed))
    swapped = list(export.UR_JOINT_NAMES)
    swapped[1], swapped[2] = swapped[2], swapped[1]
    assert export.ur_arm_problem(arm(swapped)) != ""
    five = arm(list(export.UR_JOINT_NAMES[:5]), {"wrist_3_joint": 0.0})
    assert "arm has 5 joints" in export.ur_arm_problem(five)
    assert "and wrist_3_joint locked" in export.ur_arm_problem(five)


def test_urscript_refuses_a_ur_with_a_locked_joint():
    robot = kinplan.load_robot("ur5", locked_joints={"wrist_3_joint": 0.0})
    motion = sampled(trajectory.quintic(np.zeros(5), np.full(5, 0.1), 1.0), robot)
    with pytest.raises(InputError, match="ur5 has 5 joints .* and wrist_3_joint locked"):
        export.urscript(motion)


@pytest.mark.parametrize(
    ("keyword", "value", "fragment"),
    [
        ("period", 0.0, "period must be > 0"),
        ("period", -0.008, "period must be > 0"),
        ("period", math.nan, "period must be a finite number"),
        ("period", math.inf, "period must be a finite number"),
        ("period", True, "period must be a number"),
        ("period", "0.008", "period must be a number"),
        ("lookahead_time", 0.5, "lookahead_time must be ≤ 0.2"),
        ("lookahead_time", 0.01, "lookahead_time must be ≥ 0.03"),
        ("gain", 50, "gain must be ≥ 100"),
        ("start_speed", 0.0, "start_speed must be > 0"),
        ("start_acceleration", -1.0, "start_acceleration must be > 0"),
    ],
)
def test_urscript_parameters_are_checked(ur_plan, tmp_path, keyword, value, fragment):
    path = tmp_path / "x.script"
    with pytest.raises(InputError, match=re.escape(fragment)):
        export.write_urscript(path, ur_plan, **{keyword: value})
    assert not path.exists()


def test_servo_samples_period_is_checked(ur_plan):
    with pytest.raises(InputError, match="period must be > 0"):
        export.servo_samples(ur_plan, 0.0)


# ----------------------------------------------------------------------------------------------
# Failed plans: never exported for a controller
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "write",
    [
        lambda path, plan: export.write_urscript(path / "x.script", plan),
        lambda path, plan: export.write_joint_trajectory(path / "x.json", plan),
        lambda path, plan: export.write_joint_trajectory(path / "x.yaml", plan),
    ],
    ids=["urscript", "json", "yaml"],
)
def test_a_failed_plan_is_refused(failed_plan, tmp_path, write):
    with pytest.raises(InputError) as info:
        write(tmp_path, failed_plan)
    message = str(info.value)
    assert "refuses a failed plan: the plan failed at move 2 (unreachable)" in message
    assert "a controller must not run a partial motion" in message and "\n" not in message
    assert list(tmp_path.iterdir()) == []
    assert export.plan_failure(failed_plan) == "the plan failed at move 2 (unreachable)"


def test_not_a_motion_is_refused(tmp_path):
    with pytest.raises(InputError, match="takes a planned motion"):
        export.joint_trajectory(trajectory.quintic([0.0], [1.0], 1.0))
    with pytest.raises(InputError, match="takes a planned motion"):
        export.urscript("plan.yaml")


# ----------------------------------------------------------------------------------------------
# JointTrajectory
# ----------------------------------------------------------------------------------------------


def check_document(document: dict, plan) -> None:
    assert list(document) == ["header", "joint_names", "points"]
    assert document["header"] == {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}
    assert document["joint_names"] == list(plan.robot.joint_names)
    points = document["points"]
    assert len(points) == len(plan.t)
    samples = {"positions": plan.q, "velocities": plan.qd, "accelerations": plan.qdd}
    for key, values in samples.items():
        read = np.array([point[key] for point in points])
        assert read.dtype == float and np.array_equal(read, values), key  # exact: repr floats
    stamps = [point["time_from_start"] for point in points]
    assert all(set(s) == {"sec", "nanosec"} and 0 <= s["nanosec"] < 10**9 for s in stamps)
    assert all(isinstance(s["sec"], int) and isinstance(s["nanosec"], int) for s in stamps)
    times = np.array([s["sec"] + 1e-9 * s["nanosec"] for s in stamps])
    np.testing.assert_allclose(times, plan.t, rtol=0, atol=1e-9)
    ordered = [(s["sec"], s["nanosec"]) for s in stamps]
    assert ordered == sorted(set(ordered))  # strictly increasing


@pytest.mark.parametrize("suffix", [".json", ".yaml", ".yml", ".JSON"])
def test_joint_trajectory_file_reads_back_to_the_plan(ur_plan, tmp_path, suffix):
    path = export.write_joint_trajectory(tmp_path / "out" / f"motion{suffix}", ur_plan)
    text = path.read_text()
    if suffix.lower() == ".json":
        document = json.loads(text, parse_constant=lambda name: pytest.fail(name))
        assert len(text.splitlines()) == len(ur_plan.t) + 6  # one point per line
    else:
        document = yaml.safe_load(text)
    check_document(document, ur_plan)
    assert export.joint_trajectory(ur_plan) == document


def test_joint_trajectory_without_a_robot_needs_joint_names():
    motion = sampled(trajectory.quintic([0.0, 1.0], [1.0, 0.0], 0.5), dt=0.1)
    with pytest.raises(InputError, match="joint_names is needed"):
        export.joint_trajectory(motion)
    with pytest.raises(InputError, match="must hold 2 names"):
        export.joint_trajectory(motion, ["a"])
    with pytest.raises(InputError, match="joint_names must be a list of 2 names"):
        export.joint_trajectory(motion, "ab")
    document = export.joint_trajectory(motion, ["a", "b"])
    assert document["joint_names"] == ["a", "b"]
    assert [p["time_from_start"] for p in document["points"]][-2:] == [
        {"sec": 0, "nanosec": 400_000_000},
        {"sec": 0, "nanosec": 500_000_000},
    ]


@pytest.mark.parametrize("name", ["motion.csv", "motion.txt", "motion", "motion.json.bak"])
def test_an_unknown_trajectory_extension_is_refused(ur_plan, tmp_path, name):
    with pytest.raises(InputError) as info:
        export.write_joint_trajectory(tmp_path / name, ur_plan)
    assert "give a file ending in .json, .yaml, .yml" in str(info.value)
    assert not (tmp_path / name).exists()


@pytest.mark.parametrize(
    ("seconds", "expected"),
    [
        (0.0, (0, 0)),
        (0.01, (0, 10_000_000)),
        (1.5, (1, 500_000_000)),
        (2.0, (2, 0)),
        (0.9999999999, (1, 0)),  # rounds up to the next second: carried
        (0.9999999995, (1, 0)),
        (0.999999999, (0, 999_999_999)),
        (12.3456789012, (12, 345_678_901)),
    ],
)
def test_ros_duration_examples(seconds, expected):
    assert export.ros_duration(seconds) == {"sec": expected[0], "nanosec": expected[1]}


@settings(max_examples=2000, deadline=None)
@given(
    st.one_of(
        st.floats(0.0, 1e6),
        st.integers(0, 10**6).map(lambda k: max(k - 1e-10, 0.0)),
        st.integers(0, 10**6).map(lambda k: k + 4.9999e-10),
    )
)
def test_ros_duration_is_a_valid_rounding(seconds):
    stamp = export.ros_duration(seconds)
    assert 0 <= stamp["nanosec"] < 10**9 and stamp["sec"] >= 0
    error = abs(stamp["sec"] + stamp["nanosec"] * 1e-9 - seconds)
    assert error <= 0.5e-9 + 4 * math.ulp(max(seconds, 1.0)), (seconds, stamp)


@pytest.mark.parametrize("seconds", [-1e-9, math.nan, math.inf, 2.0**31, "1.0", None])
def test_ros_duration_refuses_what_is_not_a_time(seconds):
    with pytest.raises(InputError, match="seconds must be"):
        export.ros_duration(seconds)


# ----------------------------------------------------------------------------------------------
# kinplan run --urscript FILE --trajectory FILE
# ----------------------------------------------------------------------------------------------


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def one_line_error(err: str, *fragments: str) -> None:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("kinplan: error: "), err
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])


def test_run_writes_urscript_and_trajectory(capsys, tmp_path, ur_plan):
    script, document = tmp_path / "out" / "motion.script", tmp_path / "out" / "motion.yaml"
    code, out, err = run(
        capsys, "run", str(UR_PROGRAM), "--urscript", str(script), "--urscript-style", "servo",
        "--trajectory", str(document),
    )  # fmt: skip
    assert code == 0 and err == "", err
    count = math.ceil(ur_plan.duration / 0.008) + 1
    assert f"wrote {script} (URScript, {count} servoj targets every 0.008 s)" in out
    assert f"wrote {document} (JointTrajectory, {len(ur_plan.t)} points" in out
    targets = SERVOJ.findall(script.read_text())
    assert len(targets) == count
    q = np.array([vector(values) for values, _ in targets])
    times = np.minimum(np.arange(count) * 0.008, ur_plan.duration)
    np.testing.assert_allclose(q, ur_plan.sample(times)[0], rtol=0, atol=1e-9)
    check_document(yaml.safe_load(document.read_text()), ur_plan)


def test_run_servo_period(capsys, tmp_path):
    script = tmp_path / "motion.script"
    argv = ["run", str(UR_PROGRAM), "--urscript", str(script), "--servo-period", "0.002"]
    argv += ["--urscript-style", "servo"]
    code, out, err = run(capsys, *argv)
    assert code == 0, err
    assert "every 0.002 s)" in out
    assert {t for _, t in SERVOJ.findall(script.read_text())} == {"0.002"}
    assert main(["run", str(UR_PROGRAM), "--urscript", str(script), "--servo-period", "0"]) == 2
    capsys.readouterr()


def test_run_trajectory_of_a_planar_arm(capsys, tmp_path, planar_plan):
    document = tmp_path / "lecture.json"
    code, out, err = run(capsys, "run", str(PLANAR_PROGRAM), "--trajectory", str(document))
    assert code == 0, err
    assert f"wrote {document} (JointTrajectory" in out
    check_document(json.loads(document.read_text()), planar_plan)


def test_run_refuses_urscript_for_a_planar_arm_before_planning(capsys, tmp_path):
    script = tmp_path / "lecture.script"
    code, out, err = run(capsys, "run", str(PLANAR_PROGRAM), "--urscript", str(script))
    assert code == 1 and out == ""  # no plan table: refused before planning
    one_line_error(
        err,
        f"--urscript {script}: URScript export needs a Universal Robots arm (6 joints named "
        "shoulder_pan_joint … wrist_3_joint); planar_2r has 2 joints (joint1, joint2); use "
        "--trajectory or --csv",
    )
    assert not script.exists()


def test_run_refuses_an_unknown_trajectory_extension_before_planning(capsys, tmp_path):
    path = tmp_path / "motion.csv"
    code, out, err = run(capsys, "run", str(PLANAR_PROGRAM), "--trajectory", str(path))
    assert code == 1 and out == ""
    one_line_error(err, f"--trajectory {path}: ", "give a file ending in .json, .yaml, .yml")
    assert not path.exists()


def test_run_of_a_failed_plan_writes_the_csv_but_no_controller_file(capsys, tmp_path):
    (tmp_path / "short.urdf").write_text(planar_arm_urdf([1.0, 0.25], name="short_forearm"))
    program = tmp_path / "across.yaml"
    program.write_text(FAILING_PLANAR)
    table, document = tmp_path / "x.csv", tmp_path / "x.json"
    argv = ["run", str(program), "--csv", str(table), "--trajectory", str(document)]
    code, out, err = run(capsys, *argv)
    assert code == 1
    one_line_error(err, "move 2 (lin to b, moves[1]): unreachable")
    assert f"wrote {table} (" in out and "for inspection, not a valid motion" in out
    assert (
        f"not written: --trajectory {document}: the plan failed at move 2 (unreachable); a "
        "controller must not run a partial motion"
    ) in out
    assert table.is_file() and not document.exists()


def test_run_of_a_failed_ur_plan_writes_no_urscript(capsys, tmp_path):
    script, document = tmp_path / "w.script", tmp_path / "w.yaml"
    argv = ["run", str(EXAMPLES / "weld_unreachable.yaml"), "--urscript", str(script)]
    code, out, err = run(capsys, *argv, "--trajectory", str(document))
    assert code == 1
    one_line_error(err, "move 3 (weld across the base: lin to seam_end, moves[2])")
    for flag, path in (("--urscript", script), ("--trajectory", document)):
        assert f"not written: {flag} {path}: the plan failed at move 3 (" in out
        assert not path.exists()
    assert out.count("a controller must not run a partial motion") == 2


@pytest.mark.parametrize("flag", ["--urscript", "--trajectory"])
def test_run_many_refuses_controller_exports(capsys, tmp_path, flag):
    path = str(tmp_path / "x.json")
    code, out, err = run(capsys, "run", str(PLANAR_PROGRAM), str(UR_PROGRAM), flag, path)
    assert code == 1 and out == ""
    one_line_error(err, f"{flag} write the motion of one program; give one PROGRAM.yaml")
    code, out, err = run(capsys, "run", str(PLANAR_PROGRAM), "--jobs", "1", flag, path)
    assert code == 1 and out == ""
    one_line_error(err, f"{flag} write the motion of a program planned here")
    assert not Path(path).exists()
