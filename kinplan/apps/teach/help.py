"""The pendant's help: the command list (:data:`HELP`), each command's usage, units and aliases
(:data:`COMMANDS`), the words the prompt completes, and ``help [command]``."""

from __future__ import annotations

from kinplan.apps.teach.parsing import JOG

HELP = """\
j <i> <deg>           jog joint i (0-based index or name) by deg; j <i>+ / j <i>- use the step
x|y|z <m>             move the tool along a world axis by m; x+ / x- use the linear step
roll|pitch|yaw <deg>  rotate the tool about the world x|y|z axis through the tool point;
                      roll+ / roll- use the angle step (rx, ry, rz also work)
step <m>              set the linear step [m]
astep <deg>           set the angle step for joints and rotations [deg]
r [name]              record the current configuration (default names p1, p2, ...)
r [name] lin [m/s]    ... reached by a straight line (r [name] circ <via> [m/s]: an arc)
tool X Y Z [R P Y]    put a tool on the flange: the TCP [m, deg] (tool off removes it)
weave|torch ...|off   weave (pattern mm Hz) or torch angles (work travel deg) of lin/circ
arc on|off            the next recorded move switches the arc when it starts
rec start [hz]        record a continuous path: the jogs that follow, sampled at hz (default 50)
rec stop [tol_deg]    end it: store a smooth spline timed as recorded, within tol_deg of the
                      recording (default 0.0573° = 1e-3 rad), and report its deviation
del <name>            forget a recorded point or path
list                  list the recorded points and paths
home                  go back to the start configuration
show                  show joints and tool pose
help [command]        this help, or a command's usage, units and aliases
q | quit | EOF        write the program and quit
abort                 quit without writing"""
"""The pendant's commands."""

