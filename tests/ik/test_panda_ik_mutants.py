"""The panda's vectorised θ7 search (PandaIK.nearest_many) and the helpers of its closed form,
each against an independent answer: the single-pose search pose by pose (the same q to 1e-10
rad, the same success), the scalar interval helpers row by row, and brute force over all the
branches of solutions_q7 and all the 2π equivalents within the limits (weighted distance),
with FK of every answer equal to the target. The compiled search, which nearest and
nearest_many use when numba is available, is switched off here (its own tests:
test_panda_search_kernel.py)."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from conftest import cached_robot

from kinplan.ik import panda_kernel
from kinplan.ik.panda import (
    _Q7_EDGE_MARGIN,
    PandaIK,
    _cos_range,
    _intervals_within,
    _project,
    _project_many,
    panda_solver_for,
)
from kinplan.ik.screws import TAU

WEIGHTS = np.array([3.0, 0.5, 2.0, 1.0, 0.25, 4.0, 1.5])


@pytest.fixture(autouse=True)
def _python_search(monkeypatch):
    """The vectorised and the Python searches: the compiled one switched off."""
    monkeypatch.setattr(panda_kernel, "ENABLED", False)


@pytest.fixture(scope="module")
def stock() -> PandaIK:
    solver = panda_solver_for(cached_robot("panda"))
    assert isinstance(solver, PandaIK)
    return solver


def _variant(stock: PandaIK, lower=None, upper=None, weights=None) -> PandaIK:
    lo = stock.lower.copy() if lower is None else np.asarray(lower, dtype=float)
    hi = stock.upper.copy() if upper is None else np.asarray(upper, dtype=float)
    return PandaIK(stock.geometry, lo, hi, weights)


def _fk(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    robot = cached_robot("panda")
    poses = [robot.fk(row) for row in q]
    return np.array([p.translation for p in poses]), np.array([p.rotation for p in poses])


def _within(solver: PandaIK, rng: np.random.Generator, count: int) -> np.ndarray:
    """Random configurations within the solver's (finite) limits."""
    return rng.uniform(solver.lower, solver.upper, (count, 7))


def _assert_reaches(q: np.ndarray, position: np.ndarray, rotation: np.ndarray) -> None:
    pose = cached_robot("panda").fk(q)
    assert np.linalg.norm(pose.translation - position) < 1e-9
    assert np.linalg.norm(pin.log3(pose.rotation.T @ rotation)) < 1e-9


def _assert_many_equals_single(solver: PandaIK, positions, rotations, refs) -> np.ndarray:
    """nearest_many gives nearest's success and q on every pose it does not leave to nearest;
    returns found."""
    q, found, left = solver.nearest_many(positions, rotations, refs)
    assert left.sum() <= 0.02 * len(refs)
    for k in np.flatnonzero(~left):
        single = solver.nearest(positions[k], rotations[k], refs[k])
        assert found[k] == (single is not None), k
        if single is not None:
            np.testing.assert_allclose(q[k], single, atol=1e-10, err_msg=str(k))
            assert np.all((q[k] >= solver.lower - 1e-12) & (q[k] <= solver.upper + 1e-12))
    return found & ~left


# ---------------------------------------------------------------------------- nearest_many
@pytest.mark.parametrize("weighted", [False, True])
def test_nearest_many_equals_nearest_on_the_stock_panda(stock, weighted):
    """Reachable poses and random boxes, references within, beyond and whole turns past the
    limits: the same answer as the single-pose search, and FK of it is the target."""
    solver = _variant(stock, weights=WEIGHTS) if weighted else stock
    rng = np.random.default_rng(40 + weighted)
    q_true = _within(solver, rng, 400)
    positions, rotations = _fk(q_true)
    positions[300:] = rng.uniform(-1.0, 1.0, (100, 3))
    refs = _within(solver, rng, 400)
    refs[:100] += rng.choice([-TAU, -1.0, 0.0, 1.0, TAU], (100, 7))
    refs[100:150] = q_true[100:150] + rng.normal(0.0, 1e-3, (50, 7))  # near the answer
    found = _assert_many_equals_single(solver, positions, rotations, refs)
    assert found[100:150].all() and found.sum() > 300
    q = solver.nearest_many(positions, rotations, refs)[0]
    for k in np.flatnonzero(found)[::7]:
        _assert_reaches(q[k], positions[k], rotations[k])


