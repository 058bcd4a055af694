"""Default values the command line shows in its help, kept apart from the modules that use
them so that building the parser loads none of those modules (``kinplan info`` starts fast)."""

from __future__ import annotations

DEFAULT_DT = 0.01
"""Sampling period of planned programs [s]."""

DEFAULT_SERVO_PERIOD = 0.008
"""Period of the ``servoj`` stream [s]: the CB-series controller's 125 Hz (e-Series: 0.002)."""
