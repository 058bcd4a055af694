"""Joint-space trajectories: polynomial segments and the classic profiles.

A :class:`Trajectory` is a list of polynomial :class:`Segment` objects evaluated by one vectorised
function, :meth:`Trajectory.sample`. Every profile is built as such a list:

- :func:`cubic` and :func:`quintic`: one polynomial fixed by its boundary conditions;
- :func:`cubic_via`: one cubic per segment through via points, velocity and acceleration
  continuous (or the velocity heuristic);
- :func:`trapezoid`: linear segment with parabolic blends (LSPB), from a duration and an
  acceleration or blend time, or minimum-time from velocity and acceleration limits with every
  joint synchronised to the slowest;
- :func:`trapezoid_via`: linear segments with parabolic blends through via points (Craig), or
  passing exactly through them with pseudo via points;
- :func:`four_three_four`: the 4-3-4 lift-off / set-down profile;
- :func:`scurve`: jerk-limited seven-phase point-to-point motion, minimum time, every joint
  synchronised to the slowest (the same duration as ruckig's);
- :func:`time_optimal`: the fastest motion along straight lines through waypoints with circular
  blends at the corners under per-joint velocity and acceleration limits (TOTG; the method is
  in :mod:`kinplan.time_optimal`).

Constructors take joint vectors (or scalars for one joint; scalars broadcast to every joint where
a vector is expected). Units are rad, rad/s, rad/s² and s; a 1-D profile of any other quantity
(for example a path length in m for Cartesian time scaling) works the same way. Joints are
numbered from 0 in messages, as in the arrays. Trajectory time starts at 0.

Every argument is checked at the door: anything that is not a finite real number (or an array of
them) of the right shape, durations outside [:data:`MIN_DURATION`, :data:`MAX_DURATION`] and
values beyond :data:`MAX_MAGNITUDE` raise :class:`~kinplan.errors.InputError` naming the argument
and what to pass; limits that cannot be met raise :class:`~kinplan.errors.InfeasibleError` with
the value that would work (rounded up, so that it does). No other exception escapes.

Example:
    >>> from kinplan import trajectory
    >>> traj = trajectory.cubic([0.0, 1.0], [1.0, 0.0], duration=2.0)
    >>> q, qd, qdd = traj.sample(traj.time_grid(0.01))
"""

from __future__ import annotations

import math
import reprlib
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from kinplan import _profiles
from kinplan.errors import InfeasibleError, InputError

__all__ = [
    "DEFAULT_BLEND_FRACTION",
    "MAX_DURATION",
    "MAX_MAGNITUDE",
    "MAX_SAMPLES",
    "MIN_DURATION",
    "MIN_MAGNITUDE",
    "Segment",
    "Trajectory",
    "Waypoints",
    "cubic",
    "cubic_via",
    "four_three_four",
    "quintic",
    "scurve",
    "spline",
    "time_grid",
    "time_optimal",
    "trapezoid",
    "trapezoid_via",
]

DEFAULT_BLEND_FRACTION = 1.0 / 3.0
"""Blend time of :func:`trapezoid` given only a duration, as a fraction of it [-].

T/3 splits the motion into equal accelerating, cruising and decelerating thirds (cruise speed
1.5 |Δ|/T, acceleration 4.5 |Δ|/T²), the default of Corke's ``lspb``/``trapezoidal``.
"""

CONTINUITY_TOLERANCE = 1e-9
"""Largest position gap accepted between consecutive segments or trajectories [rad]."""

_BLOCK = 4096
"""Samples evaluated per block by :meth:`Trajectory.sample` (cache-sized temporaries)."""

_GRID_TOLERANCE = 1e-6
"""A remainder below this fraction of ``dt`` does not add a sample to :func:`time_grid` [-]."""

MIN_DURATION = 1e-9
"""Shortest duration (and time between points) the constructors accept [s]."""

MAX_DURATION = 1e9
"""Longest duration (and time between points) the constructors accept [s] (about 32 years)."""

MAX_MAGNITUDE = 1e12
"""Largest |value| of a position, velocity, acceleration or limit the constructors accept [rad,
rad/s, rad/s² or m, m/s, m/s²].

With these bounds and :data:`MIN_DURATION` / :data:`MAX_DURATION`, every polynomial coefficient
(at most ~1e12 / (1e-9)⁵ = 1e57) and every intermediate stays far inside double range, so no
input can overflow; beyond them the inputs are almost surely a unit mistake.
"""

MIN_MAGNITUDE = 1.0 / MAX_MAGNITUDE
"""Smallest accepted positive limit or blend acceleration [rad/s, rad/s² or m/s, m/s²]."""

MAX_SAMPLES = 10_000_000
"""Most samples :func:`time_grid` returns (80 MB of times); a finer grid is a mistake in dt."""


