"""The lean per-sample follower (:mod:`cartesian.lean_track`): what its mutation survivors
showed untested, each against an independent answer.

* The stacked manipulability and rates against numpy's SVD pseudo-inverse, for square, wide
  and tall task Jacobians; the per-sample rate closures against the same.
* Every monitor condition at its safety margin on the panda (no vectorised closed form): a path
  that comes within the margin of a joint limit, the singularity threshold, a joint speed or
  acceleration limit, the cell's clearance or the jump tolerance is declined (``track`` returns
  None) although the full loop plans it without an event, and follow's plan is then the loop's;
  with the margin to spare the lean loop answers, with the loop's samples.
* The geometric trace against the exact one: the same points (bisections included), q and
  dq/ds, and a trace the Newton steps cannot finish left to the exact trace.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pinocchio as pin
import pytest
from conftest import cached_robot
from test_follow_vectorised import _assert_same

import cartesian
import kinplan
from cartesian import batch_track, lean_track
from cartesian.batch_track import CLEARANCE_MARGIN, JUMP_SHARE, LIMIT_MARGIN, RELATIVE_MARGIN
from cartesian.geometry import MAX_JOINT_STEP, MIN_REFINE_DS
from cartesian.tracker import SINGULAR_FRACTION, Tracker, matvec, pseudo_inverses
from kinplan.model.robot import manipulability_of
from kinplan.trajectory.sampling import hermite_between, joint_speeds

PANDA_START = np.array([0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.78])


def panda_line(robot: kinplan.Robot, offset=(0.0, 0.2, 0.0)) -> cartesian.Line:
    start = robot.fk(PANDA_START)
    return cartesian.Line(start, pin.SE3(start.rotation, start.translation + np.array(offset)))


def loop_plan(robot, path, monkeypatch, **options) -> cartesian.CartesianPlan:
    with monkeypatch.context() as patch:
        patch.setattr(batch_track, "ENABLED", False)
        patch.setattr(lean_track, "ENABLED", False)
        return cartesian.follow(robot, path, **options)


def lean_plan(robot, path, monkeypatch, **options):
    """(plan with the lean loop, the results lean_track.track gave)."""
    answers: list = []
    track = lean_track.track

    def spy(*args, **kwargs):
        answers.append(track(*args, **kwargs))
        return answers[-1]

    with monkeypatch.context() as patch:
        patch.setattr(lean_track, "track", spy)
        plan = cartesian.follow(robot, path, **options)
    return plan, answers


def assert_declined_and_loop(
    robot, path, monkeypatch, must_pass: bool = True, **options
) -> cartesian.CartesianPlan:
    plan, answers = lean_plan(robot, path, monkeypatch, **options)
    assert answers and answers[0] is None
    loop = loop_plan(robot, path, monkeypatch, **options)
    assert loop.ok or not must_pass, loop
    _assert_same(plan, loop, "declined")
    np.testing.assert_array_equal(plan.q, loop.q)
    return loop


def assert_answered(robot, path, monkeypatch, **options) -> cartesian.CartesianPlan:
    plan, answers = lean_plan(robot, path, monkeypatch, **options)
    assert answers and answers[0] is not None
    loop = loop_plan(robot, path, monkeypatch, **options)
    _assert_same(plan, loop, "answered")
    np.testing.assert_allclose(plan.q, loop.q, rtol=0, atol=1e-9)  # the same predictions
    return plan


def inputs(robot, path, monkeypatch, **options) -> tuple:
    """The arguments follow hands lean_track.track."""
    captured: list[tuple] = []

    def spy(*args):
        captured.append(args)
        return None

    with monkeypatch.context() as patch:
        patch.setattr(lean_track, "track", spy)
        cartesian.follow(robot, path, **options)
    return captured[0]


# ---------------------------------------------------------------------------- stacked algebra
@pytest.mark.parametrize("shape", [(6, 7), (6, 6), (6, 4), (3, 7), (2, 2)])
def test_stacked_manipulability_and_rates_against_the_pseudo_inverse(shape):
    rng = np.random.default_rng(sum(shape))
    task = rng.normal(size=(5, *shape))
    singular_values = np.linalg.svd(task, compute_uv=False)
    np.testing.assert_allclose(
        manipulability_of(task, min(shape)), np.prod(singular_values, axis=1), rtol=1e-10
    )
    xd = rng.normal(size=(5, shape[0]))
    expected = np.einsum("nij,nj->ni", np.linalg.pinv(task), xd)
    rates = matvec(pseudo_inverses(task, min(shape)), xd)
    np.testing.assert_allclose(rates, expected, atol=1e-10)


def fake_tracker(rows, nq):
    return SimpleNamespace(rows=np.asarray(rows), robot=SimpleNamespace(nq=nq))


@pytest.mark.parametrize(
    ("rows", "nq"),
    [(range(6), 7), (range(6), 6), (range(6), 4), ([0, 1, 2], 7), ([0, 1], 2), ([0, 1, 5], 2)],
)
def test_rate_closures_against_the_pseudo_inverse(rows, nq):
    """rate(J, b) = J⁺b and rates(J, B) = (J⁺B)ᵀ on the task rows of a tool Jacobian."""
    rng = np.random.default_rng(nq + len(rows))
    tracker = fake_tracker(list(rows), nq)
    J = rng.normal(size=(6, nq))
    task = J[list(rows)]
    b = rng.normal(size=len(rows))
    B = rng.normal(size=(len(rows), 2))
    pinv = np.linalg.pinv(task)
    np.testing.assert_allclose(lean_track._rates(tracker)(J, b), pinv @ b, atol=1e-10)
    np.testing.assert_allclose(lean_track._rates(tracker)(J, B), (pinv @ B).T, atol=1e-10)


# ---------------------------------------------------------------------------- clean paths
def test_a_clean_path_is_made_lean_with_the_loops_samples(panda, monkeypatch):
    """Answered by the lean loop: the loop's samples (the same predictions: q to 1e-9), q̇ with
    J q̇ = ẋ, q̈ = dq̇/dt, the tool on the path, the manipulability of J, the peak speed."""
    options = {"duration": 1.0, "q_seed": PANDA_START, "profile": "quintic", "dt": 0.005}
    path = panda_line(panda)
    plan = assert_answered(panda, path, monkeypatch, **options)
    loop = loop_plan(panda, path, monkeypatch, **options)
    np.testing.assert_allclose(plan.qd, loop.qd, atol=1e-8)
    np.testing.assert_allclose(plan.qdd, loop.qdd, atol=1e-6)
    assert plan.peak_speed_ratio == pytest.approx(loop.peak_speed_ratio, rel=1e-9)
    np.testing.assert_allclose(plan.manipulability, loop.manipulability, rtol=1e-9)
    np.testing.assert_allclose(plan.tool_positions, loop.tool_positions, atol=1e-12)
    qdd_fd = np.gradient(plan.qd, plan.t, axis=0)
    np.testing.assert_allclose(plan.qdd[2:-2], qdd_fd[2:-2], atol=2e-3 * np.abs(qdd_fd).max())
    sd = np.gradient(plan.s, plan.t)
    for k in (0, 50, 100, 150, len(plan.t) - 1):
        J = panda.jacobian(plan.q[k])
        assert plan.manipulability[k] == pytest.approx(np.sqrt(np.linalg.det(J @ J.T)), rel=1e-9)
        np.testing.assert_allclose(plan.tool_positions[k], panda.fk(plan.q[k]).translation)
        if 0 < k < len(plan.t) - 1:
            dx = path.position(plan.s[k : k + 1] + 1e-6) - path.position(plan.s[k : k + 1] - 1e-6)
            np.testing.assert_allclose((J @ plan.qd[k])[:3], dx[0] / 2e-6 * sd[k], atol=1e-3)
            np.testing.assert_allclose((J @ plan.qd[k])[3:], 0.0, atol=1e-9)


@pytest.mark.parametrize("dt", [0.05, 0.013])
def test_coarse_and_uneven_samplings_keep_the_loops_predictions(panda, monkeypatch, dt):
    """A coarse sampling (Newton corrects most predictions) and one whose last step is short
    (uneven Adams–Bashforth weights): the lean loop gives the loop's q to 1e-9."""
    path = panda_line(panda, (0.1, 0.15, -0.1))
    assert_answered(panda, path, monkeypatch, duration=0.8, q_seed=PANDA_START, dt=dt)


