"""Closed-form IK (kinplan.ik closed forms): every solution checked with Pinocchio FK."""

from __future__ import annotations

import functools
import itertools
import logging
import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import cached_robot

import kinplan
from kinplan.errors import InputError
from kinplan.ik import URIK, ClosedFormIK, PandaIK, Planar2RIK, analytic_solver_for, wrap_angle
from kinplan.ik.ur import NeedsBatch

UR_ARMS = ["ur3", "ur5", "ur10"]


@functools.cache
def solver_of(name: str):
    return analytic_solver_for(cached_robot(name))


def pose_errors(robot: kinplan.Robot, q: np.ndarray, target: pin.SE3) -> tuple[float, float]:
    """Position error [m] and rotation error [rad] of FK(q) against ``target``."""
    reached = robot.fk(q)
    position = float(np.linalg.norm(reached.translation - target.translation))
    rotation = float(np.linalg.norm(pin.log3(reached.rotation.T @ target.rotation)))
    return position, rotation


def assert_solves(robot, solutions: np.ndarray, target: pin.SE3, tol: float = 1e-9) -> None:
    for q in solutions:
        assert robot.within_limits(q, tolerance=0.0), q
        position, rotation = pose_errors(robot, q, target)
        assert position < tol and rotation < tol, (q, position, rotation)


def contains(solutions: np.ndarray, q: np.ndarray, tol: float = 1e-7) -> bool:
    """Whether ``q`` equals one of ``solutions`` modulo 2π per joint."""
    return any(np.max(np.abs(wrap_angle(s - q))) < tol for s in solutions)


def brute_force_nearest(robot, solutions: np.ndarray, q_ref: np.ndarray) -> np.ndarray:
    """Every 2π-equivalent within limits of every solution; the one nearest q_ref (Σ Δq²)."""
    best, best_cost = None, np.inf
    for s in solutions:
        options = [
            [v + 2 * np.pi * k for k in range(-3, 4) if lo <= v + 2 * np.pi * k <= hi]
            for v, lo, hi in zip(s, robot.lower, robot.upper)
        ]
        for q in itertools.product(*options):
            cost = float(np.sum((np.array(q) - q_ref) ** 2))
            if cost < best_cost:
                best, best_cost = np.array(q), cost
    return best


def follow_per_sample(solver, positions, rotations, q_ref) -> np.ndarray:
    """The reference semantics of nearest_batch: nearest() sample by sample."""
    out = np.full((len(positions), solver.nq), np.nan)
    for i, position in enumerate(positions):
        q = solver.nearest(position, None if rotations is None else rotations[i], q_ref)
        if q is not None:
            out[i] = q_ref = q
    return out


# ---------------------------------------------------------------------------- recognition
def test_solver_kinds():
    assert all(isinstance(solver_of(name), URIK) for name in UR_ARMS)
    assert isinstance(solver_of("planar_2r"), Planar2RIK)
    assert isinstance(solver_of("panda"), PandaIK)  # q7-parametrised (kinplan.ik.panda)
    assert analytic_solver_for(kinplan.planar_arm([1.0, 1.0, 1.0])) is None


def test_planar_lengths_match_robot(planar_2r):
    assert solver_of("planar_2r").link_lengths == pytest.approx(planar_2r.link_lengths)
    arm = kinplan.planar_arm([0.7, 0.25])
    assert analytic_solver_for(arm).link_lengths == pytest.approx([0.7, 0.25])


# ---------------------------------------------------------------------------- UR family
@pytest.mark.parametrize("name", UR_ARMS)
def test_ur_random_configurations(name):
    robot, solver = cached_robot(name), solver_of(name)
    rng = np.random.default_rng(20240611)
    for _ in range(500):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        solutions = solver.solutions(target.translation, target.rotation)
        assert 1 <= len(solutions) <= 8
        assert contains(solutions, q), (q, solutions)
        assert_solves(robot, solutions, target)


@pytest.mark.parametrize("name", UR_ARMS)
def test_ur_generic_pose_has_eight_solutions(name):
    robot, solver = cached_robot(name), solver_of(name)
    q = np.array([0.3, -1.2, 1.4, -0.8, 1.1, 0.4])
    target = robot.fk(q)
    assert len(solver.solutions(target.translation, target.rotation)) == 8


def test_ur_unreachable_gives_no_solution(ur5):
    solver = solver_of("ur5")
    assert solver.solutions(np.array([2.0, 0.0, 0.5]), np.eye(3)).shape == (0, 6)
    assert solver.nearest(np.array([2.0, 0.0, 0.5]), np.eye(3), ur5.neutral()) is None
    # inside the shoulder-offset cylinder around axis 1: no θ1 keeps the offset
    centre_in_tool = solver.geometry.centre_in_tool
    assert solver.solutions(-centre_in_tool + [0.0, 0.0, 0.4], np.eye(3)).shape == (0, 6)


@pytest.mark.parametrize(
    "q",
    [
        np.zeros(6),  # shoulder, elbow and wrist singular at once
        np.array([0.4, -1.0, 1.2, 0.3, 0.0, 0.7]),  # wrist singular: θ6 free
        np.array([0.4, -1.0, 1.2, 0.3, np.pi, -2.0]),
        np.array([-0.5, -0.6, 0.0, 1.0, 0.8, 0.2]),  # elbow straight
    ],
)
def test_ur_singular_configurations(ur5, q):
    solver = solver_of("ur5")
    target = ur5.fk(q)
    solutions = solver.solutions(target.translation, target.rotation)
    assert len(solutions) >= 1
    assert_solves(ur5, solutions, target)
    nearest = solver.nearest(target.translation, target.rotation, q)
    assert nearest is not None
    assert_solves(ur5, nearest[None], target)
    np.testing.assert_allclose(nearest, q, atol=1e-6)


def test_nearest_is_the_solution_nearest_the_reference(ur5):
    solver = solver_of("ur5")
    rng = np.random.default_rng(3)
    for _ in range(50):
        q = ur5.random_configuration(rng)
        target = ur5.fk(q)
        near_seed = np.clip(q + rng.normal(scale=0.05, size=6), ur5.lower, ur5.upper)
        np.testing.assert_allclose(
            solver.nearest(target.translation, target.rotation, near_seed), q, atol=1e-9
        )
        reference = ur5.random_configuration(rng)
        solutions = solver.solutions(target.translation, target.rotation)
        expected = brute_force_nearest(ur5, solutions, reference)
        found = solver.nearest(target.translation, target.rotation, reference)
        np.testing.assert_allclose(found, expected, atol=1e-9)


def test_ur_rejects_misuse():
    solver = solver_of("ur5")
    with pytest.raises(InputError, match="rotation"):
        solver.solutions(np.zeros(3), None)
    with pytest.raises(InputError):
        solver.nearest(np.zeros(3), np.eye(3), np.zeros(5))
    with pytest.raises(InputError):
        solver.nearest_batch(np.full((2, 3), np.nan), np.tile(np.eye(3), (2, 1, 1)), np.zeros(6))