# ----------------------------------------------------------------------------------------------
# Types
# ----------------------------------------------------------------------------------------------


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
        coefficients = _finite_array(self.coefficients, "segment coefficients")
        if coefficients.ndim != 2 or coefficients.size == 0:
            raise InputError(
                f"segment coefficients must have shape (n, degree + 1), got {coefficients.shape}"
            )
        t0, t1 = _scalar(self.t0, "segment t0"), _scalar(self.t1, "segment t1")
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
        times = _frozen(np.reshape(_finite_array(self.times, "waypoint times"), -1))
        positions = _frozen(np.atleast_2d(_finite_array(self.positions, "waypoint positions")))
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
            raise InputError(f"waypoints must be a Waypoints or None, got {_describe(waypoints)}")
        self.n: int = self.segments[0].coefficients.shape[0]
        self.duration: float = self.segments[-1].t1
        self._build_evaluator()
        evaluated = [x[0] for x in self._polynomials(np.array([self.duration]))]
        self.start: np.ndarray = _frozen(self.segments[0].coefficients[:, 0])
        self.end: np.ndarray = _frozen(_given_or(end, evaluated[0], self.n, "end"))
        self._end_velocity = _given_or(end_velocity, evaluated[1], self.n, "end_velocity")
        self._end_acceleration = _given_or(
            end_acceleration, evaluated[2], self.n, "end_acceleration"
        )
        if waypoints is None:
            waypoints = Waypoints(np.array([0.0, self.duration]), np.vstack([self.start, self.end]))
        self.waypoints: Waypoints = waypoints

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
        times = _finite_array(t, "t")
        if times.ndim > 1:
            raise InputError(f"t must be a scalar or a 1-D array of times, got shape {times.shape}")
        q, qd, qdd = self._evaluate(np.atleast_1d(times))
        if times.ndim == 0:
            return q[0], qd[0], qdd[0]
        return q, qd, qdd

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
                f"concatenate needs a list of Trajectory objects, got {_describe(trajectories)}"
            ) from error
        if not parts:
            raise InputError("concatenate needs at least one trajectory")
        for k, part in enumerate(parts):
            if not isinstance(part, Trajectory):
                raise InputError(
                    f"concatenate needs Trajectory objects; item {k} is {_describe(part)}"
                )
        tolerance = _scalar(tolerance, "tolerance")
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
    duration = _scalar(duration, "duration")
    dt = _scalar(dt, "dt")
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


# ----------------------------------------------------------------------------------------------
# Constructors
# ----------------------------------------------------------------------------------------------


def cubic(
    q0: ArrayLike, qf: ArrayLike, duration: float, v0: ArrayLike = 0.0, vf: ArrayLike = 0.0
) -> Trajectory:
    """One cubic per joint from (q0, v0) to (qf, vf) in ``duration``.

    Args:
        q0: Start position, shape (n,) or scalar [rad].
        qf: End position, shape (n,) or scalar [rad].
        duration: Motion time, > 0 [s].
        v0: Start velocity [rad/s].
        vf: End velocity [rad/s].

    Returns:
        A one-segment trajectory of degree 3.

    Raises:
        InputError: not numbers, mismatched lengths, NaN or inf, values beyond
            :data:`MAX_MAGNITUDE`, or a duration outside [:data:`MIN_DURATION`,
            :data:`MAX_DURATION`].
    """
    q0, qf, v0, vf = _joint_vectors(q0=q0, qf=qf, v0=v0, vf=vf)
    duration = _duration(duration, "duration")
    segment = Segment(0.0, duration, _profiles.hermite_cubic(q0, qf, v0, vf, duration))
    return Trajectory([segment], end=qf, end_velocity=vf)


def quintic(
    q0: ArrayLike,
    qf: ArrayLike,
    duration: float,
    v0: ArrayLike = 0.0,
    vf: ArrayLike = 0.0,
    a0: ArrayLike = 0.0,
    af: ArrayLike = 0.0,
) -> Trajectory:
    """One quintic per joint from (q0, v0, a0) to (qf, vf, af) in ``duration``.

    Args:
        q0: Start position, shape (n,) or scalar [rad].
        qf: End position, shape (n,) or scalar [rad].
        duration: Motion time, > 0 [s].
        v0: Start velocity [rad/s].
        vf: End velocity [rad/s].
        a0: Start acceleration [rad/s²].
        af: End acceleration [rad/s²].

    Returns:
        A one-segment trajectory of degree 5.

    Raises:
        InputError: not numbers, mismatched lengths, NaN or inf, values beyond
            :data:`MAX_MAGNITUDE`, or a duration outside [:data:`MIN_DURATION`,
            :data:`MAX_DURATION`].
    """
    q0, qf, v0, vf, a0, af = _joint_vectors(q0=q0, qf=qf, v0=v0, vf=vf, a0=a0, af=af)
    duration = _duration(duration, "duration")
    coefficients = _profiles.quintic_coefficients(q0, qf, v0, vf, a0, af, duration)
    return Trajectory(
        [Segment(0.0, duration, coefficients)], end=qf, end_velocity=vf, end_acceleration=af
    )


def cubic_via(
    points: ArrayLike,
    times: ArrayLike,
    v0: ArrayLike = 0.0,
    vf: ArrayLike = 0.0,
    via_velocities: ArrayLike | str | None = None,
) -> Trajectory:
    """One cubic per segment through every point.

    By default the velocities at the via points are chosen so that velocity and acceleration
    are continuous there (the clamped cubic spline: one tridiagonal solve for all joints).

    Args:
        points: Positions to pass, shape (m, n), or (m,) for one joint, m ≥ 2 [rad].
        times: Strictly increasing times of the points, shape (m,) [s]. They may start at any
            t0: the trajectory's time 0 is ``times[0]`` (segment durations are what count).
        v0: Velocity at the first point [rad/s].
        vf: Velocity at the last point [rad/s].
        via_velocities: ``None`` (continuous acceleration); ``"heuristic"`` (mean of the
            neighbouring chord slopes, 0 where the slope changes sign; velocity continuous,
            acceleration not); or the velocities at the m − 2 via points, shape (m − 2, n), or
            (m − 2,) for one joint, or (n,) for one via point; ``[]`` when m = 2 [rad/s].

    Returns:
        A trajectory of m − 1 cubic segments, waypoints at the given points.

    Raises:
        InputError: not numbers, bad shapes, NaN or inf, values beyond :data:`MAX_MAGNITUDE`,
            times that do not strictly increase, or steps between them outside
            [:data:`MIN_DURATION`, :data:`MAX_DURATION`].
    """
    points = _points(points, "points")
    m, n = points.shape
    times = _increasing_times(times, m)
    v0, vf = _joint_vectors(n=n, v0=v0, vf=vf)
    if via_velocities is None:
        velocities = _profiles.spline_velocities(points, times, v0, vf)
    elif isinstance(via_velocities, str):
        if via_velocities != "heuristic":
            raise InputError(
                f"via_velocities must be None, 'heuristic' or an array, got {via_velocities!r}"
            )
        velocities = _profiles.heuristic_velocities(points, times, v0, vf)
    else:
        velocities = np.vstack([v0, _via_velocities(via_velocities, m, n), vf])
    knots, coefficients = _profiles.hermite_pieces(points, times, velocities)
    return _from_pieces(
        knots,
        coefficients,
        waypoints=Waypoints(times - times[0], points),
        end=points[-1],
        end_velocity=vf,
    )


