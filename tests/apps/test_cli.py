"""The `kinplan` command: info, fk, ik, run, exit codes and one-line error messages."""

from __future__ import annotations

import csv
import io
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import REPOSITORY

from kinplan.apps.cli import main
from kinplan.model.planar import planar_arm_urdf
from kinplan.program import load_program, plan_program

EXAMPLES = REPOSITORY / "examples" / "programs"


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def assert_one_line_error(err: str, *fragments: str) -> None:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("kinplan: error: "), err
    assert "Traceback" not in err
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])


def test_info_planar(capsys):
    code, out, err = run(capsys, "info", "planar_2r")
    assert code == 0 and err == ""
    assert "planar_2r (2 joints)" in out
    assert "base frame: base_link" in out and "tip frame: tip" in out
    assert "joint1" in out and "-180.0" in out and "6.283" in out
    assert "annulus 0.0000 m ≤ r ≤ 2.0000 m" in out


def test_info_ur5_reach(capsys):
    code, out, _ = run(capsys, "info", "ur5")
    assert code == 0
    assert "tip frame: tool0" in out and "shoulder_pan_joint" in out and "3.150" in out
    reach = float(out.split("max tool distance from the first joint ")[1].split(" m")[0])
    assert 0.85 < reach < 1.0


def test_fk(capsys):
    code, out, _ = run(capsys, "fk", "ur5", "--q", "0", "-90", "90", "-90", "-90", "0", "--deg")
    assert code == 0
    assert "position [m]:          [0.4869, 0.1091, 0.4319]" in out
    assert "rpy [deg]:" in out and "quaternion [x y z w]:" in out and "manipulability:" in out


def test_fk_planar_radians(capsys):
    code, out, _ = run(capsys, "fk", "planar_2r", "--q", str(np.pi / 6), str(np.pi / 6))
    assert code == 0
    assert "position [m]:          [1.3660, 1.3660, 0.0000]" in out


def test_ik_round_trip(capsys):
    args = ("ik", "ur5", "--xyz", "0.4", "-0.1", "0.2", "--rpy-deg", "180", "0", "90")
    code, out, err = run(capsys, *args, "--seed", "0", "-90", "90", "-90", "-90", "0", "--deg")
    assert code == 0 and err == ""
    joints = out.split("joints [rad]:")[1].splitlines()[0].strip().strip("[]")
    code, out, _ = run(capsys, "fk", "ur5", "--q", *joints.split(", "))
    assert code == 0 and "[0.4000, -0.1000, 0.2000]" in out


def test_ik_quaternion_and_planar_position_only(capsys):
    code, _, _ = run(
        capsys, "ik", "ur5", "--xyz", "0.4", "0.1", "0.3", "--quat-xyzw", "1", "0", "0", "0"
    )
    assert code == 0
    code, out, _ = run(capsys, "ik", "planar_2r", "--xyz", "1", "1", "0")
    assert code == 0 and "IK of the position" in out


def test_ik_unreachable_fails_with_one_line(capsys):
    code, _, err = run(capsys, "ik", "planar_2r", "--xyz", "3", "0", "0")
    assert code == 1
    assert_one_line_error(
        err, "no IK solution", "it is 3.0000 m from the arm's first joint, which reaches 2.0000 m"
    )


def test_ik_beyond_the_reach_says_the_distance_and_the_reach(capsys, ur5):
    """Issue 12: the target is 1.5 m away and the UR5 reaches about 0.95 m: say that, not "no
    IK solution within the joint limits"."""
    code, _, err = run(
        capsys, "ik", "ur5", "--xyz", "1.5", "0", "0.3", "--rpy-deg", "180", "0", "90"
    )
    assert code == 1
    assert_one_line_error(err, "no IK solution for the pose at [1.500, 0.000, 0.300] m")
    distance = float(err.split("it is ")[1].split(" m from the arm's first joint")[0])
    reach = float(err.split("which reaches ")[1].split(" m")[0])
    assert distance == pytest.approx(np.hypot(1.5, 0.3 - 0.089159), abs=1e-4)
    assert reach == pytest.approx(ur5.reach(), abs=1e-4) and 0.85 < reach < 1.0