# ---------------------------------------------------------------------------- modified URDFs
UR5_URDF = cached_robot("ur5").urdf_path


def modified_ur5(
    tmp_path: Path, tool_rpy: str | None = None, **replacements: tuple[str, str]
) -> kinplan.Robot:
    """A copy of the UR5 URDF with joint origins replaced (and tool0 turned), loaded from disk."""
    text = UR5_URDF.read_text()
    if tool_rpy is not None:
        text = text.replace(
            'rpy="-1.57079632679 0 0" xyz="0 0.0823 0"', f'rpy="{tool_rpy}" xyz="0 0.0823 0"'
        )
    for joint, (old, new) in replacements.items():
        pattern = rf'(<joint name="{joint}".*?){re.escape(old)}'
        text, count = re.subn(pattern, rf"\g<1>{new}", text, count=1, flags=re.S)
        assert count == 1, (joint, old)
    path = tmp_path / "ur5_modified.urdf"
    path.write_text(text)
    return kinplan.load_robot(path, tip="tool0")


def test_modified_ur_geometry_is_read_from_the_urdf(tmp_path):
    robot = modified_ur5(
        tmp_path,
        shoulder_lift_joint=('xyz="0.0 0.13585 0.0"', 'xyz="0.0 0.2 0.0"'),
        elbow_joint=('xyz="0.0 -0.1197 0.425"', 'xyz="0.0 -0.05 0.55"'),
        wrist_1_joint=('xyz="0.0 0.0 0.39225"', 'xyz="0.0 0.0 0.3"'),
        wrist_3_joint=('xyz="0.0 0.0 0.09465"', 'xyz="0.0 0.0 0.12"'),
    )
    solver = analytic_solver_for(robot)
    assert isinstance(solver, URIK)
    assert np.hypot(*solver.geometry.r23) == pytest.approx(0.55)
    assert solver.geometry.shoulder_offset == pytest.approx(0.2 - 0.05 + 0.093)
    rng = np.random.default_rng(11)
    for _ in range(200):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        solutions = solver.solutions(target.translation, target.rotation)
        assert contains(solutions, q)
        assert_solves(robot, solutions, target)
    # the stock UR5 solver gets this robot wrong: the geometry really comes from the file
    stock = solver_of("ur5").solutions(target.translation, target.rotation)
    assert not contains(stock, q)


def test_joint_zero_offsets_and_tool_rotation_are_absorbed(tmp_path):
    robot = modified_ur5(
        tmp_path,
        tool_rpy="0.3 -0.5 1.2",
        wrist_2_joint=('rpy="0.0 0.0 0.0"', 'rpy="0.0 0.3 0.0"'),  # a θ4 offset
        elbow_joint=('rpy="0.0 0.0 0.0"', 'rpy="0.0 -0.7 0.0"'),  # a θ3 offset
        wrist_3_joint=('rpy="0.0 0.0 0.0"', 'rpy="0.0 0.0 0.4"'),  # a θ5 offset
    )
    solver = analytic_solver_for(robot)
    assert isinstance(solver, URIK)
    rng = np.random.default_rng(12)
    for _ in range(100):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        solutions = solver.solutions(target.translation, target.rotation)
        assert contains(solutions, q)
        assert_solves(robot, solutions, target)


@pytest.mark.parametrize(
    "replacements",
    [
        {"elbow_joint": ('rpy="0.0 0.0 0.0"', 'rpy="0.1 0.0 0.0"')},  # elbow axis tilted
        {"wrist_3_joint": ('xyz="0.0 0.0 0.09465"', 'xyz="0.02 0.0 0.09465"')},  # 5, 6 miss
        {"wrist_2_joint": ('rpy="0.0 0.0 0.0"', 'rpy="0.3 0.0 0.0"')},  # axis 5 not ⊥ axis 4
    ],
)
def test_broken_ur_structure_is_not_solved_as_a_ur(tmp_path, replacements):
    """Not the UR structure: no UR closed form. These arms keep axes 4 and 5 meeting (axes 1
    and 2 too), so the 1-D search (kinplan.ik.wrist_offset) may serve them: then its
    solutions reach the target (FK to 1e-9) and include the configuration it came from."""
    robot = modified_ur5(tmp_path, **replacements)
    solver = analytic_solver_for(robot)
    assert not isinstance(solver, URIK)
    assert "UR" not in robot.ik_solver.description.split("(")[0]
    if solver is not None:
        rng = np.random.default_rng(3)
        for _ in range(20):
            q = robot.random_configuration(rng)
            target = robot.fk(q)
            solutions = solver.solutions(target.translation, target.rotation)
            assert contains(solutions, q, tol=1e-6)
            assert_solves(robot, solutions, target)


# ---------------------------------------------------------------------------- planar 2R
def closed_form_2r(l1: float, l2: float, x: float, y: float) -> np.ndarray:
    """The textbook solutions (elbow down θ2 > 0, elbow up θ2 < 0), rows (θ1, θ2)."""
    cosine = (x**2 + y**2 - l1**2 - l2**2) / (2 * l1 * l2)
    rows = []
    for theta2 in (np.arccos(cosine), -np.arccos(cosine)):
        theta1 = np.arctan2(y, x) - np.arctan2(l2 * np.sin(theta2), l1 + l2 * np.cos(theta2))
        rows.append([theta1, theta2])
    return wrap_angle(np.array(rows))


@pytest.mark.parametrize("lengths", [(1.0, 1.0), (1.0, 0.25), (0.4, 0.9)])
def test_planar_2r_both_branches(lengths):
    robot = kinplan.planar_arm(list(lengths))
    solver = analytic_solver_for(robot)
    rng = np.random.default_rng(5)
    for _ in range(200):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        solutions = solver.solutions(target.translation, None)
        expected = closed_form_2r(*lengths, *target.translation[:2])
        assert len(solutions) == 2
        for row in expected:
            assert contains(solutions, row, tol=1e-9)
        assert contains(solutions, q)
        for s in solutions:
            position, _ = pose_errors(robot, s, target)
            assert position < 1e-9
        # with the orientation, only the solution with θ1 + θ2 of the target remains
        oriented = solver.solutions(target.translation, target.rotation)
        assert len(oriented) == 1 and contains(oriented, q)


def test_planar_2r_limits_and_wraps():
    robot = kinplan.planar_arm([1.0, 0.5], lower=[0.0, 0.0], upper=[2 * np.pi, np.pi])
    solver = analytic_solver_for(robot)
    q = np.array([5.5, 1.0])  # θ1 beyond π: only reachable as itself, not as 5.5 − 2π
    target = robot.fk(q)
    solutions = solver.solutions(target.translation, None)
    np.testing.assert_allclose(solutions, q[None], atol=1e-9)  # the θ2 < 0 branch is excluded
    np.testing.assert_allclose(solver.nearest(target.translation, None, np.zeros(2)), q)