def test_a_turning_orientation_and_a_position_only_task(panda, monkeypatch):
    start = panda.fk(PANDA_START)
    turned = start.rotation @ pin.exp3(np.array([0.2, -0.1, 0.3]))
    path = cartesian.Line(start, pin.SE3(turned, start.translation + [0.05, 0.1, 0.0]))
    assert_answered(panda, path, monkeypatch, duration=1.0, q_seed=PANDA_START)
    line = cartesian.Line(start.translation, start.translation + [0.0, 0.15, 0.05])
    plan = assert_answered(
        panda, line, monkeypatch, duration=1.0, q_seed=PANDA_START, position_only=True
    )
    J = np.array([panda.jacobian(q)[:3] for q in plan.q])
    np.testing.assert_allclose(
        plan.manipulability, np.sqrt(np.linalg.det(J @ J.transpose(0, 2, 1))), rtol=1e-9
    )


def test_a_moving_start_uses_no_start_acceleration(panda, monkeypatch):
    """ẋ ≠ 0 at the first sample (a constant-speed law): the prediction of the second sample is
    Taylor without q̈; the samples keep J q̇ = ẋ."""
    tracker, targets, timing, xd, xdd, seed = inputs(
        panda, panda_line(panda), monkeypatch, duration=1.0, q_seed=PANDA_START
    )
    moving = targets.rate * 0.1
    result = lean_track.track(tracker, targets, timing, moving, np.zeros_like(xdd), seed)
    assert result is not None
    J = np.array([panda.jacobian(q) for q in result.q])
    np.testing.assert_allclose(np.einsum("nij,nj->ni", J, result.qd), moving, atol=1e-9)
    assert np.all(np.linalg.norm(result.qd, axis=1) > 0)
    # a single sample
    one = SimpleNamespace(t=timing.t[:1], s=timing.s[:1])
    first = cartesian.tracker.Targets(targets.positions[:1], targets.rotations[:1],
                                      targets.rate[:1], targets.curvature[:1])  # fmt: skip
    single = lean_track.track(tracker, first, one, xd[:1], xdd[:1], seed)
    assert single is not None and len(single.q) == 1 and single.q.shape == (1, 7)
    assert single.tool_positions.shape == (1, 3)


