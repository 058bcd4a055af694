"""Reading a program file: YAML to a validated :class:`~kinplan.program.Program`.

:func:`load_program` and :func:`parse_program` read the whole file and raise one
:class:`~kinplan.program.ProgramError` listing every problem with its key path (``moves[2].lin``)
and YAML line. The sections are read by :mod:`~kinplan.program.robot_keys`,
:mod:`~kinplan.program.points` and :mod:`~kinplan.program.moves`.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import yaml

from kinplan import checks
from kinplan.errors import InputError
from kinplan.program.cell_keys import read_cell
from kinplan.program.checker import Checker, describe, format_path
from kinplan.program.errors import Issue, ProgramError
from kinplan.program.moves import read_moves
from kinplan.program.points import read_points, read_start
from kinplan.program.process import (
    check_signals,
    read_arc_output,
    read_colors,
    read_job_output,
    read_payload,
)
from kinplan.program.robot_keys import read_robot
from kinplan.program.schema import TOP_KEYS, KeyPath, Move, Program, ProgramLoader

__all__ = ["load_program", "parse_program"]


def load_program(path: str | os.PathLike[str]) -> Program:
    """Read and validate a program file.

    Args:
        path: The YAML file (UTF-8); a URDF path in it is relative to the file's folder.

    Returns:
        The validated program.

    Raises:
        ProgramError: the file is missing, unreadable, not UTF-8 text, not YAML, or invalid
            (every problem is listed with its key path and line).
        InputError: ``path`` is not a file path (str or os.PathLike).
    """
    file = Path(checks.file_path(path, "path (the program file)"))
    try:
        raw = file.read_bytes()
    except OSError as exc:
        reason = exc.strerror or str(exc)
        issue = Issue("program", f"cannot read the file: {reason}")
        raise ProgramError(str(file), [issue]) from exc
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        issue = Issue(
            "program",
            f"the file is not UTF-8 text (byte 0x{raw[exc.start]:02x} at offset {exc.start}); "
            "save it with UTF-8 encoding",
            line,
        )
        raise ProgramError(str(file), [issue]) from None
    return parse_program(text, base_dir=file.parent, source=str(file))


def parse_program(
    text: str,
    base_dir: str | os.PathLike[str] | None = None,
    source: str = "<string>",
) -> Program:
    """Parse and validate the YAML text of a program.

    Args:
        text: The program.
        base_dir: Folder that relative URDF paths are taken from (default: current directory).
        source: Name used in messages.

    Returns:
        The validated program.

    Raises:
        ProgramError: listing every problem found.
        InputError: ``text`` is not a string, ``base_dir`` not a path, ``source`` not a string.
    """
    source = checks.text(source, "source (the program's name in messages)")
    if not isinstance(text, str):
        raise InputError(f"text must be the program's YAML text (a str), got {describe(text)}")
    if base_dir is not None:
        base_dir = checks.file_path(base_dir, "base_dir (the folder of relative URDF paths)")
    try:
        node = yaml.compose(text, Loader=ProgramLoader)
        data = yaml.load(text, Loader=ProgramLoader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = mark.line + 1 if mark is not None else None
        problem = getattr(exc, "problem", None) or (str(exc).splitlines() or ["?"])[0]
        raise ProgramError(source, [Issue("program", f"not valid YAML: {problem}", line)]) from exc
    except RecursionError:
        issue = Issue("program", "nested too deeply to read; flatten the lists and mappings")
        raise ProgramError(source, [issue]) from None
    except (ValueError, OverflowError) as exc:  # a value PyYAML cannot build (a bad date, say)
        issue = Issue("program", f"a value cannot be read: {exc}; write it as a number or text")
        raise ProgramError(source, [issue]) from None
    lines: dict[KeyPath, int] = {}
    duplicates: list[tuple[KeyPath, str, int]] = []
    if node is not None:
        _index_lines(node, (), lines, duplicates, set())
    checker = Checker(lines)
    for path, key, line in duplicates:
        checker.issues.append(
            Issue(format_path(path), f"duplicate key {key!r}; each key may appear once", line)
        )
    program = _read_program(
        checker, data, source, Path(base_dir) if base_dir is not None else Path.cwd()
    )
    if checker.issues or program is None:
        issues = sorted(checker.issues, key=lambda issue: issue.line or math.inf)
        raise ProgramError(source, issues)
    return program


def _index_lines(
    node: yaml.Node,
    path: KeyPath,
    lines: dict[KeyPath, int],
    duplicates: list[tuple[KeyPath, str, int]],
    visited: set[int],
) -> None:
    """Record the 1-based line of every key path of the YAML node tree (and duplicate keys).

    A node reached again through an alias (``*name``) is not walked twice: aliases can make the
    tree cyclic or exponentially large.
    """
    lines[path] = node.start_mark.line + 1
    if id(node) in visited:
        return
    visited.add(id(node))
    if isinstance(node, yaml.MappingNode):
        seen = set()
        for key_node, value_node in node.value:
            key = str(key_node.value) if isinstance(key_node, yaml.ScalarNode) else "<complex key>"
            if key in seen:
                duplicates.append((path + (key,), key, key_node.start_mark.line + 1))
            seen.add(key)
            _index_lines(value_node, path + (key,), lines, duplicates, visited)
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            _index_lines(item, path + (i,), lines, duplicates, visited)


def _read_program(checker: Checker, data: object, source: str, base_dir: Path) -> Program | None:
    """The program of the parsed YAML, or None when a problem was reported."""
    if not isinstance(data, dict):
        checker.error(
            (),
            "expected a mapping with robot, start, points and moves at the top level, got "
            f"{describe(data)}",
        )
        return None
    for key in data:
        if str(key) not in TOP_KEYS:
            checker.error((str(key),), f"unknown key {key!r}; expected keys: {', '.join(TOP_KEYS)}")
    robot_source, robot = read_robot(checker, data, base_dir)
    robot, cell, clearance = read_cell(checker, data, base_dir, robot)
    start = read_start(checker, robot, data)
    points = read_points(checker, robot, data.get("points"), start)
    nq = robot.nq if robot is not None else None
    max_acceleration = None
    if "max_acceleration" in data:
        where: KeyPath = ("max_acceleration",)
        max_acceleration = checker.accelerations(data["max_acceleration"], where, nq)
    moves = read_moves(checker, data.get("moves"), points, nq)
    avoid = _read_avoid(checker, data, moves)
    arc_output = read_arc_output(checker, data)
    job_output = read_job_output(checker, data, arc_output)
    check_signals(checker, moves, arc_output, points, job_output)
    payload, colors = read_payload(checker, data), read_colors(checker, data)
    description = data.get("description", "")
    if not isinstance(description, str):
        checker.error(("description",), f"expected text, got {describe(description)}")
    if checker.issues or robot is None or start is None:
        return None
    return Program(
        source=source,
        robot=robot,
        robot_source=robot_source,
        start=start,
        points=points,
        moves=moves,
        description=description or "",
        warnings=checker.warnings,
        cell=cell,
        clearance=clearance,
        payload=payload,
        obstacle_colors=colors,
        arc_output=arc_output,
        job_output=job_output,
        avoid=avoid,
        max_acceleration=None if max_acceleration is None else np.broadcast_to(
            np.asarray(max_acceleration, dtype=float), (robot.nq,)
        ).copy(),
    )  # fmt: skip


def _read_avoid(checker: Checker, data: dict, moves: list[Move]) -> bool:
    """The program's ``avoid:`` (default false); a ptp it applies to may not have a duration."""
    value = data.get("avoid", False)
    if not isinstance(value, bool):
        checker.error(("avoid",), f"expected true or false, got {describe(value)}")
        return False
    for move in moves if value else []:
        if move.kind == "ptp" and not move.through and move.avoid is None:
            for key in ("duration", "times"):
                if getattr(move, key) is not None:
                    checker.error(
                        ("moves", move.index, key),
                        "the program's avoid: true plans this ptp around the obstacles, timed "
                        f"by the joint limits: remove {key}, or give the move avoid: false",
                    )
    return value
