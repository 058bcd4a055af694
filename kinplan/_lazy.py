"""Names a package loads on first use (PEP 562): what ``kinplan.ik`` and ``kinplan.cell`` use
so that importing them does not import every solver or work-cell module."""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Callable
from typing import Any


def lazy_attributes(package: str, names: dict[str, str]) -> Callable[[str], Any]:
    """A module ``__getattr__`` for ``package``: a name of ``names`` (name → submodule) is
    imported from its submodule on first use, and a submodule not yet loaded is imported when
    it is asked for as an attribute (``kinplan.ik.ur``), as an eager import would have left it."""

    def __getattr__(name: str) -> Any:
        if name in names:
            return getattr(importlib.import_module(f"{package}.{names[name]}"), name)
        if importlib.util.find_spec(f"{package}.{name}") is not None:
            return importlib.import_module(f"{package}.{name}")
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__