def test_a_deficient_task_is_left_to_the_loop(monkeypatch):
    """A task of rank below its size (the loop's SVD pseudo-inverse): declined."""
    robot = cached_robot("ur5")
    tracker = Tracker(robot, False, 1e-7, 1e-7, 0.0, 1.0, 0.05)
    assert lean_track._full_rank(tracker)
    tracker.rank = 5
    assert not lean_track._full_rank(tracker)
    twin = SimpleNamespace(rank=2, rows=np.arange(3), robot=SimpleNamespace(nq=2))
    assert lean_track._full_rank(twin)
    twin = SimpleNamespace(rank=2, rows=np.arange(2), robot=SimpleNamespace(nq=3))
    assert lean_track._full_rank(twin)
    twin = SimpleNamespace(rank=1, rows=np.arange(2), robot=SimpleNamespace(nq=3))
    assert not lean_track._full_rank(twin)


# ---------------------------------------------------------------------------- monitor at the margin
def test_a_path_within_the_limit_margin_falls_back(monkeypatch):
    options = {"duration": 1.0, "q_seed": PANDA_START}
    base = cached_robot("panda")
    loop = loop_plan(base, panda_line(base), monkeypatch, **options)
    low, high = loop.q.min(axis=0), loop.q.max(axis=0)
    for j, side in ((0, "lower"), (0, "upper"), (3, "upper"), (6, "lower")):
        for share, declined in ((0.5, True), (2.0, False)):
            narrow = kinplan.load_robot("panda")
            lower, upper = narrow.lower.copy(), narrow.upper.copy()
            if side == "lower":
                lower[j] = low[j] - share * LIMIT_MARGIN
            else:
                upper[j] = high[j] + share * LIMIT_MARGIN
            narrow.model.lowerPositionLimit[:] = lower
            narrow.model.upperPositionLimit[:] = upper
            narrow.lower, narrow.upper = lower, upper
            path = panda_line(narrow)
            if declined:
                assert_declined_and_loop(narrow, path, monkeypatch, **options)
            else:
                assert_answered(narrow, path, monkeypatch, **options)


