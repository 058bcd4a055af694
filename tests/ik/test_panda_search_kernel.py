"""The compiled θ7 search of the panda-type closed form (:func:`kinplan.ik.panda_kernel.search`
behind ``PandaIK.nearest``, :func:`~kinplan.ik.panda_kernel.search_many` behind
``PandaIK.nearest_many``) against the Python search (``PandaIK.nearest`` with the compiled path
switched off), which is the reference: the same answer (None alike) to 1e-12 rad on thousands of
poses and references, and Pinocchio's FK of every answer on the target. Its parts too: the
θ7-independent part of a pose and the θ7 intervals where the elbow reaches, bit for bit; the
stages of θ7 values with the "already tried" rule, value for value.

Arms: the stock panda; a tilted mount with oblique axes, uneven limits (θ7's range wider than a
turn) and weights; an iiwa-type arm (no elbow offset, axis 7 through the wrist centre: θ7 does
not move the elbow, so its intervals are the whole range or nothing).
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from test_panda_ik import modified_panda

from kinplan.errors import InputError
from kinplan.ik import panda_kernel
from kinplan.ik.panda import PandaIK, panda_solver_for
from kinplan.ik.panda_intervals import Q7_STEPS

WEIGHTS = np.array([3.0, 0.5, 2.0, 1.0, 0.25, 4.0, 1.5])
#: Compiled and Python answers agree to this [rad] (see _assert_same).
ANGLE_TOL = 1e-12
#: Pinocchio's FK of an answer reaches the target to this [m, rad] ...
FK_TOL = 1e-9
#: ... and this at a free angle (two joints at zero: aligned axes), where the angle beside the
#: free one is the square root of a rounding error (the closed form's, either search's: as in
#: test_panda_kernel's free-angle test; Robot.ik checks by FK and polishes).
FREE_FK_TOL = 3e-8


def _python(solver: PandaIK, position, rotation, ref) -> np.ndarray | None:
    """The Python search's answer (the compiled path switched off for the call)."""
    panda_kernel.ENABLED = False
    try:
        return solver.nearest(position, rotation, ref)
    finally:
        panda_kernel.ENABLED = True


def _references(rng, solver: PandaIK, q: np.ndarray, k: int) -> np.ndarray:
    """A reference for case ``k``: random within the limits, up to 0.5 rad beyond, whole
    turns beyond, near the configuration ``q`` or mid-range."""
    lower, upper = solver.lower, solver.upper
    kind = k % 5
    if kind == 0:
        return rng.uniform(lower, upper)
    if kind == 1:
        return rng.uniform(lower - 0.5, upper + 0.5)
    if kind == 2:
        return rng.uniform(lower, upper) + rng.choice([-9.0, -3.0, 3.0, 9.0], 7)
    if kind == 3:
        return q + rng.normal(0.0, 0.02, 7)
    return 0.5 * (lower + upper)


def _poses(rng, robot, solver: PandaIK, count: int):
    """(position, rotation, reference, FK tolerance [m, rad]) cases: FK of random
    configurations (some with a joint on a limit or joints at zero: free angles), and random
    poses within 1.2 m (many unreachable, some reachable only far from the reference's θ7: the
    grids are searched)."""
    for k in range(count):
        q = rng.uniform(solver.lower, solver.upper)
        if k % 4 == 1:
            j = rng.integers(7)
            q[j] = (solver.lower, solver.upper)[int(rng.integers(2))][j]
        elif k % 4 == 2:
            q[rng.choice(7, size=2, replace=False)] = 0.0
            q = np.clip(q, solver.lower, solver.upper)
        if k % 4 == 3:
            position, rotation = rng.uniform(-1.2, 1.2, 3), pin.SE3.Random().rotation
        else:
            pose = robot.fk(q)
            position, rotation = pose.translation, pose.rotation
        tolerance = FREE_FK_TOL if k % 4 == 2 else FK_TOL
        yield position, rotation, _references(rng, solver, q, k), tolerance


