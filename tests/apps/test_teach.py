"""The teach pendant, driven by scripted input: jogs, refusals, recording, the written program."""

from __future__ import annotations

import io
import re
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from kinplan.apps.teach import (
    COMMANDS,
    HELP,
    HISTORY_ENV,
    PromptLines,
    TeachPendant,
    default_history_file,
    fit_spline,
    home_configuration,
    run_session,
)
from kinplan.errors import InputError, KinplanError
from kinplan.model.planar import planar_arm_urdf
from kinplan.program import load_program, plan_program
from kinplan.trajectory import whole_periods


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


# -- continuous paths (issue 17) ---------------------------------------------------------------
PATH_SCRIPT = """\
    r before
    j 1 -5
    rec start
    z -0.05
    x 0.05
    j 0 -10
    yaw 20
    y 0.03
    rec stop
    r after
"""


def taught_path(robot, script: str = PATH_SCRIPT) -> tuple[TeachPendant, list[str]]:
    pendant = TeachPendant(robot, robot_source=robot.name)
    shown: list[str] = []
    for line in script.splitlines():
        reply = pendant.execute(line)
        assert not reply.text.startswith(("error", "refused")), (line, reply.text)
        shown.append(reply.text)
    return pendant, shown


def closest_distances(
    motion, samples: np.ndarray, t0: float = 0.0, t1: float | None = None, count: int = 40_000
) -> np.ndarray:
    """Distance [rad, max over joints] from each sample to the nearest of ``count`` points of
    the motion's path between t0 and t1 (an answer independent of the timing)."""
    t1 = motion.duration if t1 is None else t1
    dense = motion.sample(np.linspace(t0, t1, count))[0]
    return np.array([np.abs(dense - q).max(axis=1).min() for q in samples])


def test_recording_jogs_gives_a_spline_within_the_tolerance(ur5):
    pendant, shown = taught_path(ur5)
    assert list(pendant.paths) == ["path1"] and list(pendant.points) == ["before", "after"]
    path = pendant.paths["path1"]
    report = next(text for text in shown if text.startswith("stored path1"))
    n_samples, n_knots = len(path.samples), len(path.knot_indices)
    assert f"{n_samples} samples" in report
    assert f"spline through {n_knots} knots at their recorded times" in report
    assert f"max deviation {path.max_deviation:.2e} rad" in report
    assert f"{1000 * path.tool_deviation:.3f} mm at the tool" in report
    assert "plays it in" not in report  # not slowed: the jogs were at 10 % of the limits
    # the recording: 50 Hz from where rec start found the arm to where rec stop found it
    np.testing.assert_allclose(
        path.samples[0], pendant.points["before"] + [0, -np.radians(5), 0, 0, 0, 0]
    )
    np.testing.assert_allclose(path.samples[-1], pendant.points["after"])
    steps = np.diff(path.sample_times)
    np.testing.assert_allclose(steps[:-1], 0.02, atol=1e-12)
    assert 0 < steps[-1] <= 0.02 + 1e-12
    # each jog moves at the jog speed: 10 % of the UR5's velocity limits (mean speeds between
    # samples), and the tool jogs follow their straight line (z, then x)
    speeds = np.abs(np.diff(path.samples, axis=0)) / steps[:, None]
    assert np.max(speeds / ur5.velocity_limit) <= 0.1 + 1e-9
    xyz = np.array([ur5.fk(q).translation for q in path.samples])
    down = xyz[: np.argmax(xyz[:, 2] <= xyz[0, 2] - 0.05 + 1e-7) + 1]  # the z jog
    assert len(down) > 20
    np.testing.assert_allclose(down[:, :2], np.tile(xyz[0, :2], (len(down), 1)), atol=1e-5)
    # the fit: knots are samples, both ends kept, each at its recorded time (to 1e-6 s) and
    # joints (to 1e-6°, as the program reads them)
    assert 2 <= n_knots < n_samples / 3
    assert n_knots <= 40  # timed by chord length (before the times: key) it took 53 knots
    assert path.knot_indices[0] == 0 and path.knot_indices[-1] == n_samples - 1
    spline = path.spline
    np.testing.assert_allclose(spline.waypoints.times, path.knot_times, rtol=0, atol=5e-7)
    np.testing.assert_allclose(spline.waypoints.positions, path.knots, rtol=0, atol=1e-8)
    np.testing.assert_array_equal(path.times, spline.waypoints.times[1:])
    np.testing.assert_allclose(spline.sample(path.knot_times)[0], path.knots, rtol=0, atol=1e-8)
    assert not path.slowed and path.speed_ratio <= 1.0
    assert spline.duration == pytest.approx(path.duration, abs=5e-7)  # the recorded time
    np.testing.assert_allclose(path.played_times, path.sample_times, rtol=0, atol=5e-7)
    _, qd, _ = spline.sample(np.array([0.0, spline.duration]))
    np.testing.assert_allclose(qd, 0.0, atol=1e-12)  # at rest at both ends
    # every sample within the tolerance of the spline at the same time, and of its path (the
    # played times are the recorded ones but in the last piece, stretched by < 5e-7 s)
    at_played_times = np.abs(spline.sample(path.played_times)[0] - path.samples).max(axis=1)
    np.testing.assert_allclose(at_played_times, path.deviation, rtol=0, atol=1e-12)
    at_equal_times = np.abs(spline.sample(path.sample_times)[0] - path.samples).max(axis=1)
    np.testing.assert_allclose(at_equal_times, path.deviation, rtol=0, atol=1e-7)
    assert path.max_deviation <= path.tolerance == pytest.approx(1e-3)
    assert np.max(closest_distances(spline, path.samples)) <= path.max_deviation + 1e-9
    tool = max(
        np.linalg.norm(ur5.fk(a).translation - ur5.fk(b).translation)
        for a, b in zip(spline.sample(path.played_times)[0], path.samples)
    )
    assert tool == pytest.approx(path.tool_deviation) and tool < 1e-3  # below 1 mm
    # timed as recorded, the spline stays near the jog speed: well within the velocity limits
    t = spline.time_grid(0.001)
    peak = np.max(np.abs(spline.sample(t)[1]) / ur5.velocity_limit)
    assert peak == pytest.approx(path.speed_ratio, rel=1e-3) and peak < 0.11
    # a looser tolerance keeps fewer knots
    loose, _ = taught_path(ur5, PATH_SCRIPT.replace("rec stop", "rec stop 0.5"))
    assert len(loose.paths["path1"].knot_indices) < n_knots
    assert loose.paths["path1"].max_deviation <= np.radians(0.5)


