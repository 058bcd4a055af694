"""The trajectory types: polynomial :class:`Segment` s, :class:`Waypoints` and the
:class:`Trajectory` that evaluates them (vectorised), with :func:`time_grid`."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from kinplan.errors import InputError
from kinplan.trajectory import _profiles
from kinplan.trajectory.arguments import (
    describe,
    finite_array,
    joint_vectors,
    scalar_value,
)

__all__ = [
    "CONTINUITY_TOLERANCE",
    "MAX_SAMPLES",
    "Segment",
    "Trajectory",
    "Waypoints",
    "check_rates_continuous",
    "from_pieces",
    "time_grid",
]

CONTINUITY_TOLERANCE = 1e-9
"""Largest position gap accepted between consecutive segments or trajectories [rad]."""

_BLOCK = 4096
"""Samples evaluated per block by :meth:`Trajectory.sample` (cache-sized temporaries)."""

_GRID_TOLERANCE = 1e-6
"""A remainder below this fraction of ``dt`` does not add a sample to :func:`time_grid` [-]."""

MAX_SAMPLES = 10_000_000
"""Most samples :func:`time_grid` returns (80 MB of times); a finer grid is a mistake in dt."""


@dataclass(frozen=True, eq=False)
class Segment:
    """One polynomial piece of a trajectory.

    Attributes:
        t0: Start time [s].
        t1: End time [s], ``t1 >= t0``.
        coefficients: Shape (n, degree + 1), lowest power first, in local time τ = t − t0:
            ``q_j(t) = Σ_k coefficients[j, k] τ^k`` [rad, rad/s, rad/s², ...].
    """

    t0: float
    t1: float
    coefficients: np.ndarray

    def __post_init__(self) -> None:
        coefficients = finite_array(self.coefficients, "segment coefficients")
        if coefficients.ndim != 2 or coefficients.size == 0:
            raise InputError(
                f"segment coefficients must have shape (n, degree + 1), got {coefficients.shape}"
            )
        t0, t1 = scalar_value(self.t0, "segment t0"), scalar_value(self.t1, "segment t1")
        if t1 < t0:
            raise InputError(f"segment times must have t1 >= t0, got t0={t0}, t1={t1}")
        coefficients.setflags(write=False)
        object.__setattr__(self, "t0", t0)
        object.__setattr__(self, "t1", t1)
        object.__setattr__(self, "coefficients", coefficients)

    @property
    def duration(self) -> float:
        """Length of the segment [s]."""
        return self.t1 - self.t0

    @property
    def degree(self) -> int:
        """Polynomial degree."""
        return self.coefficients.shape[1] - 1


@dataclass(frozen=True, eq=False)
class Waypoints:
    """Points a trajectory was asked to visit, for plotting (not necessarily passed through).

    Attributes:
        times: Nominal times, shape (k,) [s].
        positions: Positions, shape (k, n) [rad].
    """

    times: np.ndarray
    positions: np.ndarray

    def __post_init__(self) -> None:
        times = _frozen(np.reshape(finite_array(self.times, "waypoint times"), -1))
        positions = _frozen(np.atleast_2d(finite_array(self.positions, "waypoint positions")))
        if positions.shape[0] != times.size:
            raise InputError(
                f"waypoints need one position row per time, got {times.size} times and "
                f"positions of shape {positions.shape}"
            )
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "positions", positions)


class Trajectory:
    """A joint-space motion made of polynomial segments, starting at time 0.

    Attributes:
        segments: The pieces, contiguous in time, the first starting at 0.
        duration: End time of the last segment [s].
        n: Number of joints.
        start: Position at time 0, shape (n,) [rad].
        end: Position at ``duration``, shape (n,) [rad] (exactly the requested target for the
            constructors of this module).
        waypoints: Points the motion was planned through (start, via points, end), for plots.
    """

    def __init__(
        self,
        segments: Sequence[Segment],
        *,
        waypoints: Waypoints | None = None,
        end: ArrayLike | None = None,
        end_velocity: ArrayLike | None = None,
        end_acceleration: ArrayLike | None = None,
    ) -> None:
        """Build a trajectory from segments.

        Args:
            segments: Contiguous segments, the first starting at t = 0, all with the same n.
            waypoints: Planned points for plots; default the start and end points.
            end: Exact final position, shape (n,) [rad]; default the last segment at its end.
                Given by the constructors so that ``sample(duration)`` returns the target exactly.
            end_velocity: Exact final velocity, shape (n,) [rad/s]; default evaluated.
            end_acceleration: Exact final acceleration, shape (n,) [rad/s²]; default evaluated.

        Raises:
            InputError: no segments, mixed joint counts, gaps in time or jumps in position.
        """
        self.segments: tuple[Segment, ...] = _segment_tuple(segments)
        _check_segments(self.segments)
        if waypoints is not None and not isinstance(waypoints, Waypoints):
            raise InputError(f"waypoints must be a Waypoints or None, got {describe(waypoints)}")
        self.n: int = self.segments[0].coefficients.shape[0]
        self.duration: float = self.segments[-1].t1
        self._build_evaluator()
        _check_junctions(self.segments, self._position_coefficients)
        self.start: np.ndarray = _frozen(self.segments[0].coefficients[:, 0])
        self.end: np.ndarray = _frozen(self._end_state(end, self._position_coefficients, "end"))
        self._end_velocity = self._end_state(
            end_velocity, self._velocity_coefficients, "end_velocity"
        )
        self._end_acceleration = self._end_state(
            end_acceleration, self._acceleration_coefficients, "end_acceleration"
        )
        self._waypoints = waypoints

    @property
    def waypoints(self) -> Waypoints:
        """Points the motion was planned through (start, via points, end), for plots; the
        start and end points unless the constructor gave others."""
        if self._waypoints is None:  # made on first use: most motions are never plotted
            self._waypoints = Waypoints(
                np.array([0.0, self.duration]), np.vstack([self.start, self.end])
            )
        return self._waypoints

    def __repr__(self) -> str:
        degrees = sorted({s.degree for s in self.segments})
        return (
            f"Trajectory(n={self.n}, duration={self.duration:.6g} s, "
            f"segments={len(self.segments)}, degrees={degrees})"
        )

    @property
    def knots(self) -> np.ndarray:
        """Segment boundaries, shape (len(segments) + 1,) [s]."""
        return np.array([s.t0 for s in self.segments] + [self.duration])

    def time_grid(self, dt: float) -> np.ndarray:
        """Sample times 0, dt, 2 dt, ..., the last exactly at :attr:`duration` [s]."""
        return time_grid(self.duration, dt)

    def sample(self, t: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity and acceleration at the times ``t``.

        Outside [0, duration] the motion holds its end states: the start (before 0) or end
        position, with zero velocity and acceleration. At a knot the later segment is used.

        Args:
            t: A time or a 1-D array of times [s].

        Returns:
            ``(q, qd, qdd)`` [rad, rad/s, rad/s²], each of shape (len(t), n) for an array ``t``
            and (n,) for a scalar.

        Raises:
            InputError: ``t`` is not a scalar or 1-D, or holds NaN or inf.
        """
        times = finite_array(t, "t")
        if times.ndim > 1:
            raise InputError(f"t must be a scalar or a 1-D array of times, got shape {times.shape}")
        q, qd, qdd = self._evaluate(np.atleast_1d(times))
        if times.ndim == 0:
            return q[0], qd[0], qdd[0]
        return q, qd, qdd

    def held(self, duration: float) -> Trajectory:
        """This motion, then standing still at its end until ``duration`` [s] (≥
        :attr:`duration`): a constant segment appended (its velocity and acceleration zero), so
        the motion itself — its timing, peaks and end — is unchanged. Programs hold every move
        so until a whole number of periods (:func:`whole_periods`).

        Raises:
            InputError: ``duration`` shorter than this motion's, or not a finite number.
        """
        duration = scalar_value(duration, "duration")
        if duration < self.duration:
            raise InputError(
                f"a held motion lasts at least its {self.duration:.9g} s, got {duration:.9g} s"
            )
        if duration == self.duration:
            return self
        hold = Segment(self.duration, duration, self.end[:, None].copy())
        return Trajectory(
            [*self.segments, hold], waypoints=self.waypoints, end=self.end,
            end_velocity=np.zeros(self.n), end_acceleration=np.zeros(self.n),
        )  # fmt: skip

    def then(self, other: Trajectory) -> Trajectory:
        """This motion followed by ``other`` (see :meth:`concatenate`)."""
        return Trajectory.concatenate([self, other])

    @staticmethod
    def concatenate(
        trajectories: Iterable[Trajectory], tolerance: float = CONTINUITY_TOLERANCE
    ) -> Trajectory:
        """One trajectory playing the given ones back to back.

        Each trajectory must start where the previous one ends (within ``tolerance`` [rad]);
        velocities are not checked, so a jump in velocity is the caller's choice.

        Raises:
            InputError: no trajectories, different joint counts or a jump in position.
        """
        try:
            parts = list(trajectories)
        except TypeError as error:
            raise InputError(
                f"concatenate needs a list of Trajectory objects, got {describe(trajectories)}"
            ) from error
        if not parts:
            raise InputError("concatenate needs at least one trajectory")
        for k, part in enumerate(parts):
            if not isinstance(part, Trajectory):
                raise InputError(
                    f"concatenate needs Trajectory objects; item {k} is {describe(part)}"
                )
        tolerance = scalar_value(tolerance, "tolerance")
        if tolerance < 0.0:
            raise InputError(f"tolerance must be >= 0 rad, got {tolerance}")
        for k, (before, after) in enumerate(zip(parts[:-1], parts[1:], strict=True)):
            _check_junction(k, before, after, tolerance)
        moving = [p for p in parts if p.duration > 0.0] or parts[-1:]
        segments: list[Segment] = []
        times: list[np.ndarray] = []
        positions: list[np.ndarray] = []
        offset = 0.0
        for part in moving:
            segments += [
                Segment(s.t0 + offset, s.t1 + offset, s.coefficients) for s in part.segments
            ]
            keep = slice(1, None) if times else slice(None)
            times.append(part.waypoints.times[keep] + offset)
            positions.append(part.waypoints.positions[keep])
            offset = segments[-1].t1
        last = parts[-1]
        return Trajectory(
            segments,
            waypoints=Waypoints(np.concatenate(times), np.vstack(positions)),
            end=last.end,
            end_velocity=last._end_velocity,
            end_acceleration=last._end_acceleration,
        )

    # -- evaluation ----------------------------------------------------------------------------

    def _build_evaluator(self) -> None:
        """Coefficients padded to a common degree, as (degree + 1, segments, n) arrays."""
        degree = max(s.degree for s in self.segments)
        padded = np.zeros((degree + 1, len(self.segments), self.n))
        for i, segment in enumerate(self.segments):
            padded[: segment.degree + 1, i, :] = segment.coefficients.T
        powers = np.arange(degree + 1)[:, None, None]
        velocity = (padded * powers)[1:]
        acceleration = (padded * powers * (powers - 1))[2:]
        self._position_coefficients = padded
        self._velocity_coefficients = velocity if degree >= 1 else np.zeros_like(padded)
        self._acceleration_coefficients = acceleration if degree >= 2 else np.zeros_like(padded)
        self._segment_starts = np.array([s.t0 for s in self.segments])

    def _end_state(
        self, given: ArrayLike | None, coefficients: np.ndarray, name: str
    ) -> np.ndarray:
        """The end state ``given`` (n,) (checked), or else the last segment's polynomial of
        ``coefficients`` at :attr:`duration`: :meth:`_polynomials` there (the same arithmetic)
        without its search."""
        if given is not None:
            (result,) = joint_vectors(n=self.n, **{name: given})
            return result
        last = np.array([len(self.segments) - 1])
        tau = np.array([[self.duration - self._segment_starts[-1]]])
        return _horner(coefficients, last, tau)[0]

    def _polynomials(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The segments' polynomials at times ``t`` clipped to [0, duration], (len(t), n) each.

        Vectorised over samples; the samples are processed in blocks of ``_BLOCK`` only so that
        the temporaries stay in the CPU cache (about 2-3 times faster for 1e6 samples).
        """
        clipped = np.clip(t, 0.0, self.duration)
        index = np.searchsorted(self._segment_starts[1:], clipped, side="right")
        tau = (clipped - self._segment_starts[index])[:, None]
        coefficients = (
            self._position_coefficients,
            self._velocity_coefficients,
            self._acceleration_coefficients,
        )
        shape = (t.size, self.n)
        results = (np.empty(shape), np.empty(shape), np.empty(shape))
        for start in range(0, t.size, _BLOCK):
            block = slice(start, start + _BLOCK)
            for values, c in zip(results, coefficients, strict=True):
                values[block] = _horner(c, index[block], tau[block])
        return results

    def _evaluate(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The polynomials, with the exact end state at ``duration`` and the holds outside."""
        q, qd, qdd = self._polynomials(t)
        at_end = t >= self.duration
        if at_end.any():
            q[at_end] = self.end
            qd[at_end] = self._end_velocity
            qdd[at_end] = self._end_acceleration
        outside = (t < 0.0) | (t > self.duration)
        if outside.any():
            qd[outside] = 0.0
            qdd[outside] = 0.0
        return q, qd, qdd


def _horner(coefficients: np.ndarray, index: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """Σ_k coefficients[k, index] τ^k for every sample at once, shape (len(index), n)."""
    out = np.take(coefficients[-1], index, axis=0)
    for level in coefficients[-2::-1]:
        out *= tau
        out += np.take(level, index, axis=0)
    return out


def time_grid(duration: float, dt: float) -> np.ndarray:
    """Sample times 0, dt, 2 dt, ..., with the last sample exactly at ``duration``.

    When ``dt`` does not divide ``duration`` the last step is shorter; a remainder below 1e-6 dt
    (rounding) is absorbed into the previous step instead of adding a tiny one.

    Args:
        duration: End time, ≥ 0 [s]; 0 gives the single sample [0].
        dt: Sampling step, > 0 [s].

    Returns:
        Increasing times, shape (k,) [s].

    Raises:
        InputError: a negative duration, a non-positive dt, NaN or inf, or more than
            :data:`MAX_SAMPLES` samples.
    """
    duration = scalar_value(duration, "duration")
    dt = scalar_value(dt, "dt")
    if duration < 0.0:
        raise InputError(f"duration must be >= 0 s, got {duration}")
    if dt <= 0.0:
        raise InputError(f"dt must be > 0 s, got {dt}; give the sampling step in seconds")
    steps = duration / dt
    if not steps < MAX_SAMPLES:  # also catches an overflow to inf
        raise InputError(
            f"dt = {dt:.6g} s would need {steps:.3g} samples over {duration:.6g} s (at most "
            f"{MAX_SAMPLES:,}); give a dt of at least "
            f"{_profiles.round_up(duration / MAX_SAMPLES, 3):.3g} s"
        )
    count = round(steps)
    if abs(steps - count) > _GRID_TOLERANCE:
        count = math.ceil(steps)
    if duration > 0.0:
        count = max(count, 1)
    t = np.arange(count + 1) * dt
    t[-1] = duration
    return t


def whole_periods(duration: float, dt: float) -> float:
    """The shortest whole number of periods ``dt`` [s] not shorter than ``duration`` [s] (a
    duration within 1e-9 periods above a whole number counts as that number: rounding): what a
    program holds each move's end until, so that all its samples lie on one grid k · dt."""
    return max(0, math.ceil(duration / dt - 1e-9)) * dt


def from_pieces(knots: np.ndarray, coefficients: list[np.ndarray], **kwargs) -> Trajectory:
    """A trajectory of the constructors' pieces (continuous by construction).

    Raises:
        InputError: the pieces do not join within rounding: the inputs mix magnitudes that
            double precision cannot resolve together.
    """
    segments = [
        Segment(float(t0), float(t1), c)
        for t0, t1, c in zip(knots[:-1], knots[1:], coefficients, strict=True)
    ]
    try:
        return Trajectory(segments, **kwargs)
    except InputError as error:
        raise InputError(
            f"the motion cannot be computed accurately in double precision ({error}); the "
            "inputs mix magnitudes too far apart: give durations within a factor of about 1e6 "
            "of each other and moves that are not tiny next to the positions"
        ) from error


def check_rates_continuous(coefficients: list[np.ndarray], durations: np.ndarray) -> None:
    """InputError unless velocity and acceleration are continuous at the inner knots and zero at
    both ends within 1e-9 of their largest value at the knots, as sampled (the monomial
    coefficients cancel more and more as the durations part: from a ratio of about 1e7 the rates
    evaluated at the knots no longer meet)."""
    for order in (1, 2):
        rates = []
        for c, h in zip(coefficients, durations, strict=True):
            powers = np.arange(c.shape[1])
            derivative = c * np.prod([powers - k for k in range(order)], axis=0)[None, :]
            tau = h ** np.maximum(powers - order, 0)
            rates.append((derivative[:, order], derivative @ tau))
        values = np.max([np.maximum(np.abs(r[0]), np.abs(r[1])) for r in rates], axis=0)
        gaps = [
            np.abs(rates[0][0]),
            np.abs(rates[0][1] - rates[1][0]),
            np.abs(rates[1][1] - rates[2][0]),
            np.abs(rates[2][1]),
        ]
        # An absolute floor far below any physical rate, for moves in the subnormal range.
        if np.any(np.max(gaps, axis=0) > CONTINUITY_TOLERANCE * values + 1e-300):
            raise InputError(
                f"durations {durations.tolist()} s are too far apart for an accurate 4-3-4 "
                f"profile (its {'velocity' if order == 1 else 'acceleration'} is continuous "
                "only to more than 1e-9 of its scale); give durations within a factor of about "
                "1e6 of each other"
            )


def _frozen(array: np.ndarray) -> np.ndarray:
    result = np.array(array, dtype=float)
    result.setflags(write=False)
    return result


def _segment_tuple(segments: Sequence[Segment]) -> tuple[Segment, ...]:
    """The segments as a tuple, checked (callers without types may pass anything)."""
    try:
        result = tuple(segments)
    except TypeError as error:
        raise InputError(f"segments must be a list of Segment, got {describe(segments)}") from error
    for k, segment in enumerate(result):
        if not isinstance(segment, Segment):
            raise InputError(f"segments must be Segment objects; item {k} is {describe(segment)}")
    return result


def _check_segments(segments: tuple[Segment, ...]) -> None:
    if not segments:
        raise InputError("a trajectory needs at least one segment")
    if segments[0].t0 != 0.0:
        raise InputError(f"the first segment must start at t = 0 s, got t0 = {segments[0].t0}")
    n = segments[0].coefficients.shape[0]
    for k, segment in enumerate(segments[1:], start=1):
        if segment.coefficients.shape[0] != n:
            raise InputError(
                f"segment {k} has {segment.coefficients.shape[0]} joints, segment 0 has {n}"
            )
    t0 = np.array([s.t0 for s in segments])
    t1 = np.array([s.t1 for s in segments])
    for j in np.flatnonzero(np.abs(t0[1:] - t1[:-1]) > 1e-12 * np.maximum(1.0, np.abs(t1[:-1]))):
        raise InputError(
            f"segment {j + 1} starts at {t0[j + 1]} s but segment {j} ends at {t1[j]} s; "
            "segments must be contiguous"
        )


def _check_junctions(segments: tuple[Segment, ...], padded: np.ndarray) -> None:
    """InputError where a segment does not start where the one before it ends.

    Args:
        segments: Contiguous segments (checked by :func:`_check_segments`).
        padded: Their position coefficients padded to a common degree, (degree + 1, S, n).
    """
    if len(segments) < 2:
        return
    t0 = np.array([s.t0 for s in segments])
    powers = (np.array([s.t1 for s in segments]) - t0)[:, None] ** np.arange(len(padded))
    ends = np.einsum("dsk,sd->sk", padded, powers)
    # Positions accumulate rounding in proportion to the largest terms anywhere in the motion
    # (its extent), not to the position at the junction.
    scale = 1.0 + np.max(np.einsum("dsk,sd->sk", np.abs(padded), powers), axis=0)
    gaps = np.abs(ends[:-1] - padded[0, 1:])
    for k, j in zip(*np.nonzero(gaps > CONTINUITY_TOLERANCE * scale), strict=True):
        raise InputError(
            f"joint {j} jumps by {gaps[k, j]:.3g} rad between segments {k} and {k + 1} "
            f"(at t = {t0[k + 1]:.6g} s); segments must join in position"
        )


def _check_junction(k: int, before: Trajectory, after: Trajectory, tolerance: float) -> None:
    if after.n != before.n:
        raise InputError(
            f"trajectory {k + 1} has {after.n} joints but trajectory {k} has {before.n}; "
            "only trajectories of the same robot can be concatenated"
        )
    gap = np.abs(after.start - before.end)
    for j in np.flatnonzero(gap > tolerance):
        raise InputError(
            f"trajectory {k + 1} does not start where trajectory {k} ends: joint {j} is at "
            f"{after.start[j]:.9g} rad instead of {before.end[j]:.9g} rad (gap {gap[j]:.3g} rad, "
            f"tolerance {tolerance:g}); start the next motion at the previous end"
        )
