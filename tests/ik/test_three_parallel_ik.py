"""Closed-form IK of 6R arms with three parallel axes 2 ∥ 3 ∥ 4 and axes 1, 5, 6 anywhere
(kinplan.ik.three_parallel, IK-Geo's subproblem-6 solver): synthetic arms with random,
non-perpendicular, non-meeting axes 1, 5, 6 and random offsets (tests/ik/parallel_arms.py),
UR5 variants whose wrist the UR closed form refuses (axis 5 tilted; axis 6 tilted and 2 cm off
axis 5; axis 6 2 cm off axis 5), and Unitree's Z1 (example-robot-data, no shoulder offset).

Tolerances: every solution reaches its target within 1e-9 m and 1e-9 rad by Pinocchio's FK
(the kernel's own check is the product of exponentials to 1e-9); a configuration is "among the
solutions" when one is within 1e-7 rad of it on every joint (mod 2π); ``ik`` within 1e-6 (its
default tolerances); ``ik_batch`` equal to ``ik`` within 1e-9 rad; the compiled ``nearest``
equal to the base class's numpy choice within 1e-12 rad.
"""

from __future__ import annotations

import functools
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from ik_checks import (
    check_ik_and_batch,
    check_nearest_rule,
    contains,
    pose_errors,
    smallest_sigma,
    typical_sigma,
)
from parallel_arms import parallel_arm_urdf, skewed_ur5_urdf

import kinplan
from kinplan.ik import URIK, ThreeParallelIK, closed_form_report, wrap_angle
from kinplan.ik.screws import Screws, screws_at_zero
from kinplan.ik.three_parallel_geometry import three_parallel_geometry
from kinplan.ik.three_parallel_quartic import MOST, real_roots
from kinplan.ik.ur_geometry import ur_geometry
from kinplan.model.sources import example_robot_data_dir

Z1 = example_robot_data_dir() / "example-robot-data" / "robots" / "z1_description/urdf/z1.urdf"

SYNTHETIC = [0, 1, 2, 3]
UR_VARIANTS = ["axis5", "axis6", "miss"]
ALL = [("synthetic", s) for s in SYNTHETIC] + [("ur5", v) for v in UR_VARIANTS] + [("z1", "")]
ALL_IDS = [f"arm{s}" for s in SYNTHETIC] + [f"ur5-{v}" for v in UR_VARIANTS] + ["z1"]

#: A configuration counts as found when a solution is within this of it on every joint [rad].
FOUND = 1e-7
#: FK tolerance of every solution [m] and [rad].
REACH = 1e-9


@functools.cache
def robot_of(kind: str, which, folder: str) -> kinplan.Robot:
    if kind == "z1":
        return kinplan.load_robot(Z1)
    if kind == "synthetic":
        text = parallel_arm_urdf(which)
    else:
        text = skewed_ur5_urdf(kinplan.load_robot("ur5").urdf_path.read_text(), which)
    path = Path(folder) / f"{kind}_{which}.urdf"
    path.write_text(text)
    return kinplan.load_robot(path, tip="tool0")


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> str:
    return str(tmp_path_factory.mktemp("parallel_arms"))


#: A configuration whose smallest Jacobian singular value is below this share of the arm's
#: typical one is "at a singularity": there two branches meet (a double root of the quartic,
#: merged when rounding splits it into two roots ≲ 1e-7 apart), and the solution returned may
#: be that double root rather than the generating configuration a hair away.
AT_SINGULARITY = 1e-4


# ---------------------------------------------------------------------------- structure
@pytest.mark.parametrize("kind, which", ALL, ids=ALL_IDS)
def test_the_arms_get_the_family(folder, kind, which):
    robot = robot_of(kind, which, folder)
    solver = robot.closed_form_ik
    assert isinstance(solver, ThreeParallelIK), robot.ik_solver.description
    assert robot.ik_solver.description == ThreeParallelIK.description
    assert robot.ik_solver.description.startswith("closed form: three parallel axes 2 ∥ 3 ∥ 4")
    assert ur_geometry(screws_at_zero(robot)) is None  # the UR closed form refuses them
    assert robot.batch_solver.method(False) == "closed-form"


