"""The ``moves:`` of a program: kinds, target and via points, and options."""

from __future__ import annotations

import math

import numpy as np

from cartesian.weave import WEAVE_PATTERNS
from kinplan.program.checker import Checker, describe, is_number, to_float
from kinplan.program.process import read_signals
from kinplan.program.schema import (
    MAX_SECONDS,
    MOVE_KINDS,
    MOVE_OPTIONS,
    THROUGH_PROFILES,
    TORCH_KEYS,
    WEAVE_KEYS,
    KeyPath,
    Move,
    Point,
    TorchSpec,
    WeaveSpec,
)
from kinplan.trajectory._profiles import PROFILES, PTP_PROFILES

__all__ = ["read_moves"]


def read_moves(
    checker: Checker, spec: object, points: dict[str, Point], nq: int | None = None
) -> list[Move]:
    """The moves of a program.

    Args:
        checker: Collects the problems.
        spec: The ``moves:`` entry (None when absent).
        points: The program's points by name (the targets a move may name).
        nq: The robot's number of joints (for ``max_acceleration:`` lists), or None.

    Returns:
        The valid moves, in order (an invalid move is reported and left out).
    """
    if spec is None:
        checker.error(("moves",), "missing; expected a list of moves such as {ptp: a}")
        return []
    if not isinstance(spec, list) or not spec:
        checker.error(("moves",), f"expected a non-empty list of moves, got {describe(spec)}")
        return []
    moves = []
    for index, item in enumerate(spec):
        move = _read_move(checker, index, item, points, nq)
        if move is not None:
            moves.append(move)
    _check_blends(checker, moves, len(spec))
    return moves


def _check_blends(checker: Checker, moves: list[Move], count: int) -> None:
    """A blended lin/circ needs a lin/circ after it; moves blended together share their timing."""
    by_index = {move.index: move for move in moves}
    for move in moves:
        if move.kind == "ptp" or move.blend is None:
            continue
        path: KeyPath = ("moves", move.index, "blend")
        after = by_index.get(move.index + 1)
        if move.index + 1 >= count:
            checker.error(path, "the last move has nothing to blend into; remove blend")
        elif after is not None and after.kind == "ptp":
            checker.error(path, "a lin/circ blends into the next lin or circ move, not into a ptp")
        elif after is not None:
            if move.dwell > 0:
                checker.error(
                    ("moves", move.index, "dwell"),
                    "a blended move does not stop at its end, so it cannot dwell there",
                )
            for key in ("speed", "profile", "weave", "torch", "max_acceleration"):
                if getattr(after, key) != getattr(move, key):
                    checker.error(
                        ("moves", after.index, key),
                        f"moves blended together are one motion: give the same {key} as "
                        f"moves[{move.index}] (or none on both)",
                    )
            if move.duration is not None or after.duration is not None:
                checker.error(
                    path,
                    "moves blended together are one motion at one tool speed: give speed, "
                    "not duration",
                )


def _point_name(
    checker: Checker, value: object, path: KeyPath, points: dict[str, Point]
) -> str | None:
    known = ", ".join(points) if points else "none (add a points: section)"
    if not isinstance(value, (str, int)) or isinstance(value, bool):
        checker.error(path, f"expected the name of a point; known points: {known}")
        return None
    if str(value) not in points:
        checker.error(path, f"unknown point {str(value)!r}; known points: {known}")
        return None
    return str(value)


