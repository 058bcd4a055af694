"""Jogging commands: a joint (``j``), the tool along or about a world axis (``x``, ``yaw+``, ...,
checked for reach, joint limits, branch flips and singularities), the steps (``step``,
``astep``), ``home``; what the operator can do about a refused tool jog."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

import cartesian
from kinplan.apps.teach.parsing import AXES, ROTATIONS, number
from kinplan.apps.teach.settings import (
    MAX_BRANCH_STEP,
    MAX_JOINT_JOG_DEG,
    MAX_LINEAR_JOG,
    MAX_ROTATION_JOG_DEG,
)
from kinplan.apps.teach.state import PendantState, Reply
from kinplan.model.robot import Robot


class JogCommands(PendantState):
    """The pendant's jogging commands."""

    def _jog_joint(self, arguments: list[str]) -> Reply:
        usage = "usage: j <index or name> <delta_deg>, or j <index>+ / j <index>-"
        if not arguments:
            raise ValueError(usage)
        target, sign = arguments[0], ""
        if target[-1] in "+-" and len(target) > 1:
            target, sign = target[:-1], target[-1]
        j = self._joint_index(target)
        if sign and len(arguments) == 1:
            delta = self.angular_step * (1.0 if sign == "+" else -1.0)
        elif len(arguments) == 2 and arguments[1] in ("+", "-"):
            delta = self.angular_step * (1.0 if arguments[1] == "+" else -1.0)
        elif len(arguments) == 2 and not sign:
            delta = math.radians(
                number(arguments[1], "the jog", "degrees", maximum=MAX_JOINT_JOG_DEG)
            )
        else:
            raise ValueError(usage)
        q = self.q.copy()
        q[j] += delta
        robot = self.robot
        if not robot.within_limits(q):
            return Reply(
                f"refused: joint {j} ({robot.joint_names[j]}) would reach "
                f"{math.degrees(q[j]):.2f}°, beyond its limits "
                f"[{math.degrees(robot.lower[j]):.1f}°, {math.degrees(robot.upper[j]):.1f}°]"
            )
        return self._go(q)

    def _joint_index(self, text: str) -> int:
        names = self.robot.joint_names
        if text in names:
            return names.index(text)
        try:
            j = int(text)
        except ValueError:
            raise ValueError(
                f"no joint {text!r}; give an index 0..{len(names) - 1} or a name: "
                f"{', '.join(names)}"
            ) from None
        if not 0 <= j < len(names):
            raise ValueError(
                f"joint index {j} is out of range 0..{len(names) - 1} ({self.robot.name} has "
                f"{len(names)} joints)"
            )
        return j

    def _jog_tool(self, axis: str, sign: str, arguments: list[str]) -> Reply:
        rotate = axis in ROTATIONS
        if sign and not arguments:
            step = self.angular_step if rotate else self.linear_step
            delta = step if sign == "+" else -step
        elif len(arguments) == 1 and not sign:
            if rotate:
                value = number(arguments[0], "the jog", "degrees", maximum=MAX_ROTATION_JOG_DEG)
                delta = math.radians(value)
            else:
                delta = number(arguments[0], "the jog", "metres", maximum=MAX_LINEAR_JOG)
        else:
            unit = "deg" if rotate else "m"
            raise ValueError(f"usage: {axis} <delta_{unit}>, or {axis}+ / {axis}-")
        robot = self.robot
        position_only = robot.default_position_only()
        if rotate and position_only:
            return Reply(
                f"refused: {robot.name} has {robot.nq} joints and controls the tool position "
                "only; jog x, y, z or the joints"
            )
        plane_normal = robot.model.jointPlacements[1].rotation[:, 2]
        if axis == "z" and robot.planar_reach() is not None and abs(plane_normal[2]) > 1 - 1e-9:
            return Reply(
                f"refused: {robot.name} is a planar arm and moves in its xy-plane; jog x, y or "
                "the joints"
            )
        pose = robot.fk(self.q)
        position, rotation = pose.translation.copy(), pose.rotation.copy()
        if rotate:
            axis_vector = np.zeros(3)
            axis_vector[ROTATIONS[axis]] = 1.0
            rotation = pin.exp3(axis_vector * delta) @ rotation
        else:
            position[AXES[axis]] += delta
        return self._move_tool(position, None if position_only else rotation)

    def _move_tool(self, position: np.ndarray, rotation: np.ndarray | None) -> Reply:
        """Move the tool on a straight line to the target, checked for reach, joint limits,
        branch flips and singularities along the way (IK warm-started from the current q)."""
        robot = self.robot
        start = robot.fk(self.q)
        where = ", ".join(f"{v:.4f}" for v in position)
        if rotation is None:
            path = cartesian.Line(start.translation, position)
        else:
            path = cartesian.Line(start, pin.SE3(rotation, position))
        check = cartesian.check_reachability(
            robot, path, q_seed=self.q, position_only=rotation is None
        )
        if not check.ok:
            event = check.events[0]
            advice = _pendant_advice(event, robot)
            distance, reach = robot.shoulder_distance(position), robot.reach()
            beyond = ""
            if distance > reach * (1.0 + 1e-9) and event.kind != "unreachable":
                beyond = (
                    f" (the jog ends {distance:.4f} m from the first joint, beyond the reach of "
                    f"{robot.name}, {reach:.4f} m)"
                )
                advice = _PENDANT_ADVICE["unreachable"]
            return Reply(
                f"refused: {event.kind} at {100 * event.s:.0f} % of the jog to ({where}) m: "
                f"{event.message}{beyond}" + (f"; {advice}" if advice else "")
            )
        along: tuple[np.ndarray, np.ndarray] | None = None
        if len(check.q):
            q = check.q[-1]
            along = (np.asarray(check.s, dtype=float), np.asarray(check.q, dtype=float))
        else:  # planar arms are checked analytically: solve the end point
            target = position if rotation is None else pin.SE3(rotation, position)
            result = robot.ik(target, q_seed=self.q, position_only=rotation is None)
            if not result.success:
                from cartesian.events import out_of_reach

                why = out_of_reach(robot, result, position)
                return Reply(
                    f"refused: ({where}) m cannot be reached from here: {why}; "
                    f"{_PENDANT_ADVICE['unreachable']}"
                )
            q = result.q
        change = np.abs(q - self.q)
        if change.max() > MAX_BRANCH_STEP + path.length + (path.slerp.angle if path.slerp else 0):
            j = int(np.argmax(change))
            return Reply(
                f"refused: reaching ({where}) m would swing joint {j} ({robot.joint_names[j]}) by "
                f"{math.degrees(change[j]):.1f}° (a branch flip); take a smaller step or jog the "
                "joints"
            )
        return self._go(np.array(q, dtype=float), along)

    def _set_step(self, arguments: list[str], angular: bool) -> Reply:
        usage = "usage: astep <deg>" if angular else "usage: step <m>"
        if len(arguments) != 1:
            raise ValueError(f"{usage} (a number > 0)")
        try:
            if angular:
                value = number(
                    arguments[0],
                    "the angle step",
                    "degrees",
                    positive=True,
                    maximum=MAX_ROTATION_JOG_DEG,
                )
            else:
                value = number(
                    arguments[0], "the linear step", "metres", positive=True, maximum=MAX_LINEAR_JOG
                )
        except ValueError as exc:
            raise ValueError(f"{usage}: {exc}") from None
        if angular:
            self.angular_step = math.radians(value)
            return Reply(f"angle step {value:g}°")
        self.linear_step = value
        return Reply(f"linear step {value:g} m")

    def _home(self) -> Reply:
        return self._go(self.start.copy())


_PENDANT_ADVICE = {
    "unreachable": "jog back toward the robot, or take a smaller step (step <m>)",
    "joint_limit": "jog that joint away from its limit (j <joint> <deg>), or go around another way",
    "jump": "take a smaller step (step <m> / astep <deg>), or jog the joints",
    "singular": "jog the joints out of the singular pose (e.g. bend the elbow or the wrist), or "
    "jog in another direction",
    "velocity_limit": "take a smaller step (step <m> / astep <deg>)",
    "collision": "jog away from the obstacle, or jog the joints around it",
}
"""What the operator can do about a refused tool jog, by event kind: pendant commands only (an
event's own ``remedy`` names arguments of :func:`cartesian.follow` the pendant does not have)."""


def _pendant_advice(event, robot: Robot) -> str:
    """The pendant's advice for a refused jog's event (see :data:`_PENDANT_ADVICE`)."""
    advice = _PENDANT_ADVICE.get(event.kind, "")
    joint = getattr(event, "joint", None)
    if event.kind == "joint_limit" and joint in robot.joint_names:
        j = robot.joint_names.index(joint)
        advice = advice.replace("that joint", f"joint {j} ({joint})").replace("<joint>", str(j))
    return advice
