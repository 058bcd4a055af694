"""The pendant's defaults and limits: jog steps and their largest values, the recording's rate,
tolerance and jog speed."""

from __future__ import annotations

DEFAULT_LINEAR_STEP = 0.01
"""Default tool jog [m]."""
DEFAULT_ANGULAR_STEP_DEG = 5.0
"""Default joint and tool rotation jog [deg]."""
MAX_BRANCH_STEP = 0.5
"""Joint change a tool jog may cause, beyond its length [m] and angle [rad], before it counts as
a branch flip [rad] (jogs are also checked for continuity along the way)."""
MAX_LINEAR_JOG = 10.0
"""Longest tool jog or linear step the pendant accepts [m] (beyond the reach of any arm)."""
MAX_JOINT_JOG_DEG = 720.0
"""Largest joint jog the pendant accepts [deg] (two turns, for continuous joints)."""
MAX_ROTATION_JOG_DEG = 180.0
"""Largest tool rotation jog or angle step the pendant accepts [deg]."""

DEFAULT_RATE_HZ = 50.0
"""Sampling rate of a continuous-path recording (``rec start``) [Hz]."""
MAX_RATE_HZ = 1000.0
"""Highest sampling rate ``rec start`` accepts [Hz]."""
DEFAULT_PATH_TOLERANCE = 1e-3
"""Largest joint deviation of a recorded path's spline from the recording (``rec stop``) [rad]."""
MAX_PATH_TOLERANCE_DEG = 10.0
"""Largest tolerance ``rec stop`` accepts [deg]."""
DEFAULT_JOG_SPEED = 0.1
"""Jog speed, share of the joint velocity limits [-]: a recorded jog cruises at most at this
share of each joint's limit (joints without one at the programs' fallback speed) and reaches it
in the programs' ramp time (the acceleration limits, scaled alike, where the robot has them)."""
MAX_RECORDING_SAMPLES = 200_000
"""Most samples one recording keeps (over an hour at 50 Hz); ``rec stop`` and start again."""