def test_planar_2r_unreachable_and_singular(planar_2r):
    solver = solver_of("planar_2r")
    assert solver.solutions(np.array([2.5, 0.0, 0.0]), None).shape == (0, 2)
    assert solver.solutions(np.array([1.0, 0.0, 0.3]), None).shape == (0, 2)  # out of plane
    assert solver.nearest(np.array([2.5, 0.0, 0.0]), None, np.zeros(2)) is None
    stretched = solver.solutions(np.array([0.0, 2.0, 0.0]), None)
    np.testing.assert_allclose(stretched, [[np.pi / 2, 0.0]], atol=1e-9)
    # target on the base axis (l1 = l2): θ1 is free and keeps the reference
    folded = solver.nearest(np.zeros(3), None, np.array([0.7, 3.0]))
    np.testing.assert_allclose(folded, [0.7, np.pi], atol=1e-12)


# ---------------------------------------------------------------------------- batch
def ur5_path(count: int) -> np.ndarray:
    """A joint path through a run of wrist-singular samples (θ5 = 0) and past θ6's limit."""
    t = np.linspace(0.0, 1.0, count)
    q = np.column_stack(
        [
            0.3 + 1.5 * t,
            -1.4 + 0.6 * np.sin(3 * t),
            1.6 - 3.0 * t,  # elbow straightens at t = 0.53 and bends the other way
            -0.8 + 2.0 * t,
            np.sign(t - 0.4) * np.maximum(np.abs(t - 0.4) - 0.05, 0.0) * 3.0,
            4.0 + 5.0 * t,  # leaves the +2π limit: the per-sample rule wraps it
        ]
    )
    return q


def test_batch_equals_per_sample_ur5(ur5):
    solver = solver_of("ur5")
    q_path = ur5_path(600)
    poses = [ur5.fk(q) for q in q_path]
    positions = np.array([p.translation for p in poses])
    rotations = np.array([p.rotation for p in poses])
    positions[200:210] += [3.0, 0.0, 0.0]  # unreachable stretch
    q_ref = q_path[0] + 0.01
    batch = solver.nearest_batch(positions, rotations, q_ref)
    expected = follow_per_sample(solver, positions, rotations, q_ref)
    np.testing.assert_allclose(batch, expected, atol=1e-9, equal_nan=True)
    reached = ~np.isnan(batch[:, 0])
    np.testing.assert_array_equal(np.flatnonzero(~reached), np.arange(200, 210))
    for i in np.flatnonzero(reached)[::7]:
        assert_solves(ur5, batch[i][None], poses[i])
    assert np.all(batch[reached] >= ur5.lower) and np.all(batch[reached] <= ur5.upper)
    # at θ6's upper limit the nearest solution within limits is the other wrist branch
    flip = np.flatnonzero(np.abs(np.diff(batch[:, 5])) > 3.0)
    assert flip.size == 1 and q_path[flip[0] + 1, 5] > ur5.upper[5]
    # on the run of exactly wrist-singular samples θ6 is held until the elbow cannot follow;
    # then it takes the nearest value the elbow reaches (stretched straight)
    singular = np.flatnonzero(q_path[:, 4] == 0.0)
    assert singular.size > 20
    for i in singular:
        assert_solves(ur5, batch[i][None], poses[i])
    moved = singular[1:][np.diff(batch[singular, 5]) != 0.0]
    assert 0 < moved.size < singular.size - 10
    np.testing.assert_allclose(batch[moved, 2], 0.0, atol=1e-6)


def test_batch_follows_the_original_branch(ur5):
    solver = solver_of("ur5")
    t = np.linspace(0.0, 1.0, 300)[:, None]
    q_path = np.array([0.2, -1.3, 1.5, -0.9, 1.2, 0.3]) + t * [1.0, 0.5, -0.6, 0.8, 0.7, 2.0]
    poses = [ur5.fk(q) for q in q_path]
    positions = np.array([p.translation for p in poses])
    rotations = np.array([p.rotation for p in poses])
    batch = solver.nearest_batch(positions, rotations, q_path[0])
    np.testing.assert_allclose(batch, q_path, atol=1e-9)


def test_batch_equals_per_sample_planar_2r(planar_2r):
    solver = solver_of("planar_2r")
    s = np.linspace(0.0, 1.0, 401)
    radius = np.abs(2.0 * np.cos(np.pi * s))  # full stretch, through the base axis (s = 0.5)
    angle = 3.0 * s
    positions = np.column_stack([radius * np.cos(angle), radius * np.sin(angle), 0 * s])
    positions[300:305, 2] = 0.1  # out of the plane: no solution
    q_ref = np.array([0.1, 0.2])
    batch = solver.nearest_batch(positions, None, q_ref)
    expected = follow_per_sample(solver, positions, None, q_ref)
    np.testing.assert_allclose(batch, expected, atol=1e-9, equal_nan=True)
    assert np.all(np.isnan(batch[300:305]))
    assert np.isnan(batch).sum() == 10


def test_batch_single_sample_and_empty_cases(ur5):
    solver = solver_of("ur5")
    q = np.array([0.3, -1.2, 1.4, -0.8, 1.1, 0.4])
    pose = ur5.fk(q)
    one = solver.nearest_batch(pose.translation[None], pose.rotation[None], q)
    np.testing.assert_allclose(one, q[None], atol=1e-9)
    none = solver.nearest_batch(np.array([[3.0, 0, 0]]), np.eye(3)[None], q)
    assert np.all(np.isnan(none))


# ---------------------------------------------------------------------------- single-pose path
def batch_nearest(solver, target: pin.SE3, q_ref: np.ndarray) -> np.ndarray | None:
    """The answer of the vectorised machinery (the reference of the single-pose path)."""
    return solver._nearest_batch_path(target.translation, target.rotation, q_ref)


def fast_nearest(solver, target: pin.SE3, q_ref: np.ndarray):
    """The single-pose path alone; None when it leaves the pose to the batch path."""
    try:
        return ("fast", solver._nearest_fast(target.translation, target.rotation, q_ref))
    except NeedsBatch:
        return ("batch", None)


def assert_same_answer(solver, robot, target: pin.SE3, q_ref: np.ndarray) -> np.ndarray | None:
    """nearest() equals the batch path's answer (1e-9 rad) and reaches the target (1e-9)."""
    found = solver.nearest(target.translation, target.rotation, q_ref)
    expected = batch_nearest(solver, target, q_ref)
    if expected is None:
        assert found is None
        return None
    assert found is not None
    np.testing.assert_allclose(found, expected, rtol=0.0, atol=1e-9)
    assert_solves(robot, found[None], target, tol=1e-9)
    return found


