"""The vectorised closed-form follower (:mod:`cartesian.batch_track`): what its mutation
survivors showed untested, each against an independent answer.

* The stacked algebra against numpy's LAPACK (determinants, solves) and J̇q̇ against central
  differences of Pinocchio's Jacobians.
* The branch choice and the unwrapping against hand-made branch tables.
* Every monitor condition at its safety margin: a path that comes within the margin of a joint
  limit, the singularity threshold, a joint speed or acceleration limit, the cell's clearance
  or the jump tolerance is declined (``track`` returns None) although the loop plans it without
  an event, and the plan follow then makes is the loop's; the same path with the margin to
  spare is answered by the fast path, with the loop's samples.
"""

from __future__ import annotations

import itertools
from types import SimpleNamespace

import numpy as np
import pinocchio as pin
import pytest
from conftest import cached_robot
from test_follow_vectorised import _assert_same

import cartesian
import kinplan
from cartesian import batch_track, lean_track
from cartesian.batch_track import (
    CLEARANCE_MARGIN,
    JUMP_SHARE,
    LIMIT_MARGIN,
    MAX_STEP,
    OTHER_BRANCH,
    RELATIVE_MARGIN,
    SAME_BRANCH,
)
from cartesian.tracker import SINGULAR_FRACTION, Tracker
from kinplan.trajectory.sampling import hermite_between, joint_speeds

UR5_START = np.array([0.0, -1.2, 1.5, -1.9, -1.57, 0.0])
PLANAR_START = np.array([0.3, 1.2])


def ur5_line(robot: kinplan.Robot, offset=(0.0, 0.2, 0.0)) -> cartesian.Line:
    start = robot.fk(UR5_START)
    return cartesian.Line(start, pin.SE3(start.rotation, start.translation + np.array(offset)))


PLANAR_LINE = cartesian.Line([1.2, 0.3, 0.0], [0.3, 1.2, 0.0])


def loop_plan(robot, path, monkeypatch, **options) -> cartesian.CartesianPlan:
    """The plan of the per-sample loop (both fast paths switched off)."""
    with monkeypatch.context() as patch:
        patch.setattr(batch_track, "ENABLED", False)
        patch.setattr(lean_track, "ENABLED", False)
        return cartesian.follow(robot, path, **options)


def fast_plan(robot, path, monkeypatch, **options):
    """(plan with the fast paths, the results batch_track.track and lean_track.track gave)."""
    answers: dict[str, list] = {"batch": [], "lean": []}
    batch, lean = batch_track.track, lean_track.track

    def spy(name, function):
        def call(*args, **kwargs):
            result = function(*args, **kwargs)
            answers[name].append(result)
            return result

        return call

    with monkeypatch.context() as patch:
        patch.setattr(batch_track, "track", spy("batch", batch))
        patch.setattr(lean_track, "track", spy("lean", lean))
        plan = cartesian.follow(robot, path, **options)
    return plan, answers


def inputs(robot, path, monkeypatch, **options) -> tuple:
    """The arguments follow hands batch_track.track (tracker, targets, timing, ẋ, ẍ, seed)."""
    captured: list[tuple] = []

    def spy(*args):
        captured.append(args)
        return None

    with monkeypatch.context() as patch:
        patch.setattr(batch_track, "track", spy)
        patch.setattr(lean_track, "ENABLED", False)
        cartesian.follow(robot, path, **options)
    return captured[0]


def assert_declined_and_loop(
    robot, path, monkeypatch, must_pass: bool = True, **options
) -> cartesian.CartesianPlan:
    """The path is declined by the fast path, planned (ok, when ``must_pass``) by the loop, and
    follow's plan is the loop's, exactly."""
    plan, answers = fast_plan(robot, path, monkeypatch, **options)
    assert answers["batch"] and answers["batch"][0] is None
    loop = loop_plan(robot, path, monkeypatch, **options)
    assert loop.ok or not must_pass, loop
    _assert_same(plan, loop, "declined")
    np.testing.assert_array_equal(plan.q, loop.q)  # the loop itself made it
    return loop


def assert_answered(robot, path, monkeypatch, **options) -> cartesian.CartesianPlan:
    """The path is answered by the fast path, with the loop's samples."""
    plan, answers = fast_plan(robot, path, monkeypatch, **options)
    assert answers["batch"] and answers["batch"][0] is not None
    assert not answers["lean"]  # the lean loop was not asked
    loop = loop_plan(robot, path, monkeypatch, **options)
    _assert_same(plan, loop, "answered")
    return plan


# ---------------------------------------------------------------------------- stacked algebra
def ur5_jacobians(count: int = 7) -> tuple[np.ndarray, np.ndarray]:
    """q (N, 6) along a smooth joint path of the UR5 and its tool Jacobians as rows (6, 6, N)."""
    robot = cached_robot("ur5")
    q = UR5_START + np.linspace(0.0, 0.3, count)[:, None] * np.array([1, -1, 1, 0.5, -0.5, 1])
    return q, np.array([robot.jacobian(row) for row in q]).transpose(1, 2, 0)


def test_stacked_lu_matches_lapack_determinants_and_solves():
    _, J = ur5_jacobians()
    factors = batch_track._factor(J)
    assert factors is not None
    stack = J.transpose(2, 0, 1)
    np.testing.assert_allclose(factors.determinant, np.linalg.det(stack), rtol=1e-10)
    rng = np.random.default_rng(3)
    b = rng.normal(size=(6, J.shape[2]))
    x = batch_track._solve(factors, b.copy())
    np.testing.assert_allclose(x.T, np.linalg.solve(stack, b.T[:, :, None])[:, :, 0], rtol=1e-9)
    # b is not overwritten
    b2 = b.copy()
    batch_track._solve(factors, b2)
    np.testing.assert_array_equal(b2, b)


