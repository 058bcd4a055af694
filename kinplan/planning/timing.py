"""Timing a certified joint path and certifying the timed motion.

The waypoints are timed by :func:`kinplan.trajectory.time_optimal` (time-optimal along straight
lines with circular blends at the corners, each within ``blend`` rad of its corner; rest to rest,
within the joint velocity and acceleration limits). The blends leave the certified polyline, so
the timed motion's path — the :class:`kinplan.trajectory.totg.JointPath` of the same waypoints and
blend, which the trajectory follows to 1e-12 rad — is checked again with
:meth:`kinplan.WorkCell.check_motion` on points along it: at most :data:`LINE_STEP` rad apart,
and on the blends close enough that the chord between two points leaves the arc by at most
``sagitta`` rad (κh²/8 for a chord of length h on an arc of curvature κ). The check's clearance
is raised by the largest distance a body point can move for that joint deviation (the
lever-arm bound of :mod:`kinplan.cell.motion`, :func:`lever_bound`), so the robot–obstacle pairs
keep the clearance on the arcs themselves; self pairs (contact only) are then certified to
``lever · sagitta`` (:data:`SELF_TOLERANCE`, 50 µm). When the blended motion fails, the blend is
halved, and at last dropped (``blend = 0``: the motion stops at each corner and its path is the
certified polyline itself).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from kinplan import trajectory
from kinplan.cell import MotionCheck, WorkCell
from kinplan.cell.body import bounding_radius
from kinplan.cell.motion import joint_levers
from kinplan.cell.robot_geometry import robot_geometry
from kinplan.model.arm import Arm
from kinplan.trajectory import Trajectory
from kinplan.trajectory.totg import JointPath

__all__ = [
    "DEFAULT_BLEND",
    "LINE_STEP",
    "SELF_TOLERANCE",
    "TimedMotion",
    "check_path",
    "lever_bound",
    "timed_motion",
]

DEFAULT_BLEND = 0.05
"""Largest deviation of the timed path from a corner of the waypoints [rad]."""

LINE_STEP = 0.15
"""Largest distance between the points the timed path is checked at [rad]."""

SELF_TOLERANCE = 5e-5
"""Largest contact depth between two robot bodies that may go unseen on a blend [m]."""

_BLEND_TRIES = 3
"""Blends tried (halving) before the motion stops at its corners."""


@dataclass(frozen=True)
class TimedMotion:
    """A timed motion and the check that certified its path.

    Attributes:
        trajectory: The timed motion.
        blend: Its largest deviation from a corner [rad].
        check: The check of its path (``ok``; ``min_obstacle_clearance`` and
            ``min_self_clearance`` at the checked points).
        attempts: Blends tried.
    """

    trajectory: Trajectory
    blend: float
    check: MotionCheck
    attempts: int


def lever_bound(robot: Arm) -> float:
    """Largest distance a point of a robot body can move per rad of joint motion (Euclidean
    norm over the joints) [m/rad]: the norm of its lever arms (:func:`joint_levers`), twice
    the largest over the bodies so that it bounds the relative motion of any pair (computed
    once per robot)."""
    found = _LEVERS.get(robot)
    if found is None:
        found = _LEVERS[robot] = _lever_bound(robot)
    return found


_LEVERS: weakref.WeakKeyDictionary[Arm, float] = weakref.WeakKeyDictionary()


def _lever_bound(robot: Arm) -> float:
    geometry = robot_geometry(robot)
    if not geometry.objects:
        return 0.0
    radii = [bounding_radius(obj.geometry, obj.placement) for obj in geometry.objects]
    levers, carried, coordinate = joint_levers(
        robot.model, robot.lower, robot.upper, geometry.objects, radii
    )
    per_body = (levers * carried) @ coordinate  # (bodies, nq) [m/rad]
    return 2.0 * float(np.max(np.linalg.norm(per_body, axis=1)))


def check_path(
    cell: WorkCell, points: np.ndarray, blend: float, clearance: float, lever: float
) -> MotionCheck:
    """Check the path through ``points`` with corners blended within ``blend`` [rad].

    Args:
        cell: The work cell.
        points: The waypoints (K, nq) [rad].
        blend: Largest deviation from a corner [rad] (0: the polyline).
        clearance: Margin from the obstacles [m].
        lever: :func:`lever_bound` of the robot [m/rad].
    """
    path = JointPath(points, blend)
    if path.piece_count == 0:
        return cell.check_motion(path.points[:1], clearance)
    corners = path.corner_parameters[1:-1]
    curvature = np.linalg.norm(path.evaluate(corners, order=2), axis=1) if corners.size else []
    kappa = float(np.max(curvature)) if len(curvature) else 0.0
    sagitta = SELF_TOLERANCE / lever if lever > 0 else 0.0
    coarse = np.linspace(0.0, path.length, max(2, int(np.ceil(path.length / LINE_STEP)) + 1))
    if kappa <= 0.0 or sagitta <= 0.0:
        s = coarse
        pad = 0.0
    else:
        fine = np.sqrt(8.0 * sagitta / kappa)  # chord length whose sagitta is `sagitta`
        bent = np.linalg.norm(path.evaluate(coarse, order=2), axis=1) > 0.0
        middle = 0.5 * (coarse[1:] + coarse[:-1])
        bent_middle = np.linalg.norm(path.evaluate(middle, order=2), axis=1) > 0.0
        holds_corner = np.zeros(len(middle), dtype=bool)
        holds_corner[np.clip(np.searchsorted(coarse, corners) - 1, 0, len(middle) - 1)] = True
        refine = bent[1:] | bent[:-1] | bent_middle | holds_corner
        parts = [coarse[:1]]
        for k in range(len(middle)):
            a, b = coarse[k], coarse[k + 1]
            count = int(np.ceil((b - a) / fine)) if refine[k] else 1
            parts.append(np.linspace(a, b, count + 1)[1:])
        s = np.concatenate(parts)
        pad = 0.5 * lever * sagitta  # one body's bound (lever is twice it)
    q = path.evaluate(s)
    q[0], q[-1] = path.points[0], path.points[-1]
    return cell.check_motion(q, clearance + pad)


def timed_motion(
    cell: WorkCell,
    points: np.ndarray,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    clearance: float,
    blend: float = DEFAULT_BLEND,
) -> TimedMotion:
    """Time the certified polyline ``points`` and certify the timed motion (see the module).

    Args:
        cell: The work cell.
        points: Waypoints (K, nq) [rad], consecutive ones joined by certified segments.
        max_velocity: Joint velocity limits (nq,) [rad/s].
        max_acceleration: Joint acceleration limits (nq,) [rad/s²].
        clearance: Margin from the obstacles [m].
        blend: Largest deviation from a corner to try first [rad].

    Returns:
        The timed motion whose path passed the check (the polyline, stopping at the corners,
        when every blend failed).
    """
    lever = lever_bound(cell.robot)
    attempts = 0
    tries = [blend / 2**k for k in range(_BLEND_TRIES)] if blend > 0 and len(points) > 2 else []
    for value in [*tries, 0.0]:
        attempts += 1
        check = check_path(cell, points, value, clearance, lever)
        if check.ok or value == 0.0:
            traj = trajectory.time_optimal(points, max_velocity, max_acceleration, value)
            return TimedMotion(traj, value, check, attempts)
    raise AssertionError("unreachable: the last try has no blend")
