"""The teach pendant: :class:`TeachPendant`, its state and commands in one object that executes
one command line at a time, dispatching it to the commands of its kind."""

from __future__ import annotations

from kinplan import checks
from kinplan.apps.teach.help import command_help
from kinplan.apps.teach.jogging import JogCommands
from kinplan.apps.teach.parsing import AXES, JOG, ROTATIONS, control_message
from kinplan.apps.teach.points import PointCommands
from kinplan.apps.teach.process import ProcessCommands
from kinplan.apps.teach.recording import RecordingCommands
from kinplan.apps.teach.state import Reply
from kinplan.apps.teach.writer import ProgramWriter
from kinplan.errors import KinplanError


class TeachPendant(JogCommands, ProcessCommands, PointCommands, RecordingCommands, ProgramWriter):
    """The state of a teach session and its commands.

    Args:
        robot: The arm.
        q_start: Start configuration [rad] (default :func:`home_configuration`).
        robot_source: How the program names the robot (a name or URDF path; default its name).
        linear_step: Tool jog step [m].
        angular_step_deg: Joint and rotation jog step [deg].
        jog_speed: Speed of the jogs a recording captures, share of the joint velocity limits,
            in (0, 1] [-].
        path_tolerance: Default largest deviation of a recorded path's spline from the
            recording (``rec stop`` without a tolerance) [rad].

    Attributes:
        q: Current configuration [rad].
        points: Recorded points: name → configuration [rad], in recording order.
        move_specs: How the program reaches each point (``r NAME lin ...``).
        tool_pose: The pendant's tool (``tool X Y Z [R P Y]``): (xyz [m], rpy [deg]) in the
            flange frame, or None.
        paths: Recorded continuous paths: name → :class:`RecordedPath`, in recording order.
    """

    # -- commands ------------------------------------------------------------------------------
    def execute(self, line: str) -> Reply:
        """Run one command line; unknown or malformed commands get a message, never raise."""
        if not isinstance(line, str):
            return Reply(f"error: a command is a line of text, got {checks.describe(line)}")
        control = control_message(line)
        if control:
            return Reply(f"error: {control}")
        words = line.split("#", 1)[0].split()
        if not words:
            return Reply("")
        command, arguments = words[0].lower(), words[1:]
        try:
            reply = self._dispatch(command, arguments)
        except (ValueError, KinplanError) as exc:
            return Reply(f"error: {exc}")
        recording = self._recording
        if reply.moved and recording is not None:
            reply.text += (
                f"\nrecording: {len(recording.times)} samples, {recording.elapsed:.2f} s "
                "(rec stop to store the path)"
            )
        return reply

    def _dispatch(self, command: str, arguments: list[str]) -> Reply:
        simple = {
            "show": lambda: Reply(self.status()),
            "list": self._list,
            "home": self._home,
            "q": self._finish,
            "quit": self._finish,
            "exit": self._finish,
            "abort": self._abort,
        }
        if command in simple and not arguments:
            return simple[command]()
        if command in ("help", "?"):
            return self._help(arguments)
        if command in ("j", "joint"):
            return self._jog_joint(arguments)
        if command in ("r", "rec", "record"):
            if arguments and arguments[0].lower() == "start":
                return self._start_recording(arguments[1:])
            if arguments and arguments[0].lower() == "stop":
                return self._stop_recording(arguments[1:])
            return self._record(arguments)
        if command in ("tool", "weave", "torch", "arc"):
            return {"tool": self._tool, "weave": self._weave, "torch": self._torch,
                    "arc": self._arc}[command](arguments)  # fmt: skip
        if command in ("del", "delete"):
            return self._delete(arguments)
        if command == "step":
            return self._set_step(arguments, angular=False)
        if command == "astep":
            return self._set_step(arguments, angular=True)
        match = JOG.match(command)
        axis, sign = (match["axis"], match["sign"]) if match else (command, "")
        if axis in AXES or axis in ROTATIONS:
            return self._jog_tool(axis, sign, arguments)
        if command in simple:
            raise ValueError(f"usage: {command} (no arguments); help {command} explains it")
        return Reply(f"error: unknown command {command!r}; type help for the commands")

    def _help(self, arguments: list[str]) -> Reply:
        return Reply(command_help(arguments))

    def _finish(self) -> Reply:
        text = self._stop_recording([]).text if self._recording is not None else ""
        return Reply(text, done=True, write=True)

    def _abort(self) -> Reply:
        text = "recording dropped" if self._recording is not None else ""
        self._recording = None
        return Reply(text, done=True, write=False)