def test_ik_within_reach_but_not_the_limits(capsys):
    # 1 cm above the base: within the reach sphere, but no configuration puts the tool there
    code, _, err = run(capsys, "ik", "ur5", "--xyz", "0", "0", "0.1", "--rpy-deg", "180", "0", "90")
    assert code == 1
    assert_one_line_error(err, "within the arm's reach", "within the joint limits is")


@pytest.mark.parametrize(
    ("argv", "fragments"),
    [
        (["fk", "ur5", "--q", "1", "2"], ["--q must hold 6 joint values"]),
        (["info", "nosuch"], ["unknown robot 'nosuch'", "ur5"]),
        (["info", "ur5", "--tip", "nosuch"], ["no frame 'nosuch'"]),
        (["run", "/nonexistent/program.yaml"], ["cannot read the file"]),
    ],
)
def test_errors_are_one_line(capsys, argv, fragments):
    code, _, err = run(capsys, *argv)
    assert code == 1
    assert_one_line_error(err, *fragments)


def test_usage_errors_exit_2(capsys):
    assert main(["bogus"]) == 2
    assert main(["fk", "ur5"]) == 2  # --q is required
    assert main(["demo", "nosuch"]) == 2
    assert main(["--version"]) == 0
    capsys.readouterr()


def test_run_writes_csv_plot_and_html(capsys, tmp_path):
    program = EXAMPLES / "lecture_2r.yaml"
    files = {name: tmp_path / "out" / f"motion.{name}" for name in ("csv", "png", "html")}
    code, out, err = run(
        capsys,
        "run",
        str(program),
        "--csv",
        str(files["csv"]),
        "--plot",
        str(files["png"]),
        "--html",
        str(files["html"]),
        "--dt",
        "0.02",
    )
    assert code == 0, err
    assert err == ""
    for name in ("straight line: lin to final", "joint space back: ptp to initial", "total"):
        assert name in out
    assert "ok: 3 moves, 4.000 s" in out
    plan = plan_program(load_program(program), dt=0.02)
    with files["csv"].open() as handle:
        rows = list(csv.reader(handle))
    header = rows[0]
    assert header[:3] == ["t", "q_joint1", "q_joint2"]
    assert header[3:7] == ["qd_joint1", "qd_joint2", "qdd_joint1", "qdd_joint2"]
    assert header[7:] == ["x", "y", "z", "qx", "qy", "qz", "qw"]
    assert len(rows) - 1 == len(plan.t)
    table = np.array(rows[1:], dtype=float)
    np.testing.assert_allclose(table[:, 0], plan.t, atol=1e-8)
    np.testing.assert_allclose(table[:, 1:3], plan.q, atol=1e-8)
    np.testing.assert_allclose(table[-1, 7:10], plan.tool_positions[-1], atol=1e-8)
    assert files["png"].stat().st_size > 10_000
    assert files["png"].read_bytes()[:4] == b"\x89PNG"
    page = files["html"].read_text()
    assert page.lstrip().lower().startswith("<!doctype html") and "</html>" in page


