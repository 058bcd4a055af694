"""Process commands of the pendant (issue 30): the tool on the flange (``tool``), how the next
points are reached (``r NAME lin [SPEED]``, ``r NAME circ VIA [SPEED]``), the weld options of
those moves (``weave``, ``torch``) and the arc (``arc on|off``, on the next recorded move).

What they set is written by :mod:`kinplan.apps.teach.writer`: ``tool: {xyz, rpy_deg}`` and each
point's move, e.g. ``{lin: b, speed: 0.008, weave: {...}, torch: {...}, arc: on}``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pinocchio as pin

from kinplan.apps.teach.parsing import NAME
from kinplan.apps.teach.state import MoveSpec, PendantState, Reply
from kinplan.errors import KinplanError

__all__ = ["ProcessCommands"]

MAX_TOOL_OFFSET = 2.0
"""Largest TCP offset from the flange the pendant accepts [m]."""
MAX_SPEED = 2.0
"""Largest tool speed of a recorded lin/circ move [m/s]."""
WEAVE_PATTERNS = ("sine", "triangle", "trapezoid")


def _number(text: str, what: str, low: float, high: float) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"expected a number for {what}, got {text!r}") from None
    if not (math.isfinite(value) and low <= value <= high):
        raise ValueError(f"{what} must be between {low:g} and {high:g}, got {text}")
    return value


class ProcessCommands(PendantState):
    """The pendant's process commands (see the module docstring)."""

    def _tool(self, arguments: list[str]) -> Reply:
        """``tool X Y Z [R P Y]`` [m, deg] in the flange frame; ``tool off``; ``tool``."""
        if not arguments:
            if self.tool_pose is None:
                return Reply("no tool: the tool frame is the flange (tool X Y Z [R P Y] sets one)")
            return Reply(f"tool: {self._tool_text()}")
        if [a.lower() for a in arguments] == ["off"]:
            self.tool_pose = None
            self.robot = self.flange_robot
            if self.cell is not None:
                self.cell = self.cell.for_robot(self.robot)
            return Reply("tool removed: the tool frame is the flange")
        if len(arguments) not in (3, 6):
            raise ValueError("usage: tool X Y Z [R P Y]  (m, deg, in the flange frame) | tool off")
        xyz = [_number(a, "the TCP offset [m]", -MAX_TOOL_OFFSET, MAX_TOOL_OFFSET)
               for a in arguments[:3]]  # fmt: skip
        rpy = [_number(a, "the TCP angles [deg]", -360.0, 360.0) for a in arguments[3:]]
        rpy = rpy or [0.0, 0.0, 0.0]
        pose = pin.SE3(pin.rpy.rpyToMatrix(*np.radians(rpy)), np.array(xyz))
        self.robot = self.flange_robot.with_tool(pose)
        self.tool_pose = (tuple(xyz), tuple(rpy))
        if self.cell is not None:
            self.cell = self.cell.for_robot(self.robot)
        where = ", ".join(f"{v:.4f}" for v in self.robot.fk(self.q).translation)
        return Reply(f"tool: {self._tool_text()}; the TCP is at ({where}) m")

    def use_cell(self, program: str | os.PathLike[str]) -> str:
        """Check every jog against the ``obstacles:`` (and ``clearance:``) of a program file and
        write them into the taught program (mesh paths made absolute).

        Returns:
            A one-line description of the cell.

        Raises:
            KinplanError: the file cannot be read, has no obstacles, or they are invalid.
        """
        import yaml

        from kinplan.program.cell_keys import read_cell
        from kinplan.program.checker import Checker
        from kinplan.program.schema import ProgramLoader

        file = Path(program)
        try:
            data = yaml.load(file.read_text(encoding="utf-8"), Loader=ProgramLoader)
        except (OSError, yaml.YAMLError) as exc:
            raise KinplanError(f"cannot read the cell of {file}: {exc}") from None
        if not isinstance(data, dict) or not isinstance(data.get("obstacles"), dict):
            raise KinplanError(f"{file} has no obstacles: mapping to check the jogs against")
        keys = {key: data[key] for key in ("obstacles", "clearance") if key in data}
        checker = Checker({})
        _, cell, clearance = read_cell(checker, keys, file.resolve().parent, self.robot)
        if checker.issues or cell is None:
            problems = "; ".join(f"{i.path}: {i.message}" for i in checker.issues)
            raise KinplanError(f"the cell of {file} cannot be used: {problems or 'invalid'}")
        obstacles = {}
        for name, entry in keys["obstacles"].items():
            entry = dict(entry)
            if isinstance(entry.get("mesh"), str):
                mesh = Path(entry["mesh"]).expanduser()
                entry["mesh"] = str(mesh if mesh.is_absolute() else file.resolve().parent / mesh)
            obstacles[str(name)] = entry
        self.cell, self.clearance = cell, float(clearance)
        lines = yaml.safe_dump({"obstacles": obstacles}, sort_keys=False, width=10**6)
        self.cell_lines = lines.rstrip("\n").splitlines()
        if "clearance" in keys:
            self.cell_lines.append(f"clearance: {self.clearance:g}")
        if not cell.check_motion(self.q[None, :], self.clearance).ok:
            raise KinplanError(
                f"the start configuration collides with the cell of {file}; give --start"
            )
        return (
            f"cell of {file.name}: {', '.join(obstacles)} (jogs are checked, clearance "
            f"{1e3 * self.clearance:g} mm)"
        )

    def _tool_text(self) -> str:
        assert self.tool_pose is not None
        xyz, rpy = self.tool_pose
        return (
            f"xyz [{', '.join(f'{v:g}' for v in xyz)}] m, rpy [{', '.join(f'{v:g}' for v in rpy)}]"
            " deg in the flange frame"
        )

    def _weave(self, arguments: list[str]) -> Reply:
        """``weave PATTERN AMPLITUDE_MM FREQUENCY_HZ`` for the next lin/circ moves;
        ``weave off``."""
        if [a.lower() for a in arguments] == ["off"]:
            self.weave = None
            return Reply("weave off")
        if len(arguments) != 3 or arguments[0].lower() not in WEAVE_PATTERNS:
            raise ValueError(
                f"usage: weave {'|'.join(WEAVE_PATTERNS)} <amplitude mm> <frequency Hz> | weave off"
            )
        amplitude = _number(arguments[1], "the weave amplitude [mm]", 0.01, 50.0)
        frequency = _number(arguments[2], "the weave frequency [Hz]", 0.01, 50.0)
        self.weave = (arguments[0].lower(), amplitude / 1000.0, frequency)
        return Reply(
            f"weave {arguments[0].lower()} ±{amplitude:g} mm at {frequency:g} Hz on the next "
            "lin/circ moves (weave off ends it)"
        )

    def _torch(self, arguments: list[str]) -> Reply:
        """``torch WORK_DEG TRAVEL_DEG`` for the next lin/circ moves; ``torch off``."""
        if [a.lower() for a in arguments] == ["off"]:
            self.torch = None
            return Reply("torch angles off")
        if len(arguments) != 2:
            raise ValueError("usage: torch <work angle deg> <travel angle deg> | torch off")
        work = _number(arguments[0], "the work angle [deg]", -89.0, 89.0)
        travel = _number(arguments[1], "the travel angle [deg]", -89.0, 89.0)
        self.torch = (work, travel)
        return Reply(
            f"torch at {work:g}° work, {travel:g}° travel angle on the next lin/circ moves "
            "(torch off ends it)"
        )

    def _arc(self, arguments: list[str]) -> Reply:
        """``arc on|off``: the next recorded move switches the arc when it starts."""
        if len(arguments) != 1 or arguments[0].lower() not in ("on", "off"):
            raise ValueError("usage: arc on | arc off")
        self.arc = arguments[0].lower()
        return Reply(f"arc {self.arc} when the next recorded move starts")

    def _move_spec(self, arguments: list[str]) -> MoveSpec:
        """The move of ``r NAME [ptp | lin [SPEED] | circ VIA [SPEED]]`` (after the name),
        with the weave, torch and arc set; the arc is used up."""
        kind = arguments[0].lower() if arguments else "ptp"
        rest = arguments[1:]
        if kind not in ("ptp", "lin", "circ"):
            raise ValueError("usage: r [name] [ptp | lin [speed m/s] | circ <via> [speed m/s]]")
        via = None
        if kind == "circ":
            if not rest or not NAME.match(rest[0]) or rest[0] not in self.points:
                known = ", ".join(self.points) or "none yet"
                raise ValueError(
                    f"a circ needs a recorded via point: r NAME circ VIA; known: {known}"
                )
            via, rest = rest[0], rest[1:]
        speed = None
        if rest and kind != "ptp":
            speed = _number(rest[0], "the tool speed [m/s]", 1e-4, MAX_SPEED)
            rest = rest[1:]
        if rest:
            raise ValueError("usage: r [name] [ptp | lin [speed m/s] | circ <via> [speed m/s]]")
        tool_move = kind != "ptp"
        spec = MoveSpec(
            kind, via, speed, self.weave if tool_move else None,
            self.torch if tool_move else None, self.arc,
        )  # fmt: skip
        self.arc = None
        return spec