def test_nearest_many_equals_nearest_where_the_search_reaches_its_grids(stock):
    """Narrow limits of joints 1, 2 and 4 leave few θ7 values with a solution: most poses take
    the later stages (±steps, then grids), whose values are projected into the elbow's
    intervals and deduplicated; the first stage with a solution and its nearest value win."""
    lower, upper = stock.lower.copy(), stock.upper.copy()
    lower[[0, 1, 3]], upper[[0, 1, 3]] = [-0.4, -0.3, -2.2], [0.4, 0.5, -1.6]
    solver = _variant(stock, lower, upper)
    rng = np.random.default_rng(42)
    q_true = _within(solver, rng, 300)
    positions, rotations = _fk(q_true)
    refs = _within(stock, rng, 300)
    found = _assert_many_equals_single(solver, positions, rotations, refs)
    assert found.sum() > 250
    q = solver.nearest_many(positions, rotations, refs)[0]
    moved = np.abs(q[found, 6] - np.clip(refs[found, 6], lower[6], upper[6]))
    assert np.sum(moved > 0.8) > 20  # the grids were needed
    for k in np.flatnonzero(found)[::11]:
        _assert_reaches(q[k], positions[k], rotations[k])


def test_nearest_many_equals_nearest_on_a_modified_geometry(tmp_path):
    from test_panda_ik import modified_panda

    robot = modified_panda(
        tmp_path,
        joint3=('xyz="0 -0.316 0"', 'xyz="0 -0.35 0"'),
        joint4=('xyz="0.0825 0 0"', 'xyz="0.1 0 0"'),
        joint5=('xyz="-0.0825 0.384 0"', 'xyz="-0.06 0.42 0"'),
        joint7=('rpy="1.5707963267948966 0 0" xyz="0.088 0 0"', 'rpy="1.4 0 0" xyz="0.11 0 0"'),
        hand_tcp_joint=('xyz="0 0 0.1034"', 'xyz="0.01 0.02 0.15"'),
    )
    solver = panda_solver_for(robot, weights=WEIGHTS)
    assert isinstance(solver, PandaIK)
    rng = np.random.default_rng(43)
    q_true = np.array([robot.random_configuration(rng) for _ in range(300)])
    poses = [robot.fk(q) for q in q_true]
    positions = np.array([p.translation for p in poses])
    rotations = np.array([p.rotation for p in poses])
    refs = np.array([robot.random_configuration(rng) for _ in range(300)])
    found = _assert_many_equals_single(solver, positions, rotations, refs)
    assert found.sum() >= 295
    q = solver.nearest_many(positions, rotations, refs)[0]
    for k in np.flatnonzero(found)[::10]:
        pose = robot.fk(q[k])
        assert np.linalg.norm(pose.translation - positions[k]) < 1e-9
        assert np.linalg.norm(pin.log3(pose.rotation.T @ rotations[k])) < 1e-9


def test_a_tilted_mount_is_solved_as_the_upright_one(tmp_path):
    """The panda on a base tilted about x and y (no axis along a world axis any more, so no
    term of the screw formulas vanishes): every configuration is among the solutions for its
    θ7, and the vectorised search equals the single-pose one."""
    from test_panda_ik import check_solutions_q7, modified_panda

    robot = modified_panda(tmp_path, joint1=('rpy="0 0 0"', 'rpy="0.3 0.2 0.1"'))
    solver = panda_solver_for(robot)
    assert isinstance(solver, PandaIK)
    check_solutions_q7(robot, solver, count=60, seed=49)
    rng = np.random.default_rng(49)
    q_true = np.array([robot.random_configuration(rng) for _ in range(200)])
    poses = [robot.fk(q) for q in q_true]
    positions = np.array([p.translation for p in poses])
    rotations = np.array([p.rotation for p in poses])
    refs = np.array([robot.random_configuration(rng) for _ in range(200)])
    assert _assert_many_equals_single(solver, positions, rotations, refs).sum() >= 195
    # θ2 = 0 puts axis 3 on axis 1 (θ1 + θ3 free): left to nearest, which still reaches it
    q_true[:20, 1] = 0.0
    poses = [robot.fk(q) for q in q_true[:20]]
    positions = np.array([p.translation for p in poses])
    rotations = np.array([p.rotation for p in poses])
    assert solver.nearest_many(positions, rotations, q_true[:20])[2].all()
    for k in range(20):
        q = solver.nearest(positions[k], rotations[k], q_true[k] + 0.05)
        pose = robot.fk(q)
        assert np.linalg.norm(pose.translation - positions[k]) < 1e-9
        assert np.linalg.norm(pin.log3(pose.rotation.T @ rotations[k])) < 1e-9