def _read_move(
    checker: Checker, index: int, spec: object, points: dict[str, Point], nq: int | None = None
) -> Move | None:
    path: KeyPath = ("moves", index)
    expected = "a mapping such as {ptp: a}, {lin: b, speed: 0.05} or {circ: c, via: d}"
    if not isinstance(spec, dict):
        checker.error(path, f"expected {expected}, got {describe(spec)}")
        return None
    kinds = [key for key in MOVE_KINDS if key in spec]
    for key in spec:
        if key not in MOVE_KINDS and key not in MOVE_OPTIONS:
            checker.error(
                path + (str(key),),
                f"unknown key {key!r}; a move has one of {', '.join(MOVE_KINDS)} (with the "
                f"target point) and options {', '.join(MOVE_OPTIONS)}",
            )
    if len(kinds) != 1:
        found = f"got {', '.join(kinds)}" if kinds else "got none"
        checker.error(path, f"expected exactly one of {', '.join(MOVE_KINDS)}; {found}")
        return None
    kind = kinds[0]
    through: tuple[str, ...] = ()
    target: str | None
    if kind == "ptp" and isinstance(spec[kind], list):
        names = _point_list(checker, spec[kind], path + (kind,), points)
        if names is None:
            return None
        *before, target = names
        through = tuple(before)
    else:
        target = _point_name(checker, spec[kind], path + (kind,), points)
    via = None
    if kind == "circ":
        if "via" not in spec:
            checker.error(path, "a circ move needs via: <point> (the arc passes through it)")
        else:
            via = _point_name(checker, spec["via"], path + ("via",), points)
    elif "via" in spec:
        checker.error(path + ("via",), f"via only goes with circ, not {kind}")
    several = len(through) + 1 if through else 0
    options = _move_options(checker, kind, spec, path, several=several, nq=nq)
    if target is None or options is None or (kind == "circ" and via is None):
        return None
    return Move(index, kind, target, via, through=through, **options)


def _point_list(
    checker: Checker, value: list, path: KeyPath, points: dict[str, Point]
) -> list[str] | None:
    if not value:
        checker.error(path, "expected a point name or a non-empty list of point names")
        return None
    names = [_point_name(checker, item, path + (k,), points) for k, item in enumerate(value)]
    if any(name is None for name in names):
        return None
    return [name for name in names if name is not None]


def _move_options(
    checker: Checker, kind: str, spec: dict, path: KeyPath, several: int = 0,
    nq: int | None = None,
) -> dict | None:  # fmt: skip
    """The options of a move (``several``: the number of points of a ptp through several
    points, else 0; ``nq``: the robot's number of joints, or None); None after reporting a
    problem."""
    ok = True
    duration = speed = None
    if "duration" in spec:
        duration = _seconds(checker, spec["duration"], path + ("duration",), "duration")
        ok &= duration is not None
    if "speed" in spec:
        what = "share of the joint velocity limits, ≤ 1" if kind == "ptp" else "tool speed [m/s]"
        speed = checker.positive(spec["speed"], path + ("speed",), what)
        if speed is not None and kind == "ptp" and speed > 1.0:
            checker.error(
                path + ("speed",),
                f"for a ptp move, speed is the share of the joint velocity limits, "
                f"0 < speed ≤ 1; got {speed:g}",
            )
            speed = None
        ok &= speed is not None
    if duration is not None and speed is not None:
        checker.error(path, "give duration or speed, not both")
        ok = False
    profile = spec.get("profile", THROUGH_PROFILES[0] if several else "trapezoid")
    profiles = PTP_PROFILES if kind == "ptp" else PROFILES
    if several and profile not in THROUGH_PROFILES:
        checker.error(
            path + ("profile",),
            f"a ptp through several points is timed as one motion: profile "
            f"{' or '.join(THROUGH_PROFILES)}, got {describe(profile)}",
        )
        ok = False
    elif not several and profile not in profiles:
        only_ptp = " (scurve and time_optimal time ptp moves only)"
        checker.error(
            path + ("profile",),
            f"unknown profile {describe(profile)}; expected one of {', '.join(profiles)}"
            + (only_ptp if profile in PTP_PROFILES else ""),
        )
        ok = False
    blend = None
    if "blend" in spec:
        unit = "[rad]" if kind == "ptp" else "[m]"
        blend = _non_negative(checker, spec["blend"], path + ("blend",), f"blend {unit}")
        if blend is not None and kind == "ptp" and not (several and profile == "time_optimal"):
            checker.error(
                path + ("blend",),
                "blend on a ptp is the largest deviation [rad] from the corners of a ptp "
                "through several points with profile time_optimal, e.g. {ptp: [a, b, c], "
                "blend: 0.05}",
            )
            blend = None
        ok &= blend is not None
    weave = torch = None
    for key in ("weave", "torch"):
        if key in spec and kind == "ptp":
            checker.error(path + (key,), f"{key} goes with lin and circ moves, not ptp")
            ok = False
    if "weave" in spec and kind != "ptp":
        weave = _weave(checker, spec["weave"], path + ("weave",))
        if weave is not None and duration is not None:
            checker.error(
                path + ("duration",),
                "a weave's frequency is per second of travel: give the travel speed, not a "
                "duration",
            )
            weave = None
        ok &= weave is not None
    if "torch" in spec and kind != "ptp":
        torch = _torch(checker, spec["torch"], path + ("torch",))
        ok &= torch is not None
    times = None
    if "times" in spec:
        times = _times(checker, spec["times"], path + ("times",), several, profile, duration)
        ok &= times is not None
    dwell = 0.0
    if "dwell" in spec:
        value = _seconds(checker, spec["dwell"], path + ("dwell",), "dwell", zero=True)
        dwell = 0.0 if value is None else value
        ok &= value is not None
    max_acceleration = None
    if "max_acceleration" in spec:
        where = path + ("max_acceleration",)
        max_acceleration = checker.accelerations(spec["max_acceleration"], where, nq)
        ok &= max_acceleration is not None
    avoid = None
    if "avoid" in spec:
        avoid = _avoid(checker, spec, path, kind, several)
        ok &= avoid is not None
    signals = read_signals(checker, spec, path)
    ok &= signals is not None
    arc, io, job = signals if signals is not None else (None, (), None)
    name = spec.get("name")
    if name is not None and not isinstance(name, str):
        checker.error(path + ("name",), f"expected text, got {describe(name)}")
        ok = False
    if not ok:
        return None
    return {
        "duration": duration, "speed": speed, "profile": profile, "name": name, "blend": blend,
        "weave": weave, "torch": torch, "dwell": dwell, "times": times,
        "max_acceleration": max_acceleration, "arc": arc, "io": io, "avoid": avoid, "job": job,
    }  # fmt: skip