def test_a_joint_jog_is_timed_as_a_trapezoid_at_the_jog_speed(ur5):
    pendant, _ = taught_path(ur5, "rec start 100\nj 2 10\nrec stop")
    path = pendant.paths["path1"]
    distance, speed = np.radians(10.0), 0.1 * ur5.velocity_limit[2]
    acceleration = speed / 0.5  # the programs' ramp time, the UR5 has no acceleration limits
    duration = distance / speed + speed / acceleration  # it reaches the cruise speed
    assert path.duration == pytest.approx(duration, rel=1e-9)
    assert len(path.samples) == int(np.floor(duration * 100)) + 2  # grid and the end
    others = path.samples[:, [0, 1, 3, 4, 5]]
    np.testing.assert_array_equal(others - others[0], 0.0)  # only joint 2 moves


def test_the_program_has_the_spline_move(ur5):
    pendant, _ = taught_path(ur5)
    path = pendant.paths["path1"]
    text = pendant.program_text()
    names = path.point_names()
    assert names == [f"path1_{k}" for k in range(len(path.knot_indices))]
    assert "  - ptp: [path1_1, path1_2, path1_3," in text  # from path1_0, where the arm is
    assert "    profile: spline\n" in text and "    times: [" in text and "duration" not in text
    program = yaml.safe_load(text)
    assert list(program["points"]) == ["before", *names, "after"]
    for name, q in zip(names, path.knots):
        np.testing.assert_allclose(np.radians(program["points"][name]["joints_deg"]), q, atol=1e-7)
    spline_move = {"ptp": names[1:], "name": "path1", "profile": "spline"}
    assert program["moves"] == [
        {"ptp": "before"},
        {"ptp": "path1_0"},  # the arm moved after r before: to the start of the path first
        {**spline_move, "times": path.times.tolist()},
        {"ptp": "after"},
    ]
    # the times: the knots' recorded times from knot 0, to 6 decimals, increasing
    times = np.array(program["moves"][2]["times"])
    np.testing.assert_array_equal(times, np.round(path.knot_times[1:] - path.knot_times[0], 6))
    assert np.all(np.diff(times) > 0) and times[0] > 0
    assert times[-1] == pytest.approx(path.duration, abs=5e-7)