@pytest.mark.parametrize("name", UR_ARMS)
def test_fast_nearest_equals_batch_path(name):
    robot, solver = cached_robot(name), solver_of(name)
    assert solver._fast is not None  # the stock URs have exactly orthonormal axes
    rng = np.random.default_rng([20240612, UR_ARMS.index(name)])
    left_to_batch = 0
    for i in range(1000):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        if i % 2:
            q_ref = robot.random_configuration(rng)
        else:  # a seed near the solution, as Robot.ik hands over
            q_ref = np.clip(q + rng.normal(scale=0.2, size=6), robot.lower, robot.upper)
        path, fast = fast_nearest(solver, target, q_ref)
        left_to_batch += path == "batch"
        found = assert_same_answer(solver, robot, target, q_ref)
        if path == "fast":
            np.testing.assert_array_equal(fast, found)  # nearest() took the single-pose path
    assert left_to_batch <= 10  # only poses within ~1e-4 of a singularity


@pytest.mark.parametrize("name", UR_ARMS)
def test_fast_solutions_equal_batch_path(name):
    robot, solver = cached_robot(name), solver_of(name)
    rng = np.random.default_rng(8)
    for _ in range(200):
        target = robot.fk(robot.random_configuration(rng))
        fast = solver.solutions(target.translation, target.rotation)
        batch = ClosedFormIK.solutions(solver, target.translation, target.rotation)
        assert fast.shape == batch.shape
        np.testing.assert_allclose(fast, batch, rtol=0.0, atol=1e-9)


def shoulder_singular(robot, solver, q: np.ndarray, offset: float = 0.0) -> np.ndarray:
    """``q`` with θ2 moved until the wrist centre is ``offset`` [m] from the shoulder-singular
    set, i.e. at distance √(d4² + offset²) from axis 1 (bisection on the signed offset)."""
    g = solver.geometry

    def signed(theta2: float) -> float:
        q_try = q.copy()
        q_try[1] = theta2
        pose = robot.fk(q_try)
        centre = pose.translation + pose.rotation @ g.centre_in_tool
        return float((centre - g.p1) @ (pin.exp3(g.u1 * q[0]) @ g.b1)) - offset

    grid = np.linspace(-np.pi, np.pi, 181)
    values = [signed(t) for t in grid]
    i = next(i for i in range(180) if values[i] * values[i + 1] < 0.0)
    low, high = grid[i], grid[i + 1]
    for _ in range(60):
        middle = 0.5 * (low + high)
        if (signed(middle) < 0.0) == (signed(low) < 0.0):
            low = middle
        else:
            high = middle
    out = q.copy()
    out[1] = 0.5 * (low + high)
    return out


@pytest.mark.parametrize("name", UR_ARMS)
@pytest.mark.parametrize(
    "case, expected_path",
    [
        ("wrist 1e-3", "fast"),
        ("wrist 1e-6", "batch"),
        ("wrist 0", "batch"),
        ("wrist pi", "batch"),
        ("elbow 1e-3", "fast"),
        ("elbow 0", "batch"),
        ("shoulder 1e-3 m", "fast"),
        ("shoulder 0", "batch"),
        ("all at once", "batch"),
    ],
)
def test_fast_nearest_near_singularities(name, case, expected_path):
    robot, solver = cached_robot(name), solver_of(name)
    rng = np.random.default_rng([3, len(case)])
    for _ in range(20):
        q = robot.random_configuration(rng)
        kind, _, value = case.partition(" ")
        amount = {"0": 0.0, "pi": np.pi, "1e-3": 1e-3, "1e-6": 1e-6, "1e-3 m": 1e-3}.get(value)
        if kind == "wrist":
            q[4] = solver.geometry.delta5 + amount
        elif kind == "elbow":
            q[2] = amount
        elif kind == "shoulder":
            q = shoulder_singular(robot, solver, q, offset=amount)
        else:
            q = np.zeros(6)
        target = robot.fk(q)
        # seeded at q, the singular branch is the answer (the single-pose path may skip an
        # elbow pair that cannot win, so from other seeds it may answer a straight-elbow pose)
        assert fast_nearest(solver, target, q)[0] == expected_path
        for q_ref in (q, robot.random_configuration(rng)):
            assert assert_same_answer(solver, robot, target, q_ref) is not None
        np.testing.assert_allclose(
            solver.nearest(target.translation, target.rotation, q), q, atol=1e-6
        )


def test_ur_wrist_singularity_keeps_reference_theta6(ur5):
    """At θ5 = 0 the single-pose and batch paths agree and keep the reference θ6."""
    solver = solver_of("ur5")
    q = np.array([0.4, -1.0, 1.2, 0.3, 0.0, 0.7])
    target = ur5.fk(q)
    for theta6 in (-2.5, 0.0, 1.9):
        reference = q.copy()
        reference[5] = theta6
        nearest = assert_same_answer(solver, ur5, target, reference)
        assert nearest[5] == theta6
        assert_solves(ur5, nearest[None], target)


@pytest.mark.parametrize("name", UR_ARMS)
def test_fast_nearest_unreachable(name):
    robot, solver = cached_robot(name), solver_of(name)
    q_ref = robot.neutral()
    reach = float(np.hypot(*solver.geometry.r23) + np.hypot(*solver.geometry.r34))
    rng = np.random.default_rng(4)
    targets = [
        pin.SE3(np.eye(3), np.array([3.0 * reach, 0.0, 0.5])),  # out of reach
        pin.SE3(np.eye(3), -solver.geometry.centre_in_tool + [0.0, 0.0, 0.4]),  # axis-1 cylinder
    ]
    for _ in range(20):  # random rotations at twice the planar reach: the elbow cannot follow
        direction = rng.normal(size=3)
        rotation = pin.exp3(rng.normal(size=3))
        targets.append(pin.SE3(rotation, 2.0 * reach * direction / np.linalg.norm(direction)))
    for target in targets:
        assert fast_nearest(solver, target, q_ref) == ("fast", None)
        assert batch_nearest(solver, target, q_ref) is None
        assert solver.nearest(target.translation, target.rotation, q_ref) is None
        assert solver.solutions(target.translation, target.rotation).shape == (0, 6)


def test_fast_nearest_with_weights_and_narrow_limits(ur5):
    geometry = solver_of("ur5").geometry
    rng = np.random.default_rng(21)
    lower = np.array([-np.pi, -2.0, -2.5, -np.pi, -1.0, -4.0])
    upper = np.array([np.pi, 0.5, 2.5, 1.0, 2.5, 4.0])
    solvers = [
        URIK(geometry, ur5.lower, ur5.upper, weights=np.array([3.0, 2.0, 1.0, 0.5, 0.2, 0.1])),
        URIK(geometry, lower, upper),
        URIK(geometry, lower, upper, weights=np.array([1.0, 0.0, 1.0, 0.0, 2.0, 1.0])),
    ]
    found_some = {id(s): 0 for s in solvers}
    for _ in range(300):
        q = ur5.random_configuration(rng)
        target = ur5.fk(q)
        q_ref = 1.5 * ur5.random_configuration(rng)  # also outside the limits
        for solver in solvers:
            found = assert_same_answer(solver, ur5, target, q_ref)
            if found is not None:
                found_some[id(solver)] += 1
                assert np.all(found >= solver.lower) and np.all(found <= solver.upper)
    assert all(0 < count < 300 for count in list(found_some.values())[1:])


