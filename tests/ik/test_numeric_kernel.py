"""The compiled numerical IK (kinplan.ik.numeric_kernel) against Pinocchio and against the
Python loop of IKSolver it is a twin of."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from wrist_arms import wrist_arm_urdf

import kinplan
from kinplan.ik import numeric_kernel
from kinplan.model.sources import example_robot_data_dir

pytestmark = pytest.mark.skipif(not numeric_kernel.available(), reason="numba switched off")

ROBOTS = example_robot_data_dir() / "example-robot-data" / "robots"


@pytest.fixture(scope="module")
def z1() -> kinplan.Robot:
    return kinplan.load_robot(ROBOTS / "z1_description/urdf/z1.urdf")


@pytest.fixture(scope="module")
def offset_wrist(tmp_path_factory) -> kinplan.Robot:
    """A 6R arm whose axis 6 misses the wrist centre by 0.05 m and whose axes 4 and 5 do not
    meet either (joint 5 moved 5 cm across both): no closed form fits, not even the 1-D search."""
    text = wrist_arm_urdf(5).replace(
        '<child link="l6"/><origin xyz="0 0 0"', '<child link="l6"/><origin xyz="0 0 0.05"'
    )
    pattern = r'(<joint name="j5"[^>]*>.*?<origin xyz=")(\S+) (\S+) (\S+)"'
    text, count = re.subn(pattern, lambda m: f'{m[1]}{m[2]} {m[3]} {float(m[4]) + 0.05!r}"', text)
    assert count == 1
    path = tmp_path_factory.mktemp("offset") / "offset_wrist.urdf"
    path.write_text(text)
    robot = kinplan.load_robot(path, tip="tool0")
    assert robot.closed_form_ik is None
    return robot


def test_log_rotation_equals_pinocchio_at_every_angle():
    rng = np.random.default_rng(0)
    out = np.empty(3)
    angles = np.concatenate([rng.uniform(0, np.pi, 300), np.pi - np.logspace(-12, -1, 40), [0.0]])
    for angle in angles:
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        rotation = pin.exp3(angle * axis)
        numeric_kernel.log_rotation(rotation, out)
        expected = pin.log3(rotation)
        if angle > np.pi - 1e-6:  # ±axis both valid at a half turn
            assert min(np.abs(out - expected).max(), np.abs(out + expected).max()) < 1e-6
        else:
            np.testing.assert_allclose(out, expected, atol=1e-9)


@pytest.mark.parametrize("which", ["z1", "offset_wrist", "ur5"])
def test_screw_kinematics_equal_pinocchio(which, request):
    robot = kinplan.load_robot("ur5") if which == "ur5" else request.getfixturevalue(which)
    found = numeric_kernel.screw_constants(robot.model, robot.tip_id)
    assert found is not None
    screws, tool = found
    rng = np.random.default_rng(1)
    for _ in range(50):
        q = robot.random_configuration(rng)
        pose, jacobian = np.empty((4, 4)), np.empty((6, robot.nq))
        numeric_kernel.kinematics(q, screws[: robot.nq], screws[robot.nq :], tool, pose, jacobian)
        np.testing.assert_allclose(pose, robot.fk(q).homogeneous, atol=1e-12)
        np.testing.assert_allclose(jacobian, robot.jacobian(q), atol=1e-12)


@pytest.mark.parametrize("which", ["z1", "offset_wrist"])
def test_compiled_solve_is_the_python_loop(which, request):
    """Same targets and seeds: the same success, attempts and iterations, and the same answer
    within the tolerances' reach."""
    robot = request.getfixturevalue(which)
    compiled = robot.ik_solver
    python = kinplan.ik.IKSolver(robot.model, robot.tip_id, robot.lower, robot.upper)
    python._kernel = False  # the Python loop only
    rng = np.random.default_rng(2)
    for k in range(150):
        target = robot.fk(robot.random_configuration(rng))
        seed = robot.random_configuration(rng)
        a = compiled.solve(target.translation, target.rotation, seed)
        b = python.solve(target.translation, target.rotation, seed)
        assert a.success and b.success, k
        assert (a.attempts, a.iterations) == (b.attempts, b.iterations), k
        np.testing.assert_allclose(a.q, b.q, atol=1e-5, err_msg=str(k))
        assert a.position_error <= 1e-6 and a.rotation_error <= 1e-6
        assert robot.within_limits(a.q, tolerance=0.0)
    # position only
    target = robot.fk(robot.random_configuration(rng)).translation
    a = compiled.solve(target, None, robot.neutral())
    b = python.solve(target, None, robot.neutral())
    assert a.success and b.success and a.iterations == b.iterations


