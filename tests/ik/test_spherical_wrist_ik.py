"""Closed-form IK of spherical-wrist 6R arms (kinplan.ik.spherical_wrist), on synthetic arms
written as URDF strings: every solution checked by Pinocchio FK, the compiled kernel against
the numpy path, the branches against a brute-force numerical search, refusals with reasons."""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from ik_checks import check_ik_and_batch, contains, pose_errors
from wrist_arms import wrist_arm_urdf

import kinplan
from kinplan.ik import ClosedFormIK, SphericalWristIK, closed_form_report, wrap_angle
from kinplan.ik.screws import screws_at_zero
from kinplan.ik.spherical_wrist_geometry import wrist_geometry
from kinplan.ik.subproblems import sp1, sp2, sp4
from kinplan.ik.wrist_offset import OffsetWristIK

#: (seed, skewed wrist, lateral offset) of the synthetic arms; seeds ≥ 10 also tilt axes 2 ∥ 3
#: by 0.4 rad out of the plane normal to axis 1.
ARMS = [
    (0, False, False), (1, False, True), (2, True, True), (3, True, False), (4, False, True),
    (10, True, True),
]  # fmt: skip


@functools.cache
def arm(seed: int, skew: bool, lateral: bool, folder: str) -> kinplan.Robot:
    path = Path(folder) / f"wrist_{seed}_{skew}_{lateral}.urdf"
    tilt = 0.4 if seed >= 10 else 0.0
    path.write_text(wrist_arm_urdf(seed, skew_wrist=skew, lateral=lateral, tilt=tilt))
    return kinplan.load_robot(path, tip="tool0")


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> str:
    return str(tmp_path_factory.mktemp("wrist_arms"))


# ---------------------------------------------------------------------------- subproblems
def test_subproblems_against_random_rotations():
    rng = np.random.default_rng(7)
    for _ in range(200):
        k1, k2, h = (v / np.linalg.norm(v) for v in rng.normal(size=(3, 3)))
        p = rng.normal(size=3)
        theta = rng.uniform(-np.pi, np.pi, 2)
        q = pin.exp3(k1 * theta[0]) @ p
        found, free = sp1(k1, p, q)
        assert not free
        np.testing.assert_allclose(wrap_angle(found - theta[0]), 0.0, atol=1e-12)
        # subproblem 2: R(k1, θ1) p = R(k2, θ2) q
        q2 = pin.exp3(k2 * -theta[1]) @ (pin.exp3(k1 * theta[0]) @ p)
        t1, t2, ok, free2 = sp2(k1, k2, p, q2)
        assert ok.all() and not free2
        for a, b in zip(t1, t2):
            np.testing.assert_allclose(pin.exp3(k1 * a) @ p, pin.exp3(k2 * b) @ q2, atol=1e-10)
        assert np.min(np.abs(wrap_angle(t1 - theta[0])) + np.abs(wrap_angle(t2 - theta[1]))) < 1e-8
        # subproblem 4: h·R(k, θ) p = d
        d = h @ pin.exp3(k1 * theta[0]) @ p
        t4, ok4, free4 = sp4(h, k1, p, d)
        assert ok4.all() and not free4
        for a in t4:
            assert abs(h @ pin.exp3(k1 * a) @ p - d) < 1e-10
        assert np.min(np.abs(wrap_angle(t4 - theta[0]))) < 1e-6


def test_subproblem_4_unreachable_and_free():
    h, k = np.array([1.0, 0, 0]), np.array([0, 0, 1.0])
    _, ok, free = sp4(h, k, np.array([1.0, 0, 0]), 2.0)
    assert not ok.any() and not free
    _, ok, free = sp4(h, k, np.array([0, 0, 1.0]), 0.0)  # p on the axis, d fits: free
    assert ok.all() and free


# ---------------------------------------------------------------------------- detection
@pytest.mark.parametrize("seed, skew, lateral", ARMS)
def test_synthetic_arms_get_the_closed_form(folder, seed, skew, lateral):
    robot = arm(seed, skew, lateral, folder)
    assert isinstance(robot.closed_form_ik, SphericalWristIK)
    assert robot.ik_solver.description.startswith("closed form: spherical wrist")


