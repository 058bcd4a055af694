"""Recorded paths: :class:`RecordedPath`, the spline fitted through few of a recording's samples
(:func:`fit_spline`), and the spline a program plays for it, through the knots as the program
reads them (its numbers written by :func:`decimals`), slowed only where a joint velocity limit
requires."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from kinplan import checks, trajectory
from kinplan.apps.teach.settings import DEFAULT_PATH_TOLERANCE
from kinplan.errors import InputError
from kinplan.model.robot import Robot
from kinplan.trajectory import Trajectory
from kinplan.trajectory.sampling import joint_speeds

_SPEED_MARGIN = 1e-3
"""Extra share by which a recorded path's times are stretched when its spline would exceed a
joint velocity limit at the recorded times [-]."""
_SPEED_STEP = 0.0025
"""Time step at which a recorded path's spline is checked against the velocity limits [s] (a
quarter of the programs' default sampling period)."""
_LIMIT_TOLERANCE = 1e-9
"""How far a fitted spline may pass a joint limit at a sample before a knot is added there [rad]."""


@dataclass(frozen=True, eq=False)
class RecordedPath:
    """A continuous path recorded with ``rec start`` / ``rec stop`` and its fitted spline.

    Attributes:
        name: Its name in the session (``path1``, ...); its knots are the program's points
            ``<name>_0``, ``<name>_1``, ...
        rate_hz: Sampling rate of the recording [Hz].
        sample_times: Times of the recorded samples, from 0 [s], shape (N,).
        samples: The recorded configurations [rad], shape (N, n).
        knot_indices: The samples kept as the spline's knots, shape (k,), 0 first, N − 1 last.
        spline: The motion the program plays (:func:`kinplan.trajectory.cubic_via`): the
            clamped cubic spline through the knots as the program reads them (to 1e-6°), at rest
            at both ends, each knot at its recorded time (to 1e-6 s; all stretched alike only if
            the recorded timing would exceed a joint velocity limit). Its waypoints are the
            knots and their times in the program (see :attr:`times`).
        played_times: The time on :attr:`spline` of each sample [s], shape (N,): its recorded
            time (mapped linearly between the knots' times in the program).
        deviation: Largest |spline − recording| over the joints at each sample, both at the
            sample's time [rad], shape (N,).
        tool_deviation: Largest distance between the tool positions of the spline and of the
            recording at the samples' times [m].
        tolerance: The deviation the fit was asked to stay within [rad].
        speed_ratio: The spline's largest joint speed over its velocity limit when timed as
            recorded [-] (joints without a limit left out); above 1 the program plays it slower.
    """

    name: str
    rate_hz: float
    sample_times: np.ndarray
    samples: np.ndarray
    knot_indices: np.ndarray
    spline: Trajectory
    played_times: np.ndarray
    deviation: np.ndarray
    tool_deviation: float
    tolerance: float
    speed_ratio: float

    @property
    def duration(self) -> float:
        """Recorded duration [s]."""
        return float(self.sample_times[-1])

    @property
    def knot_times(self) -> np.ndarray:
        """Times of the knots in the recording [s], shape (k,)."""
        return self.sample_times[self.knot_indices]

    @property
    def knots(self) -> np.ndarray:
        """The knots' configurations as recorded [rad], shape (k, n)."""
        return self.samples[self.knot_indices]

    @property
    def times(self) -> np.ndarray:
        """The program's ``times:``: when the spline passes knots 1, ..., k − 1, from its start
        at knot 0 [s], shape (k − 1,) (the last is its duration)."""
        return self.spline.waypoints.times[1:]

    @property
    def slowed(self) -> bool:
        """Whether the program plays the path slower than recorded (velocity limits)."""
        return self.spline.duration > self.duration + 1e-6

    @property
    def max_deviation(self) -> float:
        """Largest joint deviation of the spline from the recording at the samples [rad]."""
        return float(self.deviation.max())

    def point_names(self) -> list[str]:
        """The program's names of the knots: ``<name>_0``, ``<name>_1``, ..."""
        return [f"{self.name}_{k}" for k in range(len(self.knot_indices))]


