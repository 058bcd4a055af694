"""The work-cell keys of a program: ``tool:``, ``obstacles:`` and ``clearance:``.

``tool: {xyz: [..], rpy_deg: [..], body: BODY}`` puts a tool on the flange (the robot's tip):
the TCP pose and the body's pose are given in the flange frame, and the program's robot becomes
``robot.with_tool(...)`` (points, FK, IK and paths are then at the TCP). ``obstacles: {name:
BODY}`` are fixed in the world. A BODY is one of::

    {box: [x, y, z]}                     # edge lengths [m]
    {cylinder: {radius: r, length: l}}   # along its z axis [m]
    {sphere: r}                          # or {sphere: {radius: r}} [m]
    {mesh: part.stl, scale: 0.001}       # STL/OBJ/DAE/..., relative to the program's folder

with an optional pose ``xyz: [..]`` [m], ``rpy_deg: [..]`` [deg] (and, for an obstacle,
``allowed: [link, ...]``: robot links allowed to touch it). ``clearance: METRES`` is the margin
kept between the robot (links and tool body) and the obstacles: closer counts as a collision
(default 0); the robot's own link pairs collide only on contact. A :class:`kinplan.WorkCell` is
always built, so the robot's self-collision is checked even without ``obstacles:``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Literal

import numpy as np
import pinocchio as pin

from kinplan.cell import Body, CellError, WorkCell
from kinplan.errors import KinplanError
from kinplan.model.robot import Robot
from kinplan.program.checker import Checker, describe, is_number, to_float
from kinplan.program.schema import MAX_COORDINATE, KeyPath

__all__ = ["SHAPE_KEYS", "read_cell"]

SHAPE_KEYS = ("box", "cylinder", "sphere", "mesh")
"""The shapes of a body (an obstacle or a tool body)."""
_POSE_KEYS = ("xyz", "rpy_deg")
_TOOL_KEYS = ("xyz", "rpy_deg", "body", "payload")
"""``payload:`` and obstacles' ``color:`` are read by :mod:`kinplan.program.process`."""


def read_cell(
    checker: Checker, data: dict, base_dir: Path, robot: Robot | None
) -> tuple[Robot | None, WorkCell | None, float]:
    """Read ``tool:``, ``obstacles:`` and ``clearance:``, reporting every problem.

    Args:
        checker: Collects the problems.
        data: The program's top-level mapping.
        base_dir: The program's folder (relative mesh paths are taken from it).
        robot: The program's robot (None when it could not be loaded).

    Returns:
        The robot (with its tool when ``tool:`` is given), the work cell (None after a problem
        or without a robot) and the clearance [m].
    """
    tool = _tool(checker, data.get("tool"), base_dir) if "tool" in data else None
    obstacles = _obstacles(checker, data.get("obstacles"), base_dir) if "obstacles" in data else {}
    clearance = _clearance(checker, data.get("clearance")) if "clearance" in data else 0.0
    if robot is None or tool is False or obstacles is None:
        return robot, None, clearance or 0.0
    if tool is not None:
        tcp, body = tool
        try:
            robot = robot.with_tool(tcp, body)
        except KinplanError as exc:
            checker.error(("tool",), str(exc))
            return robot, None, clearance or 0.0
    try:
        cell = WorkCell(robot)
    except KinplanError as exc:
        checker.error(("robot",), f"its collision geometry cannot be used: {exc}")
        return robot, None, clearance or 0.0
    for name, (body, allowed) in obstacles.items():
        try:
            cell.add(name, body, allowed=allowed)
        except KinplanError as exc:
            checker.error(("obstacles", name), str(exc))
    return robot, cell, clearance or 0.0


def _clearance(checker: Checker, value: object) -> float | None:
    if not is_number(value) or not math.isfinite(to_float(value)) or to_float(value) < 0:
        checker.error(
            ("clearance",),
            f"expected a number ≥ 0 (the margin kept from the obstacles [m]), got "
            f"{describe(value)}",
        )
        return None
    return to_float(value)


def _tool(
    checker: Checker, spec: object, base_dir: Path
) -> tuple[pin.SE3, Body | None] | Literal[False]:
    """``tool: {xyz, rpy_deg, body}`` → (TCP in the flange frame, body or None); False after
    a problem."""
    path: KeyPath = ("tool",)
    if not isinstance(spec, dict) or not spec:
        checker.error(
            path,
            "expected {xyz: [x, y, z] [m], rpy_deg: [r, p, y], body: {cylinder: {radius, "
            "length}, xyz, rpy_deg}} (the TCP and the tool body in the flange frame), got "
            f"{describe(spec)}",
        )
        return False
    ok = True
    for key in spec:
        if key not in _TOOL_KEYS:
            checker.error(
                path + (str(key),), f"unknown key {key!r}; expected {', '.join(_TOOL_KEYS)}"
            )
            ok = False
    tcp = _pose(checker, spec, path, "the TCP position in the flange frame [m]")
    body = None
    if "body" in spec:
        body = _body(checker, spec["body"], path + ("body",), base_dir)
        ok = ok and body is not None
    if not ok or tcp is None:
        return False
    return tcp, body