def _assert_same(
    robot, solver: PandaIK, position, rotation, ref, fk_tol: float = FK_TOL
) -> tuple[bool, bool]:
    """Compiled and Python answers: both None, or equal to ANGLE_TOL (the per-θ7 solves may
    differ in a last bit where two branches' distances tie but for it, see panda_kernel),
    within the limits, and reaching the target by Pinocchio's FK. Returns (found, bit for
    bit)."""
    compiled = solver.nearest(position, rotation, ref)
    python = _python(solver, position, rotation, ref)
    assert (compiled is None) == (python is None), (position, rotation, ref, compiled, python)
    if python is None:
        return False, True
    np.testing.assert_allclose(compiled, python, rtol=0, atol=ANGLE_TOL, err_msg=f"{ref!r}")
    assert np.all((compiled >= solver.lower) & (compiled <= solver.upper)), compiled
    pose = robot.fk(compiled)
    assert np.linalg.norm(pose.translation - position) < fk_tol
    assert np.linalg.norm(pin.log3(pose.rotation.T @ rotation)) < fk_tol
    return True, bool(np.array_equal(compiled, python))


def _check_many(robot, solver: PandaIK, count: int, seed: int) -> tuple[int, int, int]:
    """``count`` cases through :func:`_assert_same`: (found, bit for bit, total)."""
    assert panda_kernel.available()
    found = exact = 0
    for position, rotation, ref, fk_tol in _poses(
        np.random.default_rng(seed), robot, solver, count
    ):
        ok, same = _assert_same(robot, solver, position, rotation, ref, fk_tol)
        found += ok
        exact += same
    return found, exact, count


@pytest.fixture(scope="module")
def tilted(tmp_path_factory):
    """A tilted mount with oblique shoulder and wrist axes, uneven limits (θ7 over 9.4 rad,
    more than a turn, and joints 1 and 5 too) and weights."""
    robot = modified_panda(
        tmp_path_factory.mktemp("tilted"),
        joint1=('rpy="0 0 0"', 'rpy="0.3 0.2 0.1"'),
        joint2=('rpy="-1.5707963267948966 0 0"', 'rpy="-1.3 0 0"'),
        joint6=('rpy="1.5707963267948966 0 0"', 'rpy="1.2 0 0"'),
    )
    stock = panda_solver_for(robot)
    assert isinstance(stock, PandaIK)
    lower, upper = stock.lower.copy(), stock.upper.copy()
    lower[[0, 4, 6]], upper[[0, 4, 6]] = (-4.0, -5.0, -5.0), (3.5, 4.0, 4.4)
    solver = PandaIK(stock.geometry, lower, upper, WEIGHTS)
    assert abs(solver._wrist_pair.c) > 0.3 and abs(solver._shoulder_pair.c) > 0.2
    return robot, solver


@pytest.fixture(scope="module")
def iiwa_type(tmp_path_factory):
    """The panda without its elbow offset and with axis 7 through the wrist centre: the
    iiwa's structure (θ7 does not change the shoulder–wrist distance)."""
    robot = modified_panda(
        tmp_path_factory.mktemp("iiwa"),
        joint4=('xyz="0.0825 0 0"', 'xyz="0 0 0"'),
        joint5=('xyz="-0.0825 0.384 0"', 'xyz="0 0.384 0"'),
        joint7=('xyz="0.088 0 0"', 'xyz="0 0 0"'),
    )
    solver = panda_solver_for(robot)
    assert isinstance(solver, PandaIK)
    return robot, solver


# ---------------------------------------------------------------------------- whole searches
@pytest.mark.parametrize("seed", [0, 1])
def test_compiled_search_is_the_python_search_on_the_stock_panda(panda, seed):
    """2 × 1,600 cases: the same answers (None alike), nearly all of them bit for bit."""
    found, exact, count = _check_many(panda, panda.closed_form_ik, 1600, seed)
    assert found >= 0.6 * count  # the random poses of every fourth case are mostly unreachable
    assert exact >= 0.99 * count


def test_compiled_search_is_the_python_search_on_a_tilted_oblique_arm(tilted):
    robot, solver = tilted
    found, exact, count = _check_many(robot, solver, 1200, 2)
    assert found >= 0.5 * count and exact >= 0.99 * count


