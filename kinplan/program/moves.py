"""The ``moves:`` of a program: kinds, target and via points, and options."""

from __future__ import annotations

from kinplan._profiles import PROFILES, PTP_PROFILES
from kinplan.program.checker import Checker, describe
from kinplan.program.schema import MOVE_KINDS, MOVE_OPTIONS, KeyPath, Move, Point

__all__ = ["read_moves"]


def read_moves(checker: Checker, spec: object, points: dict[str, Point]) -> list[Move]:
    """The moves of a program.

    Args:
        checker: Collects the problems.
        spec: The ``moves:`` entry (None when absent).
        points: The program's points by name (the targets a move may name).

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
        move = _read_move(checker, index, item, points)
        if move is not None:
            moves.append(move)
    return moves


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


def _read_move(checker: Checker, index: int, spec: object, points: dict[str, Point]) -> Move | None:
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
    target = _point_name(checker, spec[kind], path + (kind,), points)
    via = None
    if kind == "circ":
        if "via" not in spec:
            checker.error(path, "a circ move needs via: <point> (the arc passes through it)")
        else:
            via = _point_name(checker, spec["via"], path + ("via",), points)
    elif "via" in spec:
        checker.error(path + ("via",), f"via only goes with circ, not {kind}")
    options = _move_options(checker, kind, spec, path)
    if target is None or options is None or (kind == "circ" and via is None):
        return None
    return Move(index, kind, target, via, **options)


def _move_options(checker: Checker, kind: str, spec: dict, path: KeyPath) -> dict | None:
    ok = True
    duration = speed = None
    if "duration" in spec:
        duration = checker.positive(spec["duration"], path + ("duration",), "duration [s]")
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
    profile = spec.get("profile", "trapezoid")
    profiles = PTP_PROFILES if kind == "ptp" else PROFILES
    if profile not in profiles:
        only_ptp = " (scurve and time_optimal time ptp moves only)"
        checker.error(
            path + ("profile",),
            f"unknown profile {describe(profile)}; expected one of {', '.join(profiles)}"
            + (only_ptp if profile in PTP_PROFILES else ""),
        )
        ok = False
    name = spec.get("name")
    if name is not None and not isinstance(name, str):
        checker.error(path + ("name",), f"expected text, got {describe(name)}")
        ok = False
    if not ok:
        return None
    return {"duration": duration, "speed": speed, "profile": profile, "name": name}
