"""Bad input to the viewer, plots, exports, reach maps, placement, batch engines and demos is a
:class:`kinplan.KinplanError` saying what was wrong (issue 26), never a raw TypeError,
ValueError, AttributeError, OverflowError or MemoryError.

The named cases of the issue have their own tests; then every public function is called with
each of its arguments replaced, one at a time, by values that break naive code (None, text,
NaN, negative, zero, tiny, huge, containers, booleans, arrays, objects): each call returns or
raises a KinplanError.
"""

from __future__ import annotations

import math
import signal
import time

import numpy as np
import pytest
from conftest import REPOSITORY

import kinplan
from kinplan import export, plot, trajectory, viewer
from kinplan.apps import demos
from kinplan.errors import InputError, KinplanError
from kinplan.scale import batch, engines, placement, reach
from kinplan.trajectory.motion import sampled

LECTURE = str(REPOSITORY / "examples" / "programs" / "lecture_2r.yaml")


@pytest.fixture(scope="module")
def ur5():
    return kinplan.load_robot("ur5")


@pytest.fixture(scope="module")
def arm():
    return kinplan.load_robot("planar_2r")


@pytest.fixture(scope="module")
def motion(arm):
    return trajectory.cubic(np.zeros(2), np.full(2, 0.1), 1.0)


# ----------------------------------------------------------------------------------------------
# The cases named in the issue
# ----------------------------------------------------------------------------------------------


def test_save_html_without_a_robot(motion, tmp_path):
    with pytest.raises(InputError, match=r"robot must be a kinplan\.Robot .*got None"):
        viewer.save_html(None, motion, tmp_path / "a.html")
    with pytest.raises(InputError, match=r"robot must be a kinplan\.Robot"):
        viewer.render_html("ur5", motion)
    assert not (tmp_path / "a.html").exists()


def test_save_html_markers_that_are_not_points(arm, motion, tmp_path):
    with pytest.raises(InputError, match=r"marker 'x' must be a position 3-vector .*'abc'"):
        viewer.save_html(arm, motion, tmp_path / "a.html", markers={"x": "abc"})
    with pytest.raises(InputError, match="markers must be a list of positions"):
        viewer.save_html(arm, motion, tmp_path / "a.html", markers="abc")
    with pytest.raises(InputError, match=r"marker 'p0' must be"):
        viewer.save_html(arm, motion, tmp_path / "a.html", markers=[[0.0, None, 1.0]])


@pytest.mark.parametrize(
    ("keyword", "value", "fragment"),
    [
        ("path", None, "path (the HTML file to write) must be a file path"),
        ("fps", 1e12, "fps must be at most 1000"),
        ("title", 5, "title must be a string or None"),
        ("loop", np.zeros(2), "loop must be True or False"),
    ],
)
def test_save_html_arguments(arm, motion, tmp_path, keyword, value, fragment):
    arguments = {"path": tmp_path / "a.html", keyword: value}
    with pytest.raises(InputError, match=re_escape(fragment)):
        viewer.save_html(arm, motion, **arguments)


def test_plot_tip_path_of_nothing():
    for value, fragment in (
        (None, "tip_paths must be a path of shape (k, 2) or (k, 3) [m]"),
        ("abc", "tip_paths must be a path"),
        (np.full((3, 2), np.nan), "tip path 0 must be a path of shape (k, 2) or (k, 3) [m] of"),
        ([], "plot_tip_path needs at least one path"),
        ([[0.0, 1.0], ["a", "b"]], "must be a path of shape"),
    ):
        with pytest.raises(InputError, match=re_escape(fragment)):
            plot.plot_tip_path(value)


def test_plot_siblings(motion, tmp_path):
    path = np.zeros((3, 2))
    with pytest.raises(InputError, match="labels must be a list of 1 names"):
        plot.plot_trajectory(motion, labels=5)
    with pytest.raises(InputError, match="title must be a string"):
        plot.plot_trajectory(motion, title=np.zeros(2))
    with pytest.raises(InputError, match="show_knots must be True or False"):
        plot.plot_trajectory(motion, show_knots="yes")
    with pytest.raises(InputError, match="reference must be two points"):
        plot.plot_tip_path(path, reference=5)
    with pytest.raises(InputError, match="points must be"):
        plot.plot_tip_path(path, points="abc")
    with pytest.raises(InputError, match=r"path \(the image file to write\) must be a file path"):
        plot.plot_tip_path(path, path=5)
    with pytest.raises(InputError, match="cannot save"):
        plot.plot_tip_path(path, path=tmp_path / "a.unknownformat")