def test_compiled_search_is_the_python_search_on_an_iiwa_type_arm(iiwa_type):
    """Flat intervals (the whole θ7 range or none); the search still answers as Python's."""
    robot, solver = iiwa_type
    rng = np.random.default_rng(3)
    flat = 0
    for _ in range(200):
        pose = robot.fk(rng.uniform(solver.lower, solver.upper))
        intervals = solver.elbow_q7_intervals(pose.translation, pose.rotation)
        flat += intervals == [(solver.lower[6], solver.upper[6])]
    assert flat == 200
    found, exact, count = _check_many(robot, solver, 800, 4)
    assert found >= 0.5 * count and exact >= 0.99 * count


def test_narrow_and_empty_elbow_intervals(panda):
    """Poses slid along the line from the shoulder centre, by bisection, to where the elbow
    just reaches (θ7 intervals down to a point) and just beyond (none, so no answer), and in
    steps between: the two searches agree, at random references."""
    solver = panda.closed_form_ik
    shoulder = np.array(solver.geometry.shoulder)
    rng = np.random.default_rng(5)
    widths = []
    for k in range(120):
        pose = panda.fk(rng.uniform(solver.lower, solver.upper))
        rotation, direction = pose.rotation, pose.translation - shoulder

        def reaches(scale: float, direction=direction, rotation=rotation) -> bool:
            return bool(solver.elbow_q7_intervals(shoulder + scale * direction, rotation))

        inside, outside = 1.0, (2.0 if k % 2 else 0.1)  # stretched, or folded
        if reaches(outside):
            continue
        for _ in range(60):
            middle = 0.5 * (inside + outside)
            inside, outside = (middle, outside) if reaches(middle) else (inside, middle)
        for t in (0.0, 1e-9, 1e-6, 1e-4, 1e-3, 1e-2):
            toward = math.copysign(t, inside - outside)  # into the reach, or out of it
            for scale in (inside + toward, outside - toward):
                position = shoulder + scale * direction
                intervals = solver.elbow_q7_intervals(position, rotation)
                widths.append(sum(b - a for a, b in intervals) if intervals else -1.0)
                ref = rng.uniform(solver.lower - 0.3, solver.upper + 0.3)
                _assert_same(panda, solver, position, rotation, ref)
    widths_ = np.array(widths)
    assert (widths_ < 0).sum() >= 100  # empty
    assert ((widths_ >= 0) & (widths_ < 1e-3)).sum() >= 100  # narrow
    assert ((widths_ >= 1e-3) & (widths_ < 0.1)).sum() >= 50


def test_unreachable_poses_give_none(panda):
    solver = panda.closed_form_ik
    rng = np.random.default_rng(6)
    for _ in range(100):
        direction = rng.normal(size=3)
        position = 3.0 * direction / np.linalg.norm(direction)
        rotation = pin.SE3.Random().rotation
        assert solver.elbow_q7_intervals(position, rotation) == []
        assert solver.nearest(position, rotation, np.zeros(7)) is None
        assert _python(solver, position, rotation, np.zeros(7)) is None


# ---------------------------------------------------------------------------- many at once
def test_nearest_many_is_nearest_pose_by_pose(panda, tilted):
    """search_many: nearest's answers, bit for bit (the same compiled search), none left over;
    a row with a NaN finds nothing; no rows, no answers."""
    for robot, solver in [(panda, panda.closed_form_ik), tilted]:
        rng = np.random.default_rng(7)
        cases = list(_poses(rng, robot, solver, 1000))
        positions = np.array([c[0] for c in cases])
        rotations = np.array([c[1] for c in cases])
        refs = np.array([c[2] for c in cases])
        positions[17, 1] = np.nan
        refs[18, 3] = np.inf
        q, found, left = solver.nearest_many(positions, rotations, refs)
        assert not left.any() and not found[17] and not found[18]
        for k in range(len(cases)):
            if k in (17, 18):
                continue
            single = solver.nearest(positions[k], rotations[k], refs[k])
            assert found[k] == (single is not None), k
            if single is not None:
                np.testing.assert_array_equal(q[k], single)
        assert found.sum() >= 500
    q, found, left = solver.nearest_many(np.zeros((0, 3)), np.zeros((0, 3, 3)), np.zeros((0, 7)))
    assert q.shape == (0, 7) and found.shape == (0,) and left.shape == (0,)


