"""Native URScript of a program plan: ``movej`` / ``movel`` / ``movec`` / ``movep`` with the
program's speeds, accelerations and blend radii, ``set_tcp`` / ``set_payload`` from its tool,
its I/O as ``set_standard_digital_out``; every native move checked before it is written.

Each move of the plan is translated to the command a PolyScope programmer would write:

* a ``ptp`` to one point → ``movej(q, a, v)``: the plan's end joints, the leading joint's peak
  speed and acceleration in the plan (a ``ptp`` with ``avoid: true`` too, when the straight
  joint motion the controller runs is clear of the cell: the replay decides);
* a ``lin`` → ``movel(pose, a, v)``, a ``circ`` → ``movec(via, pose, a, v, mode=0)``: the pose
  of the plan's end (forward kinematics of its last sample, 1e-10 m as written), the plan's
  peak tool speed and acceleration;
* lines blended together (``blend:``) → a ``movep`` chain with ``r=`` the blend radii, when the
  tool orientation is the same along the whole seam;
* a dwell → ``sleep``; a move's ``arc:`` / ``io:`` → ``set_standard_digital_out`` before it,
  a point's after the move that arrives there (before its dwell's ``sleep``); a weld job
  (``weld: {job: N}``) → ``write_output_integer_register`` or the job outputs' bits, just
  before its arc goes on.

Before a native move is written it is replayed by the independent model of the controller in
:mod:`kinplan.export.controller_model` (joint-linear trapezoid for ``movej``; the tool's line,
circle or blended chain for the others, solved by inverse kinematics from the plan's start of
the move) and checked against what the plan was checked for: joint position and velocity
limits (and acceleration limits where the robot declares them), the work cell with the plan's
clearance, the end configuration equal to the plan's (1e-5 rad: the controller must not end
on another branch), the tool within 1 mm (plus the blend radius in blends) of the plan's path
and its orientation within 1° of the plan's (the torch axis alone for moves with ``torch:``).
A move that fails (a free motion whose straight joint motion would collide, say), or has no
native form (weaves, ptp through several points, turning torches in blended seams), is written
as a ``servoj`` stream of the plan's own motion (``fallback="servoj"``, the reason in a comment
and in :attr:`NativeProgram.fallbacks`), or refused with the reason (``fallback="refuse"``).

Poses are written in the controller's base frame (the URDF's ``base`` link: ``base_link``
turned by π about z in the Universal Robots descriptions, with the program's ``base_pose:``
taken out), ``set_tcp`` in the flange frame ``tool0``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from kinplan.errors import InputError
from kinplan.export.continuous import continuous_motion
from kinplan.export.controller_model import (
    ToolTrack,
    arc_track,
    blended_track,
    line_track,
    movej_samples,
)
from kinplan.export.ur_arm import io_statement, script_list, script_number, script_pose
from kinplan.export.whole_motion import whole_motion
from kinplan.trajectory import time_grid

if TYPE_CHECKING:
    from kinplan.model.robot import Robot

__all__ = [
    "FALLBACKS",
    "NativeProgram",
    "POSITION_TOLERANCE",
    "ROTATION_TOLERANCE",
    "controller_frames",
    "native_program",
]

FALLBACKS = ("servoj", "refuse")
"""What :func:`native_program` does with a move that cannot be native."""
POSITION_TOLERANCE = 1e-3
"""Largest distance of the replayed tool from the plan's path, outside blends [m]."""
ROTATION_TOLERANCE = math.radians(1.0)
"""Largest angle between the replayed tool orientation and the plan's [rad]."""
END_TOLERANCE = 1e-5
"""Largest joint difference between the replay's end and the plan's [rad]."""
_REPLAY_STEP = 0.004
"""Time step of the replays [s] (the cell is also checked between the samples)."""


@dataclass
class NativeProgram:
    """The body of a native URScript program and what became of each move.

    Attributes:
        lines: The statements, indented for the program's ``def`` (no header, no ``def``).
        native: (move numbers, command) of each move written natively.
        fallbacks: (move numbers, reason) of each move written as ``servoj``.
        servo_targets: Number of ``servoj`` targets written.
    """

    lines: list[str] = field(default_factory=list)
    native: list[tuple[str, str]] = field(default_factory=list)
    fallbacks: list[tuple[str, str]] = field(default_factory=list)
    servo_targets: int = 0


