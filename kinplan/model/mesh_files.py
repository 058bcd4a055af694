"""Where a URDF's mesh files are: ``package://``, ``file://``, absolute and relative names.

Mesh files are found as ROS does: ``package://pkg/...`` through the robot's package folders,
example-robot-data's and the URDF's own folder and its parents; ``file://`` and absolute paths as
they are; bare relative names next to the URDF. The viewer (:mod:`kinplan.viewer.visuals`), the
work cell's collision geometry (:mod:`kinplan.cell`) and tools (:mod:`kinplan.model.tool`) resolve
meshes here, so they all find the same files.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from os import PathLike
from pathlib import Path

from kinplan.model.sources import example_robot_data_dir

__all__ = ["ANCESTOR_LEVELS", "not_found_reason", "resolve_mesh", "search_folders"]

ANCESTOR_LEVELS = 4
"""Parents of the URDF's folder searched for packages (``pkg/urdf/x.urdf``: 2 suffice)."""


def search_folders(urdf_path: Path, package_dirs: Iterable[str | PathLike[str]] = ()) -> list[Path]:
    """Folders searched for ``package://`` meshes, in order.

    The robot's package folders, example-robot-data's share folder, then the URDF's own folder
    and its parents (a ROS package usually holds ``urdf/`` and ``meshes/`` side by side).
    """
    folders = [Path(p) for p in package_dirs]
    share = example_robot_data_dir()
    if share is not None:
        folders += [share, share / "example-robot-data" / "robots"]
    folders += list(Path(urdf_path).resolve().parents)[:ANCESTOR_LEVELS]
    unique: list[Path] = []
    for folder in folders:
        if folder not in unique:
            unique.append(folder)
    return unique


def resolve_mesh(
    filename: str, urdf_path: Path, folders: Sequence[Path]
) -> tuple[Path | None, list[Path]]:
    """The mesh file a URDF names, and the places looked at.

    * ``package://pkg/rest``: ``<folder>/pkg/rest`` for each of ``folders``
      (:func:`search_folders`), or ``<folder>/rest`` when the folder is the package ``pkg``
      itself; failing that, ``rest`` under one of the URDF's parent folders (a package checked
      out under another folder name).
    * ``file:///abs/path`` and absolute paths: the file itself.
    * relative names (``meshes/arm.stl``): next to the URDF, then under each of ``folders``.

    Returns:
        (file or None when it is nowhere, the candidate paths tried).
    """
    urdf_dir = Path(urdf_path).resolve().parent
    candidates: list[Path] = []
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://") :].partition("/")
        for folder in folders:
            candidates.append(folder / package / rest)
            if folder.name == package:
                candidates.append(folder / rest)
        candidates += [parent / rest for parent in list(urdf_dir.parents)[:ANCESTOR_LEVELS]]
    elif filename.startswith("file://"):
        path = Path(filename[len("file://") :])
        candidates.append(path if path.is_absolute() else urdf_dir / path)
    elif Path(filename).is_absolute():
        candidates.append(Path(filename))
    else:
        candidates += [urdf_dir / filename, *(folder / filename for folder in folders)]
    for candidate in candidates:
        if os.path.isfile(candidate):  # False, not OSError, for a name too long
            return candidate, candidates
    return None, candidates


def not_found_reason(filename: str, tried: Sequence[Path], folders: Sequence[Path]) -> str:
    """Why a mesh was not found: the file looked for, or the folders searched for a package."""
    if filename.startswith("package://"):
        package = filename[len("package://") :].split("/", 1)[0]
        shown = ", ".join(str(f) for f in folders)
        return (
            f"not found: no package {package!r} holding it under {shown} (give the folder that "
            "holds the package with load_robot(..., package_dirs=[...]))"
        )
    if len(tried) == 1:
        return f"not found ({tried[0]} does not exist)"
    return (
        f"not found next to the URDF ({tried[0]}) nor under the package folders "
        f"{', '.join(str(f) for f in folders)}"
    )
