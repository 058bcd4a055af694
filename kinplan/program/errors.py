"""The errors of motion programs: an invalid file (:class:`ProgramError`, a list of
:class:`Issue` s) and a move that cannot be done (:class:`MoveError`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from kinplan.errors import KinplanError
from kinplan.program.plan import MoveReport

__all__ = ["Issue", "MoveError", "ProgramError"]


@dataclass(frozen=True)
class Issue:
    """One problem of a program file.

    Attributes:
        path: Key path, e.g. ``moves[2].lin`` (``program`` for the file as a whole).
        message: What is wrong and what is expected.
        line: 1-based line of the YAML file, when known.
    """

    path: str
    message: str
    line: int | None = None

    def __str__(self) -> str:
        where = f"{self.path} (line {self.line})" if self.line else self.path
        return f"{where}: {self.message}"


class ProgramError(KinplanError):
    """A program file is invalid; :attr:`issues` lists every problem found.

    ``str(error)`` is a header line followed by one indented line per issue; :meth:`one_line`
    puts them on a single line (for command-line error messages).

    Args:
        source: The program's file name (or ``<string>``).
        issues: Every problem found, in the order to report them.
    """

    def __init__(self, source: str, issues: Sequence[Issue]) -> None:
        self.source = source
        self.issues = list(issues)
        count = len(self.issues)
        self.header = f"{source}: {count} error{'s' if count != 1 else ''} in the program"
        super().__init__("\n".join([self.header + ":"] + [f"  - {issue}" for issue in issues]))

    def one_line(self) -> str:
        """The header and every issue on one line, issues separated by `` | ``."""
        return f"{self.header}: " + " | ".join(str(issue) for issue in self.issues)


class MoveError(KinplanError):
    """A move cannot be done; the message is one line naming the move and where it failed.

    Args:
        message: The one-line reason.
        report: The failed move's report.

    Attributes:
        report: The failed move's report.
    """

    def __init__(self, message: str, report: MoveReport) -> None:
        super().__init__(message)
        self.report = report