def controller_frames(robot: Robot) -> tuple[pin.SE3, pin.SE3, str]:
    """The controller's base in the world and the TCP in the flange ``tool0``.

    Returns:
        (base pose in the world, TCP pose in ``tool0``, a note for the header).
    """
    model = robot.model
    data = model.createData()
    q = np.clip(np.zeros(robot.nq), robot.lower, robot.upper)
    pin.framesForwardKinematics(model, data, q)
    notes = []
    if model.existFrame("base"):
        base = pin.SE3(data.oMf[model.getFrameId("base")])
    else:
        base = pin.SE3(data.oMf[model.getFrameId(robot.base_frame)])
        notes.append(f"no 'base' frame: the controller's base is taken as {robot.base_frame}")
    if model.existFrame("tool0"):
        tcp = pin.SE3(data.oMf[model.getFrameId("tool0")]).inverse() * robot.fk(q)
    else:
        tcp = pin.SE3.Identity()
        notes.append(f"no 'tool0' frame: the flange is taken as {robot.tip_frame}")
    return base, tcp, "; ".join(notes)


@dataclass
class _Context:
    plan: Any
    robot: Robot
    base: pin.SE3
    period: float
    servo: str
    fallback: str
    motion: Any
    clearance: float
    torch: bool = False


def native_program(
    plan: Any, *, period: float, servo: str, fallback: str = "servoj"
) -> NativeProgram:
    """The statements of a native program for a whole program plan (see the module docstring).

    Args:
        plan: A :class:`~kinplan.program.ProgramPlan` that is ok, of a UR arm, with its program.
        period: Period of ``servoj`` streams [s].
        servo: The ``servoj`` arguments after the joints (``t=..., lookahead_time=..., gain=...``).
        fallback: ``"servoj"`` or ``"refuse"`` (see :data:`FALLBACKS`).

    Raises:
        InputError: not a program plan, or (``fallback="refuse"``) a move that cannot be
            native, naming the move and why.
    """
    if fallback not in FALLBACKS:
        raise InputError(f"fallback must be one of {', '.join(FALLBACKS)}, got {fallback!r}")
    program = getattr(plan, "program", None)
    if program is None:
        raise InputError(
            "the native URScript style needs a program plan (kinplan.program.plan_program); "
            "give style='servo' for any other motion"
        )
    from kinplan.program.plan import move_span

    t, q, qd, qdd = whole_motion(plan, "urscript", between="plan")
    robot = plan.robot
    base, _, _ = controller_frames(robot)
    ctx = _Context(
        plan, robot, base, period, servo, fallback, continuous_motion(plan, t, q, qd, qdd, "plan"),
        float(getattr(plan, "clearance_margin", 0.0)),
    )  # fmt: skip
    out = NativeProgram()
    events = sorted(getattr(plan, "io_events", []), key=lambda e: e.t)
    for report in plan.moves:
        while events and events[0].t <= report.t0 + 1e-9:  # a point's arrival before a dwell
            out.lines.append(io_statement(events.pop(0)))
        if report.kind == "dwell":
            number = _ascii(report.numbers)
            out.lines.append(f"  sleep({script_number(report.duration)})  # dwell of move {number}")
            continue
        span = move_span(report.key)
        moves = [] if span is None else program.moves[span[0] - 1 : span[1]]
        title = f"  # move {report.numbers}: {report.label}"
        out.lines.append(_ascii(title))
        if report.last <= report.first:
            out.lines.append("  # (no motion)")
            continue
        command, why = _native(ctx, report, moves)
        if command is not None:
            out.lines += command
            out.native.append((_ascii(report.numbers), command[-1].split("(")[0].strip()))
            continue
        if fallback == "refuse":
            raise InputError(
                f"move {report.numbers} ({report.label}, {report.key}) cannot be written as a "
                f"native move: {why}; write it with style='servo' (--urscript-style servo) or "
                "let it be a servoj stream"
            )
        out.fallbacks.append((_ascii(report.numbers), why))
        out.lines.append(_ascii(f"  # as servoj: {why}"))
        out.lines += _servo_lines(ctx, report, out)
    for event in events:
        out.lines.append(io_statement(event))
    return out


