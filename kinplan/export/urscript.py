"""URScript for a Universal Robots arm: :func:`urscript` / :func:`write_urscript`, in two styles.

* ``servo``: a program that goes to the start with ``movej`` and replays the motion with one
  ``servoj`` per controller period (:func:`kinplan.export.servo.servo_samples`);
* ``native`` (the default for program plans): the program's own moves as ``movej`` /
  ``movel`` / ``movec`` / ``movep``, each checked by a model of the controller before it is
  written (:mod:`kinplan.export.native`).

Both write a program plan's tool as ``set_tcp`` / ``set_payload`` and its I/O events
(``arc:``, ``io:``, ``weld:``) as ``set_standard_digital_out`` at the instant each takes effect
(a weld job written to an integer register as ``write_output_integer_register``).
:func:`ur_arm_problem` says whether a robot is a UR arm.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

from kinplan import checks
from kinplan.errors import InputError
from kinplan.export.common import write_text
from kinplan.export.native import FALLBACKS, NativeProgram, controller_frames, native_program
from kinplan.export.servo import DEFAULT_SERVO_PERIOD, servo_targets
from kinplan.export.ur_arm import (
    UR_JOINT_NAMES,
    ascii_comment,
    io_statement,
    script_list,
    script_number,
    script_pose,
    ur_arm_problem,
    ur_robot,
)
from kinplan.trajectory.motion import SampledMotion

__all__ = [
    "URSCRIPT_STYLES",
    "UR_JOINT_NAMES",
    "default_style",
    "ur_arm_problem",
    "urscript",
    "write_urscript",
]

URSCRIPT_STYLES = ("native", "servo")
"""The styles of :func:`urscript` (``--urscript-style``)."""


def default_style(plan: SampledMotion) -> str:
    """``native`` for a program plan (ptp/lin/circ moves), ``servo`` for any other motion."""
    return "native" if getattr(plan, "program", None) is not None else "servo"


def urscript(
    plan: SampledMotion,
    *,
    style: str | None = None,
    period: float = DEFAULT_SERVO_PERIOD,
    lookahead_time: float = 0.1,
    gain: float = 300.0,
    start_speed: float = 0.5,
    start_acceleration: float = 1.0,
    fallback: str = "servoj",
) -> str:
    """A URScript program that runs a whole motion on a Universal Robots arm.

    The program ``kinplan_motion`` sets the TCP and payload of a program's tool, goes to the
    motion's start with ``movej``, then runs the motion:

    * ``style="servo"``: one ``servoj`` target per ``period``, the targets of
      :func:`servo_samples` (``t = k · period``, the first the start, the last exactly the
      end), then holds the end for 2 · ``lookahead_time`` (rounded up to whole periods) so the
      arm settles on it (``servoj`` lags its targets by up to the lookahead time); an I/O
      event is written before the first target at or after its time;
    * ``style="native"``: the program's moves as native commands, checked before they are
      written, a move that cannot be native as ``servoj`` (``fallback="servoj"``) or refused
      (``fallback="refuse"``): :mod:`kinplan.export.native`.

    A header comment names the program or motion, the robot, the style, the duration and the
    kinplan version. Joint vectors are in radians, base to wrist 3; poses ``p[x, y, z, rx, ry,
    rz]`` [m, rad] in the controller's base frame; numbers in fixed point with 10 decimals
    (URScript has no exponent notation). The URDF's joint zeros must be the controller's
    (true for the Universal Robots descriptions).

    Args:
        plan: A whole motion of a UR arm (:class:`~kinplan.motion.SampledMotion` that is ok,
            with its robot).
        style: ``"native"`` or ``"servo"``; None: :func:`default_style`.
        period: Period of the ``servoj`` stream [s] (the controller's: 0.008 for a CB3,
            0.002 for an e-Series).
        lookahead_time: ``servoj`` lookahead time [s], 0.03 to 0.2.
        gain: ``servoj`` proportional gain [-], 100 to 2000.
        start_speed: Joint speed of the ``movej`` to the start [rad/s], > 0.
        start_acceleration: Joint acceleration of the ``movej`` to the start [rad/s²], > 0.
        fallback: ``native`` style: ``"servoj"`` or ``"refuse"`` for a move that cannot be
            native.

    Returns:
        The program text (ASCII), ending with a call of ``kinplan_motion()``.

    Raises:
        InputError: not a motion, a failed plan (a controller must not run a partial motion),
            no robot or not a UR arm, a parameter out of its range, the native style for a
            motion that is not a program plan, or a refused move.
        LimitViolationError: the motion breaks its robot's limits (:func:`check_limits`).
    """
    from kinplan import __version__

    lookahead = checks.number(lookahead_time, "lookahead_time", minimum=0.03, maximum=0.2, unit="s")
    servo_gain = checks.number(gain, "gain", minimum=100.0, maximum=2000.0)
    speed = checks.number(start_speed, "start_speed", positive=True, unit="rad/s")
    acceleration = checks.number(
        start_acceleration, "start_acceleration", positive=True, unit="rad/s²"
    )
    chosen = default_style(plan) if style is None else style
    if chosen not in URSCRIPT_STYLES:
        raise InputError(f"style must be one of {', '.join(URSCRIPT_STYLES)}, got {style!r}")
    if fallback not in FALLBACKS:
        raise InputError(f"fallback must be one of {', '.join(FALLBACKS)}, got {fallback!r}")
    robot = ur_robot(plan, "urscript")
    times, targets = servo_targets(plan, period, "urscript")
    step = float(period)
    hold = math.ceil(2.0 * lookahead / step - 1e-9)
    servo = f"t={script_number(step)}, lookahead_time={script_number(lookahead)}, " + (
        f"gain={script_number(servo_gain)}"
    )
    program = getattr(plan, "program", None)
    what = plan.description
    if program is not None:
        what = f"program {Path(program.source).name} ({plan.description})"
    header = [
        f"# kinplan {__version__}: {what} of {robot.name} (Universal Robots arm), {chosen} style",
        f"# duration {times[-1]:.6f} s as planned; {len(plan.t)} plan samples",
        f"# joints [rad]: {', '.join(robot.joint_names)}",
    ]
    body = _tool_lines(plan, robot)
    body.append(
        f"  movej({script_list(targets[0])}, a={script_number(acceleration)}, "
        f"v={script_number(speed)})"
    )
    if chosen == "native":
        native = native_program(plan, period=step, servo=servo, fallback=fallback)
        body += native.lines
        header += _native_header(native)
    else:
        body += _servo_body(plan, times, targets, servo, hold)
        header.append(
            f"# {len(times)} servoj targets every {step:g} s (t = k * {step:g} s, the last at "
            f"the end), then the end held {hold} periods"
        )
    header.append("# Check the motion in the cell (kinplan run ... --html) before running it.")
    lines = [ascii_comment(line) for line in header]
    lines += ["def kinplan_motion():", *body, "end", "kinplan_motion()"]
    return "\n".join(lines) + "\n"


def _native_header(native: NativeProgram) -> list[str]:
    lines = [
        "# poses p[x, y, z, rx, ry, rz] [m, rad] in the controller's base frame, at the TCP "
        "set below",
        f"# {len(native.native)} native moves; {len(native.fallbacks)} as servoj "
        f"({native.servo_targets} targets)",
    ]
    lines += [f"# move {numbers} as servoj: {why}" for numbers, why in native.fallbacks]
    return lines


def _tool_lines(plan: SampledMotion, robot: Any) -> list[str]:
    """``set_tcp`` (from the robot's tool, in ``tool0``) and ``set_payload`` (from the
    program's ``payload:``) of a program plan; nothing for other motions."""
    program = getattr(plan, "program", None)
    if program is None:
        return []
    _, tcp, note = controller_frames(robot)
    lines = [f"  set_tcp({script_pose(tcp)})"]
    if note:
        lines.append(ascii_comment(f"  # {note}"))
    payload = getattr(program, "payload", None)
    if payload is not None:
        lines.append(f"  set_payload({script_number(payload.mass)}, {script_list(payload.cog)})")
    else:
        lines.append("  # no payload: in the program's tool: the controller's own setting holds")
    return lines


def _servo_body(plan: SampledMotion, times: Any, targets: Any, servo: str, hold: int) -> list[str]:
    """The ``servoj`` stream with the plan's I/O events before the first target at or after
    each event's time."""
    events = sorted(getattr(plan, "io_events", []), key=lambda e: e.t)
    start = float(plan.t[0])
    lines = []
    for when, q in zip(times.tolist(), targets, strict=True):
        while events and events[0].t - start <= when + 1e-9:
            lines.append(io_statement(events.pop(0)))
        lines.append(f"  servoj({script_list(q)}, {servo})")
    for event in events:
        lines.append(io_statement(event))
    lines += [
        f"  kinplan_end = {script_list(targets[-1])}",
        "  kinplan_hold = 0",
        f"  while kinplan_hold < {hold}:",
        f"    servoj(kinplan_end, {servo})",
        "    kinplan_hold = kinplan_hold + 1",
        "  end",
    ]
    return lines


def write_urscript(
    path: str | os.PathLike[str],
    plan: SampledMotion,
    *,
    style: str | None = None,
    period: float = DEFAULT_SERVO_PERIOD,
    lookahead_time: float = 0.1,
    gain: float = 300.0,
    start_speed: float = 0.5,
    start_acceleration: float = 1.0,
    fallback: str = "servoj",
) -> Path:
    """Write :func:`urscript` of a whole motion of a UR arm to a file (usually ``.script``).

    Args:
        path: File to write (its folder is created).
        plan: A whole motion of a UR arm, with its robot.
        style: ``"native"`` or ``"servo"``; None: :func:`default_style`.
        period: Period of the ``servoj`` stream [s].
        lookahead_time: ``servoj`` lookahead time [s], 0.03 to 0.2.
        gain: ``servoj`` proportional gain [-], 100 to 2000.
        start_speed: Joint speed of the ``movej`` to the start [rad/s].
        start_acceleration: Joint acceleration of the ``movej`` to the start [rad/s²].
        fallback: ``"servoj"`` or ``"refuse"`` (native style).

    Returns:
        The written path.

    Raises:
        InputError: as :func:`urscript`.
        KinplanError: the file cannot be written.
    """
    target = Path(checks.file_path(path, "path"))
    text = urscript(
        plan,
        style=style,
        period=period,
        lookahead_time=lookahead_time,
        gain=gain,
        start_speed=start_speed,
        start_acceleration=start_acceleration,
        fallback=fallback,
    )
    write_text(target, text, "URScript")
    return target