def test_negative_weights_use_the_batch_path(ur5):
    geometry = solver_of("ur5").geometry
    solver = URIK(geometry, ur5.lower, ur5.upper, weights=np.array([1.0, -1.0, 1, 1, 1, 1]))
    assert solver._fast is None
    q = np.array([0.3, -1.2, 1.4, -0.8, 1.1, 0.4])
    target = ur5.fk(q)
    found = solver.nearest(target.translation, target.rotation, q)
    np.testing.assert_array_equal(found, batch_nearest(solver, target, q))


def test_fast_path_rejects_bad_input_like_the_batch_path():
    solver = solver_of("ur5")
    q = np.zeros(6)
    bad_rotation = np.eye(3)
    bad_rotation[1, 2] = np.nan
    with pytest.raises(InputError, match="rotation"):
        solver.nearest(np.zeros(3), None, q)
    with pytest.raises(InputError):
        solver.nearest(np.zeros(3), bad_rotation, q)
    with pytest.raises(InputError):
        solver.nearest(np.array([0.1, np.inf, 0.2]), np.eye(3), q)
    with pytest.raises(InputError):
        solver.nearest(np.zeros(2), np.eye(3), q)
    with pytest.raises(InputError):
        solver.nearest(np.zeros(3), np.eye(3), [0.0] * 5 + [np.nan])
    with pytest.raises(InputError):
        solver.solutions(np.zeros(3), bad_rotation)


def base_turn_paths(robot, rng, count: int):
    """Random joint-space paths whose base joint crosses ±π (where the closed form's θ1, an
    atan2, wraps by 2π), sampled coarsely or finely, as (positions, rotations, q_path)."""
    for k in range(count):
        q0 = rng.uniform(np.maximum(robot.lower, -3.0), np.minimum(robot.upper, 3.0))
        side = 1.0 if k % 2 else -1.0
        q0[0] = side * rng.uniform(2.4, 3.1)
        q1 = q0 + rng.uniform(-0.6, 0.6, robot.nq)
        q1[0] = q0[0] + side * rng.uniform(0.3, 1.5)  # through ±π, outwards
        samples = int(rng.integers(3, 120))
        q_path = q0 + np.linspace(0.0, 1.0, samples)[:, None] * (q1 - q0)
        poses = [robot.fk(q) for q in q_path]
        positions = np.array([p.translation for p in poses])
        rotations = np.array([p.rotation for p in poses])
        yield positions, rotations, q_path


@pytest.mark.parametrize("name", UR_ARMS)
def test_batch_equals_per_sample_where_the_base_joint_crosses_pi(name):
    """nearest_batch against nearest() sample by sample on 40 random paths whose base joint
    crosses ±π: equal to 1e-9 rad at every sample, so θ1 does not jump by 2π where the closed
    form's atan2 wraps."""
    robot = cached_robot(name)
    solver = solver_of(name)
    rng = np.random.default_rng(21)
    for positions, rotations, q_path in base_turn_paths(robot, rng, 40):
        q_ref = q_path[0] + rng.normal(0.0, 0.02, robot.nq)
        batch = solver.nearest_batch(positions, rotations, q_ref)
        expected = follow_per_sample(solver, positions, rotations, q_ref)
        np.testing.assert_allclose(batch, expected, atol=1e-9, equal_nan=True)
        assert not np.isnan(batch).any()
        assert np.abs(np.diff(batch[:, 0])).max(initial=0.0) < np.pi  # no 2π wrap of θ1


def test_batch_equals_per_sample_on_random_pose_sequences(ur5):
    """Random walks of every size of step (0.05 rad to whole turns) from random references,
    some targets out of reach: batch equals per-sample, NaN rows included."""
    solver = solver_of("ur5")
    rng = np.random.default_rng(22)
    for k in range(60):
        samples = int(rng.integers(2, 40))
        step = (0.05, 0.3, 1.0, 3.0)[k % 4]
        q_path = ur5.random_configuration(rng) + np.cumsum(
            rng.normal(0.0, step, (samples, 6)), axis=0
        )
        poses = [ur5.fk(q) for q in q_path]
        positions = np.array([p.translation for p in poses])
        rotations = np.array([p.rotation for p in poses])
        positions[rng.random(samples) < 0.1] += [2.0, 0.0, 0.0]  # some out of reach
        q_ref = ur5.random_configuration(rng)
        batch = solver.nearest_batch(positions, rotations, q_ref)
        expected = follow_per_sample(solver, positions, rotations, q_ref)
        np.testing.assert_allclose(batch, expected, atol=1e-9, equal_nan=True)


MODIFIED_GEOMETRIES = {
    "offsets": {
        "shoulder_lift_joint": ('xyz="0.0 0.13585 0.0"', 'xyz="0.0 0.2 0.0"'),
        "elbow_joint": ('xyz="0.0 -0.1197 0.425"', 'xyz="0.0 -0.05 0.55"'),
        "wrist_1_joint": ('xyz="0.0 0.0 0.39225"', 'xyz="0.0 0.0 0.3"'),
        "wrist_3_joint": ('xyz="0.0 0.0 0.09465"', 'xyz="0.0 0.0 0.12"'),
    },
    "shifted and turned base": {
        "world_joint": (
            'rpy="0.0 0.0 0.0" xyz="0.0 0.0 0.0"',
            'rpy="0.2 -0.1 0.7" xyz="0.3 -0.2 0.1"',
        ),
        "shoulder_pan_joint": ('xyz="0.0 0.0 0.089159"', 'xyz="0.04 -0.03 0.089159"'),
    },
    "zero offsets and tool": {
        "wrist_2_joint": ('rpy="0.0 0.0 0.0"', 'rpy="0.0 0.3 0.0"'),
        "elbow_joint": ('rpy="0.0 0.0 0.0"', 'rpy="0.0 -0.7 0.0"'),
        "wrist_3_joint": ('rpy="0.0 0.0 0.0"', 'rpy="0.0 0.0 0.4"'),
    },
}