def _ascii(text: str) -> str:
    text = text.replace("–", "-").replace("→", "->")
    return "".join(c if " " <= c <= "~" else "?" for c in text)


def _servo_lines(ctx: _Context, report: Any, out: NativeProgram) -> list[str]:
    """The plan's own motion over one move as ``servoj`` targets, then the end held twice
    the lookahead time (the stream lags its targets by up to the lookahead)."""
    times = float(ctx.plan.t[report.first]) + time_grid(report.t1 - report.t0, ctx.period)
    targets = np.array(ctx.motion(times - float(ctx.plan.t[0]))[0], dtype=float)
    targets[0], targets[-1] = ctx.plan.q[report.first], ctx.plan.q[report.last]
    lines = [f"  servoj({script_list(target)}, {ctx.servo})" for target in targets]
    lookahead = float(ctx.servo.split("lookahead_time=")[1].split(",")[0])
    hold = math.ceil(2.0 * lookahead / ctx.period - 1e-9)
    lines += [f"  servoj({script_list(targets[-1])}, {ctx.servo})"] * hold
    out.servo_targets += len(targets) + hold
    return lines


def _native(ctx: _Context, report: Any, moves: list[Any]) -> tuple[list[str] | None, str]:
    """The native statements of one planned move, or (None, why not)."""
    if not moves:
        return None, "it is not a move of the program's list"
    kinds = {m.kind for m in moves}
    ctx.torch = any(m.torch is not None for m in moves)
    program_avoid = bool(getattr(getattr(ctx.plan, "program", None), "avoid", False))
    avoided = any(
        program_avoid if getattr(m, "avoid", None) is None else bool(m.avoid)
        for m in moves
        if m.kind == "ptp" and not m.through
    )
    if any(m.weave is not None for m in moves):
        return None, "a woven seam: the controller's moves cannot weave"
    if kinds == {"ptp"}:
        if moves[0].through:
            return None, "a ptp through several points is timed as one motion (no native form)"
        command, why = _movej(ctx, report)
        if command is None and avoided:  # the straight movej meets what the free motion avoids
            why = f"a free motion around obstacles (avoid: true), and {why}"
        return command, why
    if "ptp" in kinds:
        return None, "a ptp blended with lines has no native form"
    if len(moves) == 1 and moves[0].kind == "lin":
        return _movel(ctx, report)
    if len(moves) == 1 and moves[0].kind == "circ":
        return _movec(ctx, report, moves[0])
    if kinds == {"lin"}:
        return _movep(ctx, report, moves)
    return None, "lines and arcs blended together have no native form here"


def _window(ctx: _Context, report: Any) -> slice:
    return slice(report.first, report.last + 1)


def _movej(ctx: _Context, report: Any) -> tuple[list[str] | None, str]:
    plan, robot = ctx.plan, ctx.robot
    w = _window(ctx, report)
    q0, q1 = plan.q[report.first], plan.q[report.last]
    lead = int(np.argmax(np.abs(q1 - q0)))
    v = float(np.max(np.abs(plan.qd[w, lead])))
    a = float(np.max(np.abs(plan.qdd[w, lead])))
    if not (v > 0.0 and a > 0.0):
        return None, "the plan's leading joint has no speed or acceleration to give movej"
    t, q = movej_samples(q0, q1, v, a, _REPLAY_STEP)
    delta = np.abs(q1 - q0)
    speeds = v * delta / delta[lead]
    accelerations = a * delta / delta[lead]
    why = _limits(robot, q, speeds, accelerations) or _cell(ctx, q)
    if why:
        return None, f"movej as the controller runs it: {why}"
    return [f"  movej({script_list(q1)}, a={script_number(a)}, v={script_number(v)})"], ""


def _tool_rates(ctx: _Context, report: Any) -> tuple[float, float]:
    """The plan's peak tool speed [m/s] and acceleration [m/s²] over a move."""
    w = _window(ctx, report)
    speed, t = ctx.plan.tool_speed[w], ctx.plan.t[w]
    v = float(np.max(speed))
    a = float(np.max(np.abs(np.diff(speed) / np.diff(t)))) if len(t) > 1 else 0.0
    return v, a


