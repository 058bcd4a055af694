"""The compiled lean loop (:mod:`cartesian.lean_kernel`) against Pinocchio and the Python loop.

Its screw kinematics must equal Pinocchio's tool pose and Jacobian, its solve numpy's, and every
plan made with it must equal the plan made by the Python lean loop (the kernel switched off):
the same status, events and samples, q within 1e-9 rad — on the four task shapes it serves
(a 7-joint arm with a 6-D and a 3-D task: minimum norm; a 6-joint arm: square; a 5-joint arm
with a 6-D task: least squares).
"""

from __future__ import annotations

import functools

import numpy as np
import pinocchio as pin
import pytest
from conftest import TESTS, cached_robot
from test_follow_lean import _lines
from test_follow_vectorised import _assert_same

import cartesian
import kinplan
from cartesian import batch_track, lean_kernel, lean_track
from cartesian.tracker import adams_bashforth_weights

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


# ------------------------------------------------------------------ the compiled parts alone
# The plans above compare the kernel with the Python loop, which takes over at any point the
# kernel leaves: a kernel that gives up too often, or solves a point its own way within the
# tolerances, still makes the same plans. The tests below check each compiled part against an
# independent answer instead (numpy, Pinocchio, IKSolver.descend, the tracker's weights).

#: (arm, position only) of each task shape the kernel serves; the planar 2R's pose task has
#: the rows x, y and the rotation about z (not a leading block of the tool twist).
TASKS = {
    "wide": ("panda", False),
    "wide position-only": ("panda", True),
    "square": ("ur5", False),
    "square near the wrist singularity": ("ur5", False),
    "tall": ("ur5 locked wrist", False),
    "tall planar rows 0 1 5": ("planar_2r", False),
    "square planar position": ("planar_2r", True),
}


@functools.cache
def _task_arm(name: str) -> kinplan.Robot:
    if name == "ur5 locked wrist":
        return kinplan.load_robot("ur5", locked_joints={"wrist_3_joint": 0.3})
    return cached_robot(name)


def _bounds(robot: kinplan.Robot) -> tuple[np.ndarray, np.ndarray]:
    return np.maximum(robot.lower, -np.pi), np.minimum(robot.upper, np.pi)


def _point_run(kernel, robot, guess, position, rotation, velocity=None) -> lean_kernel.Run:
    """A run of three points whose last is to be solved, predicted at ``guess`` (rates zero
    before it), aiming at ``position`` and ``rotation`` (None: position only), with task
    velocity ``velocity`` (default zero)."""
    r = len(kernel.rows)
    velocities = np.zeros((3, r))
    if velocity is not None:
        velocities[2] = velocity
    run = lean_kernel.Run.empty(
        np.array([0.0, 1.0, 2.0]),
        velocities,
        np.tile(position, (3, 1)),
        None if rotation is None else np.tile(rotation, (3, 1, 1)),
        robot.nq,
    )
    run.q[:2] = guess
    run.rates[:2] = 0.0
    return run


def test_lu_solve_pivots_on_the_largest_entry_of_each_column():
    """300 seeded matrices near a permutation (one entry of magnitude 0.5–2 per row and
    column, the others ~1e-10): every column needs the row of its large entry as pivot (any
    other pivot is ~1e-10 and loses ten digits); x within 1e-14 of numpy's."""
    rng = np.random.default_rng(4)
    for _ in range(300):
        m, k = int(rng.integers(2, 8)), int(rng.integers(1, 4))
        a = np.eye(m)[rng.permutation(m)] * rng.uniform(0.5, 2.0, m) * rng.choice([-1, 1], m)
        a += 1e-10 * rng.normal(size=(m, m)) * (a == 0)
        b = rng.normal(size=(m, k))
        x = lean_kernel.lu_solve(a, b)
        np.testing.assert_allclose(x, np.linalg.solve(a, b), rtol=0, atol=1e-14)


