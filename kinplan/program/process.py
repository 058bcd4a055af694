"""A program's process keys: the arc, weld job and digital outputs of its moves and points,
the tool's payload and the obstacles' colours.

On a move (it takes effect when the move starts, after the previous move's dwell) or on a
taught point (it takes effect when a move arrives at the point: at the end of that move's
motion, the arm at rest there, before the move's dwell; every move that ends at the point sets
it again)::

    arc: on                          # or off: switches the arc output (arc_output:, default 0)
    weld: {job: 3}                   # arc on with the power source's weld job 3 (0..255)
    io: {output: 3, value: 1}        # a standard digital output 0..7 set to 0 or 1 (or a list)

At the top level: ``arc_output: N`` (the digital output the arc is on, 0..7), ``job_output:``
(where a weld job number is written: ``{register: N}``, the integer output register N = 0..47,
the default being register 0; or ``{outputs: [4, 5, 6, 7]}``, standard digital outputs in
binary, least significant bit first), ``tool: {..., payload: {mass: KG, cog: [x, y, z]}}``
(the centre of gravity in the flange frame [m]) and ``color: "#rrggbb"`` on an obstacle (its
colour in the playback). At one instant the job is written first, then the arc, then ``io:``.

A signal on a move that another move blends into has no instant of its own (the tool passes the
corner without stopping) and is refused, as is a signal on a point that a move passes without
stopping (the target of a move with ``blend:``, a ``circ``'s ``via``, a ``ptp``'s
``through``); so are an ``arc: on`` (or ``weld:``) while the arc is on, an ``arc: off`` while
it is off, ``arc:`` and ``weld:`` together, an ``io:`` on the arc's output or a job output, a
job number the job outputs cannot hold and a program that ends with the arc on. A point with a
signal that no move ends at is reported as a warning (the signal never takes effect).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import NamedTuple

from kinplan.program.checker import Checker, describe, is_number, to_float
from kinplan.program.schema import IoEvent, JobOutput, KeyPath, Move, Payload, Point

__all__ = [
    "DIGITAL_OUTPUTS",
    "INTEGER_REGISTERS",
    "IO_KEYS",
    "MAX_JOB",
    "PAYLOAD_KEYS",
    "Signals",
    "check_signals",
    "read_arc_output",
    "read_colors",
    "read_job_output",
    "read_payload",
    "read_signals",
    "signal_events",
]

DIGITAL_OUTPUTS = range(8)
"""The standard digital outputs a program may set (a Universal Robots controller's 0 to 7)."""
INTEGER_REGISTERS = range(48)
"""The integer output registers a weld job may be written to (URScript's
``write_output_integer_register`` addresses 0 to 47)."""
MAX_JOB = 255
"""Largest weld job number of ``weld: {job: N}`` (a power source's stored parameter sets)."""
IO_KEYS = ("output", "value")
"""The keys of a move's ``io:``."""
PAYLOAD_KEYS = ("mass", "cog")
"""The keys of a tool's ``payload:`` (``mass`` required)."""
MAX_PAYLOAD = 1000.0
"""Largest payload mass accepted [kg]: beyond is a unit mistake (the largest UR carries 30)."""
_COLOR = re.compile(r"^#[0-9A-Fa-f]{6}$")
_ARC_WORDS = {"on": True, "off": False}


class Signals(NamedTuple):
    """The signals of a move or point: ``arc`` (True / False / None), ``io`` ((output, value)
    pairs) and ``job`` (the weld job of ``weld: {job: N}``, which sets ``arc`` True, or None)."""

    arc: bool | None
    io: tuple[tuple[int, bool], ...]
    job: int | None


def read_signals(checker: Checker, spec: dict, path: KeyPath) -> Signals | None:
    """A move's or point's ``arc:``, ``weld:`` and ``io:``.

    Args:
        checker: Collects the problems.
        spec: The move's or point's mapping.
        path: Its key path (``("moves", 2)``, ``("points", "a")``).

    Returns:
        The signals, or None after reporting.
    """
    ok = True
    arc = None
    job = None
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
    if "weld" in spec:
        job = _weld(checker, spec["weld"], path + ("weld",))
        ok &= job is not None
        if job is not None and "arc" in spec:
            checker.error(
                path + ("arc",),
                "weld: {job: N} switches the arc on here; remove arc: (and switch the arc off "
                "with arc: off on a later move or point)",
            )
            ok = False
        arc = True if job is not None else arc
    return Signals(arc, tuple(io), job) if ok else None


def _weld(checker: Checker, value: object, path: KeyPath) -> int | None:
    """The job number of a ``weld: {job: N}``, or None after reporting."""
    example = f"{{job: 3}} (arc on with the power source's weld job 3; 0 to {MAX_JOB})"
    if not isinstance(value, dict):
        also = "; switch the arc off with arc: off" if isinstance(value, bool) else ""
        checker.error(path, f"expected {example}, got {describe(value)}{also}")
        return None
    ok = True
    for key in value:
        if key != "job":
            checker.error(path + (str(key),), f"unknown key {key!r}; expected job")
            ok = False
    if "job" not in value:
        checker.error(path, f"weld needs job, e.g. {example}")
        return None
    job = value["job"]
    if not (is_number(job) and float(job).is_integer() and 0 <= job <= MAX_JOB):
        checker.error(
            path + ("job",),
            f"expected a weld job number, an integer 0 to {MAX_JOB} (the power source's stored "
            f"parameter set), got {describe(job)}",
        )
        ok = False
    return int(job) if ok else None


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


def read_job_output(checker: Checker, data: dict, arc_output: int) -> JobOutput:
    """The top-level ``job_output:`` (default: the integer output register 0)."""
    if "job_output" not in data:
        return JobOutput()
    path: KeyPath = ("job_output",)
    spec = data["job_output"]
    expected = (
        f"{{register: N}} (an integer output register {INTEGER_REGISTERS.start} to "
        f"{INTEGER_REGISTERS.stop - 1}) or {{outputs: [4, 5, 6, 7]}} (standard digital outputs "
        "holding the job in binary, least significant bit first)"
    )
    if not isinstance(spec, dict) or len(spec) != 1 or not {"register", "outputs"} & set(spec):
        checker.error(path, f"expected {expected}, got {describe(spec)}")
        return JobOutput()
    if "register" in spec:
        value = spec["register"]
        if is_number(value) and float(value).is_integer() and int(value) in INTEGER_REGISTERS:
            return JobOutput(register=int(value))
        checker.error(path + ("register",), f"expected {expected}, got {describe(value)}")
        return JobOutput()
    values = spec["outputs"]
    outputs: list[int] = []
    for value in values if isinstance(values, list) else []:
        if is_number(value) and float(value).is_integer() and int(value) in DIGITAL_OUTPUTS:
            outputs.append(int(value))
    if not isinstance(values, list) or not values or len(outputs) != len(values):
        checker.error(path + ("outputs",), f"expected {expected}, got {describe(values)}")
        return JobOutput()
    if len(set(outputs)) != len(outputs):
        checker.error(path + ("outputs",), f"an output is listed twice in {outputs}")
    if arc_output in outputs:
        checker.error(
            path + ("outputs",),
            f"output {arc_output} is the arc's (arc_output: {arc_output}); give the job other "
            "outputs, or set arc_output: to another output",
        )
    return JobOutput(register=None, outputs=tuple(outputs))


@dataclass(frozen=True)
class _Site:
    """An instant signals are set at: a move's start or its arrival at its target point."""

    path: KeyPath  # ("moves", 2) or ("points", "b")
    signals: Signals
    label: str  # "moves[2]" or "points.b (reached by moves[2])"


def check_signals(
    checker: Checker,
    moves: list[Move],
    arc_output: int,
    points: dict[str, Point] | None = None,
    job_output: JobOutput | None = None,
) -> None:
    """Signals across the moves and the points they arrive at: one instant each, the arc
    switched on and off in turn, outputs not shared with the arc or the weld job.

    Args:
        checker: Collects the problems.
        moves: The program's valid moves, in order.
        arc_output: The arc's digital output.
        points: The taught points by name (their ``arc:``, ``io:``, ``weld:``), or None.
        job_output: Where weld jobs are written (default: integer register 0).
    """
    points = points or {}
    job_output = job_output or JobOutput()
    sites: list[_Site] = []
    reached: set[str] = set()
    for number, move in enumerate(moves):
        if move.arc is not None or move.io:
            sites.append(_Site(("moves", move.index), Signals(move.arc, move.io, move.job),
                               f"moves[{move.index}]"))  # fmt: skip
        passed = [*move.through, *([move.via] if move.via is not None else [])]
        blends_on = move.kind != "ptp" and move.blend is not None
        if blends_on and number + 1 < len(moves) and moves[number + 1].index == move.index + 1:
            passed.append(move.target)
        else:
            reached.add(move.target)
            point = points.get(move.target)
            if point is not None and (point.arc is not None or point.io):
                label = f"points.{point.name} (reached by moves[{move.index}])"
                signals = Signals(point.arc, point.io, point.job)
                sites.append(_Site(("points", point.name), signals, label))
        for name in passed:
            point = points.get(name)
            if point is not None and (point.arc is not None or point.io):
                checker.error(
                    ("points", name, _arc_key(point.job) if point.arc is not None else "io"),
                    f"moves[{move.index}] passes this point without stopping (a blend, a via or "
                    "a through point), so a signal here has no instant: put it on the point the "
                    "motion stops at, or on the move after",
                )
    for name, point in points.items():
        if (point.arc is not None or point.io) and name not in reached:
            checker.warn(
                ("points", name),
                "its signals never take effect: no move ends at this point",
            )
    _check_blended_into(checker, moves)
    for move in moves:
        _check_outputs(checker, ("moves", move.index), move.io, move.job, arc_output, job_output)
    for name, point in points.items():
        _check_outputs(checker, ("points", name), point.io, point.job, arc_output, job_output)
    _check_arc_sequence(checker, sites)


def _arc_key(job: int | None) -> str:
    return "arc" if job is None else "weld"


def _check_blended_into(checker: Checker, moves: list[Move]) -> None:
    """A move that the previous one blends into has no instant for its signals."""
    previous: Move | None = None
    for move in moves:
        blended_into = (
            previous is not None
            and previous.index == move.index - 1
            and previous.kind != "ptp"
            and previous.blend is not None
        )
        if blended_into and (move.arc is not None or move.io):
            key = _arc_key(move.job) if move.arc is not None else "io"
            checker.error(
                ("moves", move.index, key),
                f"moves[{move.index - 1}] blends into this move, so the tool passes its start "
                "without stopping and a signal there has no instant: put it on the first move "
                "of the blended seam (or remove blend from the move before)",
            )
        previous = move


def _check_outputs(
    checker: Checker,
    path: KeyPath,
    io: tuple[tuple[int, bool], ...],
    job: int | None,
    arc_output: int,
    job_output: JobOutput,
) -> None:
    """``io:`` off the arc's and the job's outputs; a job the job outputs can hold."""
    for output, _ in io:
        if output == arc_output:
            checker.error(
                path + ("io",),
                f"output {output} is the arc's (arc_output: {arc_output}); switch it with "
                "arc: on|off, or set arc_output: to another output",
            )
        elif output in job_output.outputs:
            checker.error(
                path + ("io",),
                f"output {output} holds a bit of the weld job (job_output: "
                f"{{outputs: {list(job_output.outputs)}}}); set it with weld: {{job: N}}, or "
                "give the job other outputs",
            )
    bits = len(job_output.outputs)
    if job is not None and bits and job >= 2**bits:
        checker.error(
            path + ("weld", "job"),
            f"job {job} needs {job.bit_length()} bits but job_output: has {bits} output"
            f"{'s' if bits > 1 else ''} {list(job_output.outputs)} (jobs 0 to {2**bits - 1}); "
            "add outputs, or write the job to a register: job_output: {register: N}",
        )


def _check_arc_sequence(checker: Checker, sites: list[_Site]) -> None:
    """The arc switched on and off in turn, off at the end of the program."""
    arc_on = False
    last_on: _Site | None = None
    for site in sites:
        arc = site.signals.arc
        key = site.path + (_arc_key(site.signals.job),)
        if arc is True and arc_on:
            since = last_on.label if last_on else "?"
            checker.error(
                key,
                f"the arc is already on (since {since}); remove this "
                f"{'weld:' if site.signals.job is not None else 'arc: on'} or switch it off "
                "before",
            )
        elif arc is False and not arc_on:
            where = "" if site.path[0] == "moves" else f" ({site.label})"
            checker.error(key, f"the arc is not on here{where}; remove arc: off")
        if arc is not None:
            arc_on = arc
            last_on = site if arc else last_on
    if arc_on and last_on is not None:
        checker.error(
            last_on.path + (_arc_key(last_on.signals.job),),
            f"the arc is switched on here ({last_on.label}) and never off: add arc: off to the "
            "move after the seam (it switches off when that move starts, after the seam's "
            "dwell) or to the point the seam ends at (off on arrival, before the dwell)",
        )


def signal_events(
    signals: Signals, t: float, move: int, key: str, arc_output: int, job_output: JobOutput
) -> list[IoEvent]:
    """The output events of one move's or point's signals at program time ``t`` [s]: the weld
    job (a register write, or one event per job output bit), then the arc, then ``io:``.

    Args:
        signals: The move's or point's signals.
        t: Program time they take effect [s].
        move: 1-based number of the move (that starts, or arrives at the point).
        key: Key path of the move or point (``moves[2]``, ``points.b``).
        arc_output: The arc's digital output.
        job_output: Where weld jobs are written.
    """
    events = []
    if signals.job is not None:
        job, where = signals.job, f"{key}.weld"
        if job_output.register is not None:
            events.append(IoEvent(t, job_output.register, job, "job", move, where, job, True))
        for bit, output in enumerate(job_output.outputs):
            events.append(IoEvent(t, output, bool(job >> bit & 1), "job", move, where, job))
    if signals.arc is not None:
        where = f"{key}.{_arc_key(signals.job)}"
        events.append(IoEvent(t, arc_output, signals.arc, "arc", move, where))
    for output, value in signals.io:
        events.append(IoEvent(t, output, value, "io", move, f"{key}.io"))
    return events


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