def test_a_path_within_the_singularity_margin_falls_back(panda, monkeypatch):
    options = {"duration": 1.0, "q_seed": PANDA_START}
    path = panda_line(panda)
    least = loop_plan(panda, path, monkeypatch, **options).min_manipulability
    near = least / (1.0 + 0.5 * RELATIVE_MARGIN)
    assert_declined_and_loop(panda, path, monkeypatch, singular_threshold=near, **options)
    spare = least / (1.0 + 2.0 * RELATIVE_MARGIN)
    assert_answered(panda, path, monkeypatch, singular_threshold=spare, **options)
    # the threshold's default: a share of the arm's median manipulability
    default = SINGULAR_FRACTION * panda.reference_manipulability(False)
    assert loop_plan(panda, path, monkeypatch, **options).singular_threshold == default


def test_a_path_within_the_speed_margin_falls_back(panda, monkeypatch):
    options = {"duration": 1.0, "q_seed": PANDA_START}
    path = panda_line(panda)
    reference = loop_plan(panda, path, monkeypatch, **options)
    # the lean loop's margin is on the samples' speeds; the plan's peak also counts the motion
    # between the samples (a little higher), which decides whether the loop's plan is ok
    at_samples = joint_speeds(reference.q, reference.qd, reference.t) / panda.velocity_limit
    near = float(at_samples.max()) / (1.0 - 0.5 * RELATIVE_MARGIN)
    loop = assert_declined_and_loop(
        panda, path, monkeypatch, must_pass=False, velocity_scale=near, **options
    )
    assert loop.ok == (reference.peak_speed_ratio <= near * (1 + 1e-9)), loop
    peak = reference.peak_speed_ratio
    spare = peak / (1.0 - 2.0 * RELATIVE_MARGIN)
    plan = assert_answered(panda, path, monkeypatch, velocity_scale=spare, **options)
    assert plan.peak_speed_ratio == pytest.approx(1.0 - 2.0 * RELATIVE_MARGIN)


def test_a_path_within_the_acceleration_margin_falls_back(panda, monkeypatch):
    options = {"duration": 1.0, "q_seed": PANDA_START, "profile": "quintic"}
    path = panda_line(panda)
    reference = loop_plan(panda, path, monkeypatch, **options)
    peaks = np.abs(reference.qdd).max(axis=0)  # at the samples: what the lean loop's margin sees
    fractions = np.arange(1, 16) / 16  # between them too: what decides whether the plan is ok
    between = hermite_between(reference.t, reference.q, reference.qd, reference.qdd, fractions)
    whole = np.maximum(peaks, np.abs(between[3]).max(axis=(0, 1)))
    for j in (0, 3, 6):
        near = np.full(7, 1e6)
        near[j] = peaks[j] / (1.0 - 0.5 * RELATIVE_MARGIN)
        loop = assert_declined_and_loop(
            panda, path, monkeypatch, must_pass=False, max_acceleration=near, **options
        )
        assert loop.ok == (whole[j] <= near[j] * (1 + 1e-9)), loop
    spare = whole / (1.0 - 2.0 * RELATIVE_MARGIN)
    assert_answered(panda, path, monkeypatch, max_acceleration=spare, **options)


def test_a_path_within_the_clearance_margin_falls_back(panda, monkeypatch):
    path = panda_line(panda)
    p0 = panda.fk(PANDA_START).translation
    cell = kinplan.WorkCell(panda)
    cell.add_box("post", [0.05, 0.05, 0.05], pin.SE3(np.eye(3), p0 + [0.2, 0.1, 0.0]))
    options = {"duration": 1.0, "q_seed": PANDA_START, "cell": cell}
    least = loop_plan(panda, path, monkeypatch, **options).min_clearance
    assert 0.01 < least < 0.5
    assert_declined_and_loop(
        panda, path, monkeypatch, clearance=least - 0.5 * CLEARANCE_MARGIN, **options
    )
    plan = assert_answered(
        panda, path, monkeypatch, clearance=least - 2 * CLEARANCE_MARGIN, **options
    )
    assert plan.min_clearance == pytest.approx(least) and plan.cell_check is not None
    # the plan's check is the one made with the clearance asked for
    assert plan.cell_check.clearance == least - 2 * CLEARANCE_MARGIN


