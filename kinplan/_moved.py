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


def alias_package(old: str, new: str) -> None:
    """Make the package ``old`` and each of its modules ``old.X`` names of ``new`` and ``new.X``
    (``__main__`` excepted: ``python -m old`` finds the new one through the package's path)."""
    package = importlib.import_module(new)
    sys.modules[old] = package
    for info in pkgutil.iter_modules(package.__path__):
        if info.name != "__main__":
            sys.modules[f"{old}.{info.name}"] = importlib.import_module(f"{new}.{info.name}")
