"""The console session: :func:`run_session` feeds command lines to a :class:`TeachPendant
<kinplan.apps.teach.pendant.TeachPendant>` until ``q``, ``abort`` or the end of the input."""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np

from kinplan import checks
from kinplan.apps.teach.pendant import TeachPendant
from kinplan.errors import InputError


def run_session(
    pendant: TeachPendant,
    lines: Iterable[str],
    output: Callable[[str], None],
    on_move: Callable[[np.ndarray], None] | None = None,
    echo: bool = False,
) -> bool:
    """Feed command lines to the pendant until ``q``/``abort`` or the end of the input.

    The end of the input acts as ``q``: a running recording is stopped and stored.

    Args:
        pendant: The pendant.
        lines: Command lines (e.g. ``sys.stdin``, a :class:`PromptLines` or a list of strings).
        output: Called with the text to show after each command.
        on_move: Called with the new configuration after each move (e.g. a live viewer).
        echo: Show each command before its reply (for scripted input).

    Returns:
        True when the program should be written (``q`` or end of input), False on ``abort``.

    Raises:
        InputError: ``pendant`` is not a :class:`TeachPendant`, ``lines`` not iterable,
            ``output`` or ``on_move`` not callable.
    """
    if not isinstance(pendant, TeachPendant):
        raise InputError(f"pendant must be a TeachPendant, got {checks.describe(pendant)}")
    try:
        if isinstance(lines, (str, bytes)):
            raise TypeError
        lines = iter(lines)
    except TypeError:
        raise InputError(
            f"lines must be an iterable of command lines (a list or a file), got "
            f"{checks.describe(lines)}"
        ) from None
    if not callable(output) or (on_move is not None and not callable(on_move)):
        raise InputError("output and on_move must be functions (on_move may be None)")
    echo = checks.flag(echo, "echo")
    for line in lines:
        if echo and isinstance(line, str) and line.strip():
            output(f"teach> {line.rstrip()}")
        reply = pendant.execute(line)
        if reply.text:
            output(reply.text)
        if reply.moved and on_move is not None:
            on_move(pendant.q)
        if reply.done:
            return reply.write
    reply = pendant.execute("q")  # the end of the input: as q
    if reply.text:
        output(reply.text)
    return True