def test_wrist_offset_is_not_a_spherical_wrist_and_gets_the_1d_search(tmp_path):
    """Axis 6 off the meeting of axes 4 and 5: the spherical-wrist form refuses it with its
    reason, and the arm gets the 1-D search (kinplan.ik.wrist_offset) instead."""
    text = wrist_arm_urdf(5).replace('<joint name="j6" type="revolute"><parent link="l5"/>'
                                     '<child link="l6"/><origin xyz="0 0 0"',
                                     '<joint name="j6" type="revolute"><parent link="l5"/>'
                                     '<child link="l6"/><origin xyz="0 0 0.05"')  # fmt: skip
    assert text != wrist_arm_urdf(5)
    path = tmp_path / "offset_wrist.urdf"
    path.write_text(text)
    robot = kinplan.load_robot(path, tip="tool0")
    wrist, reason = wrist_geometry(screws_at_zero(robot))
    assert wrist is None
    assert "axis 6 misses the meeting of axes 4 and 5" in reason, reason
    solver, description = closed_form_report(robot)
    assert isinstance(solver, OffsetWristIK) and not isinstance(solver, SphericalWristIK)
    assert description.startswith("closed form with a 1-D search")
    assert robot.ik_solver.description == description
    target = robot.fk(np.full(6, 0.3))
    result = robot.ik(target, np.zeros(6))
    assert result.success and result.method == "analytic"


def test_known_arms_say_which_solver():
    assert "UR family" in kinplan.load_robot("ur5").ik_solver.description
    assert "panda" in kinplan.load_robot("panda").ik_solver.description