def trapezoid(
    q0: ArrayLike,
    qf: ArrayLike,
    duration: float | None = None,
    acceleration: ArrayLike | None = None,
    max_velocity: ArrayLike | None = None,
    max_acceleration: ArrayLike | None = None,
    blend_time: float | None = None,
) -> Trajectory:
    """Linear segment with parabolic blends (trapezoidal velocity), at rest at both ends.

    Give one of these combinations:

    - ``duration`` and ``acceleration`` (blend magnitude, scalar or per joint): the classic LSPB,
      blend time ``t_a = T/2 − sqrt(a²T² − 4a|Δ|)/(2a)`` per joint. Needs ``a ≥ 4|Δ|/T²``
      (equality is the triangular profile, no cruise).
    - ``duration`` and ``blend_time`` (0 < t_b ≤ T/2, common to every joint).
    - ``duration`` alone: blend time T/3 (:data:`DEFAULT_BLEND_FRACTION`).
    - ``max_velocity`` and ``max_acceleration`` (scalar or per joint): minimum time. Each joint's
      own minimum time is found (triangular when its cruise speed is not reached); every joint
      then takes the slowest one's duration, so all start and stop together, each within its
      own limits (a joint takes the slowest joint's blend time where its limits allow, so the
      joints switch together, otherwise the nearest admissible one). With ``duration`` as well,
      the motion lasts ``duration``, which must be at least the minimum time.

    Joints that do not move stay still; negative moves work. Moves smaller than 1e-150 rad
    (``_profiles.NEGLIGIBLE_MOVE``) are planned as still and the motion still ends exactly at qf.

    Args:
        q0: Start position, shape (n,) or scalar [rad].
        qf: End position, shape (n,) or scalar [rad].
        duration: Motion time, > 0 [s].
        acceleration: Blend acceleration magnitude [rad/s²].
        max_velocity: Velocity limit, > 0 [rad/s]. The motion never exceeds it, not even by
            rounding (it is planned a few units of rounding below it).
        max_acceleration: Acceleration limit, > 0 [rad/s²]; never exceeded either.
        blend_time: Blend (acceleration) time [s].

    Returns:
        A trajectory of quadratic segments (one knot wherever any joint switches phase).

    Raises:
        InputError: an unsupported combination of arguments, bad shapes or values (as for
            :func:`cubic`; limits and accelerations within [:data:`MIN_MAGNITUDE`,
            :data:`MAX_MAGNITUDE`]).
        InfeasibleError: an acceleration below 4|Δ|/T² (the message states the minimum), or a
            duration shorter than the limits allow (the message states the minimum time).
    """
    q0, qf = _joint_vectors(q0=q0, qf=qf)
    n = q0.size
    target = _profiles.without_negligible_moves(q0, qf)
    distance = np.abs(target - q0)
    if max_velocity is not None or max_acceleration is not None:
        if max_velocity is None or max_acceleration is None:
            raise InputError("give both max_velocity and max_acceleration for a minimum-time move")
        if acceleration is not None or blend_time is not None:
            raise InputError(
                "max_velocity/max_acceleration cannot be combined with acceleration or "
                "blend_time; give the limits, or a duration with an acceleration or blend time"
            )
        max_velocity = _magnitudes(max_velocity, "max_velocity", n)
        max_acceleration = _magnitudes(max_acceleration, "max_acceleration", n)
        requested = None if duration is None else _duration(duration, "duration")
        knots, coefficients = _synchronised(q0, target, max_velocity, max_acceleration, requested)
        return _from_pieces(knots, coefficients, end=qf, end_velocity=np.zeros(n))
    if duration is None:
        raise InputError(
            "trapezoid needs a duration (with an acceleration, a blend_time or neither), "
            "or max_velocity and max_acceleration for a minimum-time move"
        )
    duration = _duration(duration, "duration")
    if acceleration is not None and blend_time is not None:
        raise InputError("give acceleration or blend_time, not both")
    if acceleration is not None:
        acceleration = _magnitudes(acceleration, "acceleration", n)
        _profiles.check_lspb_acceleration(distance, duration, acceleration)
        blend = _profiles.lspb_blend_time(distance, duration, acceleration)
    else:
        fraction = DEFAULT_BLEND_FRACTION * duration
        blend = np.full(n, fraction if blend_time is None else _blend(blend_time, duration))
    knots, coefficients = _profiles.lspb_pieces(q0, target, duration, blend)
    return _from_pieces(knots, coefficients, end=qf, end_velocity=np.zeros(n))