def test_export_siblings(ur5, tmp_path):
    plan = sampled(trajectory.cubic(np.zeros(6), np.full(6, 0.1), 1.0), ur5)
    with pytest.raises(InputError, match="joint_names must be a list of 6 names"):
        export.write_csv(tmp_path / "a.csv", plan, 5)
    with pytest.raises(InputError, match="joint_names must hold 6 names"):
        export.plot_motion(plan, joint_names=["a"])
    with pytest.raises(InputError, match=r"path \(the image file to write\)"):
        export.plot_motion(plan, path=5)
    with pytest.raises(InputError, match="robot must be a kinplan.Robot"):
        export.ur_arm_problem(None)
    with pytest.raises(InputError, match="plan_failure takes a planned motion"):
        export.plan_failure(None)
    with pytest.raises(InputError, match="joint_names must be a list of names"):
        export.csv_header(None)
    with pytest.raises(InputError, match="between must be one of"):
        export.check_limits(plan, between="nowhere")


# ----------------------------------------------------------------------------------------------
# Reach maps, placement, engines: work capped with a clear error
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("options", "fragment"),
    [
        ({"resolution": 1e-5}, "IK targets (at most 200,000,000); use a resolution of at least"),
        ({"resolution": 1e-300}, "use a resolution of at least"),
        ({"orientations": 10**9}, "orientations must be at most 100,000"),
        ({"region": [[0, 1e300], [0, 1], [0, 1]]}, "the region holds"),
        ({"max_restarts": 10**9}, "max_restarts must be at most 1000"),
        ({"jobs": 10**9}, "jobs (worker processes) must be at most 256"),
        ({"jobs": "x"}, "jobs (worker processes) must be an integer"),
        ({"progress": 5}, "progress must be None or a function"),
        ({"engine": np.zeros(2)}, "engine must be one of local, dask"),
    ],
)
def test_capability_map_refuses_absurd_work_at_once(ur5, options, fragment):
    started = time.perf_counter()
    with pytest.raises(InputError, match=re_escape(fragment)):
        reach.capability_map(ur5, **options)
    assert time.perf_counter() - started < 5.0


def test_the_printed_resolution_fits(ur5, arm):
    """The resolution the refusal names passes the check (the map is not computed here)."""
    for robot, orientations in ((ur5, 32), (ur5, 1000), (arm, 1)):
        with pytest.raises(InputError) as info:
            reach.capability_map(robot, resolution=1e-5, orientations=orientations)
        text = str(info.value).split("a resolution of at least ")[1].split(" m")[0]
        first, shape = reach._grid(robot, float(text), None, orientations)
        assert np.prod(shape.astype(float)) * orientations <= reach.MAX_POSES
        assert np.prod(shape.astype(float)) <= reach.MAX_VOXELS


def test_orientation_set_bounded():
    with pytest.raises(InputError, match="orientations must be at most 100,000"):
        reach.orientation_set(10**9)
    assert reach.orientation_set(reach.MAX_ORIENTATIONS).shape == (reach.MAX_ORIENTATIONS, 3, 3)


def test_placement_and_batch_arguments(tmp_path):
    with pytest.raises(InputError, match="would be more than 100000 values"):
        placement.place(LECTURE, x=[0.0, 1e308], y=[0.0])
    with pytest.raises(InputError, match="would be more than 100000 values"):
        placement.place(LECTURE, x=[0.0, 1.0], y=[0.0], step=1e-12)
    with pytest.raises(InputError, match="progress must be None or a function"):
        placement.place(LECTURE, x=[0.0], y=[0.0], progress="x")
    with pytest.raises(InputError, match="text must be the program's YAML text"):
        placement.with_base_pose(None, [0, 0, 0], [0, 0, 0])
    with pytest.raises(InputError, match="xyz must be 3 numbers"):
        placement.with_base_pose("robot: ur5\n", "abc", [0, 0, 0])
    with pytest.raises(InputError, match="jobs"):
        batch.plan_many([LECTURE], jobs=0)
    with pytest.raises(InputError, match="paths must be a non-empty list"):
        batch.plan_many(None)
    with pytest.raises(InputError, match="at most 256"):
        with engines.open_engine("dask", jobs=10**6):
            pass


