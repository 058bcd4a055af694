"""Motion programs: a YAML file of taught points and moves, validated and planned.

A program names a robot, a start configuration, taught points and a list of moves::

    robot: ur5                 # a load_robot source; a URDF path is relative to this file
    tip: tool0                 # optional
    start: {joints_deg: [0, -90, 90, -90, -90, 0]}
    points:                    # joints / joints_deg, or xyz [m] (+ rpy_deg or quat_xyzw)
      a: {xyz: [0.40, -0.10, 0.20], rpy_deg: [180, 0, 90]}
      b: {xyz: [0.40,  0.10, 0.20], rpy_deg: [180, 0, 90]}
      c: {xyz: [0.50,  0.00, 0.20], rpy_deg: [180, 0, 90]}
    moves:                     # ptp: joint-interpolated; lin: straight line; circ: arc via a point
      - {ptp: a, duration: 2.0}
      - {lin: b, speed: 0.02}
      - {circ: a, via: c, speed: 0.02}

Moves and their options:

- ``ptp``: joint-interpolated. By default a coordinated minimum-time trapezoid: every joint
  cruises within ``speed`` × its velocity limit (``speed`` is a fraction in (0, 1], default
  :data:`DEFAULT_PTP_SPEED`) and reaches its cruise speed in :data:`PTP_RAMP_TIME` (sooner
  where an acceleration limit is lower); with a ``duration`` [s] the move takes that long.
  Every profile keeps the continuous motion (not only its samples) within the joint position,
  velocity and acceleration limits: a ``duration`` or ``times`` too short is refused with
  the shortest one that works (rounded up, so that it can be pasted), a ``spline`` that
  overshoots a joint limit between its points is refused (``joint_limit``).
  ``profile``: ``trapezoid`` (default), ``quintic``, ``cubic``, ``scurve`` (jerk-limited, jerk
  ramps of :data:`PTP_JERK_TIME`) or ``time_optimal`` (fastest within the velocity and
  acceleration limits); ``scurve`` and ``time_optimal`` use the robot's acceleration limits
  where it has them (else the :data:`PTP_RAMP_TIME` ramp), and with a ``duration`` the full
  limits, refusing a duration they cannot meet with the minimum it needs. A ``ptp`` to a
  Cartesian point solves IK seeded from the current configuration, so the arm stays on its
  branch.
- ``lin``: the tool moves on a straight line from its current pose, at a tool ``speed`` [m/s]
  (default :data:`DEFAULT_TOOL_SPEED`) or in a ``duration`` [s], with the 1-D ``profile``.
- ``circ``: the tool moves on the arc through ``via`` to the target, as ``lin``.

Every move lasts a whole number of sampling periods ``dt``: the arm is held at rest at the
move's end for the rest of its last period (its motion, timing and peaks unchanged; a dwell is
rounded up to whole periods), so the program's samples are one grid t = 0, dt, 2 dt, ..., the
last at its end.

A Cartesian point given by ``xyz`` alone keeps the tool orientation the move starts with (arms
with 6 or more joints) or is position-only (arms with fewer). Every move starts from the end
state of the previous one.

``max_acceleration``: joint acceleration limits [rad/s² or m/s²], one number for every joint
or a list of one per joint (at most :data:`~kinplan.program.schema.MAX_ACCELERATION`), at the
top level (every move) or on a move (that move; it replaces the top-level one). They hold on
top of the robot's own (the URDF's, or ``limits:``): the lower one wins. ``ptp`` moves are
planned within them (or refused, as above); ``lin``/``circ`` moves are checked against them
at every sample (``acceleration_limit``). A joint limited by neither is not
acceleration-limited: the plan's :attr:`ProgramPlan.notes` says so, with the largest
acceleration the plan reaches (UR URDFs declare no acceleration limits).

Numbers are bounded where a larger one can only be a mistake: ``duration``, ``dwell`` and
``times`` at most :data:`~kinplan.program.schema.MAX_SECONDS`, integers of at most
:data:`~kinplan.program.schema.MAX_INTEGER_DIGITS` digits, and a planned program has at most
:data:`~kinplan.program.schema.MAX_SAMPLES` samples (a move that would exceed it fails naming
the dt).

Optional robot keys, passed to :func:`kinplan.load_robot`: ``locked_joints: {name: value}``
[rad, or m for a prismatic joint], ``limits: {joint: {lower, upper, velocity, acceleration}}``
(any subset) [rad or m, per s, per s²], ``package_dirs: [folder, ...]`` (mesh folders,
relative to the program file) and ``base_pose: {xyz: [..], rpy_deg: [..] | quat_xyzw: [..]}``
(the robot's root in the world, in which the points are given).

:func:`load_program` reads and validates a whole file and raises one :class:`ProgramError`
listing every problem with its key path (``moves[2].lin``) and YAML line; :func:`plan_program`
plans it into a :class:`ProgramPlan`. A move that cannot be done stops planning: the plan has
``ok = False`` and a one-line ``reason`` naming the move and where it failed; it holds the motion
up to the failure for inspection. :class:`MotionBuilder` chains the same moves from Python, and
also follows any :class:`cartesian.Path` (a weld seam made of lines and arcs, say).

Modules, each importing only those above it:

- :mod:`~kinplan.program.schema`: keys, defaults, :class:`Program`, :class:`Point`,
  :class:`Move`, the YAML 1.2 loader;
- :mod:`~kinplan.program.segments`: quintic Hermite pieces through samples;
- :mod:`~kinplan.program.plan`: :class:`ProgramPlan`, :class:`MoveReport`;
- :mod:`~kinplan.program.errors`: :class:`Issue`, :class:`ProgramError`, :class:`MoveError`;
- :mod:`~kinplan.program.checker`: collects issues with key path and line, reads checked values;
- :mod:`~kinplan.program.robots` (source resolution, cache), then one module per section:
  :mod:`~kinplan.program.robot_keys`, :mod:`~kinplan.program.process` (``arc:``, ``io:``,
  ``weld:`` of moves and points, ``job_output:``, ``payload:``, ``color:``),
  :mod:`~kinplan.program.points`, :mod:`~kinplan.program.moves`;
- :mod:`~kinplan.program.validate`: :func:`load_program`, :func:`parse_program`;
- :mod:`~kinplan.program.peaks` (exact peaks of polynomial motions),
  :mod:`~kinplan.program.ptp` (timing of ptp moves), :mod:`~kinplan.program.joint_checks` (a
  ptp move's speed share and cell check), :mod:`~kinplan.program.record` (samples and reports
  so far), :mod:`~kinplan.program.remedies` (how a failed move is worded),
  :mod:`~kinplan.program.seams` (the Cartesian paths of lin/circ moves, weaves, torches),
  :mod:`~kinplan.program.builder_base`, :mod:`~kinplan.program.cartesian_moves` and
  :mod:`~kinplan.program.build` (:class:`MotionBuilder`);
- :mod:`~kinplan.program.run`: :func:`plan_program`, :func:`run_program`.
"""

