"""What the closed-form IK tests measure a solution by: its pose errors, whether a list of
solutions holds a configuration, and how near a configuration is to a singularity."""

from __future__ import annotations

import functools

import numpy as np
import pinocchio as pin

import kinplan
from kinplan.ik.screws import wrap_angle


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