def test_rotation_error_is_log3_within_a_quarter_turn():
    """The rotation vector taking the tool's rotation to the target's equals ``pin.log3`` (and
    the rotation applied) for seeded random rotations of 0 to 1.5 rad and tiny ones, θ/sin θ
    included; beyond a quarter turn it declines (False: the point is left to Python)."""
    rng = np.random.default_rng(5)
    error = np.zeros(6)
    for angle in np.concatenate([[0.0, 1e-12, 1e-9, 1e-7, 1e-4], rng.uniform(0.0, 1.5, 200)]):
        axis = rng.normal(size=3)
        w = angle * axis / np.linalg.norm(axis)
        pose = pin.exp3(rng.normal(size=3))
        target = pin.exp3(w) @ pose
        assert lean_kernel._rotation_error(target, pose, error)
        np.testing.assert_allclose(error[3:], pin.log3(target @ pose.T), rtol=0, atol=1e-13)
        np.testing.assert_allclose(error[3:], w, rtol=0, atol=1e-12)
    for angle in rng.uniform(np.pi / 2 + 1e-6, np.pi, 50):
        axis = rng.normal(size=3)
        pose = pin.exp3(rng.normal(size=3))
        target = pin.exp3(angle * axis / np.linalg.norm(axis)) @ pose
        assert not lean_kernel._rotation_error(target, pose, error)


@pytest.mark.parametrize("task", TASKS)
def test_a_solved_point_gets_its_jacobian_pseudo_inverse_and_rates(task):
    """20 seeded configurations per task, each the prediction of a point whose target is its
    own tool pose (solved without Newton steps): q is the prediction, and the Jacobian, tool
    position, pseudo-inverse of the task rows and rates J⁺v equal Pinocchio's and
    ``numpy.linalg.pinv``'s within the rounding of a backward-stable solve (1e-12 × cond).
    Near the UR5's wrist singularity (θ5 ~ 1e-6–1e-4 rad, cond 1e4–1e7) a pseudo-inverse
    that squares the condition number (Jᵀ(JJᵀ)⁻¹ for a square J) fails."""
    name, position_only = TASKS[task]
    robot = _task_arm(name)
    rows = robot.task_rows(position_only)
    kernel = lean_kernel.kernel_for(robot, rows)
    assert kernel is not None
    rng = np.random.default_rng(9)
    low, high = _bounds(robot)
    for q in rng.uniform(low, high, size=(20, robot.nq)):
        if "singularity" in task:
            q[4] = rng.choice([-1.0, 1.0]) * 10 ** rng.uniform(-6.0, -4.0)
        pose = robot.fk(q)
        velocity = rng.normal(size=len(rows))
        rotation = None if position_only else pose.rotation
        run = _point_run(kernel, robot, q, pose.translation, rotation, velocity)
        assert lean_kernel.advance(kernel, run, 2, (1e-7, 1e-7)) == 3
        np.testing.assert_array_equal(run.q[2], q)
        J = robot.jacobian(q)
        np.testing.assert_allclose(run.jacobians[2], J, rtol=0, atol=1e-12)
        np.testing.assert_allclose(run.tools[2], pose.translation, rtol=0, atol=1e-12)
        pinv = np.linalg.pinv(J[rows])
        scale = 1e-12 * np.linalg.cond(J[rows]) * np.abs(pinv).max()
        np.testing.assert_allclose(run.pinvs[2], pinv, rtol=0, atol=scale)
        rates = pinv @ velocity
        np.testing.assert_allclose(run.rates[2], rates, rtol=0, atol=len(rows) * scale)


def test_a_point_left_to_python_holds_the_adams_bashforth_guess(panda, monkeypatch):
    """With no Newton iterations and an unreachable target the kernel leaves the point at
    once, its row of q holding the prediction: the two-step Adams–Bashforth of the tracker's
    weights, on a uniform grid and on uneven ones (bisected traces, retimed plans)."""
    monkeypatch.setattr(lean_kernel, "_NEWTON", lean_kernel._NEWTON * [1, 1, 1, 0, 1])
    kernel = lean_kernel.kernel_for(panda, panda.task_rows(False))
    rng = np.random.default_rng(2)
    for grid in ([0.0, 0.1, 0.2], [0.0, 0.1, 0.15], [1.0, 1.05, 1.25]):
        run = _point_run(kernel, panda, np.zeros(7), np.full(3, 9.0), np.eye(3))
        run.grid[:] = grid
        run.q[:2] = rng.normal(size=(2, 7))
        run.rates[:2] = rng.normal(size=(2, 7))
        assert lean_kernel.advance(kernel, run, 2, (1e-7, 1e-7)) == 2
        a, b = adams_bashforth_weights(np.diff(grid))[2]
        guess = run.q[1] + a * run.rates[1] + b * run.rates[0]
        np.testing.assert_allclose(run.q[2], guess, rtol=0, atol=1e-14)


