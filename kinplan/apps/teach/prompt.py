"""Reading the terminal: :class:`PromptLines`, lines typed at a prompt with line editing, history
(kept in :func:`default_history_file`) and command completion where Python has readline."""

from __future__ import annotations

import importlib
import logging
import os
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType

from kinplan import checks
from kinplan.apps.teach.help import COMPLETIONS
from kinplan.apps.teach.parsing import control_message
from kinplan.errors import InputError

logger = logging.getLogger("kinplan.teach")  # the package's name, as in the log lines before

HISTORY_ENV = "KINPLAN_HISTORY"
"""Environment variable naming the pendant's history file; empty disables the file."""
HISTORY_LENGTH = 1000
"""Lines kept in the history file."""


def default_history_file() -> Path | None:
    """The pendant's history file: ``$KINPLAN_HISTORY`` (none when it is set but empty), else
    ``~/.kinplan_history``."""
    value = os.environ.get(HISTORY_ENV)
    if value is not None:
        return Path(value).expanduser() if value.strip() else None
    return Path("~/.kinplan_history").expanduser()


def _readline_module() -> ModuleType | None:
    """Python's readline module, or None where it is missing (Windows)."""
    try:
        return importlib.import_module("readline")
    except ImportError:
        return None


class PromptLines:
    """Lines typed at a prompt, with line editing, history and command completion where
    Python has :mod:`readline` (arrow keys, Ctrl-R; not on Windows, whose console edits lines
    itself).

    Each non-empty line is added to the session's history (not twice in a row); with a
    ``history_file`` the history is read from it at the start and written back by
    :meth:`close` (the last :data:`HISTORY_LENGTH` lines). Use it as a context manager::

        with PromptLines(history_file=default_history_file()) as lines:
            run_session(pendant, lines, print)

    Args:
        prompt: The prompt.
        history_file: Where the history is kept between sessions, or None (this session only).
        read: Reads one line after showing the prompt; raises EOFError at the end (default
            :func:`input`, which uses readline when it is loaded and input is a terminal).

    Attributes:
        readline: The readline module in use, or None.
    """

    def __init__(
        self,
        prompt: str = "teach> ",
        history_file: str | os.PathLike[str] | None = None,
        read: Callable[[str], str] = input,
    ) -> None:
        if not isinstance(prompt, str):
            raise InputError(f"prompt must be text, got {checks.describe(prompt)}")
        if not callable(read):
            raise InputError(f"read must be a function like input, got {checks.describe(read)}")
        self.prompt = prompt
        self.read = read
        self.history_file = (
            None
            if history_file is None
            else Path(checks.file_path(history_file, "history_file")).expanduser()
        )
        self.readline = _readline_module()
        self._completer: Callable[[str, int], str | None] | None = None
        self._closed = False
        readline = self.readline
        if readline is None:
            return
        readline.set_auto_history(False)  # lines are added by remember(), not twice
        self._completer = readline.get_completer()
        readline.set_completer(_complete)
        if "libedit" in (getattr(readline, "__doc__", "") or ""):
            readline.parse_and_bind("bind ^I rl_complete")
        else:
            readline.parse_and_bind("tab: complete")
        if self.history_file is not None and self.history_file.is_file():
            try:
                readline.read_history_file(str(self.history_file))
            except OSError as exc:
                logger.warning("cannot read the history %s: %s", self.history_file, exc)

    def __enter__(self) -> PromptLines:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def __iter__(self) -> Iterator[str]:
        while True:
            try:
                line = self.read(self.prompt)
            except EOFError:
                return
            self.remember(line)
            yield line

    def remember(self, line: str) -> None:
        """Add ``line`` to the history (not empty lines, key codes or a repeat of the last)."""
        readline = self.readline
        text = line.strip() if isinstance(line, str) else ""
        if readline is None or not text or control_message(text):
            return
        length = readline.get_current_history_length()
        if length and readline.get_history_item(length) == text:
            return
        readline.add_history(text)

    def close(self) -> None:
        """Write the history file (if any) and give back readline's previous completer."""
        readline = self.readline
        if self._closed or readline is None:
            return
        self._closed = True
        readline.set_completer(self._completer)
        readline.set_auto_history(True)
        if self.history_file is None:
            return
        try:
            self.history_file.parent.mkdir(parents=True, exist_ok=True)
            readline.set_history_length(HISTORY_LENGTH)
            readline.write_history_file(str(self.history_file))
        except OSError as exc:
            logger.warning("cannot write the history %s: %s", self.history_file, exc)


def _complete(text: str, state: int) -> str | None:
    """readline completer: the pendant's command words starting with ``text``."""
    matches = [word for word in COMPLETIONS if word.startswith(text.lower())]
    return matches[state] if state < len(matches) else None