def trapezoid_via(
    points: ArrayLike,
    durations: ArrayLike,
    acceleration: ArrayLike,
    pass_through: bool = False,
) -> Trajectory:
    """Linear segments with parabolic blends through via points, at rest at both ends (Craig).

    Between the points the motion is linear; at each via point a parabolic blend of magnitude
    ``acceleration`` joins the two lines, centred on the point's nominal time, so the motion
    passes near the via point but not through it and never stops there. The first and last
    blends start and end at rest inside their segment, so the motion lasts ``sum(durations)``.

    With ``pass_through=True`` two pseudo via points are put around each via point k, at
    ``± δ_k`` in time with ``δ_k = min(durations[k-1], durations[k]) / 4``, on the line through
    the via point whose slope is the velocity heuristic (mean of the neighbouring chord slopes, 0
    where the motion turns). The blends happen at the pseudo via points, so the motion is on that
    line at the via point's nominal time: it passes through it exactly.

    Args:
        points: Positions, shape (m, n), or (m,) for one joint, m ≥ 2 [rad].
        durations: Nominal time from point k to point k + 1, shape (m − 1,), each > 0 [s].
        acceleration: Blend acceleration magnitude, scalar or per joint, > 0 [rad/s²].
        pass_through: Insert pseudo via points so the motion passes every via point (a bool).

    Returns:
        A trajectory of quadratic segments; its waypoints are the points at their nominal times.

    Raises:
        InputError: bad shapes or types, NaN or inf, durations out of range or so far apart
            that one is lost in the rounding of their sum, accelerations out of range.
        InfeasibleError: a blend does not fit (the message names the via point and the joint,
            the time needed and available, and what to change).
    """
    points = _points(points, "points")
    m, n = points.shape
    durations = _positive_array(durations, "durations", m - 1)
    acceleration = _magnitudes(acceleration, "acceleration", n)
    if not isinstance(pass_through, (bool, np.bool_)):
        raise InputError(f"pass_through must be True or False, got {_describe(pass_through)}")
    times = _knot_times(durations)
    waypoints = Waypoints(times, points)
    if m == 2:  # no via point: the classic LSPB
        target = _profiles.without_negligible_moves(points[0], points[1])
        distance = np.abs(target - points[0])
        _profiles.check_lspb_acceleration(distance, times[-1], acceleration)
        blend = _profiles.lspb_blend_time(distance, times[-1], acceleration)
        knots, coefficients = _profiles.lspb_pieces(points[0], target, times[-1], blend)
    else:
        if pass_through:
            corners, corner_times, names, span_names, half = _pseudo_via_points(points, times)
        else:
            corners, corner_times = points, times
            names = [f"point {k}" for k in range(m)]
            span_names = [f"durations[{k}]" for k in range(m - 1)]
        breaks, accelerations, widths = _profiles.blend_phases(
            corners, corner_times, acceleration, names, span_names
        )
        if pass_through:
            _check_through_via_points(widths, half)
        knots, coefficients = _profiles.constant_acceleration_pieces(
            corners[0], breaks, accelerations
        )
    return _from_pieces(
        knots, coefficients, waypoints=waypoints, end=points[-1], end_velocity=np.zeros(n)
    )


def four_three_four(
    q0: ArrayLike,
    q_lift: ArrayLike,
    q_set: ArrayLike,
    qf: ArrayLike,
    durations: ArrayLike,
) -> Trajectory:
    """The 4-3-4 profile: lift-off (degree 4), travel (degree 3), set-down (degree 4).

    Passes the four points at the knots, velocity and acceleration continuous there, at rest
    (zero velocity and acceleration) at both ends. One 14 × 14 solve serves every joint.

    Args:
        q0: Start position [rad].
        q_lift: Lift-off position, reached after ``durations[0]`` [rad].
        q_set: Set-down position, reached ``durations[1]`` later [rad].
        qf: End position, reached ``durations[2]`` later [rad].
        durations: The three segment durations, each > 0 [s].

    Returns:
        A trajectory of three segments of degrees 4, 3 and 4.

    Raises:
        InputError: mismatched lengths, NaN or inf, durations out of range, or durations so far
            apart (a factor of about 1e7) that the solve cannot meet the conditions to 1e-9.
    """
    q0, q_lift, q_set, qf = _joint_vectors(q0=q0, q_lift=q_lift, q_set=q_set, qf=qf)
    durations = _positive_array(durations, "durations", 3)
    knots = _knot_times(durations)
    try:
        coefficients = _profiles.four_three_four_coefficients([q0, q_lift, q_set, qf], durations)
    except np.linalg.LinAlgError as error:
        raise InputError(
            f"durations {durations.tolist()} s are too far apart for the 4-3-4 solve; give "
            "durations within a factor of about 1e6 of each other"
        ) from error
    _check_rates_continuous(coefficients, durations)
    zero = np.zeros(q0.size)
    return _from_pieces(
        knots,
        coefficients,
        waypoints=Waypoints(knots, np.vstack([q0, q_lift, q_set, qf])),
        end=qf,
        end_velocity=zero,
        end_acceleration=zero,
    )


def scurve(
    q0: ArrayLike,
    qf: ArrayLike,
    max_velocity: ArrayLike,
    max_acceleration: ArrayLike,
    max_jerk: ArrayLike,
    duration: float | None = None,
) -> Trajectory:
    """Jerk-limited (seven-phase S-curve) point-to-point motion, at rest at both ends.

    Each joint's own minimum-time profile is found in closed form (jerk up, constant
    acceleration, jerk down, cruise, and the mirror image; phases drop out when the joint does
    not reach its velocity or acceleration limit), the same duration as ruckig's for one degree
    of freedom. Every joint then takes the slowest joint's duration, so all start and stop
    together within their own limits: a joint takes the slowest joint's phase times (the joints
    switch together and move on the straight line in joint space) where its limits allow, and
    otherwise its own profile stretched in time, which divides its speed, acceleration and jerk
    by s, s² and s³ for a stretch s ≥ 1. The limits are never exceeded, not even by rounding
    (the motion is planned a few units of rounding below them, 16 ulp relative, and checked as
    sampled).

    Args:
        q0: Start position, shape (n,) or scalar [rad].
        qf: End position, shape (n,) or scalar [rad].
        max_velocity: Velocity limit, scalar or per joint, > 0 [rad/s].
        max_acceleration: Acceleration limit, scalar or per joint, > 0 [rad/s²].
        max_jerk: Jerk limit, scalar or per joint, > 0 [rad/s³].
        duration: Motion time [s]; default the minimum time. A longer duration stretches the
            slowest joint's profile in time.

    Returns:
        A trajectory of cubic segments (one knot wherever any joint switches phase), acceleration
        continuous, jerk piecewise constant; zero duration when nothing moves.

    Raises:
        InputError: bad shapes or values, non-positive or NaN limits (as for :func:`trapezoid`).
        InfeasibleError: ``duration`` shorter than the limits allow (the message states the
            minimum time).
    """
    q0, qf = _joint_vectors(q0=q0, qf=qf)
    n = q0.size
    max_velocity = _magnitudes(max_velocity, "max_velocity", n)
    max_acceleration = _magnitudes(max_acceleration, "max_acceleration", n)
    max_jerk = _magnitudes(max_jerk, "max_jerk", n)
    requested = None if duration is None else _duration(duration, "duration")
    target = _profiles.without_negligible_moves(q0, qf)
    distance = np.abs(target - q0)
    limits = (max_velocity, max_acceleration, max_jerk)
    own = _profiles.scurve_minimum_times(distance, *limits)
    slowest = int(np.argmax(own))
    if requested is not None:
        _check_requested_duration(requested, own[slowest], slowest, distance, limits)
    reduced = [limit * (1.0 - _profiles.LIMIT_MARGIN) for limit in limits]
    minimum = float(np.max(_profiles.scurve_minimum_times(distance, *reduced)))
    duration = minimum if requested is None else max(requested, minimum)
    knots, coefficients = _profiles.synchronised_scurve(q0, target, duration, *limits)
    zero = np.zeros(n)
    return _from_pieces(knots, coefficients, end=qf, end_velocity=zero, end_acceleration=zero)