def test_oblique_shoulder_and_wrist_axes(tmp_path):
    """Axes 1-2 and 5-6 meeting at angles other than 90° (cos ≠ 0 in subproblem 2): every
    configuration among the solutions of its θ7, the vectorised search equal to nearest."""
    from test_panda_ik import check_solutions_q7, modified_panda

    robot = modified_panda(
        tmp_path,
        joint2=('rpy="-1.5707963267948966 0 0"', 'rpy="-1.3 0 0"'),
        joint6=('rpy="1.5707963267948966 0 0"', 'rpy="1.2 0 0"'),
    )
    solver = panda_solver_for(robot, weights=WEIGHTS)
    assert isinstance(solver, PandaIK)
    assert abs(solver._wrist_pair.c) > 0.3 and abs(solver._shoulder_pair.c) > 0.2
    check_solutions_q7(robot, solver, count=60, seed=51)
    rng = np.random.default_rng(51)
    q_true = np.array([robot.random_configuration(rng) for _ in range(200)])
    poses = [robot.fk(q) for q in q_true]
    positions = np.array([p.translation for p in poses])
    rotations = np.array([p.rotation for p in poses])
    refs = np.array([robot.random_configuration(rng) for _ in range(200)])
    assert _assert_many_equals_single(solver, positions, rotations, refs).sum() >= 190


def test_elbow_stretched_onto_the_wrist_axis(stock):
    """θ4 at and near 0 (allowed here) puts the shoulder on axis 5 (θ5 free at exactly 0):
    nearest still reaches every target from references off the configuration: to 3e-9 from
    10⁻⁷ rad away (θ5 solved), to 3e-8 closer (the subproblem's square root of a rounding
    error; Robot.ik polishes that with Newton)."""
    lower, upper = stock.lower.copy(), stock.upper.copy()
    lower[3], upper[3] = -3.0, 0.5
    solver = _variant(stock, lower, upper)
    rng = np.random.default_rng(52)
    for fourth in (0.0, 1e-12, -1e-9, 1e-7, -1e-6, 1e-5, 3e-4):
        for _ in range(6):
            q = rng.uniform(lower, upper)
            q[3] = fourth
            position, rotation = (x[0] for x in _fk(q[None]))
            ref = np.clip(q + rng.normal(0.0, 0.3, 7), lower, upper)
            found = solver.nearest(position, rotation, ref)
            assert found is not None, (fourth, q)
            pose = cached_robot("panda").fk(found)
            tolerance = 3e-9 if abs(fourth) >= 1e-7 else 3e-8
            assert np.linalg.norm(pose.translation - position) < tolerance, fourth
            assert np.linalg.norm(pin.log3(pose.rotation.T @ rotation)) < tolerance, fourth


def test_joint_origins_anywhere_on_their_axes_give_the_same_arm(tmp_path, stock):
    """Joints 2 and 6 placed elsewhere on their own axes (the next joint moved back, so the arm
    is the stock panda): the shoulder and wrist are still found where the axes meet, and the
    solutions are the stock solver's."""
    from test_panda_ik import modified_panda

    robot = modified_panda(
        tmp_path,
        joint2=('xyz="0 0 0"', 'xyz="0 0.03 0"'),
        joint3=('xyz="0 -0.316 0"', 'xyz="0 -0.316 -0.03"'),
        joint6=('xyz="0 0 0"', 'xyz="0 -0.02 0"'),
        joint7=('xyz="0.088 0 0"', 'xyz="0.088 0 -0.02"'),
    )
    solver = panda_solver_for(robot)
    assert isinstance(solver, PandaIK)
    np.testing.assert_allclose(solver.geometry.shoulder, stock.geometry.shoulder, atol=1e-12)
    np.testing.assert_allclose(solver.geometry.wrist, stock.geometry.wrist, atol=1e-12)
    rng = np.random.default_rng(50)
    for _ in range(30):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        mine = solver.solutions_q7(target.translation, target.rotation, q[6])
        theirs = stock.solutions_q7(target.translation, target.rotation, q[6])
        np.testing.assert_allclose(mine, theirs, atol=1e-9)


