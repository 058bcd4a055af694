"""The teach pendant, driven by scripted input: jogs, refusals, recording, the written program."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from kinplan.planar import planar_arm_urdf
from kinplan.program import load_program, plan_program
from kinplan.teach import HELP, TeachPendant, home_configuration, run_session


def session(pendant: TeachPendant, script: str) -> tuple[bool, list[str]]:
    shown: list[str] = []
    finished = run_session(pendant, script.splitlines(), shown.append)
    return finished, shown


def test_scripted_ur5_session_writes_a_program_that_plans(ur5, tmp_path):
    pendant = TeachPendant(ur5, robot_source="ur5")
    start_pose = ur5.fk(pendant.q)
    moved: list[np.ndarray] = []
    script = """\
        show
        z -0.1          # down 10 cm
        r above
        step 0.02
        x+
        y-
        z-
        r pick
        yaw 30
        j 0 -25
        r
        list
        q
        this line is never read
    """
    finished = run_session(pendant, script.splitlines(), lambda text: None, on_move=moved.append)
    assert finished
    assert list(pendant.points) == ["above", "pick", "p3"]
    assert len(moved) == 6
    above = ur5.fk(pendant.points["above"])
    np.testing.assert_allclose(above.translation, start_pose.translation - [0, 0, 0.1], atol=1e-6)
    np.testing.assert_allclose(above.rotation, start_pose.rotation, atol=1e-6)  # jogs keep it
    pick = ur5.fk(pendant.points["pick"])
    np.testing.assert_allclose(
        pick.translation - above.translation, [0.02, -0.02, -0.02], atol=1e-6
    )
    path = pendant.save(tmp_path / "programs" / "taught.yaml")
    program = load_program(path)
    assert list(program.points) == ["above", "pick", "p3"]
    assert [m.label for m in program.moves] == ["ptp to above", "ptp to pick", "ptp to p3"]
    np.testing.assert_allclose(program.start, home_configuration(ur5), atol=1e-7)
    for name, q in pendant.points.items():
        np.testing.assert_allclose(program.points[name].joints, q, atol=1e-7)
    plan = plan_program(program)
    assert plan.ok, plan.reason
    np.testing.assert_allclose(plan.q[-1], pendant.points["p3"], atol=1e-7)


def test_tool_rotation_jogs(ur5):
    pendant = TeachPendant(ur5)
    before = ur5.fk(pendant.q)
    reply = pendant.execute("roll 10")
    assert reply.moved
    after = ur5.fk(pendant.q)
    np.testing.assert_allclose(after.translation, before.translation, atol=1e-6)
    angle = np.degrees(np.arccos((np.trace(after.rotation @ before.rotation.T) - 1) / 2))
    assert angle == pytest.approx(10.0, abs=1e-4)
    assert pendant.execute("astep 2").text == "angle step 2°"
    q = pendant.q.copy()
    pendant.execute("j 5+")
    assert pendant.q[5] - q[5] == pytest.approx(np.radians(2.0))


def test_refusals_leave_the_arm_where_it_is(ur5, planar_2r):
    pendant = TeachPendant(ur5)
    q = pendant.q.copy()
    replies = {
        command: pendant.execute(command).text
        for command in ("j 2 200", "x 3", "frobnicate", "j 9 1", "j", "step -1", "del nope")
    }
    np.testing.assert_array_equal(pendant.q, q)
    assert replies["j 2 200"].startswith("refused: joint 2 (elbow_joint) would reach 290.00°")
    assert replies["x 3"].startswith("refused: ")  # the first failure along the jog
    assert "% of the jog to (3.4869, 0.1091, 0.4319) m: " in replies["x 3"]
    assert (
        replies["frobnicate"] == "error: unknown command 'frobnicate'; type help for the commands"
    )
    assert "out of range" in replies["j 9 1"]
    assert replies["j"].startswith("error: usage")
    assert replies["step -1"].startswith("error: usage")
    assert replies["del nope"].startswith("no point 'nope'")
    pendant.execute("r a")
    assert pendant.execute("r a").text.startswith("refused: a point 'a' exists")
    assert pendant.execute("r 1bad").text.startswith("error: point name '1bad'")
    planar = TeachPendant(planar_2r)
    assert planar.execute("yaw 5").text.startswith("refused: planar_2r has 2 joints")
    reply = planar.execute("z 0.1")  # out of the arm's plane: refused before any check
    assert reply.text.startswith("refused: planar_2r is a planar arm and moves in its xy-plane")
    assert reply.text.endswith("jog x, y or the joints") and not reply.moved
    reply = planar.execute("x 0.2")  # beyond the reach r = 2 m
    assert reply.text.startswith("refused: unreachable at ") and not reply.moved
    assert "exceeds the reach 2.0000 m" in reply.text
    assert HELP in pendant.execute("help").text


def test_refusals_advise_only_what_the_pendant_can_do(ur5, planar_2r):
    """Issue 12: `x 1.0` was refused with "use a smaller dt"; the pendant has no dt. Its advice
    names pendant commands, never follow()'s arguments (dt, q_seed, retime, speed...)."""
    api_words = re.compile(r"\b(dt|q_seed|retime|duration|speed|tolerance|velocity_scale)\b")
    replies = []
    for robot, commands in ((ur5, ("x 1.0", "x 3", "z -1", "y 0.5")), (planar_2r, ("x 1", "y 1"))):
        pendant = TeachPendant(robot)
        for command in commands:
            reply = pendant.execute(command)
            assert reply.text.startswith("refused: ") and not reply.moved, reply.text
            assert not api_words.search(reply.text), reply.text
            replies.append(reply.text)
    # beyond the reach: says so, with the distance and the reach, whatever the first event is
    assert (
        "beyond the reach of ur5, 0.9" in replies[0] and "jog back toward the robot" in replies[0]
    )
    for bad in ("x nan", "x inf", "j 0 nan", "step inf", "astep nan"):
        assert TeachPendant(ur5).execute(bad).text.startswith("error: "), bad
    assert TeachPendant(ur5).execute(None).text.startswith("error: a command is a line of text")