def time_optimal(
    points: ArrayLike,
    max_velocity: ArrayLike,
    max_acceleration: ArrayLike,
    max_deviation: float = 0.0,
    duration: float | None = None,
) -> Trajectory:
    """Time-optimal motion along a joint-space path through waypoints (TOTG), rest to rest.

    The path (Kunz & Stilman 2012) is made of straight lines between the points, each corner
    replaced by a circular blend that passes within ``max_deviation`` of it (Euclidean norm over
    the joints); with ``max_deviation=0`` the path goes exactly through every point and the
    motion stops at each corner (a corner that reverses the direction stops too; points on a
    straight line are passed without stopping). The timing is the fastest one that keeps every
    joint within its velocity and acceleration limits; see :mod:`kinplan.time_optimal` for the
    method, the representation and its accuracy (lines exact; blends as quintics that keep the
    path to 1e-12 rad, planned 1e-4 below the limits and checked on dense samples).

    Args:
        points: Joint-space points, shape (m, n), or (m,) for one joint, m ≥ 2 [rad].
            Consecutive duplicates (closer than 1e-12 rad) are dropped; when every point is the
            same, the result is a motion of zero duration (or of ``duration``, standing still).
        max_velocity: Velocity limit, scalar or per joint, > 0 [rad/s].
        max_acceleration: Acceleration limit, scalar or per joint, > 0 [rad/s²].
        max_deviation: Largest distance of the path from a corner, ≥ 0 [rad].
        duration: Motion time [s]; default the minimum. A longer duration plays the optimal
            timing uniformly slower.

    Returns:
        A trajectory of quadratic (lines) and quintic (blends) segments; its waypoints are the
        points at the times the motion is nearest them.

    Raises:
        InputError: bad shapes or values, non-positive or NaN limits, a negative or NaN
            ``max_deviation``.
        InfeasibleError: ``duration`` shorter than the limits allow (the message states the
            minimum time).
    """
    from kinplan import time_optimal as totg  # builds on this module's profiles

    points = _points(points, "points")
    n = points.shape[1]
    max_velocity = _magnitudes(max_velocity, "max_velocity", n)
    max_acceleration = _magnitudes(max_acceleration, "max_acceleration", n)
    deviation = _scalar(max_deviation, "max_deviation")
    if deviation < 0.0:
        raise InputError(f"max_deviation must be >= 0 rad, got {deviation}")
    _check_magnitudes(np.asarray(deviation), "max_deviation")
    requested = None if duration is None else _duration(duration, "duration")
    plan = totg.plan(points, max_velocity, max_acceleration, deviation, requested)
    return _from_pieces(
        plan.knots,
        plan.coefficients,
        waypoints=Waypoints(plan.waypoint_times(), plan.path.points),
        end=points[-1],
        end_velocity=np.zeros(n),
    )  # the end acceleration is the braking one, as for the minimum-time trapezoid


def spline(
    points: ArrayLike,
    max_velocity: ArrayLike,
    max_acceleration: ArrayLike,
    duration: float | None = None,
) -> Trajectory:
    """A smooth motion through joint-space points: the clamped cubic spline, timed by the limits.

    The knot times are proportional to the chord lengths (Euclidean distance over the joints
    between consecutive points), so the shape in joint space does not depend on the timing; the
    spline is at rest at both ends, with velocity and acceleration continuous at every point
    (:func:`cubic_via`). The time scale is then the smallest that keeps every joint within its
    velocity and acceleration limits (peaks computed exactly per cubic, not sampled), or the
    given ``duration``. Scaling time by k divides the velocities by k and the accelerations by
    k², so the geometry stays the same.

    Args:
        points: Joint-space points, shape (m, n), or (m,) for one joint, m ≥ 2 [rad].
            Consecutive duplicates (closer than 1e-12 rad) are dropped; when every point is the
            same, the motion has zero duration (or stands still for ``duration``).
        max_velocity: Velocity limit, scalar or per joint, > 0 [rad/s].
        max_acceleration: Acceleration limit, scalar or per joint, > 0 [rad/s²].
        duration: Motion time [s]; default the minimum within the limits.

    Returns:
        A trajectory of cubic segments, one per pair of consecutive (distinct) points, with the
        points as waypoints.

    Raises:
        InputError: bad shapes or values, non-positive or NaN limits.
        InfeasibleError: ``duration`` shorter than the limits allow (the message states the
            minimum time and the joint that sets it).
    """
    points = _points(points, "points")
    n = points.shape[1]
    max_velocity = _magnitudes(max_velocity, "max_velocity", n)
    max_acceleration = _magnitudes(max_acceleration, "max_acceleration", n)
    requested = None if duration is None else _duration(duration, "duration")
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    points = points[np.concatenate(([True], steps > 1e-12))]
    zero = np.zeros(n)
    if len(points) < 2:
        if requested is None:
            return trapezoid(points[0], points[0], max_velocity=1.0, max_acceleration=1.0)
        return cubic(points[0], points[0], requested)
    chords = np.linalg.norm(np.diff(points, axis=0), axis=1)
    unit_times = np.concatenate(([0.0], np.cumsum(chords / chords.sum())))
    velocities = _profiles.spline_velocities(points, unit_times, zero, zero)
    speed, acceleration = _profiles.hermite_peaks(points, unit_times, velocities)
    # time scale k: peak speed / k and peak acceleration / k² within the limits
    by_speed = speed / max_velocity
    by_acceleration = np.sqrt(acceleration / max_acceleration)
    minimum = float(max(by_speed.max(), by_acceleration.max()))
    if requested is not None and requested < minimum * (1.0 - 1e-12):
        j = int(np.argmax(np.maximum(by_speed, by_acceleration)))
        what = "velocity" if by_speed[j] >= by_acceleration[j] else "acceleration"
        raise InfeasibleError(
            f"duration {requested:g} s is too short for this spline: joint {j} would exceed its "
            f"{what} limit; the minimum is {minimum:.6g} s"
        )
    scale = minimum * (1.0 + 1e-12) if requested is None else requested
    times = unit_times * scale
    return cubic_via(points, times)