@pytest.mark.parametrize("n", [2, 3, 4])
def test_stacked_lu_of_permuted_matrices_keeps_the_determinants_sign(n):
    """Matrices whose partial pivoting swaps rows (odd and even permutations): signed
    determinants and solutions as LAPACK's."""
    rng = np.random.default_rng(n)
    base = rng.normal(size=(n, n)) + np.diag(np.arange(1.0, n + 1))
    permutation = np.roll(np.eye(n), 1, axis=0)  # a cyclic shift: odd for even n
    first = permutation @ np.triu(base + n * np.eye(n))  # pivots far from the diagonal
    stack = np.stack([first + 0.01 * k * rng.normal(size=(n, n)) for k in range(5)])
    factors = batch_track._factor(stack.transpose(1, 2, 0))
    assert factors is not None
    np.testing.assert_allclose(factors.determinant, np.linalg.det(stack), rtol=1e-10)
    b = rng.normal(size=(n, 5))
    x = batch_track._solve(factors, b)
    np.testing.assert_allclose(x.T, np.linalg.solve(stack, b.T[:, :, None])[:, :, 0], rtol=1e-9)


def test_pivot_order_is_partial_pivoting():
    """The row order against the elimination done by hand: largest magnitude first in each
    column of the remaining rows."""
    a = np.array([[1.0, 2.0, 3.0], [4.0, 1.0, 0.0], [-8.0, 2.0, 1.0]])
    # column 0: |−8| first; then rows [4, 1, 0] and [1, 2, 3] reduced: 1 + 0.5·2 = 2 and
    # 2 + 0.125·2 = 2.25 → row 0 second
    np.testing.assert_array_equal(batch_track._pivot_order(a), [2, 0, 1])
    assert batch_track._pivot_order(np.eye(3)).tolist() == [0, 1, 2]
    # a zero column below the diagonal: no division, the order stays
    singular = np.array([[0.0, 1.0], [0.0, 2.0]])
    assert batch_track._pivot_order(singular).tolist() == [0, 1]
    # an integer matrix is eliminated in floats
    np.testing.assert_array_equal(
        batch_track._pivot_order(np.array([[1, 3, 0], [2, 1, 1], [1, 1, 4]])), [1, 0, 2]
    )


def test_pivot_order_reduces_the_remaining_rows_with_their_multipliers():
    # after the first pivot (row 1, value 2) the rows are reduced by their own multipliers:
    # row 0 → [0, 3 − 0.5·1, 0 − 0.5·1] = [0, 2.5, −0.5]; row 2 → [0, 1 − 2·1, 4 − 2·1] = [0, −1, 2]
    a = np.array([[1.0, 3.0, 0.0], [2.0, 1.0, 1.0], [4.0, 1.0, 4.0]])
    # column 0: row 2 (4) first; row 1 → [0, 1 − 0.5, 1 − 2] = [0, 0.5, −1];
    # row 0 → [0, 3 − 0.25, 0 − 1] = [0, 2.75, −1] → row 0 second
    np.testing.assert_array_equal(batch_track._pivot_order(a), [2, 0, 1])
    b = np.array([[1.0, 0.2, 0.0], [4.0, 1.0, 0.0], [2.0, 0.6, 1.0]])
    # row 1 first; row 0 → [0, 0.2 − 0.25, 0] = [0, −0.05, 0];
    # row 2 → [0, 0.6 − 0.5, 1] = [0, 0.1, 1]
    np.testing.assert_array_equal(batch_track._pivot_order(b), [1, 2, 0])


def test_stacked_lu_refuses_an_order_unsuited_to_a_later_matrix():
    """The first matrix's pivoting applied to a matrix whose pivot is small: a multiplier
    beyond MAX_MULTIPLIER, or a zero pivot, is refused (None)."""
    first = np.array([[2.0, 0.0], [1.0, 1.0]])
    for later, refused in (
        (np.array([[2.0, 0.0], [15.0, 1.0]]), False),  # multiplier 7.5
        (np.array([[2.0, 0.0], [16.0, 1.0]]), False),  # multiplier exactly 8
        (np.array([[2.0, 0.0], [17.0, 1.0]]), True),  # 8.5
        (np.array([[2.0, 0.0], [-17.0, 1.0]]), True),  # −8.5
        (np.array([[0.0, 1.0], [1.0, 1.0]]), True),  # a zero pivot
    ):
        stack = np.stack([first, later], axis=-1)
        factors = batch_track._factor(stack)
        assert (factors is None) == refused, later
        if factors is not None:
            np.testing.assert_allclose(factors.determinant, np.linalg.det(stack.T.swapaxes(1, 2)))


def test_drift_is_the_time_derivative_of_the_jacobian_times_the_rates(ur5):
    """J̇q̇ against central differences of Pinocchio's Jacobian along q̇."""
    q, J = ur5_jacobians(4)
    rng = np.random.default_rng(7)
    qd = rng.normal(size=q.shape)
    drift = batch_track._drift(J, np.ascontiguousarray(qd.T))
    eps = 1e-6
    for k in range(len(q)):
        dJ = (ur5.jacobian(q[k] + eps * qd[k]) - ur5.jacobian(q[k] - eps * qd[k])) / (2 * eps)
        np.testing.assert_allclose(drift[:, k], dJ @ qd[k], atol=1e-7)
    # a position task: the same linear rows, alone
    linear = batch_track._drift(J, np.ascontiguousarray(qd.T), angular=False)
    np.testing.assert_array_equal(linear, drift[:3])


def test_summed_cross_products():
    rng = np.random.default_rng(1)
    a, b = rng.normal(size=(3, 4, 5)), rng.normal(size=(3, 4, 5))
    expected = np.cross(a.transpose(1, 2, 0), b.transpose(1, 2, 0)).sum(axis=0).T
    np.testing.assert_allclose(batch_track._summed_cross(a, b), expected, atol=1e-14)


