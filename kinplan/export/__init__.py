"""Files out of a planned motion: CSV samples, a plot, and programs a controller can run.

The module moved as it is to :mod:`kinplan.export.plots` (history follows); its names are
re-exported here, where they were.
"""

from kinplan.export.plots import (
    CHECK_SUBDIVISIONS,
    DEFAULT_SERVO_PERIOD,
    POSITION_SLACK,
    RATE_SLACK,
    TRAJECTORY_FORMATS,
    UR_JOINT_NAMES,
    LimitViolationError,
    check_limits,
    csv_header,
    joint_trajectory,
    plan_failure,
    plot_motion,
    ros_duration,
    servo_samples,
    trajectory_format,
    ur_arm_problem,
    urscript,
    write_csv,
    write_joint_trajectory,
    write_urscript,
)

__all__ = [
    "CHECK_SUBDIVISIONS",
    "DEFAULT_SERVO_PERIOD",
    "POSITION_SLACK",
    "RATE_SLACK",
    "TRAJECTORY_FORMATS",
    "UR_JOINT_NAMES",
    "LimitViolationError",
    "check_limits",
    "csv_header",
    "joint_trajectory",
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
