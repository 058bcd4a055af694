"""Time scaling of a Cartesian path: the tool's progress along it as a function of time.

The 1-D profiles are those of :mod:`kinplan.trajectory` (one implementation serves joint and
Cartesian planning): the arc length u(t) ∈ [0, L] [m] follows a trapezoid (cruise at the tool
speed), a quintic or a cubic, given a duration or a tool speed. The path fraction is s = u / L.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from kinplan import trajectory
from kinplan.errors import InputError
from kinplan.trajectory._profiles import PROFILES, REST_TO_REST_PEAKS

#: A time law: times t [s] (N,) ↦ (s, ṡ, s̈), each (N,), s ∈ [0, 1].
TimeLaw = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]

#: Default time to reach the cruise speed when only a tool speed is given [s].
DEFAULT_RAMP_TIME = 0.25


@dataclass
class PathTiming:
    """Samples of a time law s(t) along a path.

    Attributes:
        t: Sample times [s]: the caller's grid 0, dt, ..., duration (the last exactly at the
            end), or a finer check grid made from it (:meth:`refined`).
        s: Path fractions [-].
        sd: ds/dt [1/s].
        sdd: d²s/dt² [1/s²].
        duration: Motion duration [s].
        law: The law itself, to sample it at other times.
        rest_from: When the path's end is reached and the tool held there until
            ``duration`` (:meth:`on_whole_periods`) [s]; None: at ``duration``.
    """

    t: np.ndarray
    s: np.ndarray
    sd: np.ndarray
    sdd: np.ndarray
    duration: float
    law: TimeLaw
    rest_from: float | None = None

    @property
    def moving_intervals(self) -> float:
        """How many intervals of :attr:`t` the motion lasts (a fraction of one for a motion
        shorter than a period held at rest until the period's end)."""
        if self.rest_from is None or len(self.t) < 2:
            return float(len(self.t) - 1)
        return self.rest_from / float(self.t[1] - self.t[0])

    def refined(self, parts: int) -> PathTiming:
        """The same law on a grid that splits every interval of :attr:`t` into ``parts`` equal
        ones: sample k of this grid is sample ``k * parts`` of the refined one."""
        if parts == 1 or len(self.t) < 2:
            return self
        steps = np.diff(self.t)
        inner = self.t[:-1, None] + steps[:, None] * (np.arange(parts) / parts)
        return at_times(self.law, np.append(inner.ravel(), self.t[-1]), self.duration)

    def on_whole_periods(self, dt: float) -> PathTiming:
        """The same law, then at rest at its end (s = 1) until a whole number of periods
        ``dt`` [s] (:func:`kinplan.trajectory.whole_periods`: less than one period more),
        sampled at 0, dt, ..., the end: the motion itself is unchanged (its samples before its
        end are the same). Programs plan their moves so, that all their samples lie on one
        grid."""
        duration = trajectory.whole_periods(self.duration, dt)
        if duration <= self.duration * (1.0 + 1e-12) or self.duration == 0.0:
            return self  # whole already, to rounding
        end, law = self.duration, self.law

        def held(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            s, sd, sdd = law(np.minimum(t, end))
            after = t >= end
            return np.where(after, 1.0, s), np.where(after, 0.0, sd), np.where(after, 0.0, sdd)

        timing = at_times(held, trajectory.time_grid(duration, dt), duration)
        timing.rest_from = end
        return timing

    @property
    def peak_speed(self) -> float:
        """Largest ṡ over the samples [1/s]."""
        return float(np.abs(self.sd).max(initial=0.0))


def at_times(law: TimeLaw, t: np.ndarray, duration: float) -> PathTiming:
    """Sample ``law`` at the times ``t`` [s] (the last the end: s = 1 exactly there)."""
    s, sd, sdd = law(t)
    s = np.clip(s, 0.0, 1.0)
    s[-1] = 1.0
    return PathTiming(t, s, sd, sdd, float(duration), law)


def path_law(
    length: float,
    duration: float | None = None,
    speed: float | None = None,
    acceleration: float | None = None,
    profile: str = "trapezoid",
) -> tuple[trajectory.Trajectory, float]:
    """The 1-D law of the path parameter and the scale from it to s.

    Args:
        length: Path length L [m] (0 for a pure re-orientation: then s itself is planned).
        duration: Motion duration [s]; or
        speed: Tool cruise speed [m/s] (the peak speed for quintic/cubic).
        acceleration: Tool acceleration [m/s²] of the trapezoid; default speed / 0.25 s.
        profile: "trapezoid", "quintic" or "cubic".

    Returns:
        (law, scale): the profile in metres (or in s for zero length) and 1 / L (or 1).
    """
    if profile not in PROFILES:
        raise InputError(f"unknown profile {profile!r}; choose one of {', '.join(PROFILES)}")
    if (duration is None) == (speed is None):
        raise InputError("give exactly one of duration [s] or speed [m/s] for a Cartesian motion")
    for name, value in (("duration", duration), ("speed", speed), ("acceleration", acceleration)):
        if value is not None and not (np.isfinite(value) and value > 0):
            raise InputError(f"{name} must be a finite number > 0, got {value!r}")
    distance, scale = (length, 1.0 / length) if length > 0 else (1.0, 1.0)
    if speed is not None:
        if length <= 0:
            raise InputError("a tool speed needs a path of non-zero length; give a duration")
        if profile == "trapezoid":
            accel = acceleration if acceleration is not None else speed / DEFAULT_RAMP_TIME
            law = trajectory.trapezoid(0.0, distance, max_velocity=speed, max_acceleration=accel)
            return law, scale
        duration = REST_TO_REST_PEAKS[profile][0] * distance / speed  # peak speed k_v L/T
    assert duration is not None  # exactly one of duration and speed (checked above)
    if profile == "trapezoid":
        law = trajectory.trapezoid(0.0, distance, duration=duration, acceleration=acceleration)
    elif profile == "quintic":
        law = trajectory.quintic(0.0, distance, duration)
    else:
        law = trajectory.cubic(0.0, distance, duration)
    return law, scale


def time_path(
    length: float,
    duration: float | None = None,
    speed: float | None = None,
    acceleration: float | None = None,
    profile: str = "trapezoid",
    dt: float = 0.01,
) -> PathTiming:
    """Sample the time law of a path of the given length every ``dt`` seconds.

    See :func:`path_law` for the arguments; ``dt`` [s] is the sampling period.
    """
    if not (np.isfinite(dt) and dt > 0):
        raise InputError(f"dt must be a finite number of seconds > 0, got {dt!r}")
    return sample_law(*path_law(length, duration, speed, acceleration, profile), dt)


def sample_law(law: trajectory.Trajectory, scale: float, dt: float) -> PathTiming:
    """Sample a 1-D law u(t) every ``dt`` seconds (t = 0, dt, ..., the last exactly at the end:
    the caller's grid) as path fractions s = scale · u, the last exactly 1 (``scale``: 1 / path
    length [1/m], or 1 for a law of s itself)."""

    def fractions(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        u, ud, udd = law.sample(t)
        return u[:, 0] * scale, ud[:, 0] * scale, udd[:, 0] * scale

    return at_times(fractions, trajectory.time_grid(law.duration, dt), float(law.duration))