def test_the_recorded_program_loads_and_plans(ur5, tmp_path):
    """The program plays the path as recorded: through each knot at its recorded time."""
    pendant, _ = taught_path(ur5)
    path = pendant.paths["path1"]
    names = path.point_names()
    program = load_program(pendant.save(tmp_path / "path.yaml"))
    plan = plan_program(program)
    assert plan.ok, plan.reason
    assert [m.label for m in plan.moves][:2] == ["ptp to before", "ptp to path1_0"]
    move = plan.moves[2]
    k = len(names) - 1
    assert move.label == f"path1: ptp through {k - 1} points to path1_{k}"
    assert program.moves[2].times == tuple(path.times)
    # as long as the recording (then at rest until the next whole period, as every move of
    # a program), passing each knot (as the program reads it) at its time
    assert move.t1 - move.t0 == pytest.approx(whole_periods(path.duration, plan.dt), abs=1e-9)
    assert move.t1 - move.t0 == pytest.approx(
        whole_periods(path.spline.duration, plan.dt), abs=1e-12
    )
    passed = plan.sample(move.t0 + np.array(program.moves[2].times))[0]
    expected = np.array([program.points[name].joints for name in names[1:]])
    np.testing.assert_allclose(passed, expected, rtol=0, atol=1e-9)
    np.testing.assert_allclose(plan.sample(move.t0)[0], program.points[names[0]].joints, atol=1e-9)
    np.testing.assert_allclose(
        plan.sample(move.t0 + path.knot_times)[0], path.knots, rtol=0, atol=1e-7
    )
    # the played motion is the pendant's spline
    played = plan.q[move.first : move.last + 1]
    fitted = path.spline.sample(plan.t[move.first : move.last + 1] - move.t0)[0]
    np.testing.assert_allclose(played, fitted, rtol=0, atol=1e-9)
    # within the tolerance of the recording at the recorded times, and of its path
    at_equal_times = plan.sample(move.t0 + path.sample_times)[0]
    deviation = np.abs(at_equal_times - path.samples).max(axis=1)
    assert deviation.max() <= path.tolerance
    np.testing.assert_allclose(deviation, path.deviation, rtol=0, atol=1e-7)
    geometric = closest_distances(plan, path.samples, move.t0, move.t1)
    assert geometric.max() <= deviation.max() + 1e-9
    np.testing.assert_allclose(plan.q[-1], pendant.points["after"], atol=1e-7)


def test_a_path_too_fast_for_its_spline_plays_slower_and_says_so(ur5, tmp_path):
    """Jogs at the full velocity limits: a spline with few knots through them would pass a limit
    at the recorded times, so the program stretches them (the report and the program say so)."""
    pendant = TeachPendant(ur5, jog_speed=1.0)
    pendant.execute("rec start")
    pendant.execute("j 0 300")
    report = pendant.execute("rec stop 3").text
    path = pendant.paths["path1"]
    assert path.slowed and path.speed_ratio > 1.0
    assert (
        f"timed as recorded the spline would need {100 * path.speed_ratio:.1f} % of the velocity "
        "limit of joint 0 (shoulder_pan_joint), so the program plays it in "
        f"{path.spline.duration:.3f} s, not the recorded {path.duration:.3f} s"
    ) in report
    stretch = path.spline.duration / path.duration
    assert 1.0 < stretch <= path.speed_ratio * 1.002
    np.testing.assert_allclose(path.times, (path.knot_times[1:]) * stretch, rtol=0, atol=1e-6)
    assert path.max_deviation <= path.tolerance
    assert "stretched to" in pendant.program_text()
    plan = plan_program(load_program(pendant.save(tmp_path / "fast.yaml")))
    assert plan.ok, plan.reason
    assert plan.duration == pytest.approx(whole_periods(path.spline.duration, plan.dt))
    assert np.max(np.abs(plan.qd) / ur5.velocity_limit) <= 1.0