def _movel(ctx: _Context, report: Any) -> tuple[list[str] | None, str]:
    start, end = ctx.robot.fk(ctx.plan.q[report.first]), ctx.robot.fk(ctx.plan.q[report.last])
    v, a = _tool_rates(ctx, report)
    if float(np.linalg.norm(end.translation - start.translation)) < 1e-6 or v <= 0 or a <= 0:
        return None, "the tool turns in place (movel times the path length)"
    track = line_track(start, end, v, a, _REPLAY_STEP)
    why = _tool_check(ctx, report, track, 0.0)
    if why:
        return None, f"movel as the controller runs it: {why}"
    pose = ctx.base.inverse() * end
    return [f"  movel({script_pose(pose)}, a={script_number(a)}, v={script_number(v)})"], ""


def _movec(ctx: _Context, report: Any, move: Any) -> tuple[list[str] | None, str]:
    program, robot = ctx.plan.program, ctx.robot
    start, end = robot.fk(ctx.plan.q[report.first]), robot.fk(ctx.plan.q[report.last])
    via = program.points[move.via].tool_position(robot)
    v, a = _tool_rates(ctx, report)
    try:
        track = arc_track(start, via, end, v, a, _REPLAY_STEP)
    except ValueError as exc:
        return None, str(exc)
    why = _tool_check(ctx, report, track, 0.0)
    if why:
        return None, f"movec as the controller runs it: {why}"
    pose_via = ctx.base.inverse() * pin.SE3(end.rotation, via)
    pose = ctx.base.inverse() * end
    return [
        f"  movec({script_pose(pose_via)}, {script_pose(pose)}, a={script_number(a)}, "
        f"v={script_number(v)}, r=0, mode=0)"
    ], ""


def _movep(ctx: _Context, report: Any, moves: list[Any]) -> tuple[list[str] | None, str]:
    robot, plan = ctx.robot, ctx.plan
    w = _window(ctx, report)
    start = robot.fk(plan.q[report.first])
    rotations = [robot.fk(q).rotation for q in plan.q[w]]
    turn = max(float(np.linalg.norm(pin.log3(start.rotation.T @ r))) for r in rotations)
    if turn > 1e-6:
        return None, (
            f"the tool turns {math.degrees(turn):.3g} deg along the blended seam (torch angles "
            "that follow its corners); movep would turn it between the waypoints instead"
        )
    waypoints = [plan.program.points[m.target].tool_position(robot) for m in moves[:-1]]
    waypoints.append(robot.fk(plan.q[report.last]).translation)
    radii = [float(m.blend or 0.0) for m in moves[:-1]]
    v, a = _tool_rates(ctx, report)
    try:
        track = blended_track(start, waypoints, radii, start.rotation, v, a, _REPLAY_STEP)
    except ValueError as exc:
        return None, str(exc)
    why = _tool_check(ctx, report, track, max(radii, default=0.0))
    if why:
        return None, f"movep as the controller runs it: {why}"
    lines = []
    for point, r in zip(waypoints, radii + [0.0], strict=True):
        pose = ctx.base.inverse() * pin.SE3(start.rotation, point)
        lines.append(
            f"  movep({script_pose(pose)}, a={script_number(a)}, v={script_number(v)}, "
            f"r={script_number(r)})"
        )
    return lines, ""


def _limits(robot: Robot, q: np.ndarray, speeds: np.ndarray,
            accelerations: np.ndarray | None) -> str:  # fmt: skip
    """Why replayed joints break a limit, or ""."""
    names = robot.joint_names
    low = np.min(q, axis=0) < robot.lower - 1e-9
    high = np.max(q, axis=0) > robot.upper + 1e-9
    for j in np.flatnonzero(low | high):
        return (
            f"joint {names[j]} leaves its limits [{robot.lower[j]:.4g}, {robot.upper[j]:.4g}] rad"
        )
    for j in np.flatnonzero(speeds > robot.velocity_limit * (1 + 1e-6)):
        return (
            f"joint {names[j]} would need {speeds[j]:.4g} rad/s, beyond its limit "
            f"{robot.velocity_limit[j]:.4g} rad/s"
        )
    if accelerations is not None:
        limit = robot.acceleration_limit
        for j in np.flatnonzero(np.isfinite(limit) & (accelerations > limit * (1 + 1e-6))):
            return (
                f"joint {names[j]} would need {accelerations[j]:.4g} rad/s², beyond its limit "
                f"{limit[j]:.4g} rad/s²"
            )
    return ""