def test_ik_batch_takes_the_compiled_search(panda):
    """Robot.ik_batch on 400 poses with a seed each: ik's answers."""
    rng = np.random.default_rng(8)
    q_true = rng.uniform(panda.lower, panda.upper, (400, 7))
    seeds = rng.uniform(panda.lower, panda.upper, (400, 7))
    targets = np.array([panda.fk(q).homogeneous for q in q_true])
    q, success = panda.ik_batch(targets, q_seed=seeds)[:2]
    for k in range(len(targets)):
        result = panda.ik(targets[k], q_seed=seeds[k])
        assert success[k] == result.success
        np.testing.assert_allclose(q[k], result.q, rtol=0, atol=1e-12)
    assert success.all()


def test_switched_off_the_vectorised_search_runs(panda, monkeypatch):
    """KINPLAN_JIT=0 (ENABLED False): nearest_many is the numpy search, which leaves poses near
    a free angle (θ2 = 0) to nearest; switched on, none is left."""
    solver = panda.closed_form_ik
    rng = np.random.default_rng(9)
    q_true = rng.uniform(panda.lower, panda.upper, (20, 7))
    q_true[:, 1] = 0.0
    poses = [panda.fk(q) for q in q_true]
    positions = np.array([p.translation for p in poses])
    rotations = np.array([p.rotation for p in poses])
    assert not solver.nearest_many(positions, rotations, q_true)[2].any()
    monkeypatch.setattr(panda_kernel, "ENABLED", False)
    assert solver.nearest_many(positions, rotations, q_true)[2].all()


def test_malformed_input_raises_as_in_python(panda):
    solver = panda.closed_form_ik
    pose = panda.fk(np.zeros(7))
    p, r, q = pose.translation, pose.rotation, np.zeros(7)
    bad = [
        (p, r, np.zeros(6)),
        (p, r, np.full(7, np.nan)),
        (np.array([np.nan, 0.0, 0.0]), r, q),
        (p, np.full((3, 3), np.inf), q),
        (p[:2], r, q),
        (p, r[:2], q),
        (np.array([1e308, 1e308, 0.0]), r, q),  # finite values whose sum is not
        (p, r, np.array([1e308, 1e308, 0.0, 0.0, 0.0, 0.0, 0.0])),
    ]
    for args in bad:
        with pytest.raises(InputError) as compiled:
            solver.nearest(*args)
        with pytest.raises(InputError) as python:
            _python(solver, *args)
        assert str(compiled.value) == str(python.value)
    assert solver.nearest(p, None, q) is None
    np.testing.assert_array_equal(
        solver.nearest(list(p), r.tolist(), list(q)), _python(solver, p, r, q)
    )


# ---------------------------------------------------------------------------- the parts
def _compiled_parts(solver: PandaIK, position, rotation):
    """(``M T⁻¹ s``, ``R_T M_Rᵀ``, intervals) by the compiled helpers."""
    axes, vectors, _, _, limits, frame, _, _ = solver._search_inputs()
    seen, rotation_tm = np.empty(3), np.empty((3, 3))
    panda_kernel._prepare(frame, np.asarray(position), np.asarray(rotation), seen, rotation_tm)
    starts, ends = np.empty(40), np.empty(40)
    count = panda_kernel._intervals(
        axes, vectors, frame, limits[0, 6], limits[1, 6], seen, starts, ends
    )
    return seen, rotation_tm, list(zip(starts[:count].tolist(), ends[:count].tolist()))


def test_the_pose_part_and_the_intervals_are_python_s_bit_for_bit(panda, tilted, iiwa_type):
    """_prepare and _intervals against PandaIK._prepare and _elbow_q7_intervals, exactly, also
    with θ7's range wider than a turn (pieces shifted by turns and merged)."""
    for robot, solver in [(panda, panda.closed_form_ik), tilted, iiwa_type]:
        for position, rotation, *_ in _poses(np.random.default_rng(10), robot, solver, 500):
            prepared = solver._prepare(*solver._pose(position, rotation))
            seen, rotation_tm, intervals = _compiled_parts(solver, position, rotation)
            assert tuple(seen.tolist()) == prepared[0]
            assert tuple(rotation_tm.reshape(-1).tolist()) == prepared[1]
            assert intervals == solver._elbow_q7_intervals(prepared)
    _, solver = tilted
    many = 0
    for position, rotation, *_ in _poses(np.random.default_rng(11), tilted[0], solver, 300):
        many += len(_compiled_parts(solver, position, rotation)[2]) >= 2
    assert many >= 20  # intervals in more than one turn