def test_a_path_of_two_knots_is_a_cubic_ptp(ur5, tmp_path):
    pendant = TeachPendant(ur5)
    pendant.execute("rec start")
    pendant.execute("j 0 10")
    assert "spline through 2 knots" in pendant.execute("rec stop 10").text
    path = pendant.paths["path1"]
    duration = float(path.times[0])
    assert f"  - {{ptp: path1_1, name: path1, profile: cubic, duration: {duration!r}}}" in (
        pendant.program_text()
    )
    plan = plan_program(load_program(pendant.save(tmp_path / "two.yaml")))
    assert plan.ok, plan.reason
    assert plan.moves[0].label == "path1: ptp to path1_1"
    np.testing.assert_allclose(plan.q, path.spline.sample(plan.t)[0], rtol=0, atol=1e-9)


def test_recording_commands_refuse_with_the_reason(ur5, planar_2r):
    pendant = TeachPendant(ur5)
    replies = {
        command: pendant.execute(command).text
        for command in (
            "rec stop",
            "rec start abc",
            "rec start 0",
            "rec start nan",
            "rec start 5000",
            "rec start 10 20",
        )
    }
    assert replies["rec stop"] == "refused: not recording; rec start [hz] starts a path"
    assert (
        replies["rec start abc"]
        == "error: expected a number of Hz for the sampling rate, got 'abc'"
    )
    assert replies["rec start 0"] == "error: the sampling rate must be > 0 Hz, got '0'"
    assert "must be a finite number of Hz" in replies["rec start nan"]
    assert (
        replies["rec start 5000"] == "error: the sampling rate must be at most 1000 Hz, got '5000'"
    )
    assert replies["rec start 10 20"] == "error: usage: rec start [hz]"
    assert not pendant.recording
    assert pendant.execute("rec start 20").text.startswith("recording at 20 Hz")
    assert pendant.execute("rec start").text.startswith("refused: already recording")
    assert pendant.execute("rec stop abc").text == (
        "error: expected a number of degrees for the tolerance, got 'abc'"
    )
    assert pendant.execute("rec stop -1").text.startswith("error: the tolerance must be > 0")
    assert pendant.recording  # still: a bad tolerance does not end the recording
    assert pendant.execute("rec stop").text == (
        "recording stopped: the arm did not move, so no path was stored"
    )
    assert not pendant.paths and not pendant.recording
    with pytest.raises(KinplanError, match="no point recorded"):
        pendant.program_text()
    pendant.execute("rec start")
    pendant.execute("j 0 5")
    with pytest.raises(KinplanError, match="a path is being recorded; rec stop"):
        pendant.program_text()
    reply = pendant.execute("j 2 200")  # refused jogs are not recorded
    assert reply.text.startswith("refused") and "recording:" not in reply.text
    assert pendant.execute("abort").text == "recording dropped"
    assert not pendant.recording and not pendant.paths


def test_paths_and_points_in_one_session(planar_2r, tmp_path):
    pendant = TeachPendant(planar_2r)
    finished, shown = session(
        pendant,
        "r a\nrec start\nj 0 10\nx -0.1\nr mid\nhome\nrec stop\nlist\nrec start 25\n"
        "j 1 -20\nj 1 10",  # the end of the input stops the recording and stores it
    )
    assert finished
    assert list(pendant.paths) == ["path1", "path2"] and list(pendant.points) == ["a", "mid"]
    assert any(line.startswith("path1: path of ") for text in shown for line in text.splitlines())
    assert shown[-1].startswith("stored path2: ")
    assert pendant.paths["path2"].rate_hz == 25
    np.testing.assert_allclose(pendant.paths["path1"].samples[-1], pendant.start)  # home
    assert pendant.execute("r path1").text.startswith("refused: 'path1' is taken by the path")
    assert pendant.execute("r path2_0").text.startswith("refused: 'path2_0' is taken")
    program = load_program(pendant.save(tmp_path / "p.yaml"))
    assert plan_program(program).ok
    assert pendant.execute("del path1").text == "deleted path1"
    assert "path1" not in pendant.program_text()
    assert pendant.execute("del path1").text.startswith("no point 'path1'; recorded: a, mid, path2")