def test_ur5_keeps_the_ur_closed_form_and_both_agree():
    """The UR5 is of the family too but keeps URIK (tried first); the family's solver built on
    its geometry gives the same solutions on 300 random targets."""
    robot = kinplan.load_robot("ur5")
    assert isinstance(robot.closed_form_ik, URIK)
    geometry, reason = three_parallel_geometry(screws_at_zero(robot))
    assert geometry is not None, reason
    ours = ThreeParallelIK(geometry, robot.lower, robot.upper)
    rng = np.random.default_rng(61)
    for _ in range(300):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        mine = ours.solutions(target.translation, target.rotation)
        ur = robot.closed_form_ik.solutions(target.translation, target.rotation)
        assert len(mine) == len(ur), (mine, ur)
        for s in ur:
            assert contains(mine, s, 1e-8), (s, mine)


def test_arms_outside_the_family_say_why(tmp_path):
    """Refusals name the reason; an arm with axis 4 tilted off axes 2 ∥ 3 is numerical and its
    report says why it is not three-parallel."""
    base = screws_at_zero(robot_of("synthetic", 0, str(tmp_path)))

    def reason_with(index: int, direction=None, point=None) -> str:
        u, p = base.directions.copy(), base.points.copy()
        if direction is not None:
            u[index] = direction / np.linalg.norm(direction)
        if point is not None:
            p[index] = point
        geometry, reason = three_parallel_geometry(Screws(u, p, base.tool))
        assert geometry is None
        return reason

    u, p = base.directions, base.points
    across = np.cross(u[1], u[0]) / np.linalg.norm(np.cross(u[1], u[0]))
    tilted = np.cos(0.05) * u[1] + np.sin(0.05) * across  # 0.05 rad off axis 2
    assert reason_with(3, direction=tilted).startswith("axes 2 and 4 are not parallel (sin 5.0e-02")
    assert reason_with(2, direction=tilted).startswith("axes 2 and 3 are not parallel")
    assert "axis 3 is the same line as axis 2" in reason_with(2, point=p[1] + 0.3 * u[1])
    assert "axis 1 is parallel to them" in reason_with(0, direction=u[1])
    assert "axis 5 is parallel to them" in reason_with(4, direction=-u[1])
    assert "axes 5 and 6 are the same line" in reason_with(
        5, direction=u[4], point=p[4] + 0.2 * u[4]
    )
    short = Screws(u[:5], p[:5], base.tool)
    assert three_parallel_geometry(short) == (None, "5 joints, not 6")
    # a whole arm: axis 4 turned 0.1 rad about the link (no other closed form fits either)
    text = parallel_arm_urdf(0)
    pattern = r'(<joint name="j4".*?<axis xyz=")(\S+) (\S+) (\S+)"'
    axis4 = np.array([float(x) for x in re.search(pattern, text, re.S).groups()[1:]])
    turned = pin.exp3(0.1 * np.cross(axis4, [0.0, 0.0, 1.0]) / np.linalg.norm(
        np.cross(axis4, [0.0, 0.0, 1.0]))) @ axis4  # fmt: skip
    text = re.sub(pattern, lambda m: m[1] + " ".join(f"{x:.17g}" for x in turned) + '"', text,
                  count=1, flags=re.S)  # fmt: skip
    path = tmp_path / "tilted4.urdf"
    path.write_text(text)
    robot = kinplan.load_robot(path, tip="tool0")
    solver, description = closed_form_report(robot)
    assert solver is None and robot.closed_form_ik is None
    assert "not three parallel axes: axes 2 and 4 are not parallel (sin 1.0e-01)" in description
    assert "no 1-D search form" in description and "not the UR structure" in description


