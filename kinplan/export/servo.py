"""A whole motion resampled at a controller's period: the targets of a ``servoj`` stream
(:func:`servo_samples`), the plan's own continuous motion at ``t = k · period``.
"""

from __future__ import annotations

import numpy as np

from kinplan import checks, defaults
from kinplan.export.continuous import continuous_motion
from kinplan.export.whole_motion import whole_motion
from kinplan.trajectory import time_grid
from kinplan.trajectory.motion import SampledMotion

__all__ = ["DEFAULT_SERVO_PERIOD", "servo_samples", "servo_targets"]


DEFAULT_SERVO_PERIOD = defaults.DEFAULT_SERVO_PERIOD
"""Period of the ``servoj`` stream [s]: the CB-series controller's 125 Hz (e-Series: 0.002)."""


def servo_samples(
    plan: SampledMotion, period: float = DEFAULT_SERVO_PERIOD
) -> tuple[np.ndarray, np.ndarray]:
    """The motion resampled at a controller's period: the targets of a ``servoj`` stream.

    The times are ``k · period`` from the plan's first sample, the last exactly at its end
    (:func:`kinplan.trajectory.time_grid`: ceil(duration / period) + 1 samples, a remainder
    below 10⁻⁶ period absorbed); the positions are the plan's continuous motion there (its own
    ``sample`` for a program plan or a sampled joint trajectory, otherwise the quintic Hermite
    interpolation of the plan's samples: positions, velocities and accelerations), the first
    ``plan.q[0]`` and the last ``plan.q[-1]``, exactly. That motion is checked against the
    robot's limits first (:func:`check_limits` with ``between="plan"``).

    Args:
        plan: A whole motion (:class:`~kinplan.motion.SampledMotion` that is ok).
        period: Sampling period [s], > 0.

    Returns:
        Times (K,) [s] from the plan's start and joint positions (K, nq) [rad or m].

    Raises:
        InputError: not a motion, a failed plan, samples that are not finite or whose times do
            not increase, or a period that is not a positive number.
        LimitViolationError: the motion breaks its robot's limits (:func:`check_limits`).
    """
    return servo_targets(plan, period, "servo_samples")


def servo_targets(plan: SampledMotion, period: float, what: str) -> tuple[np.ndarray, np.ndarray]:
    """:func:`servo_samples`, its errors naming ``what``."""
    step = checks.number(period, "period", positive=True, unit="s")
    t, q, qd, qdd = whole_motion(plan, what, between="plan")
    times = time_grid(float(t[-1] - t[0]), step)
    if len(t) == 1:
        return times, np.repeat(q, len(times), axis=0)
    targets = np.array(continuous_motion(plan, t, q, qd, qdd, "plan")(times)[0], dtype=float)
    targets[0], targets[-1] = q[0], q[-1]  # the motion's ends, exactly
    return times, targets