# ---------------------------------------------------------------------------- branches
def test_branch_of_picks_the_one_branch_near_the_start():
    q0 = np.array([0.1, -0.2, 0.3])
    raw = np.array([[1.0, 1.0, 1.0], [np.nan] * 3, q0 + 2 * np.pi, [0.1, -0.2, 2.0]])
    assert batch_track._branch_of(raw, q0) == 2  # a whole turn away is the same branch
    near = raw.copy()
    near[2] = q0 + 0.9 * SAME_BRANCH
    assert batch_track._branch_of(near, q0) == 2
    near[2] = q0 + [0.0, 0.0, 1.1 * SAME_BRANCH]
    assert batch_track._branch_of(near, q0) is None  # not near enough
    near[2] = q0 - [0.0, SAME_BRANCH, 0.0]
    assert batch_track._branch_of(near, q0) == 2  # exactly at the distance
    ambiguous = near.copy()
    ambiguous[3] = q0 + [0.0, 0.0, 0.9 * OTHER_BRANCH]
    assert batch_track._branch_of(ambiguous, q0) is None  # a second branch too near
    ambiguous[3] = q0 + [0.0, 0.0, 1.1 * OTHER_BRANCH]
    assert batch_track._branch_of(ambiguous, q0) == 2
    assert batch_track._branch_of(np.full((4, 3), np.nan), q0) is None


def test_branch_path_unwraps_each_joint_from_the_start():
    """A joint crossing ±π stays continuous; the first row is the start itself; a step beyond
    MAX_STEP is ambiguous."""
    angles = np.linspace(2.9, 3.5, 7)
    raw = np.column_stack([np.angle(np.exp(1j * angles)), np.linspace(-0.1, 0.1, 7)])
    q0 = np.array([2.9 + 1e-9, -0.1 - 4 * np.pi])  # the second joint two turns down
    q = batch_track._branch_path(raw, q0)
    assert q is not None
    np.testing.assert_array_equal(q[0], q0)
    np.testing.assert_allclose(q[:, 0], angles, atol=1e-8)
    np.testing.assert_allclose(q[:, 1], np.linspace(-0.1, 0.1, 7) - 4 * np.pi, atol=1e-12)
    step = raw.copy()
    d = raw[4, 1] - raw[3, 1]
    step[4:, 1] += 1.01 * MAX_STEP - d  # a step of 1.01 MAX_STEP between samples 3 and 4
    assert batch_track._branch_path(step, raw[0]) is None
    step[4:, 1] -= 0.02 * MAX_STEP  # 0.99 MAX_STEP: kept, continuous
    q = batch_track._branch_path(step, raw[0])
    assert q is not None
    np.testing.assert_allclose(q[:, 1], step[:, 1], atol=1e-12)
    # the first sample's own step from q0 is not limited: q0 wins
    far = batch_track._branch_path(raw, raw[0] + [0.0, 3.0])
    assert far is not None and far[0, 1] == raw[0, 1] + 3.0


# ---------------------------------------------------------------------------- monitor predicates
def tracker_of(robot: kinplan.Robot, **options) -> Tracker:
    position_only = options.pop("position_only", robot.default_position_only())
    threshold = options.pop(
        "singular_threshold", SINGULAR_FRACTION * robot.reference_manipulability(position_only)
    )
    return Tracker(
        robot, position_only, options.pop("tolerance", 1e-7), options.pop("rotation", 1e-7),
        threshold, 1.0, 0.05, options.pop("acceleration_limit", None),
    )  # fmt: skip


def test_limit_margin_is_kept_on_both_sides(planar_2r):
    tracker = tracker_of(planar_2r)
    lower, upper = planar_2r.lower, planar_2r.upper
    inside = np.array([lower + LIMIT_MARGIN, upper - LIMIT_MARGIN, np.zeros(2)])
    assert batch_track.within_limits(tracker, inside)
    for j in range(2):
        for bound, sign in ((lower, 1.0), (upper, -1.0)):
            q = np.zeros((3, 2))
            q[1, j] = bound[j] + sign * 0.5 * LIMIT_MARGIN
            assert not batch_track.within_limits(tracker, q), (j, sign)


def test_regular_keeps_the_relative_margin_above_threshold_and_floor(planar_2r):
    tracker = tracker_of(planar_2r, singular_threshold=0.1)
    assert tracker.rank_floor < 0.1
    floor = 0.1 * (1.0 + RELATIVE_MARGIN)
    assert batch_track.regular(tracker, np.array([1.0, floor * (1 + 1e-9)]))
    assert not batch_track.regular(tracker, np.array([1.0, floor]))
    assert not batch_track.regular(tracker, np.array([0.1 * (1 + 0.5 * RELATIVE_MARGIN), 1.0]))
    # a zero threshold: NEAR_SINGULAR times the rank floor (where the loop's IK tolerance
    # moves the manipulability by more than the relative margin)
    zero = tracker_of(planar_2r, singular_threshold=0.0)
    near = zero.rank_floor * batch_track.NEAR_SINGULAR
    assert batch_track.regular(zero, np.array([near * (1 + 1e-9)]))
    assert not batch_track.regular(zero, np.array([near]))
    assert not batch_track.regular(zero, np.array([zero.rank_floor * (1 + 2 * RELATIVE_MARGIN)]))


def test_acceleration_margin(planar_2r):
    limit = np.array([2.0, 4.0])
    tracker = tracker_of(planar_2r, acceleration_limit=limit)
    ok = (1.0 - 2 * RELATIVE_MARGIN) * limit
    assert batch_track.within_accelerations(tracker, np.array([ok, -ok]))
    for j in range(2):
        near = np.zeros((2, 2))
        near[1, j] = -(1.0 - 0.5 * RELATIVE_MARGIN) * limit[j]
        assert not batch_track.within_accelerations(tracker, near), j
    exact = np.array([[(1.0 - RELATIVE_MARGIN) * 2.0, 0.0]])
    assert not batch_track.within_accelerations(tracker, exact)
    assert batch_track.within_accelerations(tracker, np.empty((0, 2)))
    # only limited joints count; none limited: anything goes
    one = tracker_of(planar_2r, acceleration_limit=np.array([np.inf, 4.0]))
    assert batch_track.within_accelerations(one, np.array([[1e9, 3.0]]))
    assert not batch_track.within_accelerations(one, np.array([[0.0, 3.999]]))
    free = tracker_of(planar_2r, acceleration_limit=np.full(2, np.inf))
    assert batch_track.within_accelerations(free, np.array([[1e9, -1e9]]))


