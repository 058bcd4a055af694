"""How far an arm reaches: its planar link lengths, its prismatic joints, an upper bound of its
reach and the reach itself, searched within the joint limits.

:class:`kinplan.Robot` computes these once (``link_lengths``, ``prismatic``, :meth:`Robot.reach`);
they need only what the lower layers know of an arm (:class:`kinplan.model.arm.Arm`).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from kinplan.ik import IKSolver
from kinplan.model.arm import Arm


def planar_link_lengths(model: pin.Model, tip_id: int) -> list[float] | None:
    """Link lengths [m] if the arm is planar (revolute about parallel z axes, links in the
    xy-plane of the first joint), else None."""
    if any(model.joints[j].shortname() != "JointModelRZ" for j in range(1, model.njoints)):
        return None
    offsets = [model.jointPlacements[j] for j in range(2, model.njoints)]
    offsets.append(model.frames[tip_id].placement)
    lengths = []
    for placement in offsets:
        if not np.allclose(placement.rotation, np.eye(3), atol=1e-12):
            return None
        if abs(placement.translation[2]) > 1e-12:
            return None
        lengths.append(float(np.linalg.norm(placement.translation)))
    return lengths


def prismatic_joints(model: pin.Model) -> np.ndarray:
    """Which joint coordinates are prismatic (in m, the others in rad), shape (nq,) bool."""
    prismatic = np.zeros(model.nq, dtype=bool)
    for joint in model.joints[1:]:
        if joint.nq == 1 and joint.shortname().startswith("JointModelP"):  # PX/PY/PZ/Unaligned
            prismatic[joint.idx_q] = True
    return prismatic


def chain_length(arm: Arm) -> float:
    """Sum of the distances between consecutive joint origins and the tool offset, plus
    the largest extension of every prismatic joint [m]: an upper bound of the reach."""
    model = arm.model
    offsets = [model.jointPlacements[j] for j in range(2, model.njoints)]
    total = sum(float(np.linalg.norm(p.translation)) for p in offsets)
    total += float(np.linalg.norm(model.frames[arm.tip_id].placement.translation))
    extension = np.maximum(np.abs(arm.lower), np.abs(arm.upper))[prismatic_joints(model)]
    return total + float(extension.sum())


def search_reach(arm: Arm) -> float:
    """The largest distance [m] of the tool from the first joint's origin within the joint
    limits, searched (see :meth:`kinplan.Robot.reach`): from the best of 128 configurations (the
    tool driven toward far points in directions spread over the sphere), the tool is pushed
    outward along its own direction, a step δ at a time (the limits respected; δ halved whenever
    the step cannot be taken), until δ < 1e-7 m."""
    origin = np.array(arm.model.jointPlacements[1].translation)
    solver = IKSolver(arm.model, arm.tip_id, arm.lower, arm.upper)
    # a distance no configuration exceeds: the chain's offsets laid end to end
    far = 10.0 * (chain_length(arm) + 1.0)

    def tool_of(q: np.ndarray) -> np.ndarray:
        return np.asarray(arm.fk(q).translation)

    def distance_of(q: np.ndarray) -> float:
        return float(np.linalg.norm(tool_of(q) - origin))

    count = 128
    k = np.arange(count) + 0.5
    polar, azimuth = np.arccos(1 - 2 * k / count), np.pi * (1 + 5**0.5) * k
    directions = np.stack(
        [np.sin(polar) * np.cos(azimuth), np.sin(polar) * np.sin(azimuth), np.cos(polar)], 1
    )
    start = arm.neutral()
    candidates = []
    for u in directions:
        q, *_ = solver.descend(start, origin + far * u, None, 1e-12, 1.0, 30)
        candidates.append((distance_of(q), q))
    candidates.sort(key=lambda pair: -pair[0])
    best = 0.0
    for distance, q in candidates[:4]:  # the best few basins
        step = 0.05
        for _ in range(400):
            if step < 1e-7:
                break
            tool = tool_of(q) - origin
            direction = tool / max(float(np.linalg.norm(tool)), 1e-12)
            target = origin + (distance + step) * direction
            q_next, *_ = solver.descend(q, target, None, 1e-12, 1.0, 20)
            reached = distance_of(q_next)
            if reached > distance + 1e-12:
                q, distance = q_next, reached
                step = min(2.0 * step, 0.05)
            else:
                step *= 0.5
        best = max(best, distance)
    return float(best)
