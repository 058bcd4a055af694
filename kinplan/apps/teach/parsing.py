"""What the operator types: numbers with their units, names, axis and jog words, and lines that
are no command at all (terminal key codes, control characters)."""

from __future__ import annotations

import math
import re

AXES = {"x": 0, "y": 1, "z": 2}
"""The tool's linear jog words and their world axes."""
ROTATIONS = {"roll": 0, "rx": 0, "pitch": 1, "ry": 1, "yaw": 2, "rz": 2}
"""The tool's rotation jog words and the world axes they turn about."""
NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_\-]*$")
"""A point's name: letters, digits, _ and -, not first a digit."""
JOG = re.compile(r"^(?P<axis>[a-z]+)(?P<sign>[+-])$")
"""A jog by the step: a word and its sign (``x+``, ``yaw-``)."""
_CONTROL = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]")


def number(
    text: str, what: str, unit: str, *, positive: bool = False, maximum: float | None = None
) -> float:
    """A number typed by the operator, in ``unit`` (ValueError with the reason otherwise).

    Args:
        text: What was typed.
        what: What the number is, for the message (``the jog``).
        unit: Its unit in words (``degrees``, ``metres``, ``Hz``).
        positive: Require > 0.
        maximum: Largest magnitude accepted.
    """
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"expected a number of {unit} for {what}, got {text!r}") from None
    if not math.isfinite(value):
        raise ValueError(f"{what} must be a finite number of {unit}, got {text!r}")
    if positive and value <= 0:
        raise ValueError(f"{what} must be > 0 {unit}, got {text!r}")
    if maximum is not None and abs(value) > maximum:
        limit = f"at most {maximum:g}" if positive else f"between -{maximum:g} and {maximum:g}"
        raise ValueError(f"{what} must be {limit} {unit}, got {text!r}")
    return value


def control_message(line: str) -> str:
    """Why a line holding terminal escape sequences or control characters is not a command
    ("" for an ordinary line)."""
    if "\x1b" in line:
        start = line.index("\x1b")
        key = line[start : start + 3] if line[start + 1 : start + 2] in "[O" else line[start]
        return (
            f"{key!r} is a terminal key code (an arrow or function key), not a command: arrow "
            "keys edit and recall lines only when the pendant reads a terminal with Python's "
            "readline module; type the command instead"
        )
    found = _CONTROL.search(line)
    if found:
        return (
            f"the line holds the control character {found.group()!r}, not part of any command; "
            "type the command again"
        )
    return ""