def test_clear_keeps_the_margin_from_the_clearance_and_from_contact():
    def check(obstacle, own, index=None):
        return SimpleNamespace(
            index=index, obstacle_distances=np.array(obstacle), self_distances=np.array(own)
        )

    c = 0.01
    assert batch_track.clear(check([0.5, c + 2 * CLEARANCE_MARGIN], [0.2, 2 * CLEARANCE_MARGIN]), c)
    assert not batch_track.clear(check([0.5, c + 0.5 * CLEARANCE_MARGIN], [0.2]), c)
    assert not batch_track.clear(check([c + CLEARANCE_MARGIN], [0.2]), c)
    assert not batch_track.clear(check([0.5], [0.2, 0.5 * CLEARANCE_MARGIN]), c)
    assert not batch_track.clear(check([0.5], [CLEARANCE_MARGIN]), c)
    assert not batch_track.clear(check([0.5], [0.2], index=3), c)
    assert batch_track.clear(check([0.5], [0.2], index=None), c)
    assert batch_track.clear(check([], []), 0.0)  # no pairs at all


# ---------------------------------------------------------------------------- clean paths
@pytest.mark.parametrize("name", ["ur5", "planar_2r"])
def test_a_clean_path_is_made_whole_with_the_loops_samples(name, monkeypatch):
    """The fast path answers a clean path (the loop is not run), with the loop's samples: q, q̇
    and q̈ (q̈ also the time derivative of q̇), the tool on the path, the manipulability
    |det J|, the peak speed ratio."""
    robot = cached_robot(name)
    path = ur5_line(robot) if name == "ur5" else PLANAR_LINE
    seed = UR5_START if name == "ur5" else PLANAR_START
    options = {"duration": 1.0, "q_seed": seed, "profile": "quintic", "dt": 0.005}
    plan = assert_answered(robot, path, monkeypatch, **options)
    loop = loop_plan(robot, path, monkeypatch, **options)
    np.testing.assert_allclose(plan.q, loop.q, atol=1e-6)
    np.testing.assert_allclose(plan.qd, loop.qd, atol=1e-5)
    np.testing.assert_allclose(plan.qdd, loop.qdd, atol=1e-4)
    assert plan.peak_speed_ratio == pytest.approx(loop.peak_speed_ratio, rel=1e-6)
    qdd_fd = np.gradient(plan.qd, plan.t, axis=0)
    np.testing.assert_allclose(plan.qdd[2:-2], qdd_fd[2:-2], atol=2e-3 * np.abs(qdd_fd).max())
    for k in (0, len(plan.t) // 3, len(plan.t) - 1):
        pose = robot.fk(plan.q[k])
        np.testing.assert_allclose(plan.tool_positions[k], pose.translation, atol=1e-12)
        np.testing.assert_allclose(pose.translation, path.position(plan.s[k : k + 1])[0], atol=1e-9)
        J = robot.jacobian(plan.q[k])[robot.task_rows(plan.position_only)]
        assert plan.manipulability[k] == pytest.approx(abs(np.linalg.det(J)), rel=1e-9)
        xd = path.position(plan.s[k : k + 1] + 1e-7) - path.position(plan.s[k : k + 1] - 1e-7)
        if 0 < k < len(plan.t) - 1 and name == "planar_2r":  # q̇ = J⁻¹ẋ
            sd = np.gradient(plan.s, plan.t)[k]
            np.testing.assert_allclose(J @ plan.qd[k], (xd[0] / 2e-7 * sd)[:2], atol=1e-4)
    assert plan.min_manipulability == plan.manipulability.min()
    assert plan.q.flags.c_contiguous and plan.qd.flags.c_contiguous
    assert plan.qdd.flags.c_contiguous and plan.tool_positions.flags.c_contiguous


def test_direct_track_returns_the_loops_samples(ur5, monkeypatch):
    path = ur5_line(ur5)
    args = inputs(ur5, path, monkeypatch, duration=1.0, q_seed=UR5_START)
    result = batch_track.track(*args)
    assert result is not None and result.check is None
    loop = loop_plan(ur5, path, monkeypatch, duration=1.0, q_seed=UR5_START)
    np.testing.assert_allclose(result.q, loop.q, atol=1e-6)
    np.testing.assert_allclose(result.qd, loop.qd, atol=1e-5)
    np.testing.assert_allclose(result.qdd, loop.qdd, atol=1e-4)
    np.testing.assert_allclose(result.tool_positions, loop.tool_positions, atol=1e-6)
    np.testing.assert_allclose(result.manipulability, loop.manipulability, rtol=1e-5)
    # a seed a whole turn off on joint 4 (limits ±2π): the first sample is the seed's branch
    # representative the loop starts from
    shifted = UR5_START + np.array([0, 0, 0, 2 * np.pi, 0, 0])
    args = inputs(ur5, path, monkeypatch, duration=1.0, q_seed=shifted)
    result = batch_track.track(*args)
    assert result is not None
    assert result.q[0, 3] == pytest.approx(shifted[3], abs=1e-6)
    # switched off: None
    monkeypatch.setattr(batch_track, "ENABLED", False)
    assert batch_track.track(*args) is None


def test_a_single_sample_path_and_a_moving_start(planar_2r, monkeypatch):
    """A path of one sample (nothing to predict); and the prediction check of the second
    sample when the first is not at rest (xd[0] ≠ 0: Taylor without q̈)."""
    tracker, targets, timing, xd, xdd, seed = inputs(
        planar_2r, PLANAR_LINE, monkeypatch, duration=1.0, q_seed=PLANAR_START
    )
    one = SimpleNamespace(t=timing.t[:1], s=timing.s[:1])
    single = cartesian.tracker.Targets(
        targets.positions[:1], None, targets.rate[:1], targets.curvature[:1]
    )
    result = batch_track.track(tracker, single, one, xd[:1], xdd[:1], seed)
    assert result is not None and len(result.q) == 1
    # moving at the start: a constant-speed law (ẋ = v x', ẍ = 0), which the loop predicts by
    # Taylor without q̈; far from every flag it is answered
    speed = 0.2
    moving_xd = targets.rate * speed
    result = batch_track.track(tracker, targets, timing, moving_xd, np.zeros_like(xdd), seed)
    assert result is not None
    J = np.array([planar_2r.jacobian(q)[:2] for q in result.q])
    np.testing.assert_allclose(np.einsum("nij,nj->ni", J, result.qd), moving_xd, atol=1e-9)


# ---------------------------------------------------------------------------- monitor at the margin
def test_a_path_within_the_limit_margin_falls_back(monkeypatch):
    """Joint limits moved to within LIMIT_MARGIN of the path's joint range: the loop plans it
    ok, the fast path declines; limits twice the margin away: answered."""
    robot = cached_robot("planar_2r")
    options = {"duration": 1.0, "q_seed": PLANAR_START}
    loop = loop_plan(robot, PLANAR_LINE, monkeypatch, **options)
    low, high = loop.q.min(axis=0), loop.q.max(axis=0)
    for j in range(2):
        for side in ("lower", "upper"):
            for share, declined in ((0.5, True), (2.0, False)):
                narrow = kinplan.load_robot("planar_2r")
                lower, upper = narrow.lower.copy(), narrow.upper.copy()
                if side == "lower":
                    lower[j] = low[j] - share * LIMIT_MARGIN
                else:
                    upper[j] = high[j] + share * LIMIT_MARGIN
                narrow.model.lowerPositionLimit[:] = lower
                narrow.model.upperPositionLimit[:] = upper
                narrow.lower, narrow.upper = lower, upper
                if declined:
                    assert_declined_and_loop(narrow, PLANAR_LINE, monkeypatch, **options)
                else:
                    assert_answered(narrow, PLANAR_LINE, monkeypatch, **options)


@pytest.mark.parametrize("name", ["ur5", "planar_2r"])
def test_a_path_within_the_singularity_margin_falls_back(name, monkeypatch):
    robot = cached_robot(name)
    path = ur5_line(robot) if name == "ur5" else PLANAR_LINE
    seed = UR5_START if name == "ur5" else PLANAR_START
    options = {"duration": 1.0, "q_seed": seed}
    least = loop_plan(robot, path, monkeypatch, **options).min_manipulability
    near = least / (1.0 + 0.5 * RELATIVE_MARGIN)
    assert_declined_and_loop(robot, path, monkeypatch, singular_threshold=near, **options)
    spare = least / (1.0 + 2.0 * RELATIVE_MARGIN)
    assert_answered(robot, path, monkeypatch, singular_threshold=spare, **options)


@pytest.mark.parametrize("name", ["ur5", "planar_2r"])
def test_a_path_within_the_speed_margin_falls_back(name, monkeypatch):
    robot = cached_robot(name)
    path = ur5_line(robot) if name == "ur5" else PLANAR_LINE
    seed = UR5_START if name == "ur5" else PLANAR_START
    options = {"duration": 1.0, "q_seed": seed}
    reference = loop_plan(robot, path, monkeypatch, **options)
    # the fast path's margin is on the samples' speeds; the plan's peak also counts the motion
    # between the samples (a little higher), which decides whether the loop's plan is ok
    at_samples = joint_speeds(reference.q, reference.qd, reference.t) / robot.velocity_limit
    near = float(at_samples.max()) / (1.0 - 0.5 * RELATIVE_MARGIN)
    loop = assert_declined_and_loop(
        robot, path, monkeypatch, must_pass=False, velocity_scale=near, **options
    )
    assert loop.ok == (reference.peak_speed_ratio <= near * (1 + 1e-9)), loop
    peak = reference.peak_speed_ratio
    spare = peak / (1.0 - 2.0 * RELATIVE_MARGIN)
    plan = assert_answered(robot, path, monkeypatch, velocity_scale=spare, **options)
    assert plan.peak_speed_ratio == pytest.approx(1.0 - 2.0 * RELATIVE_MARGIN)


@pytest.mark.parametrize("name", ["ur5", "planar_2r"])
def test_a_path_within_the_acceleration_margin_falls_back(name, monkeypatch):
    robot = cached_robot(name)
    path = ur5_line(robot) if name == "ur5" else PLANAR_LINE
    seed = UR5_START if name == "ur5" else PLANAR_START
    options = {"duration": 1.0, "q_seed": seed, "profile": "quintic"}
    reference = loop_plan(robot, path, monkeypatch, **options)
    peaks = np.abs(reference.qdd).max(axis=0)  # at the samples: what the fast path's margin sees
    # between the samples too: what decides whether the loop's plan is ok
    fractions = np.arange(1, 16) / 16
    between = hermite_between(reference.t, reference.q, reference.qd, reference.qdd, fractions)
    whole = np.maximum(peaks, np.abs(between[3]).max(axis=(0, 1)))
    for j in range(robot.nq):  # one joint at a time near its limit, the others free
        near = np.full(robot.nq, 1e6)
        near[j] = peaks[j] / (1.0 - 0.5 * RELATIVE_MARGIN)
        loop = assert_declined_and_loop(
            robot, path, monkeypatch, must_pass=False, max_acceleration=near, **options
        )
        assert loop.ok == (whole[j] <= near[j] * (1 + 1e-9)), loop
        if j == 0:
            spare = np.full(robot.nq, 1e6)
            spare[j] = whole[j] / (1.0 - 2.0 * RELATIVE_MARGIN)
            assert_answered(robot, path, monkeypatch, max_acceleration=spare, **options)


def test_a_path_within_the_clearance_margin_falls_back(ur5, monkeypatch):
    """A box beside the path: clearance within CLEARANCE_MARGIN of the smallest distance is
    declined (the loop plans it ok), with the margin to spare answered, with the same check."""
    path = ur5_line(ur5)
    p0 = ur5.fk(UR5_START).translation
    cell = kinplan.WorkCell(ur5)
    cell.add_box("post", [0.05, 0.05, 0.05], pin.SE3(np.eye(3), p0 + [0.2, 0.1, 0.0]))
    options = {"duration": 1.0, "q_seed": UR5_START, "cell": cell}
    least = loop_plan(ur5, path, monkeypatch, **options).min_clearance
    assert 0.01 < least < 0.5
    loop = assert_declined_and_loop(
        ur5, path, monkeypatch, clearance=least - 0.5 * CLEARANCE_MARGIN, **options
    )
    assert loop.min_clearance == pytest.approx(least)
    plan = assert_answered(
        ur5, path, monkeypatch, clearance=least - 2 * CLEARANCE_MARGIN, **options
    )
    assert plan.min_clearance == pytest.approx(least) and plan.cell_check is not None
    assert plan.min_self_clearance == pytest.approx(loop.min_self_clearance, abs=1e-8)
    # the plan's check is the one made with the clearance asked for
    assert plan.cell_check.clearance == least - 2 * CLEARANCE_MARGIN
    assert plan.cell_check.index is None


def test_a_path_within_the_jump_margin_falls_back(monkeypatch):
    """The jump tolerance lowered until the path's largest unexplained joint step (trapezoidal
    rule on q̇) is above JUMP_SHARE of it: declined, although the loop (which tests jumps only
    where Newton corrected a sample, against the whole tolerance) plans it ok."""
    robot = cached_robot("planar_2r")
    options = {"duration": 0.6, "q_seed": PLANAR_START, "dt": 0.0375}  # 16 intervals: one grid
    loop = loop_plan(robot, PLANAR_LINE, monkeypatch, **options)
    h = np.diff(loop.t)[:, None]
    unexplained = np.abs(np.diff(loop.q, axis=0) - 0.5 * h * (loop.qd[1:] + loop.qd[:-1])).max()
    assert unexplained > 1e-4
    near = 0.99 * unexplained / JUMP_SHARE
    assert_declined_and_loop(robot, PLANAR_LINE, monkeypatch, jump_tolerance=near, **options)
    assert_answered(
        robot, PLANAR_LINE, monkeypatch, jump_tolerance=10 * unexplained / JUMP_SHARE, **options
    )


def test_a_poor_prediction_falls_back(monkeypatch):
    """The loop's predictions (Taylor at the second sample, Adams–Bashforth after) against the
    solutions: a coarse fast sampling whose predictions miss by more than JUMP_SHARE of the
    jump tolerance is declined; the check of the second sample alone too."""
    robot = cached_robot("planar_2r")
    options = {"duration": 0.6, "q_seed": PLANAR_START, "dt": 0.0375}  # 16 intervals: one grid
    tracker, targets, timing, xd, xdd, seed = inputs(robot, PLANAR_LINE, monkeypatch, **options)
    result = batch_track.track(tracker, targets, timing, xd, xdd, seed)
    assert result is not None
    q, qd, t = result.q, result.qd, timing.t
    h = np.diff(t)
    J0 = robot.jacobian(q[0])[:2]
    taylor = q[0] + qd[0] * h[0] + 0.5 * h[0] ** 2 * np.linalg.solve(J0, xdd[0])
    second = np.abs(taylor - q[1]).max()
    ratio = 0.5 * h[1:] / h[:-1]
    ab = q[1:-1] + qd[1:-1] * (h[1:] * (1 + ratio))[:, None] - qd[:-2] * (h[1:] * ratio)[:, None]
    later = np.abs(ab - q[2:]).max()
    step = np.abs(np.diff(q, axis=0) - 0.5 * h[:, None] * (qd[1:] + qd[:-1])).max()
    assert second > 0 and later > step  # the predictions are the binding test here
    for miss, declined in ((later, True), (max(step, second) * 1.01, True), (later * 1.02, False)):
        tracker.jump_tolerance = miss / JUMP_SHARE * (0.99 if declined else 1.0)
        answered = batch_track.track(tracker, targets, timing, xd, xdd, seed)
        assert (answered is None) == declined, miss
    # the second sample's Taylor prediction alone: a two-sample path
    two = SimpleNamespace(t=t[:2], s=timing.s[:2])
    short = cartesian.tracker.Targets(
        targets.positions[:2], None, targets.rate[:2], targets.curvature[:2]
    )
    tracker.jump_tolerance = 10.0
    # (ẍ of the first sample tripled: only the prediction uses it, so the Taylor term binds)
    xdd2 = xdd[:2] * np.array([[3.0], [1.0]])
    base = batch_track.track(tracker, short, two, xd[:2], xdd2, seed)
    assert base is not None
    step2 = np.abs(base.q[1] - base.q[0] - 0.5 * h[0] * (base.qd[1] + base.qd[0])).max()
    miss2 = np.abs(
        base.q[0] + base.qd[0] * h[0] + 0.5 * h[0] ** 2 * np.linalg.solve(J0, xdd2[0]) - base.q[1]
    ).max()
    assert miss2 > 1.5 * step2
    tracker.jump_tolerance = 0.99 * miss2 / JUMP_SHARE
    assert batch_track.track(tracker, short, two, xd[:2], xdd2, seed) is None
    tracker.jump_tolerance = 1.01 * miss2 / JUMP_SHARE
    assert batch_track.track(tracker, short, two, xd[:2], xdd2, seed) is not None


def test_tolerances_above_the_maximum_are_left_to_the_loop(ur5, monkeypatch):
    path = ur5_line(ur5)
    options = {"duration": 1.0, "q_seed": UR5_START}
    assert_answered(ur5, path, monkeypatch, tolerance=1e-6, rotation_tolerance=1e-6, **options)
    for loose in ({"tolerance": 2e-6}, {"rotation_tolerance": 2e-6}):
        plan, answers = fast_plan(ur5, path, monkeypatch, **loose, **options)
        assert answers["batch"] == [None] and plan.ok, loose


def test_a_start_the_ik_cannot_reach_is_left_to_the_loop(ur5, planar_2r, monkeypatch):
    """A path starting beyond reach: the first configuration misses the target (None); the
    loop reports it unreachable."""
    far = cartesian.Line([2.5, 0.0, 0.0], [1.0, 0.5, 0.0])
    plan, answers = fast_plan(planar_2r, far, monkeypatch, duration=1.0, q_seed=PLANAR_START)
    assert answers["batch"] == [None] and plan.status == "unreachable"
    start = ur5.fk(UR5_START)
    out = cartesian.Line(
        pin.SE3(start.rotation, np.array([1.5, 0.0, 0.4])),
        pin.SE3(start.rotation, start.translation),
    )
    plan, answers = fast_plan(ur5, out, monkeypatch, duration=1.0, q_seed=UR5_START)
    assert answers["batch"] == [None] and plan.status == "unreachable"


def test_a_path_leaving_the_workspace_is_left_to_the_loop(planar_2r, monkeypatch):
    """A path that starts reachable and ends beyond reach: no solution on the branch (NaN)."""
    line = cartesian.Line([1.2, 0.3, 0.0], [2.4, 0.6, 0.0])
    plan, answers = fast_plan(planar_2r, line, monkeypatch, duration=5.0, q_seed=PLANAR_START)
    assert answers["batch"] and not any(answers["batch"])
    assert plan.status in ("unreachable", "singular")
    loop = loop_plan(planar_2r, line, monkeypatch, duration=5.0, q_seed=PLANAR_START)
    _assert_same(plan, loop, "leaving")


def test_a_singular_start_configuration_is_ambiguous(planar_2r, monkeypatch):
    """At the 2R's stretched configuration the two branches coincide: the branch is ambiguous
    (None) and the loop reports the singularity."""
    line = cartesian.Line([2.0, 0.0, 0.0], [1.2, 0.5, 0.0])
    plan, answers = fast_plan(
        planar_2r, line, monkeypatch, duration=1.0, q_seed=[0.0, 0.0], singular_threshold=0.0
    )
    assert answers["batch"] == [None]
    loop = loop_plan(planar_2r, line, monkeypatch, duration=1.0, q_seed=[0.0, 0.0],
                     singular_threshold=0.0)  # fmt: skip
    _assert_same(plan, loop, "stretched start")


def test_position_only_ur_and_orientation_planar_tasks_are_declined(ur5, monkeypatch):
    """The UR closed form needs a rotation; a planar 2R solves positions only."""
    path = ur5_line(ur5)
    plan, answers = fast_plan(ur5, path, monkeypatch, duration=1.0, q_seed=UR5_START,
                              position_only=True)  # fmt: skip
    assert answers["batch"] == [None] and plan.ok
    tracker = tracker_of(ur5, position_only=False)
    assert batch_track._branch_solver(tracker) is ur5.closed_form_ik
    tracker = tracker_of(ur5, position_only=True)
    assert batch_track._branch_solver(tracker) is None
    planar = cached_robot("planar_2r")
    assert batch_track._branch_solver(tracker_of(planar)) is planar.closed_form_ik
    panda = cached_robot("panda")
    assert batch_track._branch_solver(tracker_of(panda, position_only=False)) is None


def test_a_moving_start_is_predicted_without_a_start_acceleration(planar_2r, monkeypatch):
    """At a start that is not at rest the loop predicts the second sample by Taylor without q̈
    (J⁻¹ẍ is q̈ only at rest: moving, q̈ = J⁻¹(ẍ − J̇q̇)). On an arc at constant speed that
    prediction misses by about ½h²|q̈|, far more than any later prediction or step: a jump
    tolerance whose share lies just below that miss is declined, just above it answered."""
    arc = cartesian.Arc([1.2, 0.3, 0.0], [0.9, 0.9, 0.0], [0.3, 1.2, 0.0])
    tracker, _, timing, *_, seed = inputs(
        planar_2r, arc, monkeypatch, duration=1.0, q_seed=PLANAR_START, dt=0.01
    )
    rate = 0.8  # ṡ [1/s]
    t = timing.t[timing.t <= 1.0 / rate]
    s = rate * t
    targets = cartesian.tracker.path_targets(arc, s, True, tracker.rows)
    xd, xdd = targets.rate * rate, targets.curvature * rate**2
    clock = SimpleNamespace(t=t, s=s)
    tracker.jump_tolerance = 10.0
    result = batch_track.track(tracker, targets, clock, xd, xdd, seed)
    assert result is not None
    q, qd, h = result.q, result.qd, np.diff(t)
    J0 = planar_2r.jacobian(q[0])[:2]
    np.testing.assert_allclose(J0 @ qd[0], xd[0], atol=1e-9)  # moving at the start
    without = np.abs(q[0] + qd[0] * h[0] - q[1]).max()
    at_rest = np.abs(q[0] + qd[0] * h[0] + 0.5 * h[0] ** 2 * np.linalg.solve(J0, xdd[0]) - q[1])
    ratio = 0.5 * h[1:] / h[:-1]
    ab = q[1:-1] + qd[1:-1] * (h[1:] * (1 + ratio))[:, None] - qd[:-2] * (h[1:] * ratio)[:, None]
    unexplained = np.abs(np.diff(q, axis=0) - 0.5 * h[:, None] * (qd[1:] + qd[:-1])).max()
    assert without > 100 * max(np.abs(ab - q[2:]).max(), unexplained)
    assert at_rest.max() > 2 * without  # the at-rest guess would be the worse one here
    tracker.jump_tolerance = 0.99 * without / JUMP_SHARE
    assert batch_track.track(tracker, targets, clock, xd, xdd, seed) is None
    tracker.jump_tolerance = 1.01 * without / JUMP_SHARE
    assert batch_track.track(tracker, targets, clock, xd, xdd, seed) is not None


def test_uneven_steps_are_predicted_with_their_own_ratio(planar_2r, monkeypatch):
    """Samples at uneven times (a subset of a timed path's samples, steps of 1 to 3 dt): the
    loop's Adams–Bashforth predictions use each step's ratio to the one before; the fast path's
    check of them declines a jump tolerance whose share is just below their largest miss and
    answers one just above."""
    tracker, targets, timing, xd, xdd, seed = inputs(
        planar_2r, PLANAR_LINE, monkeypatch, duration=1.0, q_seed=PLANAR_START, dt=0.01
    )
    idx = np.cumsum([0] + [1, 3, 1, 2, 3, 1, 1, 2] * 12)
    idx = idx[idx < len(timing.t)]
    clock = SimpleNamespace(t=timing.t[idx], s=timing.s[idx])
    subset = cartesian.tracker.Targets(
        targets.positions[idx], None, targets.rate[idx], targets.curvature[idx]
    )
    tracker.jump_tolerance = 10.0
    result = batch_track.track(tracker, subset, clock, xd[idx], xdd[idx], seed)
    assert result is not None
    q, qd, h = result.q, result.qd, np.diff(clock.t)
    ratio = 0.5 * h[1:] / h[:-1]
    ab = q[1:-1] + qd[1:-1] * (h[1:] * (1 + ratio))[:, None] - qd[:-2] * (h[1:] * ratio)[:, None]
    miss = np.abs(ab - q[2:]).max()
    J0 = planar_2r.jacobian(q[0])[:2]
    taylor = np.abs(q[0] + 0.5 * h[0] ** 2 * np.linalg.solve(J0, xdd[idx][0]) - q[1]).max()
    unexplained = np.abs(np.diff(q, axis=0) - 0.5 * h[:, None] * (qd[1:] + qd[:-1])).max()
    assert miss > 1.05 * max(taylor, unexplained)
    for factor, declined in ((0.99, True), (1.01, False)):
        tracker.jump_tolerance = factor * miss / JUMP_SHARE
        answer = batch_track.track(tracker, subset, clock, xd[idx], xdd[idx], seed)
        assert (answer is None) == declined, factor


def test_branch_path_follows_a_joint_over_more_than_a_turn():
    """A joint turning 5 rad in small steps (the closed form returns it wrapped to ±π): the
    path accumulates every step from the start, so the last sample is 5 rad from the first."""
    angles = np.linspace(0.5, 5.5, 41)
    raw = np.column_stack([np.angle(np.exp(1j * angles)), np.angle(np.exp(-1j * angles))])
    q = batch_track._branch_path(raw, np.array([0.5, -0.5]))
    assert q is not None
    np.testing.assert_allclose(q, np.column_stack([angles, -angles]), atol=1e-12)


def test_a_zero_pivot_is_refused_quietly():
    """A later matrix with a zero pivot in the first one's row order (1/0 and 0/0): refused,
    without a floating-point warning."""
    import warnings

    first = np.array([[2.0, 0.0], [1.0, 1.0]])
    for later in (np.array([[0.0, 1.0], [1.0, 1.0]]), np.array([[0.0, 0.0], [0.0, 1.0]])):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert batch_track._factor(np.stack([first, later], axis=-1)) is None


def test_a_seed_near_the_start_is_answered(ur5, monkeypatch):
    """A seed 0.05 rad off the start configuration on every joint: the first sample is the full
    pose's IK from it (its orientation too), so the fast path answers with the loop's plan."""
    seed = UR5_START + 0.05
    assert_answered(ur5, ur5_line(ur5), monkeypatch, duration=1.0, q_seed=seed)


def test_the_closed_forms_poses_are_checked_against_the_tolerances(ur5, monkeypatch):
    """Tolerances below the closed form's rounding (set on the tracker after its first sample
    passed): a position or a rotation not met is declined."""
    args = inputs(ur5, ur5_line(ur5), monkeypatch, duration=1.0, q_seed=UR5_START)
    tracker = args[0]
    assert batch_track.track(*args) is not None
    tracker.tolerance = 1e-30
    assert batch_track.track(*args) is None
    tracker.tolerance, tracker.rotation_tolerance = 1e-7, 1e-30
    assert batch_track.track(*args) is None


def test_a_path_ending_at_full_stretch_is_left_to_the_loop():
    """With the singularity threshold off, a line ending 2 nm inside the planar 2R's reach:
    the exact closed form ends regular (θ2 ≈ 9e-5), but the loop's IK (within 1e-7 m) lands
    nearer the stretched arm and reports a singularity. That close to the rank floor only the
    loop can say what the loop would report: the fast path declines and follow's plan is the
    loop's (found by the mutation pass)."""
    robot = cached_robot("planar_2r")
    end = (2 - 2e-9) * np.array([np.cos(0.4), np.sin(0.4), 0.0])
    line = cartesian.Line([1.6, 0.3, 0.0], end)
    options = dict(duration=2.0, q_seed=[0.3, 1.0], singular_threshold=0.0)
    plan = cartesian.follow(robot, line, **options)
    assert plan.status == "singular" and plan.events[0].index == len(plan.t)


def test_permutation_sign_is_the_determinant_of_the_permutation_matrix():
    """Every permutation of up to 6 rows: −1 to the number of inversions equals numpy's
    determinant of the permutation matrix."""
    for n in range(1, 7):
        for order in itertools.permutations(range(n)):
            order = np.array(order)
            expected = np.linalg.det(np.eye(n)[order])
            assert batch_track._permutation_sign(order) == round(expected), order


def pivot_order_reference(matrix: np.ndarray) -> np.ndarray:
    """Partial pivoting in numpy (argmax takes the first of equal magnitudes)."""
    a = matrix.astype(float)
    n = len(a)
    order = np.arange(n)
    for k in range(n - 1):
        p = k + int(np.argmax(np.abs(a[k:, k])))
        a[[k, p]], order[[k, p]] = a[[p, k]], order[[p, k]]
        if a[k, k] != 0.0:
            a[k + 1 :] -= np.outer(a[k + 1 :, k] / a[k, k], a[k])
    return order


def test_pivot_order_equals_numpy_partial_pivoting_on_random_matrices():
    """3,000 random matrices of sizes 1–7, a third with ties (small integers) and zero
    columns: the same row order as elimination in numpy."""
    rng = np.random.default_rng(31)
    for i in range(3000):
        n = int(rng.integers(1, 8))
        if i % 3 == 0:
            a = rng.integers(-2, 3, size=(n, n)).astype(float)  # ties and zero pivots
        else:
            a = rng.normal(size=(n, n)) * 10.0 ** rng.uniform(-3, 3, size=(n, 1))
        np.testing.assert_array_equal(batch_track._pivot_order(a), pivot_order_reference(a))
