"""URIK.nearest_many (the UR closed form vectorised over poses) against independent answers:
nearest pose by pose (same q to 1e-10 rad, same success), the branch index against the branch
of the all-branch solutions the answer is, the mask of branches within the limits against
brute force over every branch and every 2π-equivalent, FK of the answer equal to the target;
on stock and modified geometries, with weights, narrow, wide and exactly-met limits, and near
singularities (left to nearest)."""

from __future__ import annotations

import warnings

import numpy as np
import pinocchio as pin
import pytest
from conftest import cached_robot
from test_analytic_ik import MODIFIED_GEOMETRIES, modified_ur5, shoulder_singular, solver_of

from kinplan.ik import URIK, analytic_solver_for
from kinplan.ik.screws import LIMIT_TOL, TAU

WEIGHTS = np.array([3.0, 0.5, 2.0, 1.0, 0.25, 4.0])


def _poses(robot, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    poses = [robot.fk(row) for row in q]
    return np.array([p.translation for p in poses]), np.array([p.rotation for p in poses])


def _equivalent_within(value: float, lower: float, upper: float) -> bool:
    """Whether some 2π-equivalent of ``value`` lies within [lower, upper] (to LIMIT_TOL)."""
    k = np.round((0.5 * (lower + upper) - value) / TAU)
    return any(
        lower - LIMIT_TOL <= value + (k + d) * TAU <= upper + LIMIT_TOL for d in (-2, -1, 0, 1, 2)
    )


def _assert_many_equals_single(robot, solver: URIK, positions, rotations, refs) -> np.ndarray:
    """nearest_many: nearest's success and q; branch the one whose raw solution is q modulo
    2π; mask the branches with every joint within the limits (brute force); FK = target."""
    q, branch, mask, left = solver.nearest_many(positions, rotations, refs)
    assert left.sum() <= 0.05 * len(refs)
    checked = 0
    for k in np.flatnonzero(~left):
        single = solver.nearest(positions[k], rotations[k], refs[k])
        assert (branch[k] >= 0) == (single is not None), k
        raw = solver._fast_all_branches(positions[k], rotations[k])
        expected_mask = 0
        for b, row in enumerate(raw):
            if not np.isnan(row).any() and all(
                _equivalent_within(v, lo, hi) for v, lo, hi in zip(row, solver.lower, solver.upper)
            ):
                expected_mask |= 1 << b
        assert int(mask[k]) == expected_mask, (k, bin(mask[k]), bin(expected_mask))
        if single is None:
            continue
        np.testing.assert_allclose(q[k], single, atol=1e-10, err_msg=str(k))
        turns = (q[k] - raw[branch[k]]) / TAU
        np.testing.assert_allclose(turns, np.round(turns), atol=1e-9, err_msg=str(k))
        assert expected_mask >> int(branch[k]) & 1
        if checked < 40:
            pose = robot.fk(q[k])
            assert np.linalg.norm(pose.translation - positions[k]) < 1e-9
            assert np.linalg.norm(pin.log3(pose.rotation.T @ rotations[k])) < 1e-9
        checked += 1
    return branch >= 0


@pytest.mark.parametrize("name", ["ur3", "ur5", "ur10"])
def test_nearest_many_equals_nearest_on_the_stock_arms(name):
    robot, solver = cached_robot(name), solver_of(name)
    rng = np.random.default_rng([50, ["ur3", "ur5", "ur10"].index(name)])
    q_true = np.array([robot.random_configuration(rng) for _ in range(300)])
    positions, rotations = _poses(robot, q_true)
    positions[250:] = rng.uniform(-1.5, 1.5, (50, 3))
    refs = np.array([robot.random_configuration(rng) for _ in range(300)])
    refs[:60] = q_true[:60] + rng.normal(0.0, 0.1, (60, 6))
    refs[60:100] += rng.choice([-TAU, -3.0, 3.0, TAU], (40, 6))  # beyond the limits
    found = _assert_many_equals_single(robot, solver, positions, rotations, refs)
    assert found[:250].all() and not found[250:].all()


def test_nearest_many_with_weights_and_narrow_limits():
    """Weights change the nearest branch; narrow limits drop branches (the mask), sometimes
    all of them."""
    robot, geometry = cached_robot("ur5"), solver_of("ur5").geometry
    lower = np.array([-np.pi, -2.0, -2.5, -np.pi, -1.0, -4.0])
    upper = np.array([np.pi, 0.5, 2.5, 1.0, 2.5, 4.0])
    rng = np.random.default_rng(51)
    q_true = np.array([robot.random_configuration(rng) for _ in range(250)])
    positions, rotations = _poses(robot, q_true)
    refs = 1.5 * np.array([robot.random_configuration(rng) for _ in range(250)])
    counts = []
    for solver in (
        URIK(geometry, robot.lower, robot.upper, WEIGHTS),
        URIK(geometry, lower, upper),
        URIK(geometry, lower, upper, np.array([1.0, 0.0, 1.0, 0.0, 2.0, 1.0])),
    ):
        found = _assert_many_equals_single(robot, solver, positions, rotations, refs)
        counts.append(found.sum())
    assert counts[0] == 250 and 0 < counts[1] < 250 and counts[2] == counts[1]


def test_nearest_many_takes_the_equivalent_nearest_the_reference_over_wide_limits():
    """Limits of ±3 turns: every joint of the answer is the equivalent nearest the reference
    (brute force over the equivalents of every branch), including references far outside."""
    robot, geometry = cached_robot("ur5"), solver_of("ur5").geometry
    wide = np.full(6, 3 * TAU)
    solver = URIK(geometry, -wide, wide, WEIGHTS)
    rng = np.random.default_rng(52)
    q_true = np.array([robot.random_configuration(rng) for _ in range(120)])
    positions, rotations = _poses(robot, q_true)
    refs = rng.uniform(-25.0, 25.0, (120, 6))
    _assert_many_equals_single(robot, solver, positions, rotations, refs)
    q = solver.nearest_many(positions, rotations, refs)[0]
    for k in range(0, 120, 4):
        raw = solver._fast_all_branches(positions[k], rotations[k])
        best = np.inf
        for row in raw[~np.isnan(raw).any(axis=1)]:
            cost = 0.0
            for v, r, w, hi in zip(row, refs[k], WEIGHTS, wide):
                options = v + TAU * np.arange(-5, 6)
                options = options[np.abs(options) <= hi]
                cost += w * np.min((options - r) ** 2)
            best = min(best, cost)
        assert np.sum(WEIGHTS * (q[k] - refs[k]) ** 2) == pytest.approx(best, rel=1e-9)


def test_nearest_many_with_joints_exactly_on_narrow_limits():
    robot = cached_robot("ur5")
    half = np.array([3.0, 2.0, 2.5, 3.0, 2.0, 3.0])
    solver = URIK(solver_of("ur5").geometry, -half, half)
    rng = np.random.default_rng(53)
    q_true = rng.uniform(-half, half, (200, 6))
    for k in range(200):
        joints = rng.choice(6, size=1 + k % 3, replace=False)
        q_true[k, joints] = np.where(rng.random(len(joints)) < 0.5, -half[joints], half[joints])
    positions, rotations = _poses(robot, q_true)
    refs = q_true + np.where(
        np.arange(200)[:, None] % 2,
        rng.normal(0.0, 0.05, (200, 6)),
        rng.choice([-3.1, 3.1], (200, 6)),
    )
    found = _assert_many_equals_single(robot, solver, positions, rotations, refs)
    q = solver.nearest_many(positions, rotations, refs)[0]
    assert np.all((q[found] >= -half) & (q[found] <= half))
    assert np.sum(np.any(np.abs(np.abs(q[found]) - half) == 0.0, axis=1)) > 50


@pytest.mark.parametrize("variant", list(MODIFIED_GEOMETRIES))
def test_nearest_many_equals_nearest_on_modified_geometries(tmp_path, variant):
    tool_rpy = "0.3 -0.5 1.2" if variant == "zero offsets and tool" else None
    robot = modified_ur5(tmp_path, tool_rpy=tool_rpy, **MODIFIED_GEOMETRIES[variant])
    solver = analytic_solver_for(robot)
    assert isinstance(solver, URIK) and solver._fast is not None
    rng = np.random.default_rng(54)
    q_true = np.array([robot.random_configuration(rng) for _ in range(150)])
    positions, rotations = _poses(robot, q_true)
    refs = np.array([robot.random_configuration(rng) for _ in range(150)])
    found = _assert_many_equals_single(robot, solver, positions, rotations, refs)
    assert found.sum() >= 145


def test_nearest_many_leaves_singular_poses_and_negative_weights_to_nearest():
    """Wrist (θ5 = 0), elbow (θ3 = 0) and shoulder singularities are left to nearest(); a solver
    with a negative weight (no single-pose path) leaves every pose; an empty batch is empty."""
    robot, solver = cached_robot("ur5"), solver_of("ur5")
    rng = np.random.default_rng(55)
    q_true = np.array([robot.random_configuration(rng) for _ in range(90)])
    q_true[:30, 4] = 0.0
    q_true[30:60, 2] = 0.0
    for k in range(60, 75):  # the wrist centre at |d4| from axis 1: θ1's two values meet
        q_true[k] = shoulder_singular(robot, solver, q_true[k])
    positions, rotations = _poses(robot, q_true)
    q, branch, mask, left = solver.nearest_many(positions, rotations, q_true)
    assert left[:75].all() and not left[75:].any()
    with warnings.catch_warnings():  # the all-branch path they go to: no warning either
        warnings.simplefilter("error")
        for k in range(0, 75, 5):
            found = solver.nearest(positions[k], rotations[k], q_true[k])
            np.testing.assert_allclose(found, q_true[k], atol=1e-6)
    negative = URIK(solver.geometry, robot.lower, robot.upper, -WEIGHTS)
    q, branch, mask, left = negative.nearest_many(positions, rotations, q_true)
    assert left.all() and (branch == -1).all() and not mask.any() and q.shape == (90, 6)
    empty = solver.nearest_many(np.zeros((0, 3)), np.zeros((0, 3, 3)), np.zeros((0, 6)))
    assert [x.shape for x in empty] == [(0, 6), (0,), (0,), (0,)]


def test_nearest_many_of_unreachable_poses_has_no_branch():
    solver = solver_of("ur5")
    positions = np.array([[2.0, 0.0, 0.0], [0.0, 0.0, 3.0], [0.05, 0.05, 0.0]])
    rotations = np.array([np.eye(3)] * 3)
    q, branch, mask, left = solver.nearest_many(positions, rotations, np.zeros((3, 6)))
    # beyond reach, and close to axis 1 (no θ1: |d4| / radius > 1): decided here, not left
    assert not left.any() and (branch == -1).all() and not mask.any()
    for k in range(3):
        assert solver.nearest(positions[k], rotations[k], np.zeros(6)) is None


def test_nearest_many_breaks_ties_towards_the_lower_branch():
    """Exact ties: with zero weights every branch is as near as any other, so the answer is
    the lowest branch with a solution within the limits; with only θ1 weighted, the lowest
    branch of the nearer shoulder. nearest() decides the same."""
    robot, geometry = cached_robot("ur5"), solver_of("ur5").geometry
    rng = np.random.default_rng(56)
    q_true = np.array([robot.random_configuration(rng) for _ in range(100)])
    positions, rotations = _poses(robot, q_true)
    refs = np.array([robot.random_configuration(rng) for _ in range(100)])
    for weights in (np.zeros(6), np.array([1.0, 0, 0, 0, 0, 0])):
        solver = URIK(geometry, robot.lower, robot.upper, weights)
        _assert_many_equals_single(robot, solver, positions, rotations, refs)
        q, branch, mask, left = solver.nearest_many(positions, rotations, refs)
        for k in np.flatnonzero(~left & (branch >= 0)):
            bits = [b for b in range(8) if mask[k] >> b & 1]
            if not weights.any():
                assert branch[k] == bits[0]
            else:
                # branches 0-3 share θ1, and 4-7: the lowest of the nearer shoulder's
                assert branch[k] in (bits[0], next((b for b in bits if b >= 4), -1))


def _wrapped(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % TAU - np.pi


def _assert_branch_many(
    robot, solver: URIK, q_true: np.ndarray, rng
) -> tuple[np.ndarray, np.ndarray]:
    """branch_many of each branch against pose_branches of each pose alone (same angles
    modulo 2π to 1e-9 rad, same missing branches, wherever neither calls the pose near a
    singularity), FK of every answer at its target (1e-9), a branch per pose giving the rows
    of the branches it names, and the pose's own configuration among its branches."""
    count = len(q_true)
    positions, rotations = _poses(robot, q_true)
    alone = [solver.pose_branches(p, r) for p, r in zip(positions, rotations)]
    per_branch, edges = [], []
    compared = 0
    for branch in range(8):
        q, edge = solver.branch_many(positions, rotations, branch)
        per_branch.append(q)
        edges.append(edge)
        assert q.shape == (count, 6) and edge.shape == (count,)
        for k in range(count):
            if edge[k] or alone[k] is None:
                continue
            assert np.isnan(q[k]).any() == np.isnan(alone[k][branch]).any(), (branch, k)
            if not np.isnan(q[k]).any():
                np.testing.assert_allclose(
                    _wrapped(q[k] - alone[k][branch]), 0.0, rtol=0, atol=1e-9
                )
                pose = robot.fk(q[k])
                assert np.linalg.norm(pose.translation - positions[k]) < 1e-9
                assert np.linalg.norm(pin.log3(pose.rotation.T @ rotations[k])) < 1e-9
                compared += 1
    assert compared > count * 3  # most branches of most poses exist and were compared
    chosen = rng.integers(0, 8, count)
    q_chosen, edge_chosen = solver.branch_many(positions, rotations, chosen)
    expected = np.array([per_branch[b][k] for k, b in enumerate(chosen)])
    np.testing.assert_array_equal(q_chosen, expected)
    np.testing.assert_array_equal(edge_chosen, [edges[b][k] for k, b in enumerate(chosen)])
    stacked = np.stack(per_branch, axis=1)  # (N, 8, 6)
    distance = np.abs(_wrapped(stacked - q_true[:, None, :])).max(axis=2)
    own = np.nanargmin(np.where(np.isnan(distance), np.inf, distance), axis=1)
    regular = np.array([a is not None for a in alone])
    assert np.all(distance[regular, own[regular]] < 1e-8)
    return np.array(edges), own


@pytest.mark.parametrize("name", ["ur3", "ur5", "ur10"])
def test_branch_many_equals_every_pose_alone_and_its_forward_kinematics(name):
    """URIK.branch_many (one branch of many poses, the follower's fast path) on the stock arms
    over 400 random and near-singular poses (wrist θ5 ≈ 0, elbow θ3 ≈ 0): see
    :func:`_assert_branch_many`; and a pose whose own branch is within 1e-6 rad of the
    straight elbow or the aligned wrist is flagged near a singularity (edge) on that branch."""
    robot, solver = cached_robot(name), solver_of(name)
    rng = np.random.default_rng([61, ["ur3", "ur5", "ur10"].index(name)])
    q_true = np.array([robot.random_configuration(rng) for _ in range(400)])
    q_true[300:340, 4] = rng.uniform(-1e-3, 1e-3, 40)  # near the wrist singularity
    q_true[340:370, 2] = rng.uniform(-1e-3, 1e-3, 30)  # near the straight elbow
    q_true[370:385, 2] = rng.uniform(-1e-7, 1e-7, 15)  # at it (within the edge)
    q_true[385:, 4] = rng.uniform(-1e-7, 1e-7, 15)  # at the wrist singularity
    edges, own = _assert_branch_many(robot, solver, q_true, rng)
    assert np.all(edges[own[370:], np.arange(370, 400)])


@pytest.mark.parametrize("variant", list(MODIFIED_GEOMETRIES))
def test_branch_many_on_modified_geometries(tmp_path, variant):
    """The same on UR5s with moved joint origins (offsets, zero offsets, a turned tool):
    elbow offsets and wrist angles δ that the stock arms have at zero."""
    tool_rpy = "0.3 -0.5 1.2" if variant == "zero offsets and tool" else None
    robot = modified_ur5(tmp_path, tool_rpy=tool_rpy, **MODIFIED_GEOMETRIES[variant])
    solver = analytic_solver_for(robot)
    assert isinstance(solver, URIK) and solver.branch_many_available
    rng = np.random.default_rng(62)
    q_true = np.array([robot.random_configuration(rng) for _ in range(150)])
    _assert_branch_many(robot, solver, q_true, rng)


def test_branch_many_at_singularities_and_without_the_single_pose_path():
    """At exact wrist, elbow and shoulder singularities branch_many warns about nothing (its
    NaN lanes are expected) and flags every pose on some branch; a solver without the single-pose
    path (a negative weight) answers every pose as near a singularity, with float NaN rows."""
    robot, solver = cached_robot("ur5"), solver_of("ur5")
    rng = np.random.default_rng(63)
    q_true = np.array([robot.random_configuration(rng) for _ in range(45)])
    q_true[:15, 4] = 0.0
    q_true[15:30, 2] = 0.0
    for k in range(30, 45):
        q_true[k] = shoulder_singular(robot, solver, q_true[k])
    positions, rotations = _poses(robot, q_true)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        edges = np.array([solver.branch_many(positions, rotations, b)[1] for b in range(8)])
    assert edges.any(axis=0).all()  # every singular pose is flagged on some branch
    negative = URIK(solver.geometry, robot.lower, robot.upper, -WEIGHTS)
    assert not negative.branch_many_available
    q, edge = negative.branch_many(positions, rotations, 3)
    assert q.dtype == float and q.shape == (45, 6) and np.isnan(q).all() and edge.all()
