"""``main``: the ``kinplan`` command run: its arguments parsed, the command's handler called,
every failure one ``kinplan: error:`` line on stderr, the exit status returned."""

from __future__ import annotations

import argparse
import logging
import os
import sys
import warnings
from collections.abc import Sequence

from kinplan.apps.cli.output import fail, one_line
from kinplan.apps.cli.parser import build_parser
from kinplan.errors import KinplanError

__all__ = ["main"]


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``kinplan`` command.

    Args:
        argv: Arguments (default ``sys.argv[1:]``).

    Returns:
        Exit status: 0 success, 1 failure (one-line reason on stderr), 2 command-line error.
    """
    parser = build_parser()
    if argv is not None and not isinstance(argv, (str, bytes)) and hasattr(argv, "__iter__"):
        argv = list(argv)  # a generator is read once
    if argv is not None and (
        not isinstance(argv, list) or not all(isinstance(arg, str) for arg in argv)
    ):
        print(
            f"kinplan: error: main() takes a list of argument strings, got {argv!r:.80}",
            file=sys.stderr,
        )
        return 2
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a usage error (already printed)
        return int(exc.code or 0) if not isinstance(exc.code, str) else 2
    if args.verbose:
        logging.basicConfig(level=logging.INFO, format="%(name)s: %(message)s")
        logging.captureWarnings(True)  # Python warnings become log lines
    else:
        _notes_on_stderr()
    with warnings.catch_warnings():
        if not args.verbose:  # stderr holds kinplan's own lines only (one line on failure)
            warnings.simplefilter("ignore")
        return _dispatch(args)


def _dispatch(args: argparse.Namespace) -> int:
    """Run the command's handler; every failure becomes one ``kinplan: error:`` line."""
    try:
        return args.handler(args)
    except BrokenPipeError:  # the reader stopped early (e.g. `kinplan info ur5 | head`)
        _silence_stdout()
        return 1
    except (KinplanError, OSError) as exc:
        return fail(one_line(exc))
    except KeyboardInterrupt:
        print("kinplan: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # a bug: still one line (the traceback is logged with -v)
        logging.getLogger("kinplan.cli").info("internal error", exc_info=True)
        return fail(
            f"internal error ({type(exc).__name__}: {one_line(exc)}); please report it with the "
            "command that caused it (kinplan -v ... logs the traceback)"
        )


def interactive() -> bool:
    """Whether stderr is a terminal (a person waiting, not a log that must stay one line)."""
    return bool(getattr(sys.stderr, "isatty", lambda: False)())


class _NoteHandler(logging.Handler):
    """Log records as ``kinplan: note: ...`` lines on the current stderr, when it is a
    terminal (off one, stderr keeps the one-line error of a failure)."""

    def emit(self, record: logging.LogRecord) -> None:
        if interactive():
            print(f"kinplan: note: {record.getMessage()}", file=sys.stderr, flush=True)


def _notes_on_stderr() -> None:
    """Print the library's one-line notes (numba compiling on first use) on stderr."""
    compiled = logging.getLogger("kinplan.compiled")
    if not any(isinstance(h, _NoteHandler) for h in compiled.handlers):
        compiled.addHandler(_NoteHandler(logging.INFO))
        compiled.setLevel(logging.INFO)


def _silence_stdout() -> None:
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # not a real file (captured output)
        pass
