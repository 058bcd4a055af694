"""Files out of a planned motion: CSV samples, a plot, and programs a controller can run.

:func:`write_csv` writes one row per sample (time, joint positions, velocities, accelerations and
the tool pose); :func:`plot_motion` draws joint position, velocity, acceleration and the tool
speed against time, with the move boundaries. Both take any planned motion with a robot
(:class:`kinplan.motion.SampledMotion`: a :class:`kinplan.program.ProgramPlan`, a
:class:`cartesian.CartesianPlan`, or a joint trajectory sampled by
:func:`kinplan.motion.sampled` with its robot); the tool poses and speeds come from the robot's
kinematics at the samples (:func:`kinplan.motion.tool_track`).

Controller exports (issue 17) take the same motions, but only whole ones: a failed plan is
refused (:class:`~kinplan.errors.InputError`), since a controller would run the partial motion.

* :func:`urscript` / :func:`write_urscript`: a URScript program for a Universal Robots arm that
  goes to the start with ``movej`` and replays the motion with one ``servoj`` per controller
  period, the motion resampled at that period (:func:`servo_samples`);
* :func:`joint_trajectory` / :func:`write_joint_trajectory`: a ROS 2
  ``trajectory_msgs/msg/JointTrajectory`` document (JSON or YAML) holding the plan's samples.

Between its samples a motion is its own continuous motion when it has one (a
:class:`~kinplan.program.ProgramPlan` is a Trajectory: a ptp move's profile, the quintic Hermite
through the samples of the other moves; a sampled joint trajectory is the trajectory), otherwise
the quintic Hermite interpolation of the samples (exact in position, velocity and acceleration
at every sample: :func:`kinplan.program.hermite_segments`). The servo stream resamples the
former; a controller given the written points (a JointTrajectory, a CSV) interpolates the
latter.

Every export that writes a motion (:func:`write_csv`, :func:`servo_samples`, :func:`urscript`,
:func:`joint_trajectory` and their writers) first checks the continuous motion it stands for
against the robot's limits, whatever built the motion (:func:`check_limits`): positions,
velocities and the accelerations the robot declares, at the samples and between them. A motion
beyond a limit is refused with a :class:`LimitViolationError` naming the joint, the time, the
value and the limit.

Modules, each one job (imports go down the list, never up, type-only imports included;
Matplotlib is imported only when a plot is drawn, PyYAML only when YAML is written):

* :mod:`~kinplan.export.common`: helpers the exports share: a motion's checked samples, its
  joint names, its tool along the motion, writing a text file, the ``kinplan.export`` logger;
* :mod:`~kinplan.export.continuous`: the continuous motion a sampled motion stands for (its own,
  or the quintic Hermite through its samples) as a function of time;
* :mod:`~kinplan.export.limits`: :func:`check_limits` and :class:`LimitViolationError`, the
  limit check every export runs;
* :mod:`~kinplan.export.csv`: :func:`write_csv` and :func:`csv_header`, one row per sample;
* :mod:`~kinplan.export.whole_motion`: what a controller may run: a whole plan
  (:func:`plan_failure`) within its robot's limits;
* :mod:`~kinplan.export.servo`: :func:`servo_samples`, the motion resampled at a controller's
  period (:data:`DEFAULT_SERVO_PERIOD`);
* :mod:`~kinplan.export.ur_arm`: what URScript needs of a robot (:func:`ur_arm_problem`,
  :data:`UR_JOINT_NAMES`) and how it writes numbers and poses;
* :mod:`~kinplan.export.controller_model`: an independent model of a UR controller's
  ``movej`` / ``movel`` / ``movec`` / ``movep`` motion (trapezoids, lines, circles, blends);
* :mod:`~kinplan.export.native`: :func:`native_program`, the program's moves as native
  commands, each replayed by the controller model and checked before it is written;
* :mod:`~kinplan.export.urscript`: :func:`urscript`, :func:`write_urscript` in the ``native``
  or ``servo`` style (:data:`URSCRIPT_STYLES`, :func:`default_style`);
* :mod:`~kinplan.export.joint_trajectory`: :func:`joint_trajectory`,
  :func:`write_joint_trajectory`, :func:`ros_duration`, :func:`trajectory_format`;
* :mod:`~kinplan.export.plots`: :func:`plot_motion`, with the move boundaries and the clearance.

Every public name is re-exported here: ``from kinplan.export import ...`` as before.
"""

from kinplan.export.csv import csv_header, write_csv
from kinplan.export.joint_trajectory import (
    TRAJECTORY_FORMATS,
    joint_trajectory,
    ros_duration,
    trajectory_format,
    write_joint_trajectory,
)
from kinplan.export.limits import (
    CHECK_SUBDIVISIONS,
    POSITION_SLACK,
    RATE_SLACK,
    LimitViolationError,
    check_limits,
)
from kinplan.export.native import FALLBACKS, NativeProgram, controller_frames, native_program
from kinplan.export.plots import plot_motion
from kinplan.export.servo import DEFAULT_SERVO_PERIOD, servo_samples
from kinplan.export.urscript import (
    UR_JOINT_NAMES,
    URSCRIPT_STYLES,
    default_style,
    ur_arm_problem,
    urscript,
    write_urscript,
)
from kinplan.export.whole_motion import plan_failure

__all__ = [
    "CHECK_SUBDIVISIONS",
    "DEFAULT_SERVO_PERIOD",
    "FALLBACKS",
    "POSITION_SLACK",
    "RATE_SLACK",
    "TRAJECTORY_FORMATS",
    "URSCRIPT_STYLES",
    "UR_JOINT_NAMES",
    "LimitViolationError",
    "NativeProgram",
    "check_limits",
    "controller_frames",
    "csv_header",
    "default_style",
    "joint_trajectory",
    "native_program",
    "plan_failure",
    "plot_motion",
    "ros_duration",
    "servo_samples",
    "trajectory_format",
    "ur_arm_problem",
    "urscript",
    "write_csv",
    "write_joint_trajectory",
    "write_urscript",
]