COMMANDS = {
    "j": """\
j <joint> <deg>  |  j <joint>+  |  j <joint>-                        (also: joint)
Jog one joint by <deg> degrees (negative to go back, at most 720); + and - jog by the angle
step (astep). <joint> is a 0-based index or a joint name (show lists the joints). A jog beyond
the joint's limits is refused. Example: j 2 -5""",
    "x": """\
x|y|z <m>  |  x+  |  x-  |  y+  |  y-  |  z+  |  z-
Move the tool along the world x, y or z axis by <m> metres (at most 10) on a straight line,
keeping its orientation; + and - move by the linear step (step). The line is checked first: a
jog that leaves the workspace, meets a joint limit or a singularity, or would flip the arm to
another branch is refused with the reason. Example: z -0.01""",
    "roll": """\
roll|pitch|yaw <deg>  |  roll+  |  roll-  |  ...                  (also: rx, ry, rz)
Rotate the tool by <deg> degrees (at most 180) about the world x (roll), y (pitch) or z (yaw)
axis through the tool point; + and - rotate by the angle step (astep). Checked like x|y|z. Arms
that control the tool position only cannot rotate it. Example: yaw 15""",
    "step": """\
step <m>
Set the linear step of x+, y-, ... to <m> metres, a number > 0 and at most 10.
Example: step 0.005""",
    "astep": """\
astep <deg>
Set the angle step of j <i>+, roll-, ... to <deg> degrees, a number > 0 and at most 180.
Example: astep 1""",
    "r": """\
r [name]  |  rec [name]  |  record [name]
Record the current configuration as a point named <name> (letters, digits, _ and -, not first a
digit; default p1, p2, ...). The program moves to each point with a ptp move, in teaching order.
r [name] lin [m/s]  |  r [name] circ <via> [m/s]
The program reaches the point on a straight tool line (or an arc through the recorded point
<via>) at the tool speed given (default 0.05 m/s), with the weave and torch angles set.
rec start [hz]
Record a continuous path: every jog that follows (and home) is captured as a motion at the jog
speed (10 % of the joint velocity limits) and sampled <hz> times a second (default 50, > 0, at
most 1000). The arm's configuration at rec start is the path's first point.
rec stop [tol_deg]
End the recording and store it as path1, path2, ...: a smooth joint spline (acceleration
continuous, at rest at both ends) that passes as few of the samples as keep every sample within
<tol_deg> degrees of it (default 0.0573° = 1e-3 rad, > 0, at most 10), each knot at the time it
was recorded, each sample compared with the spline at its recorded time. Reports the samples,
the knots kept and the largest deviation, in joint space [rad] and at the tool [mm]. The program
plays it as one ptp through the knots (profile: spline, times: the recorded times), as
recorded; slower only if the spline would exceed a joint velocity limit (the report says so).""",
    "tool": """\
tool X Y Z [R P Y]  |  tool off  |  tool
Put a tool on the flange: the TCP at X Y Z metres and R P Y degrees (roll, pitch, yaw) in the
flange frame. Tool jogs (x, yaw, ...) then move the TCP, and the program gets tool: {xyz,
rpy_deg}. tool off removes it; tool alone shows it. Example: tool 0 0 0.2""",
    "weave": """\
weave sine|triangle|trapezoid <amplitude mm> <frequency Hz>  |  weave off
Weave on the lin and circ moves recorded next (r NAME lin ...): the torch oscillates across the
seam by ±amplitude at frequency oscillations per second of travel. Example: weave sine 1.5 2""",
    "torch": """\
torch <work angle deg> <travel angle deg>  |  torch off
Hold the torch at these welding angles on the lin and circ moves recorded next (the surface
normal +z). Example: torch 45 10""",
    "arc": """\
arc on  |  arc off
The next recorded move switches the arc (digital output 0) when it starts: arc on before the
seam's point, arc off before the retreat's. Example: arc on, then r seam_end lin 0.008""",
    "del": """\
del <name>                                                          (also: delete)
Forget a recorded point or path (list shows them).""",
    "list": """\
list
List the recorded points (joints [deg], tool position [m]) and paths, in teaching order.""",
    "home": """\
home
Go back to the start configuration (a joint move; recorded while rec start is on).""",
    "show": """\
show
Show the joint values [deg] and the tool position [m] and orientation (roll, pitch, yaw [deg]).""",
    "help": """\
help [command]                                                      (also: ?)
List the commands, or explain one: its usage, units and aliases. Example: help rec""",
    "q": """\
q  |  quit  |  exit  |  end of input
Write the program and quit (a running recording is stopped first, as rec stop).""",
    "abort": """\
abort
Quit without writing the program (a running recording is dropped).""",
}
"""Help on each command (``help <command>``): usage, what it does, units, aliases."""

_HELP_ALIASES = {
    "joint": "j",
    "y": "x",
    "z": "x",
    "pitch": "roll",
    "yaw": "roll",
    "rx": "roll",
    "ry": "roll",
    "rz": "roll",
    "rec": "r",
    "record": "r",
    "delete": "del",
    "?": "help",
    "quit": "q",
    "exit": "q",
}
COMPLETIONS = sorted({*COMMANDS, *_HELP_ALIASES, "start", "stop"})
"""Words the prompt completes: the commands, their aliases, ``rec``'s ``start`` and ``stop``."""


def command_help(arguments: list[str]) -> str:
    """``help [command]``: :data:`HELP`, or one command's entry of :data:`COMMANDS` (by its name,
    an alias or a jog word such as ``x+``); ValueError for anything else."""
    if not arguments:
        return HELP
    if len(arguments) > 1:
        raise ValueError("usage: help [command]")
    name = arguments[0].lower()
    key = _HELP_ALIASES.get(name, name)
    match = JOG.match(key)
    if key not in COMMANDS and match:  # help x+, help yaw-, help j+
        key = _HELP_ALIASES.get(match["axis"], match["axis"])
    if key not in COMMANDS:
        raise ValueError(
            f"no command {arguments[0]!r}; help explains {', '.join(COMMANDS)} (and their aliases)"
        )
    return COMMANDS[key]
