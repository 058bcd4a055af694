"""Tool paths in Cartesian space, parametrised by the path-length fraction s ∈ [0, 1].

Every path gives, vectorised over an array of s:

* ``position(s)`` (N, 3) [m] and its derivatives ``position_derivatives(s)`` (dp/ds, d²p/ds²);
* ``rotation(s)`` (N, 3, 3) and ``angular_rates(s)`` (ω_s = dω/dṡ and its derivative, world frame)
  when the path carries an orientation; a path built from 3-vectors is position-only.

s is proportional to arc length (s = u / length), so a constant ṡ is a constant tool speed.
Orientation moves by geodesic interpolation (slerp) from the start to the end rotation.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TypeAlias

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from kinplan import checks
from kinplan.checks import parse_target
from kinplan.errors import InputError

_FD_STEP = 1e-5  # [-] step in s for the finite-difference fallbacks

#: A path point: a ``pinocchio.SE3`` pose, a 4×4 homogeneous matrix or a position 3-vector [m].
PointLike: TypeAlias = pin.SE3 | Sequence[float] | np.ndarray
#: A tool rotation: a 3×3 rotation matrix or a ``pinocchio.SE3`` (its rotation).
RotationLike: TypeAlias = pin.SE3 | Sequence[Sequence[float]] | np.ndarray


def _points(
    values: Sequence[PointLike], names: Sequence[str]
) -> tuple[list[np.ndarray], list[np.ndarray] | None]:
    """Positions and rotations of several path points; all poses or all positions.

    Raises:
        InputError: a point that is not an SE3 pose or a finite 3-vector [m] (a 4×4 matrix
            whose rotation part is not a rotation), or a mix of poses and positions.
    """
    parsed = [parse_target(v, n) for v, n in zip(values, names)]
    rotations = [r for _, r in parsed]
    if all(r is None for r in rotations):
        return [p for p, _ in parsed], None
    if any(r is None for r in rotations):
        raise InputError(
            f"give {', '.join(names)} either all as poses (SE3) or all as positions (3-vectors); "
            "a path is position-only or fully oriented"
        )
    return [p for p, _ in parsed], [r for r in rotations if r is not None]


def as_fractions(s: ArrayLike) -> np.ndarray:
    """Path fractions as a 1-D float array (values outside [0, 1] are clipped by the callers).

    Raises:
        InputError: not a number or a 1-D array of finite numbers.
    """
    if type(s) is np.ndarray and s.dtype == np.float64 and s.ndim == 1:  # the common case
        arr = s
    else:
        arr = np.atleast_1d(checks.floats(s, "s", "a number or a 1-D array of path fractions"))
    if arr.ndim != 1:
        raise InputError(
            f"s must be a number or a 1-D array of path fractions, got shape {arr.shape}"
        )
    if not np.all(np.isfinite(arr)):
        raise InputError(f"s must hold finite path fractions in [0, 1], got {arr}")
    return arr


class Slerp:
    """Geodesic interpolation R(s) = R0 exp(s v), v = log(R0ᵀ R1); ω = R0 v ṡ in the world."""

    def __init__(self, start: np.ndarray, end: np.ndarray) -> None:
        self.start = np.array(start, dtype=float)
        self.local_axis = pin.log3(self.start.T @ np.asarray(end, dtype=float))
        self.world_rate = self.start @ self.local_axis  # [rad per unit s], constant
        # Rodrigues about the one unit axis k: exp(θ[k]×) = I + sin θ [k]× + (1 − cos θ)[k]×²,
        # so R(s) = R0 + sin(sθ)·R0[k]× + (1 − cos(sθ))·R0[k]×², rows of 9 entries
        self._angle = angle = float(np.linalg.norm(self.local_axis))
        cross = pin.skew(self.local_axis / angle) if angle > 0.0 else np.zeros((3, 3))
        terms = (self.start, self.start @ cross, self.start @ cross @ cross)
        self._terms = np.stack(terms).reshape(3, 9)

    @property
    def angle(self) -> float:
        """Rotation angle from start to end [rad]."""
        return self._angle

    def __call__(self, s: np.ndarray) -> np.ndarray:
        """Rotations (N, 3, 3) at path fractions ``s`` (N,) in [0, 1]; exactly R0 where the
        angle sθ is below 1e-12 rad."""
        theta = s * self._angle
        small = theta < 1e-12
        weights = np.empty((len(s), 3))
        weights[:, 0] = 1.0
        weights[:, 1] = np.where(small, 0.0, np.sin(theta))
        weights[:, 2] = np.where(small, 0.0, 1.0 - np.cos(theta))
        return (weights @ self._terms).reshape(-1, 3, 3)

    def rates(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        n = len(s)
        return np.tile(self.world_rate, (n, 1)), np.zeros((n, 3))


class Path:
    """Base class of tool paths: s ∈ [0, 1] is the fraction of the path length.

    Attributes:
        length: Path length [m].
        has_orientation: Whether the path prescribes the tool rotation.
    """

    length: float = 0.0
    has_orientation: bool = False
    _fd_step: float = _FD_STEP  # [-] finite-difference step in s
    slerp: Slerp | None = None  # start-to-end geodesic orientation, when the path uses one

    # -- to implement -------------------------------------------------------------------
    def position(self, s: ArrayLike) -> np.ndarray:
        """Tool positions (N, 3) [m] in the world frame at path fractions ``s``."""
        raise NotImplementedError

    def _rotation(self, s: np.ndarray) -> np.ndarray:
        """Rotations at clipped fractions s (oriented paths): the slerp unless overridden."""
        if self.slerp is None:
            raise NotImplementedError("an oriented path without a slerp implements _rotation")
        return self.slerp(s)

    # -- shared -------------------------------------------------------------------------
    def rotation(self, s: ArrayLike) -> np.ndarray | None:
        """Tool rotations (N, 3, 3) in the world frame, or None for a position-only path."""
        if not self.has_orientation:
            return None
        return self._rotation(np.clip(as_fractions(s), 0.0, 1.0))

    def position_derivatives(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(dp/ds, d²p/ds²), each (N, 3) [m]; central finite differences unless overridden
        (one-sided at the ends; fractions beyond them get the end's)."""
        s = as_fractions(s).clip(0.0, 1.0)
        h = self._fd_step
        lo, hi = np.clip(s - h, 0, 1), np.clip(s + h, 0, 1)
        mid = 0.5 * (lo + hi)
        p_lo, p_mid, p_hi = self.position(lo), self.position(mid), self.position(hi)
        width = (hi - lo)[:, None]
        first = (p_hi - p_lo) / width
        second = 4.0 * (p_hi - 2.0 * p_mid + p_lo) / width**2
        return first, second

    def angular_rates(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(ω_s, dω_s/ds), each (N, 3) in the world frame: ω = ω_s ṡ [rad/s]."""
        s = as_fractions(s)
        if not self.has_orientation:
            zeros = np.zeros((len(s), 3))
            return zeros, zeros
        if self.slerp is not None:
            return self.slerp.rates(s)
        s = s.clip(0.0, 1.0)  # beyond the ends: the end's rates (differences, not 0/0)
        h = self._fd_step
        lo, hi = np.clip(s - h, 0, 1), np.clip(s + h, 0, 1)
        mid = 0.5 * (lo + hi)
        r_lo, r_mid, r_hi = self._rotation(lo), self._rotation(mid), self._rotation(hi)
        width = hi - lo
        w_lo = np.array([pin.log3(b @ a.T) for a, b in zip(r_lo, r_mid)]) / (0.5 * width)[:, None]
        w_hi = np.array([pin.log3(b @ a.T) for a, b in zip(r_mid, r_hi)]) / (0.5 * width)[:, None]
        return 0.5 * (w_lo + w_hi), (w_hi - w_lo) / (0.5 * width)[:, None]

    def pose(self, s: float) -> pin.SE3:
        """Tool pose at path fraction ``s`` (identity rotation for a position-only path).

        Raises:
            InputError: ``s`` is not a finite number.
        """
        s = checks.number(s, "s")
        position = self.position(np.array([s]))[0]
        rotation = self.rotation(np.array([s]))
        return pin.SE3(np.eye(3) if rotation is None else rotation[0], position)

    @property
    def start(self) -> pin.SE3:
        return self.pose(0.0)

    @property
    def end(self) -> pin.SE3:
        return self.pose(1.0)


class Line(Path):
    """Straight line from ``start`` to ``end`` (SE3 poses or 3-vectors [m]).

    Orientation (for poses) moves by slerp from the start to the end rotation.
    """

    def __init__(self, start: PointLike, end: PointLike) -> None:
        (self.a, self.b), rotations = _points([start, end], ["start", "end"])
        with np.errstate(over="ignore", invalid="ignore"):
            self.delta = self.b - self.a
            self.length = float(np.linalg.norm(self.delta))
        if not np.isfinite(self.length):
            raise InputError(
                f"a Line from {self.a.tolist()} to {self.b.tolist()} m is too long to compute "
                "with; give start and end points in metres at a working distance"
            )
        self.has_orientation = rotations is not None
        self.slerp = Slerp(*rotations) if rotations else None
        if self.length == 0.0 and (self.slerp is None or self.slerp.angle == 0.0):
            raise InputError(
                "a Line needs two different points (or rotations): start == end; give an end "
                "away from the start"
            )

    def __repr__(self) -> str:
        return f"Line({self.a.round(4).tolist()} → {self.b.round(4).tolist()}, {self.length:.4g} m)"

    def position(self, s: ArrayLike) -> np.ndarray:
        s = as_fractions(s).clip(0.0, 1.0)
        return self.a + s[:, None] * self.delta

    def position_derivatives(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        n = len(as_fractions(s))
        return np.tile(self.delta, (n, 1)), np.zeros((n, 3))


class CircularArc(Path):
    """Arc of a circle: p(s) = c + r (cos(θs) e1 + sin(θs) e2), θ the swept angle [rad].

    Args:
        center: Circle centre [m].
        radius: Radius [m] (> 0).
        e1: Unit vector from the centre to the start point.
        e2: Unit vector in the circle's plane, 90° ahead of e1 in the direction of travel.
        sweep: Swept angle θ [rad] (> 0; 2π for a full circle).
        rotations: (start, end) tool rotations for slerp, or None for position only.
    """

    def __init__(
        self,
        center: ArrayLike,
        radius: float,
        e1: ArrayLike,
        e2: ArrayLike,
        sweep: float,
        rotations: Sequence[RotationLike] | None = None,
    ) -> None:
        self.center = checks.vector(center, "center", 3, "m")
        self.radius = checks.number(radius, "radius", positive=True, unit="m")
        self.e1 = checks.vector(e1, "e1", 3)
        self.e2 = checks.vector(e2, "e2", 3)
        self.sweep = checks.number(sweep, "sweep", positive=True, unit="rad")
        for name, vector in (("e1", self.e1), ("e2", self.e2)):
            norm = float(np.linalg.norm(vector))
            if abs(norm - 1.0) > 1e-9:
                raise InputError(f"{name} must be a unit vector, got {vector} of norm {norm:.6g}")
        if abs(float(self.e1 @ self.e2)) > 1e-9:
            raise InputError(
                f"e1 and e2 must be perpendicular unit vectors (e1·e2 = 0), got e1·e2 = "
                f"{self.e1 @ self.e2:.3g}"
            )
        self.length = self.radius * self.sweep
        if not np.isfinite(self.length):
            raise InputError(f"radius × sweep overflows: {self.radius} m × {self.sweep} rad")
        self.has_orientation = rotations is not None
        if rotations is not None:
            if not isinstance(rotations, (tuple, list)) or len(rotations) != 2:
                raise InputError(
                    "rotations must be a pair (start, end) of 3×3 rotation matrices, or None for "
                    f"position only; got {checks.describe(rotations)}"
                )
            rotations = (
                checks.rotation(rotations[0], "the start rotation"),
                checks.rotation(rotations[1], "the end rotation"),
            )
        self.slerp = Slerp(*rotations) if rotations is not None else None

    def __repr__(self) -> str:
        return (
            f"{type(self).__name__}(centre {self.center.round(4).tolist()}, r {self.radius:.4g} m, "
            f"{np.degrees(self.sweep):.1f}°)"
        )

    def position(self, s: ArrayLike) -> np.ndarray:
        phi = self.sweep * np.clip(as_fractions(s), 0.0, 1.0)
        return self.center + self.radius * (
            np.cos(phi)[:, None] * self.e1 + np.sin(phi)[:, None] * self.e2
        )

    def position_derivatives(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        phi = self.sweep * np.clip(as_fractions(s), 0.0, 1.0)
        cos, sin = np.cos(phi)[:, None], np.sin(phi)[:, None]
        k = self.radius * self.sweep
        first = k * (-sin * self.e1 + cos * self.e2)
        second = -k * self.sweep * (cos * self.e1 + sin * self.e2)
        return first, second


class Arc(CircularArc):
    """Arc of the circle through ``start``, ``via`` and ``end``, from start through via to end.

    The points are SE3 poses or 3-vectors [m]; with poses the tool rotation moves by slerp from
    the start to the end rotation (the via point's rotation is not used).

    Raises:
        InputError: the three points are (nearly) collinear or coincide.
    """

    def __init__(self, start: PointLike, via: PointLike, end: PointLike) -> None:
        (a, b, c), rotations = _points([start, via, end], ["start", "via", "end"])
        ab, ac = b - a, c - a
        normal = np.cross(ab, ac)
        scale = max(float(np.linalg.norm(ab)), float(np.linalg.norm(ac)), 1e-300)
        if np.linalg.norm(normal) <= 1e-9 * scale**2:
            raise InputError(
                "Arc: start, via and end are collinear (or coincide), so no circle passes through "
                "them; use a Line, or move the via point off the line"
            )
        # Circumcentre of the triangle (a, b, c).
        u, v = a - c, b - c
        w = np.cross(u, v)
        center = c + np.cross(u @ u * v - v @ v * u, w) / (2.0 * (w @ w))
        radius = float(np.linalg.norm(a - center))
        if not (np.all(np.isfinite(center)) and np.isfinite(radius) and radius > 0):
            raise InputError(
                "Arc: the circle through start, via and end cannot be computed in double "
                "precision (the points are nearly collinear, nearly coincide or are very far "
                "apart); use a Line, or move the via point off the line"
            )
        n = normal / np.linalg.norm(normal)
        e1 = (a - center) / radius
        e2 = np.cross(n, e1)
        rel = c - center
        sweep = float(np.arctan2(rel @ e2, rel @ e1)) % (2.0 * np.pi)
        ends = None if rotations is None else (rotations[0], rotations[-1])
        super().__init__(center, radius, e1, e2, sweep, ends)
        self.via = b


def Circle(
    center: ArrayLike,
    radius: float,
    normal: ArrayLike = (0.0, 0.0, 1.0),
    start_direction: ArrayLike = (1.0, 0.0, 0.0),
    rotation: RotationLike | None = None,
) -> CircularArc:
    """Full circle (one turn, counter-clockwise about ``normal``) starting at
    ``center + radius * start_direction``.

    Args:
        center: Circle centre [m], a 3-vector.
        radius: Radius [m], > 0.
        normal: Axis of the circle (any non-zero 3-vector; normalised).
        start_direction: Direction from the centre to the start point (its component along
            ``normal`` is dropped; it must not be parallel to ``normal``).
        rotation: Constant tool rotation (3×3 rotation matrix or SE3), or None for position only.

    Raises:
        InputError: a centre, normal or direction that is not a finite 3-vector, a zero normal,
            a radius that is not a finite number > 0, a rotation that is not a rotation matrix.
    """
    center = checks.vector(center, "center", 3, "m")
    radius = checks.number(radius, "radius", positive=True, unit="m")
    n = checks.vector(normal, "normal", 3)
    size = float(np.linalg.norm(n))
    if not 0.0 < size < np.inf:
        raise InputError(f"Circle: normal must be a non-zero 3-vector (the circle's axis), got {n}")
    n = n / size
    d = checks.vector(start_direction, "start_direction", 3)
    d = d - (d @ n) * n
    if not np.linalg.norm(d) >= 1e-12 * max(1.0, float(np.abs(d).max(initial=0.0))):
        raise InputError(
            "Circle: start_direction must not be parallel to the normal (it points from the "
            "centre to the start point, in the circle's plane)"
        )
    e1 = d / np.linalg.norm(d)
    fixed = None if rotation is None else checks.rotation(rotation, "rotation")
    rotations = None if fixed is None else (fixed, fixed)
    return CircularArc(center, radius, e1, np.cross(n, e1), 2.0 * np.pi, rotations)


class PathSequence(Path):
    """Paths joined end to start (a polyline, lines and arcs of a seam), s over the total length.

    Raises:
        InputError: a path does not start where the previous one ends (1e-6 m, 1e-6 rad), some
            paths are oriented and others not, or a piece has zero length.
    """

    paths: list[Path]
    breaks: np.ndarray

    def __init__(self, paths: Sequence[Path]) -> None:
        try:
            if isinstance(paths, (str, bytes, Path)):
                raise TypeError
            paths = list(paths)
        except TypeError:
            raise InputError(
                f"PathSequence needs a list of paths (Line, Arc, ...), got {checks.describe(paths)}"
            ) from None
        pieces: list[Path] = []
        for k, path in enumerate(paths):
            if not isinstance(path, Path):
                raise InputError(
                    f"paths[{k}] must be a cartesian path (Line, Arc, Circle, ...), got "
                    f"{checks.describe(path)}"
                )
            pieces.extend(path.paths if isinstance(path, PathSequence) else [path])
        if not pieces:
            raise InputError("a path sequence needs at least one path")
        oriented = {p.has_orientation for p in pieces}
        if len(oriented) != 1:
            raise InputError("a path sequence cannot mix oriented and position-only paths")
        for k, (prev, nxt) in enumerate(zip(pieces, pieces[1:]), start=1):
            if prev.length <= 0 or nxt.length <= 0:
                raise InputError(f"piece {k} of the sequence has zero length")
            gap = np.linalg.norm(prev.end.translation - nxt.start.translation)
            turn = np.linalg.norm(pin.log3(prev.end.rotation.T @ nxt.start.rotation))
            if gap > 1e-6 or (nxt.has_orientation and turn > 1e-6):
                raise InputError(
                    f"piece {k + 1} of the sequence starts {gap:.3g} m / {turn:.3g} rad away from "
                    f"where piece {k} ends; paths of a sequence must be continuous"
                )
        self.paths = pieces
        self.has_orientation = oriented.pop()
        lengths = np.array([p.length for p in pieces])
        self.length = float(lengths.sum())
        self.breaks = np.concatenate(([0.0], np.cumsum(lengths) / self.length))
        self.breaks[-1] = 1.0

    def __repr__(self) -> str:
        return f"PathSequence({len(self.paths)} pieces, {self.length:.4g} m)"

    def _split(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        s = as_fractions(s).clip(0.0, 1.0)
        index = np.clip(np.searchsorted(self.breaks, s, side="right") - 1, 0, len(self.paths) - 1)
        width = self.breaks[index + 1] - self.breaks[index]
        return index, (s - self.breaks[index]) / width

    def _gather(self, s: ArrayLike, method: str, chain: int) -> list[np.ndarray]:
        index, local = self._split(s)
        outputs: list[np.ndarray] | None = None
        for k in np.unique(index) if len(index) else [0]:  # no s: piece 0 gives the shapes
            mask = index == k
            parts = getattr(self.paths[k], method)(local[mask])
            parts = parts if isinstance(parts, tuple) else (parts,)
            if outputs is None:
                outputs = [np.empty((len(index),) + p.shape[1:]) for p in parts]
            width = self.breaks[k + 1] - self.breaks[k]
            for order, (out, part) in enumerate(zip(outputs, parts)):
                out[mask] = part / width ** (chain * (order + 1)) if chain else part
        assert outputs is not None  # the loop ran at least once
        return outputs

    def position(self, s: ArrayLike) -> np.ndarray:
        return self._gather(s, "position", 0)[0]

    def position_derivatives(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        first, second = self._gather(s, "position_derivatives", 1)
        return first, second

    def _rotation(self, s: np.ndarray) -> np.ndarray:
        return self._gather(s, "rotation", 0)[0]

    def angular_rates(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        if not self.has_orientation:
            return super().angular_rates(s)
        first, second = self._gather(s, "angular_rates", 1)
        return first, second


def Polyline(points: Sequence[PointLike]) -> PathSequence:
    """Straight lines through ``points`` (poses or 3-vectors [m]), joined at sharp corners.

    Raises:
        InputError: fewer than two points, points that are not poses or finite 3-vectors, or two
            consecutive points that coincide.
    """
    try:
        if isinstance(points, (str, bytes, pin.SE3)):
            raise TypeError
        points = list(points)
    except TypeError:
        raise InputError(
            f"points must be a list of poses (SE3) or 3-vectors [m], got {checks.describe(points)}"
        ) from None
    if len(points) < 2:
        raise InputError(f"a polyline needs at least two points, got {len(points)}")
    lines = []
    for k, (a, b) in enumerate(zip(points, points[1:])):
        try:
            lines.append(Line(a, b))
        except InputError as exc:
            raise InputError(f"Polyline: points[{k}] to points[{k + 1}]: {exc}") from None
    return PathSequence(lines)


class HeldOrientation(Path):
    """A position-only path (built from 3-vectors) with the tool held at one rotation along it.

    What :func:`cartesian.follow` makes of a 3-vector path on an arm with 6 or more joints: the
    tool keeps the orientation it starts with.

    Args:
        path: A path without orientation.
        rotation: The tool rotation (3×3 or SE3) in the world frame.
    """

    def __init__(self, path: Path, rotation: RotationLike) -> None:
        if not isinstance(path, Path) or path.has_orientation:
            raise InputError(
                f"HeldOrientation needs a path without orientation, got {checks.describe(path)}"
            )
        fixed = checks.rotation(rotation, "rotation")
        self.path = path
        self.length = path.length
        self.has_orientation = True
        self._fd_step = path._fd_step
        self.slerp = Slerp(fixed, fixed)  # constant: vectorised, exact zero angular rates

    def __repr__(self) -> str:
        return f"HeldOrientation({self.path!r})"

    def position(self, s: ArrayLike) -> np.ndarray:
        return self.path.position(s)

    def position_derivatives(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        return self.path.position_derivatives(s)


class FunctionPath(Path):
    """Any continuous curve p(u), u ∈ [0, 1], re-parametrised by arc length.

    Args:
        function: p(u) [m]; called with an array of u (returning (N, 3)) when it accepts one,
            otherwise once per u (returning (3,)).
        orientation: None (position only), a constant rotation (3×3 or SE3), or a function
            s ↦ 3×3 rotation of the path fraction s.
        samples: Points of the arc-length table (the re-parametrisation's resolution).
    """

    def __init__(
        self,
        function: Callable[..., ArrayLike],
        orientation: RotationLike | Callable[[float], RotationLike] | None = None,
        samples: int = 4001,
    ) -> None:
        if not callable(function):
            raise InputError(
                "FunctionPath needs a function u ↦ position [m] (u in [0, 1]), got "
                f"{checks.describe(function)}"
            )
        samples = checks.count(samples, "samples", minimum=3)
        self.function = function
        u = np.linspace(0.0, 1.0, samples)
        points = self._evaluate(u)
        chords = np.linalg.norm(np.diff(points, axis=0), axis=1)
        cumulative = np.concatenate(([0.0], np.cumsum(chords)))
        self.length = float(cumulative[-1])
        if self.length <= 0:
            raise InputError("FunctionPath: the curve has zero length")
        self._u_table, self._s_table = u, cumulative / self.length
        # Differences over several table intervals: the table's u(s) is piecewise linear.
        self._fd_step = 4.0 / samples
        self._orientation: Callable[[float], RotationLike] | None = None
        if orientation is None:
            self.has_orientation = False
        elif callable(orientation):
            self.has_orientation = True
            self._orientation = orientation
        else:
            fixed = checks.rotation(orientation, "orientation")
            self.has_orientation = True
            self.slerp = Slerp(fixed, fixed)  # constant: vectorised, exact zero angular rates

    def _evaluate(self, u: np.ndarray) -> np.ndarray:
        try:
            out = np.asarray(self.function(u), dtype=float)
            if out.shape == (len(u), 3):
                values = out
            else:
                raise ValueError
        except Exception:  # the function takes one u at a time
            try:
                values = np.array([np.asarray(self.function(x), dtype=float) for x in u])
            except Exception as exc:
                raise InputError(
                    f"FunctionPath: the function failed at u in [0, 1] ({type(exc).__name__}: "
                    f"{exc}); it must return a position 3-vector [m] for each u"
                ) from exc
        if values.shape != (len(u), 3) or not np.all(np.isfinite(values)):
            raise InputError("FunctionPath: the function must return finite 3-vectors [m]")
        return values

    def position(self, s: ArrayLike) -> np.ndarray:
        s = as_fractions(s).clip(0.0, 1.0)
        return self._evaluate(np.interp(s, self._s_table, self._u_table))

    def _rotation(self, s: np.ndarray) -> np.ndarray:
        if self._orientation is None:  # a constant orientation
            return super()._rotation(s)
        try:
            rotations = [self._orientation(x) for x in s]
        except Exception as exc:
            raise InputError(
                f"FunctionPath: the orientation function failed ({type(exc).__name__}: {exc}); "
                "it must return a 3×3 rotation matrix for each path fraction s"
            ) from exc
        return np.stack([checks.rotation(r, "the orientation function's value") for r in rotations])