# ---------------------------------------------------------------------------- solutions
@pytest.mark.parametrize("kind, which", ALL, ids=ALL_IDS)
def test_every_solution_reaches_the_target(folder, kind, which):
    """200 random configurations: the generating one among the solutions, each solution within
    the limits and within 1e-9 m and 1e-9 rad of the target by Pinocchio's FK."""
    robot = robot_of(kind, which, folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(17)
    counts = []
    for _ in range(200):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        solutions = solver.solutions(target.translation, target.rotation)
        assert contains(solutions, q, FOUND), (q, solutions)
        for s in solutions:
            assert robot.within_limits(s, tolerance=0.0)
            position, rotation = pose_errors(robot, s, target)
            assert position <= REACH and rotation <= REACH, (s, position, rotation)
        raw, _ = solver.all_branches(target.translation[None], target.rotation[None], q[None])
        counts.append(int(np.isfinite(raw[0, :, 0]).sum()))  # limits aside
    assert max(counts) == 8  # all eight branches on some targets


@pytest.mark.parametrize("kind, which", ALL, ids=ALL_IDS)
def test_generating_configurations_are_found_over_thousands_of_targets(folder, kind, which):
    """3,000 seeded configurations at once (every solution of many poses, compiled): the
    generating configuration is among the solutions, except at a singularity (smallest
    Jacobian singular value below :data:`AT_SINGULARITY` of the arm's typical one), and there
    at most one in 3,000."""
    robot = robot_of(kind, which, folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(23)
    qs = np.array([robot.random_configuration(rng) for _ in range(3000)])
    poses = [robot.fk(q) for q in qs]
    raw, singular = solver.all_branches(np.array([p.translation for p in poses]),
                                        np.array([p.rotation for p in poses]), qs)  # fmt: skip
    gap = np.abs(wrap_angle(raw - qs[:, None, :])).max(axis=2)
    missed = np.flatnonzero(~(np.nan_to_num(gap, nan=np.inf) < FOUND).any(axis=1))
    assert missed.size <= 1, (missed, qs[missed[:3]])
    for index in missed:
        sigma = smallest_sigma(robot, qs[index])
        assert sigma < AT_SINGULARITY * typical_sigma(robot), (qs[index], sigma)
    counts = np.isfinite(raw[:, :, 0]).sum(axis=1)
    assert counts.max() <= solver.slots
    assert not singular.any()  # random configurations are not exactly singular


#: Random reachable targets of the brute-force comparison: 50 in ``make test``, 200 in
#: ``make soak`` (each target costs 200 numerical solves).
BRUTE_FORCE_TARGETS = [
    pytest.param(50, id="50"),
    pytest.param(200, id="200", marks=pytest.mark.slow),
]
BRUTE_FORCE_ARMS = [ALL[0], ALL[1], ALL[5], ALL[7]]
#: Distinct numerical solutions per target at least (the Z1's narrow limits keep about one).
LEAST_BRANCHES = {"z1": 1}
BRUTE_FORCE_IDS = [ALL_IDS[0], ALL_IDS[1], ALL_IDS[5], ALL_IDS[7]]


@pytest.mark.parametrize("targets", BRUTE_FORCE_TARGETS)
@pytest.mark.parametrize("kind, which", BRUTE_FORCE_ARMS, ids=BRUTE_FORCE_IDS)
def test_brute_force_numerical_branches_are_all_found(folder, kind, which, targets):
    """Random reachable targets: every distinct solution (mod 2π, within the limits) that the
    numerical solver converges to (1e-10 m and rad) from 200 random seeds is one of the closed
    form's (within 1e-6 rad: the numerical solutions' own accuracy near singularities)."""
    robot = robot_of(kind, which, folder)
    solver = robot.closed_form_ik
    numeric = robot.ik_solver
    rng = np.random.default_rng(31)
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
            assert contains(closed, q, 1e-6), (q, closed)
        branches += len(found)
    assert branches >= LEAST_BRANCHES.get(kind, 2) * targets  # several branches per target


@pytest.mark.parametrize("kind, which", ALL, ids=ALL_IDS)
def test_nearest_follows_the_closed_form_rule(folder, kind, which):
    """The compiled nearest equals the base class's choice over the same solutions (per joint
    the equivalent within the limits nearest the reference, then the least Σ wᵢ Δqᵢ²), and
    ``nearest_many`` equals it pose by pose."""
    robot = robot_of(kind, which, folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(41)
    positions, rotations, refs, expected = [], [], [], []
    for _ in range(150):
        target = robot.fk(robot.random_configuration(rng))
        ref = robot.random_configuration(rng) + rng.normal(0.0, 0.5, 6)
        found = check_nearest_rule(robot, solver, target, ref)
        positions.append(target.translation)
        rotations.append(target.rotation)
        refs.append(ref)
        expected.append(found)
    q, row, mask, left = solver.nearest_many(np.array(positions), np.array(rotations),
                                             np.array(refs))  # fmt: skip
    assert not left.any() and (row >= 0).all() and (mask > 0).all()
    np.testing.assert_allclose(q, np.array(expected), rtol=0, atol=1e-12)


@pytest.mark.parametrize("kind, which", ALL, ids=ALL_IDS)
def test_unreachable_targets_give_no_solution(folder, kind, which):
    robot = robot_of(kind, which, folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(43)
    far = np.full(3, 25.0)  # 25 m away on every axis
    for _ in range(20):
        rotation = pin.exp3(rng.normal(size=3))
        assert len(solver.solutions(far, rotation)) == 0
        assert solver.nearest(far, rotation, np.zeros(6)) is None
        result = robot.ik(pin.SE3(rotation, far), np.zeros(6), max_restarts=2)
        assert not result.success
    q, success = robot.ik_batch(np.tile(pin.SE3(np.eye(3), far).homogeneous, (5, 1, 1)),
                                max_restarts=0)  # fmt: skip
    assert not success.any() and np.all(np.isfinite(q))


@pytest.mark.parametrize("kind, which", ALL, ids=ALL_IDS)
def test_robot_ik_and_batch_on_random_targets(folder, kind, which):
    """300 random reachable targets from random seeds: ``ik`` solves each by the closed form
    (within 1e-6, within the limits) and ``ik_batch`` gives the same answers (1e-9 rad)."""
    robot = robot_of(kind, which, folder)
    rng = np.random.default_rng(47)
    count = 300
    check_ik_and_batch(robot, rng, count)


@pytest.mark.parametrize("kind, which", [ALL[0], ALL[5]], ids=[ALL_IDS[0], ALL_IDS[5]])
def test_path_following_equals_sample_by_sample_nearest(folder, kind, which):
    """``nearest_batch`` along a line and a turn equals ``nearest`` sample after sample."""
    robot = robot_of(kind, which, folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(53)
    start = robot.random_configuration(rng) * 0.5
    pose = robot.fk(start)
    steps = np.linspace(0.0, 1.0, 60)
    positions = pose.translation + np.outer(steps, [0.05, -0.03, 0.04])
    rotations = np.array([pose.rotation @ pin.exp3(np.array([0.0, 0.3, 0.2]) * s) for s in steps])
    followed = solver.nearest_batch(positions, rotations, start)
    ref = start
    for k in range(len(steps)):
        q = solver.nearest(positions[k], rotations[k], ref)
        if q is None:
            assert np.isnan(followed[k]).all()
            continue
        np.testing.assert_allclose(followed[k], q, atol=1e-9, err_msg=f"sample {k}")
        ref = q
    assert np.isfinite(followed).all()
    assert np.abs(np.diff(followed, axis=0)).max() < 0.2  # one branch: small joint steps


# ---------------------------------------------------------------------------- singular poses
def test_wrist_singularity_keeps_the_reference(folder):
    """UR5 with axis 6 2 cm off axis 5, θ5 = 0 (axis 6 ∥ axes 2–4: a continuum of θ6): the
    pose is flagged singular; the branches with θ5 = 0 take θ6 from the reference, or, where
    that leaves the elbow out of reach, the nearest θ6 that does not (the elbow then straight
    or folded: both elbow rows equal); every solution reaches the target; from the
    configuration itself the nearest solution is that configuration; path following through
    the singularity stays on the path it came from. The home pose q = 0."""
    robot = robot_of("ur5", "miss", folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(71)
    kept = moved = 0
    for _ in range(100):
        q = robot.random_configuration(rng)
        q[4] = 0.0
        target = robot.fk(q)
        ref = robot.random_configuration(rng)
        raw, singular = solver.all_branches(target.translation[None], target.rotation[None],
                                            ref[None])  # fmt: skip
        assert singular[0]
        rows = raw[0][np.isfinite(raw[0, :, 0])]
        for s in rows:
            position, rotation = pose_errors(robot, s, target)
            assert position <= REACH and rotation <= REACH, (s, position, rotation)
        free = rows[np.abs(np.sin(rows[:, 4])) < 1e-12]
        assert len(free) >= 2
        for s in free:
            if abs(wrap_angle(s[5] - ref[5])) < 1e-12:
                kept += 1
            else:  # the elbow at its reach limit: the two elbow rows coincide
                twins = free[np.abs(wrap_angle(free[:, 0] - s[0])) < 1e-12]
                assert np.abs(wrap_angle(twins - s)).max() < 1e-6, (s, free)
                moved += 1
        again = solver.nearest(target.translation, target.rotation, q)
        np.testing.assert_allclose(again, q, atol=1e-9)
        assert robot.ik(target, ref).success
    assert kept > 100 and moved > 0
    # a path through the singularity (θ5 from −0.05 to 0.05, exactly 0 at sample 20): followed
    # sample by sample, θ6 keeps its value across it and the path is the one it came from
    q = robot.random_configuration(rng) * 0.5
    path = np.tile(q, (41, 1))
    path[:, 4] = np.linspace(-0.05, 0.05, 41)
    poses = [robot.fk(x) for x in path]
    followed = solver.nearest_batch(np.array([x.translation for x in poses]),
                                    np.array([x.rotation for x in poses]), path[0])  # fmt: skip
    np.testing.assert_allclose(wrap_angle(followed - path), 0.0, atol=1e-9)
    home = robot.fk(np.zeros(6))
    result = robot.ik(home, np.zeros(6))
    assert result.success and result.method == "analytic"
    np.testing.assert_allclose(result.q, np.zeros(6), atol=1e-9)


def test_shoulder_singularity_of_the_z1(folder):
    """Z1 (no shoulder offset) with the meeting point of axes 5 and 6 on axis 1: equation (A)
    vanishes (A loses rank), θ1 is free. The pose is flagged singular; from the configuration
    itself it is among the solutions (θ1 taken from the reference), each reaching the
    target; from another reference any solution keeps that θ1 (when (C) allows it), and ik
    solves the pose."""
    robot = robot_of("z1", "", folder)
    solver = robot.closed_form_ik
    geometry = solver.geometry
    tool = pin.SE3(geometry.tool_rotation, geometry.tool_position)
    h1, p1, p6 = geometry.axes[0], geometry.points[0], geometry.points[5]

    def reach_across(q3: float, q: np.ndarray) -> float:
        """The meeting point of axes 5, 6 along the arm's horizontal direction from axis 1."""
        q = q.copy()
        q[2] = q3
        centre = (robot.fk(q) * tool.inverse()).act(p6) - p1
        return float(centre @ np.array([np.cos(q[0]), np.sin(q[0]), 0.0]))

    rng = np.random.default_rng(73)
    done = 0
    while done < 10:
        q = robot.random_configuration(rng)
        grid = np.linspace(robot.lower[2], robot.upper[2], 40)
        values = [reach_across(x, q) for x in grid]
        change = [i for i in range(39) if values[i] * values[i + 1] < 0]
        if not change:
            continue
        lo, hi = grid[change[0]], grid[change[0] + 1]
        for _ in range(80):  # bisection to rounding
            mid = 0.5 * (lo + hi)
            if (reach_across(mid, q) < 0) == (reach_across(lo, q) < 0):
                lo = mid
            else:
                hi = mid
        q[2] = 0.5 * (lo + hi)
        target = robot.fk(q)
        centre = (target * tool.inverse()).act(p6) - p1
        assert np.linalg.norm(np.cross(centre, h1)) < 1e-12
        raw, singular = solver.all_branches(target.translation[None], target.rotation[None],
                                            q[None])  # fmt: skip
        assert singular[0]
        rows = raw[0][np.isfinite(raw[0, :, 0])]
        assert contains(rows, q, FOUND), (q, rows)
        ref = robot.random_configuration(rng)
        for s in np.vstack([rows, solver.solutions(target.translation, target.rotation)]):
            position, rotation = pose_errors(robot, s, target)
            assert position <= REACH and rotation <= REACH, (s, position, rotation)
        assert robot.ik(target, ref).success
        done += 1


def test_near_singular_targets(folder):
    """Within 1e-10–1e-4 rad of the elbow singularity (links 2, 3 aligned) and of the wrist
    singularity (axis 6 ∥ axes 2–4): every solution within 1e-9 of the target; the generating
    configuration among them when it is at least 1e-6 rad from the singularity, within
    1e-7 + 1e-9/σ rad (σ the smallest singular value of its Jacobian: a target known to 1e-9
    fixes the configuration no better). Closer than 1e-6 rad, two branches are a double root
    of the quartic, resolved to √ε only, and θ6 is nearly free: the solution given for them
    may be the singular one."""
    robot = robot_of("ur5", "miss", folder)
    solver = robot.closed_form_ik
    geometry = solver.geometry
    r23, r34 = geometry.r23, geometry.r34
    straight = np.arctan2(r23[1], r23[0]) - np.arctan2(r34[1], r34[0])  # ψ of aligned links
    rng = np.random.default_rng(79)
    for k in range(120):
        q = robot.random_configuration(rng)
        offset = 10.0 ** rng.uniform(-10, -4) * rng.choice([-1.0, 1.0])
        if k % 2:
            q[2] = geometry.signs[0] * (straight + offset)
        else:
            q[4] = offset
        target = robot.fk(q)
        solutions = solver.solutions(target.translation, target.rotation)
        assert len(solutions) >= 1
        if abs(offset) >= 1e-6:
            tolerance = FOUND + REACH / smallest_sigma(robot, q)
            assert contains(solutions, q, tolerance), (q, solutions, tolerance)
        for s in solutions:
            position, rotation = pose_errors(robot, s, target)
            assert position <= REACH and rotation <= REACH, (s, position, rotation)


# ---------------------------------------------------------------------------- the quartic
def test_quartic_roots_against_numpy():
    """Random quartics (random coefficients; four real roots; an exact double root with two
    real roots or a complex pair beside it, which rounding the coefficients turns into two
    close roots or a complex pair): every real root numpy finds (|imaginary part| < 1e-9) is
    among the candidates within 1e-9 (relative; 1e-6 beside a double root, where numpy's are
    no better), each group's first candidate is a distinct root, and the double root is a
    group's first candidate within 1e-6 (a neighbouring root may make it nearly triple)."""
    rng = np.random.default_rng(83)
    out = np.empty(MOST)
    group = np.empty(MOST, dtype=np.int64)
    for trial in range(4000):
        kind = trial % 4
        r = rng.normal(size=4)
        if kind == 0:
            c = rng.normal(size=5)
        elif kind == 1:
            c = np.poly(r)[::-1] * rng.uniform(0.1, 10.0)
        elif kind == 2:
            c = np.poly([r[0], r[0], r[1], r[2]])[::-1]
        else:
            c = np.polymul(np.poly([r[0], r[0]]), [1.0, -2.0 * r[1], r[1] ** 2 + r[2] ** 2 + 0.1])
            c = c[::-1]
        n = real_roots(c, float(np.abs(c).max()), out, group)
        assert np.all(np.diff(group[:n]) >= 0)
        first = out[:n][np.r_[True, np.diff(group[:n]) > 0][:n]]
        assert np.all(np.diff(first) > 0)  # distinct, ascending
        expected = np.roots(c[::-1])
        expected = expected[np.abs(expected.imag) < 1e-9].real
        # (with a double root, its neighbours are as ill-conditioned as numpy's roots: 1e-6)
        tolerance = 1e-9 if kind < 2 else 1e-6
        for x in expected:
            assert np.min(np.abs(out[:n] - x)) < tolerance * (1.0 + abs(x)), (c, x, out[:n])
        if kind >= 2:
            assert np.min(np.abs(first - r[0])) < 1e-6 * (1.0 + abs(r[0])), (c, r[0], first)
        else:
            assert len(first) == len(expected)


def test_pure_python_kernel_gives_the_same_solutions(folder, tmp_path):
    """``KINPLAN_JIT=0``: the same functions as plain Python give the compiled kernel's rows."""
    robot = robot_of("synthetic", 1, folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(89)
    qs = np.array([robot.random_configuration(rng) for _ in range(5)])
    poses = [robot.fk(q) for q in qs]
    positions = np.array([p.translation for p in poses])
    rotations = np.array([p.rotation for p in poses])
    compiled, _ = solver.all_branches(positions, rotations, qs)
    data = tmp_path / "poses.npz"
    np.savez(data, k=solver._constants, tool=solver._tool, positions=positions,
             rotations=rotations, fills=qs)  # fmt: skip
    script = (
        "import sys, numpy as np\n"
        "from kinplan.ik import three_parallel_kernel as kernel\n"
        "assert not kernel.available()\n"
        f"d = np.load({str(data)!r})\n"
        "raw = np.empty((5, kernel.SLOTS, 6)); singular = np.empty(5, dtype=bool)\n"
        "kernel.raw_many(d['k'], d['tool'], d['positions'], d['rotations'], d['fills'], raw,"
        " singular)\n"
        f"np.save({str(tmp_path / 'raw.npy')!r}, raw)\n"
    )
    env = {**os.environ, "KINPLAN_JIT": "0"}
    subprocess.run([sys.executable, "-c", script], env=env, check=True, timeout=120)
    plain = np.load(tmp_path / "raw.npy")
    np.testing.assert_allclose(plain, compiled, rtol=0, atol=1e-12)


def test_horner_matches_numpy_on_seeded_polynomials():
    """kinplan.compiled.horner, the polynomial evaluator both quartic solvers use: P(t) and
    P'(t) against numpy's polyval of the coefficients and of their derivative (1e-12
    relative), over 2,000 seeded polynomials of degree 0–4."""
    from kinplan.compiled import horner

    rng = np.random.default_rng(7)
    for _ in range(2000):
        degree = int(rng.integers(0, 5))
        c = rng.normal(size=degree + 1)
        t = float(rng.uniform(-3.0, 3.0))
        p, dp = horner(c, degree, t)
        power = np.polynomial.polynomial
        scale = np.abs(c) @ np.abs(t) ** np.arange(degree + 1) + 1.0
        assert abs(p - power.polyval(t, c)) <= 1e-12 * scale
        assert abs(dp - power.polyval(t, power.polyder(c))) <= 1e-12 * (4.0 * scale)