def _avoid(checker: Checker, spec: dict, path: KeyPath, kind: str, several: int) -> bool | None:
    """A move's ``avoid:`` (true or false); None after reporting a problem."""
    value = spec["avoid"]
    where = path + ("avoid",)
    if not isinstance(value, bool):
        checker.error(where, f"expected true or false, got {describe(value)}")
        return None
    if value and (kind != "ptp" or several):
        checker.error(
            where,
            "avoid: true plans a ptp to one point around the obstacles (kinplan.free_motion); "
            "lin, circ and ptp through several points follow their own path",
        )
        return None
    if value:
        for key in ("duration", "profile", "times"):
            if key in spec:
                checker.error(
                    path + (key,),
                    f"a ptp with avoid: true is timed time-optimally along the waypoints it "
                    f"finds, within the joint limits (scaled by speed); remove {key}",
                )
                return None
    return value


def _times(
    checker: Checker, value: object, path: KeyPath, count: int, profile: str,
    duration: float | None,
) -> tuple[float, ...] | None:  # fmt: skip
    """``times:`` of a spline through ``count`` points: one time per point, increasing, > 0."""
    if not count or profile != "spline":
        checker.error(
            path, "times go with a ptp through several points and profile spline, e.g. "
            "{ptp: [a, b, c], profile: spline, times: [1.0, 2.5, 4.0]}",
        )  # fmt: skip
        return None
    if duration is not None:
        checker.error(path, "give times or duration, not both (the last time is the duration)")
        return None
    numbers = checker.numbers(value, path, count, "the time [s] at each point", bound=MAX_SECONDS)
    if numbers is None:
        return None
    steps = np.diff(np.concatenate(([0.0], numbers)))
    if np.any(steps <= 0.0):
        k = int(np.argmax(steps <= 0.0))
        checker.error(
            path + (k,), f"times must increase from 0 (the move's start): {numbers[k]:g} s is "
            f"not after {0.0 if k == 0 else numbers[k - 1]:g} s",
        )  # fmt: skip
        return None
    return tuple(float(t) for t in numbers)


def _non_negative(checker: Checker, value: object, path: KeyPath, what: str) -> float | None:
    """A finite number ≥ 0 (``what``: its name and unit, for messages), or None after
    reporting."""
    if not is_number(value) or not math.isfinite(to_float(value)) or value < 0:
        checker.error(path, f"expected a number >= 0 ({what}), got {describe(value)}")
        return None
    return to_float(value)


def _seconds(
    checker: Checker, value: object, path: KeyPath, what: str, zero: bool = False
) -> float | None:
    """A time [s] in (0, :data:`MAX_SECONDS`] (``zero``: [0, ...]), or None after reporting."""
    number = to_float(value) if is_number(value) else math.nan
    if not ((number >= 0.0 if zero else number > 0.0) and number <= MAX_SECONDS):
        checker.error(
            path,
            f"expected a number {'>=' if zero else '>'} 0 ({what} [s], at most "
            f"{MAX_SECONDS:g}: more is a unit mistake), got {describe(value)}",
        )
        return None
    return number