def test_a_path_within_the_jump_margin_falls_back(panda, monkeypatch):
    """The jump tolerance lowered until the largest unexplained joint step is above
    JUMP_SHARE of it: declined (the loop plans it ok); with room: answered."""
    options = {"duration": 0.6, "q_seed": PANDA_START, "dt": 0.0375}  # 16 intervals: one grid
    path = panda_line(panda)
    loop = loop_plan(panda, path, monkeypatch, **options)
    h = np.diff(loop.t)[:, None]
    unexplained = np.abs(np.diff(loop.q, axis=0) - 0.5 * h * (loop.qd[1:] + loop.qd[:-1])).max()
    assert unexplained > 1e-5
    near = 0.99 * unexplained / JUMP_SHARE
    assert_declined_and_loop(panda, path, monkeypatch, jump_tolerance=near, **options)
    assert_answered(panda, path, monkeypatch, jump_tolerance=1.01 * unexplained / JUMP_SHARE,
                    **options)  # fmt: skip


def test_a_path_leaving_the_workspace_is_left_to_the_loop(panda, monkeypatch):
    start = panda.fk(PANDA_START)
    far = cartesian.Line(start, pin.SE3(start.rotation, start.translation + [1.0, 0.0, 0.0]))
    plan, answers = lean_plan(panda, far, monkeypatch, duration=5.0, q_seed=PANDA_START)
    assert answers and not any(a is not None for a in answers) and not plan.ok
    _assert_same(plan, loop_plan(panda, far, monkeypatch, duration=5.0, q_seed=PANDA_START), "far")


# ---------------------------------------------------------------------------- geometric trace
def exact_trace(tracker, path, s, seed, monkeypatch):
    from cartesian.geometry import trace_geometry

    with monkeypatch.context() as patch:
        patch.setattr(lean_track, "ENABLED", False)
        return trace_geometry(tracker, path, s, seed)


def panda_tracker(panda, position_only=False, threshold=None) -> Tracker:
    if threshold is None:
        threshold = SINGULAR_FRACTION * panda.reference_manipulability(position_only)
    return Tracker(panda, position_only, 1e-7, 1e-7, threshold, 1.0, 0.1)


@pytest.mark.parametrize("max_step", [MAX_JOINT_STEP, 0.01])
def test_the_lean_trace_is_the_exact_trace(panda, monkeypatch, max_step):
    """The same points (bisected where a joint steps more than max_step: many with 0.01 rad),
    q and dq/ds (the rates of the same Jacobians) as the exact trace; dq/ds against differences
    of q."""
    from cartesian import geometry

    path = panda_line(panda, (0.1, 0.25, -0.1))
    tracker = panda_tracker(panda)
    s = np.linspace(0.0, 1.0, 6)
    lean = lean_track.trace(tracker, path, s, PANDA_START, max_step, MIN_REFINE_DS)
    assert lean is not None
    fractions, q, dq, jacobians = lean
    monkeypatch.setattr(geometry, "MAX_JOINT_STEP", max_step)
    exact = exact_trace(tracker, path, s, PANDA_START, monkeypatch)
    assert not exact.events
    np.testing.assert_array_equal(fractions, exact.s)
    assert len(fractions) > len(s) if max_step < MAX_JOINT_STEP else len(fractions) >= len(s)
    assert np.abs(np.diff(q, axis=0)).max() <= max_step
    np.testing.assert_allclose(q, exact.q, atol=1e-9)
    np.testing.assert_allclose(dq, exact.dq_ds, atol=1e-8)
    np.testing.assert_allclose(jacobians, exact.jacobians, atol=1e-9)
    mid = 0.5 * (dq[1:] + dq[:-1])
    np.testing.assert_allclose(np.diff(q, axis=0) / np.diff(fractions)[:, None], mid, atol=2e-2)