def _python_stages(solver: PandaIK, q7_ref, intervals, tried):
    return [list(stage) for stage in solver._q7_stages(q7_ref, intervals, set(tried))]


def _compiled_stages(solver: PandaIK, q7_ref, intervals, tried):
    *_, stages, sizes = solver._search_inputs()
    count = len(intervals)
    starts = np.array([a for a, _ in intervals] + [0.0])
    ends = np.array([b for _, b in intervals] + [0.0])
    margin = solver.search_constants()[0][9, 2]
    settings = np.array([q7_ref, solver.lower[6], solver.upper[6], margin])
    buffer = np.empty(2 + sizes[0] + stages.size)
    buffer[: len(tried)] = tried
    n_tried = len(tried)
    values = np.empty(max(sizes[1:]))
    out = []
    for stage in range(sizes[0] + len(sizes) - 1):
        fresh, n_tried = panda_kernel.stage_values(
            stage, settings, stages, sizes, starts, ends, count, buffer, n_tried, values
        )
        if fresh:
            out.append(values[:fresh].tolist())
    return out


def test_stage_values_follow_the_python_stages_and_skip_what_was_tried(panda, tilted):
    """stage_values against PandaIK._q7_stages: the same values, stage by stage, in order,
    with the same values skipped: duplicates made by clipping into the limits, by moving
    into narrow intervals (many values onto one edge), and values tried before (the first
    value and the middle, or a value of a later stage)."""
    rng = np.random.default_rng(12)
    checked = skipped = 0
    for solver in (panda.closed_form_ik, tilted[1]):
        lo7, hi7 = solver.lower[6], solver.upper[6]
        for k in range(400):
            cuts = np.sort(rng.uniform(lo7, hi7, 2 * int(rng.integers(1, 4))))
            if k % 3 == 0:  # narrow ones: many values move onto the same edges
                cuts[1::2] = cuts[::2] + rng.choice([0.0, 1e-8, 1e-3, 0.05], len(cuts) // 2)
            intervals: list[tuple[float, float]] = []
            for a, b in zip(cuts[::2].tolist(), cuts[1::2].tolist()):
                if not intervals or a > intervals[-1][1]:  # sorted and disjoint
                    intervals.append((a, min(b, hi7)))
            q7_ref = float(rng.choice([rng.uniform(lo7, hi7), lo7, hi7, intervals[0][0]]))
            start, end = intervals[0]
            tried = [start + 0.25 * (end - start), 0.5 * (start + end)]
            if k % 4 == 1:  # a value of a later stage tried already
                later = _python_stages(solver, q7_ref, intervals, tried)
                if later:  # (a point-like interval may have no value left untried)
                    tried[1] = later[-1][len(later[-1]) // 2]
            python = _python_stages(solver, q7_ref, intervals, tried)
            assert _compiled_stages(solver, q7_ref, intervals, tried) == python
            total = 2 * len(Q7_STEPS) + sum(map(len, solver._q7_grids))
            skipped += total - sum(map(len, python))
            checked += 1
    assert checked == 800 and skipped > 10_000


def test_the_frame_constants_are_the_solver_s(panda):
    solver = panda.closed_form_ik
    frame, stages, sizes = solver.search_constants()
    g = solver.geometry
    assert frame.shape == (10, 3) and tuple(frame[0]) == g.shoulder
    np.testing.assert_array_equal(frame[1:4].reshape(-1), g.tool_rotation)
    np.testing.assert_array_equal(frame[5:8], frame[1:4].T)
    assert list(sizes) == [8, 16, 64, 256, 1024] and stages.size == 8 + 1360
    assert math.isclose(frame[9, 2], 1e-7)


def test_a_solver_that_has_searched_still_pickles(panda):
    """The compiled search's constants are arrays on the solver (the kernel module is not):
    a solver pickled after a search answers as before."""
    import pickle

    solver = panda.closed_form_ik
    pose = panda.fk(np.full(7, 0.3))
    q = solver.nearest(pose.translation, pose.rotation, np.zeros(7))
    copy = pickle.loads(pickle.dumps(solver))
    np.testing.assert_array_equal(copy.nearest(pose.translation, pose.rotation, np.zeros(7)), q)