def test_demo_arguments(tmp_path):
    with pytest.raises(InputError, match="kinplan ships no demo program 'abc'"):
        demos.demo_program("abc")
    with pytest.raises(InputError, match="kinplan ships no demo program None"):
        demos.demo_program(None)
    for dt in (1e-9, 5.0, math.nan, "x"):
        with pytest.raises(InputError, match="dt must be"):
            demos.lecture(out_dir=tmp_path, dt=dt)
    with pytest.raises(InputError, match="progress must be None or a function"):
        demos.weld(out_dir=tmp_path, progress=5)


# ----------------------------------------------------------------------------------------------
# Every argument of every public function, one bad value at a time
# ----------------------------------------------------------------------------------------------

BAD = [
    None, "abc", math.nan, -1, 0, 1e-9, 1e300, 10**9, -(10**9), [], {}, True,
    np.zeros((2, 2)), object(),
]  # fmt: skip


class _Timeout(BaseException):
    pass


def _calls(arm, ur5, motion, tmp_path):
    """(name, function, positional arguments, keyword arguments) of valid calls."""
    plan = sampled(trajectory.cubic(np.zeros(6), np.full(6, 0.1), 1.0), ur5)
    return [
        ("render_html", viewer.render_html, [arm, motion],
         {"markers": None, "fps": 30.0, "title": "x", "max_triangles": 1000}),
        ("save_html", viewer.save_html, [arm, motion, tmp_path / "f.html"],
         {"fps": 30.0, "loop": True, "autoplay": True}),
        ("plot_trajectory", plot.plot_trajectory, [motion],
         {"dt": 0.01, "title": "x", "labels": None, "joint_names": None, "show_knots": True}),
        ("plot_tip_path", plot.plot_tip_path, [np.zeros((3, 2))],
         {"labels": None, "reference": None, "points": None, "title": None}),
        ("write_csv", export.write_csv, [tmp_path / "f.csv", plan, ur5.joint_names], {}),
        ("plot_motion", export.plot_motion, [plan], {"joint_names": None, "title": None}),
        ("urscript", export.urscript, [plan],
         {"period": 0.008, "lookahead_time": 0.1, "gain": 300.0, "start_speed": 0.5}),
        ("joint_trajectory", export.joint_trajectory, [plan], {"joint_names": None}),
        ("write_joint_trajectory", export.write_joint_trajectory, [tmp_path / "f.json", plan],
         {}),
        ("servo_samples", export.servo_samples, [plan], {"period": 0.008}),
        ("check_limits", export.check_limits, [plan], {}),
        ("ros_duration", export.ros_duration, [1.0], {}),
        ("csv_header", export.csv_header, [ur5.joint_names], {}),
        ("orientation_set", reach.orientation_set, [8], {"direction": None, "cone_deg": 0.0}),
        ("with_base_pose", placement.with_base_pose, ["robot: ur5\n", [0, 0, 0], [0, 0, 0]], {}),
        ("demo_program", demos.demo_program, ["weld_seam.yaml"], {}),
    ]  # fmt: skip


def test_every_argument_bad_one_at_a_time(arm, ur5, motion, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # a path argument given as text writes here
    previous = signal.signal(signal.SIGALRM, _raise_timeout)
    failures = []
    try:
        for name, function, args, kwargs in _calls(arm, ur5, motion, tmp_path):
            slots = [(False, k) for k in range(len(args))] + [(True, k) for k in kwargs]
            for keyword, key in slots:
                for bad in BAD:
                    positional, named = list(args), dict(kwargs)
                    if keyword:
                        named[key] = bad
                    else:
                        positional[key] = bad
                    signal.alarm(20)
                    try:
                        function(*positional, **named)
                    except KinplanError as exc:
                        assert str(exc).strip()
                    except _Timeout:
                        failures.append(f"{name}({key}={bad!r:.30}): more than 20 s")
                    except Exception as exc:
                        failures.append(f"{name}({key}={bad!r:.30}): {type(exc).__name__}: {exc}")
                    finally:
                        signal.alarm(0)
    finally:
        signal.signal(signal.SIGALRM, previous)
    assert not failures, "\n".join(failures)


def _raise_timeout(*_: object) -> None:
    raise _Timeout


def re_escape(text: str) -> str:
    import re

    return re.escape(text)