@pytest.mark.parametrize("variant", list(MODIFIED_GEOMETRIES))
def test_fast_nearest_equals_batch_path_on_modified_geometries(tmp_path, variant):
    """The single-pose path in plain floats against the vectorised one on UR-type arms whose
    offsets, base placement, joint zeros and tool differ from the stock UR5 (terms that vanish
    on a stock arm do not there): the same answer to 1e-9 rad, reaching the target."""
    tool_rpy = "0.3 -0.5 1.2" if variant == "zero offsets and tool" else None
    robot = modified_ur5(tmp_path, tool_rpy=tool_rpy, **MODIFIED_GEOMETRIES[variant])
    solver = analytic_solver_for(robot)
    assert isinstance(solver, URIK) and solver._fast is not None
    rng = np.random.default_rng(31)
    used_fast = 0
    for i in range(150):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        q_ref = robot.random_configuration(rng) if i % 2 else q + rng.normal(0.0, 0.2, 6)
        q_ref = np.clip(q_ref, robot.lower, robot.upper)
        path, _ = fast_nearest(solver, target, q_ref)
        used_fast += path == "fast"
        assert assert_same_answer(solver, robot, target, q_ref) is not None
        fast = solver.solutions(target.translation, target.rotation)
        batch = ClosedFormIK.solutions(solver, target.translation, target.rotation)
        np.testing.assert_allclose(fast, batch, rtol=0.0, atol=1e-9)
    assert used_fast >= 140


def test_self_check_refuses_solvers_that_miss_the_pose(ur5):
    """The FK self-check behind analytic_solver_for: a closed form that returns the
    configuration itself passes; one that misses it, or adds a solution off in position or
    only in the tool's rotation (the last joint turned: the UR tool stays put), fails."""
    from kinplan.ik import self_check

    exact = solver_of("ur5")
    assert self_check(ur5, lambda pose, q: exact.solutions(pose.translation, pose.rotation))
    assert self_check(ur5, lambda pose, q: q[None])
    assert not self_check(ur5, lambda pose, q: (q + 0.01)[None])
    assert not self_check(ur5, lambda pose, q: np.zeros((0, 6)))
    turned = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1e-3])
    assert not self_check(ur5, lambda pose, q: np.array([q, q + turned]))
    moved = np.array([1e-3, 0.0, 0.0, 0.0, 0.0, 0.0])
    assert not self_check(ur5, lambda pose, q: np.array([q, q + moved]))


def test_solutions_are_listed_nearest_the_middle_of_asymmetric_limits(ur5):
    """With limits [−π/2, 3π] on every joint, each solution is given as its 2π-equivalent
    nearest the middle 1.25π of the range, within the limits, still reaching the target."""
    lower, upper = np.full(6, -np.pi / 2), np.full(6, 3 * np.pi)
    solver = URIK(solver_of("ur5").geometry, lower, upper)
    middle = 0.5 * (lower + upper)
    rng = np.random.default_rng(41)
    for _ in range(30):
        target = ur5.fk(ur5.random_configuration(rng))
        solutions = solver.solutions(target.translation, target.rotation)
        assert len(solutions) >= 2
        assert np.all(solutions >= lower) and np.all(solutions <= upper)
        assert np.all(np.abs(solutions - middle) <= np.pi + 1e-9)
        for q in solutions:
            position, rotation = pose_errors(ur5, q, target)
            assert position < 1e-9 and rotation < 1e-9


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda s: s.nearest_batch(np.zeros((2, 2)), np.tile(np.eye(3), (2, 1, 1)), np.zeros(6)),
         "positions"),
        (lambda s: s.nearest_batch(np.zeros((2, 3)), np.tile(np.eye(3), (2, 1, 1)), np.zeros(5)),
         "q_ref"),
        (lambda s: s.nearest_batch(np.zeros((2, 3)), np.tile(np.eye(3), (3, 1, 1)), np.zeros(6)),
         "rotations"),
        (lambda s: s.nearest(np.zeros(3), np.eye(3), [np.nan] * 6), "q_ref"),
        (lambda s: s.nearest(np.zeros(2), np.eye(3), np.zeros(6)), "position"),
    ],
    ids=["positions shape", "q_ref size", "rotations count", "q_ref NaN", "position size"],
)  # fmt: skip
def test_closed_form_inputs_are_refused_by_name(call, name):
    with pytest.raises(InputError, match=name):
        call(solver_of("ur5"))


def test_fast_nearest_equals_batch_path_with_joints_on_their_limits(ur5):
    """Configurations with joints exactly on (narrow) limits, as taught points often are: the
    closed form returns those joints a rounding error beyond the limit, which both paths must
    take as on it (LIMIT_TOL) and clip; references on either side, and half a turn away."""
    half = np.array([3.0, 2.0, 2.5, 3.0, 2.0, 3.0])
    solver = URIK(solver_of("ur5").geometry, -half, half)
    rng = np.random.default_rng(43)
    on_limit = 0
    for i in range(200):
        q = rng.uniform(-half, half)
        joints = rng.choice(6, size=1 + i % 3, replace=False)
        q[joints] = np.where(rng.random(len(joints)) < 0.5, -half[joints], half[joints])
        target = ur5.fk(q)
        q_ref = q + rng.normal(0.0, 0.05, 6) if i % 2 else q + rng.choice([-3.1, 3.1], 6)
        found = assert_same_answer(solver, ur5, target, q_ref)
        if found is None:
            continue
        assert np.all(found >= -half) and np.all(found <= half)
        on_limit += np.any(np.abs(np.abs(found) - half) == 0.0)
    assert on_limit > 50


def test_planar_2r_closed_form_on_a_moved_and_tilted_base():
    """The lecture's 2R on a base shifted and tilted in space: both elbow solutions of random
    targets (and only those: none off the arm's tilted plane) reach them, and nearest() keeps
    the reference's branch; targets on the first joint's axis leave θ1 free at the reference."""
    base = pin.SE3(pin.utils.rpyToMatrix(0.3, -0.2, 0.5), np.array([0.4, -0.3, 0.2]))
    robot = kinplan.load_robot("planar_2r", base_pose=base)
    solver = robot.closed_form_ik
    assert isinstance(solver, Planar2RIK)
    rng = np.random.default_rng(44)
    for _ in range(50):
        q = rng.uniform(-3.0, 3.0, 2)
        target = robot.fk(q)
        solutions = solver.solutions(target.translation, None)
        assert contains(solutions, q) and len(solutions) == 2
        for s in solutions:
            reached = robot.fk(s).translation
            np.testing.assert_allclose(reached, target.translation, atol=1e-9)
        near = solver.nearest(target.translation, None, q + rng.normal(0.0, 0.05, 2))
        np.testing.assert_allclose(near, q, atol=1e-9)
        off_plane = target.translation + 0.01 * base.rotation[:, 2]
        assert len(solver.solutions(off_plane, None)) == 0
    axis_point = robot.fk([0.0, np.pi]).translation  # folded (l1 = l2): on joint 1's axis
    folded = solver.nearest(axis_point, None, np.array([0.7, 3.0]))
    np.testing.assert_allclose(folded, [0.7, np.pi], atol=1e-9)


