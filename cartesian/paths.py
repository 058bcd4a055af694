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
from kinplan.errors import InputError
from kinplan.robot import parse_target

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


WEAVE_PATTERNS = ("sine", "triangle", "trapezoid")


class Weave(Path):
    """A weaving torch: a lateral oscillation across a seam, superposed on any path.

    The tool moves along ``path`` (the seam) and, at the same time, across it: by w(u) along
    e(s) = (n × t)/|n × t|, the direction across the seam in the plane perpendicular to ``normal``
    (n; t is the seam's tangent), where u is the distance travelled along the seam [m]. The
    path parameter s stays the seam's length fraction and :attr:`length` the seam's length, so a
    tool ``speed`` given to :func:`cartesian.follow` is the travel speed along the seam (kept
    constant) while the torch weaves. The orientation is the seam's.

    Patterns over one wavelength λ (amplitude A): ``sine`` A sin(2πu/λ); ``triangle`` straight
    sweeps between ±A; ``trapezoid`` straight sweeps with a quarter wavelength held at each side.
    ``dwell`` [m of travel] holds the torch at each side for that distance more (a dwell time of
    dwell / speed), within the same wavelength.

    **Corners are rounded.** A triangle, a trapezoid or a dwell turns the sweep at a corner,
    where the lateral velocity would jump (an infinite acceleration no arm can follow and no
    sampling can represent). Each corner is rounded over ``rounding`` metres of travel (a cubic
    blend: the shape convolved with a triangular window of that width, so velocity and
    acceleration are continuous), then the shape is scaled so that its extremes still reach ±A.
    The sweeps between corners stay straight. The sine without dwell has no corner; its dwell
    edges join with continuous velocity (the acceleration jumps, finitely).

    Args:
        path: The seam (any path).
        amplitude: A, the largest lateral offset [m] (> 0, below half the seam length).
        wavelength: λ, the seam distance of one full oscillation [m] (> 2 dwell, ≥ 1 µm).
        pattern: "sine", "triangle" or "trapezoid".
        dwell: Travel held at each side [m] (≥ 0).
        normal: n, the axis the oscillation is perpendicular to (world frame); default the tool
            axis (the z axis of the seam's orientation), or the world z for a position-only seam.
        rounding: Travel over which each corner is rounded [m] (> 0, at most λ / 4); default
            λ / 16. Ignored for a sine without corners.

    Attributes:
        feature_length: The shortest stretch [m] the timing and sampling must resolve: the
            rounding of the corners, or a quarter wavelength for a sine.
    """

    def __init__(
        self,
        path: Path,
        amplitude: float,
        wavelength: float,
        pattern: str = "sine",
        dwell: float = 0.0,
        normal: ArrayLike | None = None,
        rounding: float | None = None,
    ) -> None:
        if not isinstance(path, Path):
            raise InputError(f"Weave needs a path to weave along, got {checks.describe(path)}")
        if path.length <= 0:
            raise InputError("Weave needs a seam of non-zero length")
        self.amplitude = checks.number(amplitude, "amplitude", positive=True, unit="m")
        self.wavelength = checks.number(wavelength, "wavelength", positive=True, unit="m")
        self.pattern = checks.choice(pattern, "pattern", WEAVE_PATTERNS)
        self.dwell = checks.number(dwell, "dwell", minimum=0.0, unit="m")
        if self.amplitude >= 0.5 * path.length:
            raise InputError(
                f"weave amplitude {self.amplitude:g} m is not small against the seam "
                f"({path.length:.4g} m long); give an amplitude below half the seam length"
            )
        if self.wavelength < MIN_WAVELENGTH:
            raise InputError(
                f"weave wavelength {self.wavelength:g} m is below {MIN_WAVELENGTH:g} m: no torch "
                "weaves that finely; give the travel of one oscillation in metres"
            )
        if self.wavelength > path.length * 1e6:
            raise InputError(
                f"weave wavelength {self.wavelength:g} m is more than a million times the seam "
                f"({path.length:.4g} m): give the travel of one oscillation in metres"
            )
        if 2.0 * self.dwell >= self.wavelength:
            raise InputError(
                f"dwell {self.dwell} m at each side leaves no travel to sweep across in a "
                f"wavelength of {self.wavelength} m; give dwell < wavelength / 2"
            )
        self.normal: np.ndarray | None = None
        if normal is not None:
            n = checks.vector(normal, "normal", 3)
            if np.linalg.norm(n) < 1e-9:
                raise InputError(f"normal must be a non-zero 3-vector, got {n.tolist()}")
            self.normal = n / np.linalg.norm(n)
        self.has_corners = self.pattern != "sine"
        if rounding is None:
            self.rounding = self.wavelength / 16.0 if self.has_corners else 0.0
        else:
            self.rounding = checks.number(rounding, "rounding", positive=True, unit="m")
            if self.rounding > 0.25 * self.wavelength:
                raise InputError(
                    f"rounding {self.rounding:g} m is more than a quarter of the wavelength "
                    f"{self.wavelength:g} m; give rounding ≤ {0.25 * self.wavelength:g} m"
                )
        self.path = path
        self.length = path.length
        self.has_orientation = path.has_orientation
        self.slerp = path.slerp
        self.feature_length = self.rounding if self.has_corners else 0.25 * self.wavelength
        if self.dwell > 0:
            self.feature_length = min(self.feature_length, max(self.dwell, self.rounding))
        # differences resolve the seam's own turns (the oscillation is differentiated exactly)
        self._fd_step = min(path._fd_step, self.wavelength / self.length / 100.0)
        self._kinks = self._corner_kinks()
        self._scale = 1.0
        if self.has_corners:
            cycle = np.linspace(0.0, self.wavelength, 4097)
            self._scale = 1.0 / float(np.abs(self._shape(cycle)[0]).max())
        if self._sides(np.linspace(0.0, 1.0, 257))[2].size:
            raise InputError("Weave: the seam runs along the normal somewhere; give another normal")

    def __repr__(self) -> str:
        rounded = f", corners rounded over {self.rounding:g} m" if self.has_corners else ""
        return (
            f"Weave({self.path!r}, {self.pattern}, amplitude {self.amplitude:g} m, "
            f"wavelength {self.wavelength:g} m{rounded})"
        )

    def _normals(self, s: np.ndarray) -> np.ndarray:
        if self.normal is not None:
            return np.tile(self.normal, (len(s), 1))
        rotations = self.path.rotation(s)
        if rotations is None:
            return np.tile([0.0, 0.0, 1.0], (len(s), 1))
        return rotations[:, :, 2]

    def _sides(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """n × t at the fractions ``s`` (N, 3) [m], its norms (N,), and the indices where it
        (nearly) vanishes: |n × t| < 1e-9 L, the seam running along the normal."""
        tangent, _ = self.path.position_derivatives(s)
        side = np.cross(self._normals(s), tangent)
        norm = np.linalg.norm(side, axis=1)
        return side, norm, np.flatnonzero(~(norm >= 1e-9 * self.length))

    def _phase_knots(self) -> tuple[list[float], list[float]]:
        """The warp from travel within a cycle [m] to the phase of the shape (the dwells)."""
        moving = self.wavelength - 2.0 * self.dwell
        quarter, d = 0.25 * moving, self.dwell
        knots = [0.0, quarter, quarter + d, 3 * quarter + d, 3 * quarter + 2 * d, self.wavelength]
        return knots, [0.0, 0.25, 0.25, 0.75, 0.75, 1.0]

    def _broken_line(self) -> tuple[np.ndarray, np.ndarray]:
        """Triangle and trapezoid: the unrounded shape over one cycle as a broken line, its
        knots [m of travel] and values (±1 at the sides)."""
        knots, phases = self._phase_knots()
        triangle_phase = [0.0, 0.25, 0.75, 1.0]
        if self.pattern == "trapezoid":  # the triangle doubled and clipped: ±1 from |2w| = 1
            triangle_phase = [0.0, 0.125, 0.25, 0.375, 0.625, 0.75, 0.875, 1.0]
        u = np.union1d(knots, np.interp(triangle_phase, phases, knots))
        triangle = np.interp(np.interp(u, knots, phases), [0, 0.25, 0.75, 1], [0, 1, -1, 0])
        values = triangle if self.pattern == "triangle" else np.clip(2.0 * triangle, -1.0, 1.0)
        return u, values

    def _corner_kinks(self) -> tuple[np.ndarray, np.ndarray]:
        """Where the broken line turns within a cycle [m] and by how much its slope changes
        [1/m], with the images one cycle before and after (for the rounding near the ends)."""
        if not self.has_corners:
            return np.zeros(0), np.zeros(0)
        u, values = self._broken_line()
        slopes = np.diff(values) / np.diff(u)
        turns = np.diff(np.concatenate((slopes, slopes[:1])))  # at u[1:-1] and at the cycle end
        where = np.concatenate((u[1:-1], [self.wavelength]))
        keep = np.abs(turns) > 1e-12 / self.wavelength
        where, turns = where[keep], turns[keep]
        images = np.concatenate((where - self.wavelength, where, where + self.wavelength))
        return images, np.tile(turns, 3)

    def _shape(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The unit shape and its first two derivatives [1/m, 1/m²] at travels ``u`` [m]."""
        cycle = np.mod(u, self.wavelength)
        knots, phases = self._phase_knots()
        if not self.has_corners:
            phase = np.interp(cycle, knots, phases)
            spans, rises = np.diff(knots), np.diff(phases)
            rates = np.divide(rises, spans, out=np.zeros_like(rises), where=spans > 0)
            rate = rates[np.clip(np.searchsorted(knots, cycle, "right") - 1, 0, len(rates) - 1)]
            angle = 2.0 * np.pi * phase
            w1 = 2.0 * np.pi * rate
            return np.sin(angle), np.cos(angle) * w1, -np.sin(angle) * w1**2
        line_u, values = self._broken_line()
        piece = np.clip(np.searchsorted(line_u, cycle, "right") - 1, 0, len(line_u) - 2)
        slopes = np.diff(values) / np.diff(line_u)
        shape, first = np.interp(cycle, line_u, values), slopes[piece]
        second = np.zeros_like(cycle)
        r = 0.5 * self.rounding
        where, turns = self._kinks
        x = cycle[:, None] - where[None, :]
        near = np.abs(x) < r
        rest = np.where(near, r - np.abs(x), 0.0)
        shape = shape + (turns * rest**3).sum(axis=1) / (6.0 * r**2)
        side = np.where(x >= 0.0, 1.0, -1.0)  # at a kink: its later piece, as `first` has
        first = first - (turns * side * rest**2).sum(axis=1) / (2.0 * r**2)
        second = second + (turns * rest).sum(axis=1) / r**2
        return shape * self._scale, first * self._scale, second * self._scale

    def offset(self, s: ArrayLike) -> np.ndarray:
        """The lateral offset w [m] at path fractions ``s`` (N,)."""
        u = np.clip(as_fractions(s), 0.0, 1.0) * self.length
        return self.amplitude * self._shape(u)[0]

    def across(self, s: ArrayLike) -> np.ndarray:
        """The unit direction across the seam (N, 3) at path fractions ``s``.

        Raises:
            InputError: the seam runs along the normal at some of ``s`` (a stretch too short
                for the check at construction, which samples the seam 257 times): no direction
                is across it there.
        """
        s = as_fractions(s).clip(0.0, 1.0)
        side, norm, along = self._sides(s)
        if along.size:
            raise InputError(
                f"Weave: the seam runs along the normal at s = {s[along[0]]:.6g} (no direction is "
                "across it there); give another normal, or a seam that turns off it"
            )
        return side / norm[:, None]

    def position(self, s: ArrayLike) -> np.ndarray:
        s = as_fractions(s).clip(0.0, 1.0)
        return self.path.position(s) + self.offset(s)[:, None] * self.across(s)

    def position_derivatives(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """(dP/ds, d²P/ds²) [m]: the seam's, plus the oscillation's differentiated exactly
        (L w' e and L² w'' e) and the turning of the across direction e (finite differences on
        the seam's scale): P = C + w e, P' = C' + L w' e + w e', P'' = C'' + L² w'' e +
        2 L w' e' + w e''."""
        s = as_fractions(s).clip(0.0, 1.0)
        seam_first, seam_second = self.path.position_derivatives(s)
        shape, first, second = self._shape(s * self.length)
        w, w1, w2 = (self.amplitude * x for x in (shape, first, second))
        e = self.across(s)
        h = self.path._fd_step
        lo, hi = np.clip(s - h, 0, 1), np.clip(s + h, 0, 1)
        mid = 0.5 * (lo + hi)
        width = (hi - lo)[:, None]
        e_lo, e_mid, e_hi = self.across(lo), self.across(mid), self.across(hi)
        e1 = (e_hi - e_lo) / width
        e2 = 4.0 * (e_hi - 2.0 * e_mid + e_lo) / width**2
        L = self.length
        d1 = seam_first + (L * w1)[:, None] * e + w[:, None] * e1
        d2 = (
            seam_second + (L * L * w2)[:, None] * e + (2.0 * L * w1)[:, None] * e1 + w[:, None] * e2
        )
        return d1, d2

    def _rotation(self, s: np.ndarray) -> np.ndarray:
        rotations = self.path.rotation(s)
        assert rotations is not None  # called for an oriented weave only: its seam's rotations
        return rotations

    def angular_rates(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        return self.path.angular_rates(s)


#: Shortest weave wavelength [m] (1 µm).
MIN_WAVELENGTH = 1e-6


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
