"""Semi-analytic IK of panda-type arms (kinplan.ik.panda), checked against Pinocchio FK."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from conftest import cached_robot
from ik_checks import check_missed_targets_solved_numerically, random_targets

import kinplan
from kinplan.errors import InputError
from kinplan.ik.panda import PandaIK, panda_solver_for


@pytest.fixture(scope="module")
def panda_solver() -> PandaIK:
    solver = panda_solver_for(cached_robot("panda"))
    assert isinstance(solver, PandaIK)
    return solver


def contains(solutions: np.ndarray, q: np.ndarray, tol: float = 1e-7) -> bool:
    return any(np.max(np.abs(s - q)) < tol for s in solutions)


def assert_reaches(robot, q: np.ndarray, target: pin.SE3, tol: float = 1e-9) -> None:
    assert robot.within_limits(q, tolerance=0.0)
    reached = robot.fk(q)
    assert np.linalg.norm(reached.translation - target.translation) < tol
    assert np.linalg.norm(pin.log3(reached.rotation.T @ target.rotation)) < tol


def check_solutions_q7(robot, solver: PandaIK, count: int, seed: int) -> None:
    """Every random configuration is among the solutions for its θ7; all reach the target."""
    rng = np.random.default_rng(seed)
    for _ in range(count):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        solutions = solver.solutions_q7(target.translation, target.rotation, q[6])
        assert solutions.shape[1] == 7 and len(solutions) <= 8
        assert contains(solutions, q), q
        for s in solutions:
            assert s[6] == q[6]
            assert_reaches(robot, s, target)


def modified_panda(tmp_path, tip: str = "panda_hand_tcp", **replacements) -> kinplan.Robot:
    """The stock panda URDF with text replacements ``joint=(old, new)`` inside the element of
    joint ``panda_<joint>`` (where ``old`` must occur exactly once)."""
    text = cached_robot("panda").urdf_path.read_text()
    for joint, (old, new) in replacements.items():
        start = text.index(f'<joint name="panda_{joint}"')
        end = text.index("</joint>", start)
        element = text[start:end]
        assert element.count(old) == 1, (joint, old)
        text = text[:start] + element.replace(old, new) + text[end:]
    path = tmp_path / "panda_modified.urdf"
    path.write_text(text)
    return kinplan.load_robot(path, tip=tip)


# ---------------------------------------------------------------------------- solutions for a θ7
def test_solutions_q7_contain_the_configuration_and_reach_the_target(panda, panda_solver):
    check_solutions_q7(panda, panda_solver, count=500, seed=2021)


def test_q7_outside_its_limits_has_no_solution(panda, panda_solver):
    target = panda.fk(panda.neutral())
    solutions = panda_solver.solutions_q7(target.translation, target.rotation, 3.0)
    assert solutions.shape == (0, 7)


def test_unreachable_pose_has_no_solution(panda_solver):
    for q7 in np.linspace(-2.8, 2.8, 15):
        assert panda_solver.solutions_q7(np.array([2.0, 0.0, 0.5]), np.eye(3), q7).shape == (0, 7)
    assert panda_solver.nearest(np.array([2.0, 0.0, 0.5]), np.eye(3), np.zeros(7)) is None


def test_elbow_q7_intervals_match_a_scan_of_q7(panda, panda_solver):
    """θ7 lies in the closed-form intervals exactly where θ4 has a value within its limits."""
    from kinplan.ik.panda import _dot, _rotate, _sub
    from kinplan.ik.screws import joint_choice as _joint_choice

    g, solver = panda_solver.geometry, panda_solver
    rng = np.random.default_rng(16)
    grid = np.linspace(solver.lower[6], solver.upper[6], 3001)
    joints = solver._joints(np.zeros(7))
    checked = empty = 0
    for k in range(120):
        if k % 4 == 3:  # poses the arm may not reach at all
            target = pin.SE3(pin.exp3(rng.normal(size=3)), rng.uniform(-1.2, 1.2, 3))
        else:
            target = panda.fk(panda.random_configuration(rng))
        prepared = solver._prepare(*solver._pose(target.translation, target.rotation))
        intervals = solver._elbow_q7_intervals(prepared)
        empty += not intervals
        for q7 in grid:
            y = _rotate(_sub(prepared[0], g.points[6]), g.axes[6], q7)
            v = _sub((y[0] + g.points[6][0], y[1] + g.points[6][1], y[2] + g.points[6][2]), g.wrist)
            feasible = any(_joint_choice(t, joints[3]) for t in solver._elbow(_dot(v, v)))
            distance = min((min(abs(q7 - a), abs(q7 - b)) for a, b in intervals), default=1.0)
            if distance > 1e-6:  # away from the edges, where rounding decides
                inside = any(a <= q7 <= b for a, b in intervals)
                assert inside == feasible, (k, q7, intervals)
                checked += 1
    assert checked > 300_000 and empty > 5


# ---------------------------------------------------------------------------- nearest
def test_nearest_from_random_seeds_solves_almost_every_reachable_target(panda, panda_solver):
    rng = np.random.default_rng(7)
    count, failures = 2000, 0
    for _ in range(count):
        target = panda.fk(panda.random_configuration(rng))
        seed = panda.random_configuration(rng)
        q = panda_solver.nearest(target.translation, target.rotation, seed)
        if q is None:
            failures += 1
        else:
            assert_reaches(panda, q, target)
    assert failures <= 0.001 * count


def test_nearest_keeps_the_reference_q7_and_branch_when_it_can(panda, panda_solver):
    rng = np.random.default_rng(8)
    for _ in range(200):
        q_true = panda.random_configuration(rng)
        target = panda.fk(q_true)
        q_ref = np.clip(q_true + rng.normal(0.0, 1e-3, 7), panda.lower, panda.upper)
        q_ref[6] = q_true[6]
        q = panda_solver.nearest(target.translation, target.rotation, q_ref)
        np.testing.assert_allclose(q, q_true, atol=1e-7)


def test_nearest_is_the_nearest_solution_of_the_reference_q7(panda, panda_solver):
    rng = np.random.default_rng(9)
    for _ in range(200):
        target = panda.fk(panda.random_configuration(rng))
        q_ref = panda.random_configuration(rng)
        solutions = panda_solver.solutions_q7(target.translation, target.rotation, q_ref[6])
        q = panda_solver.nearest(target.translation, target.rotation, q_ref)
        if len(solutions):
            distances = np.sum((solutions - q_ref) ** 2, axis=1)
            np.testing.assert_allclose(q, solutions[np.argmin(distances)], atol=1e-12)


def test_nearest_searches_q7_when_the_reference_q7_has_no_solution(panda, panda_solver):
    rng = np.random.default_rng(10)
    searched = 0
    for _ in range(300):
        target = panda.fk(panda.random_configuration(rng))
        q_ref = panda.random_configuration(rng)
        if len(panda_solver.solutions_q7(target.translation, target.rotation, q_ref[6])):
            continue
        searched += 1
        q = panda_solver.nearest(target.translation, target.rotation, q_ref)
        assert q is not None and q[6] != q_ref[6]
        assert_reaches(panda, q, target)
    assert searched > 50


def test_nearest_batch_follows_nearest(panda, panda_solver):
    rng = np.random.default_rng(11)
    q0 = panda.random_configuration(rng)
    path = q0 + np.linspace(0.0, 0.3, 10)[:, None] * rng.normal(size=7)
    poses = [panda.fk(q) for q in path]
    positions = np.array([p.translation for p in poses])
    rotations = np.array([p.rotation for p in poses])
    out = panda_solver.nearest_batch(positions, rotations, q0)
    previous = q0
    for row, position, rotation in zip(out, positions, rotations):
        expected = panda_solver.nearest(position, rotation, previous)
        np.testing.assert_array_equal(row, expected)
        previous = expected


def test_malformed_input_raises_and_position_only_gives_none(panda_solver):
    assert panda_solver.nearest(np.zeros(3), None, np.zeros(7)) is None
    with pytest.raises(InputError):
        panda_solver.nearest(np.zeros(3), np.eye(3), np.zeros(6))
    with pytest.raises(InputError):
        panda_solver.nearest(np.zeros(3), np.eye(3), np.full(7, np.nan))
    with pytest.raises(InputError):
        panda_solver.solutions_q7(np.array([np.inf, 0.0, 0.0]), np.eye(3), 0.0)
    with pytest.raises(InputError):
        panda_solver.solutions_q7(np.zeros(2), np.eye(3), 0.0)


# ---------------------------------------------------------------------------- structure
@pytest.mark.parametrize("name", ["planar_2r", "ur5", "ur10"])
def test_other_arms_are_not_panda_type(name):
    assert panda_solver_for(cached_robot(name)) is None


def test_modified_panda_geometry_is_read_from_the_urdf(tmp_path, panda_solver):
    robot = modified_panda(
        tmp_path,
        joint3=('xyz="0 -0.316 0"', 'xyz="0 -0.35 0"'),
        joint4=('xyz="0.0825 0 0"', 'xyz="0.1 0 0"'),
        joint5=('xyz="-0.0825 0.384 0"', 'xyz="-0.06 0.42 0"'),
        joint7=('rpy="1.5707963267948966 0 0" xyz="0.088 0 0"', 'rpy="1.4 0 0" xyz="0.11 0 0"'),
        hand_tcp_joint=('xyz="0 0 0.1034"', 'xyz="0.01 0.02 0.15"'),
    )
    solver = panda_solver_for(robot)
    assert isinstance(solver, PandaIK)
    check_solutions_q7(robot, solver, count=200, seed=12)
    rng = np.random.default_rng(13)
    for _ in range(200):
        target = robot.fk(robot.random_configuration(rng))
        q = solver.nearest(target.translation, target.rotation, robot.random_configuration(rng))
        assert q is not None
        assert_reaches(robot, q, target)
    # the stock panda solver gets this robot wrong: the geometry really comes from the file
    q = robot.random_configuration(rng)
    target = robot.fk(q)
    assert not contains(panda_solver.solutions_q7(target.translation, target.rotation, q[6]), q)


def test_other_tip_frames_are_absorbed(tmp_path):
    robot = modified_panda(tmp_path, tip="panda_link8")
    solver = panda_solver_for(robot)
    assert isinstance(solver, PandaIK)
    check_solutions_q7(robot, solver, count=100, seed=14)


@pytest.mark.parametrize(
    "replacements",
    [
        {"joint6": ('xyz="0 0 0"', 'xyz="0.02 0 0"')},  # axes 5 and 6 miss each other
        {"joint3": ('xyz="0 -0.316 0"', 'xyz="0.02 -0.316 0"')},  # axis 3 misses the shoulder
        {"joint2": ('xyz="0 0 0"', 'xyz="0.03 0 0"')},  # axes 1 and 2 miss each other
        {"joint6": ('rpy="1.5707963267948966 0 0"', 'rpy="0 0 0"')},  # axes 5 and 6 parallel
    ],
)
def test_broken_panda_structure_gives_none(tmp_path, replacements):
    assert panda_solver_for(modified_panda(tmp_path, **replacements)) is None


def test_joint_zero_offsets_are_absorbed(tmp_path):
    robot = modified_panda(
        tmp_path,
        joint4=('rpy="1.5707963267948966 0 0"', 'rpy="1.5707963267948966 0 0.2"'),
        joint6=('rpy="1.5707963267948966 0 0"', 'rpy="1.5707963267948966 0 -0.3"'),
        joint1=('rpy="0 0 0"', 'rpy="0 0 0.4"'),
    )
    solver = panda_solver_for(robot)
    assert isinstance(solver, PandaIK)
    check_solutions_q7(robot, solver, count=100, seed=15)


# ---------------------------------------------------------------------------- Robot.ik
def test_robot_ik_uses_the_panda_solver(panda):
    from kinplan.ik import analytic_solver_for

    assert isinstance(analytic_solver_for(panda), PandaIK)
    rng = np.random.default_rng(16)
    for _ in range(100):
        target = panda.fk(panda.random_configuration(rng))
        res = panda.ik(target, q_seed=panda.random_configuration(rng))
        assert res.success and res.method == "analytic", res
        assert_reaches(panda, res.q, target, tol=1e-6)


def test_a_panda_with_a_continuous_joint_is_solved_numerically(tmp_path):
    """A panda-type arm whose joint 7 is continuous (unbounded) is not given the closed form,
    whose θ7 search needs finite limits: its IK is the numerical one, and it solves (before,
    `ik` raised on a NaN mid-range reference)."""
    stock = kinplan.load_robot("panda")
    text = stock.urdf_path.read_text()
    start = text.index('<joint name="panda_joint7"')
    end = text.index("</joint>", start)
    text = (
        text[:start] + text[start:end].replace('type="revolute"', 'type="continuous"') + text[end:]
    )
    path = tmp_path / "panda_continuous_j7.urdf"
    path.write_text(text)
    robot = kinplan.load_robot(path, tip="panda_hand_tcp")
    assert np.isinf(robot.upper[6]) and robot.closed_form_ik is None
    rng = np.random.default_rng(3)
    for _ in range(20):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        result = robot.ik(target, q_seed=robot.random_configuration(rng))
        assert result.success and result.method == "numerical"
        assert np.linalg.norm(robot.fk(result.q).translation - target.translation) < 1e-6


def test_a_pose_the_closed_form_leaves_unsolved_goes_to_the_numerical_solve(monkeypatch):
    """The panda's closed form seeks the nearest solution at the seed's θ7 or within the θ7
    intervals where the elbow reaches; another θ7 may still have a solution within the limits
    (``PandaIK.complete`` is False). ``ik`` then solves numerically, and so does ``ik_batch``
    (it used to report such targets failed: 3 of 3,000 random targets of Yaskawa's SIA20D).
    Here the closed form is made to find nothing for three targets: both give the numerical
    answer, the same success and q."""
    robot = kinplan.load_robot("panda")
    solver = robot.closed_form_ik
    assert isinstance(solver, PandaIK) and not solver.complete
    rng = np.random.default_rng(61)
    targets, seeds = random_targets(robot, rng, 10)
    check_missed_targets_solved_numerically(robot, targets, seeds, [1, 4, 9], monkeypatch)