# ---------------------------------------------------------------------------- planar single pose
def skewed_planar_2r(tmp_path: Path, lower: float, upper: float) -> kinplan.Robot:
    """A 2R arm whose second axis points the other way, with the tool off the link's line
    (r2 not along x) and first-axis limits of more than a turn: every term of the single-pose
    path differs from the lecture's arm."""
    text = kinplan.model.planar.planar_arm_urdf(
        [0.8, 0.45], lower=[lower, -2.5], upper=[upper, 2.9]
    )
    second = '<origin xyz="0.8 0 0" rpy="0 0 0" />\n    <axis xyz="0 0 1" />'
    tool = '<origin xyz="0.45 0 0" rpy="0 0 0" />\n  </joint>\n</robot>'
    text = text.replace(second, second.replace('"0 0 1"', '"0 0 -1"'))
    text = text.replace(tool, tool.replace('"0.45 0 0"', '"0.45 0.12 0"'))
    assert text.count('axis xyz="0 0 -1"') == 1 and "0.45 0.12 0" in text
    path = tmp_path / "skewed_2r.urdf"
    path.write_text(text)
    base = pin.SE3(pin.utils.rpyToMatrix(0.4, 0.1, -0.7), np.array([0.2, -0.1, 0.3]))
    return kinplan.load_robot(str(path), tip="tip", base_pose=base)


def planar_arms(tmp_path: Path) -> list[kinplan.Robot]:
    return [
        cached_robot("planar_2r"),
        kinplan.planar_arm([1.0, 0.5], lower=[0.0, 0.0], upper=[2 * np.pi, np.pi]),
        kinplan.planar_arm([0.4, 0.9], lower=[-1.0, -0.5], upper=[2.0, 2.5]),
        skewed_planar_2r(tmp_path, -4.0, 4.0),
    ]


def test_planar_fast_nearest_equals_batch_path(tmp_path):
    """The planar 2R's plain-float nearest() against its vectorised path on 4 arms (a tilted
    base, a reversed second axis, an offset tool, limits of more or less than a turn), 1,500
    targets each: reachable, unreachable, out of the plane, on the workspace boundary; seeds
    random, near, and beyond the limits."""
    rng = np.random.default_rng(20261128)
    for robot in planar_arms(tmp_path):
        solver = robot.closed_form_ik
        assert isinstance(solver, Planar2RIK)
        normal = solver._axis  # the plane's normal in the world frame
        paths = {"fast": 0, "none": 0, "batch": 0}
        for i in range(1500):
            q = rng.uniform(robot.lower - 0.5, robot.upper + 0.5)
            target = robot.fk(q).translation
            kind = i % 5
            if kind == 1:  # beyond reach along the same direction
                target = target + rng.uniform(0.0, 1.0) * (target - robot.fk(q * 0).translation)
            elif kind == 2:  # off the plane by up to 1e-8 m (PLANAR_TOL is 1e-9)
                target = target + rng.uniform(-1e-8, 1e-8) * normal
            elif kind == 3:  # stretched or folded: on the boundary of the workspace
                q = np.array([q[0], rng.choice([0.0, np.pi])])
                target = robot.fk(q).translation
            q_ref = (
                np.clip(q + rng.normal(scale=0.3, size=2), robot.lower, robot.upper)
                if i % 2
                else rng.uniform(robot.lower - 3.0, robot.upper + 3.0)
            )
            expected = solver._nearest_batch_path(target, None, q_ref)
            try:
                fast = solver._nearest_fast(target, q_ref)
            except NeedsBatch:  # on the first axis (θ1 free): only the folded lecture arm
                assert kind == 3 and np.hypot(*target[:2]) < 1e-12, target
                np.testing.assert_array_equal(solver.nearest(target, None, q_ref), expected)
                paths["batch"] += 1
                continue
            paths["none" if fast is None else "fast"] += 1
            assert (fast is None) == (expected is None), (i, target, q_ref, fast, expected)
            if fast is not None:
                np.testing.assert_allclose(fast, expected, rtol=0.0, atol=1e-9)
                assert robot.within_limits(fast, tolerance=0.0)
                reached = robot.fk(fast).translation
                np.testing.assert_allclose(reached, target, rtol=0.0, atol=1e-9)
                np.testing.assert_array_equal(solver.nearest(target, None, q_ref), fast)
            else:
                assert solver.nearest(target, None, q_ref) is None
        assert paths["fast"] > 600 and paths["none"] > 200 and paths["batch"] < 200, paths


def test_planar_fast_nearest_leaves_to_the_batch_path(planar_2r):
    """A target on the first axis (θ1 free), a rotation, bad shapes and NaN take the vectorised
    path: θ1 keeps the reference there, and bad input raises its InputError."""
    solver = solver_of("planar_2r")
    on_axis = planar_2r.fk([0.0, np.pi]).translation  # folded, l1 = l2
    with pytest.raises(NeedsBatch):
        solver._nearest_fast(on_axis, np.array([0.7, 3.0]))
    np.testing.assert_allclose(solver.nearest(on_axis, None, np.array([0.7, 3.0])),
                               [0.7, np.pi], atol=1e-12)  # fmt: skip
    for position, q_ref in [
        (np.array([1.0, 0.5]), np.zeros(2)),
        (np.array([1.0, 0.5, 0.0]), np.zeros(3)),
        (np.array([np.nan, 0.5, 0.0]), np.zeros(2)),
        (np.array([1.0, 0.5, 0.0]), np.array([np.inf, 0.0])),
    ]:
        with pytest.raises(NeedsBatch):
            solver._nearest_fast(position, q_ref)
        with pytest.raises(InputError):
            solver.nearest(position, None, q_ref)
    q = np.array([0.4, 1.1])
    pose = planar_2r.fk(q)
    np.testing.assert_allclose(solver.nearest(pose.translation, pose.rotation, q), q, atol=1e-12)


def test_planar_fast_nearest_breaks_a_tie_as_the_batch_path():
    """Two elbow solutions (−0.75, 1.5) and (0.75, −1.5) as far from q_ref = 0 to the last bit
    (their distances are equal in floats): both paths take the first branch (θ2 ≥ 0)."""
    solver = solver_of("planar_2r")
    target = np.array([2.0 * np.cos(0.75), 0.0, 0.0])
    distances = np.sum(solver.solutions(target, None) ** 2, axis=1)
    assert distances[0] == distances[1]
    fast = solver._nearest_fast(target, np.zeros(2))
    np.testing.assert_array_equal(fast, solver._nearest_batch_path(target, None, np.zeros(2)))
    np.testing.assert_allclose(fast, [-0.75, 1.5], atol=1e-12)