def fit_spline(
    samples: ArrayLike,
    times: ArrayLike,
    tolerance: float = DEFAULT_PATH_TOLERANCE,
    lower: ArrayLike | None = None,
    upper: ArrayLike | None = None,
) -> tuple[np.ndarray, Trajectory, np.ndarray]:
    """Few of the recorded samples as knots of a smooth spline, timed as recorded, within
    ``tolerance`` of them all.

    The spline is the one a program's ``ptp`` through several points with ``profile: spline``
    and ``times:`` plays (:func:`kinplan.trajectory.cubic_via`): the clamped cubic spline
    through the knots at their recorded times, at rest at both ends. It is compared with the
    recording at the recorded times (each sample with the spline at the same time), which also
    bounds each sample's distance to the spline's path.

    Knots are inserted greedily: from the first and last sample, each pass adds, between every
    two neighbouring knots, the sample where the spline is farthest from the recording, until no
    sample is farther than ``tolerance`` in any joint and (with limits) none is beyond them.
    Samples less than a tenth of the median time step after the previous candidate are not made
    knots (a sample just before the last one, say); they are still measured.

    Args:
        samples: Recorded configurations, in order, shape (N, n), N ≥ 2 [rad].
        times: Their times, strictly increasing, shape (N,) [s]; the spline's time 0 is
            ``times[0]``.
        tolerance: Largest deviation at a sample, > 0 [rad].
        lower: Joint lower limits, shape (n,) [rad] (−inf where none), or None.
        upper: Joint upper limits, shape (n,) [rad] (inf where none), or None.

    Returns:
        ``(knot_indices, spline, deviation)``: the samples kept as knots (sorted, 0 and N − 1
        included); the spline (its waypoints are the knots at ``times[knot_indices] −
        times[0]``); the largest joint deviation at each sample [rad], shape (N,).

    Raises:
        InputError: not numbers, bad shapes, NaN or inf, times that do not strictly increase,
            a tolerance that is not > 0, or only one of the limits.
    """
    points = checks.floats(samples, "samples", "an (N, n) array of configurations [rad]")
    if points.ndim == 1:
        points = points[:, None]
    if points.ndim != 2 or points.shape[0] < 2 or not np.all(np.isfinite(points)):
        raise InputError(
            f"samples must be a finite (N, n) array with N ≥ 2 [rad], got shape {points.shape}"
        )
    count, n = points.shape
    t = checks.floats(times, "times", "a 1-D array of sample times [s]")
    if t.shape != (count,) or not np.all(np.isfinite(t)):
        raise InputError(
            f"times must be {count} finite sample times [s], one per sample, got shape {t.shape}"
        )
    steps = np.diff(t)
    if np.any(steps < trajectory.MIN_DURATION) or t[-1] - t[0] > trajectory.MAX_DURATION:
        raise InputError("times must strictly increase (by at least 1e-9 s) [s]")
    tolerance = checks.number(tolerance, "tolerance", positive=True, unit="rad")
    if (lower is None) != (upper is None):
        raise InputError("give both lower and upper joint limits, or neither")
    limits = None
    if lower is not None and upper is not None:
        limits = (
            checks.vector(lower, "lower", n, unit="rad", infinite=True),
            checks.vector(upper, "upper", n, unit="rad", infinite=True),
        )
    candidate = _spaced(t, 0.1 * float(np.median(steps)))
    knots = np.array([0, count - 1])
    while True:
        spline = trajectory.cubic_via(points[knots], t[knots])
        fitted = spline.sample(t - t[0])[0]
        deviation = np.abs(fitted - points).max(axis=1)
        error = deviation.copy()
        if limits is not None:
            beyond = (fitted < limits[0] - _LIMIT_TOLERANCE) | (
                fitted > limits[1] + _LIMIT_TOLERANCE
            )
            error[beyond.any(axis=1)] = np.inf
        added = []
        for first, last in zip(knots[:-1], knots[1:], strict=True):
            inside = np.arange(first + 1, last)
            if not len(inside) or error[inside].max() <= tolerance:
                continue
            eligible = inside[candidate[inside]]
            if len(eligible):
                added.append(int(eligible[np.argmax(error[eligible])]))
        if not added:
            return knots, spline, deviation
        knots = np.union1d(knots, added)


def _spaced(times: np.ndarray, gap: float) -> np.ndarray:
    """Which samples may be knots: each at least ``gap`` [s] after the previous one (the last
    sample always, in place of a previous one closer than ``gap``)."""
    candidate = np.zeros(len(times), dtype=bool)
    last = 0
    candidate[0] = True
    for k in range(1, len(times)):
        if times[k] - times[last] >= gap:
            candidate[k] = True
            last = k
    if not candidate[-1]:
        if last:
            candidate[last] = False
        candidate[-1] = True
    return candidate


def decimals(values: np.ndarray) -> str:
    """Numbers as a YAML list, to 6 decimals (no trailing zeros, no "-0")."""
    texts = (f"{v:.6f}".rstrip("0").rstrip(".") for v in values)
    return "[" + ", ".join("0" if text == "-0" else text for text in texts) + "]"


def _as_read(values: np.ndarray) -> np.ndarray:
    """The numbers a program reads back from :func:`decimals` (rounded to 6 decimals)."""
    return np.array([float(f"{v:.6f}") for v in values])


def program_spline(
    robot: Robot, knot_times: np.ndarray, knots: np.ndarray
) -> tuple[Trajectory, float, int]:
    """The spline a program plays for a recorded path: the clamped cubic spline, at rest at both
    ends, through ``knots`` [rad] (k, n) as the program reads them (to 1e-6°) at their recorded
    times ``knot_times`` [s] (k,) from the first (to 1e-6 s), all stretched alike if the recorded
    timing would exceed a joint velocity limit.

    Returns:
        The spline, its largest joint speed over the velocity limit when timed as recorded [-]
        and the joint where that is.
    """
    positions = np.radians(np.array([_as_read(np.degrees(q)) for q in knots]))
    recorded = knot_times - knot_times[0]
    spline = trajectory.cubic_via(positions, _as_read(recorded))
    first, joint = _speed_ratio(robot, spline)
    ratio, stretch = first, 1.0
    for _ in range(10):  # one stretch is enough, but for rounding
        if ratio <= 1.0:
            break
        stretch *= ratio * (1.0 + _SPEED_MARGIN)
        spline = trajectory.cubic_via(positions, _as_read(recorded * stretch))
        ratio, _ = _speed_ratio(robot, spline)
    return spline, first, joint


def _speed_ratio(robot: Robot, spline: Trajectory) -> tuple[float, int]:
    """The largest joint speed of ``spline`` over its velocity limit [-] (sampled every
    :data:`_SPEED_STEP`, with the mean speeds between samples as the programs check it; joints
    without a limit left out, 0 when none has one) and the joint where that is."""
    limit = robot.velocity_limit
    if not np.isfinite(limit).any():
        return 0.0, 0
    t = spline.time_grid(_SPEED_STEP)
    q, qd, _ = spline.sample(t)
    share = joint_speeds(q, qd, t).max(axis=0) / limit  # 0 where the limit is inf
    joint = int(np.argmax(share))
    return float(share[joint]), joint