def test_the_lean_trace_declines_near_flags(monkeypatch):
    """Limits within LIMIT_MARGIN, a threshold within RELATIVE_MARGIN of the smallest
    manipulability, a jump tolerance within JUMP_SHARE of the largest unexplained step: None;
    a point the Newton steps cannot reach (beyond reach): None."""
    panda = cached_robot("panda")
    path = panda_line(panda)
    s = np.linspace(0.0, 1.0, 11)
    tracker = panda_tracker(panda)
    traced = lean_track.trace(tracker, path, s, PANDA_START, MAX_JOINT_STEP, MIN_REFINE_DS)
    assert traced is not None
    fractions, q, dq, jacobians = traced
    least = manipulability_of(jacobians, 6).min()
    for factor, declined in ((1 + 0.5 * RELATIVE_MARGIN, True), (1 + 2 * RELATIVE_MARGIN, False)):
        tracker = panda_tracker(panda, threshold=least / factor)
        result = lean_track.trace(tracker, path, s, PANDA_START, MAX_JOINT_STEP, MIN_REFINE_DS)
        assert (result is None) == declined
    h = np.diff(fractions)[:, None]
    unexplained = np.abs(np.diff(q, axis=0) - 0.5 * h * (dq[1:] + dq[:-1])).max()
    for factor, declined in ((0.99, True), (1.01, False)):
        tracker = panda_tracker(panda)
        tracker.jump_tolerance = factor * unexplained / JUMP_SHARE
        result = lean_track.trace(tracker, path, s, PANDA_START, MAX_JOINT_STEP, MIN_REFINE_DS)
        assert (result is None) == declined
    narrow = kinplan.load_robot("panda")
    upper = narrow.upper.copy()
    upper[0] = q[:, 0].max() + 0.5 * LIMIT_MARGIN
    narrow.model.upperPositionLimit[:] = upper
    narrow.upper = upper
    tracker = panda_tracker(narrow)
    assert lean_track.trace(tracker, path, s, PANDA_START, MAX_JOINT_STEP, MIN_REFINE_DS) is None
    start = panda.fk(PANDA_START)
    far = cartesian.Line(start, pin.SE3(start.rotation, start.translation + [1.0, 0.0, 0.0]))
    tracker = panda_tracker(panda)
    assert lean_track.trace(tracker, far, s, PANDA_START, MAX_JOINT_STEP, MIN_REFINE_DS) is None
    monkeypatch.setattr(lean_track, "ENABLED", False)
    assert lean_track.trace(tracker, path, s, PANDA_START, MAX_JOINT_STEP, MIN_REFINE_DS) is None


def test_the_lean_trace_stops_bisecting_at_the_smallest_interval(panda):
    """With a smallest interval wider than the grid's, steps above max_step are accepted (no
    bisection), the points are the grid's."""
    path = panda_line(panda, (0.1, 0.25, -0.1))
    tracker = panda_tracker(panda)
    s = np.linspace(0.0, 1.0, 4)
    result = lean_track.trace(tracker, path, s, PANDA_START, 0.001, 0.5)
    assert result is not None
    np.testing.assert_array_equal(result[0], s)
    assert np.abs(np.diff(result[1], axis=0)).max() > 0.001
    finer = lean_track.trace(tracker, path, s, PANDA_START, 0.001, 0.3)
    assert finer is not None and len(finer[0]) > len(s)


def test_the_lean_trace_judges_the_task_rows_manipulability(planar_2r):
    """On the planar 2R (task rows x, y of a 6-row Jacobian) the singularity margin is that of
    the 2×2 task Jacobian, |det| = |sin θ2| for unit links: a threshold within RELATIVE_MARGIN
    of the trace's smallest |sin θ2| is declined, one with room answered."""
    path = cartesian.Line([1.2, 0.3, 0.0], [0.3, 1.2, 0.0])
    s = np.linspace(0.0, 1.0, 11)
    seed = np.array([0.3, 1.2])

    def trace(threshold):
        tracker = Tracker(planar_2r, True, 1e-7, 1e-7, threshold, 1.0, 0.1)
        return lean_track.trace(tracker, path, s, seed, MAX_JOINT_STEP, MIN_REFINE_DS)

    traced = trace(0.0)
    assert traced is not None
    least = np.abs(np.sin(traced[1][:, 1])).min()
    assert trace(least / (1.0 + 0.5 * RELATIVE_MARGIN)) is None
    assert trace(least / (1.0 + 2.0 * RELATIVE_MARGIN)) is not None


def test_a_seed_near_the_start_is_answered(panda, monkeypatch):
    """A seed 0.05 rad off the start configuration on every joint: the first sample is the full
    pose's IK from it (its orientation too), and the lean loop answers with the loop's plan."""
    plan = assert_answered(
        panda, panda_line(panda), monkeypatch, duration=1.0, q_seed=PANDA_START + 0.05
    )
    start, first = panda.fk(PANDA_START), panda.fk(plan.q[0])
    np.testing.assert_allclose(first.translation, start.translation, atol=1e-7)
    np.testing.assert_allclose(first.rotation, start.rotation, atol=1e-7)
