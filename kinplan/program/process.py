"""A program's process keys: the arc and digital outputs of its moves, the tool's payload and
the obstacles' colours.

On a move (it takes effect when the move starts, after the previous move's dwell)::

    arc: on                          # or off: switches the arc output (arc_output:, default 0)
    io: {output: 3, value: 1}        # a standard digital output 0..7 set to 0 or 1 (or a list)

At the top level: ``arc_output: N`` (the digital output the arc is on, 0..7), ``tool: {...,
payload: {mass: KG, cog: [x, y, z]}}`` (the centre of gravity in the flange frame [m]) and
``color: "#rrggbb"`` on an obstacle (its colour in the playback).

A signal on a move that another move blends into has no instant of its own (the tool passes the
corner without stopping) and is refused; so are an ``arc: on`` while the arc is on, an
``arc: off`` while it is off, an ``io:`` on the arc's output and a program that ends with the
arc on.
"""

from __future__ import annotations

import math
import re

from kinplan.program.checker import Checker, describe, is_number, to_float
from kinplan.program.schema import KeyPath, Move, Payload

__all__ = [
    "DIGITAL_OUTPUTS",
    "IO_KEYS",
    "PAYLOAD_KEYS",
    "check_signals",
    "read_arc_output",
    "read_colors",
    "read_payload",
    "read_signals",
]

DIGITAL_OUTPUTS = range(8)
"""The standard digital outputs a program may set (a Universal Robots controller's 0 to 7)."""
IO_KEYS = ("output", "value")
"""The keys of a move's ``io:``."""
PAYLOAD_KEYS = ("mass", "cog")
"""The keys of a tool's ``payload:`` (``mass`` required)."""
MAX_PAYLOAD = 1000.0
"""Largest payload mass accepted [kg]: beyond is a unit mistake (the largest UR carries 30)."""
_COLOR = re.compile(r"^#[0-9A-Fa-f]{6}$")
_ARC_WORDS = {"on": True, "off": False}


def read_signals(
    checker: Checker, spec: dict, path: KeyPath
) -> tuple[bool | None, tuple[tuple[int, bool], ...]] | None:
    """A move's ``arc:`` and ``io:``.

    Args:
        checker: Collects the problems.
        spec: The move's mapping.
        path: Its key path (``("moves", 2)``).

    Returns:
        (arc: True / False / None, io: (output, value) pairs), or None after reporting.
    """
    ok = True
    arc = None
    if "arc" in spec:
        value = spec["arc"]
        if isinstance(value, bool):  # YAML 1.1 reads on/off as booleans
            arc = value
        elif isinstance(value, str) and value.strip().lower() in _ARC_WORDS:
            arc = _ARC_WORDS[value.strip().lower()]
        else:
            checker.error(path + ("arc",), f"expected on or off, got {describe(value)}")
            ok = False
    io: list[tuple[int, bool]] = []
    if "io" in spec:
        entries = spec["io"] if isinstance(spec["io"], list) else [spec["io"]]
        if not entries:
            checker.error(path + ("io",), "expected {output: N, value: 0|1} or a list of them")
            ok = False
        for k, entry in enumerate(entries):
            where = path + ("io",) + ((k,) if isinstance(spec["io"], list) else ())
            signal = _io(checker, entry, where)
            ok &= signal is not None
            if signal is not None:
                if any(signal[0] == output for output, _ in io):
                    checker.error(where, f"output {signal[0]} is set twice on this move")
                    ok = False
                io.append(signal)
    return (arc, tuple(io)) if ok else None


def _io(checker: Checker, entry: object, path: KeyPath) -> tuple[int, bool] | None:
    example = "{output: 2, value: 1}"
    if not isinstance(entry, dict):
        checker.error(path, f"expected a mapping such as {example}, got {describe(entry)}")
        return None
    ok = True
    for key in entry:
        if key not in IO_KEYS:
            checker.error(path + (str(key),), f"unknown key {key!r}; expected output and value")
            ok = False
    for key in IO_KEYS:
        if key not in entry:
            checker.error(path, f"io needs {key} (e.g. {example})")
            ok = False
    if not ok:
        return None
    output, value = entry["output"], entry["value"]
    if not (is_number(output) and float(output).is_integer() and int(output) in DIGITAL_OUTPUTS):
        checker.error(
            path + ("output",),
            f"expected a standard digital output number {DIGITAL_OUTPUTS.start} to "
            f"{DIGITAL_OUTPUTS.stop - 1}, got {describe(output)}",
        )
        ok = False
    if isinstance(value, bool):
        level = value
    elif is_number(value) and value in (0, 1):
        level = bool(value)
    else:
        checker.error(path + ("value",), f"expected 0 or 1, got {describe(value)}")
        ok = False
    return (int(output), level) if ok else None


