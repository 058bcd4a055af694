"""What a Cartesian plan reports: its status and the events that stopped it.

:class:`Status` names the outcomes (``"ok"`` and the kinds of :class:`Event`); an event says what
happened and where (``message``) and what to do about it (``remedy``). The helpers here phrase the
facts every event states: a position, a joint's unit, why a point is out of reach.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np

from kinplan.cell import MotionCheck
from kinplan.ik import IKResult
from kinplan.model.robot import Robot


class Status(str, enum.Enum):
    """Outcome of a plan or kind of an event; compares equal to its string value."""

    OK = "ok"
    UNREACHABLE = "unreachable"
    SINGULAR = "singular"
    JOINT_LIMIT = "joint_limit"
    VELOCITY_LIMIT = "velocity_limit"
    JUMP = "jump"
    ACCELERATION_LIMIT = "acceleration_limit"
    COLLISION = "collision"
    SAMPLING = "sampling"  # the sampling period cannot represent the motion

    def __str__(self) -> str:
        return self.value


@dataclass
class Event:
    """Why a plan stopped.

    Attributes:
        kind: "unreachable", "joint_limit", "jump", "singular", "velocity_limit",
            "acceleration_limit", "collision" or "sampling" (the samples are within every
            limit, but the sampling period cannot represent the motion between them: the
            interpolant leaves the path or a limit) (a :class:`Status`).
        t: Time of the offending sample [s] (0 for a geometric check).
        s: Path fraction of the offending sample [-].
        index: Index of the offending sample.
        message: What happened and where (no advice: see ``remedy``).
        position: Target tool position of the offending sample [m].
        joint: The joint concerned (limits, speeds, jumps), if any.
        value: The offending value (joint position [rad or m], speed [rad/s or m/s],
            manipulability).
        limit: The limit it broke.
        remedy: What the caller of :func:`follow` can do about it ("" when nothing obvious).
    """

    kind: str
    t: float
    s: float
    index: int
    message: str
    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    joint: str | None = None
    value: float | None = None
    limit: float | None = None
    remedy: str = ""

    def __str__(self) -> str:
        return f"{self.message}; {self.remedy}" if self.remedy else self.message


@dataclass(frozen=True)
class OutOfReach:
    """A stretch of path that no joint configuration within the limits reaches, on any branch
    (:func:`unreachable_stretch`).

    Attributes:
        start: Path fraction of the first unreachable point found [-].
        end: Path fraction of the last one of the same stretch [-].
        position: Tool position of the first one [m].
        why: Why it is out of reach, as text.
    """

    start: float
    end: float
    position: np.ndarray
    why: str

    def __str__(self) -> str:
        return (
            f"the path is out of reach from s = {self.start:.3f} to s = {self.end:.3f} "
            f"({where(self.position)}: {self.why}), so no start configuration, branch or slower "
            "motion can follow it: move the path or the robot's base"
        )


def beyond_reach(robot: Robot, position: np.ndarray) -> str | None:
    """ "it is D m from the arm's first joint, which reaches R m" for a position [m] beyond the
    arm's reach, else None."""
    distance, reach = robot.shoulder_distance(position), robot.reach()
    if distance > reach * (1 + 1e-12):
        return f"it is {distance:.4f} m from the arm's first joint, which reaches {reach:.4f} m"
    return None


def out_of_reach(robot: Robot, result: IKResult, position: np.ndarray) -> str:
    """Why a target is out of reach, from an unsuccessful IK ``result``: the distance from the
    arm's first joint and its reach, or how close the best configuration came."""
    beyond = beyond_reach(robot, position)
    if beyond is not None:
        return beyond
    distance, reach = robot.shoulder_distance(position), robot.reach()
    annulus = robot.planar_reach()
    if annulus is not None and distance < annulus[0]:
        return (
            f"its distance to the first joint, {distance:.4f} m, is inside the hole "
            f"r < {annulus[0]:.4f} m that the arm cannot reach"
        )
    text = (
        f"within the arm's reach ({distance:.4f} m of {reach:.4f} m from its first joint), but the "
        f"closest tool pose within the joint limits is {result.position_error:.4f} m"
    )
    if result.rotation_error > 0:
        text += f" and {result.rotation_error:.3f} rad"
    return text + " away"


def joint_units(robot: Robot) -> list[str]:
    """Unit of each joint coordinate: "m" for prismatic joints, "rad" for the others."""
    return ["m" if prismatic else "rad" for prismatic in robot.prismatic.tolist()]


def where(position: np.ndarray) -> str:
    """A position [m] as text: "(x, y, z) m" to 0.1 mm."""
    return "(" + ", ".join(f"{x:.4f}" for x in position) + ") m"


def distinct(value: float, limit: float, decimals: int = 4) -> tuple[str, str]:
    """``value`` and ``limit`` printed with the fewest decimals (at least ``decimals``, at most
    12) that tell them apart: "-1.04723 beyond -1.04720", never "-1.0472 beyond -1.0472"."""
    for places in range(decimals, 13):
        a, b = f"{value:.{places}f}", f"{limit:.{places}f}"
        if a != b:
            return a, b
    return f"{value:.12g}", f"{limit:.12g}"


def small_length(metres: float) -> str:
    """A small distance [m] in mm with the digits it needs (never "0.0 mm" for a non-zero
    one): 1 decimal from 0.1 mm up, 2 significant digits below."""
    millimetres = 1e3 * metres
    if millimetres == 0 or abs(millimetres) >= 0.1:
        return f"{millimetres:.1f} mm"
    return f"{millimetres:.2g} mm"


def collision_event(
    check: MotionCheck, t: np.ndarray, s: np.ndarray, position: np.ndarray
) -> Event:
    """The "collision" event of a failed :meth:`~kinplan.WorkCell.check_motion`: the two bodies,
    where (at sample ``check.index`` or between it and the one before) and how deep."""
    k = check.index
    assert k is not None and check.bodies is not None  # a failed check: its sample and bodies
    first, second = check.bodies
    when = (
        f"between samples at t = {t[k - 1]:.4f} and {t[k]:.4f} s"
        if check.between
        else f"at the sample at t = {t[k]:.4f} s"
    )
    if check.kind == "obstacle" and check.clearance > 0 and check.distance > 0:
        what = (
            f"{first} comes within {small_length(check.distance)} of {second}, "
            f"{small_length(check.penetration)} inside the clearance "
            f"{small_length(check.clearance)}"
        )
    else:
        what = f"{first} collides with {second} ({small_length(check.penetration)} deep)"
    point = "" if check.point is None else f" near {where(check.point)}"
    return Event(
        Status.COLLISION, float(t[k]), float(s[k]), k, f"{what} {when}{point}", position,
        value=float(check.distance), limit=float(check.clearance),
        remedy="move the path or the obstacle, or start from another configuration (q_seed)",
    )  # fmt: skip