def _mapping(checker: Checker, value: object, path: KeyPath, keys: tuple[str, ...],
             example: str) -> dict | None:  # fmt: skip
    if not isinstance(value, dict):
        checker.error(path, f"expected a mapping such as {example}, got {describe(value)}")
        return None
    unknown = [key for key in value if key not in keys]
    for key in unknown:
        checker.error(path + (str(key),), f"unknown key {key!r}; expected {', '.join(keys)}")
    return None if unknown else value


def _weave(checker: Checker, value: object, path: KeyPath) -> WeaveSpec | None:
    example = "{pattern: sine, amplitude: 0.002, frequency: 2.0}"
    spec = _mapping(checker, value, path, WEAVE_KEYS, example)
    if spec is None:
        return None
    ok = True
    for key in ("amplitude", "frequency"):
        if key not in spec:
            checker.error(path, f"a weave needs {key} (e.g. {example})")
            ok = False
    amplitude = frequency = None
    if "amplitude" in spec:
        amplitude = checker.positive(spec["amplitude"], path + ("amplitude",), "amplitude [m]")
    if "frequency" in spec:
        frequency = checker.positive(spec["frequency"], path + ("frequency",), "frequency [Hz]")
    pattern = spec.get("pattern", "sine")
    if pattern not in WEAVE_PATTERNS:
        checker.error(
            path + ("pattern",),
            f"unknown pattern {describe(pattern)}; expected one of {', '.join(WEAVE_PATTERNS)}",
        )
        ok = False
    dwell = _seconds(checker, spec.get("dwell", 0.0), path + ("dwell",), "dwell", zero=True)
    normal = None
    if "normal" in spec:
        normal = _direction(checker, spec["normal"], path + ("normal",))
        ok &= normal is not None
    if not ok or amplitude is None or frequency is None or dwell is None:
        return None
    return WeaveSpec(pattern, amplitude, frequency, dwell, normal)


def _torch(checker: Checker, value: object, path: KeyPath) -> TorchSpec | None:
    example = "{normal: [0, 0, 1], work_angle_deg: 45, travel_angle_deg: 10}"
    spec = _mapping(checker, value, path, TORCH_KEYS, example)
    if spec is None:
        return None
    normal: tuple[float, float, float] | None = (0.0, 0.0, 1.0)
    if "normal" in spec:
        normal = _direction(checker, spec["normal"], path + ("normal",))
    angles: list[float | None] = []
    for key, bound in (("work_angle_deg", 90.0), ("travel_angle_deg", 90.0), ("roll_deg", 360.0)):
        if key == "roll_deg" and key not in spec:
            angles.append(None)  # the roll is free: plan_seam searches it
            continue
        number = spec.get(key, 0.0)
        if not is_number(number) or not abs(to_float(number)) < bound:
            checker.error(
                path + (key,), f"expected a number of degrees strictly between -{bound:g} and "
                f"{bound:g} (exclusive), got {describe(number)}",
            )  # fmt: skip
            return None
        angles.append(math.radians(to_float(number)))
    tolerances = []
    for key in ("work_tolerance_deg", "travel_tolerance_deg"):
        number = spec.get(key, 0.0)
        if not is_number(number) or not 0.0 <= to_float(number) < 90.0:
            checker.error(
                path + (key,), f"expected a number of degrees from 0 to below 90 (the band the "
                f"torch axis may tilt within, e.g. {key}: 10), got {describe(number)}",
            )  # fmt: skip
            return None
        tolerances.append(math.radians(to_float(number)))
    if normal is None:
        return None
    work, travel, roll = angles
    assert work is not None and travel is not None
    return TorchSpec(normal, work, travel, roll, *tolerances)


def _direction(checker: Checker, value: object, path: KeyPath) -> tuple[float, float, float] | None:
    vector = checker.numbers(value, path, 3, "a direction x, y, z", bound=1e6)
    if vector is None:
        return None
    norm = float(np.linalg.norm(vector))
    if norm < 1e-9:
        checker.error(path, "expected a non-zero direction, got [0, 0, 0]")
        return None
    x, y, z = (float(v) for v in vector / norm)
    return (x, y, z)