def test_planar_branch_many_and_pose_branches_equal_all_branches(tmp_path):
    """The planar 2R's one-branch pass (branch_many) and plain-float pose_branches give the
    rows of all_branches: on 4 arms, 2,000 targets each (reachable, beyond reach, off the
    plane, on the first axis)."""
    rng = np.random.default_rng(77)
    for robot in planar_arms(tmp_path):
        solver = robot.closed_form_ik
        q = rng.uniform(robot.lower - 0.5, robot.upper + 0.5, size=(2000, 2))
        positions = np.array([robot.fk(row).translation for row in q])
        positions[::7] *= 1.0 + rng.uniform(0.0, 1.0, size=(len(positions[::7]), 1))
        positions[3::11] += 1e-8 * solver._axis  # off the plane
        positions[5] = robot.fk([0.3, np.pi]).translation  # folded (on the axis when l1 = l2)
        every, free = solver.all_branches(positions, None, np.zeros((2000, 2)))
        for branch in (0, 1):
            raw, edge = solver.branch_many(positions, None, branch)
            np.testing.assert_array_equal(raw, every[:, branch])
            np.testing.assert_array_equal(edge, free)
        assert 100 < np.isnan(every[:, 0, 0]).sum() < 1000
        for k in range(0, 2000, 4):
            first = solver.pose_branches(positions[k], None)
            if free[k]:
                assert first is None
                continue
            np.testing.assert_allclose(first, every[k], rtol=0.0, atol=1e-12)
        assert solver.pose_branches(positions[1], np.eye(3)) is None


def test_planar_inner_boundary_within_rounding_is_reached_folded():
    """A target at |l1 − l2| from the first axis, 1e-12 m inside it (cos θ2 just below −1,
    within the clamp): the folded arm (θ2 = π) reaches it, on both paths."""
    robot = kinplan.planar_arm([1.0, 0.4])
    solver = analytic_solver_for(robot)
    target = np.array([0.6 - 1e-12, 0.0, 0.0])
    for nearest in (solver._nearest_fast, lambda p, q: solver._nearest_batch_path(p, None, q)):
        q = nearest(target, np.array([0.1, 3.0]))
        assert q is not None
        np.testing.assert_allclose(np.abs(wrap_angle(q - [0.0, np.pi])), 0.0, atol=2e-6)
        np.testing.assert_allclose(robot.fk(q).translation, target, atol=1e-9)


def test_planar_weights_choose_the_branch():
    """The weights w of Σ wᵢ Δqᵢ² pick the branch. Target (2 cos 0.6, 0): solutions A =
    (−0.6, 1.2) and B = (0.6, −1.2); from q_ref = (−0.5, −0.3), A is off by (−0.1, 1.5) and B
    by (1.1, −0.9): unit weights 2.26 against 2.02 (B), w = (10, 0.1) 0.325 against 12.181
    (A), w = (0.1, 10) 22.501 against 8.221 (B); both paths alike."""
    robot = cached_robot("planar_2r")
    target = np.array([2.0 * np.cos(0.6), 0.0, 0.0])
    q_ref = np.array([-0.5, -0.3])
    for weights, expected in [(None, [0.6, -1.2]), ([10.0, 0.1], [-0.6, 1.2]),
                              ([0.1, 10.0], [0.6, -1.2])]:  # fmt: skip
        solver = analytic_solver_for(robot, None if weights is None else np.array(weights))
        found = solver.nearest(target, None, q_ref)
        np.testing.assert_allclose(found, expected, atol=1e-12)
        np.testing.assert_array_equal(found, solver._nearest_batch_path(target, None, q_ref))


def test_two_joints_on_crossed_axes_have_no_planar_closed_form(tmp_path, caplog):
    """A 2-joint arm whose second axis is not parallel to the first (z then y) is not a planar
    2R: no closed form (the numerical solver serves it), refused by its geometry before any
    solver is built and checked against the forward kinematics."""
    text = kinplan.model.planar.planar_arm_urdf([0.8, 0.45])
    second = '<origin xyz="0.8 0 0" rpy="0 0 0" />\n    <axis xyz="0 0 1" />'
    assert second in text
    path = tmp_path / "crossed.urdf"
    path.write_text(text.replace(second, second.replace('"0 0 1"', '"0 1 0"')))
    robot = kinplan.load_robot(str(path), tip="tip")
    with caplog.at_level(logging.DEBUG, logger="kinplan.ik.closed_form"):
        assert analytic_solver_for(robot) is None
    assert "disagrees with its forward kinematics" not in caplog.text


def test_planar_rotation_targets_fix_the_first_joint_on_its_axis():
    """A pose on the first axis (folded, l1 = l2) with a rotation: θ1 is free for the position
    but the rotation fixes θ1 + θ2, so nearest() takes it from the rotation, not the reference;
    and with a rotation the branch comes from the rotation, not the reference's nearness."""
    robot = cached_robot("planar_2r")
    solver = solver_of("planar_2r")
    folded = robot.fk([0.9, np.pi])
    q = solver.nearest(folded.translation, folded.rotation, np.array([0.1, 3.0]))
    np.testing.assert_allclose(wrap_angle(q - [0.9, np.pi]), 0.0, atol=1e-9)
    # the elbow-down pose from a reference next to the elbow-up solution
    pose = robot.fk([0.6, -1.2])
    q = solver.nearest(pose.translation, pose.rotation, np.array([-0.6, 1.2]))
    np.testing.assert_allclose(q, [0.6, -1.2], atol=1e-9)


def test_planar_branch_many_with_rotations_equals_all_branches(planar_2r):
    """branch_many of poses (a rotation per target) gives all_branches' rows: a rotation keeps
    only the branch with its θ1 + θ2, the other row NaN."""
    solver = solver_of("planar_2r")
    q = np.random.default_rng(9).uniform(-3.0, 3.0, size=(300, 2))
    poses = [planar_2r.fk(row) for row in q]
    positions = np.array([p.translation for p in poses])
    rotations = np.array([p.rotation for p in poses])
    every, free = solver.all_branches(positions, rotations, np.zeros((300, 2)))
    for branch in (0, 1):
        raw, edge = solver.branch_many(positions, rotations, branch)
        np.testing.assert_array_equal(raw, every[:, branch])
        np.testing.assert_array_equal(edge, free)
    assert np.all(np.isnan(every[:, 0, 0]) != np.isnan(every[:, 1, 0]))  # one branch each


def test_planar_pose_out_of_reach_or_off_the_plane_has_no_solution(planar_2r):
    """A rotation does not make an unreachable position reachable: beyond the reach (2.5 m;
    with the rotation of the stretched arm pointing there, which the clamped closed form would
    otherwise take) or off the plane (0.3 m above a reachable point, with the rotation of one of
    its solutions), a pose has no solution."""
    solver = solver_of("planar_2r")
    beyond = (np.array([2.5, 0.0, 0.0]), planar_2r.fk([0.0, 0.0]).rotation)
    below = solver.solutions(np.array([1.0, 0.0, 0.0]), None)[0]
    above = (np.array([1.0, 0.0, 0.3]), planar_2r.fk(below).rotation)
    for position, rotation in (beyond, above):
        assert solver.solutions(position, rotation).shape == (0, 2)
        assert solver.nearest(position, rotation, np.zeros(2)) is None