# ----------------------------------------------------------------------------------------------
# Helpers of the constructors
# ----------------------------------------------------------------------------------------------


def _from_pieces(knots: np.ndarray, coefficients: list[np.ndarray], **kwargs) -> Trajectory:
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


def _check_rates_continuous(coefficients: list[np.ndarray], durations: np.ndarray) -> None:
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


def _synchronised(
    q0: np.ndarray,
    qf: np.ndarray,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    requested: float | None,
) -> tuple[np.ndarray, list[np.ndarray]]:
    """Knots [s] and coefficients of the synchronised minimum-time LSPB (or lasting ``requested``).

    A requested duration within rounding (relative 1e-12) of the minimum time is taken as the
    minimum time.
    """
    distance = np.abs(qf - q0)
    own = _profiles.lspb_minimum_times(distance, max_velocity, max_acceleration)
    slowest = int(np.argmax(own))
    if requested is not None and requested < own[slowest] * (1.0 - _profiles.RELATIVE_TOLERANCE):
        least = _profiles.round_up(float(own[slowest]))
        raise InfeasibleError(
            f"duration {requested:.6g} s is too short: joint {slowest} needs at least "
            f"{least:.6g} s to move {distance[slowest]:.6g} rad within max_velocity "
            f"{max_velocity[slowest]:.6g} rad/s and max_acceleration "
            f"{max_acceleration[slowest]:.6g} rad/s²; give a duration of at least "
            f"{least:.6g} s or raise the limits"
        )
    duration = _profiles.synchronised_minimum_time(distance, max_velocity, max_acceleration)
    if requested is not None:
        duration = max(requested, duration)
    return _profiles.synchronised_lspb(q0, qf, duration, max_velocity, max_acceleration)


def _check_requested_duration(
    requested: float,
    least: float,
    joint: int,
    distance: np.ndarray,
    limits: Sequence[np.ndarray],
) -> None:
    """InfeasibleError stating the minimum time when ``requested`` is below ``least`` (relative
    slack :data:`~kinplan._profiles.RELATIVE_TOLERANCE` for rounding)."""
    if requested >= least * (1.0 - _profiles.RELATIVE_TOLERANCE):
        return
    names = ("max_velocity", "max_acceleration", "max_jerk")
    units = ("rad/s", "rad/s²", "rad/s³")
    parts = [
        f"{name} {limit[joint]:.6g} {unit}"
        for name, limit, unit in zip(names, limits, units, strict=False)
    ]
    within = ", ".join(parts[:-1]) + f" and {parts[-1]}"
    rounded = _profiles.round_up(float(least))
    raise InfeasibleError(
        f"duration {requested:.6g} s is too short: joint {joint} needs at least {rounded:.6g} s "
        f"to move {distance[joint]:.6g} rad within {within}; give a duration of at least "
        f"{rounded:.6g} s or raise the limits"
    )


def _pseudo_via_points(
    points: np.ndarray, times: np.ndarray
) -> tuple[np.ndarray, np.ndarray, list[str], list[str], np.ndarray]:
    """Corners for ``pass_through``: each via point replaced by two pseudo via points.

    Returns:
        Corner positions (2m − 2, n) [rad], corner times (2m − 2,) [s], corner names and span
        names for messages, and the half-widths δ (m − 2,) [s] of the lines through the via points.
    """
    m, n = points.shape
    slopes = _profiles.heuristic_velocities(points, times, np.zeros(n), np.zeros(n))[1:-1]
    spans = np.diff(times)
    half = 0.25 * np.minimum(spans[:-1], spans[1:])
    via_times = times[1:-1]
    pseudo = np.empty((2 * (m - 2), n))
    pseudo[0::2] = points[1:-1] - slopes * half[:, None]
    pseudo[1::2] = points[1:-1] + slopes * half[:, None]
    pseudo_times = np.empty(2 * (m - 2))
    pseudo_times[0::2] = via_times - half
    pseudo_times[1::2] = via_times + half
    corners = np.vstack([points[0], pseudo, points[-1]])
    corner_times = np.concatenate([[0.0], pseudo_times, [times[-1]]])
    names = ["point 0"]
    span_names = ["durations[0]"]
    for k in range(1, m - 1):
        names += [f"the pseudo via point before point {k}", f"the pseudo via point after point {k}"]
        span_names += [f"durations[{k - 1}] and durations[{k}]", f"durations[{k}]"]
    names.append(f"point {m - 1}")
    return corners, corner_times, names, span_names, half


