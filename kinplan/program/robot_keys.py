"""The robot keys of a program: ``robot``, ``tip`` and the options passed to
:func:`kinplan.load_robot` (``locked_joints``, ``limits``, ``package_dirs``, ``base_pose``)."""

from __future__ import annotations

import enum
import math
import re
from pathlib import Path
from typing import Literal

import numpy as np
import pinocchio as pin

from kinplan.errors import KinplanError
from kinplan.model.robot import Robot
from kinplan.model.sources import known_names
from kinplan.model.urdf_model import LIMIT_KEYS
from kinplan.program.checker import Checker, describe, is_number, to_float
from kinplan.program.robots import load_cached_robot, resolve_robot_source
from kinplan.program.schema import POSE_KEYS, KeyPath

__all__ = ["read_robot"]


class _Invalid(enum.Enum):
    INVALID = "invalid"


_INVALID = _Invalid.INVALID
"""What a robot option's reader returns when it reported a problem."""
Invalid = Literal[_Invalid.INVALID]


def read_robot(checker: Checker, data: dict, base_dir: Path) -> tuple[str, Robot | None]:
    """Load the robot a program names, with its options, reporting every problem.

    Args:
        checker: Collects the problems.
        data: The program's top-level mapping.
        base_dir: The program's folder (relative URDF and mesh paths are taken from it).

    Returns:
        The ``robot`` entry as written ("" when missing or not text) and the robot, or None
        when it could not be loaded.
    """
    source = data.get("robot")
    tip = data.get("tip")
    if tip is not None and not isinstance(tip, str):
        checker.error(("tip",), f"expected a frame or link name, got {describe(tip)}")
        tip = None
    if source is None:
        checker.error(
            ("robot",),
            f"missing; give a robot name ({', '.join(known_names())}) or a URDF path",
        )
        return "", None
    if not isinstance(source, str):
        checker.error(("robot",), f"expected a robot name or URDF path, got {describe(source)}")
        return "", None
    locked_joints = _locked_joints(checker, data.get("locked_joints"))
    limits = _limits(checker, data.get("limits"))
    package_dirs = _package_dirs(checker, data.get("package_dirs"), base_dir)
    base_pose = _base_pose(checker, data.get("base_pose"))
    if (
        locked_joints is _INVALID
        or limits is _INVALID
        or package_dirs is _INVALID
        or base_pose is _INVALID
    ):
        return source, None  # reported; the robot would not be the one the program means
    try:
        robot = load_cached_robot(
            resolve_robot_source(source, base_dir), tip, locked_joints, limits, package_dirs,
            base_pose,
        )  # fmt: skip
    except KinplanError as exc:
        checker.error(_error_key(str(exc), type(exc).__name__, data), str(exc))
        return source, None
    return source, robot


def _error_key(message: str, kind: str, data: dict) -> KeyPath:
    """The key a loading error is about: a joint of ``locked_joints:`` or ``limits:`` (its
    message starts with the key), ``tip`` (a frame error) or ``robot``."""
    for key in ("locked_joints", "limits", "base_pose", "package_dirs"):
        if message.startswith(key):
            entries = data.get(key)
            named = re.search(r"(?:no joint |\[)'([^']*)'", message)
            if isinstance(entries, dict) and named and named.group(1) in entries:
                return (key, named.group(1))
            return (key,)
    return ("tip",) if "frame" in kind.lower() else ("robot",)


def _locked_joints(checker: Checker, spec: object) -> dict[str, float] | None | Invalid:
    """``locked_joints: {name: value}`` [rad, or m for a prismatic joint]."""
    if spec is None:
        return None
    path: KeyPath = ("locked_joints",)
    if not isinstance(spec, dict) or not spec:
        checker.error(
            path,
            "expected a mapping {joint name: value} (rad, or m for a prismatic joint), got "
            f"{describe(spec)}",
        )
        return _INVALID
    locked: dict[str, float] = {}
    ok = True
    for name, value in spec.items():
        if not is_number(value) or not math.isfinite(to_float(value)):
            checker.error(
                path + (str(name),),
                "expected the joint's value, a finite number (rad, or m for a prismatic "
                f"joint), got {describe(value)}",
            )
            ok = False
        else:
            locked[str(name)] = to_float(value)
    return locked if ok else _INVALID