def test_nearest_many_with_wide_limits_takes_the_equivalent_nearest_the_reference(stock):
    """Joints 1, 3, 5, 6 and 7 with ranges wider than a turn: every joint value is the
    2π-equivalent within the limits nearest the reference (as nearest), and θ7's intervals
    repeat over its range."""
    lower, upper = stock.lower.copy(), stock.upper.copy()
    for j, (lo, hi) in {0: (-5.0, 4.0), 2: (-4.5, 5.5), 4: (-7.0, 6.0), 5: (-3.0, 7.0)}.items():
        lower[j], upper[j] = lo, hi
    lower[6], upper[6] = -6.0, 7.5
    solver = _variant(stock, lower, upper, WEIGHTS)
    rng = np.random.default_rng(44)
    q_true = _within(stock, rng, 300)
    positions, rotations = _fk(q_true)
    refs = _within(solver, rng, 300)
    found = _assert_many_equals_single(solver, positions, rotations, refs)
    assert found.all()
    q = solver.nearest_many(positions, rotations, refs)[0]
    wide = [0, 2, 4, 5]
    for k in range(0, 300, 3):
        _assert_reaches(q[k], positions[k], rotations[k])
        for j in wide:  # no other equivalent within the limits is nearer the reference
            for turn in (-TAU, TAU):
                other = q[k, j] + turn
                if lower[j] <= other <= upper[j]:
                    assert abs(other - refs[k, j]) >= abs(q[k, j] - refs[k, j]) - 1e-12


def test_nearest_many_without_poses(stock):
    q, found, left = stock.nearest_many(np.zeros((0, 3)), np.zeros((0, 3, 3)), np.zeros((0, 7)))
    assert q.shape == (0, 7) and found.shape == (0,) and left.shape == (0,)
    fresh = PandaIK(stock.geometry, stock.lower, stock.upper)
    assert fresh.weights.shape == (7,) and np.all(fresh.weights == 1.0)  # one per joint


def test_a_non_finite_pose_is_refused_by_name(stock):
    from kinplan.errors import InputError

    with pytest.raises(InputError, match="needs the tool rotation"):
        stock.nearest_batch(np.zeros((1, 3)), None, np.zeros(7))

    with pytest.raises(InputError, match=r"pose must be finite.*nan"):
        stock.nearest(np.array([0.3, np.nan, 0.5]), np.eye(3), np.zeros(7))
    with pytest.raises(InputError, match=r"3-vector position.*\(2,\) and \(3, 3\)"):
        stock.solutions_q7(np.zeros(2), np.eye(3), 0.0)
    with pytest.raises(InputError, match=r"q_ref must be a vector of 7.*\(6,\)"):
        stock.nearest(np.zeros(3), np.eye(3), np.zeros(6))
    with pytest.raises(InputError, match=r"q_ref must be finite.*inf"):
        stock.nearest(np.zeros(3), np.eye(3), np.array([0, 0, 0, -1.5, 0, 1.5, np.inf]))


def test_nearest_many_of_unreachable_poses_finds_nothing(stock):
    positions = np.array([[2.0, 0.0, 0.5], [0.0, -3.0, 0.0], [0.0, 0.0, 2.5]])
    rotations = np.broadcast_to(np.eye(3), (3, 3, 3)).copy()
    q, found, left = stock.nearest_many(positions, rotations, np.zeros((3, 7)))
    assert not found.any() and not left.any()


# ---------------------------------------------------------------------------- brute force
def _equivalents(value: float, lower: float, upper: float) -> list[float]:
    turns = range(math.ceil((lower - value) / TAU), math.floor((upper - value) / TAU) + 1)
    return [value + k * TAU for k in turns]