def _check_through_via_points(widths: np.ndarray, half: np.ndarray) -> None:
    """Raise InfeasibleError when a pseudo via point's blend reaches over its via point."""
    for k, delta in enumerate(half, start=1):
        for side, row in (("before", 2 * k - 1), ("after", 2 * k)):
            needed = 0.5 * widths[row]
            for j in np.flatnonzero(needed > delta * (1.0 + _profiles.RELATIVE_TOLERANCE)):
                raise InfeasibleError(
                    f"joint {j}: the blend at the pseudo via point {side} point {k} needs "
                    f"{needed[j]:.6g} s on that side of point {k} but only {delta:.6g} s is "
                    f"available, so the motion would miss point {k}; raise the acceleration or "
                    f"lengthen durations[{k - 1}] and durations[{k}]"
                )


# ----------------------------------------------------------------------------------------------
# Input checks
# ----------------------------------------------------------------------------------------------


def _describe(value: object) -> str:
    """A short description of an argument for messages (long arrays abbreviated)."""
    return reprlib.repr(value)


def _finite_array(value: object, name: str) -> np.ndarray:
    """``value`` as a new float array: real numbers only (no text, None, booleans or ragged
    nesting), all finite."""
    if type(value) is float or (isinstance(value, np.ndarray) and value.dtype.kind in "iuf"):
        array = np.array(value, dtype=float)  # the common cases, without the checks below
        if not np.isfinite(array).all():
            raise InputError(
                f"{name} must be finite, got {_describe(value)} (NaN or inf); give finite values"
            )
        return array
    if isinstance(value, (str, bytes)):
        raise InputError(f"{name} must be a number or an array of numbers, got the text {value!r}")
    try:
        raw = np.asarray(value)
    except Exception as error:  # ragged nesting, or objects numpy cannot read as an array
        raise InputError(
            f"{name} must be a number or a regular array of numbers (equal-length rows), "
            f"got {_describe(value)}"
        ) from error
    if raw.dtype.kind == "O":
        for item in raw.flat:
            if item is None or isinstance(item, (str, bytes, bool, np.bool_)):
                where = "" if raw.ndim == 0 else f" in {_describe(value)}"
                raise InputError(f"{name} must hold numbers only, got {item!r}{where}")
    elif raw.dtype.kind not in "iuf":
        what = "booleans" if raw.dtype.kind == "b" else f"values of type {raw.dtype}"
        raise InputError(f"{name} must be real numbers, got {what}: {_describe(value)}")
    try:
        array = raw.astype(float)
    except Exception as error:  # objects that are not numbers, integers beyond float range
        raise InputError(
            f"{name} must be real numbers within floating-point range, got {_describe(value)}"
        ) from error
    if not np.isfinite(array).all():
        raise InputError(
            f"{name} must be finite, got {_describe(value)} (NaN or inf); give finite values"
        )
    return array


def _scalar(value: object, name: str) -> float:
    if type(value) is float and math.isfinite(value):
        return value
    array = _finite_array(value, name)
    if array.ndim != 0:
        raise InputError(f"{name} must be a scalar, got shape {array.shape}")
    return float(array)


def _check_durations(values: np.ndarray, name: str) -> None:
    """InputError unless every value is within [MIN_DURATION, MAX_DURATION] s."""
    flat = np.atleast_1d(values)
    label = (lambda k: name) if np.ndim(values) == 0 else (lambda k: f"{name}[{k}]")
    for k in np.flatnonzero(flat <= 0.0):
        raise InputError(f"{label(k)} must be > 0 s, got {flat[k]}")
    for k in np.flatnonzero((flat < MIN_DURATION) | (flat > MAX_DURATION)):
        raise InputError(
            f"{label(k)} = {flat[k]:.6g} s is outside the supported range "
            f"[{MIN_DURATION:g}, {MAX_DURATION:g}] s; give a duration in seconds within it"
        )


def _duration(value: object, name: str) -> float:
    result = _scalar(value, name)
    _check_durations(np.asarray(result), name)
    return result


def _blend(value: object, duration: float) -> float:
    result = _scalar(value, "blend_time")
    if not 0.0 < result <= 0.5 * duration:
        raise InputError(
            f"blend_time must be in (0, duration/2] = (0, {0.5 * duration:.6g}] s, got {result}"
        )
    _check_durations(np.asarray(result), "blend_time")
    return result


def _check_magnitudes(array: np.ndarray, name: str) -> None:
    """InputError when a value exceeds MAX_MAGNITUDE in absolute value."""
    flat = array.reshape(-1)
    if not (np.abs(flat) > MAX_MAGNITUDE).any():
        return
    for k in np.flatnonzero(np.abs(flat) > MAX_MAGNITUDE):
        where = name if array.ndim == 0 else f"{name} (element {k})"
        raise InputError(
            f"{where} = {flat[k]:.6g} is beyond the supported magnitude {MAX_MAGNITUDE:g}; "
            "give positions, velocities and accelerations in rad, rad/s and rad/s² (or m, m/s, "
            "m/s²) of at most that size"
        )


def _vector(value: object, name: str) -> np.ndarray:
    array = _finite_array(value, name)
    if array.ndim > 1:
        raise InputError(f"{name} must be a joint vector or a scalar, got shape {array.shape}")
    if array.size == 0:
        raise InputError(f"{name} is empty; give one value per joint")
    _check_magnitudes(array, name)
    return array.reshape(-1)