def test_planar_session_and_abort(planar_2r, tmp_path):
    pendant = TeachPendant(planar_2r)
    np.testing.assert_allclose(pendant.q, np.radians([30.0, 30.0]))
    finished, shown = session(pendant, "x -0.2\nr a\ny 0.1\nr b\nabort\n")
    assert finished is False
    assert any(text.startswith("recorded b") for text in shown)
    finished, _ = session(pendant, "home\nr c\n")  # the end of the input writes the program
    assert finished is True
    program = load_program(pendant.save(tmp_path / "p.yaml"))
    assert program.robot.name == "planar_2r" and len(program.moves) == 3
    assert plan_program(program).ok


def test_urdf_robot_is_written_relative_to_the_program(tmp_path):
    urdf = tmp_path / "robots" / "arm3.urdf"
    urdf.parent.mkdir()
    urdf.write_text(planar_arm_urdf([0.5, 0.4, 0.3], name="arm3"))
    from kinplan import load_robot

    robot = load_robot(urdf)
    pendant = TeachPendant(robot, robot_source=str(urdf))
    pendant.execute("j 1 -10")
    pendant.execute("r a")
    output = tmp_path / "programs" / "taught.yaml"
    text = pendant.program_text(output)
    assert "robot: ../robots/arm3.urdf" in text
    program = load_program(pendant.save(output))
    assert program.robot.nq == 3
    assert plan_program(program).ok


def test_writing_without_points_is_refused(planar_2r, tmp_path):
    pendant = TeachPendant(planar_2r)
    with pytest.raises(Exception, match="no point recorded"):
        pendant.save(tmp_path / "p.yaml")
    assert not Path(tmp_path / "p.yaml").exists()