def _limits(checker: Checker, spec: object) -> dict[str, dict[str, float]] | None | Invalid:
    """``limits: {joint: {lower, upper, velocity, acceleration}}`` (any subset) [rad or m,
    /s, /s²]."""
    if spec is None:
        return None
    path: KeyPath = ("limits",)
    keys = ", ".join(LIMIT_KEYS)
    if not isinstance(spec, dict) or not spec:
        checker.error(path, f"expected a mapping {{joint name: {{{keys}}}}}, got {describe(spec)}")
        return _INVALID
    limits: dict[str, dict[str, float]] = {}
    ok = True
    for name, entry in spec.items():
        where = path + (str(name),)
        if not isinstance(entry, dict) or not entry:
            checker.error(
                where,
                f"expected a mapping with any of {keys} (rad or m; velocity per s, "
                f"acceleration per s²), got {describe(entry)}",
            )
            ok = False
            continue
        values: dict[str, float] = {}
        for key, value in entry.items():
            if key not in LIMIT_KEYS:
                checker.error(where + (str(key),), f"unknown key {key!r}; expected {keys}")
                ok = False
            elif key in ("velocity", "acceleration"):
                unit = "rad/s or m/s" if key == "velocity" else "rad/s² or m/s²"
                number = checker.positive(value, where + (key,), f"{key} limit [{unit}]")
                ok = ok and number is not None
                if number is not None:
                    values[key] = number
            elif not is_number(value) or not math.isfinite(to_float(value)):
                checker.error(
                    where + (key,),
                    f"expected a finite number ({key} limit [rad or m]), got {describe(value)}",
                )
                ok = False
            else:
                values[key] = to_float(value)
        if "lower" in values and "upper" in values and values["lower"] >= values["upper"]:
            checker.error(
                where,
                f"lower {values['lower']:g} must be below upper {values['upper']:g}",
            )
            ok = False
        limits[str(name)] = values
    return limits if ok else _INVALID


def _package_dirs(checker: Checker, spec: object, base_dir: Path) -> list[Path] | None | Invalid:
    """``package_dirs: [folder, ...]``: mesh folders, relative to the program's folder."""
    if spec is None:
        return None
    path: KeyPath = ("package_dirs",)
    if isinstance(spec, str):
        spec = [spec]
    if not isinstance(spec, list) or not spec or not all(isinstance(d, str) for d in spec):
        checker.error(path, f"expected a list of folders, got {describe(spec)}")
        return _INVALID
    folders = []
    for k, text in enumerate(spec):
        folder = Path(text).expanduser()
        folder = folder if folder.is_absolute() else base_dir / folder
        if not folder.is_dir():
            checker.error(
                path + (k,),
                f"no folder {str(folder)!r} (relative folders are taken from the program's folder)",
            )
            return _INVALID
        folders.append(folder)
    return folders


def _base_pose(checker: Checker, spec: object) -> pin.SE3 | None | Invalid:
    """``base_pose: {xyz: [..] m, rpy_deg: [..] | quat_xyzw: [..]}``: the robot's root in
    the world."""
    if spec is None:
        return None
    path: KeyPath = ("base_pose",)
    if not isinstance(spec, dict) or "xyz" not in spec:
        checker.error(
            path,
            "expected {xyz: [x, y, z]} [m] with rpy_deg: [r, p, y] or quat_xyzw: [x, y, z, "
            f"w] (the robot's root in the world), got {describe(spec)}",
        )
        return _INVALID
    unknown = [key for key in spec if key not in POSE_KEYS]
    for key in unknown:
        checker.error(path + (str(key),), f"unknown key {key!r}; expected {', '.join(POSE_KEYS)}")
    point = checker.cartesian_pose(spec, path, "the robot's root position [m]")
    if unknown or point is None:
        return _INVALID
    position, rotation = point
    return pin.SE3(np.eye(3) if rotation is None else rotation, position)