def test_nearest_is_the_weighted_nearest_of_all_branches_and_equivalents(stock):
    """With the reference's θ7 solvable, nearest is the minimum of Σ wᵢ Δqᵢ² over every
    branch of solutions_q7 and every 2π-equivalent of each joint within the (wide) limits."""
    lower, upper = stock.lower.copy(), stock.upper.copy()
    lower[[0, 2, 4]], upper[[0, 2, 4]] = [-5.0, -4.5, -7.0], [4.0, 5.5, 6.0]
    solver = _variant(stock, lower, upper, WEIGHTS)
    rng = np.random.default_rng(45)
    checked = 0
    for k in range(150):
        q_true = _within(stock, rng, 1)
        position, rotation = (x[0] for x in _fk(q_true))
        ref = rng.uniform(lower, upper)
        if k % 2:  # a θ7 with a solution
            ref[6] = q_true[0, 6]
        solutions = solver.solutions_q7(position, rotation, ref[6])
        if not len(solutions):
            continue
        best = math.inf
        for s in solutions:
            cost = 0.0
            for j in range(7):
                options = _equivalents(s[j], lower[j], upper[j])
                cost += WEIGHTS[j] * min((x - ref[j]) ** 2 for x in options)
            best = min(best, cost)
        q = solver.nearest(position, rotation, ref)
        assert q is not None and q[6] == ref[6]
        assert np.sum(WEIGHTS * (q - ref) ** 2) == pytest.approx(best, rel=1e-9, abs=1e-12)
        _assert_reaches(q, position, rotation)
        checked += 1
    assert checked > 80


# ---------------------------------------------------------------------------- θ7 intervals
@pytest.mark.parametrize(
    "limits",
    [
        {},
        {3: (-2.2, -1.6)},  # a narrow elbow: short intervals
        {6: (-6.0, 7.5), 3: (-3.0, -0.1)},  # θ7 over two turns: pieces repeat
        {6: (-1.0, 1.0)},
        {6: (-9.0, 9.0)},
    ],
)
def test_elbow_intervals_of_many_poses_equal_the_single_pose_ones(stock, limits):
    lower, upper = stock.lower.copy(), stock.upper.copy()
    for j, (lo, hi) in limits.items():
        lower[j], upper[j] = lo, hi
    solver = _variant(stock, lower, upper)
    rng = np.random.default_rng(46)
    positions, rotations = _fk(_within(stock, rng, 200))
    positions[150:] = rng.uniform(-1.2, 1.2, (50, 3))
    seen, _ = solver._prepare_many(positions, rotations)
    starts, ends = solver._elbow_q7_intervals_many(seen)
    counts = []
    for k in range(len(positions)):
        prepared = solver._prepare(tuple(positions[k]), tuple(rotations[k].reshape(9)))
        np.testing.assert_allclose([x[k] for x in seen], prepared[0], atol=1e-15)
        expected = solver._elbow_q7_intervals(prepared)
        got = [(a, b) for a, b in zip(starts[k], ends[k]) if not np.isnan(a)]
        assert np.all(np.isnan(starts[k, len(got) :])), k
        assert len(got) == len(expected), (k, got, expected)
        if got:
            np.testing.assert_allclose(got, expected, atol=1e-12, err_msg=str(k))
        counts.append(len(got))
    assert 0 in counts and max(counts) >= 2


def test_elbow_intervals_when_q7_does_not_change_the_elbow(stock):
    """The shoulder seen from the tool on axis 7: θ7 turns nothing the elbow sees, so the
    whole θ7 range or nothing, as the distance is within the elbow's range or not."""
    g = stock.geometry
    axis, point = np.array(g.axes[6]), np.array(g.points[6])
    low, high = stock._elbow_distance2
    offset = np.array(stock._p7_from_wrist)
    seen_rows = []
    for along in np.linspace(-1.0, 1.0, 81):
        seen_rows.append(point + along * axis)
    seen = tuple(np.array(seen_rows).T)
    starts, ends = stock._elbow_q7_intervals_many(seen)
    inside = outside = 0
    for k, row in enumerate(seen_rows):
        expected = stock._elbow_q7_intervals((tuple(row), ()))
        d = row - point
        distance2 = np.sum((d + offset) ** 2)
        if low + 1e-9 < distance2 < high - 1e-9:
            assert expected == [(stock._lo[6], stock._hi[6])]
            inside += 1
        elif distance2 < low - 1e-9 or distance2 > high + 1e-9:
            assert expected == []
            outside += 1
        got = [(a, b) for a, b in zip(starts[k], ends[k]) if not np.isnan(a)]
        assert got == expected
    assert inside > 5 and outside > 5


