"""Old module paths kept importable after issue 31's move into sub-packages.

A module that moved leaves a shim at its old path that replaces itself in ``sys.modules`` by the
new module, so ``import kinplan.robot``, ``mock.patch("kinplan.robot.X")`` and pickles naming the
old path all reach the one module object. A package that moved does the same for itself and each
of its modules (:func:`alias_package`).
"""

from __future__ import annotations

import importlib
import pkgutil
import sys

#: Every module or package that moved in issue 31: its old name under ``kinplan`` → the module
#: it is now (the old path is a shim). ``kinplan``'s lazy attributes and
#: ``tools/import_graph.py`` read it.
MOVED: dict[str, str] = {
    **{name: f"kinplan.model.{name}" for name in (
        "robot", "urdf_model", "urdf_read", "urdf_frames", "sources", "planar", "mesh_files",
        "tool", "arm",
    )},
    "_profiles": "kinplan.trajectory._profiles",
    "time_optimal": "kinplan.trajectory.totg",
    "phase_plane": "kinplan.trajectory.phase_plane",
    "sampling": "kinplan.trajectory.sampling",
    "motion": "kinplan.trajectory.motion",
    **{name: f"kinplan.scale.{name}" for name in (
        "reach", "reach_view", "placement", "batch", "engines",
    )},
    "batch_ik": "kinplan.ik.batch",
    **{name: f"kinplan.apps.{name}" for name in ("cli", "teach", "demos", "lecture")},
}  # fmt: skip


def alias_package(old: str, new: str) -> None:
    """Make the package ``old`` and each of its modules ``old.X`` names of ``new`` and ``new.X``
    (``__main__`` excepted: ``python -m old`` finds the new one through the package's path)."""
    package = importlib.import_module(new)
    sys.modules[old] = package
    for info in pkgutil.iter_modules(package.__path__):
        if info.name != "__main__":
            sys.modules[f"{old}.{info.name}"] = importlib.import_module(f"{new}.{info.name}")
