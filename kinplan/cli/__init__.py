"""The ``kinplan`` command (the console script ``kinplan = kinplan.cli:main``).

Its code is in :mod:`kinplan.cli.main`; ``python -m kinplan.cli`` runs it too.
"""

from __future__ import annotations

from kinplan.cli.main import build_parser as build_parser
from kinplan.cli.main import main

__all__ = ["main"]
