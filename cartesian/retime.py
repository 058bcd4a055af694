"""Retiming a path so every joint stays within its speed limit (near singularities).

The geometric pass gives dq/ds along the path; each joint's speed limit caps the path speed at
ṡ ≤ v_j / |dq_j/ds|. A forward and a backward pass with the nominal law's largest path
acceleration turn the nominal speed, capped by those limits, into a feasible speed profile
ṡ(s). Between grid points the path acceleration is constant, so the new law is a chain of
quadratic segments: a :class:`kinplan.trajectory.Trajectory`, sampled by the same evaluator as
every other profile. The path itself is unchanged; only its timing is slower where needed.
"""

from __future__ import annotations

import numpy as np

from cartesian.timing import PathTiming, sample_law
from kinplan import trajectory

#: Share of the joint speed limits the retimed motion aims for (the rest absorbs sampling).
SPEED_MARGIN = 0.98
#: Spacing of the geometric grid along the path [m], and its bounds on the number of points.
GRID_SPACING = 0.0005
GRID_POINTS = (201, 20001)


def retime_for_speed_limits(
    s: np.ndarray, dq_ds: np.ndarray, speed_limit: np.ndarray, timing: PathTiming, dt: float
) -> PathTiming:
    """A slower time law for a path within the joint speed limits, or ``timing`` unchanged.

    Args:
        s: Path fractions of the geometric pass, increasing from 0 to 1 (see
            :data:`GRID_SPACING` for a sensible spacing).
        dq_ds: Joint rates dq/ds there (N, nq) [rad or m per unit s].
        speed_limit: Joint speed limits (nq,) [rad/s or m/s].
        timing: The nominal time law.
        dt: Sampling period [s].

    Returns:
        ``timing`` itself when it already respects the limits, else the retimed law, sampled.
    """
    rates = np.abs(dq_ds)
    with np.errstate(divide="ignore"):
        cap = np.min(SPEED_MARGIN * speed_limit / rates, axis=1)
    nominal = np.interp(s, timing.s, timing.sd)
    if np.all(nominal <= cap / SPEED_MARGIN):
        return timing
    top = float(timing.sd.max())
    accel = float(np.abs(timing.sdd).max())
    speed = _feasible_speeds(np.minimum(cap, top), np.diff(s), accel)
    return sample_law(_law_from_speeds(s, speed), 1.0, dt)


def grid_points(length: float) -> int:
    """Number of points of the geometric grid of a path of ``length`` [m]."""
    return int(np.clip(np.ceil(length / GRID_SPACING) + 1, *GRID_POINTS))


def _feasible_speeds(cap: np.ndarray, ds: np.ndarray, accel: float) -> np.ndarray:
    """Largest ṡ(s) ≤ cap, at rest at both ends, with |s̈| ≤ accel (forward/backward passes)."""
    speed = cap.copy()
    speed[0] = speed[-1] = 0.0
    for i in range(len(ds)):
        speed[i + 1] = min(speed[i + 1], np.sqrt(speed[i] ** 2 + 2.0 * accel * ds[i]))
    for i in range(len(ds) - 1, -1, -1):
        speed[i] = min(speed[i], np.sqrt(speed[i + 1] ** 2 + 2.0 * accel * ds[i]))
    return speed


def _law_from_speeds(s: np.ndarray, speed: np.ndarray) -> trajectory.Trajectory:
    """Constant-acceleration segments between grid points with the given speeds ṡ."""
    ds = np.diff(s)
    durations = 2.0 * ds / (speed[:-1] + speed[1:])
    accel = (speed[1:] - speed[:-1]) / durations
    knots = np.concatenate(([0.0], np.cumsum(durations)))
    segments = [
        trajectory.Segment(knots[i], knots[i + 1], np.array([[s[i], speed[i], 0.5 * accel[i]]]))
        for i in range(len(ds))
    ]
    return trajectory.Trajectory(segments, end=[1.0], end_velocity=[0.0], end_acceleration=[0.0])