def read_arc_output(checker: Checker, data: dict) -> int:
    """The top-level ``arc_output:`` (default 0)."""
    if "arc_output" not in data:
        return 0
    value = data["arc_output"]
    if is_number(value) and float(value).is_integer() and int(value) in DIGITAL_OUTPUTS:
        return int(value)
    checker.error(
        ("arc_output",),
        f"expected the digital output the arc is on, {DIGITAL_OUTPUTS.start} to "
        f"{DIGITAL_OUTPUTS.stop - 1}, got {describe(value)}",
    )
    return 0


def check_signals(checker: Checker, moves: list[Move], arc_output: int) -> None:
    """Signals across the moves: one instant each, the arc switched on and off in turn.

    Args:
        checker: Collects the problems.
        moves: The program's valid moves, in order.
        arc_output: The arc's digital output.
    """
    arc_on = False
    last_on: Move | None = None
    previous: Move | None = None
    for move in moves:
        blended_into = (
            previous is not None
            and previous.index == move.index - 1
            and previous.kind != "ptp"
            and previous.blend is not None
        )
        if blended_into and (move.arc is not None or move.io):
            key = "arc" if move.arc is not None else "io"
            checker.error(
                ("moves", move.index, key),
                f"moves[{move.index - 1}] blends into this move, so the tool passes its start "
                "without stopping and a signal there has no instant: put it on the first move "
                "of the blended seam (or remove blend from the move before)",
            )
        for output, _ in move.io:
            if output == arc_output:
                checker.error(
                    ("moves", move.index, "io"),
                    f"output {output} is the arc's (arc_output: {arc_output}); switch it with "
                    "arc: on|off, or set arc_output: to another output",
                )
        if move.arc is True and arc_on:
            checker.error(
                ("moves", move.index, "arc"),
                f"the arc is already on (since moves[{last_on.index if last_on else '?'}]); "
                "remove this arc: on or switch it off before",
            )
        elif move.arc is False and not arc_on:
            checker.error(("moves", move.index, "arc"), "the arc is not on here; remove arc: off")
        if move.arc is not None:
            arc_on = move.arc
            last_on = move if move.arc else last_on
        previous = move
    if arc_on and last_on is not None:
        checker.error(
            ("moves", last_on.index, "arc"),
            "the arc is switched on here and never off: add arc: off to the move after the "
            "seam (it switches off when that move starts, after the seam's dwell)",
        )


def read_payload(checker: Checker, data: dict) -> Payload | None:
    """The ``tool:``'s ``payload: {mass: KG, cog: [x, y, z]}``, or None (absent or invalid)."""
    tool = data.get("tool")
    if not isinstance(tool, dict) or "payload" not in tool:
        return None
    path: KeyPath = ("tool", "payload")
    spec = tool["payload"]
    example = "{mass: 1.2, cog: [0, 0, 0.08]} (kg; m in the flange frame)"
    if not isinstance(spec, dict):
        checker.error(path, f"expected a mapping such as {example}, got {describe(spec)}")
        return None
    ok = True
    for key in spec:
        if key not in PAYLOAD_KEYS:
            checker.error(path + (str(key),), f"unknown key {key!r}; expected mass and cog")
            ok = False
    if "mass" not in spec:
        checker.error(path, f"a payload needs mass (e.g. {example})")
        return None
    mass = spec["mass"]
    number = to_float(mass) if is_number(mass) else math.nan
    if not 0.0 <= number <= MAX_PAYLOAD:
        checker.error(
            path + ("mass",),
            f"expected a mass >= 0 kg (at most {MAX_PAYLOAD:g}: more is a unit mistake), got "
            f"{describe(mass)}",
        )
        ok = False
    cog = (0.0, 0.0, 0.0)
    if "cog" in spec:
        values = checker.numbers(
            spec["cog"], path + ("cog",), 3, "the centre of gravity x, y, z in the flange "
            "frame [m]", bound=10.0,
        )  # fmt: skip
        if values is None:
            ok = False
        else:
            cog = (float(values[0]), float(values[1]), float(values[2]))
    return Payload(number, cog) if ok else None


def read_colors(checker: Checker, data: dict) -> dict[str, str]:
    """The ``color: "#rrggbb"`` of each obstacle that gives one (lower case)."""
    obstacles = data.get("obstacles")
    colors: dict[str, str] = {}
    if not isinstance(obstacles, dict):
        return colors
    for name, entry in obstacles.items():
        if not isinstance(entry, dict) or "color" not in entry:
            continue
        value = entry["color"]
        if isinstance(value, str) and _COLOR.match(value.strip()):
            colors[str(name)] = value.strip().lower()
        else:
            checker.error(
                ("obstacles", str(name), "color"),
                f'expected a colour "#rrggbb" (6 hex digits, quoted in YAML), got '
                f"{describe(value)}",
            )
    return colors