def _joint_vectors(n: int | None = None, **values: object) -> list[np.ndarray]:
    """Joint vectors of a common length; scalars (and 1-vectors) broadcast to every joint."""
    arrays = {name: _vector(value, name) for name, value in values.items()}
    lengths = {a.size for a in arrays.values() if a.size != 1}
    if n is not None:
        lengths.add(n)
    if len(lengths) > 1:
        given = ", ".join(f"{name} has {a.size}" for name, a in arrays.items() if a.size != 1)
        expected = "" if n is None else f" (the points have {n} joints)"
        raise InputError(
            f"joint vectors disagree in length: {given}{expected}; give one value per joint "
            "(a scalar applies to every joint)"
        )
    size = lengths.pop() if lengths else (n or 1)
    # Every array is a new one (_finite_array copies), so it can be returned as it is.
    return [a if a.size == size else np.full(size, a[0]) for a in arrays.values()]


def _magnitudes(value: object, name: str, n: int) -> np.ndarray:
    (result,) = _joint_vectors(n=n, **{name: value})
    for j in np.flatnonzero(result <= 0.0):
        raise InputError(f"{name} must be > 0 for every joint, got {result[j]} for joint {j}")
    for j in np.flatnonzero(result < MIN_MAGNITUDE):
        raise InputError(
            f"{name} = {result[j]:.6g} for joint {j} is below the supported minimum "
            f"{MIN_MAGNITUDE:g}; give it in rad/s or rad/s² (m/s or m/s²)"
        )
    return result


def _positive_array(value: object, name: str, count: int) -> np.ndarray:
    array = _finite_array(value, name)
    if array.shape != (count,):
        raise InputError(
            f"{name} must be a list of {count} durations [s], shape ({count},), got shape "
            f"{array.shape}"
        )
    _check_durations(array, name)
    return array


def _points(value: object, name: str) -> np.ndarray:
    array = _finite_array(value, name)
    given = array.shape
    if array.ndim == 1:
        array = array[:, None]
    if array.ndim != 2 or array.shape[0] < 2 or array.shape[1] == 0:
        raise InputError(
            f"{name} must have shape (m, n) or (m,) with at least 2 points, got {given}"
        )
    _check_magnitudes(array, name)
    return array


def _increasing_times(value: object, count: int) -> np.ndarray:
    times = _finite_array(value, "times")
    if times.shape != (count,):
        raise InputError(f"times must have shape ({count},), one per point, got {times.shape}")
    for k in np.flatnonzero(np.diff(times) <= 0.0):
        raise InputError(
            f"times must strictly increase: times[{k + 1}] = {times[k + 1]} s is not after "
            f"times[{k}] = {times[k]} s"
        )
    for k in np.flatnonzero((np.diff(times) < MIN_DURATION) | (np.diff(times) > MAX_DURATION)):
        raise InputError(
            f"times[{k + 1}] − times[{k}] = {times[k + 1] - times[k]:.6g} s is outside the "
            f"supported range [{MIN_DURATION:g}, {MAX_DURATION:g}] s; give times in seconds"
        )
    return times


def _knot_times(durations: np.ndarray) -> np.ndarray:
    """Times from 0 after each duration [s]; InputError when a duration is lost in the rounding
    of the running total (durations too many orders of magnitude apart)."""
    times = np.concatenate([[0.0], np.cumsum(durations)])
    resolved = np.diff(times)
    for k in np.flatnonzero(np.abs(resolved - durations) > 1e-6 * durations):
        raise InputError(
            f"durations[{k}] = {durations[k]:.6g} s is lost in the rounding of the {times[k]:.6g} "
            "s before it; give durations within a factor of about 1e9 of each other"
        )
    return times


def _via_velocities(value: object, m: int, n: int) -> np.ndarray:
    """Explicit via-point velocities as shape (m − 2, n) [rad/s].

    Accepted: shape (m − 2, n); (m − 2,) for one joint; (n,) or a scalar (one joint) for one via
    point; an empty list when there is no via point.
    """
    given = _finite_array(value, "via_velocities")
    shapes: set[tuple[int, ...]] = {(m - 2, n)}
    if n == 1:
        shapes |= {(m - 2,)}
    if m == 3:
        shapes |= {(n,)} | ({()} if n == 1 else set())
    if m == 2:
        shapes |= {(0,)}
    if given.shape not in shapes:
        raise InputError(
            f"via_velocities must have shape ({m - 2}, {n}) (one row per via point, one column "
            f"per joint), got shape {given.shape}; or pass None or 'heuristic'"
        )
    given = given.reshape(m - 2, n)
    _check_magnitudes(given, "via_velocities")
    return given


def _given_or(value: ArrayLike | None, default: np.ndarray, n: int, name: str) -> np.ndarray:
    if value is None:
        return default.copy()
    (result,) = _joint_vectors(n=n, **{name: value})
    return result


def _frozen(array: np.ndarray) -> np.ndarray:
    result = np.array(array, dtype=float)
    result.setflags(write=False)
    return result


def _segment_tuple(segments: Sequence[Segment]) -> tuple[Segment, ...]:
    """The segments as a tuple, checked (callers without types may pass anything)."""
    try:
        result = tuple(segments)
    except TypeError as error:
        raise InputError(
            f"segments must be a list of Segment, got {_describe(segments)}"
        ) from error
    for k, segment in enumerate(result):
        if not isinstance(segment, Segment):
            raise InputError(f"segments must be Segment objects; item {k} is {_describe(segment)}")
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
    degree = max(s.degree for s in segments)
    padded = np.zeros((len(segments), n, degree + 1))
    for k, segment in enumerate(segments):
        padded[k, :, : segment.degree + 1] = segment.coefficients
    powers = (t1 - t0)[:, None] ** np.arange(degree + 1)  # (S, degree + 1)
    ends = np.einsum("skd,sd->sk", padded, powers)
    # Positions accumulate rounding in proportion to the largest terms anywhere in the motion
    # (its extent), not to the position at the junction.
    scale = 1.0 + np.max(np.einsum("skd,sd->sk", np.abs(padded), powers), axis=0)
    gaps = np.abs(ends[:-1] - padded[1:, :, 0])
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
