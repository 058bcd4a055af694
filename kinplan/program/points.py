"""The configurations of a program: ``start:`` and the taught ``points:``.

Joint values are checked against the robot's limits; a Cartesian point is checked to be within
reach (by IK seeded from the start), so an unreachable point is reported with the file's other
problems rather than when a move gets there.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pinocchio as pin

from cartesian.events import out_of_reach
from kinplan.model.robot import Robot
from kinplan.program.checker import Checker, describe, format_path
from kinplan.program.process import read_signals
from kinplan.program.schema import NAME_PATTERN, POINT_KEYS, KeyPath, Point

__all__ = ["read_joints", "read_points", "read_start"]


def read_joints(
    checker: Checker, robot: Robot | None, spec: Mapping, path: KeyPath
) -> np.ndarray | None:
    """Joint values [rad] from ``joints`` [rad] or ``joints_deg`` [deg], within the limits.

    Args:
        checker: Collects the problems.
        robot: The program's robot, or None when it could not be loaded (the values are then
            read but not checked against it).
        spec: A mapping with ``joints`` or ``joints_deg``.
        path: Its key path.

    Returns:
        The joint values [rad], or None after reporting a problem.
    """
    nq = robot.nq if robot else None
    names = f" of {robot.name}: {', '.join(robot.joint_names)}" if robot else ""
    in_degrees = "joints_deg" in spec
    key = "joints_deg" if in_degrees else "joints"
    unit = "deg" if in_degrees else "rad"
    values = checker.numbers(spec[key], path + (key,), nq, f"joint values [{unit}]{names}")
    if values is None:
        return None
    q = np.radians(values) if in_degrees else values
    if robot is not None:
        scale = np.degrees if in_degrees else (lambda x: x)
        beyond = np.flatnonzero((q < robot.lower - 1e-9) | (q > robot.upper + 1e-9))
        for j in beyond:
            checker.error(
                path + (key,),
                f"joint {j} ({robot.joint_names[j]}) = {values[j]:g} {unit} is beyond its "
                f"limits [{scale(robot.lower[j]):.6g}, {scale(robot.upper[j]):.6g}] {unit}",
            )
        if beyond.size:
            return None  # reported; not used as an IK seed either
    return q


def read_start(checker: Checker, robot: Robot | None, data: dict) -> np.ndarray | None:
    """The ``start:`` configuration [rad] of a program's top-level mapping ``data``, or None
    after reporting a problem."""
    spec = data.get("start")
    if spec is None:
        checker.error(("start",), "missing; expected {joints: [...]} [rad] or {joints_deg: [...]}")
        return None
    if not isinstance(spec, dict) or len([k for k in ("joints", "joints_deg") if k in spec]) != 1:
        checker.error(
            ("start",),
            "expected {joints: [...]} [rad] or {joints_deg: [...]} (the start is a joint "
            f"configuration), got {describe(spec)}",
        )
        return None
    for key in spec:
        if key not in ("joints", "joints_deg"):
            checker.error(
                ("start", str(key)), f"unknown key {key!r}; expected joints or joints_deg"
            )
    return read_joints(checker, robot, spec, ("start",))


def read_points(
    checker: Checker, robot: Robot | None, spec: object, start: np.ndarray | None
) -> dict[str, Point]:
    """The taught points of a program.

    Args:
        checker: Collects the problems.
        robot: The program's robot, or None when it could not be loaded.
        spec: The ``points:`` entry (None when absent).
        start: The start configuration [rad] (the seed of the reachability checks), or None.

    Returns:
        Every point by name, in file order, with its signals (``arc:``, ``io:``, ``weld:``;
        :mod:`kinplan.program.process`); an invalid point is an empty :class:`Point` (so the
        moves naming it are not reported again).
    """
    if spec is None:
        return {}
    if not isinstance(spec, dict):
        checker.error(("points",), f"expected a mapping of point names, got {describe(spec)}")
        return {}
    points = {}
    for name, value in spec.items():
        point = _read_point(checker, robot, str(name), value, ("points", str(name)), start)
        if point is None:
            point = Point(str(name))  # known name, so moves don't re-report it
        signals = (
            read_signals(checker, value, ("points", str(name))) if isinstance(value, dict) else None
        )
        if signals is not None:
            point.arc, point.io, point.job = signals
        points[str(name)] = point
    return points


def _read_point(
    checker: Checker,
    robot: Robot | None,
    name: str,
    spec: object,
    path: KeyPath,
    start: np.ndarray | None,
) -> Point | None:
    expected = "joints, joints_deg, or xyz (+ rpy_deg or quat_xyzw), and arc, io or weld"
    if not isinstance(spec, dict):
        checker.error(path, f"expected a mapping with {expected}, got {describe(spec)}")
        return None
    if not NAME_PATTERN.match(name):
        checker.error(
            path, f"point name {name!r} must start with a letter or _ (letters, digits, _ . -)"
        )
    for key in spec:
        if key not in POINT_KEYS:
            checker.error(path + (str(key),), f"unknown key {key!r}; expected {expected}")
    kinds = [key for key in ("joints", "joints_deg", "xyz") if key in spec]
    if len(kinds) != 1:
        found = f"got {', '.join(kinds)}" if kinds else "got none of them"
        checker.error(path, f"give exactly one of joints, joints_deg or xyz; {found}")
        return None
    if kinds[0] != "xyz":
        for key in ("rpy_deg", "quat_xyzw"):
            if key in spec:
                checker.error(path + (key,), f"{key} only goes with xyz (joints fix the pose)")
        q = read_joints(checker, robot, spec, path)
        return Point(name, joints=q, key=format_path(path)) if q is not None else None
    return _read_cartesian_point(checker, robot, name, spec, path, start)


def _read_cartesian_point(
    checker: Checker,
    robot: Robot | None,
    name: str,
    spec: dict,
    path: KeyPath,
    start: np.ndarray | None,
) -> Point | None:
    pose = checker.cartesian_pose(spec, path)
    if pose is None:
        return None
    position, rotation = pose
    if robot is not None and rotation is not None and robot.default_position_only():
        checker.warn(
            path,
            f"{robot.name} has {robot.nq} joints and is planned position-only; the "
            "orientation is ignored",
        )
        rotation = None
    if robot is not None:
        _check_reachable(checker, robot, position, rotation, path, start)
    return Point(name, position=position, rotation=rotation, key=format_path(path))


def _check_reachable(
    checker: Checker,
    robot: Robot,
    position: np.ndarray,
    rotation: np.ndarray | None,
    path: KeyPath,
    start: np.ndarray | None,
) -> None:
    """Report a tool position [m] (with a rotation, or None) that no configuration within the
    joint limits reaches."""
    target = position if rotation is None else pin.SE3(rotation, position)
    result = robot.ik(target, q_seed=start, position_only=rotation is None)
    if result.success:
        return
    where = ", ".join(f"{x:.4g}" for x in position)
    why = out_of_reach(robot, result, position)
    fix = "move the point" + ("" if rotation is None else " or change its orientation")
    checker.error(path, f"({where}) m is out of reach of {robot.name}: {why}; {fix}")
