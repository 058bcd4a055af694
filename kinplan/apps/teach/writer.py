"""The taught program: its YAML text (start, points and path knots as joint values, a ``ptp`` to
each point and one ``ptp`` through each path's knots, in teaching order) and the file."""

from __future__ import annotations

import logging
import os
import textwrap
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from kinplan import checks
from kinplan.apps.teach.paths import decimals
from kinplan.apps.teach.state import PendantState
from kinplan.errors import KinplanError

logger = logging.getLogger("kinplan.teach")  # the package's name, as in the log lines before


class ProgramWriter(PendantState):
    """Writes what the pendant recorded as a program."""

    def program_text(self, output: str | os.PathLike[str] | None = None) -> str:
        """The program as YAML: start, the recorded points and path knots as joints, then in
        teaching order a ``ptp`` to each point and, for each path, a ``ptp`` to its first knot
        when the arm is elsewhere, then one ``ptp`` from there through the other knots
        (``profile: spline``, ``times:`` those of :attr:`RecordedPath.times`: when it passes
        each, from its start; a path of two knots is the same motion as a ``ptp`` with
        ``profile: cubic`` and that ``duration``).

        Args:
            output: Where the program will be written; a URDF robot source is written relative
                to its folder.

        Raises:
            KinplanError: nothing recorded yet, or a path still being recorded.
            InputError: ``output`` is not a file path.
        """
        if output is not None:
            output = checks.file_path(output, "output (the program file)")
        if self._recording is not None:
            raise KinplanError("a path is being recorded; rec stop stores it before writing")
        if not self._order:
            raise KinplanError(
                "no point recorded (r [name]) and no path (rec start ... rec stop); record one "
                "before writing"
            )
        stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
        lines = [
            f"# Taught with `kinplan teach` on {stamp}.",
            "# Points are the recorded joint values; run with `kinplan run <this file>`.",
            f"robot: {_yaml_scalar(self._robot_entry(output))}",
            f"tip: {_yaml_scalar(self.flange_robot.tip_frame)}",
            *self._locked_lines(),
            *self._tool_lines(),
            *self.cell_lines,
            f"start: {{joints_deg: {_degrees(self.start)}}}",
            "points:",
        ]
        moves = []
        current = self.start
        for kind, name in self._order:
            if kind == "point":
                q = self.points[name]
                lines.append(f"  {name}: {{joints_deg: {_degrees(q)}}}  # tool at {self._at(q)}")
                spec = self.move_specs.get(name)
                moves.append(f"  - {spec.yaml(name) if spec is not None else f'{{ptp: {name}}}'}")
                current = q
                continue
            path = self.paths[name]
            names = path.point_names()
            for point, q, t in zip(names, path.knots, path.knot_times, strict=True):
                lines.append(
                    f"  {point}: {{joints_deg: {_degrees(q)}}}  # {name}, recorded at "
                    f"t = {t:.4f} s, tool at {self._at(q)}"
                )
            if _degrees(path.knots[0]) != _degrees(current):  # the spline starts where the arm is
                moves.append(f"  - {{ptp: {names[0]}}}  # to the start of {name}")
            timing = "their recorded times"
            if path.slowed:
                timing += f" stretched to {path.spline.duration:.3f} s (velocity limits)"
            moves.append(
                f"  # {name}: recorded {len(path.samples)} samples at {path.rate_hz:g} Hz over "
                f"{path.duration:.3f} s; a spline from {names[0]} through"
            )
            moves.append(
                f"  # the knots at {timing}, within {path.max_deviation:.2e} rad "
                f"({1000 * path.tool_deviation:.3f} mm at the tool)"
            )
            times = decimals(path.times)
            if len(names) == 2:  # the clamped cubic spline through two points: a cubic
                moves.append(
                    f"  - {{ptp: {names[1]}, name: {name}, profile: cubic, "
                    f"duration: {times[1:-1]}}}"
                )
            else:
                moves += _flow_list("  - ptp: ", names[1:])
                moves.append(f"    name: {name}")
                moves.append("    profile: spline")
                moves += _flow_list("    times: ", times[1:-1].split(", "))
            current = path.knots[-1]
        lines.append("moves:")
        lines += moves
        return "\n".join(lines) + "\n"

    def _at(self, q: np.ndarray) -> str:
        """The tool position at ``q``, for a comment [m]."""
        return "(" + ", ".join(f"{v:.4f}" for v in self.robot.fk(q).translation) + ") m"

    def _tool_lines(self) -> list[str]:
        """The program's ``tool:`` line (none without a pendant tool)."""
        if self.tool_pose is None:
            return []
        xyz, rpy = self.tool_pose
        return [
            f"tool: {{xyz: [{', '.join(f'{v:g}' for v in xyz)}], "
            f"rpy_deg: [{', '.join(f'{v:g}' for v in rpy)}]}}  # the TCP in the flange frame"
        ]

    def _locked_lines(self) -> list[str]:
        """The program's ``locked_joints:`` line (none when no joint is locked)."""
        locked = self.robot.locked_joints
        if not locked:
            return []
        entries = ", ".join(
            f"{_yaml_scalar(name)}: {float(value)!r}" for name, value in locked.items()
        )
        return [f"locked_joints: {{{entries}}}  # [rad or m]"]

    def _robot_entry(self, output: str | os.PathLike[str] | None) -> str:
        source = self.robot_source
        path = Path(source)
        if output is None or not path.is_file():
            return source
        try:
            return os.path.relpath(path.resolve(), Path(output).resolve().parent)
        except ValueError:  # another drive (Windows)
            return str(path.resolve())

    def save(self, output: str | os.PathLike[str]) -> Path:
        """Write :meth:`program_text` to ``output`` (its folder is created).

        Raises:
            KinplanError: nothing recorded yet, a path still being recorded, or the file
                cannot be written.
            InputError: ``output`` is not a file path.
        """
        target = Path(checks.file_path(output, "output (the program file)"))
        text = self.program_text(target)
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_text(text, encoding="utf-8")
        except OSError as exc:
            raise KinplanError(f"cannot write the program {target}: {exc}") from exc
        logger.info("wrote %s", target)
        return target


def _degrees(q: np.ndarray) -> str:
    """Joint values as a YAML list of degrees, to 1e-6° (no "-0")."""
    return decimals(np.degrees(q))


def _flow_list(start: str, items: list[str]) -> list[str]:
    """``start`` then ``items`` as a YAML flow list, wrapped to lines of 100 characters."""
    indent = " " * (len(start) + 1)
    chunks = textwrap.wrap(", ".join(items), 99 - len(indent), break_long_words=False)
    lines = [indent + chunk for chunk in chunks]
    lines[0] = start + "[" + chunks[0]
    lines[-1] += "]"
    return lines


def _yaml_scalar(text: str) -> str:
    """``text`` as a YAML scalar (quoted when plain style would change its meaning)."""
    import yaml

    return yaml.safe_dump(text, default_style=None).splitlines()[0].removesuffix(" ...")