def test_a_point_exactly_at_the_tolerance_is_accepted(panda):
    """A prediction whose tool is exactly 2⁻²⁰ m off its target in x (and on it otherwise; the
    sums exact in binary) meets a position tolerance of 2⁻²⁰ m: accepted without a Newton
    step, as ``Evaluation.within`` (≤) accepts it in the Python loop."""
    kernel = lean_kernel.kernel_for(panda, panda.task_rows(False))
    q = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.78])
    pose, jacobian = np.empty((4, 4)), np.empty((6, 7))
    lean_kernel.kinematics(q, kernel.directions, kernel.points, kernel.tool, pose, jacobian)
    tolerance = 2.0**-20
    target = pose[:3, 3] + [tolerance, 0.0, 0.0]
    assert target[0] - pose[0, 3] == tolerance
    run = _point_run(kernel, panda, q, target, pose[:3, :3])
    assert lean_kernel.advance(kernel, run, 2, (tolerance, 1e-7)) == 3
    np.testing.assert_array_equal(run.q[2], q)


@pytest.mark.parametrize("name", ["panda", "ur5"])
def test_a_joint_step_beyond_max_step_is_left_to_python(name):
    """Points predicted exactly at their target (no Newton step), one joint stepping 0.2 rad
    from the point before and the others up to 0.01 rad: left to Python under a max_step of
    0.199 rad, solved under 0.201 rad; a step of exactly max_step is solved (the Python
    trace's test is ``>``)."""
    robot = cached_robot(name)
    kernel = lean_kernel.kernel_for(robot, robot.task_rows(False))
    rng = np.random.default_rng(6)
    low, high = _bounds(robot)
    for case in range(20):
        q = rng.uniform(low + 0.5, high - 0.5)
        step = rng.uniform(-0.01, 0.01, robot.nq)
        step[case % robot.nq] = rng.choice([-0.2, 0.2])
        if case == 0:  # binary fractions: the prediction q[1] + 1.5 step − 0.5 step is exact
            q, step = np.full(robot.nq, 0.5), np.zeros(robot.nq)
            step[1] = 0.25
        pose = robot.fk(q)
        largest = np.abs(step).max()
        limits = [(largest - 1e-3, 2), (largest + 1e-3, 3)] + [(largest, 3)] * (case == 0)
        for max_step, end in limits:
            run = _point_run(kernel, robot, q - step, pose.translation, pose.rotation)
            run.q[0] = q - 2 * step
            run.rates[:2] = step  # predicted at q − step + 1.5 step − 0.5 step = q
            assert lean_kernel.advance(kernel, run, 2, (1e-7, 1e-7), max_step) == end, case
            np.testing.assert_allclose(run.q[2], q, rtol=0, atol=1e-14)


