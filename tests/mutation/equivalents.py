"""Equivalent mutants of the core modules: mutants that no test can tell from the original, each
with the reason. ``tools/mutation.py`` leaves them out of the score and lists them in
``tests/bench/MUTATION.md``.

An entry matches a surviving mutant of ``module`` whose removed lines read ``original`` and whose
added lines read ``mutant`` (whitespace-insensitive; several lines joined by a space), so the list
survives line moves and mutmut's renumbering.
"""

from __future__ import annotations

EQUIVALENTS: list[dict[str, str]] = []
