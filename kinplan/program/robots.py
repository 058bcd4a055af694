"""A program's robot: its ``robot:`` entry resolved to a name or a file, loaded and cached.

Loading parses a URDF, so named robots loaded without options are kept for the next program.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import pinocchio as pin

from kinplan import checks
from kinplan.model.robot import Robot, load_robot
from kinplan.model.sources import bundled_robots, known_names

__all__ = ["load_cached_robot", "resolve_robot_source"]

_ROBOT_CACHE: dict[tuple[str, str | None], Robot] = {}


def resolve_robot_source(source: str, base_dir: Path) -> str:
    """A robot name as is; a file path, relative to the program's folder, made absolute.

    Args:
        source: The ``robot`` entry of a program: a robot name or a URDF path.
        base_dir: The program's folder.

    Returns:
        The name, or the absolute path of the file.

    Raises:
        InputError: ``source`` is not a string or ``base_dir`` not a folder path.
    """
    source = checks.text(source, "source (a robot name or URDF path)")
    base_dir = Path(checks.file_path(base_dir, "base_dir (the program's folder)"))
    if source in bundled_robots() or source in known_names():
        return source
    try:
        path = Path(source).expanduser()
    except RuntimeError:  # ~user of an unknown user: load_robot says the file does not exist
        path = Path(source)
    if not path.is_absolute():
        path = base_dir / path
    looks_like_a_path = "/" in source or "\\" in source or path.suffix.lower() in (".urdf", ".xml")
    is_file = os.path.isfile(path)  # False for a name too long to look up or a NUL character
    return str(path) if looks_like_a_path or is_file else source


def load_cached_robot(
    source: str,
    tip: str | None,
    locked_joints: Mapping[str, float] | None = None,
    limits: Mapping[str, Mapping[str, float]] | None = None,
    package_dirs: Sequence[Path] | None = None,
    base_pose: pin.SE3 | None = None,
) -> Robot:
    """:func:`kinplan.load_robot`, cached for named robots without options.

    Args:
        source: A robot name or a URDF path (:func:`resolve_robot_source`).
        tip: The tool frame, or None for the robot's default.
        locked_joints: Joint values to lock [rad, or m for a prismatic joint].
        limits: Per-joint limits to override [rad or m, per s, per s²].
        package_dirs: Mesh folders.
        base_pose: The robot's root in the world.

    Raises:
        KinplanError: the robot cannot be loaded (as :func:`kinplan.load_robot`).
    """
    options = (locked_joints, limits, package_dirs, base_pose)
    if source not in known_names() or any(value is not None for value in options):
        return load_robot(
            source, tip=tip, locked_joints=locked_joints, limits=limits,
            package_dirs=package_dirs, base_pose=base_pose,
        )  # fmt: skip
    key = (source, tip)
    if key not in _ROBOT_CACHE:
        _ROBOT_CACHE[key] = load_robot(source, tip=tip)
    return _ROBOT_CACHE[key]
