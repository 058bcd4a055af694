"""The compiled lean loop (:mod:`cartesian.lean_kernel`) against Pinocchio and the Python loop.

Its screw kinematics must equal Pinocchio's tool pose and Jacobian, its solve numpy's, and every
plan made with it must equal the plan made by the Python lean loop (the kernel switched off):
the same status, events and samples, q within 1e-9 rad — on the four task shapes it serves
(a 7-joint arm with a 6-D and a 3-D task: minimum norm; a 6-joint arm: square; a 5-joint arm
with a 6-D task: least squares).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import TESTS, cached_robot
from test_follow_lean import _lines
from test_follow_vectorised import _assert_same

import cartesian
import kinplan
from cartesian import batch_track, lean_kernel, lean_track

URDF = TESTS / "urdf"
#: Serial arms of revolute joints (the kernel's), with and without unbounded joints.
ARMS = ["panda", "ur5", "skewed_axes", "continuous_arm"]


def _arm(name: str) -> kinplan.Robot:
    if name in ("panda", "ur5"):
        return cached_robot(name)
    return kinplan.load_robot(URDF / f"{name}.urdf")


@pytest.mark.parametrize("name", ARMS)
def test_screw_kinematics_equal_pinocchio(name):
    """1,000 seeded random configurations per arm: tool pose and LOCAL_WORLD_ALIGNED Jacobian
    within 1e-12 of Pinocchio's (both exact up to rounding)."""
    robot = _arm(name)
    screws = lean_kernel.checked_screws(robot)
    assert screws is not None
    rng = np.random.default_rng(7)
    low = np.where(np.isfinite(robot.lower), robot.lower, -4.0)
    high = np.where(np.isfinite(robot.upper), robot.upper, 4.0)
    pose, jacobian = np.empty((4, 4)), np.empty((6, robot.nq))
    for q in rng.uniform(low, high, size=(1000, robot.nq)):
        lean_kernel.kinematics(q, *screws, pose, jacobian)
        np.testing.assert_allclose(pose, robot.fk(q).homogeneous, rtol=0, atol=1e-12)
        np.testing.assert_allclose(jacobian, robot.jacobian(q), rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", ["prismatic_gantry", "mimic_arm"])
def test_arms_without_revolute_screws_are_left_to_the_python_loop(name):
    assert lean_kernel.checked_screws(kinplan.load_robot(URDF / f"{name}.urdf")) is None


def test_the_switch_turns_the_kernel_off(panda, monkeypatch):
    rows = panda.task_rows(False)
    assert lean_kernel.kernel_for(panda, rows) is not None
    monkeypatch.setattr(lean_kernel, "ENABLED", False)
    assert lean_kernel.kernel_for(panda, rows) is None


def test_lu_solve_equals_numpy():
    """2,000 seeded random systems (sizes 1–7, 1–7 right-hand sides, condition ≤ 1e4, some
    with a zero leading pivot so that rows must be swapped): x within 1e-11 relative of
    numpy's, and the inputs left unchanged."""
    rng = np.random.default_rng(3)
    for case in range(2000):
        m, k = int(rng.integers(1, 8)), int(rng.integers(1, 8))
        u, _, vt = np.linalg.svd(rng.normal(size=(m, m)))
        a = u @ np.diag(np.logspace(0, -4 * rng.random(), m)) @ vt
        if case % 4 == 0 and m > 1:  # a zero pivot at the top: pivoting needed
            a[0, 0] = 0.0
        b = rng.normal(size=(m, k))
        a_before, b_before = a.copy(), b.copy()
        x = lean_kernel.lu_solve(a, b)
        expected = np.linalg.solve(a, b)
        scale = np.abs(expected).max()
        np.testing.assert_allclose(x, expected, rtol=0, atol=1e-11 * np.linalg.cond(a) * scale)
        np.testing.assert_array_equal(a, a_before)
        np.testing.assert_array_equal(b, b_before)


def _kernel_and_python_plans(robot, path, monkeypatch, **options):
    """(plan with the kernel, plan with the Python lean loop, points the kernel solved)."""
    advanced: list[int] = []
    advance = lean_kernel.advance

    def spy(kernel, run, k, *args, **kwargs):
        end = advance(kernel, run, k, *args, **kwargs)
        advanced.append(end - k)
        return end

    with monkeypatch.context() as patch:
        patch.setattr(batch_track, "ENABLED", False)  # the UR5's own fast path
        patch.setattr(lean_kernel, "advance", spy)
        compiled = cartesian.follow(robot, path, **options)
        patch.setattr(lean_kernel, "ENABLED", False)
        python = cartesian.follow(robot, path, **options)
    return compiled, python, sum(advanced)


@pytest.mark.parametrize(
    "name, options",
    [
        ("panda", {}),
        ("panda", {"position_only": True}),
        ("ur5", {}),
        ("ur5 locked wrist", {}),
    ],
    ids=["wide", "wide position-only", "square", "tall"],
)
def test_compiled_and_python_lean_loops_make_the_same_plans(name, options, monkeypatch):
    """60 random lines per task shape (ok and failing ones, see test_follow_lean._lines):
    the same plan with the kernel and without, and the kernel did advance most samples."""
    if name == "ur5 locked wrist":
        robot = kinplan.load_robot("ur5", locked_joints={"wrist_3_joint": 0.3})
    else:
        robot = _arm(name)
    kernel = lean_kernel.kernel_for(robot, robot.task_rows(options.get("position_only", False)))
    assert kernel is not None
    shapes = {7: lean_kernel.WIDE, 6: lean_kernel.SQUARE, 5: lean_kernel.TALL}
    assert kernel.shape == shapes[robot.nq]
    advanced = samples = 0
    for what, path, q0, line_options in _lines(robot, 60, seed=31):
        compiled, python, count = _kernel_and_python_plans(
            robot, path, monkeypatch, q_seed=q0, **line_options, **options
        )
        _assert_same(compiled, python, what)
        np.testing.assert_allclose(compiled.q, python.q, rtol=0, atol=1e-9, err_msg=what)
        if compiled.ok:
            advanced += count
            samples += len(compiled.t)
    assert advanced >= 0.5 * samples, (advanced, samples)


def _benchmark_line(panda):
    q0 = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.78])
    start = panda.fk(q0)
    return cartesian.Line(start, pin.SE3(start.rotation, start.translation + [0, 0.3, 0])), q0


