"""What the closed-form IK tests measure a solution by: its pose errors, whether a list of
solutions holds a configuration, how near a configuration is to a singularity; and the two
checks every closed-form family runs (the nearest-solution rule, ``ik`` against ``ik_batch``)."""

from __future__ import annotations

import functools

import numpy as np
import pinocchio as pin

import kinplan
from kinplan.ik import ClosedFormIK
from kinplan.ik.screws import wrap_angle, wrap_near


def pose_errors(robot: kinplan.Robot, q: np.ndarray, target: pin.SE3) -> tuple[float, float]:
    """Tool position [m] and rotation [rad] errors of ``q`` at ``target`` (Pinocchio's FK)."""
    reached = robot.fk(q)
    position = float(np.linalg.norm(reached.translation - target.translation))
    rotation = float(np.linalg.norm(pin.log3(reached.rotation.T @ target.rotation)))
    return position, rotation


def contains(solutions: np.ndarray, q: np.ndarray, tol: float) -> bool:
    """Whether a row of ``solutions`` equals ``q`` within ``tol`` [rad] per joint (mod 2π)."""
    return any(np.max(np.abs(wrap_angle(s - q))) < tol for s in solutions)


def smallest_sigma(robot: kinplan.Robot, q: np.ndarray) -> float:
    """The smallest singular value of the tool Jacobian at ``q``."""
    return float(np.linalg.svd(robot.jacobian(q), compute_uv=False)[-1])


@functools.cache
def typical_sigma(robot: kinplan.Robot, samples: int = 200) -> float:
    """The median smallest singular value of the tool Jacobian over ``samples`` random
    configurations (seeded)."""
    rng = np.random.default_rng(3)
    return float(np.median([smallest_sigma(robot, robot.random_configuration(rng))
                            for _ in range(samples)]))  # fmt: skip


def check_nearest_rule(
    robot: kinplan.Robot,
    solver: ClosedFormIK,
    target: pin.SE3,
    ref: np.ndarray,
    atol: float = 1e-12,
) -> np.ndarray:
    """``solver.nearest`` of ``target`` from ``ref``: equal to the base class's choice over the
    same solutions (per joint the equivalent within the limits nearest the reference, then the
    least Σ wᵢ Δqᵢ², ties to the lower row) to ``atol`` [rad], which is the least weighted
    distance over the solutions (to 1e-9); returned."""
    found = solver.nearest(target.translation, target.rotation, ref)
    base = ClosedFormIK.nearest(solver, target.translation, target.rotation, ref)
    assert found is not None and base is not None
    np.testing.assert_allclose(found, base, rtol=0, atol=atol)
    solutions = solver.solutions(target.translation, target.rotation)
    near = wrap_near(solutions, ref, robot.lower, robot.upper)
    distance = np.nan_to_num(((near - ref) ** 2) @ solver.weights, nan=np.inf)
    assert abs(((found - ref) ** 2) @ solver.weights - distance.min()) < 1e-9
    return found


def random_targets(
    robot: kinplan.Robot, rng: np.random.Generator, count: int
) -> tuple[np.ndarray, np.ndarray]:
    """``count`` random reachable targets (N, 4, 4) (FK of random configurations within the
    limits) and as many random seeds (N, nq), drawn from ``rng`` in that order."""
    qs = np.array([robot.random_configuration(rng) for _ in range(count)])
    targets = np.array([robot.fk(q).homogeneous for q in qs])
    seeds = np.array([robot.random_configuration(rng) for _ in range(count)])
    return targets, seeds


def check_ik_and_batch(
    robot: kinplan.Robot, rng: np.random.Generator, count: int, threads: int | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``count`` random reachable targets from random seeds: ``Robot.ik`` solves each by the
    closed form (within 1e-6 m and 1e-6 rad, within the limits) and ``Robot.ik_batch`` (on
    ``threads``) by its closed-form method, with the same answers to 1e-9 rad. Returns the
    targets (N, 4, 4), the seeds and the batch's answers."""
    targets, seeds = random_targets(robot, rng, count)
    loop = []
    for target, seed_q in zip(targets, seeds):
        result = robot.ik(pin.SE3(target), seed_q)
        assert result.success and result.method == "analytic"
        assert result.position_error <= 1e-6 and result.rotation_error <= 1e-6
        assert robot.within_limits(result.q, tolerance=0.0)
        loop.append(result.q)
    assert robot.batch_solver.method(False) == "closed-form"
    q, success = robot.ik_batch(targets, seeds, threads=threads)
    assert success.all()
    np.testing.assert_allclose(q, np.array(loop), atol=1e-9)
    return targets, seeds, q


def check_missed_targets_solved_numerically(
    robot: kinplan.Robot, targets: np.ndarray, seeds: np.ndarray, missed: list[int], monkeypatch
) -> None:
    """With the closed form made to find nothing for ``targets[missed]`` (its ``nearest`` and
    ``nearest_many`` patched; ``nearest_many``'s second output is the found flag or branch row,
    its last the poses left to ``nearest``): ``ik_batch`` solves every target, those by the
    numerical solve as ``ik`` does, with ``ik``'s q (the compiled solve in both: to 1e-9)."""
    solver = robot.closed_form_ik
    nearest, nearest_many = solver.nearest, solver.nearest_many
    missing = [targets[k, :3, 3] for k in missed]

    def missing_nearest(position, rotation, q_ref, *args, **kwargs):
        if any(np.array_equal(position, p) for p in missing):
            return None
        return nearest(position, rotation, q_ref, *args, **kwargs)

    def missing_many(positions, rotations, q_ref, *args, **kwargs):
        out = list(nearest_many(positions, rotations, q_ref, *args, **kwargs))
        for p in missing:
            hit = np.flatnonzero((positions == p).all(axis=1))
            out[1][hit] = -1 if out[1].dtype.kind == "i" else False  # none found
            out[-1][hit] = False  # not left to nearest()
            if len(out) == 4:
                out[2][hit] = 0  # no branch within the limits
        return tuple(out)

    monkeypatch.setattr(solver, "nearest", missing_nearest)
    monkeypatch.setattr(solver, "nearest_many", missing_many)
    q, success = robot.ik_batch(targets, q_seed=seeds)
    assert success.all()
    for k in range(len(targets)):
        result = robot.ik(pin.SE3(targets[k]), seeds[k])
        assert result.success and result.method == ("numerical" if k in missed else "analytic")
        np.testing.assert_allclose(q[k], result.q, rtol=0, atol=1e-9, err_msg=str(k))


def numerical_branches(robot: kinplan.Robot, target: pin.SE3, seeds: list[np.ndarray]) -> list:
    """The distinct solutions (mod 2π, 1e-6 rad apart) the numerical solver converges to, to
    1e-10 m and rad, from each of ``seeds`` (a brute-force search for every branch)."""
    found: list[np.ndarray] = []
    for seed in seeds:
        result = robot.ik_solver.solve(target.translation, target.rotation, seed,
                                       1e-10, 1e-10, 100, 0)  # fmt: skip
        if result.success and not contains(found, result.q, 1e-6):
            found.append(result.q)
    return found