from __future__ import annotations

from kinplan.program.build import MotionBuilder
from kinplan.program.errors import Issue, MoveError, ProgramError
from kinplan.program.plan import MoveReport, ProgramPlan
from kinplan.program.robots import resolve_robot_source
from kinplan.program.run import plan_program, run_program
from kinplan.program.schema import (
    DEFAULT_DT,
    DEFAULT_PTP_SPEED,
    DEFAULT_TOOL_SPEED,
    FALLBACK_JOINT_SPEED,
    JOIN_TOLERANCE,
    MAX_COORDINATE,
    MOVE_KINDS,
    PTP_JERK_TIME,
    PTP_RAMP_TIME,
    KeyPath,
    Move,
    Point,
    Program,
)
from kinplan.program.segments import hermite_segments
from kinplan.program.validate import load_program, parse_program
from kinplan.trajectory._profiles import PROFILES

__all__ = [
    "DEFAULT_DT",
    "DEFAULT_PTP_SPEED",
    "DEFAULT_TOOL_SPEED",
    "FALLBACK_JOINT_SPEED",
    "JOIN_TOLERANCE",
    "MAX_COORDINATE",
    "MOVE_KINDS",
    "PROFILES",
    "PTP_JERK_TIME",
    "PTP_RAMP_TIME",
    "Issue",
    "KeyPath",
    "MotionBuilder",
    "Move",
    "MoveError",
    "MoveReport",
    "Point",
    "Program",
    "ProgramError",
    "ProgramPlan",
    "hermite_segments",
    "load_program",
    "parse_program",
    "plan_program",
    "resolve_robot_source",
    "run_program",
]