@pytest.mark.parametrize("patience", [5, 1])
@pytest.mark.parametrize(
    "task, scales",
    [
        ("wide", (1e-3, 1e-2, 0.1, 0.3)),
        ("square", (1e-3, 1e-2, 0.1, 0.3)),
        ("tall", (1e-3, 1e-2, 0.1, 0.3)),
        ("wide position-only", (1e-2, 0.3, 1.0, 2.0)),
    ],
)
def test_the_newton_steps_are_those_of_descend(task, scales, patience, monkeypatch):
    """240 seeded guesses per task, perturbed from a solution by up to 0.3 rad (2 rad for a
    position-only task, where no quarter-turn rule applies: steps capped, up to 12
    iterations), an eighth of the targets beyond reach: the kernel solves a point exactly when
    ``IKSolver.descend`` without limits converges (the tracker's Newton steps: gain, floor,
    step cap, stall test, 12 iterations; patience 5 and 1), at its q within 1e-9 rad; else it
    leaves the point with its guess. Guesses whose rotation is off by more than 1 rad are
    skipped (the kernel leaves rotation errors beyond a quarter turn to Pinocchio)."""
    monkeypatch.setattr(lean_kernel, "_NEWTON", lean_kernel._NEWTON.copy())
    lean_kernel._NEWTON[4] = patience
    name, position_only = TASKS[task]
    robot = _task_arm(name)
    kernel = lean_kernel.kernel_for(robot, robot.task_rows(position_only))
    rng = np.random.default_rng(12)
    low, high = _bounds(robot)
    iterations = []
    for case in range(240):
        q = rng.uniform(low, high)
        guess = q + rng.normal(size=robot.nq) * scales[case % len(scales)]
        pose = robot.fk(q)
        position = pose.translation * (1.5 if case % 8 == 7 else 1.0)
        rotation = None if position_only else pose.rotation
        if rotation is not None:
            if np.linalg.norm(pin.log3(rotation @ robot.fk(guess).rotation.T)) > 1.0:
                continue
        run = _point_run(kernel, robot, guess, position, rotation)
        solved = lean_kernel.advance(kernel, run, 2, (1e-7, 1e-7)) == 3
        expected, converged, *_, count, _ = robot.ik_solver.descend(
            guess, position, rotation, 1e-7, 1e-7, 12, clamp=False, stall_iterations=patience
        )
        assert solved == converged, case
        if solved:
            np.testing.assert_allclose(run.q[2], expected, rtol=0, atol=1e-9, err_msg=str(case))
        else:
            np.testing.assert_array_equal(run.q[2], guess)
        iterations.append(count if converged else -1)
    assert min(iterations) == -1 and max(iterations) >= 6, iterations


def test_a_step_that_barely_lowers_the_cost_counts_as_a_stall(panda, monkeypatch):
    """A guess (position only) whose fourth Newton step lowers the cost by 0.04 % only (less
    than the 0.1 % the stall test asks) before the steps converge: with a patience of one
    stalled step both ``IKSolver.descend`` and the kernel give up there; with two both
    converge, to the same q."""
    guess = np.array([-1.3739696580411063, 1.0909447090898867, 1.4346635192542294,
                      -2.9273123620980916, -0.3310738023214561, 2.4358246500416083,
                      -2.407223930862907])  # fmt: skip
    target = np.array([-0.13953522992123124, 0.3679837003478754, 0.7618298232684688])
    kernel = lean_kernel.kernel_for(panda, panda.task_rows(True))
    monkeypatch.setattr(lean_kernel, "_NEWTON", lean_kernel._NEWTON.copy())
    for patience, end in ((1, 2), (2, 3)):
        lean_kernel._NEWTON[4] = patience
        expected, converged, *_ = panda.ik_solver.descend(
            guess, target, None, 1e-7, 1e-7, 12, clamp=False, stall_iterations=patience
        )
        assert converged == (end == 3)
        run = _point_run(kernel, panda, guess, target, None)
        assert lean_kernel.advance(kernel, run, 2, (1e-7, 1e-7)) == end, patience
        np.testing.assert_allclose(run.q[2], expected if converged else guess, rtol=0, atol=1e-9)


def test_a_singular_matrix_gives_non_finite_values_not_an_exception(ur5):
    """An exactly singular system: lu_solve returns inf/NaN (numpy's division), and the
    compiled loop at an exactly singular UR5 configuration leaves the point's rates
    non-finite rather than raising (the monitor's singularity check then declines the path)."""
    x = lean_kernel.lu_solve(np.array([[0.0, 0.0], [1.0, 1.0]]), np.ones((2, 1)))
    assert not np.isfinite(x).all()
    kernel = lean_kernel.kernel_for(ur5, ur5.task_rows(False))
    q0 = np.zeros(6)  # stretched and wrist-aligned: J is exactly singular
    pose = ur5.fk(q0)
    run = lean_kernel.Run.empty(
        np.array([0.0, 1.0, 2.0]),
        np.zeros((3, 6)),
        np.tile(pose.translation, (3, 1)),
        np.tile(pose.rotation, (3, 1, 1)),
        6,
    )
    run.q[:2] = q0
    run.rates[:2] = 0.0
    assert lean_kernel.advance(kernel, run, 2, (1e-7, 1e-7)) == 3
    assert not np.isfinite(run.pinvs[2]).all()
