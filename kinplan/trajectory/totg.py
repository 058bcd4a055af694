"""Time-optimal timing of joint-space paths through waypoints (what MoveIt's TOTG does).

The geometry follows Kunz & Stilman, "Time-optimal trajectory generation for path following
with bounded acceleration and velocity" (RSS 2012): straight lines between the joint-space
points, each corner replaced by a circular blend (:class:`JointPath`). The blend at a corner
with turning angle α, between segments of lengths L₁ and L₂, starts and ends
``ℓ = min(L₁/2, L₂/2, δ sin(α/2) / (1 − cos(α/2)))`` from the corner, so it passes within
δ = ``max_deviation`` of the corner (the Euclidean norm over joints, in rad); its radius is
``ℓ / tan(α/2)``. With δ = 0 (and at a full reversal, where a blend would have no radius) the
path keeps its corners, and the motion stops there. The path is parametrised by its arc length s.

The timing is the time-optimal one in the phase plane (s, x = ṡ²), under per-joint limits on
velocity ``|q'_j ṡ| ≤ v_j`` and acceleration ``|q'_j s̈ + q''_j ṡ²| ≤ a_j``, at rest at both ends:

- On a straight line q'' = 0 and q' is constant, so the limits are constant: |s̈| ≤ ā and
  ṡ ≤ v̄. The optimum there is exact and closed-form: accelerate at ā, cruise at v̄ (when
  reached), brake at ā (each phase a parabola in t).
- On a circular blend the limits vary with s. The blend is cut into intervals of at most
  :data:`ARC_STEP` rad of arc; on each interval the path acceleration s̈ = u is constant (so
  x is linear in s and s(t) a parabola), and the limits are imposed at both ends of the
  interval with that u. Each limit is linear in (u, x), so the feasible path accelerations at a
  given x form an interval, and the largest controllable x at each node follows from the next
  one in closed form (Fourier-Motzkin elimination of u: the reachability analysis of TOPP-RA,
  with no linear program to solve). A backward pass from rest at the end gives the largest
  controllable speeds, a forward pass from rest at the start the fastest feasible ones.
  Between the ends of an interval the limits are kept by planning the blends
  :data:`ARC_MARGIN` below them (the constraints vary by O(Δθ²) across an interval), and the
  result is checked on dense samples (:data:`CHECK_SAMPLES` per segment): the intervals where
  a sample still exceeds a limit (where a joint's velocity limit curves sharply along the
  blend) are cut into finer ones and the law is planned again.

Representation: the motion is a :class:`~kinplan.trajectory.Trajectory` evaluated by the one
vectorised evaluator. On lines its segments are the exact quadratics of the optimal law; on
blends one quintic per interval, Hermite-interpolating the exact position, velocity and
acceleration of q(s(t)) at both ends (position error below 1e-12 rad for the interval lengths
used, far inside the 1e-9 rad to which the path is kept). The exact path parameter law s(t)
(one parabola per phase) and the geometric path are available from :func:`plan` for checks.

Joints are numbered from 0 in messages, as in the arrays. Inputs are validated by the caller
(:func:`kinplan.trajectory.time_optimal`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinplan.errors import InfeasibleError
from kinplan.trajectory import _profiles, phase_plane
from kinplan.trajectory.phase_plane import PathLaw

__all__ = [
    "ANGLE_TOLERANCE",
    "ARC_MARGIN",
    "ARC_STEP",
    "CHECK_SAMPLES",
    "DUPLICATE_TOLERANCE",
    "REVERSAL_TOLERANCE",
    "JointPath",
    "PathLaw",
    "TimeOptimalPlan",
    "plan",
]

ANGLE_TOLERANCE = 1e-12
"""Corners whose direction changes by less than this are straight: no blend, no stop [rad]."""

REVERSAL_TOLERANCE = 1e-6
"""Corners within this of a full reversal (turning angle π) are kept as corners and the motion
stops there: a blend would have a radius of almost zero [rad]."""

DUPLICATE_TOLERANCE = 1e-12
"""Consecutive points closer than this (Euclidean norm) are one point [rad]."""

ARC_STEP = 0.01
"""Largest angle of arc of one interval of a circular blend [rad]."""

ARC_MARGIN = 1e-4
"""Relative margin below the limits that blends are planned for [-]: the limits are imposed at
the ends of each interval; in between they vary by about (Δθ)² ≤ 1e-4 of their scale."""

CHECK_SAMPLES = 16
"""Samples per blend segment at which the built motion is checked against the limits [-]."""

_REFINEMENTS = 6
"""Times the blend intervals that the dense check finds over a limit are cut finer [-]."""

_MAX_INTERVALS = 200_000
"""Most intervals the refinement may reach (about 0.2 s of planning) [-]."""

_SPLIT = 8
"""Parts each such interval is cut into (the variation between its ends falls 64-fold) [-]."""


# ----------------------------------------------------------------------------------------------
# Geometry
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class _Pieces:
    """The path's pieces as arrays, one row per piece.

    Lines have ``radius = inf``, ``normal = 0`` and ``tangent`` their direction; arcs run from
    ``start`` with unit ``tangent`` there, ``normal`` the unit vector from the centre to
    ``start``: q(θ) = start + r (normal (cos θ − 1) + tangent sin θ), θ = (s − s0) / r.
    """

    s0: np.ndarray  # (P,) [rad of path length]
    length: np.ndarray  # (P,)
    start: np.ndarray  # (P, n)
    tangent: np.ndarray  # (P, n)
    normal: np.ndarray  # (P, n)
    radius: np.ndarray  # (P,)


class JointPath:
    """Straight lines through joint-space points with circular blends at the corners.

    Attributes:
        points: The points after dropping consecutive duplicates, shape (m, n) [rad].
        max_deviation: Largest distance of a blend from its corner [rad].
        length: Arc length of the whole path [rad] (Euclidean over joints).
        n: Number of joints.
        stops: Path parameters where the path keeps a corner (the motion stops), shape (k,).
        corner_parameters: Path parameter of the point nearest each of ``points`` (the corner,
            or the middle of its blend), shape (m,).
        corner_deviation: Distance from each point to the path there, shape (m,) [rad].
    """

    def __init__(self, points: np.ndarray, max_deviation: float = 0.0) -> None:
        """Build the path.

        Args:
            points: Joint-space points, shape (m, n), m ≥ 1 [rad]; consecutive points closer than
                :data:`DUPLICATE_TOLERANCE` are merged (the last point is kept exactly).
            max_deviation: Largest distance of a blend from its corner, ≥ 0 [rad].
        """
        self.points = _without_duplicates(np.asarray(points, dtype=float))
        self.max_deviation = float(max_deviation)
        self.n = self.points.shape[1]
        pieces, stops, corners, deviation = _build(self.points, self.max_deviation)
        self._pieces = pieces
        self.length = float(pieces.s0[-1] + pieces.length[-1]) if pieces.s0.size else 0.0
        self.stops = np.asarray(stops, dtype=float)
        self.corner_parameters = np.asarray(corners, dtype=float)
        self.corner_deviation = np.asarray(deviation, dtype=float)

    @property
    def piece_count(self) -> int:
        """Number of lines and arcs."""
        return int(self._pieces.s0.size)

    def is_arc(self, index: np.ndarray) -> np.ndarray:
        """Whether the pieces ``index`` are circular blends (else lines)."""
        return np.isfinite(self._pieces.radius[index])

    def piece_at(self, s: np.ndarray) -> np.ndarray:
        """Index of the piece holding each path parameter (the later piece at a junction)."""
        index = np.searchsorted(self._pieces.s0, s, side="right") - 1
        return np.clip(index, 0, max(self.piece_count - 1, 0))

    def evaluate(
        self, s: np.ndarray, order: int = 0, piece: np.ndarray | None = None
    ) -> np.ndarray:
        """Position or its derivatives along the path, one vectorised evaluation.

        Args:
            s: Path parameters (arc length from the start), shape (k,) [rad].
            order: 0 for q(s) [rad], 1 for dq/ds (unit length) [-], 2 for d²q/ds² [1/rad].
            piece: The piece each parameter belongs to, shape (k,); default :meth:`piece_at`
                (give it to take the one-sided values at a junction).

        Returns:
            Shape (k, n).
        """
        s = np.atleast_1d(np.asarray(s, dtype=float))
        if self.piece_count == 0:
            return np.broadcast_to(self.points[0] if order == 0 else 0.0, (s.size, self.n)).copy()
        p = self._pieces
        index = self.piece_at(s) if piece is None else np.asarray(piece)
        sigma = (s - p.s0[index])[:, None]
        radius = p.radius[index][:, None]
        arc = np.isfinite(radius)
        safe_radius = np.where(arc, radius, 1.0)
        theta = np.where(arc, sigma / safe_radius, 0.0)
        tangent, normal = p.tangent[index], p.normal[index]
        if order == 0:
            bend = safe_radius * (
                -2.0 * np.sin(0.5 * theta) ** 2 * normal + np.sin(theta) * tangent
            )
            return p.start[index] + np.where(arc, bend, sigma * tangent)
        if order == 1:
            return np.where(arc, np.cos(theta) * tangent - np.sin(theta) * normal, tangent)
        if order == 2:
            curvature = -(np.cos(theta) * normal + np.sin(theta) * tangent) / safe_radius
            return np.where(arc, curvature, 0.0)
        raise ValueError(f"order must be 0, 1 or 2, got {order}")

    def chord(self, s0: np.ndarray, s1: np.ndarray, piece: np.ndarray) -> np.ndarray:
        """q(s1) − q(s0) within one piece, without cancellation (however short the step).

        On an arc, with Δθ = (s1 − s0)/r and θ_m the mean angle, the chord is
        ``2 r sin(Δθ/2) (tangent cos θ_m − normal sin θ_m)``.

        Args:
            s0: Start parameters, shape (k,).
            s1: End parameters, shape (k,), on the same pieces.
            piece: The piece of each pair, shape (k,).

        Returns:
            Shape (k, n) [rad].
        """
        p = self._pieces
        step = (np.asarray(s1, dtype=float) - s0)[:, None]
        radius = p.radius[piece][:, None]
        arc = np.isfinite(radius)
        safe_radius = np.where(arc, radius, 1.0)
        # (s0 − piece start) is exact near the piece start, (s0 + s1)/2 would not be.
        middle = ((s0 - p.s0[piece])[:, None] + 0.5 * step) / safe_radius
        bend = (2.0 * safe_radius * np.sin(0.5 * step / safe_radius)) * (
            np.cos(middle) * p.tangent[piece] - np.sin(middle) * p.normal[piece]
        )
        return np.where(arc, bend, step * p.tangent[piece])


def _without_duplicates(points: np.ndarray) -> np.ndarray:
    """``points`` without consecutive near-duplicates; the last point stays exactly."""
    kept = [0]
    for k in range(1, points.shape[0]):
        if np.linalg.norm(points[k] - points[kept[-1]]) > DUPLICATE_TOLERANCE:
            kept.append(k)
        elif k == points.shape[0] - 1 and len(kept) > 1:
            kept[-1] = k  # the end point is kept exactly
    return points[kept]


def _build(points: np.ndarray, max_deviation: float):
    """Pieces, stop parameters, corner parameters and corner deviations of the path."""
    m, n = points.shape
    rows: list[tuple[np.ndarray, np.ndarray, np.ndarray, float, float, float]] = []
    if m < 2:
        return _stack(rows, n), [], [0.0], [0.0]
    chords = np.diff(points, axis=0)
    lengths = np.linalg.norm(chords, axis=1)
    directions = chords / lengths[:, None]
    # Blend half-widths ℓ (0 where the corner is kept or straight) and their arcs.
    half = np.zeros(m)
    arcs: dict[int, tuple[np.ndarray, np.ndarray, float, float]] = {}
    kept_corner = np.zeros(m, dtype=bool)
    for k in range(1, m - 1):
        before, after = directions[k - 1], directions[k]
        difference = after - before
        angle = 2.0 * math.atan2(np.linalg.norm(difference), np.linalg.norm(after + before))
        if angle <= ANGLE_TOLERANCE:
            continue
        if max_deviation == 0.0 or angle >= math.pi - REVERSAL_TOLERANCE:
            kept_corner[k] = True
            continue
        reach = max_deviation * math.sin(0.5 * angle) / (2.0 * math.sin(0.25 * angle) ** 2)
        ell = min(0.5 * lengths[k - 1], 0.5 * lengths[k], reach)
        radius = ell / math.tan(0.5 * angle)
        inward = difference + 2.0 * math.sin(0.5 * angle) ** 2 * before
        inward /= np.linalg.norm(inward)
        half[k] = ell
        arcs[k] = (-inward, before, radius, angle)
    s = 0.0
    stops: list[float] = []
    corners = [0.0]
    deviation = [0.0]
    for k in range(m - 1):
        start = points[k] + half[k] * directions[k]
        line_length = lengths[k] - half[k] - half[k + 1]
        if line_length > 0.0:
            rows.append((start, directions[k], np.zeros(n), np.inf, line_length, s))
            s += line_length
        if k + 1 in arcs:
            normal, tangent, radius, angle = arcs[k + 1]
            arc_start = points[k + 1] - half[k + 1] * directions[k]
            rows.append((arc_start, tangent, normal, radius, radius * angle, s))
            corners.append(s + 0.5 * radius * angle)
            deviation.append(radius / math.cos(0.5 * angle) - radius)
            s += radius * angle
        elif k + 1 < m - 1:
            corners.append(s)
            deviation.append(0.0)
            if kept_corner[k + 1]:
                stops.append(s)
    corners.append(s)
    deviation.append(0.0)
    return _stack(rows, n), stops, corners, deviation


def _stack(rows: list, n: int) -> _Pieces:
    if not rows:
        empty = np.zeros((0, n))
        return _Pieces(np.zeros(0), np.zeros(0), empty, empty, empty, np.zeros(0))
    start, tangent, normal, radius, length, s0 = zip(*rows, strict=True)
    return _Pieces(
        s0=np.array(s0),
        length=np.array(length),
        start=np.array(start),
        tangent=np.array(tangent),
        normal=np.array(normal),
        radius=np.array(radius),
    )


# ----------------------------------------------------------------------------------------------
# Phase-plane timing
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class TimeOptimalPlan:
    """What :func:`plan` computes.

    Attributes:
        path: The geometric path.
        law: The path parameter against time.
        knots: Knot times of the joint-space segments, shape (S + 1,) [s].
        coefficients: S arrays of shape (n, 3) (lines) or (n, 6) (blends), lowest power first,
            in local time [rad].
        minimum_duration: The time-optimal duration (before any requested stretch) [s].
    """

    path: JointPath
    law: PathLaw
    knots: np.ndarray
    coefficients: list[np.ndarray]
    minimum_duration: float

    @property
    def duration(self) -> float:
        """Duration of the motion [s]."""
        return float(self.knots[-1])

    def waypoint_times(self) -> np.ndarray:
        """Time at which the motion is nearest each point of the path, shape (m,) [s]."""
        return self.law_time(self.path.corner_parameters)

    def law_time(self, s: np.ndarray) -> np.ndarray:
        """Times at which the path parameter reaches ``s`` (the first time), shape (k,) [s]."""
        law = self.law
        s = np.atleast_1d(np.asarray(s, dtype=float))
        ends = np.append(law.s[1:], self.path.length)  # each phase ends where the next starts
        k = np.clip(np.searchsorted(ends, s, side="left"), 0, law.t.size - 1)
        # Cancellation-free: from the start of an accelerating phase, from the end of a
        # braking one (where the speed may reach 0).
        ahead = np.clip(s - law.s[k], 0.0, ends[k] - law.s[k])
        behind = ends[k] - law.s[k] - ahead
        end_speed = law.sd[k] + law.sdd[k] * law.h[k]
        accelerating = law.sdd[k] >= 0.0
        speed = np.where(accelerating, law.sd[k], end_speed)
        distance = np.where(accelerating, ahead, behind)
        root = np.sqrt(speed**2 + 2.0 * np.abs(law.sdd[k]) * distance)
        denominator = speed + root
        tau = np.divide(
            2.0 * distance, denominator, out=np.zeros_like(distance), where=denominator > 0.0
        )
        tau = np.where(accelerating, tau, law.h[k] - tau)
        return np.minimum(law.t[k] + np.clip(tau, 0.0, law.h[k]), self.duration)


def _initial_nodes(path: JointPath, arc_step: float) -> tuple[np.ndarray, np.ndarray]:
    """Node parameters (every interval's start) and the piece of each interval: one interval
    per line, arcs cut into equal intervals of at most ``arc_step`` rad of arc."""
    p = path._pieces
    nodes: list[np.ndarray] = []
    pieces: list[np.ndarray] = []
    for k in range(path.piece_count):
        count = 1
        if np.isfinite(p.radius[k]):
            count = max(2, math.ceil(p.length[k] / (arc_step * p.radius[k])))
        nodes.append(p.s0[k] + p.length[k] * np.arange(count) / count)
        pieces.append(np.full(count, k))
    return np.concatenate(nodes), np.concatenate(pieces)


def _split(
    starts: np.ndarray, piece: np.ndarray, length: float, marked: np.ndarray, parts: int
) -> tuple[np.ndarray, np.ndarray]:
    """The intervals ``marked`` cut into ``parts`` equal intervals each."""
    ends = np.append(starts[1:], length)
    fractions = np.arange(1, parts) / parts
    extra = starts[marked, None] + (ends - starts)[marked, None] * fractions[None, :]
    order = np.argsort(np.concatenate([starts, extra.ravel()]), kind="stable")
    new_piece = np.concatenate([piece, np.repeat(piece[marked], parts - 1)])
    return np.concatenate([starts, extra.ravel()])[order], new_piece[order]


def _intervals(
    path: JointPath,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    starts: np.ndarray,
    piece: np.ndarray,
) -> phase_plane.Intervals:
    """The limits on each interval (see :class:`kinplan.trajectory.phase_plane.Intervals`).

    Args:
        path: The path.
        max_velocity: Velocity limits, shape (n,) [rad/s].
        max_acceleration: Acceleration limits, shape (n,) [rad/s²].
        starts: Parameter of each interval's start, increasing from 0, shape (I,).
        piece: The piece of each interval, shape (I,).
    """
    s = np.append(starts, path.length)
    free = ~path.is_arc(piece)
    return phase_plane.intervals(
        s,
        path.evaluate(starts, 1, piece),
        path.evaluate(starts, 2, piece),
        path.evaluate(s[1:], 1, piece),
        path.evaluate(s[1:], 2, piece),
        max_velocity,
        max_acceleration,
        np.where(free, 1.0 - _profiles.LIMIT_MARGIN, 1.0 - ARC_MARGIN),
        free=free,
        piece=piece,
        stops=path.stops,
    )


def _law(intervals: phase_plane.Intervals, x: np.ndarray) -> PathLaw:
    """The phases of the optimal law from the node speeds: one per arc interval, up to three
    (accelerate, cruise, brake) per line."""
    s_list, sd_list, sdd_list, h_list, piece_list = [], [], [], [], []

    def phase(s0: float, x0: float, x1: float, length: float, piece: int) -> None:
        if length <= 0.0:
            return
        sd0, sd1 = math.sqrt(x0), math.sqrt(x1)
        if sd0 + sd1 == 0.0:
            raise InfeasibleError(  # unreachable for positive limits
                f"the path cannot be timed: the speed is zero over [{s0:.6g}, "
                f"{s0 + length:.6g}] of its length; check the limits"
            )
        s_list.append(s0)
        sd_list.append(sd0)
        sdd_list.append((x1 - x0) / (2.0 * length))
        h_list.append(2.0 * length / (sd0 + sd1))
        piece_list.append(piece)

    w = intervals.w
    for i, (s0, length) in enumerate(zip(intervals.s[:-1], intervals.delta, strict=True)):
        x0, x1, piece = x[i], x[i + 1], int(intervals.piece[i])
        if not intervals.free[i]:
            phase(s0, x0, x1, length, piece)
            continue
        top = intervals.ceiling[i]
        accel = float(np.min(w[i]))  # lines: |u| ≤ the smallest w
        rise = min(max((top - x0) / (2.0 * accel), 0.0), length)
        fall = min(max((top - x1) / (2.0 * accel), 0.0), length)
        if rise + fall <= length:  # accelerate, cruise at the ceiling, brake
            phase(s0, x0, top, rise, piece)
            phase(s0 + rise, top, top, length - rise - fall, piece)
            phase(s0 + length - fall, top, x1, fall, piece)
        else:  # accelerate, then brake, meeting below the ceiling
            meet = min(max((x1 - x0 + 2.0 * accel * length) / (4.0 * accel), 0.0), length)
            peak = min(x0 + 2.0 * accel * meet, top)
            phase(s0, x0, peak, meet, piece)
            phase(s0 + meet, peak, x1, length - meet, piece)
    h = np.array(h_list)
    return PathLaw(
        t=np.concatenate([[0.0], np.cumsum(h)[:-1]]) if h.size else np.zeros(0),
        s=np.array(s_list),
        sd=np.array(sd_list),
        sdd=np.array(sdd_list),
        h=h,
        piece=np.array(piece_list, dtype=int),
    )


def _joint_pieces(path: JointPath, law: PathLaw) -> _profiles.Pieces:
    """Joint-space segments of the law: exact quadratics on lines, quintic Hermite on arcs."""
    piece = law.piece
    h = law.h
    s_end = law.s + law.sd * h + 0.5 * law.sdd * h**2
    sd_end = law.sd + law.sdd * h
    q0 = path.evaluate(law.s, 0, piece)
    d0 = path.evaluate(law.s, 1, piece)
    dd0 = path.evaluate(law.s, 2, piece)
    d1 = path.evaluate(s_end, 1, piece)
    dd1 = path.evaluate(s_end, 2, piece)
    sd0, sd1, sdd = law.sd[:, None], sd_end[:, None], law.sdd[:, None]
    v0, v1 = d0 * sd0, d1 * sd1
    a0 = d0 * sdd + dd0 * sd0**2
    a1 = d1 * sdd + dd1 * sd1**2
    arc = path.is_arc(piece)
    coefficients: list[np.ndarray] = list(np.stack([q0, v0, 0.5 * a0], axis=2))  # lines
    if np.any(arc):
        # The chord from the geometry, not q1 − q0: on a tiny blend the difference of two
        # positions would lose its digits, and the quintic's acceleration with them.
        chord = path.chord(law.s[arc], s_end[arc], piece[arc])
        quintic = _profiles.quintic_coefficients(
            np.zeros_like(chord), chord, v0[arc], v1[arc], a0[arc], a1[arc], h[arc, None]
        )  # (A, 6, n): the formula is elementwise, so it takes every arc phase at once
        quintic[:, 0, :] = q0[arc]
        for k, c in zip(np.flatnonzero(arc), np.transpose(quintic, (0, 2, 1)), strict=True):
            coefficients[k] = c
    knots = np.concatenate([[0.0], np.cumsum(h)])
    return knots, coefficients


def _exceeded(
    knots: np.ndarray,
    coefficients: list[np.ndarray],
    arc: np.ndarray,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
) -> np.ndarray:
    """Which segments a dense check (:data:`CHECK_SAMPLES` per blend segment) finds over a
    limit, shape (S,) bool; lines are exact and not checked."""
    exceeded = np.zeros(arc.size, dtype=bool)
    if not np.any(arc):
        return exceeded
    c = np.stack([coefficients[k] for k in np.flatnonzero(arc)])[:, None, :, :]  # (A, 1, n, 6)
    h = np.diff(knots)[arc]
    tau = (h[:, None] * np.linspace(0.0, 1.0, CHECK_SAMPLES + 1)[None, :])[:, :, None]
    qd = 5.0 * c[..., 5]  # Horner, as the evaluator: (A, K, n)
    for power in (4, 3, 2, 1):
        qd = qd * tau + power * c[..., power]
    qdd = 20.0 * c[..., 5]
    for power in (4, 3, 2):
        qdd = qdd * tau + power * (power - 1) * c[..., power]
    over = np.any(np.abs(qd) > max_velocity, axis=(1, 2)) | np.any(
        np.abs(qdd) > max_acceleration, axis=(1, 2)
    )
    exceeded[arc] = over
    return exceeded


def plan(
    points: np.ndarray,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
    max_deviation: float = 0.0,
    duration: float | None = None,
) -> TimeOptimalPlan:
    """Time-optimal motion along the blended path through ``points``, at rest at both ends.

    Args:
        points: Joint-space points, shape (m, n), m ≥ 1 [rad] (validated by the caller).
        max_velocity: Velocity limits, shape (n,), > 0 [rad/s].
        max_acceleration: Acceleration limits, shape (n,), > 0 [rad/s²].
        max_deviation: Largest distance of a blend from its corner, ≥ 0 [rad].
        duration: Requested duration [s]; the optimal law is then played slower, uniformly.

    Returns:
        The path, its law and the joint-space segments (one empty segment for a path of zero
        length: a motion of zero duration).

    Raises:
        InfeasibleError: ``duration`` is shorter than the time-optimal duration (the message
            states it).
    """
    path = JointPath(points, max_deviation)
    if path.piece_count == 0:
        t, s, sd, sdd, h = (np.zeros(1) for _ in range(5))
        law = PathLaw(t, s, sd, sdd, h, piece=np.zeros(1, dtype=int))
        q = path.points[0][:, None]
        coefficients = [np.hstack([q, np.zeros((path.n, 2))])]
        knots = np.array([0.0, 0.0 if duration is None else duration])
        return TimeOptimalPlan(path, law, knots, coefficients, 0.0)
    starts, piece = _initial_nodes(path, ARC_STEP)
    for _ in range(_REFINEMENTS + 1):
        intervals = _intervals(path, max_velocity, max_acceleration, starts, piece)
        law = _law(intervals, phase_plane.fastest(intervals, phase_plane.controllable(intervals)))
        minimum = law.duration
        if duration is not None:
            _check_duration(duration, minimum)
            law = law.stretched(max(duration / minimum, 1.0))
        knots, coefficients = _joint_pieces(path, law)
        arc = path.is_arc(law.piece)
        exceeded = _exceeded(knots, coefficients, arc, max_velocity, max_acceleration)
        if not np.any(exceeded):
            return TimeOptimalPlan(path, law, knots, coefficients, minimum)
        # Arc phases are whole intervals: cut those that went over into finer ones.
        marked = np.searchsorted(starts, law.s[exceeded], side="right") - 1
        starts, piece = _split(starts, piece, path.length, np.unique(marked), _SPLIT)
        if starts.size > _MAX_INTERVALS:
            break
    raise InfeasibleError(  # not expected: each refinement divides the variation by 64
        "the blends of the time-optimal path could not be kept within the limits on a fine "
        "grid; give a larger max_deviation or slightly lower limits"
    )


def _check_duration(requested: float, minimum: float) -> None:
    if requested < minimum * (1.0 - _profiles.RELATIVE_TOLERANCE):
        least = _profiles.round_up(minimum)
        raise InfeasibleError(
            f"duration {requested:.6g} s is too short: the path needs at least {least:.6g} s "
            "within max_velocity and max_acceleration; give a duration of at least "
            f"{least:.6g} s or raise the limits"
        )