def test_intervals_within_and_cos_range_against_a_scan():
    rng = np.random.default_rng(47)
    for _ in range(300):
        x0 = rng.uniform(-10.0, 10.0)
        x1 = x0 + rng.choice([rng.uniform(0.0, 7.0), rng.uniform(0.0, 0.5)])
        scan = np.cos(np.linspace(x0, x1, 20001))
        low, high = _cos_range(x0, x1)
        assert low <= scan.min() + 1e-12 and high >= scan.max() - 1e-12
        assert low == pytest.approx(scan.min(), abs=2e-7)
        assert high == pytest.approx(scan.max(), abs=2e-7)
        # pieces of angle taken modulo 2π, kept within [lower, upper]
        lower, upper = rng.uniform(-8.0, 0.0), rng.uniform(0.0, 8.0)
        pieces = [(a, a + rng.uniform(0.0, 3.0)) for a in rng.uniform(-7.0, 7.0, 3)]
        merged = _intervals_within(pieces, lower, upper)
        for (a, b), (c, _) in zip(merged, merged[1:]):
            assert a <= b < c  # sorted and disjoint
        grid = np.linspace(lower, upper, 4001)
        member = np.zeros(grid.shape, dtype=bool)
        for start, end in pieces:
            offset = np.mod(grid - start, TAU)
            member |= offset <= end - start
        found = np.zeros(grid.shape, dtype=bool)
        for a, b in merged:
            assert lower <= a and b <= upper
            found |= (grid >= a) & (grid <= b)
        np.testing.assert_array_equal(found, member)
    # intervals that touch are one interval; a gap keeps two
    assert _intervals_within([(0.0, 1.0), (1.0, 2.0)], -1.0, 3.0) == [(0.0, 2.0)]
    assert _intervals_within([(1.0, 2.0), (0.0, 1.0)], -1.0, 3.0) == [(0.0, 2.0)]
    assert _intervals_within([(0.0, 1.0), (1.5, 2.0)], -1.0, 3.0) == [(0.0, 1.0), (1.5, 2.0)]
    # a piece repeated by whole turns within wide limits, clipped at both ends
    np.testing.assert_allclose(
        _intervals_within([(0.0, 1.0)], -5.5, 7.0), [(-5.5, 1.0 - TAU), (0.0, 1.0), (TAU, 7.0)]
    )
    assert _intervals_within([(0.0, 1.0)], -5.0, 7.0) == [(0.0, 1.0), (TAU, 7.0)]


def test_projection_of_many_values_equals_the_single_one():
    rng = np.random.default_rng(48)
    rows, width = 400, 5
    starts = np.full((rows, 3), np.nan)
    ends = np.full((rows, 3), np.nan)
    values = rng.uniform(-4.0, 4.0, (rows, width))
    for k in range(rows):
        count = rng.integers(1, 4)
        edges = np.sort(rng.uniform(-3.0, 3.0, 2 * count))
        if k % 5 == 0:  # a very narrow interval: its middle, not the margin
            edges[1] = edges[0] + 0.5 * _Q7_EDGE_MARGIN
        starts[k, :count], ends[k, :count] = edges[0::2], edges[1::2]
        values[k, 0] = edges[0]  # exactly on an edge: inside
        values[k, 1] = edges[2 * count - 1]
        values[k, 2] = 0.5 * (edges[0] + edges[1])
    projected = _project_many(values, starts, ends)
    for k in range(rows):
        intervals = [(a, b) for a, b in zip(starts[k], ends[k]) if not np.isnan(a)]
        for j in range(width):
            expected = _project(float(values[k, j]), intervals)
            assert projected[k, j] == expected, (k, j)
            inside = any(a <= expected <= b for a, b in intervals)
            assert inside


def test_a_solver_that_fails_its_self_check_is_dropped_with_the_robot_named(monkeypatch, caplog):
    import logging

    import kinplan.ik.panda as panda_module

    monkeypatch.setattr(panda_module, "self_check", lambda robot, check: False)
    with caplog.at_level(logging.DEBUG, logger="kinplan.ik.panda"):
        assert panda_solver_for(cached_robot("panda")) is None
    assert "panda-type IK of panda disagrees with its forward kinematics" in caplog.text