def _cell(ctx: _Context, q: np.ndarray) -> str:
    """Why replayed joints collide in the plan's cell (or come closer than its clearance)."""
    cell = getattr(ctx.plan, "cell", None)
    if cell is None:
        return ""
    check = cell.check_motion(q, ctx.clearance)
    if check.ok:
        return ""
    first, second = check.bodies if check.bodies else ("the robot", "a body")
    depth = float(getattr(check, "penetration", 0.0) or 0.0)
    if depth > 0.0 or ctx.clearance <= 0.0:
        return f"{first} collides with {second}"
    return f"{first} comes closer to {second} than the clearance {1e3 * ctx.clearance:g} mm"


def _tool_check(ctx: _Context, report: Any, track: ToolTrack, blend: float) -> str:
    """Replay a tool motion by IK from the plan's start of the move and check it."""
    robot, plan = ctx.robot, ctx.plan
    q = np.empty((len(track.t), robot.nq))
    seed = plan.q[report.first]
    for k, pose in enumerate(track.poses()):
        result = robot.ik(pose, q_seed=seed)
        if not result.success:
            return f"no joint solution at t = {track.t[k]:.3f} s of the move"
        q[k] = seed = result.q
    gap = float(np.max(np.abs(q[-1] - plan.q[report.last])))
    if gap > END_TOLERANCE:
        return f"it would end {gap:.3g} rad from the plan's configuration (another branch)"
    dt = np.diff(track.t)
    speeds = (
        np.max(np.abs(np.diff(q, axis=0)) / dt[:, None], axis=0) if len(dt) else np.zeros(robot.nq)
    )
    accelerations = None
    if np.any(np.isfinite(robot.acceleration_limit)) and len(dt) > 1:
        rates = np.diff(q, axis=0) / dt[:, None]
        steps = 0.5 * (dt[1:] + dt[:-1])
        accelerations = np.max(np.abs(np.diff(rates, axis=0)) / steps[:, None], axis=0)
    why = _limits(robot, q, speeds, accelerations) or _cell(ctx, q)
    if why:
        return why
    return _deviation(ctx, report, track, blend)


def _deviation(ctx: _Context, report: Any, track: ToolTrack, blend: float) -> str:
    """How far the replayed tool strays from the plan's tool path ("" within tolerance)."""
    w = _window(ctx, report)
    path = ctx.plan.tool_positions[w]
    starts, ends = path[:-1], path[1:]
    seg = ends - starts
    length2 = np.maximum(np.einsum("ij,ij->i", seg, seg), 1e-30)
    worst, worst_angle = 0.0, 0.0
    poses = [ctx.robot.fk(q) for q in ctx.plan.q[w]]
    for position, rotation in zip(track.positions, track.rotations, strict=True):
        u = np.clip(np.einsum("ij,ij->i", position - starts, seg) / length2, 0.0, 1.0)
        distance = np.linalg.norm(starts + u[:, None] * seg - position, axis=1)
        k = int(np.argmin(distance))
        worst = max(worst, float(distance[k]))
        near = poses[k].rotation
        if ctx.torch:
            cosine = float(np.clip(np.dot(near[:, 2], rotation[:, 2]), -1.0, 1.0))
            angle = math.acos(cosine)
        else:
            angle = float(np.linalg.norm(pin.log3(near.T @ rotation)))
        worst_angle = max(worst_angle, angle)
    if worst > POSITION_TOLERANCE + blend:
        return f"the tool strays {1e3 * worst:.3g} mm from the planned path"
    if worst_angle > ROTATION_TOLERANCE:
        return (
            f"the tool turns {math.degrees(worst_angle):.3g} deg away from the planned orientation"
        )
    return ""
