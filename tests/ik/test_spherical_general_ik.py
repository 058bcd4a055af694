"""Closed-form IK of spherical-wrist 6R arms whose axes 2 and 3 are not parallel
(kinplan.ik.spherical_general: IK-Geo's axes 1, 2 meeting, axes 2, 3 meeting and general
shoulder, subproblem 5), on seeded synthetic arms written as URDF strings (random axes, not
perpendicular, offsets, link, base and tool frames; tests/ik/general_wrist_arms.py).

The solver is built from the arm's screws (``screws_at_zero`` + ``general_wrist_geometry``)
and checked with ``self_check``; ``closed_form_report`` gives it to the arms (``Robot.ik``,
``Robot.ik_batch``) after the spherical-wrist form refuses them for axes 2 ∦ 3. Every
solution reaches its target within 1e-9 (m, rad) by Pinocchio's FK and lies within the
limits; the generating configuration is among the solutions of thousands of random targets;
every branch a brute-force numerical search from 200 seeds finds is found (50 targets per arm
here, 200 with ``-m slow``); unreachable targets give none; the nearest solution follows the
rule of the other closed forms; arms outside the family say why.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from general_wrist_arms import general_arm_urdf
from ik_checks import (
    check_ik_and_batch,
    check_nearest_rule,
    contains,
    pose_errors,
    smallest_sigma,
    typical_sigma,
)

import kinplan
from kinplan.ik import ClosedFormIK, GeneralWristIK, closed_form_report, wrap_angle
from kinplan.ik.base import self_check
from kinplan.ik.screws import screws_at_zero
from kinplan.ik.spherical_general_geometry import (
    GENERAL,
    MEETING_12,
    MEETING_23,
    NOT_PARALLEL,
    general_wrist_geometry,
)
from kinplan.ik.spherical_general_kernel import SLOTS
from kinplan.ik.spherical_general_quartic import real_roots
from kinplan.ik.spherical_wrist_geometry import wrist_geometry
from kinplan.ik.subproblems import sp1

MODE_OF = {"12": MEETING_12, "23": MEETING_23, "general": GENERAL}
#: (mode, seed) of the synthetic arms: three of each mode.
ARMS = [(mode, seed) for mode in ("12", "23", "general") for seed in range(3)]
ARM_IDS = [f"{mode}-{seed}" for mode, seed in ARMS]
#: One arm per mode, for the longer tests.
ONE_PER_MODE = [("12", 0), ("23", 0), ("general", 0)]
ONE_IDS = ["12", "23", "general"]

#: Share of the arm's typical smallest singular value of the tool Jacobian below which a
#: configuration counts as singular: the only generating configurations allowed to be missed
#: (there two branches merge, and rounding decides which one is returned).
NEAR_SINGULAR = 1e-4


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> str:
    return str(tmp_path_factory.mktemp("general_wrist_arms"))


@functools.cache
def arm(mode: str, seed: int, folder: str) -> kinplan.Robot:
    path = Path(folder) / f"general_{mode}_{seed}.urdf"
    path.write_text(general_arm_urdf(seed, mode))
    return kinplan.load_robot(path, tip="tool0")


@functools.cache
def solver_of(mode: str, seed: int, folder: str) -> GeneralWristIK:
    robot = arm(mode, seed, folder)
    geometry, reason = general_wrist_geometry(screws_at_zero(robot))
    assert geometry is not None, reason
    return GeneralWristIK(geometry, robot.lower, robot.upper)


def near_singular(robot: kinplan.Robot, q: np.ndarray) -> bool:
    return smallest_sigma(robot, q) < NEAR_SINGULAR * typical_sigma(robot)


def poses_of(robot: kinplan.Robot, qs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    poses = [robot.fk(q) for q in qs]
    return np.array([p.translation for p in poses]), np.array([p.rotation for p in poses])


# ---------------------------------------------------------------------------- the quartic
def test_real_roots_of_quartics_with_known_roots():
    """Simple roots to 1e-12, a double root (once or twice) to 1e-7, degree drops, none."""
    rng = np.random.default_rng(5)
    out, work = np.empty(7), np.empty((3, 10))
    for _ in range(300):
        roots = np.sort(rng.uniform(-1.0, 1.0, 4))
        if np.min(np.diff(roots)) < 1e-3:
            continue
        c = np.poly(roots)[::-1] * rng.uniform(0.1, 10.0)
        n = real_roots(c, np.abs(c), -1.0, 1.0, out, work)
        np.testing.assert_allclose(out[:n], roots, atol=1e-12)
    double = np.poly([0.3, 0.3, -0.5, 2.0])[::-1]
    n = real_roots(double, np.abs(double), -1.0, 1.0, out, work)
    assert 2 <= n <= 3 and np.sum(np.abs(out[:n] - 0.3) < 1e-7) == n - 1
    assert np.min(np.abs(out[:n] + 0.5)) < 1e-12
    cubic = np.append(np.poly([-0.7, 0.1, 0.9])[::-1], 0.0)
    n = real_roots(cubic, np.abs(cubic), -1.0, 1.0, out, work)
    np.testing.assert_allclose(out[:n], [-0.7, 0.1, 0.9], atol=1e-12)
    quadratic = np.array([-0.25, 0.0, 1.0, 0.0, 0.0])
    n = real_roots(quadratic, np.abs(quadratic), -1.0, 1.0, out, work)
    np.testing.assert_allclose(out[:n], [-0.5, 0.5], atol=1e-12)
    none = np.array([2.0, 0.0, 3.0, 0.0, 1.0])  # (t² + 1)(t² + 2)
    assert real_roots(none, np.abs(none), -1.0, 1.0, out, work) == 0


def test_real_roots_agree_with_companion_eigenvalues():
    """Random quartics: the well-separated real roots numpy's companion matrix finds in the
    interval, and no others."""
    rng = np.random.default_rng(6)
    out, work = np.empty(7), np.empty((3, 10))
    for _ in range(500):
        c = rng.normal(size=5)
        found = out[: real_roots(c, np.abs(c), -2.0, 2.0, out, work)]
        eigen = np.roots(c[::-1])
        real = np.sort(eigen[np.abs(eigen.imag) < 1e-9].real)
        real = real[(real > -2.0) & (real < 2.0)]
        if len(real) > 1 and np.min(np.diff(real)) < 1e-4:
            continue  # nearly double: either may count it twice
        np.testing.assert_allclose(np.sort(found), real, atol=1e-9)


# ---------------------------------------------------------------------------- detection
@pytest.mark.parametrize("mode, seed", ARMS, ids=ARM_IDS)
def test_the_arms_are_read_from_their_screws(folder, mode, seed):
    robot = arm(mode, seed, folder)
    screws = screws_at_zero(robot)
    wrist, reason = wrist_geometry(screws)
    assert wrist is None and reason == NOT_PARALLEL  # the spherical-wrist form hands them on
    solver = solver_of(mode, seed, folder)
    assert solver.geometry.mode == MODE_OF[mode]
    assert solver.description == GeneralWristIK.descriptions[MODE_OF[mode]]
    assert solver.description.startswith("closed form: spherical wrist, ")
    assert ("subproblem 5" in solver.description) == (mode == "general")
    # the meeting point lies on both meeting axes
    g = solver.geometry
    for axis in {"12": (0, 1), "23": (1, 2), "general": ()}[mode]:
        off = g.origin - g.points[axis]
        assert np.linalg.norm(off - (off @ g.axes[axis]) * g.axes[axis]) < 1e-9
    assert self_check(robot, lambda pose, q: solver.solutions(pose.translation, pose.rotation))


@pytest.mark.parametrize("mode, seed", ARMS, ids=ARM_IDS)
def test_the_robot_gets_the_closed_form(folder, mode, seed):
    """``closed_form_report`` tries this family right after the spherical-wrist form refuses
    axes 2 ∦ 3 (before the 1-D search, which took arms with axes 1, 2 meeting before)."""
    robot = arm(mode, seed, folder)
    solver = robot.closed_form_ik
    assert isinstance(solver, GeneralWristIK), robot.ik_solver.description
    assert robot.ik_solver.description == GeneralWristIK.descriptions[MODE_OF[mode]]
    assert solver.geometry.mode == MODE_OF[mode]
    reported, description = closed_form_report(robot, np.full(6, 2.0))
    assert isinstance(reported, GeneralWristIK) and description == solver.description
    np.testing.assert_array_equal(reported.weights, np.full(6, 2.0))


def _variant(tmp_path, name: str, mode: str, **variants) -> kinplan.Robot:
    path = tmp_path / f"{name}.urdf"
    path.write_text(general_arm_urdf(4, mode, **variants))
    return kinplan.load_robot(path, tip="tool0")


@pytest.mark.parametrize(
    "mode, variants, reason",
    [
        ("general", {"parallel23": True}, "axes 2 ∥ 3: the spherical wrist with axes 2 ∥ 3"),
        ("general", {"parallel12": True}, "axes 1 and 2 are parallel or nearly so"),
        ("12", {"wrist_offset": 0.03}, "no spherical wrist: axis 6 misses the meeting of axes"),
        ("general", {"centre_on_axis3": True}, "the wrist centre lies on axis 3"),
        ("general", {"gap": 1e-4}, "both nearly meet: subproblem 5 is ill-conditioned"),
        ("12", {"angle12": 1e-4}, "axes 1 and 2 meet at 1.0e-04 rad: nearly parallel"),
    ],
    ids=["2-par-3", "1-par-2", "wrist-offset", "centre-on-3", "both-near", "meet-grazing"],
)
def test_arms_outside_the_family_say_why(tmp_path, mode, variants, reason):
    robot = _variant(tmp_path, "outside", mode, **variants)
    geometry, why = general_wrist_geometry(screws_at_zero(robot))
    assert geometry is None
    assert reason in why, why
    assert not isinstance(robot.closed_form_ik, GeneralWristIK)
    if "axes 2 ∥ 3" in reason:  # the spherical wrist with axes 2 ∥ 3 takes it
        assert robot.ik_solver.description.startswith("closed form: spherical wrist (axes 4")
    elif "both nearly meet" in reason:  # no other form: numerical, and the report says why
        description = robot.ik_solver.description
        assert description.startswith("numerical") and f"no IK-Geo spherical form: {why}" in (
            description
        )


def test_other_joint_counts_say_why():
    geometry, why = general_wrist_geometry(screws_at_zero(kinplan.load_robot("panda")))
    assert geometry is None and why == "7 joints, not 6"


def test_nearly_meeting_axes_use_the_general_shoulder(tmp_path):
    """Axes 1 and 2 (or 2 and 3) 3e-9 m apart: not meeting (1e-9 m), so subproblem 5 serves,
    and one nearly meeting pair loses no solution (its quartic's roots come in near pairs)."""
    for mode in ("12", "23"):
        robot = _variant(tmp_path, f"near_{mode}", mode, near=3e-9)
        geometry, why = general_wrist_geometry(screws_at_zero(robot))
        assert geometry is not None and geometry.mode == GENERAL, why
        solver = GeneralWristIK(geometry, robot.lower, robot.upper)
        rng = np.random.default_rng(8)
        qs = np.array([robot.random_configuration(rng) for _ in range(1000)])
        raw, _ = solver.all_branches(*poses_of(robot, qs), qs)
        gap = np.nan_to_num(np.abs(wrap_angle(raw - qs[:, None, :])).max(axis=2), nan=np.inf)
        for index in np.flatnonzero(gap.min(axis=1) >= 1e-7):
            assert near_singular(robot, qs[index]), qs[index]


# ---------------------------------------------------------------------------- solutions
@pytest.mark.parametrize("mode, seed", ARMS, ids=ARM_IDS)
def test_every_solution_reaches_the_target(folder, mode, seed):
    """150 random configurations: the generating one among the solutions, each solution
    within the limits and within 1e-9 m and 1e-9 rad of the target by Pinocchio's FK."""
    robot = arm(mode, seed, folder)
    solver = solver_of(mode, seed, folder)
    rng = np.random.default_rng(17 + seed)
    counts = []
    for _ in range(150):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        solutions = solver.solutions(target.translation, target.rotation)
        assert 1 <= len(solutions) <= SLOTS
        assert contains(solutions, q, 1e-7), (q, solutions)
        for s in solutions:
            assert robot.within_limits(s, tolerance=0.0)
            position, rotation = pose_errors(robot, s, target)
            assert position <= 1e-9 and rotation <= 1e-9, (s, position, rotation)
        counts.append(len(solutions))
    assert max(counts) >= 6  # the branches are found, not only the generating one


@pytest.mark.parametrize("mode, seed", ARMS, ids=ARM_IDS)
def test_generating_configurations_are_found_over_thousands_of_targets(folder, mode, seed):
    """2,000 random configurations at once: the generating one is among the solutions (any 2π
    representative) except where it is singular (:data:`NEAR_SINGULAR`), and such misses
    are rare."""
    robot = arm(mode, seed, folder)
    solver = solver_of(mode, seed, folder)
    rng = np.random.default_rng(23 + seed)
    qs = np.array([robot.random_configuration(rng) for _ in range(2000)])
    positions, rotations = poses_of(robot, qs)
    raw, _ = solver.all_branches(positions, rotations, qs)
    gap = np.nan_to_num(np.abs(wrap_angle(raw - qs[:, None, :])).max(axis=2), nan=np.inf)
    missed = np.flatnonzero(gap.min(axis=1) >= 1e-7)
    assert missed.size <= 2, missed
    for index in missed:
        assert near_singular(robot, qs[index]), (qs[index], smallest_sigma(robot, qs[index]))
    assert np.isfinite(raw[:, :, 0]).sum(axis=1).max() <= SLOTS


#: Random reachable targets of the brute-force comparison: 50 per arm in ``make test``, 200 in
#: ``make soak`` (each target costs 200 numerical solves).
BRUTE_FORCE_TARGETS = [
    pytest.param(50, ONE_PER_MODE, id="50"),
    pytest.param(200, ARMS, id="200", marks=pytest.mark.slow),
]


@pytest.mark.parametrize("targets, arms", BRUTE_FORCE_TARGETS)
def test_brute_force_numerical_branches_are_all_found(folder, targets, arms):
    """Random reachable targets: every distinct solution (mod 2π, within the limits) that the
    numerical solver converges to from 200 random seeds is one of the closed form's (except
    at a singular one, :data:`NEAR_SINGULAR`)."""
    for mode, seed in arms:
        robot = arm(mode, seed, folder)
        solver = solver_of(mode, seed, folder)
        numeric = robot.ik_solver
        rng = np.random.default_rng(31 + seed)
        seeds = [robot.random_configuration(rng) for _ in range(200)]
        branches = 0
        for _ in range(targets):
            target = robot.fk(robot.random_configuration(rng))
            closed = solver.solutions(target.translation, target.rotation)
            found: list[np.ndarray] = []
            for seed_q in seeds:
                result = numeric.solve(target.translation, target.rotation, seed_q,
                                       1e-10, 1e-10, 100, 0)  # fmt: skip
                if result.success and not contains(found, result.q, 1e-6):
                    found.append(result.q)
            for q in found:
                if not contains(closed, q, 1e-6):
                    assert near_singular(robot, q), (mode, seed, q, closed)
            branches += len(found)
        assert branches >= 2 * targets  # the search finds several branches per target


@pytest.mark.parametrize("mode, seed", ARMS, ids=ARM_IDS)
def test_nearest_follows_the_closed_form_rule(folder, mode, seed):
    """The compiled nearest (one pose and many) equals the base class's choice over the same
    branches (per joint the equivalent within the limits nearest the reference, then the
    least Σ wᵢ Δqᵢ², ties to the lower row), which is the least distance over the solutions."""
    robot = arm(mode, seed, folder)
    solver = solver_of(mode, seed, folder)
    rng = np.random.default_rng(41 + seed)
    positions, rotations, refs, expected = [], [], [], []
    for _ in range(200):
        target = robot.fk(robot.random_configuration(rng))
        ref = robot.random_configuration(rng) + rng.normal(0.0, 0.5, 6)
        found = check_nearest_rule(robot, solver, target, ref)
        positions.append(target.translation)
        rotations.append(target.rotation)
        refs.append(ref)
        expected.append(found)
    q, row, mask, left = solver.nearest_many(np.array(positions), np.array(rotations),
                                             np.array(refs))  # fmt: skip
    assert not left.any() and np.all(row >= 0) and np.all(mask & (1 << row))
    np.testing.assert_array_equal(q, np.array(expected))


def test_weights_choose_the_branch(folder):
    """A heavy weight on θ1 makes the nearest solution keep θ1 near the reference."""
    robot = arm("general", 1, folder)
    geometry = solver_of("general", 1, folder).geometry
    weights = np.array([100.0, 1.0, 1.0, 1.0, 1.0, 1.0])
    heavy = GeneralWristIK(geometry, robot.lower, robot.upper, weights)
    light = GeneralWristIK(geometry, robot.lower, robot.upper)
    rng = np.random.default_rng(44)
    differ = 0
    for _ in range(100):
        target = robot.fk(robot.random_configuration(rng))
        ref = robot.random_configuration(rng)
        a = heavy.nearest(target.translation, target.rotation, ref)
        b = light.nearest(target.translation, target.rotation, ref)
        assert abs(a[0] - ref[0]) <= abs(b[0] - ref[0]) + 1e-12
        base = ClosedFormIK.nearest(heavy, target.translation, target.rotation, ref)
        np.testing.assert_allclose(a, base, atol=1e-12)
        differ += not np.allclose(a, b)
    assert differ > 0


@pytest.mark.parametrize("mode, seed", ONE_PER_MODE, ids=ONE_IDS)
def test_robot_ik_and_batch_on_random_targets(folder, mode, seed):
    """300 random reachable targets from random seeds: ``Robot.ik`` solves each by the closed
    form (within 1e-6, within the limits), ``Robot.ik_batch`` gives the same answers."""
    robot = arm(mode, seed, folder)
    rng = np.random.default_rng(47)
    count = 300
    targets, seeds, q = check_ik_and_batch(robot, rng, count, threads=1)
    q2, success2 = robot.ik_batch(targets, seeds, threads=2)
    assert success2.all()
    np.testing.assert_allclose(q2, q, atol=1e-12)


@pytest.mark.parametrize("mode, seed", ONE_PER_MODE, ids=ONE_IDS)
def test_unreachable_targets_give_no_solution(folder, mode, seed):
    robot = arm(mode, seed, folder)
    solver = solver_of(mode, seed, folder)
    rng = np.random.default_rng(43)
    far = np.full(3, 25.0)  # 25 m away on every axis
    for _ in range(20):
        rotation = pin.exp3(rng.normal(size=3))
        assert len(solver.solutions(far, rotation)) == 0
        assert solver.nearest(far, rotation, np.zeros(6)) is None
    raw, singular = solver.all_branches(np.tile(far, (5, 1)), np.tile(np.eye(3), (5, 1, 1)),
                                        np.zeros((5, 6)))  # fmt: skip
    assert np.isnan(raw).all() and not singular.any()
    result = robot.ik(pin.SE3(np.eye(3), far), np.zeros(6), max_restarts=2)
    assert not result.success
    q, success = robot.ik_batch(np.tile(pin.SE3(np.eye(3), far).homogeneous, (5, 1, 1)),
                                max_restarts=0)  # fmt: skip
    assert not success.any() and np.all(np.isfinite(q))
    # a target just beyond the reach: the generating pose pushed out along the wrist centre
    g = solver.geometry
    q = robot.random_configuration(rng)
    target = robot.fk(q)
    centre = target.translation + target.rotation @ g.tool_rotation.T @ (g.centre - g.tool_position)
    pushed = target.translation + 100.0 * (centre - g.points[0])
    assert len(solver.solutions(pushed, target.rotation)) == 0


def test_non_finite_input_is_refused_by_the_base_checks(folder):
    solver = solver_of("general", 0, folder)
    from kinplan.errors import InputError

    with pytest.raises(InputError):
        solver.nearest(np.array([np.nan, 0.0, 0.0]), np.eye(3), np.zeros(6))
    with pytest.raises(InputError):
        solver.nearest(np.zeros(3), np.eye(3), np.full(6, np.inf))
    with pytest.raises(InputError):
        solver.nearest(np.zeros(3), None, np.zeros(6))


# ---------------------------------------------------------------------------- singularities
@pytest.mark.parametrize("mode, seed", ONE_PER_MODE, ids=ONE_IDS)
def test_near_the_wrist_singularity(folder, mode, seed):
    """θ5 within 1e-13–1e-4 rad of the wrist singularity (or on it, to rounding): every
    solution within 1e-9 of the target, the generating one among them where it is not
    within 1e-6 rad of the singularity, and from itself as reference the nearest solution
    within 1e-5 rad of it (θ4, θ6 are only fixed to about √ε there)."""
    robot = arm(mode, seed, folder)
    solver = solver_of(mode, seed, folder)
    h = solver.geometry.axes
    singular5, _ = sp1(h[4], h[5], h[3])  # θ5 with R5 h6 ∥ h4
    rng = np.random.default_rng(51)
    for trial in range(60):
        q = robot.random_configuration(rng)
        offset = 0.0 if trial % 4 == 0 else 10.0 ** rng.uniform(-13, -4) * rng.choice([-1, 1])
        q[4] = float(np.clip(singular5 + offset, robot.lower[4], robot.upper[4]))
        target = robot.fk(q)
        solutions = solver.solutions(target.translation, target.rotation)
        assert len(solutions) > 0
        for s in solutions:
            position, rotation = pose_errors(robot, s, target)
            assert position <= 1e-9 and rotation <= 1e-9, (s, position, rotation)
        if abs(q[4] - singular5) > 1e-6:
            assert contains(solutions, q, 1e-7)
        again = solver.nearest(target.translation, target.rotation, q)
        assert np.max(np.abs(wrap_angle(again - q))) < 1e-5, (again, q)


def _centre_on_axis1(solver: GeneralWristIK, rng: np.random.Generator) -> np.ndarray | None:
    """(θ2, θ3) [rad] putting ``e2 e3 c`` on axis 1 (then θ1 is free), by Gauss–Newton from
    random starts; None when no start converges."""
    g = solver.geometry
    h, p = g.axes, g.points

    def miss(t: np.ndarray) -> np.ndarray:
        x = p[2] + pin.exp3(h[2] * t[1]) @ (g.centre - p[2])
        x = p[1] + pin.exp3(h[1] * t[0]) @ (x - p[1])
        off = x - p[0]
        return off - (off @ h[0]) * h[0]

    for _ in range(20):
        t = rng.uniform(-np.pi, np.pi, 2)
        for _ in range(50):
            r = miss(t)
            jac = np.column_stack([(miss(t + d) - r) / 1e-7 for d in np.eye(2) * 1e-7])
            t = t - np.linalg.lstsq(jac, r, rcond=None)[0]
        for _ in range(5):  # Newton on the two components across axis 1, to rounding
            r = miss(t)
            jac = np.column_stack([(miss(t + d) - miss(t - d)) / 2e-6 for d in np.eye(2) * 1e-6])
            t = t - np.linalg.lstsq(jac, r, rcond=None)[0]
        if np.linalg.norm(miss(t)) < 1e-14:
            return t
    return None


@pytest.mark.parametrize("mode, seed", ONE_PER_MODE, ids=ONE_IDS)
def test_wrist_centre_on_axis_1_keeps_the_reference_theta1(folder, mode, seed):
    """The shoulder singularity (the wrist centre on axis 1: θ1 free for the position): the
    pose is flagged singular, the nearest solution reaches the target and keeps the
    reference's θ1 where the wrist can then match the rotation (else θ1 is the nearest value
    at the edge of the wrist's reach; either way a solution is found)."""
    robot = arm(mode, seed, folder)
    solver = solver_of(mode, seed, folder)
    rng = np.random.default_rng(61)
    kept = tried = 0
    for _ in range(12):
        found = _centre_on_axis1(solver, rng)
        if found is None:
            continue
        q = robot.random_configuration(rng)
        q[1], q[2] = wrap_angle(found)
        if not robot.within_limits(q, tolerance=0.0):
            continue
        target = robot.fk(q)
        for ref in (q, robot.random_configuration(rng)):
            kept += _keeps_theta1(robot, solver, target, ref)
            tried += 1
    assert tried >= 6 and kept >= 3, (tried, kept)


def _keeps_theta1(robot, solver, target: pin.SE3, ref: np.ndarray) -> bool:
    """Whether the nearest solution of ``target`` (the wrist centre on axis 1) keeps θ1 of
    ``ref`` (after checking that it is flagged singular and reaches the target)."""
    _, singular = solver.all_branches(target.translation[None], target.rotation[None],
                                      ref[None])  # fmt: skip
    assert singular[0]
    solution = solver.nearest(target.translation, target.rotation, ref)
    assert solution is not None
    position, rotation = pose_errors(robot, solution, target)
    assert position <= 1e-9 and rotation <= 1e-9
    return abs(solution[0] - ref[0]) < 1e-9


# ---------------------------------------------------------------------------- paths
@pytest.mark.parametrize("mode, seed", ONE_PER_MODE, ids=ONE_IDS)
def test_path_following_equals_sample_by_sample_nearest(folder, mode, seed):
    """``nearest_batch`` along a reachable path (the FK of a joint-space line) equals
    ``nearest`` sample after sample, and stays on the path's branch."""
    robot = arm(mode, seed, folder)
    solver = solver_of(mode, seed, folder)
    rng = np.random.default_rng(53)
    start = robot.random_configuration(rng) * 0.5
    step = rng.normal(size=6)
    path = start + np.outer(np.linspace(0.0, 1.0, 60), 0.4 * step / np.linalg.norm(step))
    positions, rotations = poses_of(robot, path)
    followed = solver.nearest_batch(positions, rotations, start)
    ref = start
    for k in range(len(path)):
        q = solver.nearest(positions[k], rotations[k], ref)
        np.testing.assert_allclose(followed[k], q, atol=1e-9, err_msg=f"sample {k}")
        ref = q
    np.testing.assert_allclose(followed, path, atol=1e-7)