# ---------------------------------------------------------------------------- solutions
@pytest.mark.parametrize("seed, skew, lateral", ARMS)
def test_every_solution_reaches_the_target(folder, seed, skew, lateral):
    robot = arm(seed, skew, lateral, folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(seed)
    counts = []
    for _ in range(150):
        q = robot.random_configuration(rng)
        target = robot.fk(q)
        solutions = solver.solutions(target.translation, target.rotation)
        assert 1 <= len(solutions) <= 8 * 2**6
        assert contains(solutions, q, 1e-7), (q, solutions)
        for s in solutions:
            assert robot.within_limits(s, tolerance=0.0)
            position, rotation = pose_errors(robot, s, target)
            assert position < 1e-9 and rotation < 1e-9, (s, position, rotation)
        counts.append(len(np.unique(np.round(wrap_angle(solutions), 6), axis=0)))
    assert max(counts) >= 4  # several branches are found, not only the generating one


@pytest.mark.parametrize("seed, skew, lateral", ARMS[:3])
def test_compiled_kernel_equals_numpy_path(folder, seed, skew, lateral):
    robot = arm(seed, skew, lateral, folder)
    solver = robot.closed_form_ik
    if not solver._compiled:
        pytest.skip("numba switched off (KINPLAN_JIT=0): only the numpy path runs")
    rng = np.random.default_rng(100 + seed)
    positions, rotations, refs, expected = [], [], [], []
    for _ in range(300):
        target = robot.fk(robot.random_configuration(rng))
        ref = rng.uniform(robot.lower - 1.0, robot.upper + 1.0)
        np.testing.assert_allclose(
            solver.solutions(target.translation, target.rotation),
            ClosedFormIK.solutions(solver, target.translation, target.rotation),
            atol=1e-9,
        )
        compiled = solver.nearest(target.translation, target.rotation, ref)
        numpy_path = ClosedFormIK.nearest(solver, target.translation, target.rotation, ref)
        assert (compiled is None) == (numpy_path is None)
        if compiled is not None:
            np.testing.assert_allclose(compiled, numpy_path, atol=1e-9)
        positions.append(target.translation)
        rotations.append(target.rotation)
        refs.append(ref)
        expected.append(np.full(6, np.nan) if numpy_path is None else numpy_path)
    q, branch, mask, left = solver.nearest_many(np.array(positions), np.array(rotations),
                                                np.array(refs))  # fmt: skip
    assert not left.any()
    np.testing.assert_allclose(q, np.array(expected), atol=1e-9)
    assert np.all((branch >= 0) == (mask > 0))


def test_singular_wrist_and_shoulder(folder):
    robot = arm(0, False, False, folder)  # perpendicular wrist, no lateral offset
    solver = robot.closed_form_ik
    rng = np.random.default_rng(3)
    singular = 0
    for _ in range(50):
        q = robot.random_configuration(rng)
        q[4] = 0.0  # axes 4 and 6 aligned: θ4 + θ6 fixed, θ4 free
        target = robot.fk(q)
        ref = robot.random_configuration(rng)
        found = solver.nearest(target.translation, target.rotation, ref)
        numpy_path = ClosedFormIK.nearest(solver, target.translation, target.rotation, ref)
        for s in (found, numpy_path):
            assert s is not None
            position, rotation = pose_errors(robot, s, target)
            assert position < 1e-9 and rotation < 1e-8
        # on a singular branch (θ5 = 0 or π: axes 4 and 6 aligned), θ4 keeps the reference's
        # value, or θ6 is at a limit (the nearest θ4 it allows)
        if abs(np.sin(found[4])) < 1e-12:
            singular += 1
            kept = abs(found[3] - np.clip(ref[3], robot.lower[3], robot.upper[3])) < 1e-9
            at_limit = min(abs(found[5] - robot.lower[5]), abs(found[5] - robot.upper[5])) < 1e-9
            assert kept or at_limit, (found, ref)
        result = robot.ik(target, ref)
        assert result.success
        # from the singular configuration itself, the singular branch is the nearest
        again = solver.nearest(target.translation, target.rotation, q)
        np.testing.assert_allclose(again, q, atol=1e-9)
    assert singular > 5
    # wrist centre on axis 1 (θ1 free): built by solving for a configuration
    centre = solver.geometry.centre
    h1, p1 = solver.geometry.axes[0], solver.geometry.points[0]
    on_axis = p1 + ((centre - p1) @ h1 + 0.3) * h1
    seen = ClosedFormIK.nearest(solver, on_axis, np.eye(3), np.zeros(6))
    if seen is not None:
        position, _ = pose_errors(robot, seen, pin.SE3(np.eye(3), on_axis))
        assert position < 1e-6


@pytest.mark.parametrize("seed, skew, lateral", ARMS[:2])
def test_brute_force_numerical_branches_are_all_found(folder, seed, skew, lateral):
    """Every branch a numerical search from 200 seeds finds is among the closed form's."""
    robot = arm(seed, skew, lateral, folder)
    solver = robot.closed_form_ik
    numeric = robot.ik_solver
    rng = np.random.default_rng(50 + seed)
    for _ in range(3):
        target = robot.fk(robot.random_configuration(rng))
        closed = solver.solutions(target.translation, target.rotation)
        found = []
        for _ in range(200):
            seed_q = robot.random_configuration(rng)
            result = numeric.solve(target.translation, target.rotation, seed_q,
                                   1e-10, 1e-10, 100, 0)  # fmt: skip
            if result.success and not contains(found, result.q, 1e-6):
                found.append(result.q)
        assert found
        for q in found:
            assert contains(closed, q, 1e-6), (q, closed)


@pytest.mark.parametrize("seed, skew, lateral", ARMS)
def test_robot_ik_and_batch_on_random_targets(folder, seed, skew, lateral):
    robot = arm(seed, skew, lateral, folder)
    rng = np.random.default_rng(200 + seed)
    count = 500
    check_ik_and_batch(robot, rng, count)


@pytest.mark.parametrize("seed, skew, lateral", ARMS[:3])
def test_near_singular_targets(folder, seed, skew, lateral):
    """Within 1e-9–1e-5 rad of the wrist singularity: every closed-form solution within 1e-7 of
    the target (√ε rounding where the cones of subproblem 2 touch), ik within 1e-6."""
    robot = arm(seed, skew, lateral, folder)
    solver = robot.closed_form_ik
    rng = np.random.default_rng(300 + seed)
    h = solver.geometry.axes
    for _ in range(40):
        q = robot.random_configuration(rng)
        offset = 10.0 ** rng.uniform(-9, -5) * rng.choice([-1.0, 1.0])
        # θ5 at which R5 h6 ∥ h4 (the wrist singularity), nudged by ``offset``
        found, _ = sp1(h[4], h[5], h[3])
        q[4] = float(np.clip(found + offset, robot.lower[4], robot.upper[4]))
        target = robot.fk(q)
        for s in solver.solutions(target.translation, target.rotation):
            position, rotation = pose_errors(robot, s, target)
            assert position < 1e-7 and rotation < 1e-7, (s, position, rotation)
        result = robot.ik(target, robot.random_configuration(rng))
        assert result.success
        assert result.position_error <= 1e-6 and result.rotation_error <= 1e-6
