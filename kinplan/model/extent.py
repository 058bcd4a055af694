"""How far an arm reaches: its planar link lengths, its prismatic joints, an upper bound of its
reach and the reach itself, searched within the joint limits.

:class:`kinplan.Robot` computes these once (``link_lengths``, ``prismatic``, :meth:`Robot.reach`);
they need only what the lower layers know of an arm (:class:`kinplan.model.arm.Arm`).
"""

from __future__ import annotations

import hashlib
import logging
import os
import tempfile
from pathlib import Path

import numpy as np
import pinocchio as pin

from kinplan.ik import IKSolver
from kinplan.model.arm import Arm

logger = logging.getLogger(__name__)

#: Version of :func:`search_reach`'s algorithm, part of the key of its stored results: a change
#: of the search must change it, so that no result of the old search is read back.
REACH_SEARCH_VERSION = 1


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


def cache_dir() -> Path:
    """Where kinplan keeps results worth computing once per machine: ``$KINPLAN_CACHE_DIR``,
    else ``$XDG_CACHE_HOME/kinplan``, else ``~/.cache/kinplan``."""
    if os.environ.get("KINPLAN_CACHE_DIR"):
        return Path(os.environ["KINPLAN_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "kinplan"


def reach_key(arm: Arm) -> str:
    """A fingerprint of everything :func:`search_reach` depends on: the search's version, the
    joint types, placements and limits, the tool frame's placement and joint, and the tool
    pose at three fixed configurations (which pin down the joint axes)."""
    model = arm.model
    digest = hashlib.sha256(f"reach v{REACH_SEARCH_VERSION} nq {model.nq}".encode())
    for j in range(1, model.njoints):
        digest.update(model.joints[j].shortname().encode())
        digest.update(np.ascontiguousarray(model.jointPlacements[j].homogeneous).tobytes())
    frame = model.frames[arm.tip_id]
    digest.update(np.ascontiguousarray(frame.placement.homogeneous).tobytes())
    digest.update(str(int(frame.parentJoint)).encode())
    digest.update(np.ascontiguousarray(arm.lower, dtype=float).tobytes())
    digest.update(np.ascontiguousarray(arm.upper, dtype=float).tobytes())
    neutral = arm.neutral()
    for scale in (0.3, -0.7, 1.1):
        q = np.clip(neutral + scale * np.linspace(0.5, 1.5, arm.nq), arm.lower, arm.upper)
        digest.update(np.ascontiguousarray(arm.fk(q).homogeneous).tobytes())
    return digest.hexdigest()


def stored_reach(arm: Arm) -> float:
    """:func:`search_reach`, computed once per machine: the result is kept in
    :func:`cache_dir` under :func:`reach_key` (a file per arm, written atomically) and read
    back by later processes, bit for bit. A missing, unreadable or unwritable cache only means
    the search runs (it takes ~50 ms for a 6-joint arm, most of ``kinplan info``'s own time)."""
    try:
        path = cache_dir() / "reach" / f"{reach_key(arm)}.txt"
    except (RuntimeError, ValueError) as exc:  # no home folder, or an arm with no fingerprint
        logger.debug("reach not cached: %s", exc)
        return search_reach(arm)
    try:
        value = float(path.read_text())
        if np.isfinite(value) and value >= 0.0:
            return value
    except (OSError, ValueError):
        pass
    value = search_reach(arm)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile("w", dir=path.parent, delete=False) as handle:
            handle.write(repr(value))
        os.replace(handle.name, path)
    except OSError as exc:
        logger.debug("reach not cached in %s: %s", path.parent, exc)
    return value
