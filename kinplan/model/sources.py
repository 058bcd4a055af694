"""Where robot descriptions come from: bundled URDFs, example-robot-data, files on disk.

A *source* is one of

* a robot bundled with kinplan (``"planar_2r"``; the files of :mod:`kinplan.robots`),
* an arm of the ``example-robot-data`` package by name (``"ur3"``, ``"ur5"``, ``"ur10"``,
  ``"panda"``),
* a path to a URDF file.

:func:`resolve_source` turns a source into a :class:`RobotSpec`: the URDF file, the directories
that resolve its ``package://`` mesh paths, the default tool frame and the joints to lock.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from kinplan.errors import RobotNotFoundError


@dataclass(frozen=True)
class RobotSpec:
    """Everything needed to build a robot model from one source.

    Attributes:
        name: Robot name (the bundled or example-robot-data name, or the file's stem).
        urdf_path: Absolute path of the URDF file.
        package_dirs: Directories searched for ``package://<pkg>/...`` mesh paths.
        default_tip: Tool frame used when the caller gives none (``None``: the chain's last link).
        locked_joints: Joints fixed at their neutral value (grippers, fingers).
    """

    name: str
    urdf_path: Path
    package_dirs: tuple[Path, ...] = ()
    default_tip: str | None = None
    locked_joints: tuple[str, ...] = field(default_factory=tuple)


@dataclass(frozen=True)
class _ExampleArm:
    relative_urdf: str
    default_tip: str
    locked_joints: tuple[str, ...] = ()


#: Arms of ``example-robot-data`` known by name. Paths are relative to its ``robots`` folder.
EXAMPLE_ARMS: dict[str, _ExampleArm] = {
    "ur3": _ExampleArm("ur_description/urdf/ur3_robot.urdf", "tool0"),
    "ur5": _ExampleArm("ur_description/urdf/ur5_robot.urdf", "tool0"),
    "ur10": _ExampleArm("ur_description/urdf/ur10_robot.urdf", "tool0"),
    "panda": _ExampleArm(
        "panda_description/urdf/panda.urdf",
        "panda_hand_tcp",
        ("panda_finger_joint1", "panda_finger_joint2"),
    ),
}

#: Universal Robots e-Series arms known by name: loaded from the first of these files found in
#: example-robot-data's ``robots`` folder (none ships them as of 6.0), else refused with the
#: path to pass.
E_SERIES_ARMS: dict[str, tuple[str, ...]] = {
    name: (
        f"ur_description/urdf/{name}_robot.urdf",
        f"ur_description/urdf/{name}.urdf",
        f"ur_e_description/urdf/{name}_robot.urdf",
        f"{name}_description/urdf/{name}.urdf",
    )
    for name in ("ur3e", "ur5e", "ur10e", "ur16e")
}

#: Default tool frames of the bundled robots.
BUNDLED_TIPS: dict[str, str] = {"planar_2r": "tip"}


def bundled_robots() -> dict[str, Path]:
    """Bundled robot names and their URDF files (shipped as package data)."""
    try:
        folder = resources.files("kinplan.robots")
    except ModuleNotFoundError:  # running from a source tree that is not installed
        folder = Path(__file__).resolve().parents[2] / "robots"  # kinplan/model/ → the tree
    found = {}
    for entry in folder.iterdir():
        if entry.name.endswith(".urdf"):
            found[entry.name[: -len(".urdf")]] = Path(str(entry))
    return dict(sorted(found.items()))


def example_robot_data_dir() -> Path | None:
    """The ``share`` folder that holds ``example-robot-data/robots``, or ``None`` if absent.

    ``example-robot-data`` (6.x) installs its files under ``<site-packages>/cmeel.prefix/share``.
    The environment variable ``EXAMPLE_ROBOT_DATA_DIR`` (a folder holding ``robots/``) overrides
    the search.
    """
    override = os.environ.get("EXAMPLE_ROBOT_DATA_DIR")
    if override:
        robots = Path(override) / "robots"
        return Path(override).parent if robots.is_dir() else None
    candidates = [Path(p) / "cmeel.prefix" / "share" for p in sys.path if p]
    candidates.append(Path(sys.prefix) / "share")
    for share in candidates:
        if (share / "example-robot-data" / "robots").is_dir():
            return share
    return None


def known_names() -> list[str]:
    """Every robot name :func:`resolve_source` accepts, bundled first."""
    return list(bundled_robots()) + list(EXAMPLE_ARMS)


def resolve_source(source: str | os.PathLike[str]) -> RobotSpec:
    """Turn a robot source (name or URDF path) into a :class:`RobotSpec`.

    Raises:
        RobotNotFoundError: the name is unknown and no such file exists, or example-robot-data is
            not installed.
    """
    text = os.fspath(source)
    bundled = bundled_robots()
    if text in bundled:
        return RobotSpec(
            name=text,
            urdf_path=bundled[text],
            package_dirs=(bundled[text].parent,),
            default_tip=BUNDLED_TIPS.get(text),
        )
    if text in EXAMPLE_ARMS:
        arm = EXAMPLE_ARMS[text]
        share = example_robot_data_dir()
        if share is None:
            raise RobotNotFoundError(
                f"robot {text!r} comes from the example-robot-data package, which is not "
                "installed (or not found); install it with `pip install example-robot-data` or "
                "set EXAMPLE_ROBOT_DATA_DIR to the folder that holds its robots/ directory"
            )
        path = share / "example-robot-data" / "robots" / arm.relative_urdf
        if not path.is_file():
            raise RobotNotFoundError(
                f"robot {text!r}: example-robot-data is installed at {share} but has no "
                f"{arm.relative_urdf}; upgrade example-robot-data"
            )
        return RobotSpec(
            name=text,
            urdf_path=path,
            package_dirs=(share,),
            default_tip=arm.default_tip,
            locked_joints=arm.locked_joints,
        )
    if text.lower() in E_SERIES_ARMS:
        return _e_series(text.lower())
    path = Path(text).expanduser()
    if path.is_file():
        path = path.resolve()
        return RobotSpec(name=path.stem, urdf_path=path, package_dirs=_package_dirs_near(path))
    if path.suffix.lower() in (".urdf", ".xml") or os.sep in text or "/" in text:
        raise RobotNotFoundError(
            f"URDF file {text!r} does not exist; check the path (relative paths are taken from "
            f"the current directory {os.getcwd()})"
        )
    raise RobotNotFoundError(
        f"unknown robot {text!r}; known robots: {', '.join(known_names())}; "
        "or give the path of a URDF file"
    )


def _e_series(name: str) -> RobotSpec:
    """A UR e-Series arm from the installed packages, or the error naming the path to pass."""
    share = example_robot_data_dir()
    searched = []
    if share is not None:
        robots = share / "example-robot-data" / "robots"
        for relative in E_SERIES_ARMS[name]:
            path = robots / relative
            searched.append(str(path))
            if path.is_file():
                return RobotSpec(
                    name=name, urdf_path=path, package_dirs=(share,), default_tip="tool0"
                )
    where = f" (looked for {searched[0]} and {len(searched) - 1} other names)" if searched else (
        " (example-robot-data is not installed)"
    )  # fmt: skip
    pretty = name[:-1].upper() + "e"
    raise RobotNotFoundError(
        f"robot {name!r}: no URDF of the {pretty} in the installed packages{where}; "
        f"give the path of a {pretty} URDF file instead, e.g. kinplan info /path/to/"
        f"{name}.urdf (Universal Robots' ur_description makes one: xacro ur.urdf.xacro "
        f"ur_type:={name} name:={name} > {name}.urdf)"
    )


def _package_dirs_near(urdf_path: Path) -> tuple[Path, ...]:
    """Folders that may resolve ``package://`` paths of a URDF found on disk.

    The ancestors of the file (a ROS package usually holds ``urdf/`` and ``meshes/``), then the
    example-robot-data share folder.
    """
    dirs = list(urdf_path.parents[:3])
    share = example_robot_data_dir()
    if share is not None:
        dirs.append(share)
    return tuple(dirs)
