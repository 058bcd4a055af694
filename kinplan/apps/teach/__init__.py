"""A teach pendant in the terminal: jog the arm, record points and paths, write a program.

As in the lecture, the operator moves the arm to each point of the task with a pendant and tells
the controller to record the joint positions there. :class:`TeachPendant` holds the arm's
configuration and executes one line-based command at a time (so scripts and tests can drive it);
:func:`run_session` feeds it lines until ``q`` or the end of input, and :class:`PromptLines`
reads them from the terminal with line editing and history (Python's :mod:`readline`, where it
exists). The recorded points become a program (start = the configuration the session started
from, the points as joint values, a ``ptp`` to each in order) that ``kinplan run`` plans.

Continuous paths: between ``rec start [hz]`` and ``rec stop [tol_deg]`` every jog is captured as
a motion at the jog speed (:data:`DEFAULT_JOG_SPEED` of the joint velocity limits), sampled at
``hz``; ``rec stop`` fits a smooth joint spline, timed as recorded, through as few of the samples
as keep it within the tolerance of all of them at the recorded times (:func:`fit_spline`),
reports its deviation in joint space [rad] and at the tool [mm], and stores it as one
multi-point ``ptp`` move with ``profile: spline`` and the knots' recorded ``times``.

The commands are in :data:`HELP` (``help`` prints them, ``help <command>`` explains one from
:data:`COMMANDS`): jog a joint (``j 2 -5``), the tool along x/y/z [m] or about roll/pitch/yaw
[deg] (``z -0.01``, ``yaw+``), set the steps, record (``r a``, ``rec start``), ``q`` to finish.
Tool jogs solve IK seeded from the current configuration and refuse a jog that is unreachable,
beyond a joint limit, or that would flip the arm to another branch.

Modules, one job each, in import order (a module imports only modules above it, type-only
imports included; none imports from ``kinplan.apps.teach`` itself):

- :mod:`~kinplan.apps.teach.settings`: the defaults and limits (steps, rate, tolerance, jog speed);
- :mod:`~kinplan.apps.teach.parsing`: what the operator types: numbers with units, names, jog words;
- :mod:`~kinplan.apps.teach.help`: :data:`HELP`, :data:`COMMANDS`, aliases, completions, ``help``;
- :mod:`~kinplan.apps.teach.paths`: :class:`RecordedPath`, :func:`fit_spline`, the program's spline;
- :mod:`~kinplan.apps.teach.capture`: a recording under way, each jog sampled into it at jog speed;
- :mod:`~kinplan.apps.teach.state`: the session's state, :class:`Reply`, status, moving the arm;
- :mod:`~kinplan.apps.teach.jogging`: jog commands (``j``, ``x``, ``yaw+``, ``step``, ``home``);
- :mod:`~kinplan.apps.teach.points`: point commands (``r``, ``del``, ``list``);
- :mod:`~kinplan.apps.teach.process`: process commands (``tool``, ``r NAME lin|circ``, ``weave``,
  ``torch``, ``arc``) and the cell the jogs are checked against (``use_cell``);
- :mod:`~kinplan.apps.teach.recording`: continuous-path commands (``rec start``, ``rec stop``);
- :mod:`~kinplan.apps.teach.writer`: the program's YAML text and file (``program_text``, ``save``);
- :mod:`~kinplan.apps.teach.pendant`: :class:`TeachPendant`, one command line dispatched by kind;
- :mod:`~kinplan.apps.teach.prompt`: :class:`PromptLines`, terminal lines with editing and history;
- :mod:`~kinplan.apps.teach.session`: :func:`run_session`, the console loop feeding the pendant.

The pendant's other defaults and limits (``MAX_LINEAR_JOG``, ``HISTORY_LENGTH``, ...) are
importable from here too, as they were from the module this package replaced.
"""

from __future__ import annotations

from kinplan.apps.teach.help import COMMANDS, HELP
from kinplan.apps.teach.paths import RecordedPath, fit_spline
from kinplan.apps.teach.pendant import TeachPendant
from kinplan.apps.teach.prompt import (  # noqa: F401
    HISTORY_ENV,
    HISTORY_LENGTH,
    PromptLines,
    default_history_file,
)
from kinplan.apps.teach.session import run_session
from kinplan.apps.teach.settings import (  # noqa: F401
    DEFAULT_ANGULAR_STEP_DEG,
    DEFAULT_JOG_SPEED,
    DEFAULT_LINEAR_STEP,
    DEFAULT_PATH_TOLERANCE,
    DEFAULT_RATE_HZ,
    MAX_BRANCH_STEP,
    MAX_JOINT_JOG_DEG,
    MAX_LINEAR_JOG,
    MAX_PATH_TOLERANCE_DEG,
    MAX_RATE_HZ,
    MAX_RECORDING_SAMPLES,
    MAX_ROTATION_JOG_DEG,
)
from kinplan.apps.teach.state import Reply, home_configuration

__all__ = [
    "COMMANDS",
    "DEFAULT_JOG_SPEED",
    "DEFAULT_PATH_TOLERANCE",
    "DEFAULT_RATE_HZ",
    "HELP",
    "HISTORY_ENV",
    "PromptLines",
    "RecordedPath",
    "Reply",
    "TeachPendant",
    "default_history_file",
    "fit_spline",
    "home_configuration",
    "run_session",
]