def test_fit_spline_alone():
    t = np.linspace(0.0, 2.0, 201)
    samples = np.column_stack([np.sin(2 * t), 0.3 * t**2, np.cos(t)])
    knots, spline, deviation = fit_spline(samples, t, 1e-4)
    assert knots[0] == 0 and knots[-1] == 200 and np.all(np.diff(knots) > 0)
    assert len(knots) < 60 and deviation.max() <= 1e-4
    np.testing.assert_array_equal(spline.waypoints.times, t[knots])
    np.testing.assert_array_equal(spline.waypoints.positions, samples[knots])
    np.testing.assert_allclose(
        deviation, np.abs(spline.sample(t)[0] - samples).max(axis=1), rtol=0, atol=1e-15
    )
    coarse, _, _ = fit_spline(samples, t, 1e-2)
    assert len(coarse) < len(knots)
    # the times count, not only the path: the same samples, the second half recorded 4× slower
    slow = np.where(t <= 1.0, t, 1.0 + 4.0 * (t - 1.0))
    knots, spline, deviation = fit_spline(samples, slow + 3.0, 1e-4)  # from any start time
    assert deviation.max() <= 1e-4 and spline.duration == pytest.approx(5.0)
    np.testing.assert_allclose(spline.sample(slow)[0], samples, rtol=0, atol=1e-4)
    # limits: no sample of the spline beyond them
    upper = np.array([0.95, 10.0, 10.0])
    clipped = samples.copy()
    clipped[:, 0] = np.minimum(clipped[:, 0], 0.95)
    knots, spline, _ = fit_spline(clipped, t, 1e-2, -upper, upper)
    assert spline.sample(t)[0][:, 0].max() <= 0.95 + 1e-9
    back = np.vstack([samples, samples[::-1]])  # there and back to the start
    knots, _, deviation = fit_spline(back, np.arange(len(back)) * 0.01, 1e-3)
    assert deviation.max() <= 1e-3
    # a last sample just after the one before it is a knot in its place
    ends = np.append(t, 2.0 + 1e-4)
    knots, _, _ = fit_spline(np.vstack([samples, samples[-1]]), ends, 1e-4)
    assert knots[-1] == 201 and 200 not in knots
    for bad, times, match in (
        ([[0.0, np.nan], [1.0, 1.0]], [0, 1], "finite"),
        ([[0.0]], [0], "N ≥ 2"),
        ("abc", [0], "samples"),
        (samples, t[:-1], "one per sample"),
        (samples, t[::-1], "strictly increase"),
        (samples, np.zeros_like(t), "strictly increase"),
        (samples, "t", "times"),
    ):
        with pytest.raises(InputError, match=match):
            fit_spline(bad, times)
    with pytest.raises(InputError, match="tolerance"):
        fit_spline(samples, t, 0.0)
    with pytest.raises(InputError, match="both lower and upper"):
        fit_spline(samples, t, 1e-3, lower=-upper)
    still = np.zeros((5, 2))  # not moving is a path too: the spline stays put
    knots, _, deviation = fit_spline(still, np.arange(5.0))
    assert list(knots) == [0, 4] and deviation.max() == 0


# -- help, numbers, key codes, line editing ----------------------------------------------------
def test_help_for_every_command(ur5):
    pendant = TeachPendant(ur5)
    assert pendant.execute("help").text == HELP
    aliases = {
        "j": ["joint", "j+"],
        "x": ["y", "z", "x+", "z-"],
        "roll": ["pitch", "yaw", "rx", "ry", "rz", "yaw-"],
        "r": ["rec", "record"],
        "del": ["delete"],
        "help": ["?"],
        "q": ["quit", "exit"],
    }
    for command, text in COMMANDS.items():
        usage = text.splitlines()[0]
        assert usage.startswith(command), usage
        for name in [command, *aliases.get(command, []), command.upper()]:
            assert pendant.execute(f"help {name}").text == text, name
        # every command in the help is one the pendant knows
        assert "unknown command" not in TeachPendant(ur5).execute(command).text
    assert "rec start [hz]" in COMMANDS["r"] and "rec stop [tol_deg]" in COMMANDS["r"]
    for units in ("degrees", "metres"):
        assert units in COMMANDS["j" if units == "degrees" else "x"]
    reply = pendant.execute("help frobnicate").text
    assert reply.startswith("error: no command 'frobnicate'; help explains j, x, roll, step")
    assert pendant.execute("help j x").text == "error: usage: help [command]"
    assert pendant.execute("show now").text.startswith("error: usage: show (no arguments)")


