"""A weaving torch: a lateral oscillation across a seam, superposed on any path.

:class:`Weave` is a :class:`cartesian.paths.Path` whose position adds to a seam's an offset
w(u) across it (u: travel along the seam [m]); patterns sine, triangle and trapezoid, dwells
at the sides, corners rounded (a cubic blend) so that the motion has a bounded acceleration.
Its derivatives are exact (the oscillation's analytically, the seam's turning by differences).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from cartesian.paths import Path, as_fractions
from kinplan import checks
from kinplan.errors import InputError

__all__ = ["MIN_WAVELENGTH", "WEAVE_PATTERNS", "Weave"]

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