def _obstacles(
    checker: Checker, spec: object, base_dir: Path
) -> dict[str, tuple[Body, list[str]]] | None:
    """``obstacles: {name: BODY}`` → name → (body, allowed links); None after a problem."""
    path: KeyPath = ("obstacles",)
    if spec is None:
        return {}
    if not isinstance(spec, dict):
        checker.error(
            path,
            "expected a mapping {name: {box: [x, y, z]} | {cylinder: {radius, length}} | "
            "{sphere: radius} | {mesh: FILE}, with xyz, rpy_deg}, got " + describe(spec),
        )
        return None
    obstacles: dict[str, tuple[Body, list[str]]] = {}
    ok = True
    for name, entry in spec.items():
        where = path + (str(name),)
        allowed: list[str] = []
        if isinstance(entry, dict) and "allowed" in entry:
            value = entry["allowed"]
            value = [value] if isinstance(value, str) else value
            if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
                checker.error(
                    where + ("allowed",), f"expected a list of link names, got {describe(value)}"
                )
                ok = False
            else:
                allowed = list(value)
            entry = {k: v for k, v in entry.items() if k != "allowed"}
        if isinstance(entry, dict):  # its colour is read by kinplan.program.process
            entry = {k: v for k, v in entry.items() if k != "color"}
        body = _body(checker, entry, where, base_dir, extra=("allowed", "color"))
        if body is None:
            ok = False
        else:
            obstacles[str(name)] = (body, allowed)
    return obstacles if ok else None


def _pose(checker: Checker, spec: dict, path: KeyPath, what: str) -> pin.SE3 | None:
    xyz: np.ndarray | None = np.zeros(3)
    if "xyz" in spec:
        xyz = checker.numbers(spec["xyz"], path + ("xyz",), 3, what, bound=MAX_COORDINATE)
    rpy: np.ndarray | None = np.zeros(3)
    if "rpy_deg" in spec:
        rpy = checker.numbers(spec["rpy_deg"], path + ("rpy_deg",), 3, "roll, pitch, yaw [deg]")
    if xyz is None or rpy is None:
        return None
    return pin.SE3(pin.rpy.rpyToMatrix(*np.radians(rpy)), xyz)


def _body(
    checker: Checker, spec: object, path: KeyPath, base_dir: Path, extra: tuple[str, ...] = ()
) -> Body | None:
    """A BODY mapping (see the module docstring) as a :class:`~kinplan.cell.Body`, or None after
    reporting a problem."""
    expected = (
        "{box: [x, y, z]}, {cylinder: {radius: r, length: l}}, {sphere: r} or {mesh: FILE} "
        "[m], with xyz: [..] and rpy_deg: [..]"
    )
    if not isinstance(spec, dict):
        checker.error(path, f"expected {expected}, got {describe(spec)}")
        return None
    shapes = [key for key in spec if key in SHAPE_KEYS]
    known = SHAPE_KEYS + _POSE_KEYS + ("scale",) + extra
    unknown = [key for key in spec if key not in known]
    for key in unknown:
        checker.error(
            path + (str(key),),
            f"unknown key {key!r}; a body is one of {', '.join(SHAPE_KEYS)} with "
            f"{', '.join(_POSE_KEYS + ('scale',) + extra)}",
        )
    if len(shapes) != 1:
        if not unknown:
            checker.error(
                path,
                f"expected exactly one shape ({', '.join(SHAPE_KEYS)}), got "
                f"{', '.join(shapes) or 'none'}; e.g. {expected}",
            )
        return None
    if unknown:
        return None
    shape = shapes[0]
    pose = _pose(checker, spec, path, "the body's position [m]")
    if pose is None:
        return None
    if "scale" in spec and shape != "mesh":
        checker.error(path + ("scale",), f"scale is for meshes only; give the {shape}'s size")
        return None
    value = spec[shape]
    where = path + (shape,)
    try:
        if shape == "box":
            size = checker.numbers(value, where, 3, "edge lengths x, y, z [m]")
            return None if size is None else Body.box(size, pose)
        if shape == "cylinder":
            if not isinstance(value, dict) or set(value) != {"radius", "length"}:
                checker.error(
                    where, f"expected {{radius: r, length: l}} [m], got {describe(value)}"
                )
                return None
            return Body.cylinder(value["radius"], value["length"], pose)
        if shape == "sphere":
            if isinstance(value, dict) and set(value) == {"radius"}:
                value = value["radius"]
            return Body.sphere(value, pose)
        if not isinstance(value, str) or not value.strip():
            checker.error(where, f"expected a mesh file (STL, OBJ, DAE...), got {describe(value)}")
            return None
        file = Path(value).expanduser()
        file = file if file.is_absolute() else base_dir / file
        if not os.path.isfile(file):  # Path.is_file raises on a name too long to look up
            checker.error(
                where,
                f"no file {str(file)!r} (relative paths are taken from the program's folder)",
            )
            return None
        return Body.mesh(file, pose, scale=spec.get("scale", 1.0))
    except CellError as exc:
        checker.error(where if "scale" not in str(exc) else path + ("scale",), str(exc))
        return None
