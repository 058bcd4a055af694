"""Reading a program's YAML values while collecting every problem with its key path and line.

A :class:`Checker` is shared by the readers of a program's sections
(:mod:`~kinplan.program.robot_keys`, :mod:`~kinplan.program.points`,
:mod:`~kinplan.program.moves`): each reports what is wrong with :meth:`Checker.error` and goes
on, so one :class:`~kinplan.program.ProgramError` lists every problem of the file.
"""

from __future__ import annotations

import math
import reprlib
from collections.abc import Mapping
from typing import TypeGuard

import numpy as np
import pinocchio as pin

from kinplan.program.errors import Issue
from kinplan.program.schema import MAX_ACCELERATION, MAX_COORDINATE, KeyPath

__all__ = ["Checker", "describe", "format_path", "is_number", "to_float"]

_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxlist, _REPR.maxdict, _REPR.maxstring, _REPR.maxother = 3, 6, 4, 40, 40


def format_path(path: KeyPath) -> str:
    """A key path as written in messages: ``moves[2].lin`` (``program`` for the whole file).

    Args:
        path: The keys and list indices from the top of the file.
    """
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text or "program"


def is_number(value: object) -> TypeGuard[int | float]:
    """Whether a YAML value is a number (an int or a float, not a boolean)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def to_float(value: float) -> float:
    """A YAML number as a float (an integer beyond the float range is inf)."""
    try:
        return float(value)
    except OverflowError:
        return math.inf


def describe(value: object) -> str:
    """A short repr (bounded in depth and length: a value may be a huge aliased structure)."""
    text = " ".join(_REPR.repr(value).split())
    return text if len(text) <= 60 else text[:57] + "..."


class Checker:
    """Collects the issues and warnings of one program file and reads checked values.

    Args:
        lines: The 1-based YAML line of every key path of the file.

    Attributes:
        lines: As given.
        issues: Every problem reported so far.
        warnings: Non-fatal remarks, ``key.path: message``.
    """

    def __init__(self, lines: Mapping[KeyPath, int]) -> None:
        self.lines = lines
        self.issues: list[Issue] = []
        self.warnings: list[str] = []

    # -- reporting ---------------------------------------------------------------------------
    def line(self, path: KeyPath) -> int | None:
        """The YAML line of a key path, or of its closest parent in the file (None if none)."""
        while path not in self.lines and path:
            path = path[:-1]
        return self.lines.get(path)

    def error(self, path: KeyPath, message: str) -> None:
        """Report a problem at a key path.

        Args:
            path: Where in the file.
            message: What is wrong and what is expected.
        """
        self.issues.append(Issue(format_path(path), message, self.line(path)))

    def warn(self, path: KeyPath, message: str) -> None:
        """Record a non-fatal remark about a key path."""
        self.warnings.append(f"{format_path(path)}: {message}")

    # -- values --------------------------------------------------------------------------------
    def numbers(
        self,
        value: object,
        path: KeyPath,
        count: int | None,
        what: str,
        bound: float = math.inf,
    ) -> np.ndarray | None:
        """A list of finite numbers.

        Args:
            value: The YAML value.
            path: Its key path.
            count: How many numbers are expected, or None for any number of them.
            what: What the numbers are, with their unit, for messages.
            bound: Largest magnitude accepted (in the numbers' unit).

        Returns:
            The numbers as floats, or None (after reporting) if ``value`` is not such a list.
        """
        expected = f"a list of {count} numbers" if count else "a list of numbers"
        if not isinstance(value, list) or not all(is_number(v) for v in value):
            self.error(path, f"expected {expected} ({what}), got {describe(value)}")
            return None
        if count is not None and len(value) != count:
            self.error(path, f"expected {count} numbers ({what}), got {len(value)}")
            return None
        try:
            array = np.array(value, dtype=float)
        except OverflowError:  # an integer beyond the float range
            array = np.full(len(value), math.inf)
        if not np.all(np.isfinite(array)):
            self.error(path, f"expected finite numbers ({what}), got {describe(value)}")
            return None
        if np.any(np.abs(array) > bound):
            self.error(path, f"expected numbers within ±{bound:g} ({what}), got {describe(value)}")
            return None
        return array

    def positive(self, value: object, path: KeyPath, what: str) -> float | None:
        """A finite number > 0, or None (after reporting).

        Args:
            value: The YAML value.
            path: Its key path.
            what: What the number is, with its unit, for messages.
        """
        if not is_number(value) or not math.isfinite(to_float(value)) or value <= 0:
            self.error(path, f"expected a number > 0 ({what}), got {describe(value)}")
            return None
        return to_float(value)

    def accelerations(
        self, value: object, path: KeyPath, nq: int | None
    ) -> float | tuple[float, ...] | None:
        """A ``max_acceleration:``: one number > 0 for every joint, or a list of one per joint
        [rad/s² or m/s²], each at most :data:`~kinplan.program.schema.MAX_ACCELERATION`.

        Args:
            value: The YAML value.
            path: Its key path.
            nq: The robot's number of joints (None when the robot could not be loaded).

        Returns:
            The number, or the numbers as a tuple; None after reporting a problem.
        """
        what = "joint acceleration limit [rad/s² or m/s²]"
        expected = (
            f"a number > 0 (every joint) or a list of {nq if nq else 'one per joint'} numbers > 0"
        )
        if isinstance(value, list):
            numbers = self.numbers(value, path, nq, f"{what}, one per joint")
            if numbers is None:
                return None
            bad = [k for k, v in enumerate(numbers) if not 0.0 < v <= MAX_ACCELERATION]
            for k in bad:
                self.error(
                    path + (k,),
                    f"expected a number in (0, {MAX_ACCELERATION:g}] ({what}), got {numbers[k]:g}",
                )
            return None if bad else tuple(float(v) for v in numbers)
        if not is_number(value) or not 0.0 < to_float(value) <= MAX_ACCELERATION:
            self.error(
                path,
                f"expected {expected} ({what}, at most {MAX_ACCELERATION:g}), got "
                f"{describe(value)}",
            )
            return None
        return to_float(value)

    def cartesian_pose(
        self, spec: dict, path: KeyPath, what: str = "tool position [m]"
    ) -> tuple[np.ndarray, np.ndarray | None] | None:
        """A pose from ``xyz`` [m] with ``rpy_deg`` [deg] or ``quat_xyzw`` (or neither).

        Args:
            spec: A mapping with ``xyz``.
            path: Its key path.
            what: What the position is, for messages.

        Returns:
            (position [m], rotation or None), or None after reporting a problem.
        """
        position = self.numbers(spec["xyz"], path + ("xyz",), 3, what, bound=MAX_COORDINATE)
        rotation = None
        if "rpy_deg" in spec and "quat_xyzw" in spec:
            self.error(path, "give rpy_deg or quat_xyzw, not both")
            return None
        if "rpy_deg" in spec:
            rpy = self.numbers(spec["rpy_deg"], path + ("rpy_deg",), 3, "roll, pitch, yaw [deg]")
            if rpy is None:
                return None
            rotation = pin.rpy.rpyToMatrix(*np.radians(rpy))
        elif "quat_xyzw" in spec:
            quat = self.numbers(spec["quat_xyzw"], path + ("quat_xyzw",), 4, "quaternion x y z w")
            if quat is None:
                return None
            with np.errstate(over="ignore"):
                norm = float(np.linalg.norm(quat))
            if not math.isfinite(norm):
                self.error(path + ("quat_xyzw",), "the quaternion is too large; give a unit one")
                return None
            if norm < 1e-9:
                self.error(path + ("quat_xyzw",), "the quaternion is zero; give a unit quaternion")
                return None
            if abs(norm - 1.0) > 1e-3:
                self.warn(path + ("quat_xyzw",), f"quaternion of norm {norm:.4g} normalised")
            x, y, z, w = np.asarray(quat, dtype=float) / norm
            rotation = pin.Quaternion(w, x, y, z).toRotationMatrix()
        return None if position is None else (position, rotation)