@pytest.mark.parametrize("newton", [True, False], ids=["newton compiled", "newton in python"])
def test_the_benchmark_line_equals_the_python_loop(panda, newton, monkeypatch):
    """The panda benchmark line (1,001 samples): with the Newton steps compiled the kernel
    solves every sample after the first two in one run; with them off (no iterations) it
    stops at each sample whose prediction misses the tolerances, the Python loop corrects it
    and the kernel resumes after it. Either way the plan equals the Python loop's (q to
    1e-12 rad, q̇ and q̈ to rounding)."""
    line, q0 = _benchmark_line(panda)
    if not newton:
        monkeypatch.setattr(lean_kernel, "_NEWTON", lean_kernel._NEWTON * [1, 1, 1, 0, 1])
    stops: list[int] = []
    advance = lean_kernel.advance

    def spy(kernel, run, k, *args, **kwargs):
        end = advance(kernel, run, k, *args, **kwargs)
        stops.append(end)
        return end

    monkeypatch.setattr(lean_kernel, "advance", spy)
    compiled = cartesian.follow(panda, line, duration=1.0, dt=0.001, q_seed=q0)
    monkeypatch.setattr(lean_kernel, "ENABLED", False)
    python = cartesian.follow(panda, line, duration=1.0, dt=0.001, q_seed=q0)
    assert compiled.ok and stops[-1] == 1001
    if newton:
        assert stops == [1001]
    else:
        assert len(stops) > 3 and all(2 <= stop < 1001 for stop in stops[:-1])
    np.testing.assert_allclose(compiled.q, python.q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(compiled.qd, python.qd, rtol=0, atol=1e-10)
    np.testing.assert_allclose(compiled.qdd, python.qdd, rtol=0, atol=1e-8)
    assert lean_track.ENABLED


@pytest.mark.parametrize("name", ["panda", "skewed_axes"])
def test_compiled_and_python_geometric_traces_agree(name, monkeypatch):
    """40 random lines per arm through :func:`cartesian.check_reachability` (the geometric
    trace retiming makes first; points bisected where a joint steps more than 0.1 rad): the
    same points, status and events with the kernel and without, q within 1e-9 rad."""
    robot = _arm(name)
    compiled_points = 0
    for what, path, q0, _ in _lines(robot, 40, seed=5):
        with monkeypatch.context() as patch:
            compiled = cartesian.check_reachability(robot, path, q_seed=q0)
            patch.setattr(lean_kernel, "ENABLED", False)
            python = cartesian.check_reachability(robot, path, q_seed=q0)
        assert compiled.status == python.status, what
        assert [e.message for e in compiled.events] == [e.message for e in python.events], what
        np.testing.assert_array_equal(compiled.s, python.s, err_msg=what)
        np.testing.assert_allclose(compiled.q, python.q, rtol=0, atol=1e-9, err_msg=what)
        compiled_points += len(compiled.s) if compiled.ok else 0
    assert compiled_points > 0


def test_kinplan_jit_0_switches_both_compiled_loops_off():
    """``KINPLAN_JIT=0`` in the environment: the pure-Python loops run (read at import)."""
    import os
    import subprocess
    import sys

    code = (
        "from cartesian import lean_kernel; from kinplan.ik import panda_kernel; "
        "print(lean_kernel.ENABLED, panda_kernel.available())"
    )
    for value, expected in (("0", "False False"), ("1", "True True")):
        env = {**os.environ, "KINPLAN_JIT": value}
        done = subprocess.run(
            [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
        )
        assert done.stdout.strip() == expected
