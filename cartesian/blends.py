"""Blended corners: a sequence of paths that does not stop where one path meets the next.

:func:`blend_corners` cuts every corner of a sequence of paths where the path enters the sphere
of the blend radius around the corner point, and joins the two cut points with a
:class:`CornerBlend`: a quintic curve that matches position, tangent and curvature of both
neighbours, so the tool passes the corner at its cruise speed (like a robot controller's
``movel(..., r=...)`` or Pilz's blend radius). The blend stays within the radius of the corner
point: its deviation from the sharp corner is at most the radius (in practice about half of it
for a 90° corner).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from cartesian.paths import Path, PathSequence, Slerp, as_fractions
from kinplan import checks
from kinplan.errors import InputError

__all__ = ["CornerBlend", "SubPath", "blend_corners"]

_TABLE_SIZE = 1025  # knots of the arc-length table of a blend
_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(6)
_STRAIGHT = 1e-9  # [rad] a corner turning less than this is already smooth: not blended


class SubPath(Path):
    """The part of a path between the path fractions ``s0`` < ``s1``, re-parametrised to [0, 1].

    Paths are parametrised proportionally to arc length, so the part is too; its length is
    (s1 − s0) × the path's length.

    Args:
        path: Any path.
        s0: Start fraction in [0, 1).
        s1: End fraction in (s0, 1].
    """

    def __init__(self, path: Path, s0: float, s1: float) -> None:
        if not isinstance(path, Path):
            raise InputError(f"SubPath needs a cartesian path, got {checks.describe(path)}")
        self.s0 = checks.number(s0, "s0", minimum=0.0)
        self.s1 = checks.number(s1, "s1")
        if not self.s0 < self.s1 <= 1.0:
            raise InputError(f"SubPath needs 0 <= s0 < s1 <= 1, got s0 = {s0}, s1 = {s1}")
        self.path = path
        self.width = self.s1 - self.s0
        self.length = path.length * self.width
        self.has_orientation = path.has_orientation
        self._fd_step = path._fd_step / self.width
        self.slerp = None  # rotations come from the path

    def __repr__(self) -> str:
        return f"SubPath({self.path!r}, {self.s0:.4g}..{self.s1:.4g})"

    def _map(self, s: ArrayLike) -> np.ndarray:
        return self.s0 + self.width * as_fractions(s).clip(0.0, 1.0)

    def position(self, s: ArrayLike) -> np.ndarray:
        return self.path.position(self._map(s))

    def position_derivatives(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        first, second = self.path.position_derivatives(self._map(s))
        return first * self.width, second * self.width**2

    def _rotation(self, s: np.ndarray) -> np.ndarray:
        rotations = self.path.rotation(self._map(s))
        assert rotations is not None  # called for oriented paths only
        return rotations

    def angular_rates(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        first, second = self.path.angular_rates(self._map(s))
        return first * self.width, second * self.width**2


class CornerBlend(Path):
    """A quintic curve from ``a`` to ``b`` matching tangents and curvatures there.

    The curve c(u), u ∈ [0, 1], has c(0) = a, c′(0) = L tₐ, c″(0) = L² kₐ and c(1) = b,
    c′(1) = L t_b, c″(1) = L² k_b, where L = |b − a|, t are the unit tangents and k the
    curvature vectors (d²p/du² per unit arc length) of the neighbouring paths. It is then
    re-parametrised by arc length exactly (a table of Gauss–Legendre arc lengths and Newton
    steps), with exact derivatives. The orientation (when the neighbours carry one) moves by
    slerp from the rotation at ``a`` to the one at ``b``.

    Args:
        a: Start point [m], shape (3,).
        b: End point [m], shape (3,).
        tangents: (tₐ, t_b), unit tangents.
        curvatures: (kₐ, k_b), curvature vectors [1/m].
        rotations: (Rₐ, R_b) or None for a position-only blend.
    """

    def __init__(
        self,
        a: np.ndarray,
        b: np.ndarray,
        tangents: tuple[np.ndarray, np.ndarray],
        curvatures: tuple[np.ndarray, np.ndarray],
        rotations: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> None:
        chord = float(np.linalg.norm(b - a))
        if chord <= 0.0:
            raise InputError("a corner blend needs two different points")
        self.a, self.b = np.array(a, dtype=float), np.array(b, dtype=float)
        self._coefficients = _quintic_hermite(
            self.a, self.b, chord * tangents[0], chord * tangents[1],
            chord**2 * curvatures[0], chord**2 * curvatures[1],
        )  # fmt: skip
        u = np.linspace(0.0, 1.0, _TABLE_SIZE)
        pieces = self._arc_between(u[:-1], u[1:])
        self._u_table = u
        self._arc_table = np.concatenate(([0.0], np.cumsum(pieces)))
        self.length = float(self._arc_table[-1])
        self.has_orientation = rotations is not None
        self.slerp = Slerp(*rotations) if rotations is not None else None

    def __repr__(self) -> str:
        return f"CornerBlend({self.a.round(4).tolist()} → {self.b.round(4).tolist()})"

    def _curve(self, u: np.ndarray, order: int) -> np.ndarray:
        """c(u) (order 0) or its derivative of the given order, shape (N, 3)."""
        powers = np.arange(6)
        factors = np.ones(6)
        exponents = powers - order
        for k in range(order):
            factors = factors * (powers - k)
        with np.errstate(divide="ignore"):
            basis = np.where(exponents >= 0, factors * u[:, None] ** np.maximum(exponents, 0), 0.0)
        return basis @ self._coefficients

    def _speed(self, u: np.ndarray) -> np.ndarray:
        return np.linalg.norm(self._curve(u, 1), axis=1)

    def _arc_between(self, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        """Arc length from ``lo`` to ``hi`` (elementwise), Gauss–Legendre with 6 nodes."""
        half = 0.5 * (hi - lo)
        middle = 0.5 * (hi + lo)
        nodes = (middle[:, None] + half[:, None] * _GAUSS_NODES).ravel()
        speeds = self._speed(nodes).reshape(len(lo), -1)
        return half * (speeds @ _GAUSS_WEIGHTS)

    def _parameter(self, s: ArrayLike) -> np.ndarray:
        """u at the path fractions s (arc length s × length), to rounding."""
        target = as_fractions(s).clip(0.0, 1.0) * self.length
        index = np.clip(np.searchsorted(self._arc_table, target, side="right") - 1, 0,
                        _TABLE_SIZE - 2)  # fmt: skip
        lo = self._u_table[index]
        width = self._u_table[index + 1] - lo
        share = (target - self._arc_table[index]) / (self._arc_table[index + 1]
                                                      - self._arc_table[index])  # fmt: skip
        u = lo + width * share
        for _ in range(3):  # Newton on arc(u) = target; arc′(u) = |c′(u)|
            error = self._arc_table[index] + self._arc_between(lo, u) - target
            u = np.clip(u - error / self._speed(u), lo, lo + width)
        return u

    def position(self, s: ArrayLike) -> np.ndarray:
        return self._curve(self._parameter(s), 0)

    def position_derivatives(self, s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        u = self._parameter(s)
        first, second = self._curve(u, 1), self._curve(u, 2)
        speed = np.linalg.norm(first, axis=1)[:, None]
        du = self.length / speed  # du/ds
        ddu = -(self.length**2) * np.sum(first * second, axis=1)[:, None] / speed**4
        return first * du, second * du**2 + first * ddu


def _quintic_hermite(
    p0: np.ndarray, p1: np.ndarray, v0: np.ndarray, v1: np.ndarray, a0: np.ndarray, a1: np.ndarray
) -> np.ndarray:
    """Coefficients (6, 3), lowest power first, of the quintic on [0, 1] with these end values,
    first and second derivatives."""
    c0, c1, c2 = p0, v0, 0.5 * a0
    d = p1 - (c0 + c1 + c2)
    e = v1 - (c1 + 2.0 * c2)
    f = a1 - 2.0 * c2
    c3 = 10.0 * d - 4.0 * e + 0.5 * f
    c4 = -15.0 * d + 7.0 * e - f
    c5 = 6.0 * d - 3.0 * e + 0.5 * f
    return np.vstack([c0, c1, c2, c3, c4, c5])


def _tangent_and_curvature(path: Path, s: float) -> tuple[np.ndarray, np.ndarray]:
    """Unit tangent and curvature vector d²p/du² (u arc length) of a path at fraction s."""
    first, second = path.position_derivatives(np.array([s]))
    speed = float(np.linalg.norm(first[0]))
    tangent = first[0] / speed
    acceleration = second[0] / speed**2
    return tangent, acceleration - (acceleration @ tangent) * tangent


def _cut(path: Path, corner: np.ndarray, radius: float, at_end: bool) -> float:
    """The path fraction where ``path`` enters the sphere of ``radius`` around its end
    (``at_end``) or leaves the one around its start."""
    s = np.linspace(0.0, 1.0, 2049)
    distance = np.linalg.norm(path.position(s) - corner, axis=1)
    inside = distance < radius
    if at_end:  # last sample outside the sphere, then the first inside after it
        k = int(np.flatnonzero(~inside)[-1])
        lo, hi = s[k], s[k + 1]
    else:
        k = int(np.flatnonzero(~inside)[0])
        lo, hi = s[k - 1], s[k]
    for _ in range(60):  # bisection on |p(s) − corner| = radius
        middle = 0.5 * (lo + hi)
        outside = np.linalg.norm(path.position(np.array([middle]))[0] - corner) >= radius
        if outside == at_end:
            lo = middle
        else:
            hi = middle
    return lo if at_end else hi


def blend_corners(paths: Sequence[Path], radius: float | Sequence[float]) -> PathSequence:
    """Join paths into one sequence whose corners are blended within ``radius``.

    Each corner (where one path ends and the next starts) is cut where the paths enter the
    sphere of the radius around it, and the two cut points are joined by a :class:`CornerBlend`
    (tangent and curvature continuous). A joint that is already smooth (tangents within 1e-9
    rad) or has radius 0 is kept as it is. Followed at a constant tool speed, the tool passes
    every blended corner at that speed.

    Args:
        paths: Two or more continuous paths (each starts where the previous ends), all oriented
            or all position-only.
        radius: Blend radius [m] ≥ 0, one for all corners or one per corner (len(paths) − 1).
            A radius may be at most half the length of each neighbouring path (so two blends
            never overlap).

    Returns:
        One :class:`~cartesian.PathSequence`.

    Raises:
        InputError: not paths, discontinuous paths, a negative radius or the wrong number of
            radii, or a radius larger than half a neighbouring path.
    """
    pieces = list(PathSequence(paths).paths) if not isinstance(paths, Path) else [paths]
    corners = len(pieces) - 1
    if np.ndim(radius) == 0:
        radii = np.full(corners, checks.number(radius, "radius", minimum=0.0, unit="m"))
    else:
        radii = checks.vector(radius, "radius", corners, "m")
        if np.any(radii < 0.0):
            raise InputError(f"blend radii must be >= 0 m, got {radii.tolist()}")
    for k, r in enumerate(radii):
        for side, piece in (("before", pieces[k]), ("after", pieces[k + 1])):
            if r > 0.5 * piece.length:
                raise InputError(
                    f"blend radius {r:g} m at corner {k + 1} is larger than half the path "
                    f"{side} it ({piece.length:.4g} m long); give a radius of at most "
                    f"{0.5 * piece.length:.4g} m there"
                )
    starts = np.zeros(len(pieces))
    ends = np.ones(len(pieces))
    blends: list[Path | None] = [None] * corners
    for k, r in enumerate(radii):
        before, after = pieces[k], pieces[k + 1]
        t_before, _ = _tangent_and_curvature(before, 1.0)
        t_after, _ = _tangent_and_curvature(after, 0.0)
        turn = float(np.arccos(np.clip(t_before @ t_after, -1.0, 1.0)))
        if r == 0.0 or turn < _STRAIGHT:
            continue
        if turn > np.pi - 1e-6:
            raise InputError(
                f"corner {k + 1} turns back on itself (180°): it cannot be blended; give radius "
                "0 there"
            )
        corner = before.end.translation
        ends[k] = _cut(before, corner, r, at_end=True)
        starts[k + 1] = _cut(after, corner, r, at_end=False)
        tangent_a, curvature_a = _tangent_and_curvature(before, ends[k])
        tangent_b, curvature_b = _tangent_and_curvature(after, starts[k + 1])
        rotations = None
        if before.has_orientation:
            r_a = before.rotation(np.array([ends[k]]))
            r_b = after.rotation(np.array([starts[k + 1]]))
            assert r_a is not None and r_b is not None
            rotations = (r_a[0], r_b[0])
        blends[k] = CornerBlend(
            before.position(np.array([ends[k]]))[0], after.position(np.array([starts[k + 1]]))[0],
            (tangent_a, tangent_b), (curvature_a, curvature_b), rotations,
        )  # fmt: skip
    joined: list[Path] = []
    for k, piece in enumerate(pieces):
        whole = starts[k] == 0.0 and ends[k] == 1.0
        joined.append(piece if whole else SubPath(piece, starts[k], ends[k]))
        blend = blends[k] if k < corners else None
        if blend is not None:
            joined.append(blend)
    return PathSequence(joined)