@pytest.mark.parametrize(
    ("command", "expected"),
    [
        ("j 2 abc", "error: expected a number of degrees for the jog, got 'abc'"),
        ("j 2 nan", "error: the jog must be a finite number of degrees, got 'nan'"),
        ("j 2 1e999", "error: the jog must be a finite number of degrees, got '1e999'"),
        ("j 0 1e300", "error: the jog must be between -720 and 720 degrees, got '1e300'"),
        ("j 9 1", "error: joint index 9 is out of range 0..5 (ur5 has 6 joints)"),
        ("j elbow 1", "error: no joint 'elbow'; give an index 0..5 or a name: shoulder_pan_joint"),
        ("x abc", "error: expected a number of metres for the jog, got 'abc'"),
        ("x -inf", "error: the jog must be a finite number of metres, got '-inf'"),
        ("x 1e300", "error: the jog must be between -10 and 10 metres, got '1e300'"),
        ("yaw 1e300", "error: the jog must be between -180 and 180 degrees, got '1e300'"),
        ("step 0", "error: usage: step <m>: the linear step must be > 0 metres, got '0'"),
        ("step x", "error: usage: step <m>: expected a number of metres for the linear step"),
        ("astep -2", "error: usage: astep <deg>: the angle step must be > 0 degrees, got '-2'"),
        ("astep 500", "error: usage: astep <deg>: the angle step must be at most 180 degrees"),
    ],
)
def test_numbers_are_refused_with_the_reason(ur5, command, expected):
    pendant = TeachPendant(ur5)
    q = pendant.q.copy()
    reply = pendant.execute(command)
    assert reply.text.startswith(expected), reply.text
    assert not reply.moved
    np.testing.assert_array_equal(pendant.q, q)


def test_key_codes_get_a_helpful_message(planar_2r):
    """The reported bug: the Up key on input without line editing printed
    unknown command '\\x1b[a'."""
    pendant = TeachPendant(planar_2r)
    for line in ("\x1b[A", "\x1b[B", "\x1bOA", "j 0 5\x1b[D"):
        text = pendant.execute(line).text
        assert text.startswith(f"error: {line[line.index(chr(27)) :][:3]!r} is a terminal key code")
        assert "readline" in text and "unknown command" not in text
    assert "control character '\\x7f'" in pendant.execute("j 0 5\x7f").text
    finished, shown = session(pendant, "\x1b[A\nshow\n")
    assert finished and "terminal key code" in shown[0] and shown[1].startswith("joints")


def test_prompt_lines_keep_a_history(tmp_path, monkeypatch):
    readline = pytest.importorskip("readline")  # absent on Windows: no line editing there
    readline.clear_history()
    typed = iter(["j 0 5", "", "j 0 5", "\x1b[A", "  show  ", "q"])

    def read(prompt: str) -> str:
        assert prompt == "teach> "
        try:
            return next(typed)
        except StopIteration:
            raise EOFError from None

    history = tmp_path / "history"
    with PromptLines(history_file=history, read=read) as lines:
        assert lines.readline is readline
        assert list(lines) == ["j 0 5", "", "j 0 5", "\x1b[A", "  show  ", "q"]
        # no empty line, no repeat, no key code; stripped
        assert readline.get_current_history_length() == 3
        assert [readline.get_history_item(k) for k in (1, 2, 3)] == ["j 0 5", "show", "q"]
    assert history.read_text().split() == ["j", "0", "5", "show", "q"]
    readline.clear_history()
    with PromptLines(history_file=history, read=read) as lines:  # the next session reads it
        assert readline.get_current_history_length() == 3
    readline.clear_history()
    monkeypatch.setenv(HISTORY_ENV, "")
    assert default_history_file() is None
    monkeypatch.setenv(HISTORY_ENV, str(history))
    assert default_history_file() == history
    monkeypatch.delenv(HISTORY_ENV)
    assert default_history_file() == Path.home() / ".kinplan_history"


def test_cli_teach_records_a_path(capsys, tmp_path, monkeypatch):
    from kinplan.apps.cli import main

    output = tmp_path / "taught.yaml"
    monkeypatch.setattr(sys, "stdin", io.StringIO("rec start\nj 0 20\nx -0.2\nrec stop\nq\n"))
    assert main(["teach", "planar_2r", "-o", str(output)]) == 0
    out = capsys.readouterr().out
    assert "stored path1: " in out and f"wrote {output}: 0 points, 1 path;" in out
    assert main(["run", str(output)]) == 0
    assert re.search(r"path1: ptp through \d+ points to path1_\d+", capsys.readouterr().out)