def test_unreachable_target_fails_like_the_python_loop(z1):
    far = np.array([5.0, 0.0, 0.0])
    python = kinplan.ik.IKSolver(z1.model, z1.tip_id, z1.lower, z1.upper)
    python._kernel = False
    a = z1.ik_solver.solve(far, None, z1.neutral())
    b = python.solve(far, None, z1.neutral())
    assert not a.success and not b.success
    np.testing.assert_allclose(a.q, b.q)


def test_the_rescue_runs_compiled_like_the_python_loop():
    """An arm whose limits stop a hair short of a whole turn (±3.14159), solved with one
    restart: many targets fail the seed's attempt and the restart; the rescue (the polish, then
    the attempt without limits, turned by whole turns into them) solves some of them, the
    others fail. The compiled solve runs the rescue too: the same attempts and iterations as
    the Python loop and the same answer in another rounding, for the rescued targets and the
    failures alike."""
    robot = kinplan.load_robot(Path(__file__).parents[1] / "urdf" / "skewed_axes.urdf")
    compiled = kinplan.ik.IKSolver(robot.model, robot.tip_id, robot.lower, robot.upper)
    assert compiled.compiled

    def python_step(*args, **kwargs):
        pytest.fail("the compiled solve left work to the Python loop")

    compiled.descend = python_step  # type: ignore[method-assign]
    python = kinplan.ik.IKSolver(robot.model, robot.tip_id, robot.lower, robot.upper)
    python._kernel = False  # the Python loop only
    rng = np.random.default_rng(0)
    rescued = failed = 0
    for k in range(200):
        target = robot.fk(robot.random_configuration(rng))
        a = compiled.solve(target.translation, target.rotation, robot.neutral(), max_restarts=1)
        if a.success and a.attempts < 3:
            continue  # solved by an attempt (the twin test above covers those)
        rescued, failed = rescued + a.success, failed + (not a.success)
        b = python.solve(target.translation, target.rotation, robot.neutral(), max_restarts=1)
        assert a.success == b.success, k
        assert (a.attempts, a.iterations) == (b.attempts, b.iterations), k
        np.testing.assert_allclose(a.q, b.q, rtol=0, atol=1e-6, err_msg=str(k))
        if a.success:
            assert a.attempts == 3
            assert a.position_error <= 1e-6 and a.rotation_error <= 1e-6
            assert robot.within_limits(a.q, tolerance=0.0)
    assert rescued >= 10 and failed >= 10, (rescued, failed)  # 32 and 45 with this seed


def test_limits_of_a_half_turn_do_not_stop_the_solve():
    """skewed_axes's joints stop a hair short of ±π: 3,000 seeded random reachable targets from
    the default seed and from random seeds. Attempts that must take a joint across ±π turn it
    by a whole turn into the limits (clamped there, 1.3-2 % of these targets failed every
    attempt and the rescue): at least 99.8 % succeed, each within the limits and on the
    target (the batch's own FK check, itself tested against Pinocchio)."""
    robot = kinplan.load_robot(Path(__file__).parents[1] / "urdf" / "skewed_axes.urdf")
    rng = np.random.default_rng(11)
    q_true = np.array([robot.random_configuration(rng) for _ in range(3000)])
    targets = np.array([robot.fk(q).homogeneous for q in q_true])
    seeds = np.array([robot.random_configuration(rng) for _ in range(3000)])
    for seed in (None, seeds):
        q, success = robot.ik_batch(targets, q_seed=seed)
        assert success.mean() >= 0.998, success.mean()
        assert np.all(q[success] >= robot.lower) and np.all(q[success] <= robot.upper)
        reached = np.array([robot.fk(row).homogeneous for row in q[success]])
        assert np.abs(reached - targets[success]).max() < 2e-6