def test_run_invalid_program(capsys, tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text(
        "robot: planar_2r\nstart: {joints: [0, 0]}\npoints:\n  a: {joints: [0, 1]}\n"
        "moves:\n  - {ptp: a}\n  - {lin: d}\n  - {ptp: a, profile: jerky}\n"
    )
    code, out, err = run(capsys, "run", str(path))
    assert code == 1 and out == ""
    assert_one_line_error(
        err,
        "2 errors in the program",
        "moves[1].lin (line 7): unknown point 'd'; known points: a",
        "moves[2].profile (line 8)",
    )


def test_run_unreachable_program_fails_with_the_move_and_where(capsys, tmp_path):
    (tmp_path / "short.urdf").write_text(planar_arm_urdf([1.0, 0.25], name="short_forearm"))
    program = tmp_path / "across.yaml"
    program.write_text(
        "robot: short.urdf\nstart: {joints_deg: [20, 60]}\npoints:\n"
        "  a: {xyz: [0.8, 0.6, 0.0]}\n  b: {xyz: [-0.8, 0.6, 0.0]}\n"
        "moves:\n  - {ptp: a}\n  - {lin: b, speed: 0.1}\n"
    )
    html = tmp_path / "partial.html"
    table = tmp_path / "x.csv"
    code, out, err = run(capsys, "run", str(program), "--html", str(html), "--csv", str(table))
    assert code == 1
    assert_one_line_error(
        err, "move 2 (lin to b, moves[1]): unreachable at s = 0.2", ") m is out of reach"
    )
    assert "unreachable" in out and "FAILED" in out
    assert html.is_file() and "not a valid motion" in out
    # the other requested file holds the achieved part too (issue 12: say what was written)
    assert f"wrote {table} (" in out and "up to the failure in move 2" in out
    rows = list(csv.reader(table.open()))
    assert rows[0][0] == "t" and len(rows) > 2


def test_example_unreachable_weld_fails(capsys):
    code, _, err = run(capsys, "run", str(EXAMPLES / "weld_unreachable.yaml"))
    assert code == 1
    assert_one_line_error(err, "move 3 (weld across the base: lin to seam_end, moves[2])", "s = ")


def test_teach_from_stdin(capsys, tmp_path, monkeypatch):
    output = tmp_path / "taught.yaml"
    script = "j 0 20\nr a\nj 1 -15\nr b\nq\n"
    monkeypatch.setattr(sys, "stdin", io.StringIO(script))
    code, out, err = run(capsys, "teach", "planar_2r", "-o", str(output))
    assert code == 0, err
    assert f"wrote {output}: 2 points" in out
    code, out, _ = run(capsys, "run", str(output))
    assert code == 0 and "ptp to b" in out


def test_teach_without_points_fails(capsys, tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "stdin", io.StringIO("show\n"))
    code, _, err = run(capsys, "teach", "planar_2r", "-o", str(tmp_path / "t.yaml"))
    assert code == 1
    assert_one_line_error(err, "nothing recorded")
    assert not (tmp_path / "t.yaml").exists()


def test_console_script():
    script = Path(sys.executable).parent / "kinplan"
    if not script.is_file():
        pytest.skip(f"the kinplan console script is not installed next to {sys.executable}")
    result = subprocess.run(
        [str(script), "info", "planar_2r"], capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 0, result.stderr
    assert "annulus" in result.stdout
    result = subprocess.run(
        [str(script), "info", "nosuch"], capture_output=True, text=True, timeout=60
    )
    assert result.returncode == 1
    assert result.stderr.count("\n") == 1 and "unknown robot" in result.stderr


# ----------------------------------------------------------------------------------------------
# Issue 12: one line on stderr for every failure, and every requested file accounted for
# ----------------------------------------------------------------------------------------------

PLANAR_PROGRAM = (
    "robot: planar_2r\nstart: {joints_deg: [30, 30]}\npoints:\n"
    "  a: {xyz: [1.2, 0.8, 0.0]}\n  b: {xyz: [1.4, 0.6, 0.0]}\n"
    "moves:\n  - {ptp: a, duration: 1.0}\n  - {lin: b, duration: 0.5}\n"
)


def test_program_that_is_not_utf8(capsys, tmp_path):
    path = tmp_path / "latin1.yaml"
    path.write_bytes("# Schwei\u00dfnaht\n".encode("latin-1") + PLANAR_PROGRAM.encode())
    code, out, err = run(capsys, "run", str(path))
    assert code == 1 and out == ""
    assert_one_line_error(err, "program (line 1): the file is not UTF-8 text (byte 0xdf", "UTF-8")


def test_plot_with_an_unknown_extension_is_refused_before_planning(capsys, tmp_path):
    program = tmp_path / "p.yaml"
    program.write_text(PLANAR_PROGRAM)
    code, out, err = run(capsys, "run", str(program), "--plot", str(tmp_path / "out.xyz"))
    assert code == 1
    assert out == ""  # no plan table: refused before planning
    assert_one_line_error(err, "Matplotlib cannot write .xyz images", ".png", ".pdf", ".svg")
    assert not (tmp_path / "out.xyz").exists()


def test_plot_without_extension_names_the_file_it_writes(capsys, tmp_path):
    program = tmp_path / "p.yaml"
    program.write_text(PLANAR_PROGRAM)
    code, out, err = run(capsys, "run", str(program), "--plot", str(tmp_path / "out"))
    assert code == 0, err
    assert f"wrote {tmp_path / 'out.png'} (" in out and "had no extension, so PNG" in out
    assert (tmp_path / "out.png").read_bytes()[:4] == b"\x89PNG"
    assert not (tmp_path / "out").exists()


def test_failed_program_writes_every_requested_file_with_the_achieved_part(capsys, tmp_path):
    (tmp_path / "short.urdf").write_text(planar_arm_urdf([1.0, 0.25], name="short_forearm"))
    program = tmp_path / "across.yaml"
    program.write_text(
        "robot: short.urdf\nstart: {joints_deg: [20, 60]}\npoints:\n"
        "  a: {xyz: [0.8, 0.6, 0.0]}\n  b: {xyz: [-0.8, 0.6, 0.0]}\n"
        "moves:\n  - {ptp: a}\n  - {lin: b, speed: 0.1}\n"
    )
    files = {flag: tmp_path / f"partial.{ext}" for flag, ext in
             (("--csv", "csv"), ("--plot", "png"), ("--html", "html"))}  # fmt: skip
    argv = ["run", str(program)] + [str(x) for pair in files.items() for x in pair]
    code, out, err = run(capsys, *argv)
    assert code == 1
    assert_one_line_error(err, "move 2 (lin to b, moves[1]): unreachable")
    for path in files.values():
        assert path.is_file() and path.stat().st_size > 0, path
        assert f"wrote {path} (" in out
    assert out.count("up to the failure in move 2") == 3
    assert out.count("(for inspection, not a valid motion)") == 3


def test_program_failing_before_any_motion_says_why_nothing_is_written(capsys, tmp_path):
    program = tmp_path / "collinear.yaml"
    program.write_text(  # the arc's start, via and end are on one line: move 1 is invalid
        "robot: planar_2r\nstart: {joints_deg: [30, 30]}\npoints:\n"
        "  a: {xyz: [1.0, 1.0, 0.0]}\n  b: {xyz: [1.2, 1.2, 0.0]}\n"
        "moves:\n  - {circ: a, via: b}\n"
    )
    files = [tmp_path / "x.csv", tmp_path / "x.png", tmp_path / "x.html"]
    argv = ["run", str(program), "--csv", str(files[0]), "--plot", str(files[1])]
    code, out, err = run(capsys, *argv, "--html", str(files[2]))
    assert code == 1
    assert_one_line_error(err, "move 1 (circ to a via b, moves[0]): invalid")
    for flag, path in zip(("--csv", "--plot", "--html"), files):
        assert f"not written: {flag} {path}: move 1 failed before any motion" in out
        assert not path.exists()


def test_unwritable_output_of_an_ok_plan_is_one_line(capsys, tmp_path):
    program = tmp_path / "p.yaml"
    program.write_text(PLANAR_PROGRAM)
    (tmp_path / "folder.csv").mkdir()
    code, _, err = run(capsys, "run", str(program), "--csv", str(tmp_path / "folder.csv"))
    assert code == 1
    assert_one_line_error(err, f"--csv {tmp_path / 'folder.csv'}: cannot write")


def test_malformed_urdf_keeps_the_parser_chatter_off_the_terminal(capfd, tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text(
        '<?xml version="1.0"?>\n<robot name="bad"><link name="base"/><link name="a"/>'
        '<joint name="ja" type="revolute"><parent link="base"/><child link="a"/>'
        '<axis xyz="0 0 1"/><origin xyz="1 0 zz"/>'
        '<limit lower="-1" upper="1" velocity="1" effort="1"/></joint></robot>\n'
    )
    code = main(["info", str(bad)])
    out, err = capfd.readouterr()  # file descriptors 1 and 2: C++ output included
    assert code == 1 and out == ""
    assert_one_line_error(err, "Pinocchio could not read", "Unable to parse component [zz]")
    assert "pose.cpp" not in err


@pytest.mark.parametrize(
    ("argv", "code", "fragments"),
    [
        (["fk", "ur5", "--q", "nan", "0", "0", "0", "0", "0"], 2,
         ["fk: argument --q: expected a finite number, got 'nan'"]),
        (["ik", "ur5", "--xyz", "inf", "0", "0"], 2,
         ["ik: argument --xyz: expected a finite number, got 'inf'"]),
        (["ik", "ur5", "--xyz", "0.4", "0", "0.3", "--quat-xyzw", "0", "0", "0", "0"], 1,
         ["--quat-xyzw must be a non-zero quaternion"]),
        (["info", "ur5", "--tip", ""], 1,
         ["tip (a frame or link name) must be a non-empty string"]),
        (["info", "nosuch.urdf"], 1, ["does not exist"]),
    ],
)  # fmt: skip
def test_bad_numbers_and_names_are_one_line(capsys, argv, code, fragments):
    """Numbers that are not finite are malformed command lines (exit 2); values the robot
    refuses are failures (exit 1); either way one line."""
    status, _, err = run(capsys, *argv)
    assert status == code
    assert_one_line_error(err, *fragments)


def test_numeric_warnings_stay_off_the_terminal(capfd, tmp_path):
    """A target 1e200 m away overflows numpy inside the IK: the warning is not printed."""
    code = main(["ik", "ur5", "--xyz", "1e200", "0", "0"])
    _, err = capfd.readouterr()
    assert code == 1
    assert_one_line_error(err, "no IK solution")
    program = tmp_path / "far.yaml"
    program.write_text(PLANAR_PROGRAM.replace("[1.4, 0.6, 0.0]", "[1.0e300, 0.6, 0.0]"))
    code = main(["run", str(program)])
    _, err = capfd.readouterr()
    assert code == 1
    assert_one_line_error(err, "points.b.xyz (line 5): expected numbers within ±1e+06")


# ----------------------------------------------------------------------------------------------
# info: units of prismatic joints and acceleration limits (issue 26)
# ----------------------------------------------------------------------------------------------


def test_info_says_accelerations_are_not_limited(capsys):
    code, out, _ = run(capsys, "info", "ur5")
    assert code == 0
    assert "accelerations: not limited (the URDF declares none" in out
    assert "acceleration [" not in out  # no column of "none"


def test_info_names_the_joints_without_acceleration_limits(capsys, tmp_path):
    text = (REPOSITORY / "tests" / "urdf" / "prismatic_gantry.urdf").read_text()
    first = text.index('velocity="', text.index('<joint name="rail"'))
    edited = text[:first] + 'drake:acceleration="2.0" ' + text[first:]  # Drake's key
    (tmp_path / "gantry.urdf").write_text(edited)
    code, out, _ = run(capsys, "info", str(tmp_path / "gantry.urdf"))
    assert code == 0
    line = next(line for line in out.splitlines() if line.startswith("accelerations:"))
    assert "not limited on lift, shoulder" in line and "rail" not in line


def test_info_prints_metres_for_prismatic_joints(capsys):
    code, out, _ = run(capsys, "info", str(REPOSITORY / "tests" / "urdf" / "prismatic_gantry.urdf"))
    assert code == 0
    rail = next(line for line in out.splitlines() if " rail " in line)
    assert "-0.500 m" in rail and "0.500 m/s" in rail and "deg" not in rail
    shoulder = next(line for line in out.splitlines() if " shoulder " in line)
    assert "-180.0 deg" in shoulder and "rad/s" in shoulder
    assert "[rad or m]" not in out


def test_info_prints_the_unit_of_a_locked_prismatic_joint(capsys):
    from kinplan.model.sources import example_robot_data_dir

    tiago = example_robot_data_dir() / "example-robot-data/robots/tiago_description/robots"
    code, out, _ = run(
        capsys, "info", str(tiago / "tiago.urdf"), "--tip", "arm_tool_link",
        "--lock", "torso_lift_joint=0.15",
    )  # fmt: skip
    assert code == 0
    assert "locked joint (not in q): torso_lift_joint = 0.15 m" in out
    assert "[rad or m]" not in out


def test_ik_options_have_help(capsys):
    assert main(["ik", "--help"]) == 0
    out = capsys.readouterr().out
    for option, words in (
        ("--xyz", "tool position [m]"),
        ("--rpy-deg", "roll, pitch, yaw [deg]"),
        ("--quat-xyzw", "quaternion x y z w"),
        ("--seed", "start configuration"),
        ("--position-only", "ignore the orientation"),
    ):
        assert option in out and words in " ".join(out.split()), option
